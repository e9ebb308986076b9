"""The exploration's aim (:mod:`helmcheck.certify.vehicle.aim`, :mod:`helmcheck.certify.vehicle.tour`).

What a run has not reached yet becomes targets, each a way into the state it needs and a firing
there. On the reference emulator in virtual time, behind the certifier's own link, observer and
session (no port, no wall time spent waiting): every way leads where it says; the targets listed
for a fresh run, driven one after another, reach what they say they reach; the model coverage
counts the rows time fires (a timer run out between two reports) as well as those commands meet;
every template the targets use is one the sequences' context fills; and the legs of the
vehicle's own mission are read off its reports.
"""

from __future__ import annotations

import re
from types import SimpleNamespace

from helmcheck.certify.vehicle.aim import BODIES, WAYS, MissionSurvey, edge_body, targets
from helmcheck.certify.vehicle.explore import Budget
from helmcheck.certify.vehicle.interpreter import context
from helmcheck.certify.vehicle.session import frame
from helmcheck.certify.vehicle.tour import _Driver
from helmcheck.emulator.core import EmulatorCore
from helmcheck.emulator.missionfile import DirectoryCatalog, builtin_dir
from helmcheck.model.transitions import TABLE
from helmcheck.profile import emulator_profile
from tests.virtual_vehicle import certifier_session

K = 20.0


def _session():
    profile = emulator_profile().replace(time_scale=K)
    ses = certifier_session(EmulatorCore(profile, DirectoryCatalog([builtin_dir()]), start=0.0, time_scale=K,
                                      baud=profile.baud), K)
    ses.measure_line()
    ses.cover.source = "explore"
    return ses


def _driver(ses):
    state = SimpleNamespace(coverage=ses.cover, budget=Budget(1, 1, 1e9, 1e9), vehicle_spent=0.0, batch_spent=False,
                            lines_sent=set())
    ses.reset(mission=False)
    ses.exchange(frame("OLOGL,a,b"))  # as every sequence starts (:mod:`.machine`)
    machine = SimpleNamespace(ctx=context(ses), wrote=set(), _sent=lambda body: None)
    return _Driver(ses, state, machine), state


def _aim(ses, state, **kw):
    entry = ses.obs.missions.entry(ses.profile.mission)
    park_wp = entry.park_waypoint if entry is not None else None
    return targets(ses.cover, ses.edges, ses.profile, MissionSurvey(ses.profile.mission_waypoints), park_wp=park_wp,
                   park_s=float(entry.parks.get(park_wp) or 0) if park_wp is not None else 0.0,
                   durations=ses.durations().context(), k=K, line_wall_s=0.05, left_v=1e9,
                   lines_sent=state.lines_sent, **kw)


def test_every_template_the_targets_use_is_filled_by_the_context():
    ses = _session()
    drv, state = _driver(ses)
    known = set(context(ses)) | {"wp8_lat", "wp16_lat", "park_wp"}
    texts = [s for w in WAYS.values() for s in w.steps] + list(BODIES.values())
    texts += [f for t in _aim(ses, state, limit=10_000) for f in t.fire]
    texts += [b for e in ses.edges.edges for b in (edge_body(e, ses.profile) or ("", ""))[1:] if b]
    used = {k for t in texts for k in re.findall(r"{(\w+)}", t)}
    assert used and used <= known, used - known


def test_each_way_leads_where_it_says_from_wherever_the_last_one_left_the_vehicle():
    ses = _session()
    drv, _ = _driver(ses)
    drv.poll()
    for name in WAYS:
        assert drv.way(name), (name, ses.obs.state().mode, ses.obs.state().phase)
    assert not ses.failures(), ses.failures()


def test_a_timer_run_out_counts_the_row_it_fires_and_the_timer():
    """RH-SRV-4: a servo control let run out from N is row 65 (A servo_timeout, running → N)."""
    ses = _session()
    drv, _ = _driver(ses)
    drv.way("A")
    assert ses.obs.state().mode == "A"
    drv.step("@settle:remote")
    assert ses.obs.state().mode == "N"
    assert 65 in ses.cover.rows and "remote" in ses.cover.timers
    assert {"S", "N", "A"} <= ses.cover.modes
    assert ("remote", "after") in ses.cover.bounds


def test_a_violation_counts_its_row_and_the_lockout():
    ses = _session()
    drv, _ = _driver(ses)
    drv.way("lockout")
    assert ses.obs.state().phase == "lockout"
    assert 60 in ses.cover.rows and "lockout" in ses.cover.modes
    drv.step("@lockout_end")
    assert 87 in ses.cover.rows and "lockout" in ses.cover.timers


def test_the_targets_of_a_fresh_run_reach_what_they_list():
    """Each target listed for a run that has reached nothing, driven in turn, reaches the rows,
    modes, pairs and timers it lists (most: a target the vehicle leaves before its firing does
    nothing, as the exploration's rules do)."""
    ses = _session()
    drv, state = _driver(ses)
    listed = [t for t in _aim(ses, state, limit=10_000) if any(r.startswith(("row ", "timer ")) for r in t.reaches)]
    assert len(listed) > 20
    for t in listed:
        drv.drive(t)
        assert not ses.failures(), (t, ses.failures())
    rows = {int(r.split()[1]) for t in listed for r in t.reaches if r.startswith("row ")}
    got = rows & ses.cover.rows
    assert len(got) >= 0.9 * len(rows), sorted(rows - got)
    assert len(ses.cover.rows) >= 0.75 * len(ses.cover.rows_all), sorted(ses.cover.rows_all - ses.cover.rows)
    assert TABLE  # the table the rows are of


def test_the_mission_survey_reads_the_legs_off_the_reports():
    """A leg's time is the longest distance to its waypoint reported in ``N`` at the speed reported
    (a leg not seen yet is guessed at 60 s): the cost of a target that follows the vehicle's own
    mission is the vehicle's, not a guess about it."""
    from helmcheck.grammar import decode
    from helmcheck.model.geo import KNOT_MPS
    profile = emulator_profile()
    survey = MissionSurvey(4)
    for wp, dist, mode in ((0, 30.0, "N"), (0, 25.0, "N"), (1, 100.0, "N"), (2, 999.0, "A")):
        body = (f"OSI,8080808080,{mode},{wp},41.5,-71.3,2.0,{dist:.1f},N,10.0,P0,-14.2,conformance,0.0,90.0,"
                "0.0,90.0,False,IVER,a,b,c")
        osi = decode(frame(body), profile).sentence
        assert osi is not None, body
        survey.seen(osi)
    mps = 2.0 * KNOT_MPS
    assert abs(survey.leg_v(0) - 30.0 / mps) < 1e-6 and abs(survey.leg_v(1) - 100.0 / mps) < 1e-6
    assert survey.leg_v(2) == 60.0  # seen only under remote control: not a leg of the mission
    assert abs(survey.to_v(1) - 130.0 / mps) < 1e-6


def test_RH_SAF_5_without_the_oxflt_extension_no_target_sends_it():
    """A profile whose violations are the vehicle's own (``fault_injection`` not ``oxflt``, RH-SAF-5):
    no target — a way, a firing, a tour, a lockout's error code — sends ``$OXFLT``; with the
    extension declared, some do (the lockout and the ascent are reached that way)."""
    ses = _session()
    drv, state = _driver(ses)
    with_ext = _aim(ses, state, limit=10_000)
    assert any("OXFLT" in s for t in with_ext for s in (*(WAYS[t.way].steps if t.way else ()), *t.fire))
    ses.profile = ses.profile.replace(fault_injection="none", violation_trigger="mission-rule")
    without = _aim(ses, state, limit=10_000)
    assert without and not [t for t in without
                             if any("OXFLT" in s for s in (*(WAYS[t.way].steps if t.way else ()), *t.fire))]


def test_an_aimed_batch_drives_every_band_of_its_list_however_short():
    """hypothesis counts the ``@initialize`` rule (the verified reset) as a step: an aimed batch's
    step count is one ``tour`` per band of :data:`~helmcheck.certify.vehicle.tour.TOUR_MAX` targets
    and one more — one fewer, and a list of eight or fewer targets (a long tour alone) was never
    driven at all. Checked against hypothesis's own stateful runner."""
    from hypothesis import settings
    from hypothesis.stateful import RuleBasedStateMachine, initialize, rule, run_state_machine_as_test

    from helmcheck.certify.vehicle.explore import aimed_steps
    from helmcheck.certify.vehicle.tour import TOUR_MAX

    for n in (1, TOUR_MAX, TOUR_MAX + 1, 96):
        bands = []

        class Tour(RuleBasedStateMachine):
            @initialize()
            def reset(self):
                bands.append("reset")

            @rule()
            def tour(self):
                bands.append("tour")

        run_state_machine_as_test(Tour, settings=settings(max_examples=1, stateful_step_count=aimed_steps(n),
                                                          deadline=None, database=None))
        assert bands == ["reset"] + ["tour"] * -(-n // TOUR_MAX), (n, bands)


def test_a_target_no_slice_fits_is_a_batch_of_its_own_when_the_whole_budget_fits_it():
    """The vehicle's own mission toured to its park's end can cost more than an aimed batch's slice
    (a third vehicle's 165 s park at ×20): given what is left of the whole budget, the aim returns
    the richest such target alone; without it, none costing more than the slice."""
    ses = _session()
    _drv, state = _driver(ses)
    everything = _aim(ses, state, limit=10_000)
    slice_v = 25.0
    assert any(t.cost_v > slice_v for t in everything)

    def aim(**kw):
        return targets(ses.cover, ses.edges, ses.profile, MissionSurvey(ses.profile.mission_waypoints), park_wp=None,
                       park_s=0.0, durations=ses.durations().context(), k=K, line_wall_s=0.05, left_v=slice_v,
                       lines_sent=state.lines_sent, **kw)
    short = aim()
    assert short and all(t.cost_v <= slice_v for t in short)
    long = aim(whole_v=1e9)
    assert len(long) == 1 and long[0].cost_v > slice_v
    assert len(long[0].reaches) == max(len(t.reaches) for t in everything if t.cost_v > slice_v)
