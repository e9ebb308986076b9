"""The line budget: what the serial line costs an observer, and the durations it can time.

A tester chooses durations — servo and primitive timeouts, ``$OPK`` parks, park times on queued
waypoints, the waits between two commands — and the observer must be able to time every one of
them (RH-TIM-1) on the line the run uses, at the declared time scale ``k`` (RH-TIM-2). The line
is not free: a report takes its transmit time at the baud to arrive, the vehicle may answer a
command up to the ACK window after its last byte (RH-ACK-2), and the host stamps what it reads a
little late. In vehicle time all of it is multiplied by ``k``: at ×20 a 0.6 s reply is 12 vehicle
seconds. :class:`LineBudget` holds what the line was measured to cost (or, before it was
measured, a stated assumption) and turns it into:

* :attr:`LineBudget.rtt_s` — wall seconds from writing a poll (``$OSD,S``) until its report has
  arrived: the poll's transmit time, the vehicle's reply latency, the report's and its ``$ACK``'s
  transmit time, the host's jitter;
* :attr:`LineBudget.observe_v` — vehicle seconds by which one report and the command that armed
  a timer are uncertain: half the report's transmit time (it shows the state the instant it was
  sent, which its arrival bounds less its own transmit time), the ``$ACK``'s transmit time (the
  timer starts as the ACK goes out, RH-RD-15), twice the jitter and timestamp step. The latency
  is *not* in it: the judge times every observation from the reply instant, whatever the latency
  (:mod:`helmcheck.judge.vehicle.answers`);
* :attr:`LineBudget.poll_v` — vehicle seconds between two reports when polling closely: one
  round trip and the tester's pause;
* :meth:`LineBudget.timeable` — can the observer time a duration ``d``? The bracket of a timer's
  transition (:func:`helmcheck.judge.vehicle.brackets.bracket`) passes when the last report of
  the state before and the first of the state after lie within ``d / 2`` of the deadline's
  tolerance band, its own uncertainty included; with reports :attr:`poll_v` apart that is
  ``max(0, poll_v − tol(d)) + observe_v ≤ d / 2`` (with :data:`MARGIN`). A state the case must
  see before acting — a control it just took — must also outlast the confirming poll:
  ``d − tol(d) − observe_v ≥ hold_v``;
* :meth:`LineBudget.shortest` — the shortest whole number of seconds in a range that is
  timeable; ``None`` when none is (the case is then NOT-TESTED before it runs, with
  :meth:`LineBudget.advice`: the time scale, or the baud, at which it would be);
* :meth:`LineBudget.precision_v` — the widened RH-TIM-1 tolerance a duration is judged with on
  this line: the nominal ``max(0.5 s, 5 %)``, the observer's uncertainty and the spacing of the
  reports that sample the deadline (a transition later than that is certain to be seen as late);
  :meth:`LineBudget.widening_v` what is added to the nominal, :meth:`LineBudget.nominal_scale` the
  time scale at which that is at most :data:`NOMINAL_WIDENING_S` (``--precision nominal``);
* :attr:`LineBudget.spread_s` — how much later one line may be answered than another written with
  it (the latencies' spread): what a lockout's burst of commands after ``$OXFLT`` must fit in.

The planning latency is the largest reply latency measured so far with a margin
(:func:`planning_latency`), never more than the ACK window (a slower answer is itself a finding,
RH-ACK-2). Decisions (the profile is silent), shown in reports: :data:`MARGIN` = 1.25 on every
uncertainty a choice rests on; :data:`POLL_PAUSE_S` = 0.01 s between close polls; a report of
:data:`OSI_BYTES` bytes until one is measured; the host's jitter is the larger of
:data:`~helmcheck.judge.timing.JITTER_S` and what the host was measured to add.

The budget is a record fact: the tester writes it to the wire log as a ``line budget:`` note
(:meth:`LineBudget.note`, :func:`parse_budget`), so an offline check of the log uses the same
jitter as the live judge and the report shows the line the verdicts were reached on.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, replace
from typing import Iterable, Optional

from ..grammar.wirelog import transmit_time
from ..model.timers import tolerance
from .timing import JITTER_S

__all__ = ["LineBudget", "MARGIN", "POLL_PAUSE_S", "OSI_BYTES", "POLL_BYTES", "ACK_BYTES", "planning_latency",
           "planning_spread", "NOMINAL_WIDENING_S", "from_settings",
           "parse_budget", "BAUDS", "assumed"]

#: Every uncertainty a tester's choice rests on is taken 1.25 times (a choice that only just fits
#: fails on the next slow report).
MARGIN = 1.25
#: Wall seconds the tester pauses between two close polls.
POLL_PAUSE_S = 0.01
#: Bytes of an ``$OSI`` report (rh5, 21 fields) until the vehicle's own are measured.
OSI_BYTES = 170
#: ``$OSD,S*27`` CR LF, and an ``$ACK,8,0,0*hh`` CR LF.
POLL_BYTES = 11
ACK_BYTES = 15
#: Timing judged to *nominal precision*: what the observer adds to RH-TIM-1's tolerance is at most
#: this (vehicle seconds), so a duration off by more than the tolerance and 0.3 s is certain to fail.
#: Coarser than that a timing PASS says how coarse (:meth:`LineBudget.nominal_scale`, ``--precision``).
NOMINAL_WIDENING_S = 0.3
#: The baud rates RH-FRM-9 names, for advice.
BAUDS = (9600, 19200, 57600, 115200)
#: The reply latency assumed before the link check has measured one (wall seconds).
ASSUMED_LATENCY_S = 0.05


def planning_spread(samples: Iterable[float], window_s: float) -> float:
    """How much later than another a line may be answered: the measured spread a tenth more and
    10 ms (:func:`planning_latency`'s rule), never more than the ACK window."""
    xs = [x for x in samples if x == x]
    if not xs:
        return min(window_s, ASSUMED_LATENCY_S * 1.1 + 0.01)
    return min(window_s, (max(xs) - min(xs)) * 1.1 + 0.01)


def planning_latency(samples: Iterable[float], window_s: float) -> float:
    """The reply latency a tester plans with: the largest measured and a tenth more, and 10 ms,
    never more than the ACK window (RH-ACK-2)."""
    worst = max((x for x in samples if x == x), default=ASSUMED_LATENCY_S)
    return min(window_s, max(0.0, worst) * 1.1 + 0.01)


@dataclass(frozen=True)
class LineBudget:
    """What the line costs (module docstring). Wall seconds unless named ``_v``."""

    k: float
    baud: int
    latency_s: float  #: the planning reply latency (:func:`planning_latency`)
    jitter_s: float = JITTER_S
    #: how much later one line may be answered than the line before it (the spread of the measured
    #: latencies, planned like the latency): what separates two lines written together, such as
    #: an ``$OXFLT`` and the commands after it (RH-ACK-6: in arrival order)
    spread_s: float = ASSUMED_LATENCY_S
    osi_bytes: int = OSI_BYTES
    resolution: float = 1e-6
    latency_p50: Optional[float] = None  #: measured, for the report
    latency_p99: Optional[float] = None
    samples: int = 0
    measured: bool = False

    # ------------------------------------------------------------------ the line
    def tx(self, nbytes: int) -> float:
        return transmit_time(nbytes, self.baud)

    @property
    def rtt_s(self) -> float:
        return self.tx(POLL_BYTES) + self.latency_s + self.tx(self.osi_bytes + ACK_BYTES) + self.jitter_s

    @property
    def observe_v(self) -> float:
        report = self.tx(self.osi_bytes) / 2 + self.jitter_s + self.resolution
        arming = self.tx(ACK_BYTES) + self.jitter_s + self.resolution
        return self.k * (report + arming)

    @property
    def poll_v(self) -> float:
        return self.k * (self.rtt_s + POLL_PAUSE_S)

    @property
    def hold_v(self) -> float:
        """Vehicle seconds from a command's ``$ACK`` to the report that confirms what it did."""
        return MARGIN * (self.k * self.rtt_s + self.observe_v)

    @property
    def command_v(self) -> float:
        """Vehicle seconds from writing a command until the vehicle has acted on it (its ACK out):
        the planning latency already has its margin."""
        return self.k * (self.tx(POLL_BYTES) + self.latency_s + self.jitter_s)

    # ------------------------------------------------------------------ durations
    def timeable(self, d: float, hold: bool = True, unseen_start: bool = False) -> bool:
        """Can the observer time a duration of ``d`` vehicle seconds (module docstring)?
        ``unseen_start``: it starts with an event no report shows (on station at an ``$OPK``
        position or a queued waypoint), placed between two reports: their spacing widens it."""
        tol = tolerance(d)
        own = MARGIN * (self.observe_v + (self.poll_v if unseen_start else 0.0))
        if max(0.0, MARGIN * self.poll_v - tol) + own > d / 2:
            return False
        return not hold or d - tol - own >= self.hold_v

    def shortest(self, lo: float, hi: float, hold: bool = True, at_least: float = 0.0,
                 unseen_start: bool = False) -> Optional[int]:
        """The shortest whole number of seconds in ``[lo, hi]`` (and ``≥ at_least``) that
        :meth:`timeable` accepts, or ``None``."""
        start = max(int(math.ceil(lo)), int(math.ceil(at_least)))
        d = max(1, start)
        while d <= hi:  # whole seconds, in steps that grow with d (a park may be a day long)
            if self.timeable(d, hold, unseen_start):
                return d
            d += max(1, d // 50)
        return None

    def gap_v(self, d: float) -> float:
        """Vehicle seconds two deadlines ``d`` long must lie apart to be told apart: each one's
        tolerance and the observer's uncertainty, and a report between them."""
        return 2 * (tolerance(d) + MARGIN * self.observe_v) + MARGIN * self.poll_v

    def precision_v(self, d: float) -> float:
        """The widened tolerance a duration ``d`` is judged with here (module docstring)."""
        return tolerance(d) + self.observe_v + self.poll_v

    def widening_v(self) -> float:
        """What the observer adds to RH-TIM-1's tolerance on this line (:meth:`precision_v` less
        the tolerance): a duration off by more than the tolerance and this is certain to fail."""
        return self.observe_v + self.poll_v

    def nominal_scale(self) -> Optional[float]:
        """The largest whole time scale (at most this one) at which the observer judges durations to
        nominal precision (:data:`NOMINAL_WIDENING_S`) on this line, or None (not even at x1). The
        line's typical reply (its 99th percentile, when measured) counts here, not one slow
        exchange: it is advice on where to run, not a duration a case rests on."""
        typical = self if self.latency_p99 is None else replace(
            self, latency_s=min(self.latency_s, self.latency_p99 * 1.1 + 0.01))
        k = math.floor(self.k)
        while k >= 1:
            if typical.at(k=float(k)).widening_v() <= NOMINAL_WIDENING_S:
                return float(k)
            k -= 1
        return None

    def at(self, k: Optional[float] = None, baud: Optional[int] = None) -> "LineBudget":
        """The same line at another time scale or baud (the latency and the host stay)."""
        return replace(self, k=self.k if k is None else k, baud=self.baud if baud is None else baud)

    def advice(self, need: float, hi: float) -> str:
        """What would let a duration of at least ``need`` vehicle seconds, at most ``hi``, be timed:
        the largest time scale (a whole number, or a tenth below 1) and the lowest baud."""
        ks = []
        k = self.k
        while k > 0.1:
            k = math.floor(k) - 1 if k > 2 else round(k - 0.1, 1)
            if k <= 0:
                break
            if self.at(k=k).shortest(need, hi) is not None:
                ks.append(k)
                break
        parts = []
        if ks:
            parts.append(f"--time-scale {ks[0]:g}")
        for b in BAUDS:
            if b > self.baud and self.at(baud=b).shortest(need, hi) is not None:
                parts.append(f"--baud {b} (if the vehicle's line allows it)")
                break
        return " or ".join(parts) if parts else "a vehicle that answers sooner"

    # ------------------------------------------------------------------ the record
    def describe(self) -> str:
        """One line for people: the line and what it costs in vehicle time."""
        lat = (f"reply p50 {self.latency_p50:.3f} s, p99 {self.latency_p99:.3f} s ({self.samples} probes)"
               if self.latency_p99 is not None else f"reply latency assumed {self.latency_s:.3f} s")
        return (f"{self.baud} baud, {lat}, host jitter {self.jitter_s:.3f} s → observer uncertainty "
                f"{self.observe_v:.1f} + {self.poll_v:.1f} vehicle s between reports at ×{self.k:g}")

    def note(self) -> str:
        """The ``line budget:`` wire-log note (:func:`parse_budget` reads it back)."""
        p50 = "-" if self.latency_p50 is None else f"{self.latency_p50:.4f}"
        p99 = "-" if self.latency_p99 is None else f"{self.latency_p99:.4f}"
        return (f"line budget: baud {self.baud} latency {self.latency_s:.4f} p50 {p50} p99 {p99} "
                f"samples {self.samples} jitter {self.jitter_s:.4f} osi {self.osi_bytes} k {self.k:g} "
                f"spread {self.spread_s:.4f}")

    def as_dict(self) -> dict:
        """For ``results.json`` ``settings.line_budget``."""
        return {"baud": self.baud, "time_scale": self.k, "measured": self.measured,
                "latency_planned_s": round(self.latency_s, 4), "spread_planned_s": round(self.spread_s, 4),
                "latency_p50_s": None if self.latency_p50 is None else round(self.latency_p50, 4),
                "latency_p99_s": None if self.latency_p99 is None else round(self.latency_p99, 4),
                "samples": self.samples, "jitter_s": round(self.jitter_s, 4), "osi_bytes": self.osi_bytes,
                "round_trip_s": round(self.rtt_s, 4), "observe_v": round(self.observe_v, 3),
                "poll_v": round(self.poll_v, 3), "describe": self.describe()}


def from_settings(d: dict) -> Optional[LineBudget]:
    """The budget ``results.json`` recorded (``settings.line_budget``, :meth:`LineBudget.as_dict`)."""
    try:
        return LineBudget(k=float(d["time_scale"]), baud=int(d["baud"]), latency_s=float(d["latency_planned_s"]),
                          jitter_s=float(d["jitter_s"]), osi_bytes=int(d["osi_bytes"]),
                          spread_s=float(d.get("spread_planned_s", d["latency_planned_s"])), measured=True,
                          latency_p50=d.get("latency_p50_s"), latency_p99=d.get("latency_p99_s"),
                          samples=int(d.get("samples", 0)))
    except (KeyError, TypeError, ValueError):
        return None


def assumed(k: float, baud: int, window_s: float = 1.0) -> LineBudget:
    """The budget before the link check: :data:`ASSUMED_LATENCY_S`, :data:`JITTER_S`."""
    return LineBudget(k=k, baud=baud, latency_s=planning_latency((), window_s))


_NOTE = re.compile(r"^line budget: baud (\d+) latency ([0-9.]+) p50 (\S+) p99 (\S+) samples (\d+) "
                   r"jitter ([0-9.]+) osi (\d+) k ([0-9.eE+-]+)(?: spread ([0-9.]+))?")


def parse_budget(text: str) -> Optional[LineBudget]:
    """The :class:`LineBudget` of a ``line budget:`` note, or ``None``."""
    m = _NOTE.match(text)
    if not m:
        return None

    def opt(x: str) -> Optional[float]:
        return None if x == "-" else float(x)
    return LineBudget(k=float(m.group(8)), baud=int(m.group(1)), latency_s=float(m.group(2)),
                      jitter_s=float(m.group(6)), osi_bytes=int(m.group(7)), latency_p50=opt(m.group(3)),
                      latency_p99=opt(m.group(4)), samples=int(m.group(5)), measured=True,
                      spread_s=float(m.group(9)) if m.group(9) else float(m.group(2)))
