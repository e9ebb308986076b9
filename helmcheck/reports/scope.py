"""Scope: whether a run is a certificate, and the one line every rendering leads with; then what
every banner says under it, in this order: what failed (:func:`failures`, each clause with its
reason), what was not judged (:meth:`Scope.why`), what timing judged coarser than nominal
precision means for the user (:func:`precision_note`).

A verdict says how the judged clauses went; the scope says how much was judged. The rule:

* **Claimed clauses.** A vehicle run claims every vehicle clause of the reference profile (§1–8,
  :func:`helmcheck.clauses.vehicle_clauses`); a backseat run every §9 clause
  (:func:`helmcheck.clauses.backseat_clauses`); a log check the clauses it lists. A MUST is a
  MUST: no profile setting removes a clause from the claim. A profile that gives the tester no
  way to exercise a clause — no violation trigger for §7 (``fault_injection = "none"`` and
  ``violation_trigger`` none, RH-SAF-5), no ``end_mission``, a command left out of ``commands``,
  an OSD letter left out of ``osd_letters`` — leaves that clause NOT-TESTED, with the reason.
* **Judged** means a verdict of ``pass``, ``non-strict`` or ``fail``. ``not-tested``,
  ``inconclusive`` and a clause missing from the results are not judged.
* A run is a **certificate** when it finished (not ``partial``) and judged every claimed clause,
  MUST and SHOULD alike. ``--select`` runs, runs with a NOT-TESTED or INCONCLUSIVE clause and
  interrupted runs are not; their verdict and exit status are unchanged, but every rendering
  leads with ``PASS — partial: 4 of 60 claimed clauses judged; not a certificate`` and says why
  (``RH-SAF-1..5 not tested: …``). A run that judged everything and failed is a certificate
  too: a certificate of non-conformance.

**Model coverage is not scope.** What a vehicle run's exploration reached of the reference model
(``stats.explore.model_coverage``: modes, transitions — the table's rows —, interrupt pairs,
timers run out, timer boundaries, error codes, and the traceability table's rules once it is
plugged in) measures the search on top of the fixed cases; no verdict and no certificate depends
on it. Every rendering that shows it says so beside it (:func:`model_coverage_note`), and the
verdict line states it in one sentence (:func:`exploration_note`). Nor are the range edges a
vehicle run reached (``stats.edges``, :func:`edge_gist`): a bound whose edge was not reached is
still judged by its clause wherever it was met.

Nothing here reads files: the scope is a pure function of the results document (its role, its
clause verdicts, ``partial``), so ``helmcheck verify`` can recompute it from re-judged verdicts
and the schema validator can check a recorded ``certificate`` flag.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any, Iterable, Mapping

from helmcheck.clauses import backseat_clauses, catalogue, vehicle_clauses

from ..judge.verdict import Verdict
from .view import VERDICT_LABEL, non_pass_rows

__all__ = ["JUDGED", "Gap", "Scope", "claimed_clauses", "scope_of", "headline", "id_ranges", "model_coverage_note",
           "edge_coverage", "edge_gist", "what_to_change", "precision_note", "failures", "MODEL_DIMENSIONS",
           "reach_text", "exploration_note", "model_coverage"]

JUDGED = (Verdict.PASS, Verdict.NON_STRICT, Verdict.FAIL)
_GAPS_SHOWN = 4


@dataclass(frozen=True)
class Gap:
    """Claimed clauses not judged for one reason."""

    clauses: tuple[str, ...]
    verdict: str  #: ``not-tested``, ``inconclusive`` or ``missing``
    reason: str

    def text(self) -> str:
        what = {Verdict.NOT_TESTED: "not tested", Verdict.INCONCLUSIVE: Verdict.INCONCLUSIVE,
                "missing": "missing from the results"}.get(self.verdict, self.verdict)
        return f"{id_ranges(self.clauses)} {what}" + (f": {self.reason}" if self.reason else "")


@dataclass(frozen=True)
class Scope:
    """The scope of one run (module docstring)."""

    certificate: bool
    claimed: tuple[str, ...]
    judged: tuple[str, ...]
    gaps: tuple[Gap, ...]
    interrupted: bool
    #: the run finished, but a scenario's moment did not reach the backseat (its observations not
    #: claimed, ``coverage.scenarios``): partial without having been cut short
    unexercised: bool = False

    @property
    def statement(self) -> str:
        """``certificate: all 60 claimed clauses judged`` or ``partial: 4 of 60 claimed clauses
        judged; not a certificate`` (with ``the run was interrupted`` first when it was)."""
        n, k = len(self.claimed), len(self.judged)
        if self.certificate:
            return f"certificate: all {n} claimed clauses judged"
        stopped = ("not every scenario was exercised; " if self.unexercised
                   else "the run was interrupted; " if self.interrupted else "")
        return f"partial: {stopped}{k} of {n} claimed clauses judged; not a certificate"

    def why(self, limit: int = _GAPS_SHOWN) -> list[str]:
        """One line per reason a claimed clause was not judged, the first *limit* of them."""
        lines = [g.text() for g in self.gaps[:limit]]
        rest = self.gaps[limit:]
        if rest:
            lines.append(f"and {sum(len(g.clauses) for g in rest)} more clause(s) for {len(rest)} other reason(s)")
        return lines

    def as_dict(self) -> dict[str, Any]:
        return {"claimed": len(self.claimed), "judged": len(self.judged), "statement": self.statement,
                "gaps": [{"clauses": list(g.clauses), "verdict": g.verdict, "reason": g.reason} for g in self.gaps]}


def claimed_clauses(results: Mapping[str, Any]) -> list[str]:
    """The clause IDs a run claims, in profile order (module docstring)."""
    role = results.get("role")
    if role == "vehicle":
        return [c.id for c in vehicle_clauses()]
    if role == "backseat":
        return [c.id for c in backseat_clauses()]
    order = {cid: i for i, cid in enumerate(catalogue())}
    ids = [c.get("id") for c in results.get("clauses") or [] if isinstance(c, Mapping)]
    return sorted(dict.fromkeys(i for i in ids if isinstance(i, str)), key=lambda i: order.get(i, len(order)))


def scope_of(results: Mapping[str, Any], verdicts: Mapping[str, str] | None = None) -> Scope:
    """The scope of *results*; *verdicts* (clause ID → verdict) replaces the recorded ones."""
    entries = {c["id"]: c for c in results.get("clauses") or [] if isinstance(c, Mapping) and "id" in c}
    if verdicts is None:
        verdicts = {cid: c.get("verdict") for cid, c in entries.items()}
    claimed = claimed_clauses(results)
    judged = tuple(cid for cid in claimed if verdicts.get(cid) in JUDGED)
    groups: dict[tuple[str, str], list[str]] = {}
    for cid in claimed:
        v = verdicts.get(cid)
        if v in JUDGED:
            continue
        verdict = v if v in (Verdict.NOT_TESTED, Verdict.INCONCLUSIVE) else "missing"
        reason = str(entries.get(cid, {}).get("reason") or "") if verdict != "missing" else ""
        groups.setdefault((verdict, _plain_reason(reason)), []).append(cid)
    gaps = tuple(Gap(tuple(ids), v, r) for (v, r), ids in groups.items())
    interrupted = bool(results.get("partial"))
    certificate = not interrupted and not gaps and bool(claimed)
    run = results.get("run")
    unexercised = interrupted and isinstance(run, Mapping) and run.get("status") == "complete"
    return Scope(certificate, tuple(claimed), judged, gaps, interrupted, unexercised)


def _plain_reason(reason: str) -> str:
    """A clause reason without the case prefix (``V-55: …``), so one cause groups its clauses."""
    return re.sub(r"^[A-Z]+-\d+[a-z]?: ", "", reason.strip())


def headline(results: Mapping[str, Any]) -> str:
    """``PASS — partial: 4 of 60 claimed clauses judged; not a certificate`` (the verdict word and
    :attr:`Scope.statement`): the first line of every rendering."""
    verdict = results.get("verdict")
    return f"{VERDICT_LABEL.get(verdict, str(verdict).upper())} — {scope_of(results).statement}"


_REASON_SHOWN = 280  # characters of a failed clause's reason in the banner; the finding has it whole


def failures(results: Mapping[str, Any], limit: int = _GAPS_SHOWN) -> list[str]:
    """What failed, first in every banner: one line per failed clause (a SHOULD missed too), its
    ID and its reason in words (``RH-BS-2 failed: …``), worst first, the first *limit* of them,
    then how many more and which."""
    rows = [r for r in non_pass_rows(results) if r["verdict"] in (Verdict.FAIL, Verdict.NON_STRICT)]
    lines = []
    for row in rows[:limit]:
        what = "failed" if row["verdict"] == Verdict.FAIL else "not met (a SHOULD: NON-STRICT)"
        reason = " ".join(str(row.get("reason") or "").split())
        if len(reason) > _REASON_SHOWN:
            reason = reason[:_REASON_SHOWN - 1].rsplit(" ", 1)[0].rstrip(",;:") + " …"
        lines.append(f"{row['id']} {what}" + (f": {reason}" if reason else ""))
    rest = rows[limit:]
    if rest:
        lines.append(f"and {len(rest)} more: {id_ranges(r['id'] for r in rest)}")
    return lines


_RUN_AT = re.compile(r"run at (.+?)(?:$|\.\s)")


def what_to_change(results: Mapping[str, Any]) -> str:
    """What would let the clauses the line left unjudged be judged, from their reasons (the line
    budget names a time scale or a baud: ``run at --time-scale 5``), as one sentence; ``""`` when
    no gap names one."""
    out = []
    for g in scope_of(results).gaps:
        m = _RUN_AT.search(g.reason)
        if m:
            out.append(f"run at {m.group(1).rstrip('.')} to judge {id_ranges(g.clauses)}")
    return ("On this line: " + "; ".join(out) + ".") if out else ""


def precision_note(results: Mapping[str, Any]) -> str:
    """One sentence on what timing judged coarser than nominal precision (a tolerance widened by
    more than :data:`~helmcheck.judge.linebudget.NOMINAL_WIDENING_S` by what the observer could
    not see) means for the user: the timing faults that could pass at this time scale, and the
    time scale at which this line would judge timing to the profile's tolerance; ``""`` when no
    clause was judged coarser. ``Timing faults up to ±7.8 s could pass at ×40 (7 timing clause(s)
    judged coarser than RH-TIM-1's tolerance; RH-OUT-4 within ±7.8 s, nominal ±1.6 s); for timing
    at the profile's tolerance run at ×2.``"""
    from ..judge.linebudget import NOMINAL_WIDENING_S, from_settings

    coarse = []
    k = None
    for c in results.get("clauses") or []:
        pr = c.get("precision") if isinstance(c, Mapping) else None
        if c.get("verdict") in JUDGED and isinstance(pr, Mapping) and \
                pr.get("widened_s", 0) - pr.get("nominal_s", 0) > NOMINAL_WIDENING_S:
            coarse.append((c["id"], pr))
            k = pr.get("time_scale", k)
    if not coarse:
        return ""
    worst = max(coarse, key=lambda x: x[1]["widened_s"] - x[1]["nominal_s"])
    widest = max(pr["widened_s"] for _, pr in coarse)
    at = f" at ×{k:g}" if k else ""
    text = (f"Timing faults up to ±{_secs(widest)} s could pass{at} ({len(coarse)} timing clause(s) judged "
            f"coarser than RH-TIM-1's tolerance; {worst[0]} within ±{_secs(worst[1]['widened_s'])} s, "
            f"nominal ±{_secs(worst[1]['nominal_s'])} s)")
    budget = from_settings(((results.get("settings") or {}).get("line_budget")) or {})
    nominal = budget.nominal_scale() if budget is not None else None
    if nominal is not None and nominal < (k or 0):
        text += f"; for timing at the profile's tolerance run at ×{nominal:g}"
    elif budget is not None and nominal is None:
        text += ("; even at ×1 this line is coarser: timing at the profile's tolerance needs a faster baud "
                 "or a vehicle that answers sooner")
    return text + "."


def _secs(s: float) -> str:
    """Seconds to two significant figures (``7.759`` → ``7.8``, ``0.65`` → ``0.65``, ``12.3`` → ``12``)."""
    return f"{float(f'{s:.2g}'):g}"


def model_coverage_note(results: Mapping[str, Any]) -> str:
    """The one sentence shown beside the exploration's model coverage: what it means for the
    verdict (nothing) and what the verdict rests on instead (module docstring)."""
    scope = scope_of(results)
    rests = (f"which for this certificate rests on the clause verdicts: each of the {len(scope.claimed)} "
             "claimed clauses judged on the exchanges that exercised it" if scope.certificate else
             "which rests on the clause verdicts alone")
    tour = ((results.get("stats") or {}).get("explore") or {}).get("long_tour")
    extended = (f" (the budget was extended by {tour['extended_wall_s']:g} s of wall time at most for one tour "
                f"of the vehicle's own mission that no batch's share could hold, about {tour['cost_v']:g} s of "
                "vehicle time)") if tour else ""
    return ("Model coverage is how much of the reference model the exploration's random sequences "
            f"reached within their budget{extended} (the fixed test cases are not counted); it is not part of "
            f"the verdict, {rests}.")


#: The dimensions of ``stats.explore.model_coverage`` in the order every rendering shows them, each
#: with its name in a sentence.
MODEL_DIMENSIONS = {"rows": "transitions", "modes": "modes", "interrupt_pairs": "interrupt pairs",
                    "timers": "timers run out", "boundaries": "timer boundaries", "error_codes": "error codes",
                    "rules": "rules"}


def model_coverage(results: Mapping[str, Any]) -> dict[str, Mapping[str, Any]]:
    """``stats.explore.model_coverage`` of a vehicle run, in :data:`MODEL_DIMENSIONS` order (empty
    when the run recorded none)."""
    mc = ((results.get("stats") or {}).get("explore") or {}).get("model_coverage")
    if not isinstance(mc, Mapping):
        return {}
    order = list(MODEL_DIMENSIONS) + sorted(k for k in mc if k not in MODEL_DIMENSIONS)
    return {k: mc[k] for k in order if isinstance(mc.get(k), Mapping)}


def reach_text(summary: Mapping[str, Any], with_cases: bool = False) -> str:
    """``41 of 91 transitions, 9 of 9 modes, …`` from a model coverage summary; ``with_cases``:
    ``(44 with the cases)`` after each the cases add to."""
    parts = []
    for key, d in summary.items():
        if not isinstance(d, Mapping):
            continue
        word = MODEL_DIMENSIONS.get(key, key.replace("_", " "))
        more = d.get("with_cases")
        extra = (f" ({more} with the cases)" if with_cases and isinstance(more, int) and more != d.get("covered")
                 else "")
        parts.append(f"{d.get('covered')} of {d.get('of')} {word}{extra}")
    return ", ".join(parts)


def exploration_note(results: Mapping[str, Any], shown: int = 3) -> str:
    """The verdict line's sentence on the exploration's reach: ``The exploration reached 41 of 91
    transitions, …; not reached: row 2: …, … (not part of the verdict).`` — the first ``shown``
    transitions (or rules, once the traceability table is plugged in) it did not reach; ``""``
    for a run without an exploration."""
    mc = model_coverage(results)
    if not mc:
        return ""
    key = "rules" if "rules" in mc else "rows"
    missing = [str(x) for x in mc.get(key, {}).get("uncovered") or []]
    what = MODEL_DIMENSIONS[key]
    rest = (f"; {what} not reached: {'; '.join(missing[:shown])}" + (f" and {len(missing) - shown} more"
                                                                       if len(missing) > shown else "")
            if missing else "")
    return f"The exploration reached {reach_text(mc)}{rest} (not part of the verdict)."


def edge_coverage(results: Mapping[str, Any]) -> Mapping[str, Any]:
    """``stats.edges`` of a vehicle run: the range edges of §4–8b it reached (empty when it recorded none)."""
    e = (results.get("stats") or {}).get("edges")
    return e if isinstance(e, dict) and "of" in e else {}


def edge_gist(results: Mapping[str, Any]) -> str:
    """One sentence: how many range edges the run reached, and why the others were not."""
    e = edge_coverage(results)
    if not e:
        return ""
    why: dict[str, int] = {}
    for u in e.get("unreached") or ():
        k = (u.get("why") or "not sent") if isinstance(u, dict) else "not sent"
        why[k] = why.get(k, 0) + 1
    rest = "; ".join(f"{n} {k}" for k, n in sorted(why.items()))
    return (f"Range edges reached (§4–8b, both sides of every bound): {e.get('reached')} of {e.get('of')}"
            + (f" (not reached: {rest})" if rest else "") + ".")


def id_ranges(ids: Iterable[str]) -> str:
    """``RH-SAF-1, RH-SAF-2, RH-SAF-3, RH-FRM-9`` → ``RH-SAF-1..3, RH-FRM-9`` (order kept)."""
    out: list[str] = []
    run: list[tuple[str, int]] = []

    def flush() -> None:
        if not run:
            return
        fam, first = run[0]
        last = run[-1][1]
        out.append(f"{fam}-{first}" if first == last else f"{fam}-{first}..{last}")
        run.clear()

    for cid in ids:
        fam, _, num = cid.rpartition("-")
        if not num.isdigit():
            flush()
            out.append(cid)
            continue
        n = int(num)
        if run and (run[-1][0] != fam or run[-1][1] + 1 != n):
            flush()
        run.append((fam, n))
    flush()
    return ", ".join(out)
