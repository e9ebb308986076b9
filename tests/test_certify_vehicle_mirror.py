"""The certifier's oracle and motion it cannot see (RH-OUT-4, RH-INT-1, RH-RD-5)."""

from __future__ import annotations

import dataclasses

from helmcheck.conformance.vehicle.mirror import Mirror
from helmcheck.grammar import sentences as s
from helmcheck.profile import DEFAULT

D = s.Dec
K = 40.0


def _ok(t: int) -> list:
    return [s.ACK(t, 0, 0)]


def test_RH_INT_1_waypoint_reached_unseen_before_a_servo_takeover_is_accepted():
    """The vehicle reaches waypoint 0 just before the $OMS lands; an $OSD poll comes in between.

    A conforming vehicle then shows mode A with the mission frozen at waypoint 1 (RH-RD-5).
    """
    m = Mirror(DEFAULT, K)
    start = s.OMSTART(0, 0, 0, 0, DEFAULT.mission, "")
    m.receive(start, 0.10, 0.001, _ok(3))
    nominal = m.model.osi(m.v(0.12))
    assert (nominal.mode, nominal.next_waypoint) == ("N", 0)
    problems, _ = m.check_osi(nominal, 0.12, 0.002)
    assert problems == []
    oms = s.OMS(D("90"), D("2"), D("20"), D("0"), 10)
    m.receive(oms, 0.14, 0.001, _ok(9))
    poll = s.OSD(("S",))
    m.receive(poll, 0.15, 0.001, [s.OSI("8080808080", "A", 1, D(0), D(0), D(0), D(0), "N", D(0), 0, D(0)),
                                  s.ACK(8, 0, 0)])
    seen = dataclasses.replace(m.model.osi(m.v(0.15)), mode="A", next_waypoint=1)
    problems, _ = m.check_osi(seen, 0.15, 0.002)
    assert problems == [], problems
    assert m.model.mode == "A" and m.model.osi_waypoint == 1


def test_RH_OUT_4_a_waypoint_jump_nothing_explains_is_still_caught():
    m = Mirror(DEFAULT, K)
    m.receive(s.OMSTART(0, 0, 0, 0, DEFAULT.mission, ""), 0.10, 0.001, _ok(3))
    m.receive(s.OMS(D("90"), D("2"), D("20"), D("0"), 10), 0.14, 0.001, _ok(9))
    seen = dataclasses.replace(m.model.osi(m.v(0.15)), mode="A", next_waypoint=3)
    problems, _ = m.check_osi(seen, 0.15, 0.002)
    assert problems and problems[0][0] == "RH-OUT-4"
