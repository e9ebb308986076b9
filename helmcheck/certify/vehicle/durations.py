"""The durations a case or an exploration draw uses, chosen from the line budget.

Every duration the tester sets going — a servo or primitive timeout, an ``$OPK`` park, the wait
between two ``$OMS`` that restart a timeout, the depth a dive must reach so that the vehicle is
still under water when the lockout is over — is chosen here from the run's
:class:`~helmcheck.judge.linebudget.LineBudget`, inside the profile's ranges (``timeout_range``,
RH-PK-1's minutes). The rule is the same everywhere: the shortest duration the observer can time
on this line at this time scale (RH-TIM-1, RH-TIM-2) and that outlasts the report confirming it
took effect. Where no allowed duration is long enough, :meth:`Durations.unmet` says so with the
time scale or baud that would do, and the case is NOT-TESTED before it runs — never INCONCLUSIVE
after the fact (a case that cannot time its own timer is the tester's defect).

The keys :meth:`Durations.context` adds to a case's templates (:mod:`.interpreter`):

==============  ==============================================================================
``to``          a servo / primitive timeout the observer times (RH-SRV-4, RH-PRM-4)
``to_long``     a control that must outlast several steps (at least 60 s and three ``to``)
``to_tim``      RH-TIM-2's long timeout: the shortest of at least 30 s that tells a clock 30 % off
                (:data:`CLOCK_OFF`) from RH-TIM-1's tolerance widened by this line; where none
                does, the longest the profile allows (the verdict states its precision)
``to_restart``  a timeout restarted ``gap`` into it, both deadlines told apart (RH-SRV-3)
``gap``         vehicle seconds between the two ``$OMS`` of ``to_restart``
``opk_min``     ``$OPK`` minutes whose countdown is timed (RH-PK-3); ``opk_s`` the seconds
``opk_long``    ``$OPK`` minutes that outlast a report, a countdown seen starting and a wait of
                10 s after it (RH-PK-2); ``opk_long_s`` the seconds, ``opk_long_below`` 5 less
``qpark``       a park time on a queued ``$OMW`` waypoint the observer can time (RH-OMW-4)
``dive_depth``  the depth of the dive before a violation (10 m, at most half the depth range)
``dive_at``     the depth at which the dive counts as under way (four fifths of it)
``opos_m``      how far an ``$OPOS`` moves the vehicle (metres; ``{opos_lat}`` is that far north):
                far enough that the next report tells applied from not applied (RH-POS-2) however
                far the vehicle can have gone at full speed since the report before it
==============  ==============================================================================

Decisions (the profile is silent): a dive goes to 10 m (at the bench speed it takes a while); the
case that needs the vehicle under water after a lockout sends the ``$OMP`` that holds its depth
(RH-RD-12) as the probe that finds the lockout's end, so no ascent rate is assumed; a lockout's
commands go in one burst after the violation, and need the lockout to last the burst's
processing with the observer's margin; the case that needs the vehicle still under water after a
lockout assumes an ascent of :data:`ASCENT_MPS` and says so where the line makes it matter.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional

from ...judge.linebudget import BAUDS, MARGIN, LineBudget
from ...model.timers import tolerance
from ...profile import Profile

__all__ = ["Durations", "derive", "BURST_BYTES", "DURATION_KEYS"]

#: The template keys :meth:`Durations.context` fills.
DURATION_KEYS = ("to", "to_long", "to_tim", "to_restart", "gap", "opk_min", "opk_s", "qpark", "dive_depth",
                 "dive_at", "opk_long", "opk_long_s", "opk_long_below", "opos_m")
#: The ascent rate (m/s) after a lockout a case plans for (the reference emulator's): the profile
#: sets none, so a case that needs the vehicle under water after a lockout says so when it is assumed.
ASCENT_MPS = 0.3

#: Bytes of the burst of commands a lockout case sends after the violation.
BURST_BYTES = 90


@dataclass(frozen=True)
class Durations:
    """The tester's durations on one line (module docstring); ``None``: none can be timed."""

    budget: LineBudget
    lo: int
    hi: int
    to: Optional[int]
    to_long: Optional[int]
    to_tim: Optional[int]
    to_restart: Optional[int]
    gap: float
    opk_min: Optional[int]
    opk_long: int
    qpark: Optional[int]
    lockout_ok: bool
    ascent_ok: bool
    lockout_s: float
    seen_by_poll: bool  #: the violation is seen by a poll first (not ``$OXFLT``, RH-SAF-5)
    dive_depth: float
    depth_unit: str
    profile: Profile
    opos_m: float

    def advice(self, need: str) -> str:
        """The largest time scale (a whole number), else the lowest faster baud of RH-FRM-9, at
        which this line would meet ``need``; or that the vehicle would have to answer sooner."""
        b = self.budget
        k = b.k
        while k > 1:
            k = math.floor(k) - 1 if k > 2 else 1
            if derive(self.profile, b.at(k=k)).meets(need):
                return f"--time-scale {k:g}"
        for baud in BAUDS:
            if baud > b.baud and derive(self.profile, b.at(baud=baud)).meets(need):
                return f"--baud {baud} (if the vehicle's line allows it)"
        return "a vehicle that answers sooner"

    def context(self) -> dict[str, str]:
        ctx = {"gap": f"{self.gap:.1f}", "dive_depth": f"{self.dive_depth:g}",
               "dive_at": f"{0.8 * self.dive_depth:g}", "opos_m": f"{self.opos_m:.0f}"}
        for key in ("to", "to_long", "to_tim", "to_restart"):
            ctx[key] = str(getattr(self, key) or self.hi)
        m = self.opk_min or 1440
        ctx.update(opk_min=str(m), opk_s=str(60 * m), qpark=str(self.qpark or 86400), opk_long=str(self.opk_long),
                   opk_long_s=str(60 * self.opk_long), opk_long_below=str(60 * self.opk_long - 5))
        return ctx

    def meets(self, need: str) -> bool:
        """Does this line meet ``need`` (:meth:`unmet` without the reason)?"""
        kind, _, arg = need.partition(":")
        if kind == "timer":
            return (self.opk_min if arg == "opk" else getattr(self, arg, None)) is not None
        if kind == "ascent":
            return self.ascent_ok
        if kind == "lockout":
            return self.lockout_ok
        return True

    def unmet(self, need: str) -> Optional[str]:
        """Why a case needing ``need`` (``timer:to``, ``timer:opk``, ``lockout`` …) cannot be run
        on this line, or ``None``."""
        kind, _, arg = need.partition(":")
        b = self.budget
        if kind == "timer":
            value = self.opk_min if arg == "opk" else getattr(self, arg, None)
            if value is not None:
                return None
            what = {"to": "remote-control timeout", "to_long": "remote-control timeout",
                    "to_tim": "timeout of 30 s or more", "to_restart": "timeout long enough to be restarted "
                    "and have both deadlines told apart", "opk": "$OPK park"}.get(arg, arg)
            hi = 1440 * 60 if arg == "opk" else self.hi
            return (f"no {what} the profile allows (up to {hi} s) can be timed on this line at time scale "
                    f"{b.k:g} (RH-TIM-1, the line: {b.describe()}); run at {self.advice(need)}")
        if kind == "ascent" and not self.ascent_ok:
            return (f"after the lockout the vehicle may reach the surface from {0.8 * self.dive_depth:g} "
                    f"{self.depth_unit} before a command can be answered on this line at time scale {b.k:g} "
                    f"(RH-SAF-3: assuming an ascent of {ASCENT_MPS:g} m/s; the line: {b.describe()}); run at "
                    f"{self.advice(need)}")
        if kind == "lockout" and not self.lockout_ok:
            return (f"the {self.lockout_s:g} s lockout ends before the commands sent into it can be "
                    f"answered on this line at time scale {b.k:g} (RH-SAF-1, the line: {b.describe()}); run at "
                    f"{self.advice(need)}")
        return None


def _ascent_fits(b: LineBudget, dive_depth: float, unit: str) -> bool:
    """Does the ascent from the dive outlast one probe's round trip (the ``$OMP`` that finds the
    lockout's end and holds the depth, RH-RD-12)?"""
    metres = 0.8 * dive_depth * (1.0 if unit == "m" else 0.3048)
    return metres / ASCENT_MPS >= MARGIN * (b.k * b.rtt_s + b.observe_v)



def _lockout_fits(b: LineBudget, lockout_s: float, seen_by_poll: bool = False) -> bool:
    """Do the commands of a lockout case, one burst written right after the violation (or after the
    poll that saw a violation the vehicle raised itself), reach the vehicle inside the lockout?"""
    if seen_by_poll:  # the burst goes after the report that showed the violation, and is answered late
        need = b.poll_v + b.command_v
    else:  # written with the $OXFLT: answered at most the latencies' spread after it (RH-ACK-6)
        need = b.k * (b.spread_s + b.jitter_s)
    need += b.k * b.tx(BURST_BYTES) + MARGIN * b.observe_v
    return need + tolerance(lockout_s) <= lockout_s



def _opos_m(profile: Profile, b: LineBudget) -> float:
    """Metres an ``$OPOS`` moves the vehicle: four times the way it can make at full speed between
    the report before it and the report after it (two round trips) and 10 m, at least 110 m (the
    judge decides only beyond three times that, :mod:`helmcheck.judge.vehicle.osichecks`)."""
    way = profile.max_speed_kn * 0.514444 * 2 * MARGIN * b.k * b.rtt_s + 10.0
    return max(110.0, 4 * way)


#: The clock error V-62 (RH-TIM-2) is to tell apart: a vehicle clock this fraction fast or slow.
CLOCK_OFF = 0.3


def _to_tim(b: LineBudget, lo: int, hi: int) -> Optional[int]:
    """RH-TIM-2's timeout: the shortest timeable one of at least 30 s that a clock
    :data:`CLOCK_OFF` fast ends early by more than the line's precision (a fast clock is the
    smaller error: ``d·(1 − 1/1.3)``); where none does, the longest timeable one."""
    early = 1.0 - 1.0 / (1.0 + CLOCK_OFF)
    d = b.shortest(lo, hi, at_least=30.0)
    best = d
    while d is not None and d <= hi:
        if early * d >= MARGIN * b.precision_v(d):
            return d
        if b.timeable(d):
            best = d
        d += 1
    return best


def derive(profile: Profile, budget: LineBudget) -> Durations:
    """The durations for ``profile`` on the line ``budget`` describes."""
    lo, hi = int(profile.timeout_range[0]), int(profile.timeout_range[1])
    b = budget
    to = b.shortest(lo, hi)
    to_long = b.shortest(lo, hi, at_least=max(60.0, 3 * (to or hi))) if to is not None else None
    if to_long is None and to is not None:
        to_long = hi
    to_tim = _to_tim(b, lo, hi)
    to_restart = None
    gap = 0.0
    if to is not None:
        for d in range(to, hi + 1):
            g = b.gap_v(d)
            if d - tolerance(d) - MARGIN * b.observe_v >= b.hold_v + g + b.command_v and b.timeable(d):
                to_restart, gap = d, g
                break
        if to_restart is None:
            gap = b.gap_v(hi)
    opk = b.shortest(60, 1440 * 60, unseen_start=True)
    opk_min = None if opk is None else int(math.ceil(opk / 60))
    opk_long = max(2, int(math.ceil((2 * b.hold_v + 3 * MARGIN * b.poll_v + 10.0) / 60)))
    qpark = b.shortest(1, 86400, hold=False, unseen_start=True)
    depth_m = min(profile.max_depth_m / 2, 10.0)
    depth = float(math.floor(depth_m if profile.depth_unit == "m" else depth_m / 0.3048))
    by_poll = profile.trigger != "oxflt"
    return Durations(b, lo, hi, to, to_long, to_tim, to_restart, round(gap, 1), opk_min, opk_long, qpark,
                     _lockout_fits(b, profile.lockout_s, by_poll), _ascent_fits(b, depth, profile.depth_unit),
                     profile.lockout_s, by_poll, depth, profile.depth_unit, profile, _opos_m(profile, b))
