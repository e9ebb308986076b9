"""RH-BS-4: the line budget — in no one-second window more bytes than the baud drains (baud/10).

The window slides over the bytes the backseat sent, each record counted at the time it was
seen (the receiver's view: the budget protects the vehicle's input). With timestamps of
resolution ``r`` two records ``d`` apart were truly between ``d - r`` and ``d + r`` apart, so
for each record:

* the bytes of the records *certainly* within one second of it (``d < 1 - r``) above the
  budget → violation (MUST: FAIL);
* else the bytes of the records *possibly* within one second (``d < 1 + r``) above it →
  INCONCLUSIVE (RH-TIM-1: timestamps too coarse to bound the window);
* else the record met the budget.

Live, ``r`` is the wire log's 1 µs; offline the log's own step — one rule for both.
"""

from __future__ import annotations

from collections import deque

from ..ledger import Evidence, Ledger
from ..timing import BITS_PER_BYTE
from .common import Settings

__all__ = ["LineBudget", "line_budget"]


def line_budget(baud: int) -> int:
    """RH-BS-4: bytes a line drains in one second, 10 bits per byte (8N1)."""
    return baud // BITS_PER_BYTE


class _Window:
    """Bytes of the latest record and of those less than ``span`` seconds before it."""

    def __init__(self, span: float):
        self.span = span
        self.q: deque[tuple[float, int]] = deque()
        self.total = 0

    def add(self, t: float, n: int) -> int:
        q = self.q
        while q and t - q[0][0] >= self.span:
            self.total -= q.popleft()[1]
        q.append((t, n))
        self.total += n
        return self.total


class LineBudget:
    """RH-BS-4 (module docstring)."""

    def __init__(self, settings: Settings, ledger: Ledger):
        self.s = settings
        self.ledger = ledger
        r = settings.resolution
        self._certain = _Window(max(0.0, 1.0 - r))
        self._possible = _Window(1.0 + r)
        self.max_window_bytes = 0
        self.bytes = 0
        self._passed = False

    @property
    def budget(self) -> int:
        return line_budget(self.s.baud)

    def record(self, t: float, n: int, ev: Evidence) -> None:
        """``n`` bytes from the backseat seen at ``t``."""
        self.bytes += n
        sure = self._certain.add(t, n)
        maybe = self._possible.add(t, n)
        self.max_window_bytes = max(self.max_window_bytes, sure)
        budget = self.budget
        if sure > budget:
            self.ledger.failed("RH-BS-4", f"{sure} bytes sent within one second, more than the {budget} a "
                                          f"{self.s.baud}-baud line drains in a second (baud/10)", [ev], self.s.case)
        elif maybe > budget:
            self.ledger.inconclusive("RH-BS-4", f"{maybe} bytes sent within one second give or take the timestamp "
                                                f"step {self.s.resolution:g} s; a {self.s.baud}-baud line drains "
                                                f"{budget} a second (baud/10)", [ev], self.s.case)
        elif self._passed:
            self.ledger.passed("RH-BS-4", case=self.s.case)
        else:
            self._passed = True
            self.ledger.passed("RH-BS-4", f"no one second held more than the {budget} bytes a {self.s.baud}-baud "
                                          f"line drains (baud/10)", [ev], self.s.case)

    def close(self) -> None:
        """The record ended: the busiest second, beside the verdict."""
        if self.bytes and self._passed:
            self.ledger.remark("RH-BS-4", f"its busiest second held {self.max_window_bytes} bytes of the "
                                          f"{self.budget} allowed.")
