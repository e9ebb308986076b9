"""Unplugged mid-run: a port that vanishes is waited for under its name, the gap recorded, nothing lost.

The line-fault relay's cut (``cut=5s@X``, :func:`helmcheck.line.faultline.impaired_line`) closes the
pty a tester opened through a symbolic link and makes a new one under the same link 5 s later, as
a USB adapter unplugged and plugged back comes back under its ``/dev/serial/by-id`` name. On real
ptys, against the emulator (a process of its own) and the example backseat:

* ``certify vehicle`` whose vehicle port is gone for 5 s finishes: a certificate, or INCONCLUSIVE
  for nothing but the gap; the case the gap cut runs again, and the record alone re-judges to the
  same verdicts (``helmcheck verify``);
* one whose port does not come back in time exits 2 with one ``resume:`` line; that command then
  completes the run, and the wire log written before the cut is the first part of the final one,
  byte for byte;
* ``certify backseat`` whose own device is gone for 5 s finishes, the scenario it cut run again;
* ``monitor --between`` whose vehicle side is gone for 5 s goes on relaying and judging the
  backseat, opens the vehicle side again, and books no violation the gap could explain;
* the backseat judge does not hold a gap against the backseat (sans-IO): a poll interval across a
  ``run resumed`` note is not judged, one after it is.

``make matrix`` (``HELMCHECK_MATRIX=1``) adds the long variants: the independent simulator
certified whole behind a cut, a cut in the exploration, a backseat device and a monitored side
that never come back.
"""

from __future__ import annotations

import json
import os
import shlex
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from helmcheck.certify.vehicle.runner import Options, certify
from helmcheck.cli import main as cli_main
from helmcheck.grammar.wirelog import read_wire_log
from helmcheck.line.faultline import impaired_line
from helmcheck.line.faultrelay import FaultRelay
from helmcheck.line.pty_link import PtyLink
from helmcheck.line.reopen import wait_for_port
from helmcheck.profile import DEFAULT, emulator_profile
from helmcheck.reports.results import load_results

from tests.test_certify_backseat_judge import POLL, Run

MATRIX = os.environ.get("HELMCHECK_MATRIX") == "1"
ROOT = Path(__file__).resolve().parent.parent
GOOD_BACKSEAT = ROOT / "tests" / "backseats" / "good_backseat.py"
SIM = ROOT.parent / "shared" / "third-party" / "uvc_sim.py"
K = 25.0
#: the cases of a short run (about 8 s at x25): servo control, remote control and its interruption,
#: RH-ACK-1 (RH-INT-2's case alone takes 11 s: left to the whole run)
SELECT = ["RH-SRV-*", "RH-INT-1", "RH-INT-3", "RH-ACK-1"]
#: words of every verdict a gap leaves INCONCLUSIVE (the judges' own, naming it or the unknown state)
GAP_WORDS = ("after a gap of", "the run was interrupted", "a side of the line was gone", "the gap may explain",
             "state unknown", "lost track of the vehicle's state")


#: and those of a command the record ended without an answer to (a side that never came back)
NOT_BACK_WORDS = ("the record ended", "said nothing at all afterwards (a link fault?)")


def _only_the_gap(results: dict, words=GAP_WORDS) -> dict:
    """Clauses neither PASS nor NOT-TESTED for a reason other than the gap: ``{id: (verdict, reason)}``."""
    return {c["id"]: (c["verdict"], c["reason"]) for c in results["clauses"]
            if c["verdict"] not in ("pass", "not-tested")
            and not (c["verdict"] == "inconclusive" and any(w in c["reason"] for w in words))}


def _notes(path: Path) -> list[tuple[float, str]]:
    with open(path, "rb") as f:
        return [(r.t, r.note) for r in read_wire_log(f) if r.dir == "!"]


def _helmcheck(*args: str, timeout: float = 240) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "helmcheck", *args], capture_output=True, text=True,
                          stdin=subprocess.DEVNULL, cwd=ROOT, timeout=timeout)


def _wait_for_path(path: Path, timeout: float = 20.0) -> None:
    end = time.monotonic() + timeout
    while not os.path.lexists(path):
        assert time.monotonic() < end, f"{path} never came back"
        time.sleep(0.05)


# ============================================================================ the judge (sans-IO)

def test_rh_bs_8_a_poll_interval_across_a_run_resumed_note_is_not_judged_one_after_it_is():
    """RH-BS-8: polls a second apart, then 6 s unseen (the record's gap), then polls again. With
    the ``run resumed`` note at the return the interval across the gap is not judged; without it
    the same bytes are a violation. After the note the interval is judged from the note."""
    def run(resumed: bool, last: float) -> Run:
        r = Run()
        for t in (0.0, 1.0, 2.0):
            r.bs(t, POLL)
        if resumed:
            r.note(7.5, "run resumed: helmcheck's port came back after a gap of 5.50 s")
        return r.bs(8.0, POLL).bs(last, POLL).close(last + 0.5)
    assert run(True, 9.0).verdict("RH-BS-8") == "pass"
    assert run(False, 9.0).verdict("RH-BS-8") in ("fail", "non-strict")  # the gap, held against it
    late = run(True, 14.0)  # 6 s after the poll that followed the note: still the backseat's
    assert late.verdict("RH-BS-8") in ("fail", "non-strict")
    assert "after its previous poll" in late.ledger.verdict("RH-BS-8").reason


def test_rh_bs_1_a_line_the_gap_cut_is_nobody_s():
    """The first half of a line before the gap and a whole line after the ``run resumed`` note:
    the torn half is not judged against the backseat (RH-BS-1), nor counted as a faulty line's;
    without the note a faulty line's (INCONCLUSIVE); the same torn bytes three times,
    the backseat's."""
    r = Run()
    r.bs(0.0, POLL).bs(1.0, POLL[:7])  # cut in the middle
    r.note(6.0, "run resumed: helmcheck's port came back after a gap of 5.00 s")
    r.bs(6.2, POLL).close(7.0)
    assert r.fails("RH-BS-1") == 0 and r.verdict("RH-BS-1") == "pass"
    assert "spoilt" not in r.ledger.verdict("RH-BS-1").reason  # the gap's: not even a faulty line's
    torn = Run()
    torn.bs(0.0, POLL).bs(1.0, POLL[:7]).bs(6.2, POLL).close(7.0)  # the same bytes, no note
    assert torn.fails("RH-BS-1") == 0  # a torn line a faulty line may have made: not judged
    assert torn.verdict("RH-BS-1") == "inconclusive"
    assert "the line, not the implementation, may have done it" in torn.ledger.verdict("RH-BS-1").reason
    again = Run()
    for t in (1.0, 2.0, 3.0):  # the same torn bytes three times, no gap: the backseat's
        again.bs(t - 0.5, POLL).bs(t, POLL[:7])
    assert again.bs(4.0, POLL).close(5.0).fails("RH-BS-1") >= 1


def test_a_port_is_opened_as_soon_as_its_name_is_back_and_not_waited_for_past_the_wait(tmp_path):
    """wait_for_port: a link that names no device yet is tried until it does (0.4 s here); a
    name that never comes back is given up on after the wait, saying why."""
    pty = PtyLink(19200)
    link = tmp_path / "by-id"
    try:
        t0 = time.monotonic()
        threading.Timer(0.4, lambda: os.symlink(pty.name, link)).start()
        got, why = wait_for_port(str(link), baud=19200, within_s=5.0)
        assert got is not None and why == "" and 0.4 <= time.monotonic() - t0 < 2.0
        got.close()
        t0 = time.monotonic()
        none, why = wait_for_port(str(tmp_path / "never"), baud=19200, within_s=0.5)
        assert none is None and why == "no such device" and 0.5 <= time.monotonic() - t0 < 1.5
    finally:
        pty.close()


# ============================================================================ certify vehicle

def _certify_vehicle(port: str, out: Path, select=SELECT, wait: float = 30.0, examples: int = 0):
    profile = emulator_profile().replace(time_scale=K, baud=19200)
    return certify(Options(port=port, profile=profile, time_scale=K, report_dir=out, select=select, examples=examples,
                           progress=False, render=False, seed=1, reconnect_wait_s=wait, line="noisy"))


def test_a_vehicle_port_gone_for_5_s_mid_run_is_waited_for_and_the_run_finishes(tmp_path):
    """The vehicle's port (a symbolic link, as /dev/serial/by-id) is unplugged 5 s into the run
    and plugged back 5 s later: the run waits, records the gap, verifies the vehicle stopped
    and runs the cut case again; it ends a certificate of what it selected or INCONCLUSIVE for
    the gap alone (a poll the cut left unanswered is a remark, not a verdict), and ``helmcheck verify`` gets the
    same verdicts from the record. Before this, the run stopped at the cut: INCONCLUSIVE (link),
    the vehicle left unrestored."""
    from helmcheck.emulator.process import EmulatorProcess
    with EmulatorProcess(time_scale=K, baud=19200) as emu, \
            impaired_line(emu.port, "cut=5s@5", link=tmp_path / "vehicle") as line:
        out = _certify_vehicle(str(line.port), tmp_path / "r")
    r = out.results
    assert not _only_the_gap(r), out.reason
    assert out.exit_code in (0, 2) and r["partial"] is False
    [gap] = r["link_gaps"]
    assert gap["port"] == str(tmp_path / "vehicle") and 4.5 <= gap["gap_s"] < 8.0, gap
    cut = gap["cut"].removeprefix("case ")
    ids = [c["id"] for c in r["cases"]]
    assert ids.count(cut) == 2 and [c for c in r["cases"] if c.get("cut")][0]["id"] == cut  # run again
    assert {c["id"] for c in r["clauses"] if c["verdict"] == "pass"} >= {"RH-SRV-1", "RH-INT-1", "RH-INT-3", "RH-SRV-3"}
    notes = [text for _, text in _notes(tmp_path / "r" / "wire.log")]
    back = next(i for i, n in enumerate(notes) if n.startswith("run resumed: the link came back after a gap"))
    assert notes[back + 1].startswith("link reopened: ") and f"{cut} starts again" in notes[back]
    assert r["restore"]["verified"] and r["settings"]["reconnect_wait_s"] == 30.0
    assert cli_main(["verify", str(tmp_path / "r")]) == 0


def test_a_vehicle_port_that_does_not_come_back_exits_2_with_the_resume_command_which_completes_it(tmp_path):
    """--reconnect-wait 1 and a cut of 5 s: the command stops 1 s after the cut with exit 2, one
    ``resume:`` line and a partial report; the wire log and results.json hold everything up to
    the cut. Once the port is back, that very command completes the run into the same
    directory; the first part's wire log is the final log's prefix, byte for byte, and no case
    completed before the cut runs again."""
    from helmcheck.emulator.process import EmulatorProcess
    rdir = tmp_path / "r"
    prof = tmp_path / "emu.toml"
    prof.write_text('fault_injection = "oxflt"\nbaud = 19200\n')
    with EmulatorProcess(time_scale=K, baud=19200) as emu, \
            impaired_line(emu.port, "cut=5s@5", link=tmp_path / "vehicle") as line:
        first = _helmcheck("certify", "vehicle", "--no-progress", "--port", str(line.port), "--time-scale", f"{K:g}",
                           "--profile", str(prof), "--select", ",".join(SELECT), "--examples", "0",
                           "--report-dir", str(rdir), "--reconnect-wait", "1")
        assert first.returncode == 2, (first.stdout, first.stderr)
        resume = [ln for ln in first.stdout.splitlines() if ln.startswith("resume: ")]
        assert len(resume) == 1, first.stdout
        argv = shlex.split(resume[0].removeprefix("resume: "))
        assert argv[:3] == ["helmcheck", "certify", "vehicle"] and argv[argv.index("--resume") + 1] == str(rdir)
        part = load_results(rdir)
        before = (rdir / "wire.log").read_bytes()
        assert part["partial"] is True and part["resume_command"] == resume[0].removeprefix("resume: ")
        [gap] = part["link_gaps"]
        assert gap["back_at_s"] is None
        assert "did not come back within 1 s" in part["verdict_reason"]
        done = [c["id"] for c in part["cases"] if not c.get("cut")]
        notes = [text for _, text in _notes(rdir / "wire.log")]
        assert notes[-1].startswith("run partial: link fault: the vehicle's port") and "Traceback" not in first.stderr
        _wait_for_path(tmp_path / "vehicle")  # plugged back
        second = _helmcheck(*argv[1:], "--no-progress")
    r = load_results(rdir)
    after = (rdir / "wire.log").read_bytes()
    assert after.startswith(before) and len(after) > len(before)  # nothing recorded before the cut lost
    assert r["partial"] is False and second.returncode in (0, 2), (second.stdout, second.stderr)
    assert not _only_the_gap(r), r["verdict_reason"]
    ids = [c["id"] for c in r["cases"]]
    assert ids[:len(done)] == done and len(ids) == len(set(ids))  # nothing twice, nothing lost
    assert gap["cut"].removeprefix("case ") in ids[len(done):]
    assert {c["id"] for c in r["clauses"] if c["verdict"] == "pass"} >= {"RH-SRV-1", "RH-INT-1", "RH-INT-3", "RH-SRV-3"}
    assert r["restore"]["verified"]
    assert cli_main(["verify", str(rdir)]) == 0


# ============================================================================ certify backseat

def _certify_backseat(tmp: Path, faults: str, *, wait: float = 30.0, duration: float = 8.0,
                      scenarios=("nominal", "reject")):
    """certify backseat on the relay's vehicle-side pty (by its link, as a device), the good
    backseat on the relay's other side; ``faults`` cuts helmcheck's side."""
    from helmcheck.certify.backseat.certifier import Options as BsOptions, certify as certify_backseat
    k = 10.0
    with FaultRelay("pty", "pty", faults, link=tmp / "backseat", vehicle_link=tmp / "vehicle", cut_side="vehicle",
                    realtime=False) as relay:
        bs = subprocess.Popen([sys.executable, str(GOOD_BACKSEAT), str(tmp / "backseat"), "--time-scale", f"{k:g}"],
                              stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            out = certify_backseat(BsOptions(profile=DEFAULT, report_dir=tmp / "r", port=relay.vehicle_port,
                                             time_scale=k, duration=duration, scenarios=list(scenarios),
                                             reconnect_wait=wait, progress=False, render=False, connect_timeout=15,
                                             line="noisy"))
        finally:
            bs.kill()
            bs.wait()
    return out


def test_certify_backseat_whose_device_is_gone_for_5_s_runs_the_cut_scenario_again_and_passes(tmp_path):
    """helmcheck's own port (the relay's pty, opened by its link as a device) is unplugged 4 s
    in and plugged back 5 s later: the run waits, the scenario the gap cut runs again, and the
    good backseat passes every clause — RH-BS-8 included, which the 5 s it was not seen would
    have failed. Before this, the run ended "disconnected", INCONCLUSIVE."""
    out = _certify_backseat(tmp_path, "cut=5s@4")
    r = out.results
    assert r["run"]["status"] == "complete", out.reason
    [gap] = r["link_gaps"]
    assert 4.5 <= gap["gap_s"] < 8.0 and gap["cut"] in ("nominal", "reject"), gap
    assert not _only_the_gap(r), out.reason
    assert {c["id"]: c["verdict"] for c in r["clauses"]}["RH-BS-8"] == "pass"
    notes = [text for _, text in _notes(tmp_path / "r" / "wire.log")]
    assert notes.count(f"scenario {gap['cut']} starts") == 2  # run again from its start
    assert any(n.startswith("run resumed: helmcheck's port came back after a gap of") for n in notes)
    assert r["settings"]["reconnect_wait_s"] == 30.0
    assert cli_main(["verify", str(tmp_path / "r")]) == 0


# ============================================================================ monitor

def test_monitor_goes_on_with_one_side_while_the_other_is_gone_and_opens_it_again(tmp_path):
    """``monitor --between pty LINK`` with the emulator behind a cut of its side, 4 s in, for 5 s:
    the monitor says so, keeps recording (and judging) the backseat meanwhile, opens the vehicle
    side again when it is back, and books nothing the gap could explain; both directions flow
    again after it. Before this, the vehicle side was closed for good at the cut."""
    from helmcheck.emulator.process import EmulatorProcess
    k = 20.0
    d = tmp_path / "mon"
    with EmulatorProcess(time_scale=k, baud=19200) as emu, \
            impaired_line(emu.port, "cut=5s@4", link=tmp_path / "vehicle") as line:
        proc = subprocess.Popen([sys.executable, "-m", "helmcheck", "monitor", "--between", "pty", str(line.port),
                                 "--duration", "13", "--time-scale", f"{k:g}", "--no-tui", "--no-realtime",
                                 "--report-dir", str(d)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                cwd=ROOT, text=True, start_new_session=True)
        bs = None
        try:
            first = proc.stdout.readline()  # type: ignore[union-attr]
            assert first.startswith("backseat port: "), first
            bs = subprocess.Popen([sys.executable, str(GOOD_BACKSEAT), first.split(": ", 1)[1].strip(),
                                   "--time-scale", f"{k:g}"], stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                  stderr=subprocess.DEVNULL)
            out, err = proc.communicate(timeout=90)
        finally:
            if bs is not None:
                bs.kill()
                bs.wait()
            if proc.poll() is None:
                proc.kill()
                proc.wait()
    res = json.loads((d / "results.json").read_text())
    assert proc.returncode in (0, 2), (out, err)
    assert "the vehicle side's port" in err and "is back after" in err, err
    [gap] = res["monitor"]["link_gaps"]
    assert gap["side"] == "vehicle" and 4.5 <= gap["gap_s"] < 8.0, gap
    assert not _only_the_gap(res), res["verdict_reason"]
    with open(d / "wire.log", "rb") as f:
        recs = list(read_wire_log(f))
    during = [r for r in recs if gap["lost_at_s"] < r.t < gap["back_at_s"]]
    after = [r for r in recs if r.t > gap["back_at_s"]]
    assert any(r.dir == ">" for r in during) and not any(r.dir == "<" for r in during)  # one side, still recorded
    assert any(r.dir == ">" for r in after) and any(r.dir == "<" for r in after)  # both again
    assert {c["id"]: c["verdict"] for c in res["clauses"]}["RH-BS-1"] == "pass"
    assert cli_main(["verify", str(d)]) == 0


# ============================================================================ make matrix

@pytest.mark.skipif(not MATRIX, reason="make matrix (HELMCHECK_MATRIX=1): a whole certification behind a cut")
@pytest.mark.skipif(not SIM.is_file(), reason=f"the independent simulator is not there: {SIM}")
def test_matrix_a_vehicle_we_did_not_write_certified_whole_behind_a_5_s_cut(tmp_path):
    """``uvc_sim.py`` behind ``cut=5s@40``, every case and the exploration at ×20: a certificate,
    or INCONCLUSIVE for the gap alone."""
    from tests.test_slow_line import _sim_profile
    from tests.test_third_party_vehicle import uvc_sim
    k = 20.0
    with uvc_sim(tmp_path, k) as port, impaired_line(port, "cut=5s@40", link=tmp_path / "vehicle") as line:
        out = certify(Options(port=str(line.port), profile=_sim_profile(tmp_path).replace(time_scale=k), time_scale=k,
                              report_dir=tmp_path / "r", progress=False, render=False, seed=1, line="noisy"))
    assert not _only_the_gap(out.results), out.reason
    assert len(out.results["link_gaps"]) == 1 and out.results["link_gaps"][0]["gap_s"] is not None
    assert cli_main(["verify", str(tmp_path / "r")]) == 0


@pytest.mark.skipif(not MATRIX, reason="make matrix (HELMCHECK_MATRIX=1): a cut in the exploration, and two")
def test_matrix_cuts_in_the_exploration_and_in_a_case_are_each_run_again(tmp_path):
    """Two cuts: one in the cases, one in the exploration (30 s of budget): each is waited for,
    the case or the exploration runs again, and the run ends with no verdict the gaps do not
    explain."""
    from helmcheck.emulator.process import EmulatorProcess
    with EmulatorProcess(time_scale=K, baud=19200) as emu, \
            impaired_line(emu.port, "cut=5s@6,cut=5s@25", link=tmp_path / "vehicle") as line:
        profile = emulator_profile().replace(time_scale=K, baud=19200)
        out = certify(Options(port=str(line.port), profile=profile, time_scale=K, report_dir=tmp_path / "r",
                              select=["RH-SRV-*", "RH-ACK-2"], progress=False, render=False, seed=1,
                              explore_budget_s=30.0, line="noisy"))
    r = out.results
    assert not _only_the_gap(r), out.reason
    assert [g["gap_s"] is not None for g in r["link_gaps"]] == [True, True]
    assert any(g["cut"] == "the exploration" for g in r["link_gaps"]), r["link_gaps"]
    assert "explore" in r["stats"]
    assert cli_main(["verify", str(tmp_path / "r")]) == 0


@pytest.mark.skipif(not MATRIX, reason="make matrix (HELMCHECK_MATRIX=1): a backseat device that never comes back")
def test_matrix_certify_backseat_whose_device_never_comes_back_is_inconclusive_naming_it(tmp_path):
    out = _certify_backseat(tmp_path, "cut=20s@4", wait=2.0)
    r = out.results
    assert out.exit_code == 2 and r["run"]["status"] == "disconnected" and r["partial"] is True
    assert f"elmcheck's port {tmp_path / 'vehicle'} was gone" in r["verdict_reason"]  # H… at a sentence's start
    assert "did not come back within 2 s" in r["verdict_reason"]
    assert not [c for c in r["clauses"] if c["verdict"] == "fail"]
    assert cli_main(["verify", str(tmp_path / "r")]) == 0


@pytest.mark.skipif(not MATRIX, reason="make matrix (HELMCHECK_MATRIX=1): a monitored side that never comes back")
def test_matrix_a_monitored_side_that_never_comes_back_leaves_one_side_judged_to_the_end(tmp_path):
    from helmcheck.emulator.process import EmulatorProcess
    k = 20.0
    d = tmp_path / "mon"
    with EmulatorProcess(time_scale=k, baud=19200) as emu, \
            impaired_line(emu.port, "cut=30s@4", link=tmp_path / "vehicle") as line:
        proc = subprocess.Popen([sys.executable, "-m", "helmcheck", "monitor", "--between", "pty", str(line.port),
                                 "--duration", "12", "--time-scale", f"{k:g}", "--no-tui", "--no-realtime",
                                 "--reconnect-wait", "2", "--report-dir", str(d)], stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, cwd=ROOT, text=True, start_new_session=True)
        first = proc.stdout.readline()  # type: ignore[union-attr]
        bs = subprocess.Popen([sys.executable, str(GOOD_BACKSEAT), first.split(": ", 1)[1].strip(),
                               "--time-scale", f"{k:g}"], stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL)
        try:
            out, err = proc.communicate(timeout=90)
        finally:
            bs.kill()
            bs.wait()
    res = json.loads((d / "results.json").read_text())
    assert "did not come back within 2 s" in err, err
    [gap] = res["monitor"]["link_gaps"]
    assert gap["back_at_s"] is None and gap.get("gone_for_good")
    assert not _only_the_gap(res, GAP_WORDS + NOT_BACK_WORDS), res["verdict_reason"]
    notes = [text for _, text in _notes(d / "wire.log")]
    assert any(n.startswith("unconfirmed: seen while a side of the line was gone") and "the session's end" in n
               for n in notes)
    assert cli_main(["verify", str(d)]) == 0
