"""Findings and clause verdicts: what was observed, which clause it speaks to, and the evidence.

Every check the certifier makes ends up here as an :class:`Outcome` for one clause: ``pass``,
``fail``, ``inconclusive`` or ``not-tested``, with a one-sentence reason, the case it came
from and a wire excerpt. :class:`Book` merges the outcomes of a clause into its verdict with
the TTCN-3 rule "first fail wins": precedence fail > inconclusive > pass > not-tested, and the
reason of the first outcome at the winning level is kept. A SHOULD clause that fails is
``non-strict`` (the reference profile's preamble).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Iterable, Optional

from ...clauses import clause as clause_of, vehicle_clauses

__all__ = ["Outcome", "Book", "CaseFail", "CaseInconclusive", "CaseNotTested"]

_RANK = {"not-tested": 0, "pass": 1, "inconclusive": 2, "fail": 3}


@dataclass
class Outcome:
    verdict: str
    reason: str
    case: str = ""
    evidence: list = field(default_factory=list)


class CaseFail(Exception):
    """A check failed: the case stops (the first fail is the root cause)."""

    def __init__(self, clause: str, reason: str, t0: float = 0.0, also: Iterable[str] = ()):
        super().__init__(f"{clause}: {reason}")
        self.clause, self.reason, self.t0, self.also = clause, reason, t0, tuple(also)


class CaseInconclusive(Exception):
    """The case could not be judged (link trouble, noisy timing, a start state not reached)."""

    def __init__(self, reason: str, clause: Optional[str] = None):
        super().__init__(reason)
        self.reason, self.clause = reason, clause


class CaseNotTested(Exception):
    """The case does not apply (the profile does not claim it, or the mission cannot reach it)."""

    def __init__(self, reason: str):
        super().__init__(reason)
        self.reason = reason


class Book:
    """Outcomes per clause, merged into one verdict each."""

    def __init__(self, clause_ids: Optional[Iterable[str]] = None):
        ids = list(clause_ids) if clause_ids is not None else [c.id for c in vehicle_clauses()]
        self.ids = ids
        self.outcomes: dict[str, list[Outcome]] = {cid: [] for cid in ids}
        self.counts: dict[str, int] = {cid: 0 for cid in ids}  #: passing observations

    def add(self, cid: str, verdict: str, reason: str, case: str = "", evidence: Iterable[dict] = ()) -> None:
        if cid not in self.outcomes:
            return  # a clause outside the selection
        if verdict == "fail" and clause_of(cid).level == "SHOULD":
            verdict = "non-strict"
        self.outcomes[cid].append(Outcome(verdict, reason, case, list(evidence)))

    def ok(self, cid: str, n: int = 1) -> None:
        """Count a passing observation (a line checked, an ACK in time) without an outcome entry."""
        if cid in self.counts:
            self.counts[cid] += n

    def failed(self, cid: str) -> bool:
        return any(o.verdict in ("fail", "non-strict") for o in self.outcomes.get(cid, ()))

    def verdict(self, cid: str, default_reason: str = "") -> tuple[str, str, list[str], list[dict], int]:
        """(verdict, reason, cases, evidence, offending_count) for one clause."""
        outs = self.outcomes.get(cid, [])
        cases = list(dict.fromkeys(o.case for o in outs if o.case))
        fails = [o for o in outs if o.verdict in ("fail", "non-strict")]
        if fails:
            first = fails[0]
            return first.verdict, first.reason, cases, first.evidence, len(fails)
        for level in ("inconclusive", "pass"):
            hits = [o for o in outs if o.verdict == level]
            if hits:
                reason = hits[0].reason
                if level == "pass" and self.counts.get(cid):
                    reason = f"{reason} ({self.counts[cid]} observations checked)"
                return level, reason, cases, hits[0].evidence, 0
        if self.counts.get(cid):
            return "pass", f"{self.counts[cid]} observations met the clause", cases, [], 0
        nt = [o for o in outs if o.verdict == "not-tested"]
        if nt:
            return "not-tested", nt[0].reason, cases, nt[0].evidence, 0
        return "not-tested", default_reason or "no case exercised this clause", cases, [], 0
