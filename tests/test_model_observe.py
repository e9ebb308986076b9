"""The observation API: what a conforming vehicle may report at a time (RH-OUT-4, RH-TIM-1)."""

from __future__ import annotations

import dataclasses

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from helmcheck.model.observe import expectation
from helmcheck.model.plant import OnStation, Submerged, WaypointReached
from helmcheck.model.testing import oms, omw, opk, oxflt, started
from helmcheck.model.timers import tolerance


def servo_model():
    m = started()
    m.plant(WaypointReached(), 1.0)
    m.plant(WaypointReached(), 2.0)  # park 60 s from t=2
    m.receive(oms(timeout=10), 12.0)  # 50 s saved; servo until t=22
    return m


def test_RH_TIM_1_tolerance_is_max_half_second_or_five_percent():
    assert tolerance(4) == 0.5 and tolerance(100) == 5.0 and tolerance(100, 0.2) == 5.2


def test_RH_TIM_1_near_a_timeout_both_modes_are_acceptable():
    m = servo_model()
    assert expectation(m, 17.0).modes == ("A",)
    assert expectation(m, 21.6).modes == ("A", "P")
    assert expectation(m, 22.4).modes == ("A", "P")
    assert expectation(m, 22.6).modes == ("P",)
    assert expectation(m, 22.6, slack=0.2).modes == ("A", "P")


def test_RH_TIM_1_park_time_interval_follows_the_saved_park():
    m = servo_model()
    e = expectation(m, 30.0)
    (p,) = e.states
    assert (p.mode, p.waypoint) == ("P", 1)
    assert p.park_lo <= 42 <= p.park_hi and p.park_hi - p.park_lo <= 3


def test_RH_OUT_4_check_names_each_wrong_field():
    m = servo_model()
    good = m.clone()
    good.advance(30.0)
    osi = good.osi(30.0)
    e = expectation(m, 30.0)
    assert e.check(osi) == []
    assert [c for c, _ in e.check(dataclasses.replace(osi, mode="N"))] == ["RH-OUT-4"]
    msgs = e.check(dataclasses.replace(osi, next_waypoint=3, park_time=10, error_state="Sle"))  # (P: 1 or 2 is right)
    assert len(msgs) == 3 and all(c == "RH-OUT-4" for c, _ in msgs)
    assert "park time P10" in msgs[2][1]
    # each finding says the field it is about (the judge's blame reads it, never the message)
    assert [f.field for f in msgs] == ["next_waypoint", "error_state", "park_time"]
    assert [f.field for f in e.check(dataclasses.replace(osi, mode="N"))] == ["mode"]


def test_RH_OUT_4_expectation_survives_the_model_running_ahead():
    m = servo_model()
    m.advance(23.0)  # the model already released control at 22
    assert m.mode == "P"
    assert expectation(m, 21.8).modes == ("A", "P")  # from the checkpoint before the timeout


def test_RH_OUT_4_expectation_in_lockout_and_after():
    m = started()
    m.plant(Submerged(5.0), 0.0)
    m.receive(oxflt("Sop"), 1.0)
    e = expectation(m, 10.0)
    assert [(a.mode, a.error_state) for a in e.states] == [("N", "Sop")]


@settings(max_examples=40, deadline=None)
@given(t_obs=st.floats(15.0, 130.0), slack=st.floats(0.0, 0.5))
def test_RH_OUT_4_nominal_vehicle_always_passes(t_obs, slack):
    m = servo_model()
    m.receive(opk(minutes=1), 13.0)
    m.plant(OnStation(), 15.0)
    m.receive(omw(park_s=0), 80.0) if t_obs > 80.0 else None
    nominal = m.clone()
    nominal.advance(t_obs)
    assert m.expectation(t_obs, slack).check(nominal.osi(t_obs)) == []


@pytest.mark.parametrize("delay", [-0.45, 0.45])
def test_RH_TIM_1_vehicle_off_by_less_than_tolerance_passes(delay):
    m = servo_model()
    late = m.clone()
    late.timers.set_skew(1.0 if delay > 0 else -1.0, 0.0)
    for t_obs in (21.0, 21.6, 22.0, 22.4, 40.0):
        shadow = late.clone()
        shadow.checkpoints = False
        shadow.advance(t_obs)
        assert expectation(m, t_obs).check(shadow.osi(t_obs)) == [], t_obs


@settings(max_examples=150, deadline=None)
@given(t_obs=st.floats(0.0, 120.0), slack=st.floats(0.0, 3.0), waypoint=st.integers(0, 3),
       park=st.integers(0, 90), mode=st.sampled_from(["S", "N", "P", "mP", "A", "W"]), shift=st.floats(-5.0, 5.0))
def test_RH_OUT_4_quick_check_is_the_expectations_check(t_obs, slack, waypoint, park, mode, shift):
    from helmcheck.model.observe import quick_check, quick_expectation
    m = servo_model()
    m.receive(opk(minutes=1), 13.0)
    m.plant(OnStation(), 15.0)
    nominal = m.clone()
    nominal.advance(t_obs + shift)
    right = nominal.osi(t_obs + shift)
    for osi in (right, dataclasses.replace(right, mode=mode), dataclasses.replace(right, next_waypoint=waypoint),
                dataclasses.replace(right, park_time=park)):
        assert quick_check(m, osi, t_obs, slack) == quick_expectation(m, t_obs, slack).check(osi)


def test_plant_snapshot_with_is_dataclasses_replace():
    from helmcheck.model.plant import PlantSnapshot
    snap = PlantSnapshot(lat=1.5, battery_pct=50.0)
    changes = {"lat": 2.0, "lon": -3.0, "speed_kn": 1.25, "depth_m": 4.0}
    assert snap.with_(**changes) == dataclasses.replace(snap, **changes)
    assert snap.with_() == snap and snap.with_(lat=9.0).battery_pct == 50.0
    with pytest.raises(TypeError):
        snap.with_(no_such_field=1)
