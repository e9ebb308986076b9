"""Two wrong verdicts a slow or fast-scaled line once caused, each with the evidence that found it.

* RH-RD-15 / RH-TIM-1: only an *accepted* command that may set a timer going widens the window
  in which the timers it set started. A refused one (or an ``$OSD``) arms nothing, so the time its
  answer took on the line must not make every later timer untimable (it did: a refused ``$OMP``
  behind a burst of replies made the servo timeout INCONCLUSIVE on a conforming vehicle).
* RH-SAF-4 / RH-RD-11: a violation leaves the vehicle's depth for a report to show. The last
  report before it may be from before the dive began (here: a mission started at the surface,
  the ``$OXFLT`` sent 3 vehicle seconds later at ×40, no report during the lockout); the vehicle
  holds the depth it had reached, and after the lockout it ascends before the at-surface action.
  The recorded log is an excerpt of a real ``certify vehicle`` run of the reference emulator over
  a pty at ×40 (case V-59); the judge used to assume the surface from the report before the
  violation and FAILed RH-SAF-4 and RH-OUT-4 (the excerpt ends before the vehicle is back at the
  surface, so RH-SAF-4 is rightly not tested in it).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from helmcheck.checklog.checker import check_log
from helmcheck.grammar import sentences as s
from helmcheck.grammar.checksum import checksum
from helmcheck.judge.vehicle.belief import Beliefs
from helmcheck.judge.vehicle.catalog import KnownMissions
from helmcheck.model.testing import omp, oms, omstart
from helmcheck.profile import DEFAULT, emulator_profile, load_profile

LOG = Path(__file__).parent / "fixtures" / "logs" / "violation_while_diving_x40.log"


@pytest.mark.parametrize("status", [0, 1])
def test_rh_rd_15_only_an_accepted_arming_command_widens_its_timers(status):
    b = Beliefs(DEFAULT, KnownMissions(DEFAULT), 1.0)
    b.command(omstart(), 1.0, 0.01, [s.ACK(3, 0, 0)])
    base = b.arm_v
    answer = [s.ACK(10, 0, 0)] if status == 0 else [s.ACK(10, 1, 21)]
    b.command(omp(timeout=200), 2.0, 0.6, answer)  # 0.6 vehicle s of the answer's line time
    if status == 0:
        assert b.arm_v >= 0.6, b.arm_v
    else:
        assert b.arm_v == base, b.arm_v  # a refusal sets nothing going


def test_rh_rd_15_an_accepted_servo_command_widens_by_its_own_line_time():
    b = Beliefs(DEFAULT, KnownMissions(DEFAULT), 1.0)
    b.command(omstart(), 1.0, 0.01, [s.ACK(3, 0, 0)])
    b.command(oms(timeout=10), 2.0, 0.4, [s.ACK(9, 0, 0)])
    assert 0.4 <= b.arm_v < 0.6, b.arm_v


def test_rh_saf_4_a_violation_while_diving_leaves_the_depth_to_the_reports():
    out = check_log(LOG, profile=emulator_profile(), role="vehicle")
    verdicts = {c["id"]: c["verdict"] for c in out.clauses}
    assert verdicts["RH-OUT-4"] == "pass" and verdicts["RH-SAF-2"] == "pass", verdicts
    bad = {c["id"]: c["reason"] for c in out.clauses if c["verdict"] in ("fail", "inconclusive")}
    assert not bad, bad


SURFACE_LOG = Path(__file__).parent / "fixtures" / "logs" / "surface_while_omp_holds_x40.log"


def _deeper(text: str, after: float, depth: str) -> str:
    """The record with every ``$OSI`` after ``after`` s reporting ``depth`` (field 15), checksums
    made again: the same vehicle, under water."""
    out = []
    for ln in text.splitlines(keepends=True):
        parts = ln.split(" ", 2)
        if len(parts) == 3 and parts[1] == "<" and parts[2].startswith("$OSI,") and float(parts[0]) > after:
            body = parts[2][1:parts[2].index("*")].split(",")
            body[15] = depth
            body = ",".join(body)
            ln = f"{parts[0]} < ${body}*{checksum(body.encode()):02X}\n"
        out.append(ln)
    return "".join(out)


def test_rh_saf_3_a_vehicle_at_the_surface_while_omp_holds_depth_may_end_the_refusals(tmp_path):
    """A recorded x40 exploration (the emulator): a violation while the stopped vehicle floats up
    at 0.27 m, ``$OMP`` accepted after the lockout, the next report at 0.21 m (the surface: 0.25 m),
    then ``$OPK`` refused with its own err 22, not 26. RH-SAF-3 ends the refusals "until the
    vehicle is at the surface"; the model defers that while ``$OMP`` holds depth (RH-RD-12 is
    silent): both are conforming. Before: FAIL RH-SAF-3. The same record with the vehicle 5 m
    down in those reports: not a pass."""
    profile = load_profile(str(Path(__file__).parent.parent / "examples" / "emulator.toml"))
    out = check_log(SURFACE_LOG, profile=profile, role="vehicle", time_scale=40.0)
    verdicts = {c["id"]: (c["verdict"], c["reason"]) for c in out.clauses}
    assert verdicts["RH-SAF-3"][0] == "pass", verdicts["RH-SAF-3"]
    assert not {c: v for c, v in verdicts.items() if v[0] == "fail"}
    deep = tmp_path / "deep.log"
    deep.write_text(_deeper(SURFACE_LOG.read_text(), 103.26, "5.21"))
    out = check_log(deep, profile=profile, role="vehicle", time_scale=40.0)
    assert {c["id"]: c["verdict"] for c in out.clauses}["RH-SAF-3"] != "pass"


LOST_LOG = Path(__file__).parent / "fixtures" / "logs" / "lost_command_clock_check_x40.log"


def test_rh_ack_2_an_ack_that_may_answer_a_later_command_is_not_late_for_a_lost_one():
    """A recorded x40 certification of the independent simulator behind a faulty line (bytes
    dropped, noise, stalls): the clock check sends ``$OSD,G`` without waiting; the line lost one,
    and the next one's ``$ACK`` came 0.05 s after it was sent — 1.55 s after the lost one. Taken
    for the lost one's, it was late (RH-ACK-2), and with a stall's late ``$ACK`` after it, a run of
    late answers: FAIL. It may answer the later command: held, and made again clean, the line's."""
    out = check_log(LOST_LOG, role="vehicle")
    verdicts = {c["id"]: (c["verdict"], c["reason"]) for c in out.clauses}
    assert verdicts["RH-ACK-2"][0] == "pass", verdicts["RH-ACK-2"]
    assert "may have lost $OSD,G*33" in verdicts["RH-ACK-2"][1]
