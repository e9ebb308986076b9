"""RH-BS-3: a backseat respects the preconditions it can know.

Which commands: those the transition table refuses in ``S`` but accepts while a mission runs
(:data:`~helmcheck.judge.facts.NEEDS_RUNNING`: ``$OMS``, ``$OJW``, ``$OPK``, ``$OMW`` in every
form — and ``$OLOGD``) and those it accepts in ``S`` but refuses while one runs
(:data:`~helmcheck.judge.facts.NEEDS_STOPPED`: ``$OLOGL``, ``$ORWSET`` — and ``$OMLOAD``,
``$OMSTART``). The clause names six; the table shows these preconditions too, and a backseat
can know them all from the same reports, so all are judged.

When: a command is judged against every state report
(:class:`~.knowledge.StateReports`) that had fully arrived ``reaction_s`` (profile, default
0.25 s) before the command's first byte — the last of them is what the backseat knew. It
fails when that report contradicts the precondition and no later report saying what the
command needs had been *sent* before the command's first byte (the backseat may act on a report
at once; a report counts as known from its latest possible arrival, and as a possible reason
from its earliest, so only certain violations fail). Nothing is judged before the first report
has arrived.

Behind its own start: a command sent while the backseat's own ``$OMSTART`` (for a command that
needs a running mission) or ``$OMSTOP`` (for one that needs none) still waits for its
``$ACK`` is judged by that command's outcome: accepted, the precondition was met; refused, the
command is judged as above, at the time it was sent. If the answer never comes (the vehicle
fell silent, the run ended) it is not judged.
"""

from __future__ import annotations

from ..facts import NEEDS_RUNNING, NEEDS_STOPPED
from ..ledger import Ledger
from .common import SentLine, Settings
from .knowledge import Pending, StateReports

__all__ = ["Preconditions"]


class Preconditions:
    """RH-BS-3 (module docstring)."""

    def __init__(self, settings: Settings, ledger: Ledger, reports: StateReports, pending: Pending):
        self.s = settings
        self.ledger = ledger
        self.reports = reports
        self.pending = pending
        self._passed = False

    def command(self, line: SentLine) -> None:
        """A decoded command from the backseat."""
        ev = line.event
        if ev in NEEDS_RUNNING:
            need, starter = True, "OMSTART"
        elif ev in NEEDS_STOPPED:
            need, starter = False, "OMSTOP"
        else:
            return
        behind = self.pending.latest(starter)
        if behind is not None and behind is not line:
            if behind.deferred is None:
                behind.deferred = []
            behind.deferred.append((line, need, self.s.case))
            return
        self._judge(line, need, self.s.case)

    def answered(self, line: SentLine, accepted: bool) -> None:
        """The ``$ACK`` of ``line`` arrived: judge the commands sent behind it."""
        if not line.deferred:
            return
        for waiting, need, case in line.deferred:
            if accepted:
                self._ok(waiting, f"${waiting.sid} sent behind the backseat's own "
                                  f"${line.sid}, which the vehicle accepted", case)
            else:
                self._judge(waiting, need, case)
        line.deferred = None

    def _judge(self, line: SentLine, need: bool, case: str) -> None:
        t = line.t
        against = self.reports.contradicts(t - self.s.reaction_s, t, need)
        if against is None:
            return
        if not against:
            self._ok(line, f"${line.sid} while the vehicle reported "
                           f"{'a running mission' if need else 'no running mission'}", case)
            return
        if need:
            why = (f"${line.sid} sent while the vehicle reported no running mission (known for at "
                   f"least {self.s.reaction_s:g} s)")
        else:
            why = (f"${line.sid} sent while the vehicle reported a running mission (only before a "
                   f"start; known for at least {self.s.reaction_s:g} s)")
        broken = self.reports.uncertain(t - self.s.reaction_s, t)
        if broken is not None:  # a faulty line's, maybe: never a FAIL on it (docs/contracts.md)
            self.ledger.inconclusive("RH-BS-3", f"{why}; but a vehicle line the line broke reached the backseat at "
                                                f"{broken:.2f} s, after the last whole report of that state: the "
                                                f"backseat may have read a change in it (a faulty line's, maybe)",
                                     [line.evidence()], case)
            return
        self.ledger.failed("RH-BS-3", why, [line.evidence()], case)

    def _ok(self, line: SentLine, reason: str, case: str) -> None:
        if self._passed:
            self.ledger.passed("RH-BS-3", case=case)
        else:
            self._passed = True
            self.ledger.passed("RH-BS-3", reason, [line.evidence()], case)
