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


def _seen(m: Mirror, t: float, **fields) -> s.OSI:
    return dataclasses.replace(m.model.osi(m.v(t)), **fields)


def test_RH_MSN_4_the_end_of_a_mission_of_unknown_length_is_learnt():
    """The profile's end_mission is known only by name: S after its last waypoint is adopted as the
    end, and the stub learns its length."""
    m = Mirror(DEFAULT, K)
    assert m.stub.entry(DEFAULT.end_mission).waypoints is None
    m.receive(s.OMSTART(0, 0, 0, 0, DEFAULT.end_mission, ""), 0.10, 0.001, _ok(3))
    assert m.model.mission.is_open
    assert m.check_osi(_seen(m, 0.5, next_waypoint=1), 0.5, 0.002)[0] == []
    assert (m.model.mode, m.model.mission_wp) == ("N", 1)
    problems, _ = m.check_osi(_seen(m, 1.0, mode="S", next_waypoint=0), 1.0, 0.002)
    assert problems == [], problems
    assert m.model.mode == "S" and m.model.mission is None
    assert m.stub.entry(DEFAULT.end_mission).waypoints == 2


def test_RH_MSN_4_an_end_during_a_mission_park_is_caught():
    """A mission park still running is not an end: S there is an RH-OUT-4 finding."""
    m = Mirror(DEFAULT, K)
    m.receive(s.OMSTART(0, 0, 0, 0, DEFAULT.end_mission, ""), 0.10, 0.001, _ok(3))
    assert m.check_osi(_seen(m, 0.5, mode="P", park_time=30), 0.5, 0.002)[0] == []
    assert m.model.mode == "P" and m.stub.entry(DEFAULT.end_mission).parks == {0: 30.0}
    problems, _ = m.check_osi(_seen(m, 0.75, mode="S", next_waypoint=0, park_time=0), 0.75, 0.002)
    assert problems and problems[0][0] == "RH-OUT-4"
    assert m.stub.entry(DEFAULT.end_mission).waypoints is None


def test_RH_MSN_4_an_end_when_the_last_mission_park_runs_out_is_learnt():
    """The last waypoint has a park: S when it runs out (within RH-TIM-1) ends the mission there."""
    m = Mirror(DEFAULT, K)
    m.receive(s.OMSTART(0, 0, 0, 0, DEFAULT.end_mission, ""), 0.10, 0.001, _ok(3))
    assert m.check_osi(_seen(m, 0.5, mode="P", park_time=10), 0.5, 0.002)[0] == []
    t = 0.5 + 10.0 / K + 0.01
    m.receive(s.OSD(("S",)), t, 0.001, [_seen(m, t, mode="S", next_waypoint=0), s.ACK(8, 0, 0)])
    problems, _ = m.check_osi(_seen(m, t, mode="S", next_waypoint=0, park_time=0), t, 0.002)
    assert problems == [], problems
    assert m.stub.entry(DEFAULT.end_mission).waypoints == 1


def test_RH_SAF_4_the_srp_mission_is_known_by_name():
    """$OMSTART with the profile's srp_mission as SRP is accepted by the oracle (RH-RD-6), and with
    SafetyAction srp the surface action runs it (N, field 17 True)."""
    m = Mirror(DEFAULT.replace(fault_injection="oxflt"), K)
    m.receive(s.ORWSET("SafetyAction", "W", 1, ("srp",)), 0.05, 0.001)
    replies = m.receive(s.OMSTART(0, 0, 0, 0, DEFAULT.mission, DEFAULT.srp_mission), 0.10, 0.001, _ok(3))
    assert replies == _ok(3)
    assert m.model.srp_mission is not None and m.model.srp_mission.name == DEFAULT.srp_mission
    m.receive(s.OXFLT("Sfp"), 0.2, 0.0)
    t = 0.2 + 21.0 / K
    seen = _seen(m, t, mode="N", next_waypoint=0, error_state="Sfp", srp_active="True", depth=D("0"))
    m.receive(s.OSD(("S",)), t, 0.001, [seen, s.ACK(8, 0, 0)])
    problems, _ = m.check_osi(seen, t, 0.002)
    assert problems == [], problems
    assert m.model.srp_active and m.model.mission.name == DEFAULT.srp_mission
