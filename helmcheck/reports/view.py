"""The report's view of a results document: clause rows joined with the profile, grouped and counted.

Every renderer (HTML, JUnit, Markdown, compare) reads clauses through here, so they agree on
order (the profile's), grouping (its sections), requirement texts (``helmcheck.clauses``, never
copied by hand) and counts.
"""

from __future__ import annotations

from typing import Any, Mapping

from helmcheck.clauses import catalogue

from ..judge.verdict import Verdict
from .verdicts import CLAUSE_VERDICTS

__all__ = ["VERDICT_LABEL", "NON_PASS", "counts", "clause_rows", "sections", "replay_for", "non_pass_rows",
           "pass_rows"]

VERDICT_LABEL = {
    Verdict.PASS: "PASS",
    Verdict.NON_STRICT: "NON-STRICT",
    Verdict.FAIL: "FAIL",
    Verdict.INCONCLUSIVE: "INCONCLUSIVE",
    Verdict.NOT_TESTED: "NOT-TESTED",
}
#: Verdicts that get a finding of their own (replay, wire excerpt) in the reports.
NON_PASS = (Verdict.FAIL, Verdict.NON_STRICT, Verdict.INCONCLUSIVE, Verdict.NOT_TESTED)

_OTHER_SECTION = ("?", "Clauses not in the reference profile")


def counts(results: Mapping[str, Any]) -> dict[str, int]:
    """How many clauses got each verdict, in :data:`CLAUSE_VERDICTS` order (zeros included)."""
    out = {v: 0 for v in CLAUSE_VERDICTS}
    for c in results["clauses"]:
        out[c["verdict"]] = out.get(c["verdict"], 0) + 1
    return out


def clause_rows(results: Mapping[str, Any]) -> list[dict[str, Any]]:
    """The clause entries in profile order, each with ``section``, ``section_title``, ``text``.

    A clause the profile does not list keeps its entry and gets section ``?`` and an empty text.
    """
    known = catalogue()
    order = {cid: i for i, cid in enumerate(known)}
    rows = []
    for entry in results["clauses"]:
        clause = known.get(entry["id"])
        row = dict(entry)
        if clause is not None:
            row.update(section=clause.section, section_title=clause.section_title, text=clause.text)
        else:
            row.update(section=_OTHER_SECTION[0], section_title=_OTHER_SECTION[1], text="")
        rows.append(row)
    rows.sort(key=lambda r: order.get(r["id"], len(order)))
    return rows


def sections(results: Mapping[str, Any]) -> list[tuple[str, str, list[dict[str, Any]]]]:
    """``(section, section_title, rows)`` in profile order, only sections with clauses."""
    grouped: dict[str, tuple[str, str, list[dict[str, Any]]]] = {}
    for row in clause_rows(results):
        grouped.setdefault(row["section"], (row["section"], row["section_title"], []))[2].append(row)
    return list(grouped.values())


def non_pass_rows(results: Mapping[str, Any]) -> list[dict[str, Any]]:
    """Rows whose verdict is not ``pass``, worst first (fail, non-strict, inconclusive, not-tested)."""
    rank = {v: i for i, v in enumerate(NON_PASS)}
    rows = [r for r in clause_rows(results) if r["verdict"] != Verdict.PASS]
    return sorted(rows, key=lambda r: rank[r["verdict"]])  # stable: profile order within a verdict


def pass_rows(results: Mapping[str, Any]) -> list[dict[str, Any]]:
    """Rows whose verdict is ``pass``, in profile order: each carries its deciding evidence."""
    return [r for r in clause_rows(results) if r["verdict"] == Verdict.PASS]


def replay_for(results: Mapping[str, Any], entry: Mapping[str, Any]) -> dict[str, Any] | None:
    """The replay a clause entry points at, else the first replay recorded for its clause."""
    replays = results.get("replays", [])
    if entry.get("replay"):
        for rep in replays:
            if rep["file"] == entry["replay"]:
                return rep
    for rep in replays:
        if rep["clause"] == entry["id"]:
            return rep
    return None
