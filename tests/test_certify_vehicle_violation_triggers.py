"""RH-SAF-1..5 without ``$OXFLT``: the lockout judged from a violation the vehicle raises itself.

A real UVC has no test extension. ``violation_trigger = "mission-rule"`` names a mission on the
vehicle whose own safety rule (Maximum Operation Time) trips a known time after its start;
``"operator"`` has the person at the terminal trip a sensor when told. The emulator supports both
the way a bench vehicle would: a mission file's ``max_time_s`` line, and SIGUSR1 as the operator
tripping the leak sensor. Each trigger is certified against a conforming emulator (RH-SAF-1..4
PASS) and against one whose lockout is 10 s instead of the declared 20 s (RH-SAF-1 FAIL). With
the operator trigger and no terminal, the lockout clauses are NOT-TESTED with that reason.
"""

from __future__ import annotations

import os
import pty
import select
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from helmcheck.emulator.process import EmulatorProcess
from helmcheck.reports.results import load_results

K = 40.0
SAF = ["RH-SAF-1", "RH-SAF-2", "RH-SAF-3", "RH-SAF-4"]
#: Deep enough that the vehicle is still under water when the 20 s lockout ends (RH-SAF-3).
TIMED_MIS = """helmcheck-mission 1
# Its Maximum Operation Time trips (Stl) 60 s after its start, 20 m down.
max_time_s 60
41.522698   -71.320000    20.0     2.0       0
41.522698   -71.317300    20.0     2.0       0
41.520000   -71.317300    20.0     2.0       0
41.520000   -71.320000    0.0      2.0       0
"""


def _profile(tmp_path: Path, trigger: str) -> Path:
    prof = tmp_path / "tester.toml"
    text = (f'baud = 115200\nviolation_trigger = "{trigger}"\nend_mission = "short.mis"\n'
            f'srp_mission = "srp.mis"\n')
    if trigger == "mission-rule":
        text += 'violation_mission = "timed.mis"\nviolation_after_s = 60.0\n'
    prof.write_text(text)
    return prof


def _emulator(tmp_path: Path, lockout_s: float) -> EmulatorProcess:
    missions = tmp_path / "missions"
    missions.mkdir(exist_ok=True)
    (missions / "timed.mis").write_text(TIMED_MIS)
    vehicle = tmp_path / "vehicle.toml"
    vehicle.write_text(f"lockout_s = {lockout_s}\n")
    return EmulatorProcess(["--missions", str(missions), "--profile", str(vehicle)], time_scale=K, baud=115200)


def _argv(port: str, prof: Path, out: Path) -> list[str]:
    return [sys.executable, "-m", "helmcheck", "certify", "vehicle", "--port", port, "--time-scale", str(K),
            "--profile", str(prof), "--select", ",".join(SAF + ["RH-SAF-5"]), "--examples", "0",
            "--no-progress", "--report-dir", str(out)]


def _verdicts(out: Path) -> dict:
    return {c["id"]: c for c in load_results(out)["clauses"]}


def _operator_run(port: str, prof: Path, out: Path, emu: EmulatorProcess) -> tuple[int, str, int]:
    """Certify with standard input and error on a pty: each time helmcheck tells the operator to
    trip a sensor, trip it (SIGUSR1 to the emulator). Returns (exit, terminal text, trips)."""
    master, slave = pty.openpty()
    proc = subprocess.Popen(_argv(port, prof, out), stdin=slave, stdout=subprocess.PIPE, stderr=slave)
    os.close(slave)
    text, trips, seen = b"", 0, 0
    try:
        deadline = time.monotonic() + 240
        while proc.poll() is None and time.monotonic() < deadline:
            r, _, _ = select.select([master], [], [], 0.2)
            if r:
                try:
                    text += os.read(master, 4096)
                except OSError:
                    break
            while (i := text.find(b"trip a safety sensor", seen)) >= 0:
                seen = i + 1
                os.kill(emu.proc.pid, signal.SIGUSR1)  # the operator trips the leak sensor
                trips += 1
        proc.wait(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        os.close(master)
    return proc.returncode, text.decode(errors="replace"), trips


@pytest.mark.parametrize("lockout_s, want", [(20.0, "pass"), (10.0, "fail")], ids=["conforming", "lockout-10s"])
def test_RH_SAF_1_to_4_mission_rule_trigger(tmp_path, lockout_s, want):
    out = tmp_path / "r"
    with _emulator(tmp_path, lockout_s) as emu:
        p = subprocess.run(_argv(emu.port, _profile(tmp_path, "mission-rule"), out), capture_output=True,
                           text=True, timeout=240, stdin=subprocess.DEVNULL)
    v = _verdicts(out)
    assert "Traceback" not in p.stderr
    # RH-SAF-5: the violation the vehicle's own rule raised passes when field 8 shows it (V-57)
    assert v["RH-SAF-5"]["verdict"] in ("pass", "fail"), v["RH-SAF-5"]
    if want == "pass":
        assert p.returncode == 0, p.stdout
        assert all(v[c]["verdict"] == "pass" for c in SAF), {c: v[c]["reason"] for c in SAF}
        assert "Stl" in v["RH-SAF-1"]["reason"]  # the mission's own rule, not $OXFLT
    else:
        assert p.returncode == 1, p.stdout
        assert v["RH-SAF-1"]["verdict"] == "fail", v["RH-SAF-1"]["reason"]


@pytest.mark.parametrize("lockout_s, want", [(20.0, "pass"), (10.0, "fail")], ids=["conforming", "lockout-10s"])
def test_RH_SAF_1_to_4_operator_trigger_through_a_terminal(tmp_path, lockout_s, want):
    out = tmp_path / "r"
    with _emulator(tmp_path, lockout_s) as emu:
        code, text, trips = _operator_run(emu.port, _profile(tmp_path, "operator"), out, emu)
    v = _verdicts(out)
    assert trips >= 1, text
    assert "Traceback" not in text
    if want == "pass":
        assert code == 0, text
        assert all(v[c]["verdict"] == "pass" for c in SAF), {c: v[c]["reason"] for c in SAF}
        assert "Sle" in v["RH-SAF-1"]["reason"]  # the leak sensor the operator tripped
    else:
        assert code == 1, text
        assert v["RH-SAF-1"]["verdict"] == "fail", v["RH-SAF-1"]["reason"]
    wire = (out / "wire.log").read_text()
    assert "operator: V-57: trip a safety sensor" in wire  # the instruction is part of the record


def test_RH_SAF_5_operator_trigger_without_a_terminal_is_not_tested(tmp_path):
    out = tmp_path / "r"
    with _emulator(tmp_path, 20.0) as emu:
        p = subprocess.run(_argv(emu.port, _profile(tmp_path, "operator"), out), capture_output=True,
                           text=True, timeout=120, stdin=subprocess.DEVNULL)
    v = _verdicts(out)
    assert p.returncode == 2, p.stdout  # nothing judged: not a pass
    for c in SAF:
        assert v[c]["verdict"] == "not-tested", (c, v[c])
        assert "terminal" in v[c]["reason"], v[c]["reason"]


#: A surface mission whose Maximum Operation Time trips 15 s after its start: while V-60's servo
#: dive is under way (the vehicle is under servo control and going down, not yet at the case's depth).
DIVING_MIS = """helmcheck-mission 1
# Its Maximum Operation Time trips (Stl) 15 s after its start, on a surface leg.
max_time_s 15
41.522698   -71.320000    0.0      2.0       0
41.522698   -71.317300    0.0      2.0       0
41.520000   -71.317300    0.0      2.0       0
41.520000   -71.320000    0.0      2.0       0
"""


def test_RH_SAF_1_to_4_a_rule_that_trips_while_the_vehicle_dives_under_servo(tmp_path):
    """The vehicle's own rule trips whatever the case is doing: 15 s after the start, while the servo
    dive that brings the vehicle under water for RH-SAF-3 (V-60) is under way. The cases take the
    violation where it comes (the approach ends there) and judge the lockout, the ascent and the
    surface from it: RH-SAF-1..4 PASS, nothing INCONCLUSIVE (×20, 115200 baud)."""
    missions = tmp_path / "missions"
    missions.mkdir()
    (missions / "timed.mis").write_text(DIVING_MIS)
    prof = tmp_path / "tester.toml"
    prof.write_text('baud = 115200\nviolation_trigger = "mission-rule"\nviolation_mission = "timed.mis"\n'
                    'violation_after_s = 15.0\nend_mission = "short.mis"\nsrp_mission = "srp.mis"\n')
    out = tmp_path / "r"
    with EmulatorProcess(["--missions", str(missions)], time_scale=20.0, baud=115200) as emu:
        argv = _argv(emu.port, prof, out)
        argv[argv.index("--time-scale") + 1] = "20"
        p = subprocess.run(argv, capture_output=True, text=True, timeout=240, stdin=subprocess.DEVNULL)
    v = _verdicts(out)
    assert {c: v[c]["verdict"] for c in SAF + ["RH-SAF-5"]} == {c: "pass" for c in SAF + ["RH-SAF-5"]}, \
        {c: v[c]["reason"] for c in SAF + ["RH-SAF-5"]}
    assert p.returncode == 0, p.stdout
