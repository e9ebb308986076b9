"""What a conforming vehicle may report at a given time: the observation API (RH-OUT-4, RH-TIM-1).

A tester mirrors every command it sent into a :class:`~helmcheck.model.vehicle.VehicleModel`
(``receive(cmd, t)``) and, for an ``$OSI`` it received, asks ``expectation(model, t, slack)``
(or ``model.expectation(t, slack)``); :meth:`Expectation.check` lists a :class:`Finding` —
``(clause, message)``, and the field it is about — for every judged field (mode, next waypoint,
park time, error state, SRP flag) no acceptable state explains.

Approach: skewed shadows
------------------------
RH-TIM-1 lets every duration (timeouts, lockout, parks) be off by ``max(0.5 s, 5 %)`` of itself,
and the observer adds the slack it cannot see (serial transmit time, polling interval, jitter).
Between two inputs the model's future is fixed: only timers change the state, and (remote
control freezing the mission, a violation ending remote control) at most one state-changing
timer runs at a time, so the states form one chain ``s0 → s1 → …``. Two shadow copies of the
model run that chain:

* the *fast* shadow, in which every timer (already armed or armed on the way) expires
  ``tolerance(d) + slack`` early, and
* the *slow* shadow, in which every timer expires that much late.

Each is advanced from the model's last input to ``now``, recording the states it passes
through. The slow one is at some ``s_j``, the fast one at ``s_k`` (``j ≤ k``); every state
``s_j … s_k`` is acceptable — so near a timeout both the old and the new mode are. A shadow's
countdowns *display* its own clock's count (start + duration − now, unskewed), so the park time
of each acceptable state is the interval between what the two shadows show (the fast shadow in
it now or as it left it; the slow shadow in it now or the fast one as it entered it), widened by
``slack`` and rounded outwards to whole seconds (field 10 is rounded up, RH-RD-5). The
``$OPK`` park before its count begins is not widened: it shows the minutes the command gave,
exactly (a report showing one second less shows the count begun); and a running count is widened
also where it has reached 0: the slow shadow, still counting past its own count's end, shows how
far past (a report made up to ``slack`` earlier may still show ``P1``). A state that shows no park
shows ``P0`` exactly.

So that the slow shadow can still be "before" a timer the model itself already ran, the model
keeps a checkpoint: a copy of itself taken just before the first timer fires after a
state-changing input (``VehicleModel.checkpoints``, on by default; ``VehicleModel.checkpoint``
reads it, ``drop_checkpoint()`` forgets it). Shadows start from it.

Steady state: :func:`steady_expectation` answers without shadows when no checkpoint is held
and no timer can expire by ``now`` even at its earliest (RH-TIM-1): the one present state, with
its park time widened by ``slack``. :func:`quick_expectation` tries it first and falls back to
:func:`expectation` (for observers that ask for every ``$OSI`` of a long log); :func:`quick_check`
is its ``check``, which makes no expectation for a report the steady state explains.

Limits (documented, deliberate): a command that arrives within the tolerance of a timer is
applied to the nominal state only (the model cannot know which side of the race the vehicle
was on); in practice the commands that race a timeout (``$OMS`` refresh, ``$OJW``, ``$OMW,Clr``)
lead to the same state either way.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

from ..grammar import sentences as s
from .timers import tolerance

__all__ = ["Acceptable", "Expectation", "Finding", "expectation", "steady_expectation", "quick_expectation",
           "quick_check"]


class Finding(tuple):
    """``(clause, message)`` of :meth:`Expectation.check`, with ``field``: the report field it is
    about (``mode``, ``next_waypoint``, ``error_state``, ``park_time``, ``srp_active``), or None
    when each field fits some state but no single state fits them all. A pair like any other
    (unpacked, compared, written as JSON), for the judges that only book it."""

    def __new__(cls, clause: str, message: str, field: Optional[str]):
        self = super().__new__(cls, (clause, message))
        self.field = field
        return self

    def __getnewargs__(self):
        return self[0], self[1], self.field


@dataclass(frozen=True, slots=True)
class Acceptable:
    """One state a conforming vehicle may be in, with the park-time interval it may show."""

    mode: str
    waypoint: int
    error_state: str
    srp_active: bool
    park_lo: int
    park_hi: int

    def matches(self, osi: s.OSI) -> bool:
        return _fits(osi, self.mode, self.waypoint, self.error_state, self.srp_active, self.park_lo, self.park_hi)


def shown_waypoints(mode: str, waypoint: int) -> tuple[int, ...]:
    """What ``$OSI`` field 3 may show for the model's ``waypoint`` in ``mode``: in a mission park (``P``)
    the waypoint parked on or the one after it — RH-OUT-1's "next waypoint" is open there (RD-5 pins
    field 3 in A, M, mP, W and S only; the readings table: ``park_waypoint``)."""
    return (waypoint, waypoint + 1) if mode == "P" else (waypoint,)


def _fits(osi: s.OSI, mode: str, waypoint: int, error_state: str, srp_active: bool, park_lo: int,
          park_hi: int) -> bool:
    """:meth:`Acceptable.matches` of the state with these fields."""
    return (osi.mode == mode and osi.next_waypoint in shown_waypoints(mode, waypoint)
            and osi.error_state == error_state
            and park_lo <= osi.park_time <= park_hi
            and (osi.srp_active is None or osi.srp_active == ("True" if srp_active else "False")))


@dataclass(frozen=True, slots=True)
class Expectation:
    """The acceptable states at ``now`` (with ``slack`` seconds of observer uncertainty)."""

    now: float
    slack: float
    states: tuple[Acceptable, ...]

    @property
    def modes(self) -> tuple[str, ...]:
        return tuple(dict.fromkeys(a.mode for a in self.states))

    def check(self, osi: s.OSI) -> list[Finding]:
        """``[]`` when some acceptable state explains ``osi``; else one finding per field."""
        if any(a.matches(osi) for a in self.states):
            return []
        at = f"at t={self.now:.3f} (slack {self.slack:g} s)"
        out: list[Finding] = []
        cands = [a for a in self.states if a.mode == osi.mode]
        if not cands:
            return [Finding("RH-OUT-4", f"mode {osi.mode!r} {at}; a conforming vehicle reports "
                                        f"{' or '.join(self.modes)}", "mode")]
        wp = [a for a in cands if osi.next_waypoint in shown_waypoints(a.mode, a.waypoint)]
        if not wp:
            want = sorted({a.waypoint for a in cands})
            out.append(Finding("RH-OUT-4", f"next waypoint {osi.next_waypoint} in mode {osi.mode} {at}; "
                                           f"expected {' or '.join(map(str, want))}", "next_waypoint"))
            wp = cands
        err = [a for a in wp if a.error_state == osi.error_state]
        if not err:
            want = sorted({a.error_state for a in wp})
            # a safety code every explanation shows, missing or another: field 8 in the lockout and
            # after it (RH-SAF-1, RH-RD-13)
            clause = "RH-SAF-1" if "N" not in want else "RH-OUT-4"
            out.append(Finding(clause, f"error state {osi.error_state!r} {at}; expected {' or '.join(want)}",
                               "error_state"))
            err = wp
        park = [a for a in err if a.park_lo <= osi.park_time <= a.park_hi]
        if not park:
            ranges = ", ".join(f"P{a.park_lo}..P{a.park_hi}" for a in err)
            out.append(Finding("RH-OUT-4", f"park time P{osi.park_time} in mode {osi.mode} {at}; "
                                           f"expected {ranges}", "park_time"))
            park = err
        if osi.srp_active is not None and not any(
                osi.srp_active == ("True" if a.srp_active else "False") for a in park):
            out.append(Finding("RH-OUT-4", f"SRP active {osi.srp_active} {at}; expected "
                                           f"{'True' if park[0].srp_active else 'False'}", "srp_active"))
        if not out:  # each field fits some state, but no single state fits them all
            out.append(Finding("RH-OUT-4", f"mode {osi.mode}, waypoint {osi.next_waypoint}, error "
                                           f"{osi.error_state}, P{osi.park_time} {at} fit no single "
                                           f"state a conforming vehicle can be in", None))
        return out


#: A park time a state shows: ``None`` (no park, ``P0``) or ``(seconds, widened)``.
Shown = Optional[tuple[float, bool]]


def _shown(m, at: float, clip: bool = True) -> Shown:
    """What field 10 of ``m`` shows at ``at`` (before rounding), and whether it is widened by the
    observer's uncertainty: every count but the ``$OPK`` park's before it begins, which shows the
    minutes the command gave, exactly, at any moment (a count frozen — a mission park in a
    lockout, or held — shows what was left at a moment the observer knows as well as the rest)."""
    left = m.park_remaining(at, clip)
    if left is None:
        return None
    return left, not (m.mode == "mP" and not m.timers.armed("opk"))


@dataclass
class _Visit:
    sig: tuple
    entry_park: Shown
    exit_park: Shown = None


def _sig(m) -> tuple:
    return (m.mode, m.osi_waypoint, m.error_state, m.srp_active)


def _run(shadow, now: float) -> list[_Visit]:
    """Advance ``shadow`` to ``now`` one expiry at a time, recording distinct states."""
    t0 = shadow.now if shadow.now is not None else now
    visits = [_Visit(_sig(shadow), _shown(shadow, t0))]
    timers = shadow.timers
    while timers.due is not None and timers.due <= now:
        d = timers.due
        before = _shown(shadow, d)
        shadow._run_due(d)
        sig = _sig(shadow)
        if sig != visits[-1].sig:
            visits[-1].exit_park = before
            visits.append(_Visit(sig, _shown(shadow, d)))
    shadow._run_due(now)
    return visits


def _shadow(model, sign: float, slack: float):
    sh = model.clone()
    sh.checkpoints = False
    sh.timers.set_skew(sign, slack)
    return sh


def expectation(model, now: float, slack: float = 0.0) -> Expectation:
    """The :class:`Expectation` for an ``$OSI`` produced at ``now`` (see the module docstring)."""
    base = model.checkpoint if model.checkpoint is not None else model
    if base.now is not None and now < base.now:
        now = base.now
    fast, slow = _shadow(base, -1.0, slack), _shadow(base, +1.0, slack)
    fv, sv = _run(fast, now), _run(slow, now)
    k, j = len(fv) - 1, len(sv) - 1
    aligned = j <= k and all(fv[i].sig == sv[i].sig for i in range(j + 1))
    states: list[Acceptable] = []
    if aligned:
        for i in range(j, k + 1):
            values = [_shown(fast, now, clip=False) if i == k else fv[i].exit_park,
                      _shown(slow, now, clip=False) if i == j else fv[i].entry_park]
            states.append(_acceptable(fv[i].sig, values, slack))
    else:  # pragma: no cover - only if two state-changing timers ever race
        for v in fv + sv:
            states.append(_acceptable(v.sig, [v.entry_park, v.exit_park], slack))
    return Expectation(now, slack, tuple(dict.fromkeys(states)))


def _acceptable(sig: tuple, values: list[Shown], slack: float) -> Acceptable:
    """The state ``sig`` with the park times ``values`` may show (module docstring): ``None`` is no
    park (``P0`` exactly); a count, also one at or past its end, is widened by ``slack`` (not the
    ``$OPK`` park's before it begins)."""
    lo = hi = 0.0
    first = True
    for v in values:
        if v is None:
            a = b = 0.0
        else:
            w = slack if v[1] else 0.0
            a, b = v[0] - w, v[0] + w
        lo, hi = (a, b) if first else (min(lo, a), max(hi, b))
        first = False
    mode, wp, err, srp = sig
    return Acceptable(mode, wp, err, srp, max(0, math.floor(lo)), max(0, math.ceil(hi)))


def _timer_near(model, now: float, slack: float) -> bool:
    """Can some armed timer expire by ``now`` at its earliest (RH-TIM-1 tolerance + slack)?"""
    t = model.timers
    for name in t.names():
        d = t.deadline(name)
        dur = t.duration(name) or 0.0
        if d is not None and d - tolerance(dur, slack) <= now:
            return True
    return False


def steady_expectation(model, now: float, slack: float = 0.0) -> Optional[Expectation]:
    """The :class:`Expectation` at ``now`` when nothing can change before it (module
    docstring), else ``None``."""
    got = _steady(model, now, slack)
    return None if got is None else Expectation(now, slack, (Acceptable(*got),))


def _steady(model, now: float, slack: float) -> Optional[tuple]:
    """The fields of the one :class:`Acceptable` of :func:`steady_expectation`, or ``None``."""
    if model.checkpoint is not None or _timer_near(model, now, slack):
        return None
    base = model.now if model.now is not None and model.now > now else now
    mode, wp, err, park, srp = model.state(base)
    shown = _shown(model, base)
    if shown is None or shown[0] <= 0:
        lo = hi = 0
    else:
        p, w = shown[0], (slack if shown[1] else 0.0)
        lo, hi = max(0, math.floor(max(0.0, p - w))), math.ceil(p + w)
        lo = min(lo, park)
        hi = max(hi, park)
    return mode, wp, err, srp, lo, hi


def quick_expectation(model, now: float, slack: float = 0.0) -> Expectation:
    """:func:`steady_expectation` when it answers, else :func:`expectation`."""
    exp = steady_expectation(model, now, slack)
    return exp if exp is not None else expectation(model, now, slack)


def quick_check(model, osi: s.OSI, now: float, slack: float = 0.0) -> list[Finding]:
    """``quick_expectation(model, now, slack).check(osi)``; a report the one steady state
    explains (nearly every report of a session) is answered without making the expectation."""
    got = _steady(model, now, slack)
    if got is None:
        return expectation(model, now, slack).check(osi)
    if _fits(osi, *got):
        return []
    return Expectation(now, slack, (Acceptable(*got),)).check(osi)
