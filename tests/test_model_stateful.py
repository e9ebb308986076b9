"""Random command sequences, plant events and time jumps against the model (Hypothesis).

Invariants checked after every step:

* RH-ACK-1/RH-ACK-5: exactly one ``$ACK`` of the command's type per known command, last;
  ``$OXFLT`` and framing errors get nothing.
* RH-SAF-1/RH-SAF-2: inside the lockout every command but ``$OSD`` is refused (26) and changes
  nothing.
* RH-INT-2/RH-INT-3/RH-RD-11: whenever remote control ends without ``$OJW``/``$OMSTOP``, the mode,
  next waypoint and park time equal the mission behaviour saved when remote control *first* took
  over (so a mission park's time is saved across servo, and an ``$OPK`` park is never resumed).
* The python-statemachine chart picks the same table row as the fast dispatch.
* ``check_invariants()`` holds.
"""

from __future__ import annotations

from types import SimpleNamespace

from hypothesis import HealthCheck, settings
from hypothesis import strategies as st
from hypothesis.stateful import RuleBasedStateMachine, invariant, precondition, rule

from helmcheck.grammar import sentences as s
from helmcheck.grammar.errors import SentenceError
from helmcheck.model import testing as t
from helmcheck.model.chart import build_chart, chart_step
from helmcheck.model.plant import (AtSurface, OnStation, QueueWaypointReached, SafetyViolation,
                                   Submerged, WaypointReached)
from helmcheck.model.transitions import GUARD_ATOMS, REMOTE_MODES, select
from helmcheck.model.vehicle import _EVENT_OF_CLASS, VehicleModel

NEAR = t.BASE_LAT + 0.00001  # within on_station_m of the start position

commands = st.one_of(
    st.builds(t.oms, heading=st.sampled_from([0, 90, 359.9, 400]), timeout=st.integers(1, 25)),
    st.builds(t.omp, actuators=st.sampled_from(["8080808090", "a0b0c0d0e0", "80808080"]),
              timeout=st.integers(1, 25)),
    st.builds(t.ojw, st.integers(-1, 4)),
    st.builds(t.opk, lat=st.sampled_from([NEAR, t.BASE_LAT + 0.001, t.BASE_LAT + 0.2]),
              lon=st.just(t.BASE_LON), minutes=st.integers(0, 2)),
    st.builds(t.omw, park_s=st.sampled_from([0, 0, 8, 86401])),
    st.builds(t.omw_clear, keyword=st.sampled_from(["Clr", "clear", "STOP", "Halt"]),
              waypoint=st.none() | st.builds(t.omw, park_s=st.sampled_from([0, 5]))),
    st.builds(t.omstop, flag=st.sampled_from([0, 0, 1])),
    st.builds(t.omload, name=st.sampled_from(["conformance.mis", "missing.mis", "broken.mis", "../x.mis"])),
    st.builds(t.omstart, name=st.sampled_from(["conformance.mis", "srp.mis", "missing.mis", "C:a.mis"]),
              srp=st.sampled_from([None, "", "srp.mis", "gone.mis"]), ignore_gps=st.integers(0, 1),
              mission_type=st.integers(0, 1)),
    st.builds(t.omstart_paper, st.integers(0, 4)),
    st.builds(t.opos, lat=st.sampled_from([41.5, 95.0]), cond=st.none() | st.just(30)),
    st.lists(st.sampled_from(list("GCSPYDTI") + ["", "Q"]), max_size=5).map(lambda x: t.osd(*x)),
    st.lists(st.sampled_from(["a", "b", ""]), min_size=0, max_size=3).map(lambda x: t.ologl(*x)),
    st.lists(st.sampled_from(["1", "", "x"]), min_size=1, max_size=3).map(lambda x: t.ologd(*x)),
    st.sampled_from([t.orwset("Sop"), t.orwset("SafetyAction", "W", 1, "srp"),
                     t.orwset("SafetyAction", "W", 1, "park"), t.orwset("Bad")]),
    st.builds(t.odvl, timeout=st.integers(1, 10)),
    st.sampled_from([t.oxflt("Sle"), t.oxflt("Sop"), t.oxflt("Zzz")]),
    st.sampled_from([SentenceError("RH-SRV-2", "bad", None, "range", "OMS", "heading", 9, 20),
                     SentenceError("RH-OSD-2", "bad", None, "syntax", "OSD", "letters", 8, 27),
                     SentenceError("RH-FRM-2", "bad checksum")]),
)
plant_events = st.sampled_from([WaypointReached(), OnStation(), QueueWaypointReached(), AtSurface(),
                                Submerged(6.0), SafetyViolation("Sfp")])


def _event_name(cmd) -> str:
    e = _EVENT_OF_CLASS.get(type(cmd))
    if e is None and isinstance(cmd, s.OMWClear):
        e = "OMW_CLEAR" if cmd.waypoint is None else "OMW_CLEAR_WP"
    return e


def _fingerprint(m):
    return (m.state(), m.phase, m.mission_mode, m.mission_wp, m.loaded, m.servo, m.primitive,
            m.opk, tuple(m.queue), m.dvl, m.log_labels, len(m.log_rows), m.settings.as_dict(),
            m.timers.names(), m.snapshot)


class VehicleMachine(RuleBasedStateMachine):
    def __init__(self):
        super().__init__()
        self.m = VehicleModel(t.oxflt_profile(), t.catalog())
        self.now = 0.0
        self.saved = None  # mission behaviour at the first takeover
        self.chart = build_chart()()

    # -- bookkeeping of RH-INT-2 ---------------------------------------------------------

    def _behaviour(self):
        m = self.m
        if not m.running:
            return ("S", 0, None)
        if m.mission_mode == "P":
            return ("P", m.mission_wp, m.park_remaining(self.now) if m.mode == "P" else m.park_left)
        return ("N", m.mission_wp, None)

    def _before(self):
        return self.m.mode, self._behaviour() if self.m.mode not in REMOTE_MODES else None

    def _after(self, before, released_by_table: bool):
        old_mode, behaviour = before
        m = self.m
        if old_mode not in REMOTE_MODES and m.mode in REMOTE_MODES:
            self.saved = behaviour
        elif old_mode in REMOTE_MODES and m.mode not in REMOTE_MODES:
            if released_by_table and self.saved is not None:
                mode, wp, park = self.saved
                assert m.mode == mode, (m.mode, self.saved)
                assert m.osi_waypoint == wp
                if mode == "P":
                    got = m.park_remaining(self.now)
                    assert (got is None and park is None) or abs(got - park) < 1e-6, (got, park)
            self.saved = None
        if m.mode not in REMOTE_MODES:
            self.saved = None

    # -- rules ------------------------------------------------------------------------------

    @rule(cmd=commands)
    def command(self, cmd):
        m = self.m
        before = self._before()
        locked = m.phase == "lockout"
        fp = _fingerprint(m)
        name = _event_name(cmd) if not isinstance(cmd, SentenceError) else None
        if name is not None:
            ctx = SimpleNamespace(**{a: getattr(m, a) for a in GUARD_ATOMS})
            want = select(m.mode, m.phase, name, m)
            got = chart_step(self.chart, m.mode, m.phase, name, ctx)
            assert got.mode_row == got.safety_row == want.id
        replies = m.receive(cmd, self.now)
        acks = [r for r in replies if isinstance(r, s.ACK)]
        if isinstance(cmd, s.OXFLT) or (isinstance(cmd, SentenceError) and cmd.ack_type is None):
            assert replies == []
        else:
            t_ = cmd.ack_type if isinstance(cmd, SentenceError) else cmd.ACK_TYPE
            assert len(acks) == 1 and replies[-1] is acks[0] and acks[0].type == t_
            if t_ != 8:
                assert len(replies) == 1
            if locked and t_ != 8:
                assert acks[0].err == 26 and _fingerprint(m) == fp
            if acks[0].status == 1:
                assert _fingerprint(m) == fp
        released = name in ("OMW_CLEAR",) or isinstance(cmd, s.OXFLT)
        self._after(before, released)

    @rule(event=plant_events)
    def plant(self, event):
        before = self._before()
        self.m.plant(event, self.now)
        self._after(before, True)

    @rule(dt=st.floats(0.0, 30.0))
    def tick(self, dt):
        """Let time pass without reaching the next deadline."""
        d = self.m.next_deadline()
        target = self.now + dt
        if d is not None and target >= d:
            target = max(self.now, d - 1e-3)
        self.now = target
        self.m.advance(self.now)
        assert self.m.mode == self.m.state()[0]

    @precondition(lambda self: self.m.next_deadline() is not None)
    @rule()
    def fire_next_timer(self):
        before = self._before()
        self.now = max(self.now, self.m.next_deadline())
        self.m.advance(self.now)
        self._after(before, True)

    @invariant()
    def consistent(self):
        assert self.m.check_invariants() == []


VehicleMachine.TestCase.settings = settings(
    max_examples=60, stateful_step_count=30, deadline=None,
    suppress_health_check=[HealthCheck.too_slow])
test_RH_INT_2_RH_SAF_1_RH_ACK_1_random_sequences = VehicleMachine.TestCase
