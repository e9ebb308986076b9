"""``helmcheck verify`` re-judges everything from the evidence (issue "One way from judge to
certificate"): the selection, the implementation under test's end and a run cut short are
facts of the wire log (``selection:``, ``process:``, ``not judged``, ``run partial:`` notes), and
verify runs the one assembling function (:func:`helmcheck.reports.assemble.assemble`) again on
them and compares every clause, ``partial``, ``process``, the run verdict and the certificate.

The runs, made once for the module under one ``tmp_path_factory`` root:

* ``mutant`` — a vehicle that writes lower-case checksums (a RH-FRM-3 FAIL seen on every line)
  certified with ``--select RH-SRV-*,RH-ACK-1``: the FAIL is observed outside the selection;
* ``emulator`` — the emulator, ``--select RH-ACK-1``: a passing partial run;
* ``vh-dies`` — ``certify vehicle --exec`` of ``tests/faulty_vehicles/dying_vehicle.py``, which
  exits with code 5 mid-run; ``bs-crash`` — ``certify backseat --exec`` of the example backseat
  with ``--crash-after 2``;
* ``bs-never`` — ``certify backseat`` with nobody connecting; ``bs-interrupted`` —
  ``certify backseat --exec`` stopped with SIGTERM.

Each tamper test edits a copy (schema-valid: the verdict follows from the edited clauses) and
checks that unsigned ``verify`` exits 1 and names what differs; the honest runs verify (exit 0).
"""

from __future__ import annotations

import shlex
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from junitparser import Error, Failure, JUnitXml

from helmcheck.cli import main as cli_main
from helmcheck.certify.vehicle.runner import Options, certify
from helmcheck.reports.results import finish, load_results, write_results_atomic
from tests.faulty_vehicles import EMU_PROFILE, MUTANTS, make_core, serve

K = 25.0
HERE = Path(__file__).resolve().parent
PY = shlex.quote(sys.executable)
DYING = HERE / "faulty_vehicles" / "dying_vehicle.py"
BACKSEAT = f"{PY} {shlex.quote(str(HERE / 'backseats' / 'good_backseat.py'))} {{port}} --time-scale {{time_scale}}"
BS = ("certify", "backseat", "--time-scale", "5", "--connect-timeout", "20")

#: The module-scoped runs are made once: all of this module's tests go to one worker.
pytestmark = pytest.mark.xdist_group("test_verify_evidence")


def _vehicle(root: Path, name: str, mutant, select: list[str]) -> None:
    m = {x.name: x for x in MUTANTS}[mutant] if mutant else None
    with serve(lambda start: make_core(m, K, start)) as port:
        certify(Options(port=port, profile=EMU_PROFILE.replace(time_scale=K), time_scale=K,
                        report_dir=root / name, select=select, examples=0, progress=False, seed=1))


def _cli(root: Path, name: str, *argv: str) -> int:
    proc = subprocess.run([sys.executable, "-m", "helmcheck", *argv, "--report-dir", str(root / name)],
                          stdin=subprocess.DEVNULL, capture_output=True, text=True, timeout=180)
    assert "Traceback" not in proc.stderr, proc.stderr
    return proc.returncode


def _interrupted_backseat(root: Path) -> int:
    report = root / "bs-interrupted"
    proc = subprocess.Popen([sys.executable, "-m", "helmcheck", *BS, "--duration", "60", "--exec", BACKSEAT,
                             "--report-dir", str(report)],
                            stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        ready = report / "backseat.stdout.log"
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and not (ready.exists() and ready.read_text().strip()):
            time.sleep(0.1)
        time.sleep(1.5)
        proc.send_signal(signal.SIGTERM)
        proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    return proc.returncode


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("evidence")
    _vehicle(root, "mutant", "lowercase-checksum-out", ["RH-SRV-*", "RH-ACK-1"])
    _vehicle(root, "emulator", None, ["RH-ACK-1"])
    codes = {
        "vh-dies": _cli(root, "vh-dies", "certify", "vehicle", "--time-scale", str(K), "--baud", "115200",
                        "--examples", "0", "--no-progress", "--select", "RH-SRV-*,RH-INT-*,RH-PRM-*",
                        "--exec", f"{PY} {shlex.quote(str(DYING))} --after 1.5 --time-scale {{time_scale}}"),
        "bs-crash": _cli(root, "bs-crash", *BS, "--duration", "20", "--exec", BACKSEAT + " --crash-after 2"),
        "bs-never": _cli(root, "bs-never", *BS[:4], "--connect-timeout", "1", "--duration", "5"),
        "bs-interrupted": _interrupted_backseat(root),
    }
    return root, codes


def copy(runs, name: str, tmp_path: Path) -> Path:
    d = tmp_path / name
    shutil.copytree(runs[0] / name, d)
    return d


def verify(capsys, d: Path) -> tuple[int, list[str]]:
    code = cli_main(["verify", str(d)])
    captured = capsys.readouterr()
    return code, captured.out.splitlines() + captured.err.splitlines()


def mismatches(lines: list[str], subject: str) -> list[str]:
    return [ln for ln in lines if ln.startswith(f"MISMATCH {subject}:")]


def clause(results: dict, cid: str) -> dict:
    [c] = [c for c in results["clauses"] if c["id"] == cid]
    return c


def rewrite(d: Path, edit) -> dict:
    """Edit results.json in place, the run verdict recomputed so the document stays valid."""
    r = load_results(d)
    edit(r)
    finish(r, finished=r["finished"], duration_s=r["duration_s"], partial=r["partial"])
    from helmcheck.reports.scope import scope_of
    r["certificate"] = scope_of(r).certificate
    r["scope"] = scope_of(r).as_dict()
    write_results_atomic(d, r)  # schema-valid
    return r


# --------------------------------------------------------------------------- the honest runs

def test_the_selection_and_the_run_facts_are_in_the_wire_log(runs):
    root, codes = runs
    wire = (root / "mutant" / "wire.log").read_text()
    assert "! selection: RH-SRV-*,RH-ACK-1" in wire
    r = load_results(root / "mutant")
    assert r["verdict"] == "fail" and clause(r, "RH-FRM-3")["verdict"] == "fail"
    assert clause(r, "RH-FRM-3")["reason"].startswith("not selected, but observed: ")
    assert clause(r, "RH-OUT-1")["verdict"] == "not-tested"
    dies = (root / "vh-dies" / "wire.log").read_text()
    assert "! process: {" in dies and '"ended_early":true' in dies and '"exit_code":5' in dies
    crash = (root / "bs-crash" / "wire.log").read_text()
    assert "! not judged RH-BS-" in crash and "! process: {" in crash and "! run partial: " in crash
    assert "! not judged RH-BS-1,RH-BS-2,RH-BS-3" in (root / "bs-never" / "wire.log").read_text()


@pytest.mark.parametrize("name, verdict, code", [
    ("mutant", "fail", None), ("emulator", "pass", None), ("vh-dies", "fail", 1), ("bs-crash", "fail", 1),
    ("bs-never", "inconclusive", 2), ("bs-interrupted", "inconclusive", 2)])
def test_an_honest_run_verifies(runs, capsys, name, verdict, code):
    """Also a run whose --exec implementation died: its end is evidence, not a contradiction."""
    root, codes = runs
    r = load_results(root / name)
    assert r["verdict"] == verdict, r["verdict_reason"]
    if code is not None:
        assert codes[name] == code
    got, lines = verify(capsys, root / name)
    assert got == 0, "\n".join(lines)
    assert lines[-1].startswith("VERIFIED: ")


# --------------------------------------------------------------------------- tampering is named

@pytest.mark.unverifiable
def test_a_selection_declared_after_the_fact_is_caught(runs, tmp_path, capsys):
    """The run selected RH-SRV-* and RH-ACK-1; results.json now says RH-SRV-* only."""
    d = copy(runs, "mutant", tmp_path)

    def edit(r):
        r["settings"]["select"] = ["RH-SRV-*"]
        clause(r, "RH-ACK-1").update(verdict="not-tested", reason="not selected (--select)", evidence=[],
                                     offending_count=0)

    rewrite(d, edit)
    code, lines = verify(capsys, d)
    assert code == 1
    sel = mismatches(lines, "settings.select")
    assert sel and "--select RH-SRV-*" in sel[0] and "RH-SRV-*,RH-ACK-1" in sel[0], lines
    assert any("results.json says NOT-TESTED, the wire log gives PASS" in ln
               for ln in mismatches(lines, "clause RH-ACK-1")), lines


@pytest.mark.unverifiable
def test_a_fail_observed_outside_the_selection_cannot_be_relabelled(runs, tmp_path, capsys):
    d = copy(runs, "mutant", tmp_path)

    def edit(r):
        clause(r, "RH-FRM-3").update(verdict="not-tested", reason="not selected (--select)", evidence=[],
                                     offending_count=0)

    r = rewrite(d, edit)
    assert r["verdict"] == "pass"  # what the forger wanted
    code, lines = verify(capsys, d)
    assert code == 1
    assert any("results.json says NOT-TESTED, the wire log gives FAIL" in ln
               for ln in mismatches(lines, "clause RH-FRM-3")), lines
    assert any("results.json says PASS, the re-judged run gives FAIL" in ln for ln in mismatches(lines, "verdict"))


@pytest.mark.unverifiable
def test_a_deleted_process_object_is_caught(runs, tmp_path, capsys):
    """The vehicle under test died; results.json forgets it and says PASS."""
    d = copy(runs, "vh-dies", tmp_path)
    r = rewrite(d, lambda r: r.pop("process"))
    assert r["verdict"] == "pass"
    code, lines = verify(capsys, d)
    assert code == 1
    assert any("missing from results.json" in ln and "exited with code 5 before the run's end" in ln
               for ln in mismatches(lines, "process")), lines
    assert any("results.json says PASS, the re-judged run gives FAIL" in ln for ln in mismatches(lines, "verdict"))


@pytest.mark.unverifiable
def test_an_edited_process_object_is_caught(runs, tmp_path, capsys):
    d = copy(runs, "bs-crash", tmp_path)

    def edit(r):
        r["process"].update(ended_early=False, exit_code=None, signal="SIGTERM")
    rewrite(d, edit)
    code, lines = verify(capsys, d)
    assert code == 1
    assert mismatches(lines, "process.ended_early") and mismatches(lines, "process.signal"), lines
    assert mismatches(lines, "verdict"), lines


@pytest.mark.unverifiable
def test_a_flipped_run_verdict_is_caught(runs, tmp_path, capsys):
    # schema-valid: a finished run declared interrupted (INCONCLUSIVE instead of PASS)
    d = copy(runs, "emulator", tmp_path / "partial")
    r = rewrite(d, lambda r: r.update(partial=True))
    assert r["verdict"] == "inconclusive"
    code, lines = verify(capsys, d)
    assert code == 1
    assert mismatches(lines, "partial") and mismatches(lines, "verdict"), lines
    # and the other way round: a run cut short declared finished
    d = copy(runs, "bs-interrupted", tmp_path / "finished")
    r = rewrite(d, lambda r: r.update(partial=False))
    code, lines = verify(capsys, d)
    assert code == 1
    assert any("the wire log says the run was cut short" in ln for ln in mismatches(lines, "partial")), lines
    # a bare flip is not even a valid document
    d = copy(runs, "mutant", tmp_path / "bare")
    r = load_results(d)
    r["verdict"] = "pass"
    write_results_atomic(d, r, check=False)
    code, lines = verify(capsys, d)
    assert code == 1
    assert any("verdict" in ln for ln in mismatches(lines, "results.json")), lines


@pytest.mark.unverifiable
def test_a_time_scale_other_than_the_profiles_is_caught(runs, tmp_path, capsys):
    d = copy(runs, "emulator", tmp_path)
    r = load_results(d)
    r["settings"]["time_scale"] = 1.0
    write_results_atomic(d, r)
    code, lines = verify(capsys, d)
    assert code == 1
    assert any("profile.toml" in ln and "time_scale 25" in ln for ln in mismatches(lines, "settings.time_scale"))


# --------------------------------------------------------------------------- JUnit: the run verdict

def _run_case(d: Path):
    xml = JUnitXml.fromfile(str(d / "junit.xml"))
    suites = list(xml) if isinstance(xml, JUnitXml) else [xml]
    [case] = [c for s in suites for c in s if c.name == "run-verdict"]
    return suites[0], case


@pytest.mark.parametrize("name", ["bs-never", "bs-interrupted"])
def test_junit_of_an_inconclusive_run_has_an_erroring_run_verdict(runs, name):
    root, _ = runs
    suite, case = _run_case(root / name)
    [res] = case.result
    assert isinstance(res, Error) and res.type == "inconclusive"
    assert res.message.startswith("INCONCLUSIVE: ")
    assert "not a certificate" in res.text
    assert suite.errors >= 1
    props = {p.name: p.value for p in suite.properties()}
    assert "not a certificate" in props["helmcheck.not_a_certificate"]


def test_junit_of_a_failed_run_has_a_failing_run_verdict_and_a_partial_run_says_so(runs):
    root, _ = runs
    _, case = _run_case(root / "vh-dies")
    [res] = case.result
    assert isinstance(res, Failure) and res.type == "run-verdict" and "exited with code 5" in res.message
    suite, case = _run_case(root / "emulator")
    assert case.result == [] and "Not a certificate: partial: 1 of 60" in (case.system_out or "")
    assert (suite.failures, suite.errors) == (0, 0)
    [prop] = [p for p in case._elem.iter("property") if p.get("name") == "helmcheck.not_a_certificate"]
    assert prop.get("value").startswith("partial: 1 of 60 claimed clauses judged; not a certificate")


# --------------------------------------------------------------------------- the suite checks every run

def test_every_results_directory_of_the_session_is_listed_and_verifies(runs, session_results_directories):
    """The runs above live under tmp_path_factory, not a test's tmp_path: the session's check
    (tests/conftest.py) lists them with every other run this worker wrote, and each verifies."""
    from helmcheck.commands.verify_cmd import verify_run

    root, _ = runs
    listed = session_results_directories()
    mine = {root / n for n in ("mutant", "emulator", "vh-dies", "bs-crash", "bs-never", "bs-interrupted")}
    assert mine <= set(listed)
    problems = {str(d): [str(f) for f in got.findings] for d in listed if not (got := verify_run(d)).ok}
    assert problems == {}
