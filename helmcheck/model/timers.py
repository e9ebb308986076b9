"""The model's timers: named (start, duration) pairs on the model's clock (RH-TIM-1, RH-RD-15).

A timer is armed at the instant the vehicle processes the command (its ACK goes out, RH-RD-15)
and expires at ``start + duration``. Keeping the duration, not just the deadline, lets an
observer build *skewed* shadows of a model (:mod:`helmcheck.model.observe`): with ``skew =
(sign, slack)`` every deadline moves by ``sign * (max(0.5, 5 % of duration) + slack)``, the
RH-TIM-1 tolerance, so a shadow runs as the fastest (``sign = -1``) or slowest (``+1``)
conforming vehicle would.

Names used by the model: ``remote`` (``$OMS``/``$OMP`` timeout), ``opk`` (``$OPK`` countdown),
``qpark`` (park on a queued ``$OMW`` waypoint), ``park`` (mission park), ``dvl`` (``$ODVL``),
``lockout`` (RH-SAF-1).
"""

from __future__ import annotations

from typing import Optional

__all__ = ["Timers", "tolerance"]


def tolerance(duration: float, slack: float = 0.0) -> float:
    """RH-TIM-1: ``max(0.5 s, 5 %)`` of ``duration``, widened by ``slack``."""
    return max(0.5, 0.05 * duration) + slack


class Timers:
    """A small set of named timers with a cached next expiry. The name → (start, duration)
    mapping is never changed in place (arming or disarming makes a new one), so a copy shares it
    until either side changes."""

    __slots__ = ("_t", "skew", "due", "_next")

    def __init__(self) -> None:
        self._t: dict[str, tuple[float, float]] = {}
        self.skew: Optional[tuple[float, float]] = None
        self.due: Optional[float] = None  #: the earliest deadline, or None
        self._next: Optional[tuple[float, float, str]] = None

    def copy(self) -> "Timers":
        new = Timers.__new__(Timers)
        new._t = self._t  # shared: arm() and disarm() replace, never mutate
        new.skew = self.skew
        new.due = self.due
        new._next = self._next
        return new

    def set_skew(self, sign: float, slack: float) -> None:
        self.skew = (sign, slack)
        self._recompute()

    def deadline(self, name: str) -> Optional[float]:
        t = self._t.get(name)
        if t is None:
            return None
        start, dur = t
        if self.skew is None:
            return start + dur
        sign, slack = self.skew
        return max(start, start + dur + sign * tolerance(dur, slack))

    def duration(self, name: str) -> Optional[float]:
        t = self._t.get(name)
        return None if t is None else t[1]

    def armed(self, name: str) -> bool:
        return name in self._t

    def arm(self, name: str, start: float, duration: float) -> None:
        self._t = {**self._t, name: (start, duration)}
        self._recompute()

    def disarm(self, name: str) -> None:
        if name in self._t:
            self._t = {k: v for k, v in self._t.items() if k != name}
            self._recompute()

    def remaining(self, name: str, now: float, clip: bool = True) -> Optional[float]:
        """Seconds left *on the vehicle's own countdown*: ``start + duration - now``, unskewed.

        A skewed shadow expires early or late, but what it displays (``$OSI`` field 10) and
        what it saves when a park is frozen is its own clock's count (RH-TIM-1). Not below 0,
        unless ``clip`` is false: a slow shadow still counting past its own count's end (an
        observer widening the count by its uncertainty needs how far past).
        """
        t = self._t.get(name)
        if t is None:
            return None
        left = t[0] + t[1] - now
        return left if not clip or left > 0.0 else 0.0

    def earliest(self) -> Optional[tuple[float, str]]:
        """(deadline, name) of the next timer to expire; ties go by name for determinism."""
        best: Optional[tuple[float, str]] = None
        for name in self._t:
            d = self.deadline(name)
            assert d is not None
            if best is None or (d, name) < best:
                best = (d, name)
        return best

    def names(self) -> tuple[str, ...]:
        return tuple(self._t)

    def next_timer(self) -> Optional[tuple[float, float, str]]:
        """(deadline, duration, name) of the next timer to expire (as :meth:`earliest`), or None."""
        return self._next

    def _recompute(self) -> None:
        e = self.earliest() if self._t else None
        self.due = None if e is None else e[0]
        self._next = None if e is None else (e[0], self._t[e[1]][1], e[1])
