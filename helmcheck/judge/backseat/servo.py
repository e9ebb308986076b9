"""RH-BS-6 (SHOULD): to keep servo control the backseat refreshes ``$OMS`` before its timeout runs out.

*The deadline.* An accepted ``$OMS`` holds servo control until ``timeout / time_scale`` wall
seconds after its ``$ACK`` was sent (RH-RD-15: durations start when the ACK goes out; the ACK's
record time), allowed the RH-TIM-1 tolerance ``max(0.5 s, 5 %)`` of the timeout, widened by the
observer's slack (resolution and :data:`~helmcheck.judge.timing.JITTER_S`,
:func:`~helmcheck.judge.timing.slack`), all divided by the time scale where vehicle time
(RH-TIM-2). A refresh sent in time restarts the clock from its own first byte until its own
``$ACK`` gives the real start (so a refresh held up on the line still counts); the later of the
deadlines holds.

*Which ``$OMS`` is a refresh* (the spec is silent; decision): while servo control is held, an
``$OMS`` whose first byte comes no later than one more timeout after the deadline (within
twice the timeout of the ACK, plus the tolerance) is a refresh: in time → met, after the
deadline plus tolerance → violation (servo control had lapsed). An ``$OMS`` even later starts
servo control afresh: the backseat let it lapse, which the clause does not forbid. Servo
control stops being held — nothing is judged — when the backseat sends a command that ends it
(:data:`~helmcheck.judge.facts.ENDS_SERVO`), when an ``$OMS`` is refused (the backseat cannot
keep what the vehicle will not give), when the vehicle reports ``S``, when the backseat could
know of a safety lockout (RH-RD-11 ends remote control for good), or when the vehicle falls
silent (``silence starts``: the refreshes do not reach it).
"""

from __future__ import annotations

from collections import deque
from typing import Optional

from ..facts import ENDS_SERVO
from ..ledger import Ledger
from ..timing import slack, tolerance
from .common import INCONCLUSIVE, VIOLATION, SentLine, Settings, gap

__all__ = ["ServoRefresh"]


class ServoRefresh:
    """RH-BS-6 (module docstring)."""

    def __init__(self, settings: Settings, ledger: Ledger):
        self.s = settings
        self.ledger = ledger
        self._deadline: Optional[float] = None  #: servo held until (wall), None: not held
        self._tol = 0.0
        self._timeout_wall = 0.0
        self._timeout_v = 0.0  #: the timeout the holding $OMS chose, vehicle seconds
        #: refreshes sent in time, awaiting their ACK: (first byte, deadline, tolerance, wall timeout,
        #: the timeout it chose)
        self._inflight: deque[tuple[float, float, float, float, float]] = deque()
        self._ended = float("-inf")  #: when servo control last stopped being held
        self.accepted = 0
        #: the first and the latest accepted ``$OMS`` that held servo control: (its ACK's time, the
        #: timeout it chose in wall seconds, the tolerance) — the backseat's own cycle, for a tester
        #: that waits to see it twice
        self.first_accept: Optional[tuple[float, float, float]] = None
        self.last_accept: Optional[tuple[float, float, float]] = None
        self._passed = False

    def _window(self, start: float, timeout: int) -> tuple[float, float, float]:
        k = self.s.time_scale
        tol = tolerance(timeout, slack(k, start, start, self.s.resolution)) / k
        return start + timeout / k, tol, timeout / k

    def end(self, t: float) -> None:
        """Servo control stops being held at ``t`` (module docstring); an ``$OMS`` sent before
        then that is accepted afterwards does not hold it again."""
        self._drop()
        self._ended = max(self._ended, t)

    def _drop(self) -> None:
        self._deadline = None
        self._inflight.clear()

    def sent(self, line: SentLine) -> None:
        """A decoded command from the backseat."""
        ev = line.event
        if ev in ENDS_SERVO:
            self.end(line.t)
            return
        if ev != "OMS" or self._deadline is None:
            return
        t = line.t
        late = t - self._deadline
        if late > self._timeout_wall + self._tol:
            self._drop()  # a fresh start after a lapse the backseat chose; its ACK holds it anew
            return
        v = gap(t, self._deadline + self._tol, self.s.resolution)
        k = self.s.time_scale
        chose = f"its {self._timeout_v:g} s timeout" + (f" ({self._timeout_wall:.2f} s at ×{k:g})" if k != 1 else "")
        what = (f"refreshed {-late:.2f} s before {chose} ran out" if late <= 0
                else f"refreshed {late:.2f} s after {chose} ran out")
        if v == VIOLATION:
            self.ledger.failed("RH-BS-6", what + f", beyond RH-TIM-1's tolerance of {self._tol:.2f} s: servo control "
                                                 f"had lapsed", [line.evidence()], self.s.case)
            self._drop()  # lapsed; this $OMS's own ACK holds servo control afresh
            return
        if v == INCONCLUSIVE:
            self.ledger.inconclusive("RH-BS-6", what + "; the timestamp step cannot tell whether within "
                                                       f"RH-TIM-1's tolerance of {self._tol:.2f} s",
                                     [line.evidence()], self.s.case)
        elif self._passed:
            self.ledger.passed("RH-BS-6", case=self.s.case)
        else:
            self._passed = True
            self.ledger.passed("RH-BS-6", what + ("" if late <= 0 else f", within RH-TIM-1's tolerance of "
                                                                        f"{self._tol:.2f} s"),
                               [line.evidence()], self.s.case)
        self._inflight.append((t, *self._window(t, line.command.timeout), float(line.command.timeout)))
        self._extend()

    def answered(self, line: SentLine, accepted: bool, t_ack: float) -> None:
        """The ``$ACK`` of an ``$OMS`` was sent at ``t_ack``."""
        if not accepted:
            self.end(t_ack)
            return
        self.accepted += 1
        if line.t < self._ended:
            return  # sent before servo control stopped being held
        d, tol, wall = self._window(t_ack, line.command.timeout)
        self.last_accept = (t_ack, wall, tol)
        if self.first_accept is None:
            self.first_accept = self.last_accept
        while self._inflight and self._inflight[0][0] <= line.t:
            self._inflight.popleft()
        self._deadline, self._tol, self._timeout_wall = d, tol, wall
        self._timeout_v = float(line.command.timeout)
        self._extend()

    def _extend(self) -> None:
        for _, d, tol, wall, chose in self._inflight:
            if d + tol > self._deadline + self._tol:
                self._deadline, self._tol, self._timeout_wall, self._timeout_v = d, tol, wall, chose
