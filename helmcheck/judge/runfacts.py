"""Run facts: what a run's verdict depends on besides the judges' findings, as wire-log notes.

A clause verdict is the ledger's (:mod:`.ledger`); the run verdict and the certificate flag
also depend on how the run went. Every such fact is a note in the wire log, written by the
driver that knows it, so that ``helmcheck verify`` (and ``check-log``) read the very facts the
live run was assembled from (:func:`helmcheck.reports.assemble.assemble`). The notes (their words
are part of the wire-log format, ``docs/contracts.md``):

==========================================  ===================================================
``selection: RH-SRV-*,RH-INT-*``            the run selected only these clauses (``--select``):
                                            the others are NOT-TESTED "not selected", except a
                                            violation observed anyway, which stands
``not judged RH-X,RH-Y: <reason>``          whatever was observed, these clauses are not judged
                                            (NOT-TESTED with the reason), except a violation,
                                            which stands (a backseat whose exit cut short the
                                            scenarios exercising them, one that never connected)
``process: {…}``                            the implementation under test helmcheck started
                                            (``--exec``), as it ended: the ``process`` object of
                                            ``results.json`` as JSON (exit code, signal, time,
                                            last output, ``ended_early``)
``run partial: <reason>``                   the run was cut short before it finished
                                            (interrupted, never connected, …): it cannot
                                            certify a pass
``run resumed: <what>``                     an interrupted run goes on: the ``run partial`` and
                                            ``process`` facts before it no longer hold
``line model: clean|noisy — <why>``         whether the link could damage bytes
                                            (:mod:`.linemodel`); the last one holds; none:
                                            noisy, "the record does not say"
``not claimed RH-X,RH-Y in CASE: <reason>``  these clauses' observations in that case (a
                                            backseat scenario whose moment did not reach the
                                            backseat in time) are left out of the claim: the
                                            verdict is made from the rest, a violation in it
                                            standing (:meth:`.Ledger.unclaim`)
``line overrun: <what>``                    the backseat's requests asked for more replies than
                                            the line carries: a remark the run verdict's reason
                                            ends with (it changes no verdict; the last holds)
==========================================  ===================================================

(Bench safety refusing a step is a ``not tested RH-X: …`` note of :mod:`.wire`, booked by the
observers like any finding; a log with one direction only is a fact of the log itself.)

:class:`RunFacts` collects the facts from notes — fed live like an observer
(:meth:`RunFacts.feed`), or read back from a wire log (:meth:`RunFacts.from_wire_log`) — and
books the clause facts into a ledger (:meth:`RunFacts.book`, :meth:`.Ledger.withdraw`). The
``*_note`` functions make the notes' text.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass, field
from fnmatch import fnmatchcase
from pathlib import Path
from typing import Any, Iterable, Mapping, Optional

from ..grammar.wirelog import NOTE, read_wire_log
from .linemodel import UNKNOWN, LineModel, read_line_note

__all__ = ["RunFacts", "selection_note", "not_judged_note", "process_note", "partial_note", "not_claimed_note",
           "overrun_note", "NOT_SELECTED", "NOT_SELECTED_OBSERVED", "OVERRUN", "UNEXERCISED"]

NOT_SELECTED = "not selected (--select)"
NOT_SELECTED_OBSERVED = "not selected, but observed: "

_SELECTION = "selection: "
_PROCESS = "process: "
_PARTIAL = "run partial: "
_RESUMED = "run resumed: "
_NOT_JUDGED = re.compile(r"^not judged ((?:RH-[A-Z]+-\d+,?)+): (.*)$")
_NOT_CLAIMED = re.compile(r"^not claimed ((?:RH-[A-Z]+-\d+,?)+) in (\S+): (.*)$")
OVERRUN = "line overrun: "
#: How a ``run partial`` reason begins when the run was not cut short but a scenario's moment did
#: not reach the backseat (its observations not claimed): the run finished, it is not a certificate.
UNEXERCISED = "not every scenario was exercised: "


def selection_note(patterns: Iterable[str]) -> str:
    return _SELECTION + ",".join(patterns)


def not_judged_note(clauses: Iterable[str], reason: str) -> str:
    return f"not judged {','.join(clauses)}: {reason}".replace("\n", " ")


def process_note(process: Mapping[str, Any]) -> str:
    return _PROCESS + json.dumps(dict(process), sort_keys=True, ensure_ascii=True, separators=(",", ":"))


def partial_note(reason: str) -> str:
    return (_PARTIAL + reason).replace("\n", " ")


def not_claimed_note(clauses: Iterable[str], case: str, reason: str) -> str:
    return f"not claimed {','.join(clauses)} in {case}: {reason}".replace("\n", " ")


def overrun_note(text: str) -> str:
    return (OVERRUN + text).replace("\n", " ")


@dataclass
class RunFacts:
    """The run facts of one record (module docstring)."""

    select: tuple[str, ...] = ()  #: ``--select`` patterns; empty: every clause was selected
    not_judged: dict[str, str] = field(default_factory=dict)  #: clause → reason (the first note holds)
    process: Optional[dict] = None  #: the ``process`` object, when helmcheck started the implementation
    partial: Optional[str] = None  #: why the run was cut short, or None
    unreadable: list[str] = field(default_factory=list)  #: fact notes that could not be read
    line_model: LineModel = UNKNOWN  #: whether the link could damage bytes (:mod:`.linemodel`)
    #: (clause, case) -> why its observations there are not claimed (the first note holds)
    not_claimed: dict[tuple[str, str], str] = field(default_factory=dict)
    overrun: Optional[str] = None  #: the line overrun, in words (``line overrun:``), or None

    # ------------------------------------------------------------------ reading
    def feed(self, ev: Any) -> None:
        """An observer's ``feed``: a wire event (only notes matter)."""
        if ev.dir == NOTE:
            self.note(ev.note)

    def note(self, text: str) -> bool:
        """Take one note; True when it is a run fact."""
        if text.startswith(_SELECTION):
            self.select = tuple(p for p in text[len(_SELECTION):].strip().split(",") if p)
            return True
        if text.startswith(_PROCESS):
            try:
                doc = json.loads(text[len(_PROCESS):])
            except ValueError:
                doc = None
            if isinstance(doc, dict):
                self.process = doc
            else:
                self.unreadable.append(text[:120])
            return True
        if text.startswith(_PARTIAL):
            self.partial = text[len(_PARTIAL):]
            return True
        model = read_line_note(text)
        if model is not None:
            self.line_model = model
            return True
        if text.startswith(_RESUMED):
            self.partial = None
            self.process = None
            return True
        m = _NOT_JUDGED.match(text)
        if m:
            for cid in filter(None, m.group(1).split(",")):
                self.not_judged.setdefault(cid, m.group(2))
            return True
        m = _NOT_CLAIMED.match(text)
        if m:
            for cid in filter(None, m.group(1).split(",")):
                self.not_claimed.setdefault((cid, m.group(2)), m.group(3))
            return True
        if text.startswith(OVERRUN):
            self.overrun = text[len(OVERRUN):]
            return True
        return False

    @classmethod
    def from_wire_log(cls, path: Path | str) -> "RunFacts":
        """The facts of a wire log (format 1, read by :func:`helmcheck.grammar.wirelog.read_wire_log`);
        ``OSError`` if it cannot be read. Only notes are looked at; any other line is skipped."""
        facts = cls()
        with open(path, "rb") as f:
            for rec in read_wire_log(f):
                if rec.dir == NOTE:
                    facts.note(rec.note)
        return facts

    # ------------------------------------------------------------------ using
    def selected(self, cid: str) -> bool:
        return not self.select or any(fnmatchcase(cid, p) for p in self.select)

    @property
    def interrupted(self) -> bool:
        """The run was cut short (not merely a scenario left unexercised, :data:`UNEXERCISED`)."""
        return self.partial is not None and not self.partial.startswith(UNEXERCISED)

    @property
    def ended_early(self) -> bool:
        return isinstance(self.process, dict) and self.process.get("ended_early") is True

    def book(self, ledger: Any) -> None:
        """Book the clause facts into *ledger* (:meth:`~helmcheck.judge.ledger.Ledger.withdraw`):
        a clause not selected, a clause not judged. Booking again changes nothing."""
        for cid in ledger.order:
            if not self.selected(cid):
                ledger.withdraw(cid, NOT_SELECTED, NOT_SELECTED_OBSERVED)
            elif cid in self.not_judged:
                ledger.withdraw(cid, self.not_judged[cid])
        for (cid, case), why in self.not_claimed.items():
            ledger.unclaim(cid, case, why)
