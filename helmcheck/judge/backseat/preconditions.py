"""RH-BS-3: a backseat respects the preconditions it can know.

Which commands: the ones the clause names, each with the state it names — "``$OLOGL`` and
``$ORWSET`` only before starting a mission; ``$OMS``, ``$OJW``, ``$OPK``, ``$OMW`` only while the
vehicle reports a running mission" (:data:`JUDGED_STOPPED`, :data:`JUDGED_RUNNING`; ``$OMW`` in
every form). The transition table shows preconditions of other commands too (``$OLOGD`` needs a
running mission, ``$OMLOAD`` and ``$OMSTART`` none: :data:`~helmcheck.judge.facts.NEEDS_RUNNING`,
:data:`~helmcheck.judge.facts.NEEDS_STOPPED`), but whether the clause's list is exhaustive is a
reading its words leave open: read as a list of examples it would fail a backseat for an
``$OLOGD`` after the mission's end, read as the list it is it would not. A FAIL needs the
profile's words, so both readings are accepted: only the commands the clause names are judged
(docs/choices.md, "Backseat judging"). The vehicle still refuses the others (RH-ACK-4); that
refusal is the vehicle's clause, not the backseat's.

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

from ..facts import COMMAND_ID_OF_EVENT, NEEDS_RUNNING, NEEDS_STOPPED
from ..ledger import Ledger
from .common import SentLine, Settings
from .knowledge import Pending, StateReports

__all__ = ["Preconditions", "JUDGED_RUNNING", "JUDGED_STOPPED", "LISTED"]

#: The commands RH-BS-3 names, by the state it names for them (module docstring).
LISTED = {"running": ("OMS", "OJW", "OPK", "OMW"), "stopped": ("OLOGL", "ORWSET")}
#: Command events judged as needing a running mission: the clause's four, in every form.
JUDGED_RUNNING = frozenset(e for e in NEEDS_RUNNING if COMMAND_ID_OF_EVENT[e] in LISTED["running"])
#: Command events judged as needing no running mission ("only before starting a mission").
JUDGED_STOPPED = frozenset(e for e in NEEDS_STOPPED if COMMAND_ID_OF_EVENT[e] in LISTED["stopped"])


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
        if ev in JUDGED_RUNNING:
            need, starter = True, "OMSTART"
        elif ev in JUDGED_STOPPED:
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
        r = self.s.reaction_s
        against = self.reports.contradicts(t - r, t, need)
        if against is None:
            return
        if not against:
            self._ok(line, f"${line.sid} sent while the vehicle reported "
                           f"{'a running mission' if need else 'no running mission'}, as the clause asks", case)
            return
        known = self.reports.known(t - r)
        ago = f"{t - known[0]:.2f} s" if known is not None else f"at least {r:g} s"
        if need:
            why = (f"${line.sid} sent {ago} after the vehicle's report of no running mission had reached the "
                   f"backseat (it is given {r:g} s to act on a report); RH-BS-3 allows ${line.sid} only while the "
                   f"vehicle reports a running mission")
        else:
            why = (f"${line.sid} sent {ago} after the vehicle's report of a running mission had reached the "
                   f"backseat (it is given {r:g} s to act on a report); RH-BS-3 allows ${line.sid} only before "
                   f"a mission starts")
        broken = self.reports.uncertain(t - r, t)
        if broken is not None:  # a faulty line's, maybe: never a FAIL on it (docs/contracts.md)
            who = ("the vehicle sent a broken line" if self.s.clean else "a vehicle line the line broke")
            self.ledger.inconclusive("RH-BS-3", f"{why}; but {who} that reached the backseat at {broken:.2f} s, after "
                                                f"the last whole report of that state: the backseat may have read a "
                                                f"change in it", [line.evidence()], case)
            return
        self.ledger.failed("RH-BS-3", why, [line.evidence()], case)

    def _ok(self, line: SentLine, reason: str, case: str) -> None:
        if self._passed:
            self.ledger.passed("RH-BS-3", case=case)
        else:
            self._passed = True
            self.ledger.passed("RH-BS-3", reason, [line.evidence()], case)
