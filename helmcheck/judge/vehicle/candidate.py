"""One state a conforming vehicle may be in: a reference model plus what the observer adopted.

A :class:`Candidate` wraps a :class:`~helmcheck.model.vehicle.VehicleModel` (with its row
``trace`` on, and ``$OSD`` data answered by class name: the judge compares which sentences come,
never their values) and keeps, besides the model, what judging needs and the model does not:

* ``events`` / ``story`` — the unseen plant events adopted to explain the wire (fewer is more
  plausible) and what they were; ``took`` — the readings of the profile's open questions taken to
  explain an answer (:mod:`helmcheck.model.readings`: the model under them is the candidate's);
* ``extra_v`` — vehicle seconds of uncertainty an adopted event's time window adds to every
  timer it started (RH-TIM-1: the observer widens by what it cannot see); it lapses when no timer
  started inside the window is left — nor one that did and was frozen and resumed since (a mission
  park frozen by remote control resumes with what was left of it, which the window's uncertainty
  still has: ``carried``, RH-INT-2, RH-RD-5);
* ``left_v`` / ``release`` — a mission park resumed after remote control (RH-INT-2) counts from
  the release with the time that was left when control took over (RH-RD-5), and the observer
  knows neither exactly: the time left was as uncertain as the park's count was when it froze
  (``left_v``), and a timer's release (the ``$OPK`` time up, a timeout, the queue's last park)
  comes anywhere within RH-TIM-1's tolerance of the timer, itself as uncertain as its start. So
  a release that resumes a park opens a window on the park's start that wide (:meth:`_resumed`;
  ``release``: the release's model time and the time left's part of the window); the first
  report that shows the park resumed narrows it, before it is judged, to the moment the reports
  bracket (:meth:`_bracket_release`), and the park time the reports show narrows it further
  (:func:`~.brackets.retime`), as for a countdown an adopted event began; ``resumed`` — the
  mission park counting is one resumed so: a park time no conforming state explains is its time
  left's (RH-INT-2, for blame), and it may be one that counts only once back on station
  (``left_known``: how well its time left is known, :func:`~.closure.explain_osi`);
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
* ``noted`` — the moment a plant note (the emulator's own log) says the next mission waypoint was
  reached, where the observer left that event to the reports because it does not know yet what
  the waypoint holds: the closure adopts it at that moment, not in a window (until the next
  confirmed report);
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
from ...model.timers import tolerance
from ...model.transitions import COMMAND_EVENTS, REMOTE_MODES, STAY, Row
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

    __slots__ = ("model", "events", "story", "took", "extra_v", "window", "pending", "timed", "abandoned",
                 "s_cause", "refused_locked", "seen_v", "seen_mode", "seen_at", "locked_v", "code_unknown",
                 "refresh", "nav_seen", "fix_seen", "left_v", "release", "resumed", "left_known", "noted",
                 "_mode", "_phase", "carried")

    def __init__(self, model: VehicleModel):
        if model.trace is None:
            model.trace = []
        model.data_names = True  # the judge compares which data sentences come, not their values
        self.model = model
        self.events = 0
        self.story: tuple[str, ...] = ()
        #: readings of the profile's open questions this state took to explain an answer (not
        #: unseen events: a reading is a conforming vehicle's own choice, :mod:`helmcheck.model.readings`)
        self.took: tuple[str, ...] = ()
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
        self.left_v = 0.0
        #: (model time, the time left's part of the window, the window, the last report before
        #: it) of a timed release
        self.release: Optional[tuple] = None
        self.resumed = False  #: the mission park counting is one resumed after remote control
        self.left_known = 0.0  #: vehicle seconds: how well the time left of a resumed park is known
        #: vehicle time of a plant note of the next mission waypoint reached that the observer left
        #: to the reports (what the waypoint holds is not known yet): the closure places it then
        self.noted: Optional[float] = None
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
        c.took = self.took
        c.carried = self.carried
        c.pending = list(self.pending)
        c.timed = [Timed(**vars(t)) for t in self.timed] if self.timed else []
        c.abandoned = set(self.abandoned)
        c.s_cause, c.refused_locked, c.refresh = self.s_cause, self.refused_locked, self.refresh
        c.seen_v, c.seen_mode, c.locked_v = self.seen_v, self.seen_mode, self.locked_v
        c.seen_at = dict(self.seen_at)
        c.code_unknown = self.code_unknown
        c.nav_seen, c.fix_seen = self.nav_seen, self.fix_seen
        c.left_v, c.release, c.resumed, c.noted = self.left_v, self.release, self.resumed, self.noted
        c.left_known = self.left_known
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
            if (row.error is None and not st.timer and self.timed
                    and ((row.target != STAY and row.event in COMMAND_EVENTS) or self._mode in
                         {tt.pre_mode for tt in self.timed})):
                # a command took control again after a timer ran out, or the state went back to
                # the timer's before-state, before any report showed the timer's end: no report can
                # tell any more when (or whether) it ended there, so it is not judged (a $OMS with
                # the range's lowest timeout restarted at once, V-65: RH-RD-3 either way)
                self.timed = [tt for tt in self.timed if tt.timer == "lockout"]
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
            if row.error is None:
                self._resumed(st, before_mode)
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

    def _resumed(self, st, before_mode: str) -> None:
        """A mission park frozen by remote control, or resumed by its release (module docstring)."""
        row = st.row
        if before_mode == "P" and row.target in REMOTE_MODES:
            self.left_v = self.extra_v if self.window is not None else 0.0
            self.release, self.resumed = None, False
            return
        if row.target != "P" or before_mode not in REMOTE_MODES:
            if row.target not in (STAY, "P"):
                self.resumed = False
            return
        t = self.model.timers
        start = (t.deadline("park") or 0.0) - (t.duration("park") or 0.0)
        if not t.armed("park") or abs(start - st.at) > 1e-6:
            return
        self.resumed = True
        left, self.left_v = self.left_v, 0.0
        self.left_known = left
        half = left + (tolerance(st.duration) + self.extra_v if st.timer else 0.0)
        if half > 0:
            self.window = (st.at - half, st.at + half)
            self.extra_v = half
            timed = self.timed[-1] if self.timed and self.timed[-1].deadline == st.at else None
            self.release = (st.at, left, self.window, timed.t_old if timed else None) if st.timer else None

    def _bracket_release(self, v: float, slack_v: float) -> None:
        """A report made by ``v`` (± ``slack_v``) shows the park resumed by the timed release
        :attr:`release`: the release came after the last report of the state before it and
        before this one, and the resumed park's start is that moment less or more the
        uncertainty of the time left (module docstring). Where the start was already narrowed
        by the park time shown (:func:`~.brackets.retime`, when this is not the first report
        after the release) outside of that, it goes back inside: the count shown does not fit
        any release the reports allow, and is judged so."""
        at, left, (lo0, hi0), t_old = self.release  # type: ignore[misc]
        self.release = None
        t = self.model.timers
        if self.window is None or not t.armed("park"):
            return
        t_old = next((tt.t_old for tt in self.timed if abs(tt.deadline - at) <= 1e-6), t_old)
        lo = max(lo0, (t_old if t_old is not None else lo0) - slack_v - left)
        hi = min(hi0, v + slack_v + left)
        if lo > hi:
            return  # the reports contradict the window (judged as they are)
        lo_w, hi_w = self.window
        if max(lo, lo_w) <= min(hi, hi_w):
            lo, hi = max(lo, lo_w), min(hi, hi_w)
        t.arm("park", (lo + hi) / 2, t.duration("park") or 0.0)
        self.window = (lo, hi)
        self.extra_v = (hi - lo) / 2

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
        """``[]`` when this candidate explains ``osi`` at ``v`` (RH-OUT-4, RH-TIM-1); a report
        that shows a resumed park first narrows when its count began (:meth:`_bracket_release`)."""
        if self.release is not None and osi.mode == "P" and self.model.mode == "P":
            self._bracket_release(v, slack_v)
        return quick_check(self.model, osi, v, slack_v + self.extra_v)

    def saw(self, v: float, mode: str) -> None:
        """A confirmed ``$OSI`` showed ``mode``, sent at vehicle time ``v``."""
        self.seen_v, self.seen_mode, self.noted = v, mode, None
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
                m.park_left, m.opk_seconds if m.opk else None, self.code_unknown,
                tuple(sorted(m.readings.items())))
