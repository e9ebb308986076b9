"""The aimed exploration: tours of the targets :mod:`.aim` lists, driven on the vehicle.

:func:`aimed` makes the ``RuleBasedStateMachine`` of one aimed batch: it shares the random
machine's start (a verified reset, ``S``), failure handling and closing reset
(:func:`.machine.machine`'s base class), and has one rule, ``tour``: a sequence drives the
batch's list in its order (best first), a band of :data:`TOUR_MAX` at a time in an order
hypothesis draws, each target in turn — its way into the state it needs (:data:`.aim.WAYS`; none
when the vehicle is already there), then, when the vehicle is where the way leads (mode, safety
phase, mission running and parking), its firing: lines (those that leave the state as it is
written back to back), or a timer waited across its deadline (:meth:`.session.Session.settle`),
the mission followed to its next waypoint, a dive, the surface. Where the vehicle went elsewhere
the target does nothing. Every line goes through the session, so the observer judges it and the
coverage counts it, and a finding stops the tour like any sequence
(:class:`~.machine.VehicleFailure`, shrunk and re-driven as ever: the list is fixed for the batch
and the order is hypothesis's draw, so a tour replays).

:func:`_reach_park` is shared with the random machine: the test mission to its park.
"""

from __future__ import annotations

from typing import Optional

from hypothesis import strategies as st
from hypothesis.stateful import rule

from ...judge.vehicle.closure import osi_depth_m
from ...model.geo import KNOT_MPS
from .aim import INTO_PARK_V, WAYS, Target
from .interpreter import _here, fill, raw_line
from .safety import BenchSafetyRefused
from .session import frame

__all__ = ["aimed", "PARK_WITHIN_V", "TOUR_MAX", "FOLLOW_WITHIN_V"]

#: The longest a sequence waits for the mission to reach its park (vehicle seconds).
PARK_WITHIN_V = 120.0
#: The longest a target follows the mission to its next waypoint, or an ascent to the surface.
FOLLOW_WITHIN_V = 150.0
#: The longest an aimed target follows the mission to its park, or waits a timer out (vehicle
#: seconds; less when less is left of the budget).
PARK_MAX_V = 600.0
#: Targets in one tour, at most.
TOUR_MAX = 8
#: The depth a dive for an ascent goes to (at most: half the depth range), and when it counts as under.
DIVE_M = 3.0
UNDER_M = 1.5


def _reach_park(session, ctx: dict, within_v: float = PARK_WITHIN_V) -> None:
    """From ``N``: jump to the test mission's park waypoint (once it is known) and poll until ``P``,
    when the vehicle can get there within ``within_v`` vehicle seconds at the speed it reports (at
    least half a knot); else, or when it is not there by then, it is left where it is (the observer
    judges every report on the way; no tester note: the exploration needs no state)."""
    entry = session.obs.missions.entry(session.profile.mission)
    wp = entry.park_waypoint if entry is not None else None
    if wp is not None and session.obs.state().mission_wp != wp:
        session.exchange(frame(f"OJW,{wp + session.profile.waypoint_base}"))
    osi = session.poll()
    mps = max(0.5, float(osi.speed or 0)) * KNOT_MPS
    if osi.mode != "N" or float(osi.distance or 0) / mps > within_v:
        _here(session, ctx)
        return
    end = session.now() + within_v / session.k
    while session.now() < end:
        if session.poll().mode != "N":
            break
        session.link.sleep(max(session.poll_gap, 0.05))
    _here(session, ctx)


def _park_wp(session) -> Optional[int]:
    entry = session.obs.missions.entry(session.profile.mission)
    return entry.park_waypoint if entry is not None else None


#: Ways whose state is arranged beyond its mode (the next waypoint, a transit, a start ignoring
#: GPS, a dive): driven even when the vehicle is already in that mode.
_ARRANGED = frozenset({"N-last", "N-park", "N-gps", "N-under", "mP", "mP@P"})


class _Driver:
    """Drives one target's way and firing on the session (module docstring)."""

    def __init__(self, session, state, machine):
        self.session = session
        self.state = state
        self.m = machine  #: the machine instance (its ctx, what it wrote)

    @property
    def model(self):
        return self.session.obs.state()

    def _ctx(self) -> dict:
        """The sequence's templates, with the aim's own: queued waypoints 8 and 16 m north (a leg
        a report sees, short at bench speed) and the park waypoint learnt (``park_wp``)."""
        ctx = self.m.ctx
        for m in (8, 16):
            ctx[f"wp{m}_lat"] = f"{float(ctx['lat']) + m / 111320.0:.6f}"
        park = _park_wp(self.session)
        ctx["park_wp"] = str((park if park is not None else 0) + self.session.profile.waypoint_base)
        return ctx

    def send(self, body: str):
        self.m._sent(body)
        return self.session.exchange(frame(fill(body, self._ctx())))

    def poll(self):
        osi = self.session.poll()
        _here(self.session, self.m.ctx)
        return osi

    # ------------------------------------------------------------------ ways
    def way(self, name: str) -> bool:
        """Into the state of way ``name``; whether the vehicle is there (mode and phase)."""
        if not name:
            return True
        w = WAYS[name]
        if name not in _ARRANGED and self._there(w):  # already where the way leads (a target before left it)
            return True
        self.step("@calm")
        for step in w.steps:
            self.step(step)
        return self._there(w)

    def _there(self, w) -> bool:
        m = self.model
        return (m.mode == w.mode and m.phase == w.phase and (m.mission is not None) == ("running" in w.atoms)
                and m.mission_parking == ("mission_parking" in w.atoms)
                and all(bool(getattr(m, a)) for a in ("head_parks", "queue_more") if a in w.atoms))

    def step(self, step: str) -> None:
        ses, m = self.session, self.model
        if step == "@calm":  # a lockout set going before is waited out: no way leads through it
            if m.phase == "lockout":
                self.step("@lockout_end")
        elif step == "@stop":
            if m.mode != "S" or m.phase == "ascent":
                self.send("OMSTOP,0")
                self.poll()
        elif step == "@mission":
            if not (m.mode == "N" and m.mission is not None and m.phase == "none"):
                if m.mode != "S":
                    self.send("OMSTOP,0")
                self.send("OMSTART,0,0,0,0,{mission},")
                self.poll()
        elif step == "@park":
            if m.mode == "N":  # as far as the budget left allows: the mission's own legs (module docstring)
                if _park_wp(ses) is None and m.mission_wp > 0:  # past where a park may be: from the start
                    self.send("OMSTOP,0")
                    self.send("OMSTART,0,0,0,0,{mission},")
                    self.poll()
                _reach_park(ses, self.m.ctx, min(PARK_MAX_V, self.left_v()))
        elif step == "@to_park":
            if _park_wp(ses) is not None and m.mode == "N":
                self.send("OJW,{park_wp}")
        elif step == "@dive":
            if m.mode in ("N", "P", "A") and m.phase == "none":
                depth = min(DIVE_M, ses.profile.max_depth / 2)
                self.send(f"OMS,90,{depth:g},20,{{speed}},{{to_long}}")
                self._until(lambda osi: (osi_depth_m(osi, ses.profile.depth_unit) or 0) >= UNDER_M, 30.0)
        elif step == "@lockout_end":
            if m.timer("lockout") is not None:
                probe = self._probe()
                ses.settle("lockout", probe)
                self.state.coverage.boundary("lockout", "after")
                _here(ses, self.m.ctx)
        elif step.startswith("@settle:"):
            name = step.split(":", 1)[1]
            if name in ("opk", "qpark") and m.timer(name) is None and m.mode in ("mP", "W"):
                # a park's countdown starts on station (RH-PK-2, RH-OMW-4): get there first
                mode = m.mode
                self._until(lambda osi: self.model.timer(name) is not None or self.model.mode != mode,
                            FOLLOW_WITHIN_V)
            m = self.model
            got = m.timer(name)
            if got is not None and (got[0] / ses.k - ses.now()) * ses.k <= min(self.left_v(), PARK_MAX_V):
                ses.settle(name)
                self.state.coverage.boundary(name, "after")
                _here(ses, self.m.ctx)
        elif step == "@roundtrip":  # a setting written, read back, written back (RH-SET-2)
            if m.mode == "S" and "ORWSET" in ses.profile.commands:
                from .interpreter import run_step
                from .steps import SetRoundTrip
                self.m.wrote.add("Sle")
                run_step(ses, SetRoundTrip("Sle"), self.m.ctx)
        elif step == "@into_park":
            got = m.timer("park") if m.mode == "P" else None
            if got is not None:  # a share of it gone, what is left told from the whole (RH-INT-2)
                ses.wait(min(INTO_PARK_V, got[1] / 3))
        elif step == "@follow":
            if m.mode in ("N", "W"):
                wp, mode = m.mission_wp, m.mode
                self._until(lambda osi: osi.mode != mode or self.model.mission_wp != wp
                            or len(self.model.queue) == 0 and mode == "W", FOLLOW_WITHIN_V)
        elif step == "@surface":
            if m.phase == "ascent":
                self._until(lambda osi: self.model.phase != "ascent", FOLLOW_WITHIN_V)
        elif step == "@dvl":
            if "ODVL" in ses.profile.commands:
                self.send("ODVL,0.5,0,{to}")
                got = self.model.timer("dvl")
                if got is not None:
                    ses.wait(max(0.0, (got[0] / ses.k - ses.now()) * ses.k) + 2.0)
        elif step.startswith("OXFLT,"):
            # with a request behind it: its answer bounds when the violation came (RH-SAF-1)
            ses.burst([frame(step), frame("OSD,S")])
            _here(ses, self.m.ctx)
        elif step.startswith("burst:"):
            bodies = step[len("burst:"):].split("\x1f")
            for b in bodies:
                self.m._sent(b)
            raws = [frame(fill(b, self._ctx())) for b in bodies]
            held = [r for r in raws if ses.link.guard.problem(r)]
            for r in held:  # kept back alone (bench safety), not with the lines written beside it
                try:
                    ses.send(r)
                except BenchSafetyRefused:
                    pass
            if len(held) < len(raws):
                ses.burst([r for r in raws if r not in held])
        elif step.startswith("raw:"):
            _, kind, body = step.split(":", 2)
            self.state.lines_sent.add(kind)
            sent = ses.exchange(raw_line(kind, fill(body, self._ctx()), ses.profile))
            if sent is None or not any(type(r).__name__ == "ACK" for r in sent.expected):
                # a line the vehicle must discard: its answer, if it gives one, comes before the next
                # line goes, so that it is this line's (a sequence's lines go without sitting out
                # the ACK window, :attr:`.session.Session.lazy_silence`)
                b = ses.meter.budget()
                ses.link.sleep(b.latency_s + b.tx(b.osi_bytes + 40) + b.jitter_s)
                ses.check()
        else:
            self.send(step)

    def left_v(self) -> float:
        """Vehicle seconds left of the exploration's budget."""
        return max(0.0, self.state.budget.vehicle_s - self.state.vehicle_spent)

    def _probe(self) -> Optional[bytes]:
        claimed = self.session.profile.commands
        return next((frame(b) for b in ("ORWSET,Sle,R", "OLOGL,probe") if b.split(",", 1)[0] in claimed), None)

    def _until(self, done, within_v: float) -> None:
        ses = self.session
        end = ses.now() + within_v / ses.k
        while ses.now() < end and not self.state.batch_spent:
            if done(self.poll()):
                break
            ses.link.sleep(max(ses.poll_gap, 0.05))

    # ------------------------------------------------------------------ a target
    def drive(self, t: Target) -> None:
        ok = self.way(t.way)
        if not ok:
            return  # the vehicle is elsewhere: the target does nothing
        for what in t.reaches:  # a probe of no dimension: driven once a run (.aim)
            if what.startswith("probe "):
                self.state.lines_sent.add(what)
        fire = list(t.fire)
        if t.keeps:  # refusals and requests, which leave the state as it is: written back to back
            bodies = [f for f in fire if f[:1] == "O" and not f.startswith("OXFLT")]
            if len(bodies) > 1:
                self.step("burst:" + "\x1f".join(bodies))
                fire = [f for f in fire if f not in bodies]
        for step in fire:
            self.step(step)
        if not t.keeps:  # a report after what may have changed the state (a refusal changed nothing)
            self.session.poll()
        _here(self.session, self.m.ctx)


def aimed(base, state, p, aim: list):
    """The machine of one aimed batch (module docstring): ``base`` is :func:`.machine.machine`'s
    base class, ``aim`` the batch's targets, best first."""
    session = state.run.session

    class AimedMachine(base):
        def __init__(self):
            super().__init__()
            self.order: Optional[list] = None  #: the targets in the order this sequence drives them
            self.next = 0

        @rule(rnd=st.randoms(use_true_random=False))
        def tour(self, rnd):
            """The next :data:`TOUR_MAX` targets of this sequence's order, each driven in turn: the
            list in bands of :data:`TOUR_MAX`, best first, shuffled within each band by hypothesis
            (its draw, so a failing sequence replays)."""
            if self.order is None:
                bands = [list(range(i, min(i + TOUR_MAX, len(aim)))) for i in range(0, len(aim), TOUR_MAX)]
                for b in bands:
                    rnd.shuffle(b)
                self.order = [i for b in bands for i in b]
            todo, self.next = self.order[self.next:self.next + TOUR_MAX], self.next + TOUR_MAX

            def go():
                drv = _Driver(session, state, self)
                for i in todo:
                    if state.batch_spent:
                        break
                    t = aim[i]
                    self.wrote.update(t.writes)
                    drv.drive(t)
                    session.check()
            self._guard(go)

    return AimedMachine
