"""``certify backseat`` end to end over real ptys: example backseats in ``tests/backseats/``.

Every certification runs the real command (:func:`helmcheck.commands.certify_backseat_cmd.run`, in
a thread of this process so the grammar is built once) on its own pty, with the backseat a real
subprocess (pyserial) that opens the printed port. The good backseat and every faulty one run
at ×10 and the good one and the timing faults at ×5 (every fault at both in ``make matrix``), all
at once, for what the plan needs at their scale (every scenario: about 39 s at ×5, 36 s at ×10);
the module takes about 50 s of wall time. The faults a backseat makes once in a whole session run
at ×10 only: on helmcheck's pty (a clean line) each is the backseat's at once. One more test runs ``helmcheck certify backseat`` as a
subprocess to check the ``port:`` line and Ctrl-C.

Besides the verdicts themselves (mutation coverage: every fault caught on its clause, RH-BS-1..8,
at both scales), every run's ``wire.log`` is checked again offline with ``check-log --role
backseat`` and the same profile: the verdict of every clause the certification judged must be
the same (one judge for live and offline).

The example backseats' margins (polls every second against a 5 s limit, servo refresh at a
third of its timeout, 1.5 s back-off after a rejection) keep the verdicts stable on a loaded
machine.
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from helmcheck.commands import certify_backseat_cmd as cli
from helmcheck.checklog.checker import check_log
from helmcheck.grammar.wirelog import read_records
from helmcheck.profile import DEFAULT
from helmcheck.reports.results import load_results

HERE = Path(__file__).resolve().parent / "backseats"
GOOD = HERE / "good_backseat.py"
FAULTY = HERE / "faulty_backseat.py"
K = 5.0
SCALES = (5.0, 10.0)

#: fault -> (clause, verdict); see tests/backseats/faulty_backseat.py
FAULTS = {
    "bad-checksum": ("RH-BS-1", "fail"),
    "unpadded-checksum": ("RH-BS-1", "fail"),
    "lowercase-hex": ("RH-BS-7", "non-strict"),
    "bare-lf": ("RH-BS-7", "non-strict"),
    "short-omp": ("RH-BS-2", "fail"),
    "rwset-after-start": ("RH-BS-3", "fail"),
    "oms-while-stopped": ("RH-BS-3", "fail"),
    "hasty-oms": ("RH-BS-3", "fail"),
    "flood": ("RH-BS-4", "fail"),
    "lockout-ignore": ("RH-BS-5", "non-strict"),
    "fast-resend": ("RH-BS-5", "non-strict"),
    "late-refresh": ("RH-BS-6", "non-strict"),
    "no-poll": ("RH-BS-8", "non-strict"),
}
#: fault made once in a session (or a line of one form: omw-dollar-sum) -> its clause; run at ×10
ONCE = {
    "once-bad-checksum": "RH-BS-1",
    "once-timeout-121": "RH-BS-2",
    "once-heading-360": "RH-BS-2",
    "once-opk-minutes-0": "RH-BS-2",
    "omw-dollar-sum": "RH-BS-1",
}


def parse(argv: list[str]) -> argparse.Namespace:
    p = argparse.ArgumentParser()
    cli.add_arguments(p)
    return p.parse_args(argv)


def certify(report_dir: Path, backseat: list[str] | None, *, extra: tuple[str, ...] = (),
            connect_timeout: float = 20.0, scale: float = K) -> dict:
    """One certification on a new pty; ``backseat`` is the script's argv after the port."""
    procs: list[subprocess.Popen] = []
    errs = report_dir.parent / f"{report_dir.name}.backseat.err"

    def on_port(name: str) -> None:
        if backseat is not None:
            procs.append(subprocess.Popen([sys.executable, str(backseat[0]), name, *backseat[1:]],
                                          stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                          stderr=open(errs, "wb")))

    args = parse(["--time-scale", str(scale), "--report-dir", str(report_dir),
                  "--connect-timeout", str(connect_timeout), *extra])
    try:
        rc = cli.run(args, on_port=on_port)
    finally:
        for p in procs:
            try:
                p.wait(timeout=5)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
    return {"rc": rc, "results": load_results(report_dir), "dir": report_dir, "scale": scale,
            "backseat_rc": procs[0].returncode if procs else None,
            "backseat_err": errs.read_text(errors="replace") if errs.exists() else ""}


#: The module-scoped run below is made once: all of this module's tests go to one worker.
pytestmark = pytest.mark.xdist_group("test_certify_backseat")


#: ``make test`` runs every fault at ×10 and, at ×5, those whose clause times something in vehicle
#: seconds or in the line's (servo refresh, lockout, resend spacing, the reaction time, polling);
#: ``make matrix`` (``HELMCHECK_MATRIX=1``) every fault at both. All of them go at once, in one
#: batch: it lasts about as long as its longest plan (about 40 s).
MATRIX = os.environ.get("HELMCHECK_MATRIX") == "1"
AT_K = set(FAULTS) if MATRIX else {"late-refresh", "lockout-ignore", "fast-resend", "hasty-oms", "no-poll"}


def ran(fault: str, scale: float) -> bool:
    return scale != K or fault in AT_K


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Every certification of this module, all at once. Keys: ``(name, scale)``."""
    root = tmp_path_factory.mktemp("certify-backseat")
    jobs: dict[tuple[str, float], list] = {}
    for scale in SCALES:
        ks = f"{scale:g}"
        jobs["good", scale] = [GOOD, "--time-scale", ks]
        for fault in FAULTS:
            if ran(fault, scale):
                jobs[fault, scale] = [FAULTY, "--fault", fault, "--time-scale", ks]
    jobs["crash", K] = [GOOD, "--time-scale", f"{K:g}", "--crash-after", "6"]
    for fault in ONCE:
        jobs[fault, 10.0] = [FAULTY, "--fault", fault, "--time-scale", "10"]
    with ThreadPoolExecutor(max_workers=len(jobs) + 1) as pool:
        futures = {key: pool.submit(certify, root / f"{key[0]}-k{key[1]:g}", argv, scale=key[1])
                   for key, argv in jobs.items()}
        futures["never", K] = pool.submit(certify, root / "never", None, connect_timeout=1.5)
        return {key: f.result() for key, f in futures.items()}


def clauses(run: dict) -> dict[str, dict]:
    return {c["id"]: c for c in run["results"]["clauses"]}


@pytest.mark.parametrize("scale", SCALES)
def test_rh_bs_1_to_8_well_behaved_backseat_passes_every_scenario(runs, scale):
    run = runs["good", scale]
    r = run["results"]
    bad = {cid: (c["verdict"], c["reason"], c["evidence"]) for cid, c in clauses(run).items()
           if c["verdict"] != "pass"}
    assert not bad, (bad, run["backseat_err"])
    assert r["verdict"] == "pass" and run["rc"] == 0 and not r["partial"]
    assert r["role"] == "backseat"
    assert r["scenarios"] == ["nominal", "reject", "lockout", "mission-end", "silence"]
    kinds = {e["kind"] for e in r["events"]}
    assert {"lockout", "ack-error", "note"} <= kinds  # the lockout and a staged rejection happened
    assert {"A", "S"} <= set(r["coverage"]["modes"])
    # every scenario's moment reached the backseat, and the run lasted what the plan said (±10 %)
    scen = r["coverage"]["scenarios"]
    assert [x["name"] for x in scen] == r["scenarios"] and all(x["claimed"] for x in scen), scen
    assert abs(r["duration_s"] / r["settings"]["planned_s"] - 1) < 0.10, (r["duration_s"], r["settings"])
    assert r["run"]["overrun"] is None  # a poll a second asks for what the line carries
    for name in ("report.html", "report.md", "junit.xml", "wire.log"):
        assert (run["dir"] / name).stat().st_size > 0


def test_the_timeline_marks_every_command_the_backseat_sent(runs):
    """Issue 43: the report's commands lane shows the backseat's commands — each line it sent
    (not its $OSD polls; a malformed one too) marked at the time the wire log has it, and drawn."""
    short = [e["label"] for e in runs["short-omp", K]["results"]["events"] if e["kind"] == "command"]
    assert any(label.startswith("$OMP,") for label in short), short  # the faulty $OMP, refused, is marked
    run = runs["good", K]
    sent, pending = [], b""
    with open(run["dir"] / "wire.log", "rb") as f:
        for rec in read_records(f):
            if rec.dir != ">":
                continue
            *lines, pending = (pending + rec.data).split(b"\n")  # a line is marked when it is complete
            for line in lines:
                text = line.decode("latin-1").rstrip("\r")
                if text.startswith("$") and not text.startswith("$OSD,"):
                    sent.append((rec.t, text[:60]))
    marked = [(e["t"], e["label"]) for e in run["results"]["events"] if e["kind"] == "command"]
    assert len(sent) > 5 and marked == sent
    html = (run["dir"] / "report.html").read_text(encoding="utf-8")
    assert html.count('class="ev-command"') == len(sent)


FAULT_PARAMS = [pytest.param(f, id=f"{FAULTS[f][0]}-{f}") for f in sorted(FAULTS)]


@pytest.mark.parametrize("scale", SCALES)
@pytest.mark.parametrize("fault", FAULT_PARAMS)
def test_rh_bs_faulty_backseat_is_caught_on_its_clause(runs, fault, scale):
    """Mutation coverage: each faulty backseat is caught on its own clause, and only there."""
    if not ran(fault, scale):
        pytest.skip(f"{fault} at ×{scale:g} is make matrix's (HELMCHECK_MATRIX=1)")
    run = runs[fault, scale]
    clause, verdict = FAULTS[fault]
    cs = clauses(run)
    c = cs[clause]
    assert c["verdict"] == verdict, (c, run["backseat_err"])
    assert c["offending_count"] >= 1 and c["evidence"], c
    assert all(e["dir"] in (">", ">~") for e in c["evidence"])
    others = {cid: (x["verdict"], x["reason"]) for cid, x in cs.items()
              if cid != clause and x["verdict"] not in ("pass", "not-tested")}
    assert not others, others
    r = run["results"]
    assert r["verdict"] == verdict
    assert run["rc"] == (1 if verdict == "fail" else 0)


@pytest.mark.parametrize("fault", sorted(ONCE))
def test_rh_bs_1_2_one_broken_line_or_one_value_out_of_range_on_helmchecks_pty_fails(runs, fault):
    """On helmcheck's own pty (a link that cannot damage a byte: ``line model: clean``) a backseat
    that sends one broken line, or one value out of range, in a whole session FAILs on its clause
    at once: nothing is held for a line fault, no re-run is waited for, and the reason says
    nothing of a faulty line. A well-framed line with a right checksum is judged as sent."""
    run = runs[fault, 10.0]
    clause = ONCE[fault]
    r = run["results"]
    c = clauses(run)[clause]
    assert r["line_model"]["kind"] == "clean", r["line_model"]
    assert c["verdict"] == "fail" and c["offending_count"] >= 1, (c, run["backseat_err"])
    if fault.startswith("once-"):
        assert c["offending_count"] == 1, c
    for word in ("faulty line", "the line may", "no one fault", "spoilt", "made again"):
        assert word not in c["reason"], c["reason"]
    if clause == "RH-BS-2":  # in the backseat's words: the range quoted from §4, no vehicle clause first
        assert not c["reason"].split("first: ", 1)[1].startswith("RH-"), c["reason"]
        assert "§4 gives it “" in c["reason"], c["reason"]
    others = {cid: (x["verdict"], x["reason"]) for cid, x in clauses(run).items()
              if cid != clause and x["verdict"] not in ("pass", "not-tested")}
    assert not others, others
    assert r["verdict"] == "fail" and run["rc"] == 1


def test_rh_bs_1_to_8_every_backseat_clause_has_a_fault_that_is_caught():
    """RH-BS-1..8: the faulty backseats cover every backseat clause."""
    assert {c for c, _ in FAULTS.values()} == {f"RH-BS-{i}" for i in range(1, 9)}


def _offline(run: dict) -> dict[str, dict]:
    out = check_log(run["dir"] / "wire.log", profile=DEFAULT, role="backseat")
    return {c["id"]: c for c in out.clauses}


@pytest.mark.parametrize("scale", SCALES)
@pytest.mark.parametrize("name", [pytest.param("good", id="good"), *FAULT_PARAMS])
def test_rh_bs_1_to_8_check_log_of_the_wire_log_agrees_with_the_certification(runs, name, scale):
    """One judge: ``check-log --role backseat`` on the run's own wire.log, same profile, gives
    the verdict the certification gave for every clause it judged (RH-BS-1..8)."""
    if name != "good" and not ran(name, scale):
        pytest.skip(f"{name} at ×{scale:g} is make matrix's (HELMCHECK_MATRIX=1)")
    run = runs[name, scale]
    live = clauses(run)
    offline = _offline(run)
    judged = [c for c, x in live.items() if x["verdict"] != "not-tested"]
    assert judged
    differ = {c: (live[c]["verdict"], offline[c]["verdict"], live[c]["reason"], offline[c]["reason"])
              for c in judged if offline[c]["verdict"] != live[c]["verdict"]}
    assert not differ, differ
    for c in live:  # never FAIL against PASS, in either direction
        pair = {live[c]["verdict"], offline[c]["verdict"]}
        assert not (pair & {"fail", "non-strict"} and "pass" in pair), (c, pair)


@pytest.mark.parametrize("name", ["good", "short-omp"])
def test_check_log_with_no_options_judges_a_backseat_certification_as_the_backseat(runs, name, tmp_path, capsys):
    """A ``certify backseat`` log names its run: ``check-log wire.log`` with no option judges it
    as the backseat's, under the run's profile.toml, with the run's verdicts (RH-BS-1..8) and
    no vehicle clause (helmcheck's vehicle is not the implementation under test)."""
    from helmcheck.cli import main as cli_main

    run = runs[name, 10.0]
    code = cli_main(["check-log", str(run["dir"] / "wire.log"), "--report-dir", str(tmp_path / "c"), "--no-render"])
    out = capsys.readouterr().out
    assert "judged as: backseat (a certify backseat run, as its header says)" in out, out
    offline = {c["id"]: c["verdict"] for c in load_results(tmp_path / "c")["clauses"]}
    assert set(offline) == {f"RH-BS-{i}" for i in range(1, 9)}
    assert offline == {cid: c["verdict"] for cid, c in clauses(run).items()}
    assert code == run["rc"]


def test_backseat_that_crashes_mid_run_is_inconclusive(runs):
    run = runs["crash", K]
    r = run["results"]
    assert run["backseat_rc"] == 3
    assert r["verdict"] == "inconclusive" and r["partial"] and run["rc"] == 2
    assert "closed the port or crashed" in r["verdict_reason"]
    # it crashes 6 s after it started, its first byte at once (however long a loaded machine took
    # to start it)
    assert r["run"]["status"] == "disconnected" and 4 < r["run"]["ended_at"] - r["run"]["connected_at"] < 15
    assert (run["dir"] / "report.html").exists()


def test_backseat_that_never_connects_is_inconclusive(runs):
    run = runs["never", K]
    r = run["results"]
    assert r["verdict"] == "inconclusive" and run["rc"] == 2
    assert "never connected" in r["verdict_reason"]
    assert all(c["verdict"] == "not-tested" for c in r["clauses"])
    assert (run["dir"] / "report.md").exists() and (run["dir"] / "wire.log").exists()


def test_command_prints_port_first_and_writes_a_partial_report_on_ctrl_c(tmp_path):
    """The real command line: first stdout line ``port: …``; SIGINT mid-run → partial report."""
    out_dir = tmp_path / "report"
    wire = tmp_path / "copy.log"
    proc = subprocess.Popen([sys.executable, "-m", "helmcheck", "certify", "backseat", "--time-scale", str(K),
                             "--duration", "60", "--report-dir", str(out_dir), "--wire-log", str(wire),
                             "--connect-timeout", "120"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL)
    backseat = None
    try:
        first = proc.stdout.readline().decode()
        assert first.startswith("port: /dev/pts/"), first
        backseat = subprocess.Popen([sys.executable, str(GOOD), first.split(": ", 1)[1].strip(),
                                     "--time-scale", str(K)], stdin=subprocess.DEVNULL,
                                    stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        deadline = time.monotonic() + 120
        log = out_dir / "wire.log"
        while time.monotonic() < deadline:  # wait until the judged run is under way
            if log.exists() and "scenario nominal starts" in log.read_text(errors="replace"):
                break
            time.sleep(0.2)
        time.sleep(2.0)
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
        if backseat is not None:
            try:
                backseat.wait(timeout=5)
            except subprocess.TimeoutExpired:
                backseat.kill()
    assert proc.returncode == 2, err.decode()
    r = load_results(out_dir)
    assert r["partial"] and r["verdict"] == "inconclusive"
    assert "interrupted" in r["verdict_reason"]
    assert out.decode().strip().startswith("INCONCLUSIVE — partial: the run was interrupted; ")
    assert wire.read_text().startswith("# helmcheck wire-log 1")
    assert "Traceback" not in err.decode()
