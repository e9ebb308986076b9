"""The line budget: what the line costs the observer, and the durations the tester chooses on it.

helmcheck used to choose its durations as if the line cost nothing; on the Iver3's 19200 baud,
or with a vehicle that answers late inside the ACK window (RH-ACK-2), at a simulator's time
scale the observer could not time its own timeouts (RH-TIM-1) and a case could not even see the
state it had just set (a servo timeout over before the confirming report). These tests hold:

* the budget's arithmetic (:mod:`helmcheck.judge.linebudget`): a duration it calls timeable is
  one whose bracket the observer can judge (RH-TIM-1's ``d/2``), the shortest it names is
  timeable, and the advice it gives (a time scale, a baud) really makes a duration timeable;
* the durations chosen from it (:mod:`helmcheck.certify.vehicle.durations`) stay inside the
  profile's ranges (RH-SRV-2, RH-PRM-2, RH-PK-1) and are timeable, or the case is named NOT-TESTED
  with the setting that would let it run;
* **every case of the catalogue on the reference vehicle over lines in virtual time** — time
  scales 1 to 40, replies 3 ms to 0.9 s after each line, 9600 to 115200 baud: no case ends FAIL or
  INCONCLUSIVE on the reference model itself (the tester's choices never produce a verdict
  against a conforming vehicle); a case the line cannot carry is "not run" before it starts, with
  its reason. ``make test`` runs a representative part of that grid, ``make matrix`` all of it.
"""

from __future__ import annotations

import os

import pytest
from hypothesis import given
from hypothesis import strategies as st

from helmcheck.certify.vehicle.durations import derive
from helmcheck.certify.vehicle.plan import estimate
from helmcheck.judge.linebudget import LineBudget, parse_budget, planning_latency, planning_spread
from helmcheck.model.timers import tolerance

from tests.faulty_vehicles import EMU_PROFILE

MATRIX = os.environ.get("HELMCHECK_MATRIX") == "1"

budgets = st.builds(LineBudget, k=st.sampled_from([1.0, 2.0, 5.0, 10.0, 20.0, 25.0, 40.0]),
                    baud=st.sampled_from([9600, 19200, 57600, 115200]),
                    latency_s=st.floats(0.0, 1.0), jitter_s=st.floats(0.03, 0.1),
                    osi_bytes=st.integers(120, 200), spread_s=st.floats(0.0, 1.0))


@given(budgets, st.integers(1, 300))
def test_RH_TIM_1_a_timeable_duration_is_one_the_bracket_can_judge(b, d):
    """Timeable means: the worst sampling and the observer's own uncertainty within ``d/2`` of the
    tolerance band (the bracket's rule), and the state still there when the confirming report comes."""
    if b.timeable(d):
        worst = max(0.0, b.poll_v - tolerance(d)) + b.observe_v
        assert worst <= d / 2
        assert d - tolerance(d) - b.observe_v >= b.hold_v * 0.999


@given(budgets)
def test_the_shortest_duration_named_is_timeable_and_the_advice_makes_one(b):
    d = b.shortest(1, 120)
    if d is not None:
        assert b.timeable(d) and 1 <= d <= 120
        return
    advice = b.advice(1, 120)
    if advice.startswith("--time-scale"):
        k = float(advice.split()[1])
        assert k < b.k and b.at(k=k).shortest(1, 120) is not None


@given(budgets)
def test_the_line_budget_note_reads_back(b):
    """The ``line budget:`` note (the judge's jitter, the report's line) is one line that reads back."""
    got = parse_budget(b.note())
    assert got is not None
    assert (got.baud, got.osi_bytes) == (b.baud, b.osi_bytes)
    assert got.jitter_s == pytest.approx(b.jitter_s, abs=1e-4)
    assert got.spread_s == pytest.approx(b.spread_s, abs=1e-4)


@given(st.lists(st.floats(0.0, 3.0), max_size=20))
def test_RH_ACK_2_the_planned_latency_never_exceeds_the_ack_window(samples):
    """A vehicle slower than the window fails RH-ACK-2; the tester does not plan for it."""
    assert 0.0 <= planning_latency(samples, 1.0) <= 1.0
    assert 0.0 <= planning_spread(samples, 1.0) <= 1.0
    if samples:
        assert planning_latency(samples, 1.0) >= min(1.0, max(samples))


@given(budgets)
def test_every_duration_chosen_is_in_the_profiles_range_and_timeable(b):
    """RH-SRV-2/RH-PRM-2 (``timeout_range``), RH-PK-1 (minutes 1–1440): what the tester sends is
    accepted by a conforming vehicle; and each duration whose end a case times is timeable, or the
    case is named NOT-TESTED with the reason."""
    d = derive(EMU_PROFILE, b)
    lo, hi = EMU_PROFILE.timeout_range
    for key in ("to", "to_long", "to_tim", "to_restart"):
        value = getattr(d, key)
        if value is None:
            assert d.unmet(f"timer:{key}") and "run at" in d.unmet(f"timer:{key}")
        else:
            assert lo <= value <= hi
            assert d.unmet(f"timer:{key}") is None
            if key != "to_long":
                assert b.timeable(value), (key, value)
    if d.opk_min is not None:
        assert 1 <= d.opk_min <= 1440
    ctx = d.context()
    assert lo <= int(ctx["to"]) <= hi and 1 <= int(ctx["opk_min"]) <= 1440


def test_a_slow_line_gets_longer_durations_and_names_what_would_let_a_case_run():
    """The Iver3's 19200 baud and a reply 0.6 s after each line, at x20 and x40 (issue's figures):
    the timeouts grow with the line's cost; where none the profile allows can be timed, the reason
    says which time scale or baud would do."""
    fast = derive(EMU_PROFILE, LineBudget(k=20, baud=115200, latency_s=0.01))
    slow = derive(EMU_PROFILE, LineBudget(k=20, baud=19200, latency_s=planning_latency([0.6], 1.0)))
    slower = derive(EMU_PROFILE, LineBudget(k=40, baud=19200, latency_s=planning_latency([0.6], 1.0)))
    assert fast.to < slow.to < slower.to <= 120
    why = slower.unmet("timer:to_restart")
    assert why is not None and "--time-scale" in why and "RH-TIM-1" in why


def _grid():
    """(time scale, reply latency, baud): the representative part, or with HELMCHECK_MATRIX=1 all."""
    full = [(k, lat, baud) for k in (1.0, 5.0, 20.0, 40.0) for lat in (0.003, 0.3, 0.6, 0.9)
            for baud in (9600, 19200, 115200)]
    if MATRIX:
        return full
    return [(20.0, 0.6, 19200), (40.0, 0.003, 19200), (5.0, 0.003, 19200), (20.0, 0.9, 9600)]


@pytest.mark.parametrize("k,latency,baud", _grid())
def test_the_reference_vehicle_passes_every_case_on_any_line(k, latency, baud):
    """The whole catalogue on the reference vehicle (the emulator's core) over a line in virtual
    time with this time scale, reply latency and baud (``certify vehicle --plan``'s engine): no
    case stops on a finding or an INCONCLUSIVE about the reference model — each either runs to its
    end or is not run, before it starts, for a reason the line gives (with what would let it run)."""
    profile = EMU_PROFILE.replace(baud=baud)
    plan = estimate(profile, k, examples=0, latency_s=latency)
    stopped = [(x.id, x.note) for x in plan.lines if x.outcome == "stopped"]
    assert not stopped, stopped
    for x in plan.lines:
        if x.outcome == "not-run" and "line" in x.note:
            assert "run at" in x.note, (x.id, x.note)
    assert plan.line["measured"] is True and plan.line["latency_p50_s"] == pytest.approx(latency, abs=0.01)


def _freedoms():
    """The line-timing freedoms of a conforming vehicle at their bounds (docs/freedoms.md): a 5 Hz
    control loop, every timer ending late by what the tick leaves of RH-TIM-1's 0.5 s, replies drawn
    anywhere from 0.05 to 0.6 s after each line (in arrival order) — and all of them together."""
    from helmcheck.emulator.freedoms import DEFAULT_SETTINGS
    late = DEFAULT_SETTINGS.replace(control_tick_s=0.2, timer_offset_s=0.3)
    cases = [("tick-and-late-timers", late, 0.003), ("drawn-latency", DEFAULT_SETTINGS, (0.05, 0.6)),
             ("all-together", late, (0.05, 0.6)), ("all-together-fixed-0.6", late, 0.6)]
    scales = (5.0, 20.0, 40.0) if MATRIX else (20.0,)
    return [(name, vehicle, latency, k) for name, vehicle, latency in cases for k in scales]


@pytest.mark.parametrize("name,vehicle,latency,k", _freedoms(), ids=lambda x: x if isinstance(x, str) else None)
def test_a_vehicle_at_the_bounds_of_its_timing_freedoms_passes_every_case(name, vehicle, latency, k):
    """The same on vehicles that use the room the profile leaves them (RH-ACK-2, RH-RD-15, RH-TIM-1)."""
    import random
    rng = random.Random(7)
    delay = (lambda: rng.uniform(*latency)) if isinstance(latency, tuple) else latency
    plan = estimate(EMU_PROFILE, k, examples=0, latency_s=delay, vehicle=vehicle)
    stopped = [(x.id, x.note) for x in plan.lines if x.outcome == "stopped"]
    assert not stopped, stopped


#: Faults in the server's byte output (the emulator's I/O loop), which a line in virtual time does
#: not run: they are certified on real ptys only (tests/test_certify_vehicle_mutants.py).
NOT_VIRTUAL = {"uart-7e1": "its parity bits are set by the pty server's output stage"}
#: Faults in a duration smaller than the precision a 0.6 s reply leaves at x20 (the lockout's start
#: is known only within the reply latency, a timeout's end within a round trip: ±13 and ±20 vehicle
#: seconds there): certified at x5, where the line budget's precision is finer than the fault.
PRECISION_BOUND = {"lockout-10s": 5.0, "timeouts-from-ramp-end": 5.0}


def _mutants():
    """Every faulty vehicle of the suite, on the Iver3's 19200 baud with every reply 0.6 s after its
    line, at time scale 20 (``make matrix``: also replies drawn in [0.05, 0.6] s, and time scale 5)."""
    from tests.faulty_vehicles import MUTANTS
    lines = [(20.0, 0.6)] + ([(20.0, (0.05, 0.6)), (5.0, 0.6)] if MATRIX else [])
    return [(m, min(k, PRECISION_BOUND.get(m.name, k)), lat) for m in MUTANTS for k, lat in lines
            if m.name not in NOT_VIRTUAL]


@pytest.mark.parametrize("mutant,k,latency", _mutants(),
                         ids=lambda x: getattr(x, "name", None) or (f"x{x:g}" if isinstance(x, float) else None))
def test_every_faulty_vehicle_still_fails_its_clause_on_a_slow_line(mutant, k, latency):
    """A slow line must not hide a fault: each faulty vehicle of the suite FAILs on its own clause
    when every reply comes 0.6 s after its line at 19200 baud (the cases' durations grow with the
    line; what the judge looks for does not change). Run over the line in virtual time."""
    import random

    from helmcheck.model.vehicle import VehicleModel
    rng = random.Random(3)
    delay = (lambda: rng.uniform(*latency)) if isinstance(latency, tuple) else latency
    tester = EMU_PROFILE.replace(baud=19200)

    def vehicle(profile, catalog, kk):  # the faulty core on the line's baud (tests/faulty_vehicles)
        own = profile.replace(**dict(mutant.profile_changes))
        return mutant.core(own, catalog, start=0.0, time_scale=kk, baud=profile.baud,
                           model_factory=mutant.model or VehicleModel)
    plan = estimate(tester, k, select=list(mutant.select), examples=0, latency_s=delay, vehicle=vehicle)
    assert plan.verdicts.get(mutant.clause) == "fail", {c: v for c, v in plan.verdicts.items() if v != "pass"
                                                       and c in mutant.select}


def test_RH_TIM_1_a_timing_verdict_carries_the_finest_tolerance_it_was_judged_with():
    """Issue "Find the small faults": every timing verdict says how precisely it was judged, and
    a PASS coarser than nominal says so on the verdict line, with the time scale that would not be."""
    from helmcheck.judge import Ledger
    from helmcheck.reports.scope import precision_note

    led = Ledger(["RH-SRV-4", "RH-TIM-1"])
    for widened in (6.2, 2.9, 4.0):
        led.passed("RH-SRV-4", "ended within the tolerance")
        led.precision("RH-SRV-4", 0.65, widened, 20.0)
    entry = next(e for e in led.entries() if e["id"] == "RH-SRV-4")
    assert entry["precision"] == {"nominal_s": 0.65, "widened_s": 2.9, "time_scale": 20.0}
    assert "within ±2.90 s" in entry["reason"] and "nominal tolerance ±0.65 s" in entry["reason"]
    budget = LineBudget(k=20.0, baud=19200, latency_s=0.02, measured=True)
    results = {"clauses": led.entries(), "settings": {"line_budget": budget.as_dict()}}
    note = precision_note(results)
    assert "1 timing clause(s) judged coarser" in note and "RH-SRV-4 within ±2.9 s" in note
    assert f"run at ×{budget.nominal_scale():g}" in note
    # within nominal precision: nothing to say
    led2 = Ledger(["RH-SRV-4"])
    led2.passed("RH-SRV-4", "ok")
    led2.precision("RH-SRV-4", 0.5, 0.75, 1.0)
    assert precision_note({"clauses": led2.entries()}) == ""
