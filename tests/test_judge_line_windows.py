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
from helmcheck.judge.vehicle.belief import Beliefs
from helmcheck.judge.vehicle.catalog import KnownMissions
from helmcheck.model.testing import omp, oms, omstart
from helmcheck.profile import DEFAULT, emulator_profile

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
