"""One state a conforming vehicle may be in: a reference model plus what the observer adopted.

A :class:`Candidate` wraps a :class:`~helmcheck.model.vehicle.VehicleModel` (with its row
``trace`` on, and ``$OSD`` data answered by class name: the judge compares which sentences come,
never their values) and keeps, besides the model, what judging needs and the model does not:

* ``events`` / ``story`` — the unseen plant events adopted to explain the wire (fewer is more
  plausible) and what they were;
* ``extra_v`` — vehicle seconds of uncertainty an adopted event's time window adds to every
  timer it started (RH-TIM-1: the observer widens by what it cannot see); it lapses when no timer
  started inside the window is left — nor one that did and was frozen and resumed since (a mission
  park frozen by remote control resumes with what was left of it, which the window's uncertainty
  still has: ``carried``, RH-INT-2, RH-RD-5);
* ``pending`` — table rows applied since the last confirming ``$OSI``: their clauses pass when an
  ``$OSI`` confirms the state they led to (rows that change nothing visible pass at their ACK);
* ``timed`` — timer-driven transitions awaiting their RH-TIM-1 bracket (:class:`Timed`);
* ``abandoned`` — an ``$OPK`` park or an ``$OMW`` queue interrupted by another control: the next
  confirmed release shows whether it was really abandoned (RH-INT-3, RH-OMW-5);
* ``s_cause`` — the clause whose transition put the vehicle in ``S`` (``$OMSTOP``: RH-MSN-3,
  a primitive timeout from ``S``: RH-PRM-4), for the neutral fins-and-motor check;
* ``refresh`` — the rows that updated the present remote control (RH-RD-3: set-points replaced,
  the timeout or countdown restarted, a waypoint appended) since it began: a report that shows
  the control ended early blames them too (RH-SRV-3);
* ``refused_locked`` — a command was refused during the lockout; the first ``$OSI`` confirmed
  after the lockout shows it had no effect (RH-SAF-2);
* ``seen_v`` / ``seen_mode`` / ``seen_at`` / ``locked_v`` — the latest observations that tell a
  timer's before-state: the ``$OSI`` mode (the latest report, and the latest of each mode: a
  report of the after-state a little before the model's own deadline, within the tolerance,
  leaves the last report of the before-state as the bracket's start), and the last err 26 to a
  command only the lockout refuses;
* ``nav_seen`` / ``fix_seen`` — the latest report of the running mission's distance to its next
  waypoint (``$OSI`` field 7 in ``N`` or ``P`` at that waypoint: mission name, waypoint, metres,
  vehicle time, position, speed) and the latest reported position (earliest and latest vehicle
  time, lat, lon, speed), both set by the report checks (:mod:`.osichecks`): what makes an unseen waypoint
  reached physically possible or not (:mod:`.closure`).
"""

from __future__ import annotations

import math

from dataclasses import dataclass
from typing import Optional

from ...model.observe import Finding, quick_check
from ...model.transitions import STAY, Row
from ...model.vehicle import VehicleModel

__all__ = ["Candidate", "Timed", "sig"]

#: Clauses of a timer's row whose RH-TIM-1 duration the bracket judges.
TIMED_CLAUSES = frozenset({"RH-SRV-4", "RH-PRM-4", "RH-PK-3", "RH-SAF-1", "RH-OMW-4"})
#: What a mission-park expiry's timing speaks to (its row names only the reading RH-RD-5).
_PARK_CLAUSE = "RH-OUT-4"


@dataclass
class Timed:
    """A timer-driven transition (RH-TIM-1): the vehicle must leave ``pre_mode`` (or the
    lockout) at ``deadline`` ± tolerance; ``t_old`` is the latest observation of the
    before-state (vehicle seconds), ``None`` when the observer never saw it near the deadline."""

    timer: str
    row: Row
    deadline: float
    duration: float
    pre_mode: str
    t_old: Optional[float]
    extra_v: float = 0.0
    widened: Optional[float] = None  #: the precision it was judged with (:func:`~.brackets.bracket`)

    @property
    def clauses(self) -> tuple[str, ...]:
        if self.timer == "park":
            return (_PARK_CLAUSE,)
        return tuple(c for c in self.row.clauses if c in TIMED_CLAUSES)


def _started_in(t, name: str, lo: float, hi: float) -> bool:
    d, dur = t.deadline(name), t.duration(name)
    return d is not None and dur is not None and lo - 1e-6 <= d - dur <= hi + 1e-6


def sig(m: VehicleModel) -> tuple:
    """What an ``$OSI`` shows of the judged state: mode, field 3, error state, SRP flag."""
    return (m.mode, m.osi_waypoint, m.error_state, m.srp_active)


class Candidate:
    """See the module docstring."""

    __slots__ = ("model", "events", "story", "extra_v", "window", "pending", "timed", "abandoned",
                 "s_cause", "refused_locked", "seen_v", "seen_mode", "seen_at", "locked_v", "code_unknown",
                 "refresh", "nav_seen", "fix_seen", "_mode", "_phase", "carried")

    def __init__(self, model: VehicleModel):
        if model.trace is None:
            model.trace = []
        model.data_names = True  # the judge compares which data sentences come, not their values
        self.model = model
        self.events = 0
        self.story: tuple[str, ...] = ()
        self.extra_v = 0.0
        self.window: Optional[tuple[float, float]] = None
        #: timers started inside ``window`` (their remaining time carries its uncertainty when
        #: frozen and resumed)
        self.carried: frozenset = frozenset()
        self.pending: list[Row] = []
        self.timed: list[Timed] = []
        self.abandoned: set[str] = set()
        self.s_cause = ""
        self.refresh: tuple[Row, ...] = ()
        self.refused_locked = False
        self.seen_v: Optional[float] = None
        self.seen_mode = ""
        self.seen_at: dict[str, float] = {}
        self.locked_v: Optional[float] = None
        self.code_unknown = False
        self.nav_seen: Optional[tuple] = None
        self.fix_seen: Optional[tuple] = None
        self._mode = model.mode
        self._phase = model.phase

    def clone(self) -> "Candidate":
        c = Candidate.__new__(Candidate)
        c.model = self.model.clone()
        c.model.trace = list(self.model.trace or [])
        # the state before a timer that fired since the last input stays what may be expected
        # (RH-TIM-1's slow shadow): a copy answering a command is the same vehicle, not a new one
        c.model._base = self.model.checkpoint
        c.events, c.story, c.extra_v, c.window = self.events, self.story, self.extra_v, self.window
        c.carried = self.carried
        c.pending = list(self.pending)
        c.timed = [Timed(**vars(t)) for t in self.timed] if self.timed else []
        c.abandoned = set(self.abandoned)
        c.s_cause, c.refused_locked, c.refresh = self.s_cause, self.refused_locked, self.refresh
        c.seen_v, c.seen_mode, c.locked_v = self.seen_v, self.seen_mode, self.locked_v
        c.seen_at = dict(self.seen_at)
        c.code_unknown = self.code_unknown
        c.nav_seen, c.fix_seen = self.nav_seen, self.fix_seen
        c._mode, c._phase = self._mode, self._phase
        return c

    def adopted(self, what: str, lo: float, hi: float, n: int = 1) -> "Candidate":
        """Book ``n`` unseen events that happened in ``[lo, hi]`` (vehicle seconds)."""
        self.events += n
        self.story = self.story + (what,)
        width = max(0.0, hi - lo)
        self.extra_v = max(self.extra_v, width)
        self.window = (lo, hi)
        t = self.model.timers
        # an earlier window's timers keep their uncertainty (a later event does not settle them)
        self.carried = self.carried | frozenset(name for name in t.names() if _started_in(t, name, lo, hi))
        return self

    # ------------------------------------------------------------------ the trace
    def drain(self) -> list:
        """Fold the rows the model applied since the last call into the bookkeeping; returns
        the timer-fired steps (for the caller's own use)."""
        trace = self.model.trace
        if not trace:
            return []
        steps, self.model.trace = list(trace), []
        fired = []
        if any(st.row.event == "violation" for st in steps):
            self._depth_unknown(self._mode)
        for st in steps:
            row = st.row
            before_mode, before_phase = self._mode, self._phase
            if row.error is None:
                if row.target != STAY:
                    self._mode = row.target
                if row.phase_to is not None:
                    self._phase = row.phase_to
            if st.timer:
                fired.append(st)
                t_old = None
                start = st.at - st.duration
                if st.timer == "lockout":
                    if self.locked_v is not None and self.locked_v >= start:
                        t_old = self.locked_v
                elif self.seen_at.get(before_mode, -math.inf) >= start:
                    t_old = self.seen_at[before_mode]
                self.timed.append(Timed(st.timer, row, st.at, st.duration, before_mode, t_old, self.extra_v))
            self._book(row, before_mode, before_phase)
        return fired

    def _depth_unknown(self, before: str) -> None:
        """A violation came: the depth the mirror has is the last report's, from before it, and a
        vehicle that was heading down (a remote control, or a mission whose next waypoint is under
        water) may have gone down since. During the lockout it holds that unseen depth (RH-RD-11), so
        whether it is at the surface when the lockout ends (RH-SAF-4 at once, or the ascent first) is
        then for a report to show: the surface is adopted (:mod:`.closure`), never assumed from a
        depth read before the violation. A vehicle stopped, or on a surface leg, stays where it was."""
        m = self.model
        fix = m.profile.gps_fix_depth_m
        if m.phase != "lockout" or m.snapshot.depth_m > fix:
            return
        diving = before in ("A", "M", "W", "mP")
        if before in ("N", "P") and m.mission is not None:
            # without the vehicle's mission files (a catalogue that learns, :mod:`.catalog`) the
            # waypoint's depth is not known: it may be diving too
            diving = (getattr(m.missions, "learns", True) or m.mission.is_open
                      or not 0 <= m.mission_wp < len(m.mission.waypoints)
                      or m.mission.waypoints[m.mission_wp].depth > fix)
        if diving:
            m.update_plant(m.snapshot.with_(depth_m=fix + 1e-3))

    def _book(self, row: Row, before_mode: str, before_phase: str) -> None:
        if row.error is not None:
            return
        if row.target != STAY or row.phase_to is not None:
            self.pending.append(row)  # a row that changes nothing visible passes at its ACK
        if "RH-RD-3" in row.clauses:
            if row not in self.refresh:
                self.refresh += (row,)
        elif row.target not in (STAY, before_mode) or row.phase_to is not None:
            self.refresh = ()
        ev = row.event
        if ev in ("OMSTOP", "OMSTART", "OJW", "violation"):
            self.abandoned.clear()
        elif before_mode == "mP" and row.target not in (STAY, "mP") and ev != "opk_expired":
            self.abandoned.add("opk")
        elif before_mode == "W" and row.target not in (STAY, "W") and ev not in (
                "queue_wp_reached", "queue_park_expired", "OMW_CLEAR"):
            self.abandoned.add("queue")
        if row.target == "S" and before_mode != "S":
            self.s_cause = "RH-MSN-3" if ev == "OMSTOP" else ("RH-PRM-4" if ev == "primitive_timeout" else "")
        elif row.target not in (STAY, "S"):
            self.s_cause = ""

    # ------------------------------------------------------------------ questions
    def check(self, osi, v: float, slack_v: float) -> list[Finding]:
        """``[]`` when this candidate explains ``osi`` at ``v`` (RH-OUT-4, RH-TIM-1)."""
        return quick_check(self.model, osi, v, slack_v + self.extra_v)

    def saw(self, v: float, mode: str) -> None:
        """A confirmed ``$OSI`` showed ``mode``, sent at vehicle time ``v``."""
        self.seen_v, self.seen_mode = v, mode
        self.seen_at[mode] = v

    def lapse_uncertainty(self) -> None:
        """Drop ``extra_v`` once no timer started inside the adoption window remains."""
        if self.window is None:
            return
        lo, hi = self.window
        m = self.model
        t = m.timers
        inside = {name for name in t.names() if _started_in(t, name, lo, hi)}
        self.carried = (self.carried | inside) & self._alive()
        if self.carried or any(x.extra_v for x in self.timed):
            return
        self.window = None
        self.extra_v = 0.0

    def _alive(self) -> set:
        """Timers armed now, and a mission park frozen with time left (RH-RD-5)."""
        m = self.model
        alive = set(m.timers.names())
        if m.park_left is not None:
            alive.add("park")
        return alive

    def signature(self) -> tuple:
        """Equal signatures: the same future as far as judging goes (for de-duplication)."""
        m = self.model
        t = m.timers
        timers = tuple(sorted((n, round(t.deadline(n) or 0.0, 3)) for n in t.names()))
        return (m.mode, m.phase, m.mission_wp, m.mission_mode, m.error_state, m.srp_active,
                len(m.queue), m.queue_parking, timers, m.mission.name if m.mission else "",
                m.park_left, m.opk_seconds if m.opk else None, self.code_unknown)
