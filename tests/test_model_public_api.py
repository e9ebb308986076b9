"""The model's observation and bookkeeping API used by the emulator and the observers."""

from __future__ import annotations

import pytest

from helmcheck.grammar import sentences as s
from helmcheck.model import events as ev
from helmcheck.model.missions import OPEN_LENGTH, Mission, OpenWaypoints
from helmcheck.model.observe import expectation, quick_expectation, steady_expectation
from helmcheck.model.plant import OnStation
from helmcheck.model.testing import (BASE_LAT, BASE_LON, catalog, ojw, ologd, ologl, oms, omw,
                                     omstart, omw_clear, opk, opos, osd, oxflt, oxflt_profile, started)
from helmcheck.model.vehicle import VehicleModel


def test_drain_events_returns_what_receive_left_and_runs_no_timer():
    m = started()
    assert m.receive(oms(timeout=5), 1.0) == [s.ACK(9, 0, 0)]
    m.receive(oxflt("Sle"), 2.0)
    got = m.drain_events()
    assert [type(e) for e in got] == [ev.SafetyRaised]
    assert m.drain_events() == []
    assert m.lockout_active and m.timer("lockout") is not None
    assert m.drain_events() == [] and m.lockout_active  # no timer ran


def test_log_history_is_bounded_and_rows_since_counts_every_row():
    m = VehicleModel(oxflt_profile(), catalog())
    assert m.receive(ologl("a"), 0.0) == [s.ACK(5, 0, 0)]
    assert m.receive(omstart(), 0.0) == [s.ACK(3, 0, 0)]
    n = VehicleModel.HISTORY + 10
    for i in range(n):
        assert m.receive(ologd(str(i)), 0.0) == [s.ACK(4, 0, 0)]
        m.receive(opos(), 0.0)
    assert len(m.log_rows) == VehicleModel.HISTORY == len(m.opos_records)
    assert m.log_row_count == n
    assert [r.values for r in m.log_rows_since(n - 2)] == [(str(n - 2),), (str(n - 1),)]
    assert m.log_rows_since(n) == []
    assert len(m.log_rows_since(0)) == VehicleModel.HISTORY  # the dropped rows are gone
    assert len(m.clone().log_rows) == VehicleModel.HISTORY


def test_RH_RD_5_navigation_target_is_what_field_7_measures():
    m = VehicleModel(oxflt_profile(), catalog())
    assert m.navigation_target() is None and float(m.osi().distance) == 0.0
    m = started()
    w = m.mission.waypoints[0]
    assert m.navigation_target() == (w.lat, w.lon)
    m.receive(opk(lat=BASE_LAT + 0.01), 1.0)
    assert m.navigation_target() == (pytest.approx(BASE_LAT + 0.01), pytest.approx(BASE_LON))
    m.receive(omw(lat=BASE_LAT + 0.02), 2.0)
    assert m.navigation_target()[0] == pytest.approx(BASE_LAT + 0.02)


def test_control_generation_tells_a_replacing_opk_with_the_same_fields():
    m = started()
    m.receive(opk(lat=BASE_LAT + 0.01), 1.0)
    g = m.control_generation
    m.receive(osd("S"), 1.5)
    assert m.control_generation == g
    m.receive(opk(lat=BASE_LAT + 0.01), 2.0)
    assert m.control_generation != g
    g = m.control_generation
    m.receive(omw(), 3.0)
    m.receive(omw(lat=BASE_LAT + 0.03), 3.5)  # appended to the queue
    assert m.control_generation > g + 1


def test_RH_PK_2_opk_counting_and_await_on_station():
    m = started()
    m.receive(opk(lat=BASE_LAT + 0.01, minutes=2), 1.0)
    assert not m.opk_counting and m.park_remaining() == 120
    m.plant(OnStation(), 5.0)
    assert m.opk_counting
    m.await_on_station()
    assert not m.opk_counting and m.park_remaining() == 120


def test_event_of_and_row_for_change_nothing():
    m = started()
    assert VehicleModel.event_of(oms()) == "OMS"
    assert VehicleModel.event_of(omw_clear()) == "OMW_CLEAR"
    assert VehicleModel.event_of(oxflt()) is None
    before = (m.mode, m.phase, m.timers.names())
    row = m.row_for(ojw(2))
    assert row is not None and row.error is None and "RH-JW-2" in row.clauses
    assert (m.mode, m.phase, m.timers.names()) == before
    m.receive(oxflt("Sle"), 1.0)
    assert m.row_for(oms()).error == 26


def test_timer_names_the_next_expiry():
    m = started()
    assert m.timer() is None
    m.receive(oms(timeout=5), 1.0)
    assert m.timer() == (6.0, 5.0, "remote") == m.timer("remote")
    assert m.timer("opk") is None


def test_checkpoint_and_steady_expectation():
    m = started()
    m.receive(oms(timeout=5), 1.0)
    assert m.checkpoint is None
    assert steady_expectation(m, 2.0) is not None  # nothing can expire by then
    assert steady_expectation(m, 5.8) is None  # the timeout may already have run
    assert quick_expectation(m, 2.0) == expectation(m, 2.0)
    m.advance(6.2)
    assert m.checkpoint is not None and m.checkpoint.mode == "A" and m.mode == "N"
    assert expectation(m, 6.2).modes == ("A", "N")  # within RH-TIM-1 of the timeout
    m.drop_checkpoint()
    assert m.checkpoint is None and expectation(m, 6.2).modes == ("N",)


def test_open_mission_has_unknown_length():
    o = Mission.open("any.mis")
    assert o.is_open and not Mission("a", (o.waypoints[0],)).is_open
    assert isinstance(o.waypoints, OpenWaypoints)
    assert len(o.waypoints) == OPEN_LENGTH and o.last == OPEN_LENGTH - 1
    assert o.waypoints[12345].park_s == 0
    with pytest.raises(TypeError):
        list(o.waypoints)
    with pytest.raises(ValueError):
        Mission("empty", ())
