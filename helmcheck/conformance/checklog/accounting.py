"""Per-clause accounting for a log check: counts, first reasons and bounded evidence.

This module owns turning a stream of observations into one verdict per clause, the way the
certifiers report them (pass / non-strict / fail / inconclusive / not-tested, a reason, evidence
lines). Memory is bounded whatever the log length: per clause it keeps counters, the first
:data:`MAX_EVIDENCE` evidence lines and the first :data:`MAX_LINES` offending log line numbers.

Verdict of a clause (reference profile preamble, RH-TIM-1):

* a violation of a MUST → ``fail``; of a SHOULD → ``non-strict``;
* else an observation that could not be judged (timing the log cannot bound, a mission the
  checker does not know) → ``inconclusive``;
* else at least one judged observation → ``pass``;
* else ``not-tested``, with the reason recorded for the clause (or "no occasion in this log").
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from typing import Iterable, Optional

from ...clauses import catalogue

__all__ = ["ClauseBook", "Evidence", "MAX_EVIDENCE", "MAX_LINES"]

MAX_EVIDENCE = 5
MAX_LINES = 50


@dataclass(frozen=True, slots=True)
class Evidence:
    """One log line shown as evidence: time, direction, log line number, text."""

    t: float
    dir: str
    lineno: int
    text: str

    def as_dict(self) -> dict:
        return {"t": max(0.0, round(self.t, 6)), "dir": self.dir,
                "line": f"line {self.lineno}: {self.text}"[:400]}


@dataclass
class _Entry:
    passes: int = 0
    fails: int = 0
    inconclusive: int = 0
    fail_reason: str = ""
    inconc_reason: str = ""
    evidence: list = field(default_factory=list)
    inconc_evidence: list = field(default_factory=list)
    lines: list = field(default_factory=list)
    inconc_lines: list = field(default_factory=list)


class ClauseBook:
    """Observations per clause; :meth:`verdicts` turns them into clause entries."""

    def __init__(self, clauses: Iterable[str]):
        self.known = catalogue()
        self.order = [c for c in clauses if c in self.known]
        self._e: dict[str, _Entry] = {c: _Entry() for c in self.order}
        self._untested: dict[str, str] = {}
        #: pass counts by clause; hot paths may add to it directly (unknown clauses are ignored)
        self.passes: Counter = Counter()
        self._notes: dict[str, list[str]] = {}

    def _get(self, cid: str) -> Optional[_Entry]:
        return self._e.get(cid)

    def ok(self, cid: str, n: int = 1) -> None:
        self.passes[cid] += n

    def fail(self, cid: str, reason: str, evidence: Iterable[Evidence] = ()) -> None:
        e = self._e.get(cid)
        if e is None:
            return
        e.fails += 1
        if not e.fail_reason:
            e.fail_reason = reason
        _keep(evidence, e.lines, e.evidence)

    def inconclusive(self, cid: str, reason: str, evidence: Iterable[Evidence] = ()) -> None:
        e = self._e.get(cid)
        if e is None:
            return
        e.inconclusive += 1
        if not e.inconc_reason:
            e.inconc_reason = reason
        _keep(evidence, e.inconc_lines, e.inconc_evidence)

    def untested(self, cid: str, reason: str) -> None:
        """Why a clause cannot be judged from this log (used only if nothing was judged)."""
        self._untested.setdefault(cid, reason)

    def note(self, cid: str, text: str) -> None:
        """A remark appended to the clause's reason (e.g. an inference the verdict rests on)."""
        notes = self._notes.setdefault(cid, [])
        if text not in notes and len(notes) < 3:
            notes.append(text)

    def count(self, cid: str) -> tuple[int, int, int]:
        e = self._e.get(cid)
        return (self.passes[cid], e.fails, e.inconclusive) if e else (0, 0, 0)

    def lines(self, cid: str) -> list[int]:
        e = self._e.get(cid)
        return list(e.lines) if e else []

    def verdicts(self) -> list[dict]:
        """One entry per clause: id, verdict, reason, evidence (dicts), lines, offending_count."""
        out = []
        for cid in self.order:
            e = self._e[cid]
            e.passes = self.passes[cid]
            level = self.known[cid].level
            judged = e.passes + e.fails + e.inconclusive
            if e.fails:
                verdict = "fail" if level == "MUST" else "non-strict"
                where = _where(e.lines, e.fails)
                reason = f"{e.fails} violation(s) in {judged} observation(s){where}; first: {e.fail_reason}"
                evidence, lines, count = e.evidence, e.lines, e.fails
            elif e.inconclusive:
                verdict = "inconclusive"
                where = _where(e.inconc_lines, e.inconclusive)
                reason = (f"{e.inconclusive} of {judged} observation(s) could not be judged{where}: "
                          f"{e.inconc_reason}")
                evidence, lines, count = e.inconc_evidence, e.inconc_lines, 0
            elif e.passes:
                verdict = "pass"
                reason = f"{e.passes} observation(s) in the log, no deviation."
                evidence, lines, count = [], [], 0
            else:
                verdict = "not-tested"
                reason = self._untested.get(cid, "No occasion to judge this clause in the log.")
                evidence, lines, count = [], [], 0
            notes = self._notes.get(cid)
            if notes and verdict != "not-tested":
                reason += " Note: " + " ".join(notes)
            out.append({"id": cid, "verdict": verdict, "reason": reason, "level": level,
                        "evidence": [ev.as_dict() for ev in evidence], "lines": list(lines),
                        "offending_count": count})
        return out


def _where(lines: list[int], n: int) -> str:
    if not lines:
        return ""
    shown = ", ".join(map(str, lines[:10]))
    more = f" and {n - min(len(lines), 10)} more" if n > min(len(lines), 10) else ""
    return f" (log line {shown}{more})"


def _keep(evidence: Iterable[Evidence], lines: list, kept: list) -> None:
    """Bounded evidence: the first line number of each finding, the first few lines quoted."""
    evidence = list(evidence)
    if evidence and len(lines) < MAX_LINES:
        lines.append(evidence[0].lineno)
    for ev in evidence:
        if len(kept) >= MAX_EVIDENCE:
            break
        kept.append(ev)
