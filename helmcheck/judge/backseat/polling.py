"""RH-BS-8 (SHOULD): while active, the backseat polls ``$OSD`` for state at least every 5 s.

*Active* (decision): from the first byte the backseat sends to the end of the run (``certify
backseat``) or of the log (``check-log``) — a backseat that stops talking is exactly what the
clause is about. *A poll* is a well-formed ``$OSD`` whose letters include ``S`` (answered or
not). The gaps judged: first byte → first poll, poll → poll, and last poll → end of the run,
each by :func:`~.common.gap` against 5 s plus the observer's
:data:`~helmcheck.judge.timing.JITTER_S` (a poll may have been seen late). A gap is judged once,
when it closes. After a ``run resumed`` note (a gap in what the record saw) the interval starts
again at the note: one that spans what nobody saw is not judged. Polling is wall time and never scales (RH-TIM-2).
"""

from __future__ import annotations

from typing import Optional

from ..ledger import Evidence, Ledger
from ..timing import JITTER_S
from .common import INCONCLUSIVE, VIOLATION, SentLine, Settings, gap

__all__ = ["Polling", "POLL_INTERVAL_S"]

POLL_INTERVAL_S = 5.0  #: RH-BS-8


class Polling:
    """RH-BS-8 (module docstring)."""

    def __init__(self, settings: Settings, ledger: Ledger):
        self.s = settings
        self.ledger = ledger
        self._last: Optional[float] = None
        self._last_ev: Optional[Evidence] = None
        self.polls = 0
        self.max_gap = 0.0  #: the longest interval between two of its polls seen so far (its poll cycle)
        self._passed = False
        self._resumed = False  #: the interval open now began at a ``run resumed`` note

    @property
    def active(self) -> bool:
        return self._last is not None

    def start(self, t: float, ev: Evidence) -> None:
        """The backseat's first byte, at ``t``."""
        if self._last is None:
            self._last, self._last_ev = t, ev

    def sent(self, line: SentLine) -> None:
        """A decoded command from the backseat."""
        cmd = line.command
        if cmd is None or cmd.ID != "OSD" or "S" not in cmd.requested:
            return
        self.polls += 1
        if self.polls > 1 and not self._resumed:
            self.max_gap = max(self.max_gap, line.t - self._last)
        ev = line.evidence()
        self._judge(line.t, ev, "first state poll {:.2f} s after the record resumed" if self._resumed
                    else "polled for state {:.2f} s after its previous poll" if self.polls > 1
                    else "first state poll {:.2f} s after the backseat's first byte")
        self._last, self._last_ev = line.t, ev
        self._resumed = False

    def resume(self, t: float, ev: Evidence) -> None:
        """The record goes on at ``t`` after a gap it did not see (``run resumed``): the interval
        that spans the gap is not judged; the next poll is due 5 s from ``t``."""
        if self._last is not None:
            self._last, self._last_ev = t, ev
            self._resumed = True

    def close(self, t: float) -> None:
        """The run (or the log) ended at ``t``."""
        if self._last is not None:
            self._judge(t, self._last_ev, "no state poll in the last {:.2f} s of the run")

    def _judge(self, t: float, ev: Evidence, text: str) -> None:
        measured = t - self._last
        v = gap(measured, POLL_INTERVAL_S + JITTER_S, self.s.resolution)
        what = text.format(measured) + f"; RH-BS-8 asks for one at least every {POLL_INTERVAL_S:g} s"
        if v == VIOLATION:
            self.ledger.failed("RH-BS-8", what, [ev], self.s.case)
        elif v == INCONCLUSIVE:
            self.ledger.inconclusive("RH-BS-8", what + "; the timestamp step cannot tell", [ev], self.s.case)
        elif self._passed:
            self.ledger.passed("RH-BS-8", case=self.s.case)
        else:
            self._passed = True
            self.ledger.passed("RH-BS-8", what, [ev], self.s.case)
