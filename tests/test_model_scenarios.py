"""The paper's §IV–V scenarios, told as stories against the reference model."""

from __future__ import annotations

from helmcheck.grammar import sentences as s
from helmcheck.model import events as ev
from helmcheck.model.plant import AtSurface, OnStation, QueueWaypointReached, Submerged, WaypointReached
from helmcheck.model.testing import (catalog, ojw, omp, oms, omstart, omw, omw_clear, opk, orwset, osd,
                                     oxflt, oxflt_profile, started)
from helmcheck.model.vehicle import VehicleModel


def osi(m, t):
    out = m.receive(osd("S"), t)
    assert out[-1] == s.ACK(8, 0, 0)
    return out[0]


def test_RH_SRV_4_RH_INT_2_servo_interrupts_mission_park_and_resumes_it():
    """§IV.A: "the remaining time the vehicle has to park will be saved"."""
    m = started()
    m.plant(WaypointReached(0), 10.0)
    m.plant(WaypointReached(1), 40.0)  # 60 s mission park at waypoint 1 begins
    assert (osi(m, 55.0).mode, osi(m, 55.0).park_time) == ("P", 45)
    m.receive(oms(180, 3, 20, 2, 10), 55.0)  # servo takes over, 45 s of park saved
    assert osi(m, 60.0).mode == "A"
    m.receive(oms(185, 3, 20, 2, 10), 62.0)  # refreshed: timeout now 72
    assert osi(m, 71.0).park_time == 0 and m.mode == "A"
    released = m.advance(72.0)
    assert [type(e) for e in released] == [ev.ServoTimeout, ev.ControlReleased]
    o = osi(m, 72.0)
    assert (o.mode, o.next_waypoint, o.park_time) == ("P", 1, 45)  # parks for the remaining time
    m.advance(117.0)
    o = osi(m, 117.0)
    assert (o.mode, o.next_waypoint) == ("N", 2)


def test_RH_JW_2_jump_overrides_primitive_servo_and_park():
    """§IV.C: "The jump to waypoint command also overrides … Primitive, Servo and Park mode"."""
    m = started()
    for control in (omp("8080808090", 00 + 30), oms(timeout=30), opk(minutes=5)):
        m.receive(control, 1.0)
        assert m.mode in ("M", "A", "mP")
        assert m.receive(ojw(3), 2.0) == [s.ACK(7, 0, 0)]
        o = osi(m, 2.0)
        assert (o.mode, o.next_waypoint) == ("N", 3)
        assert m.next_deadline() is None
        m.receive(ojw(0), 2.0)


def test_RH_OMW_4_on_the_fly_queue_finishes_and_mission_resumes():
    """§IV.F: "Once the vehicle has completed the mission it will continue where it left off"."""
    m = started()
    m.plant(WaypointReached(0), 5.0)  # heading for waypoint 1
    m.receive(omw(lat=41.53, park_s=0), 6.0)
    m.receive(omw(lat=41.54, park_s=30), 7.0)
    assert (osi(m, 7.0).mode, osi(m, 7.0).next_waypoint) == ("W", 1)
    m.plant(QueueWaypointReached(), 20.0)
    m.plant(OnStation(), 40.0)  # at the second queued waypoint: park 30 s
    assert osi(m, 50.0).park_time == 20
    m.receive(omw(lat=41.55), 55.0)  # added while running: appended
    done = m.advance(70.0)
    assert [type(e) for e in done] == [ev.QueueParkExpired]
    assert m.mode == "W" and len(m.queue) == 1
    events = m.plant(QueueWaypointReached(), 90.0)
    assert [type(e) for e in events] == [ev.QueueDone, ev.ControlReleased]
    o = osi(m, 90.0)
    assert (o.mode, o.next_waypoint) == ("N", 1)


def test_RH_OMW_3_clear_at_any_time_resumes():
    m = started()
    m.receive(omw(), 1.0)
    m.receive(omw_clear("Clr"), 2.0)
    assert (m.mode, m.queue) == ("N", [])


def test_RH_SAF_1_RH_SAF_3_RH_SAF_4_lockout_then_primitive_then_surface_park():
    """§V: ignored for 20 s except data requests; then Primitive is released; at the surface
    the vehicle parks (SafetyAction park)."""
    m = started()
    m.plant(Submerged(12.0), 1.0)
    m.receive(oms(timeout=60), 2.0)
    m.receive(oxflt("Sed"), 3.0)
    o = osi(m, 3.0)
    assert (o.mode, o.error_state) == ("N", "Sed")
    for t in (4.0, 12.0, 22.9):
        assert m.receive(omp(), t) == [s.ACK(10, 1, 26)]
        assert m.receive(oms(), t) == [s.ACK(9, 1, 26)]
        assert isinstance(m.receive(osd("S", "C"), t)[0], s.OSI)
    assert [type(e) for e in m.advance(23.0)] == [ev.SafetyRaised, ev.LockoutEnded]
    assert m.receive(oms(), 23.5) == [s.ACK(9, 1, 26)]  # still refused until the surface
    assert m.receive(omp("8080808060", timeout=10), 24.0) == [s.ACK(10, 0, 0)]  # released
    o = osi(m, 25.0)
    assert (o.mode, o.actuators, o.error_state) == ("M", "8080808060", "Sed")
    m.advance(34.0)  # primitive times out: the ascent resumes
    assert m.mode == "N" and m.phase == "ascent"
    events = m.plant(AtSurface(), 50.0)
    assert [type(e) for e in events] == [ev.SurfaceAction] and events[0].action == "park"
    o = osi(m, 50.0)
    assert (o.mode, o.park_time, o.error_state) == ("P", 0, "Sed")  # no end time; code kept
    assert m.receive(oms(timeout=5), 51.0) == [s.ACK(9, 0, 0)]  # judged normally again
    m.advance(56.0)
    assert (m.mode, m.park_remaining()) == ("P", None)  # the endless park resumes


def test_RH_SAF_4_surface_srp_choice():
    """§V: "execute another mission called the SRP … provided to UVC at the beginning"."""
    m = VehicleModel(oxflt_profile(), catalog())
    assert m.receive(orwset("SafetyAction", "W", 1, "srp"), 0.0)[0].status == 0
    m.receive(omstart(srp="srp.mis"), 0.0)
    m.plant(Submerged(5.0), 1.0)
    m.receive(oxflt("Sle"), 2.0)
    m.advance(22.0)
    m.plant(AtSurface(), 40.0)
    o = osi(m, 40.0)
    assert (o.mode, o.next_waypoint, o.srp_active, o.mission_name) == ("N", 0, "True", "srp.mis")
    m.plant(WaypointReached(0), 50.0)
    m.plant(WaypointReached(1), 60.0)
    assert osi(m, 60.0).mode == "S" and osi(m, 60.0).srp_active == "False"


def test_RH_PK_2_RH_INT_3_park_interrupted_by_servo_is_not_resumed():
    """§IV.E: "the vehicle will exit its park location and will not return"."""
    m = started()
    m.plant(WaypointReached(0), 5.0)
    m.receive(opk(minutes=3), 6.0)
    m.plant(OnStation(), 30.0)
    assert osi(m, 90.0).park_time == 120
    m.receive(oms(timeout=5), 90.0)
    m.advance(95.0)
    o = osi(m, 95.0)
    assert (o.mode, o.next_waypoint, o.park_time) == ("N", 1, 0)
