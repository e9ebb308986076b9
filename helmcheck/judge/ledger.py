"""The verdict ledger: every finding of a run, one verdict per clause, one rule to combine them.

Every judge (the vehicle observer, the backseat observer) and every driver fact (a case that
could not run, a step bench safety refused) writes here, and nowhere else. A finding is one
observation of one clause:

* ``passed`` — the clause was exercised and the implementation met it (counted; the first
  deciding exchange is kept as evidence);
* ``failed`` — a MUST violated gives ``fail``, a SHOULD violated gives ``non-strict``
  (reference profile, preamble);
* ``inconclusive`` — the clause was exercised but could not be judged (timing the observer
  cannot bound, a mission file it does not have, a link fault);
* ``not_tested`` — why the clause could not be exercised at all;
* ``spoiled`` — an observation a faulty line may have spoilt, made again clean (the judge's
  repetition rule, :mod:`helmcheck.judge.streaks`): not booked against the implementation,
  counted, and named in the verdict's reason (an INCONCLUSIVE where nothing else was observed);
* ``withdraw`` — the clause is outside what the run judged (a ``--select`` run that did not
  select it; a backseat whose exit cut short the scenarios exercising it): NOT-TESTED with that
  reason whatever was observed, except a violation, which stands (a run fact,
  :mod:`helmcheck.judge.runfacts`);
* ``unclaim`` — the clause's observations in one case (a backseat scenario whose moment did not
  reach the backseat in time) are not claimed: the verdict is made from the other cases'
  findings, a violation in it still standing, and says so; with nothing left, NOT-TESTED with
  that reason. It needs the findings kept per case (:meth:`Ledger.track_cases`, which the backseat
  observer turns on: a handful of scenarios, so a handful of entries per clause).

The one combining rule (TTCN-3, "first fail wins"): ``fail``/``non-strict`` > ``inconclusive`` >
``pass`` > ``not-tested``. The reason shown is the first one at the winning level, with the
counts; evidence is bounded (:data:`MAX_EVIDENCE` excerpts, :data:`MAX_LINES` distinct offending
log line numbers per clause, in the order first met), so a ledger stays small whatever the length
of the run.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
from typing import Callable, Iterable, NamedTuple, Optional, Union

from ..clauses import catalogue
from .verdict import FAIL, INCONCLUSIVE, NON_STRICT, NOT_TESTED, PASS

__all__ = ["Ledger", "Evidence", "ClauseVerdict", "MAX_EVIDENCE", "MAX_LINES", "MAX_FAIL_LOG", "RANK", "combine"]

#: A finding's reason, or a function that makes it (see :meth:`Ledger.passed`).
Reason = Union[str, Callable[[], str]]
MAX_EVIDENCE = 8
MAX_LINES = 50
#: Failures kept for :meth:`Ledger.failures_since` (the counts and verdicts keep every one).
MAX_FAIL_LOG = 1024
#: The combining rule: a higher rank wins.
RANK = {NOT_TESTED: 0, PASS: 1, INCONCLUSIVE: 2, NON_STRICT: 3, FAIL: 3}


class Evidence(NamedTuple):
    """One line of wire evidence: time, wire-log direction, text as logged, log line number.
    (A named tuple: immutable, and cheap to make once per line of a long log.)"""

    t: float
    dir: str  #: ">" / "<" (a CR LF line), ">~" / "<~" (any other run), "!" (a note)
    text: str
    lineno: int = 0  #: the record's line in the wire log (0 when not known)

    def as_dict(self) -> dict:
        line = f"line {self.lineno}: {self.text}" if self.lineno else self.text
        return {"t": max(0.0, round(self.t, 6)), "dir": self.dir, "line": line[:400]}


@dataclass(frozen=True)
class ClauseVerdict:
    """The verdict of one clause, ready for ``results.json``."""

    id: str
    verdict: str
    reason: str
    level: str
    cases: tuple[str, ...] = ()
    evidence: tuple[Evidence, ...] = ()
    lines: tuple[int, ...] = ()
    offending_count: int = 0
    observations: int = 0
    #: a timing clause's precision: the finest RH-TIM-1 tolerance it was judged with (the
    #: nominal ``max(0.5 s, 5 %)`` and the tolerance widened by what the observer could not see),
    #: vehicle seconds, and the time scale (:meth:`Ledger.precision`); None for other clauses
    precision: Optional[tuple[float, float, float]] = None

    def as_entry(self) -> dict:
        out = {"id": self.id, "verdict": self.verdict, "reason": self.reason, "level": self.level,
               "cases": list(self.cases), "evidence": [e.as_dict() for e in self.evidence],
               "lines": list(self.lines), "offending_count": self.offending_count, "replay": None}
        if self.precision is not None:
            nominal, widened, k = self.precision
            out["precision"] = {"nominal_s": round(nominal, 3), "widened_s": round(widened, 3), "time_scale": k}
        return out


@dataclass(slots=True)
class _Level:
    count: int = 0
    reason: str = ""
    evidence: list = field(default_factory=list)
    lines: list = field(default_factory=list)
    full: bool = False  #: reason, evidence and lines all kept: a further finding only counts


@dataclass(slots=True)
class _Entry:
    levels: dict = field(default_factory=lambda: {k: _Level() for k in (PASS, FAIL, INCONCLUSIVE,
                                                                          NOT_TESTED)})
    cases: dict = field(default_factory=dict)
    remarks: list = field(default_factory=list)
    withdrawn: Optional[tuple[str, str]] = None  #: (reason, prefix of an observed violation's reason)
    precision: Optional[tuple[float, float, float]] = None  #: the finest (nominal, widened, k) so far
    spoiled: int = 0  #: observations a faulty line may have spoilt, made again (not judged)
    spoiled_reason: str = ""
    spoiled_evidence: list = field(default_factory=list)


class Ledger:
    """Findings per clause, combined by the one rule (module docstring)."""

    def __init__(self, clause_ids: Iterable[str]):
        known = catalogue()
        self.order = [c for c in clause_ids if c in known]
        self._level = {c: known[c].level for c in self.order}
        self._e: dict[str, _Entry] = {c: _Entry() for c in self.order}
        #: the latest failures in order: (serial, clause, reason) — drivers read :meth:`failures_since`
        #: (bounded: a ledger stays small however long the run, and however many its failures)
        self._fail_log: deque[tuple[int, str, str]] = deque(maxlen=MAX_FAIL_LOG)
        self._serial = 0
        #: violations waiting for their confirmation (:meth:`hold`), or None when none is awaited
        self._held: Optional[list[tuple[str, str, list, str]]] = None
        #: clause -> case -> kind -> its findings there (:meth:`track_cases`; None: not kept)
        self._by_case: Optional[dict[str, dict[str, dict[str, _Level]]]] = None
        #: clause -> case -> why its observations there are not claimed (:meth:`unclaim`)
        self._unclaimed: dict[str, dict[str, str]] = {}

    def __contains__(self, cid: str) -> bool:
        return cid in self._e

    # ------------------------------------------------------------------ per case
    def track_cases(self) -> None:
        """Keep every finding per case too, so that a case's observations can be left out of the
        claim later (:meth:`unclaim`). Turn it on before the first finding."""
        if self._by_case is None:
            self._by_case = {}

    def _track(self, cid: str, kind: str, reason: Reason, evidence, case: str) -> None:
        lv = self._by_case.setdefault(cid, {}).setdefault(case, {}).get(kind)  # type: ignore[union-attr]
        if lv is None:
            lv = self._by_case[cid][case][kind] = _Level()  # type: ignore[index]
        lv.count += 1
        if lv.full:
            return
        if not lv.reason and reason:
            lv.reason = reason() if callable(reason) else reason
        ev = list(evidence)
        if ev and len(lv.lines) < MAX_LINES and ev[-1].lineno and ev[-1].lineno not in lv.lines:
            lv.lines.append(ev[-1].lineno)
        if not lv.evidence and ev:
            lv.evidence = ev[:MAX_EVIDENCE]
        lv.full = bool(lv.evidence and lv.reason and len(lv.lines) >= MAX_LINES)

    def unclaim(self, cid: str, case: str, reason: str) -> None:
        """The clause's observations in ``case`` are not claimed (module docstring); the first
        reason for a case holds."""
        if cid in self._e:
            self._unclaimed.setdefault(cid, {}).setdefault(case, reason)

    def unclaimed(self, cid: str) -> dict[str, str]:
        """Case -> why the clause's observations there are not claimed."""
        return dict(self._unclaimed.get(cid, {}))

    # ------------------------------------------------------------------ findings
    def _add(self, cid: str, kind: str, reason: Reason, evidence: Iterable[Evidence], case: str) -> None:
        e = self._e.get(cid)
        if e is None:
            return  # a clause outside this ledger (not selected, or the other role)
        if self._by_case is not None:
            if type(evidence) not in (tuple, list):
                evidence = list(evidence)
            self._track(cid, kind, reason, evidence, case)
        lv = e.levels[kind]
        lv.count += 1
        if lv.full and (not case or case in e.cases):
            return  # everything kept is full: only the count changes (the common, repeated finding)
        if (not evidence and type(evidence) in (tuple, list) and (lv.reason or not reason)
                and (not case or case in e.cases)):
            # nothing to keep (no evidence, the reason kept, the case known): a count, as below
            lv.full = bool(lv.evidence and lv.reason and len(lv.lines) >= MAX_LINES)
            return
        if not lv.reason and reason:
            lv.reason = reason() if callable(reason) else reason
        ev = list(evidence)
        if ev and len(lv.lines) < MAX_LINES and ev[-1].lineno and ev[-1].lineno not in lv.lines:
            lv.lines.append(ev[-1].lineno)  # evidence runs in time order: the last line is the offending one
        if not lv.evidence and ev:
            lv.evidence = ev[:MAX_EVIDENCE]
        if case:
            e.cases[case] = None
        lv.full = bool(lv.evidence and lv.reason and len(lv.lines) >= MAX_LINES)

    def keeps(self, cid: str, kind: str, case: str = "") -> bool:
        """Whether a finding of ``kind`` would still keep its reason or evidence (else it only
        counts): lets a hot path skip formatting a reason nobody will read."""
        e = self._e.get(cid)
        if e is None:
            return False
        lv = e.levels[kind]
        return not (lv.full and (not case or case in e.cases))

    def passed(self, cid: str, reason: Reason = "", evidence: Iterable[Evidence] = (), case: str = "") -> None:
        """The clause was exercised and met (the first call's reason and evidence are kept). A
        reason may be a function that makes it: called only when the reason is kept (a repeated
        pass on a hot path then formats nothing)."""
        e = self._e.get(cid)
        if e is None:
            return
        lv = e.levels[PASS]
        if self._by_case is not None:
            self._add(cid, PASS, reason, evidence, case)  # kept per case too: the full path
            return
        if lv.full and (not case or case in e.cases):
            lv.count += 1  # the common, repeated pass: only the count changes
            return
        if (not evidence and type(evidence) in (tuple, list) and (lv.reason or not reason)
                and (not case or case in e.cases)):
            lv.count += 1  # a pass that brings nothing to keep: only the count changes (as in _add)
            return
        self._add(cid, PASS, reason, evidence, case)

    def passed_all(self, passes: Iterable[tuple[str, str]], evidence: Iterable[Evidence] = (),
                   case: str = "") -> None:
        """:meth:`passed` for each ``(clause, reason)`` of ``passes``, with the same evidence."""
        get = self._e.get
        for cid, reason in passes:
            e = get(cid)
            if e is None:
                continue
            lv = e.levels[PASS]
            if lv.full and (not case or case in e.cases) and self._by_case is None:
                lv.count += 1
            else:
                self._add(cid, PASS, reason, evidence, case)

    def failed(self, cid: str, reason: str, evidence: Iterable[Evidence] = (), case: str = "") -> None:
        """The clause was violated: ``fail`` for a MUST, ``non-strict`` for a SHOULD."""
        if cid not in self._e:
            return
        if self._held is not None:
            self._held.append((cid, reason, list(evidence)[:MAX_EVIDENCE], case))
        else:
            self._add(cid, FAIL, reason, evidence, case)
        self._serial += 1
        self._fail_log.append((self._serial, cid, reason))

    def inconclusive(self, cid: str, reason: str, evidence: Iterable[Evidence] = (), case: str = "") -> None:
        """The clause was exercised but could not be judged (the reason says why)."""
        self._add(cid, INCONCLUSIVE, reason, evidence, case)

    def not_tested(self, cid: str, reason: str, case: str = "") -> None:
        """Why the clause could not be exercised (shown only if nothing else was found)."""
        self._add(cid, NOT_TESTED, reason, (), case)

    def spoiled(self, cid: str, reason: str, evidence: Iterable[Evidence] = (), case: str = "") -> None:
        """An observation of the clause a faulty line may have spoilt (``reason`` says how) was
        made again clean: not judged, counted (module docstring)."""
        e = self._e.get(cid)
        if e is None:
            return
        e.spoiled += 1
        if not e.spoiled_reason:
            e.spoiled_reason = reason
            e.spoiled_evidence = list(evidence)[:MAX_EVIDENCE]
        if case:
            e.cases[case] = None

    def spoiled_count(self, cid: str) -> int:
        e = self._e.get(cid)
        return e.spoiled if e is not None else 0

    def withdraw(self, cid: str, reason: str, observed: str = "") -> None:
        """The clause is outside what the run judged: its verdict is NOT-TESTED with *reason*
        whatever was observed — except a violation, which stands, its reason prefixed with
        *observed*. The first withdrawal of a clause holds; booking it again changes nothing."""
        e = self._e.get(cid)
        if e is not None and e.withdrawn is None:
            e.withdrawn = (reason, observed)

    def hold(self) -> None:
        """From now on a violation is held: it is in the failure log (a driver stops on it, see
        :meth:`failures_since`) but booked only by :meth:`release` (an exploration's violations
        wait for their re-runs after shrinking)."""
        if self._held is None:
            self._held = []

    @property
    def holding(self) -> bool:
        return self._held is not None

    def held_clauses(self) -> set[str]:
        """The clauses with violations still held."""
        return {h[0] for h in self._held or ()}

    def release(self, confirmed: bool, why: str, clauses: Iterable[str] = ()) -> None:
        """Book the held violations: as violations when *confirmed*, else INCONCLUSIVE with *why*
        before their reason. With *clauses*, only those clauses' (holding goes on for the rest);
        without, all of them, and holding ends."""
        if self._held is None:
            return
        if clauses:
            only = set(clauses)
            now = [h for h in self._held if h[0] in only]
            self._held = [h for h in self._held if h[0] not in only]
        else:
            now, self._held = self._held, None
        for cid, reason, evidence, case in now:
            if confirmed:
                self._add(cid, FAIL, reason, evidence, case)
            else:
                self._add(cid, INCONCLUSIVE, f"{why}: {reason}", evidence, case)

    def precision(self, cid: str, nominal: float, widened: float, k: float) -> None:
        """A duration of ``cid`` was judged within ``widened`` vehicle seconds (RH-TIM-1's nominal
        ``nominal`` widened by what the observer could not see, at time scale ``k``): the clause
        keeps the finest — the observation that tells the closest timing fault from a conforming
        duration (a duration off by more than it is certain to have failed there)."""
        e = self._e.get(cid)
        if e is None:
            return
        if e.precision is None or widened - nominal < e.precision[1] - e.precision[0]:
            e.precision = (nominal, widened, k)

    def remark(self, cid: str, text: str) -> None:
        """A remark appended to the clause's reason (an inference its verdict rests on)."""
        e = self._e.get(cid)
        if e is not None and text not in e.remarks and len(e.remarks) < 3:
            e.remarks.append(text)

    # ------------------------------------------------------------------ queries
    def has_failed(self, cid: str) -> bool:
        e = self._e.get(cid)
        return e is not None and e.levels[FAIL].count > 0

    def has_finding(self, cid: str) -> bool:
        """Anything at all was recorded for the clause (a pass, fail, inconclusive or reason)."""
        e = self._e.get(cid)
        return e is not None and any(lv.count for lv in e.levels.values())

    def judged(self, cid: str) -> bool:
        e = self._e.get(cid)
        return e is not None and any(e.levels[k].count for k in (PASS, FAIL, INCONCLUSIVE))

    def mark(self) -> int:
        """A position in the failure log (see :meth:`failures_since`)."""
        return self._serial

    def failures_since(self, mark: int) -> list[tuple[str, str]]:
        """(clause, reason) of every failure recorded after :meth:`mark` returned ``mark`` — the
        latest :data:`MAX_FAIL_LOG` of them (a driver reads them after each step)."""
        out = []
        for n, c, r in reversed(self._fail_log):
            if n <= mark:
                break
            out.append((c, r))
        return out[::-1]

    def counts(self, cid: str) -> dict[str, int]:
        e = self._e[cid]
        return {k: lv.count for k, lv in e.levels.items()}

    def _claimed_levels(self, cid: str, e: _Entry) -> tuple[dict, tuple[str, ...], str]:
        """The findings the verdict is made from: every one, or (:meth:`unclaim`) those of the
        cases claimed and every violation; the cases they come from; what was left out, in words."""
        out = self._unclaimed.get(cid)
        if not out or self._by_case is None:
            return e.levels, tuple(e.cases), ""
        per = self._by_case.get(cid, {})
        levels = {k: _Level() for k in (PASS, FAIL, INCONCLUSIVE, NOT_TESTED)}
        cases: list[str] = []
        for case, kinds in per.items():
            for kind, got in kinds.items():
                if case in out and kind != FAIL:
                    continue
                lv = levels[kind]
                lv.count += got.count
                lv.reason = lv.reason or got.reason
                if not lv.evidence:
                    lv.evidence = list(got.evidence)
                lv.lines += [n for n in got.lines if n not in lv.lines][:max(0, MAX_LINES - len(lv.lines))]
                if case and case not in cases and (kind != NOT_TESTED):
                    cases.append(case)
        said = "; ".join(f"observations in {case} not claimed: {why}" for case, why in out.items())
        return levels, tuple(cases), said

    def verdict(self, cid: str) -> ClauseVerdict:
        """The combined verdict of one clause (the module's one rule)."""
        e = self._e[cid]
        level = self._level[cid]
        lv, cases, unclaimed = self._claimed_levels(cid, e)
        judged = lv[PASS].count + lv[FAIL].count + lv[INCONCLUSIVE].count
        if lv[FAIL].count:
            f = lv[FAIL]
            verdict = FAIL if level == "MUST" else NON_STRICT
            reason = (f"{f.count} violation(s) in {judged} observation(s){_where(f.lines)}; "
                      f"first: {f.reason}")
            out = ClauseVerdict(cid, verdict, reason, level, cases, tuple(f.evidence), tuple(f.lines),
                                f.count, judged)
        elif lv[INCONCLUSIVE].count:
            i = lv[INCONCLUSIVE]
            reason = (f"{i.count} of {judged} observation(s) could not be judged"
                      f"{_where(i.lines)}: {i.reason}")
            out = ClauseVerdict(cid, INCONCLUSIVE, reason, level, cases, tuple(i.evidence),
                                tuple(i.lines), 0, judged)
        elif lv[PASS].count:
            p = lv[PASS]
            reason = f"{p.count} observation(s) met the clause" + (f"; first: {p.reason}" if p.reason else ".")
            out = ClauseVerdict(cid, PASS, reason, level, cases, tuple(p.evidence), (), 0, judged)
        else:
            n = lv[NOT_TESTED]
            reason = n.reason or "no occasion to exercise this clause"
            if unclaimed:
                reason = unclaimed[:1].upper() + unclaimed[1:] + "."
                unclaimed = ""
            out = ClauseVerdict(cid, NOT_TESTED, reason, level, cases, (), (), 0, 0)
        if unclaimed:
            out = ClauseVerdict(out.id, out.verdict, out.reason + f" ({unclaimed[:1].upper()}{unclaimed[1:]}.)",
                                out.level, out.cases, out.evidence, out.lines, out.offending_count,
                                out.observations, out.precision)
        if e.spoiled:
            said = (f" {e.spoiled} observation(s) a faulty line may have spoilt were not judged: each was made "
                    f"again (first: {e.spoiled_reason}).")
            if out.verdict == NOT_TESTED:
                out = ClauseVerdict(cid, INCONCLUSIVE, f"nothing judged:{said}", level, cases,
                                    tuple(e.spoiled_evidence), (), 0, 0)
            else:
                out = ClauseVerdict(out.id, out.verdict, out.reason + said, out.level, out.cases, out.evidence,
                                    out.lines, out.offending_count, out.observations, out.precision)
        if e.precision is not None and out.verdict in (PASS, NON_STRICT, FAIL):
            nominal, widened, k = e.precision
            out = ClauseVerdict(out.id, out.verdict, out.reason + f" Timing judged within ±{widened:.2f} s of vehicle time "
                                f"at ×{k:g} (RH-TIM-1's nominal tolerance ±{nominal:g} s, widened by what the observer "
                                f"could not see).", out.level, out.cases, out.evidence, out.lines, out.offending_count,
                                out.observations, (nominal, widened, k))
        if e.remarks and out.verdict != NOT_TESTED:
            out = ClauseVerdict(out.id, out.verdict, out.reason + " Note: " + " ".join(e.remarks), out.level,
                                out.cases, out.evidence, out.lines, out.offending_count, out.observations,
                                out.precision)
        if e.withdrawn is not None:
            why, observed = e.withdrawn
            if out.verdict in (FAIL, NON_STRICT):
                out = ClauseVerdict(out.id, out.verdict, observed + out.reason, out.level, out.cases, out.evidence,
                                    out.lines, out.offending_count, out.observations, out.precision)
            else:
                out = ClauseVerdict(cid, NOT_TESTED, why, level, (), (), (), 0, 0)
        return out

    def verdicts(self) -> list[ClauseVerdict]:
        return [self.verdict(c) for c in self.order]

    def entries(self) -> list[dict]:
        """The clause entries of ``results.json`` (schema 1), in catalogue order."""
        return [v.as_entry() for v in self.verdicts()]


def _where(lines: list[int]) -> str:
    """`` (wire-log lines 12, 40 and 3 more)``: the distinct offending lines kept, the first ten
    named (several findings on one line name it once; past :data:`MAX_LINES` none are kept)."""
    if not lines:
        return ""
    shown = ", ".join(map(str, lines[:10]))
    rest = len(lines) - 10
    more = "" if rest <= 0 else f" and {'at least ' if len(lines) >= MAX_LINES else ''}{rest} more"
    return f" (wire-log line{'s' if len(lines) > 1 else ''} {shown}{more})"


def combine(verdicts: Iterable[str]) -> Optional[str]:
    """The winning verdict word of several findings by the one rule (``None`` for none)."""
    best: Optional[str] = None
    for v in verdicts:
        if best is None or RANK[v] > RANK[best]:
            best = v
    return best
