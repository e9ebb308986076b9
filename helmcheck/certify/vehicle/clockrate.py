"""The vehicle's clock rate against wall time, and whether it is the declared time scale (RH-TIM-2).

Sans-IO: this module reads no port and no clock. It owns the measurement → verdict part of the
start-up time-scale check (:mod:`.clockprobe` drives the wire):

* :func:`gprmc_clock` — the vehicle time a ``$GPRMC`` carries, in seconds, and the resolution
  its text gives (one unit of its last digit: ``hhmmss`` 1 s, ``hhmmss.ss`` 0.01 s);
* :func:`measure` — an interval for the rate from :class:`Sample` s;
* :func:`judge_rate` — :class:`ClockCheck`: ``mismatch`` (the run stops INCONCLUSIVE),
  ``consistent``, ``unresolved`` (measured, too coarse to tell) or ``not-measured``.

**The interval.** Each sample is a request written at wall time ``sent`` (stamped before its
first byte) answered by a ``$GPRMC`` read at ``recv`` (stamped after its last): the vehicle
read its clock at some instant in ``[sent, recv]`` and wrote time ``T``. A vehicle may write its
time in steps (the resolution of the text, or a clock that only moves when a GPS fix arrives),
so ``T`` is the true time to within one step ``q``. Every change of a stepped clock is at least
one step, so ``q`` is the larger of the text's resolution and:

* the largest change between two successive readings, when some successive readings are equal
  (a clock seen to stand still moves in steps of its own, maybe irregular ones);
* the smallest change, when every reading moved (the steps are no coarser than that: this keeps
  the interval narrow when the host is slow to read, and readings are far apart).

From the first sample (1) and the last (n), with ``dT = T_n - T_1``::

    rate >= max(0, dT - q) / (recv_n - sent_1)
    rate <= (dT + q) / (sent_n - recv_1)          (unbounded when sent_n <= recv_1)

Readings that never change give no interval (a time held from the last fix says nothing about
the clock): ``not-measured``. So does a time that goes backwards.

**Decision** (:data:`CLEAR_FACTOR`, written here and in the README): the run is stopped only when
the whole interval lies beyond ``CLEAR_FACTOR`` times the declared rate, or below it divided by
``CLEAR_FACTOR``. 1.5 because a mis-declared time scale is a factor of 2 or more in practice
(1 for 20, 40 for 10, 20 for 40), while a vehicle whose clock is off by less than that is left
to the timing clauses (RH-TIM-1, 5 %) to judge — a FAIL there is a finding about the vehicle.
An interval that lies within the factor on both sides is ``consistent``; one that holds the
declared rate but reaches past the factor is ``unresolved`` and the run goes on.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from datetime import datetime, timezone
from typing import Optional, Sequence

__all__ = ["Sample", "Rate", "ClockCheck", "gprmc_clock", "measure", "judge_rate", "not_measured",
           "CLEAR_FACTOR", "MIN_SAMPLES", "rate_text"]

#: The run stops only when the measured interval excludes the declared rate by this factor.
CLEAR_FACTOR = 1.5
#: Fewer samples than this decide nothing (a first and a last, and one between).
MIN_SAMPLES = 3
_DAY = 86400.0


@dataclass(frozen=True)
class Sample:
    """One reading of the vehicle's clock: wall ``[sent, recv]``, vehicle time ``vehicle_s``."""

    sent: float
    recv: float
    vehicle_s: float
    resolution: float


@dataclass(frozen=True)
class Rate:
    """The measured rate: vehicle seconds per wall second lie in ``[lo, hi]`` (``hi`` may be inf)."""

    lo: float
    hi: float
    samples: int
    wall_s: float  #: from the first request to the last answer
    vehicle_s: float  #: how far the vehicle's clock moved between the first and last reading
    step_s: float  #: ``q``, the step a reading is uncertain by

    @property
    def central(self) -> float:
        """Vehicle seconds moved over the wall seconds between the middles of the two brackets."""
        return self.vehicle_s / self.wall_s if self.wall_s > 0 else math.inf

    @property
    def named(self) -> Optional[float]:
        """The one rate the interval names (the roundest number in it), or ``None`` when it is
        too wide to name one (``hi > 1.25 lo``)."""
        return _nice(self.lo, self.hi)

    def text(self) -> str:
        """``×19.6–×20.4``: the interval."""
        hi = "∞" if math.isinf(self.hi) else f"×{_g(self.hi)}"
        return f"×{_g(self.lo)}–{hi}"


@dataclass(frozen=True)
class ClockCheck:
    """The verdict of the time-scale check; :meth:`note` is its wire-log line."""

    status: str  #: mismatch | consistent | unresolved | not-measured
    declared: float
    rate: Optional[Rate] = None
    reason: str = ""  #: why not measured
    factor: float = CLEAR_FACTOR
    source: str = "$GPRMC"
    extra: dict = field(default_factory=dict)

    @property
    def stops(self) -> bool:
        return self.status == "mismatch"

    def message(self) -> str:
        """One line: for a mismatch it names both rates and the option that fixes it."""
        d = f"×{_g(self.declared)}"
        if self.rate is None:
            return f"vehicle clock not measured: {self.reason}; declared {d}"
        r = self.rate
        runs = rate_text(r)
        measured = (f"its {self.source} time moved {r.vehicle_s:.3g} s in {r.wall_s:.2f} s of wall time, "
                    f"{r.samples} readings, step {r.step_s:g} s: {r.text()}")
        if self.status == "mismatch":
            nice = r.named
            fix = (f"; run again with --time-scale {_g(nice)}" if nice is not None
                   else "; give the vehicle's time scale with --time-scale")
            return f"the vehicle runs {runs}; declared {d} ({measured}){fix}"
        word = {"consistent": "agrees with", "unresolved": "cannot be told from"}[self.status]
        return f"the vehicle runs {runs}, which {word} the declared {d} ({measured})"

    def note(self) -> str:
        """The wire-log note (kept as evidence by every judge)."""
        return f"clock check: {self.status}: {self.message()}"

    def as_settings(self) -> dict:
        """What ``results.json`` ``settings.clock_check`` records."""
        out: dict = {"status": self.status, "declared": self.declared, "factor": self.factor,
                     "source": self.source}
        if self.rate is None:
            out["measured"] = None
            out["reason"] = self.reason
        else:
            r = self.rate
            out["measured"] = [round(r.lo, 4), None if math.isinf(r.hi) else round(r.hi, 4)]
            out.update(samples=r.samples, wall_s=round(r.wall_s, 4), vehicle_s=round(r.vehicle_s, 4),
                       step_s=r.step_s)
        out.update(self.extra)
        return out


def _g(x: float) -> str:
    return f"{x:.3g}"


def _nice(lo: float, hi: float) -> Optional[float]:
    """The roundest number in ``[lo, hi]`` (an integer if one fits, nearest the middle), or
    ``None`` when the interval is too wide to name one rate (``hi > 1.25 lo``)."""
    if not (lo > 0 and math.isfinite(hi)) or hi > 1.25 * lo:
        return None
    mid = (lo + hi) / 2
    for digits in range(0, 4):
        scale = 10 ** digits
        best = round(mid * scale) / scale
        if lo <= best <= hi and best > 0:
            return best
    return mid


def rate_text(r: Rate) -> str:
    """``×20`` when the interval is narrow; ``about ×19`` (its central estimate) when the
    interval is bounded but wider; ``at most ×2.5`` or ``at least ×3`` when one side is open."""
    nice = _nice(r.lo, r.hi)
    if nice is not None:
        return f"×{_g(nice)}"
    if r.lo > 0 and math.isfinite(r.hi) and r.lo <= r.central <= r.hi:
        return f"about ×{_g(r.central)}"
    if r.lo <= 0:
        return "faster than any bound" if math.isinf(r.hi) else f"at most ×{_g(r.hi)}"
    if math.isinf(r.hi):
        return f"at least ×{_g(r.lo)}"
    return f"between ×{_g(r.lo)} and ×{_g(r.hi)}"


def gprmc_clock(time: str, date: str = "") -> Optional[tuple[float, float]]:
    """``(seconds, resolution)`` of a ``$GPRMC`` time ``hhmmss[.s…]`` (with its date ``ddmmyy``
    the seconds are since the Unix epoch, else since midnight); ``None`` if it holds no time."""
    t = time.strip()
    if len(t) < 6 or not t[:6].isdigit():
        return None
    frac = ""
    if len(t) > 6:
        if t[6] != "." or not t[7:].isdigit():
            return None
        frac = t[7:]
    hh, mm, ss = int(t[0:2]), int(t[2:4]), int(t[4:6])
    if hh > 23 or mm > 59 or ss > 60:
        return None
    seconds = hh * 3600 + mm * 60 + ss + (int(frac) / 10 ** len(frac) if frac else 0.0)
    resolution = 10.0 ** -len(frac)
    d = date.strip()
    if len(d) == 6 and d.isdigit():
        try:
            day = datetime(2000 + int(d[4:6]), int(d[2:4]), int(d[0:2]), tzinfo=timezone.utc)
        except ValueError:
            return seconds, resolution
        seconds += day.timestamp()
    return seconds, resolution


def _unwrap(values: list[float]) -> list[float]:
    """Times of day that pass midnight keep counting (a reading without a date)."""
    out, offset = [], 0.0
    for i, v in enumerate(values):
        if i and v + offset < out[-1] - _DAY / 2:
            offset += _DAY
        out.append(v + offset)
    return out


def measure(samples: Sequence[Sample]) -> Rate | str:
    """The rate interval (module docstring), or why the samples give none."""
    if len(samples) < 2:
        return f"{len(samples)} reading(s) of the vehicle's time"
    times = _unwrap([s.vehicle_s for s in samples]) if max(s.vehicle_s for s in samples) <= _DAY + 1 else \
        [s.vehicle_s for s in samples]
    steps = [b - a for a, b in zip(times, times[1:])]
    if any(st < 0 for st in steps):
        return "the vehicle's time went backwards between two readings"
    moved = [st for st in steps if st > 0]
    first, last = samples[0], samples[-1]
    if not moved:
        return (f"the vehicle's time did not change in {last.recv - first.sent:.2f} s "
                f"({len(samples)} readings; a time held from the last fix?)")
    stood_still = len(moved) < len(steps)
    q = max([s.resolution for s in samples] + [max(moved) if stood_still else min(moved)])
    dt = times[-1] - times[0]
    outer = last.recv - first.sent
    inner = last.sent - first.recv
    lo = max(0.0, dt - q) / outer if outer > 0 else 0.0
    hi = (dt + q) / inner if inner > 0 else math.inf
    mid_wall = (last.sent + last.recv) / 2 - (first.sent + first.recv) / 2
    return Rate(lo=lo, hi=hi, samples=len(samples), wall_s=mid_wall, vehicle_s=dt, step_s=round(q, 6))


def not_measured(declared: float, reason: str, **extra) -> ClockCheck:
    return ClockCheck("not-measured", declared, None, reason, extra=dict(extra))


def judge_rate(samples: Sequence[Sample], declared: float, factor: float = CLEAR_FACTOR) -> ClockCheck:
    """Measure and decide (module docstring)."""
    got = measure(samples)
    if isinstance(got, str):
        return not_measured(declared, got)
    if got.lo > declared * factor or got.hi < declared / factor:
        status = "mismatch" if len(samples) >= MIN_SAMPLES else "unresolved"
    elif got.lo >= declared / factor and got.hi <= declared * factor:
        status = "consistent"
    else:
        status = "unresolved"
    return ClockCheck(status, declared, got, factor=factor)
