"""From a finished (or cut short) run to ``results.json`` and every report format.

The document is schema 1 (:mod:`helmcheck.reports.results`) with ``"role": "backseat"``: one
entry per §9 clause (RH-BS-1..8), the run verdict and the ``process`` object exactly as
:func:`helmcheck.reports.assemble.assemble` makes them from the verdict ledger (the observer's
findings, :class:`helmcheck.judge.ledger.Ledger`: verdict, reason, the scenarios it was observed
in as cases, ``offending_count`` and the first offending lines quoted as evidence) and the run
facts the record's notes give (:mod:`helmcheck.judge.runfacts`); the scenarios staged, the mode
timeline, the staged events; ``coverage.scenarios`` (each scenario as it ran: planned and actual
length, how long it was held open, its moments and when they reached the backseat, what is not
claimed, :mod:`.stage`) and ``run.overrun`` (how far the backseat's requests over-asked the
vehicle's line, or null). This module judges nothing and changes no verdict.
A MUST not met is ``fail``; a SHOULD not met ``non-strict`` (``fail`` with ``--strict``). A run
that never started or was cut short (the backseat never connected, closed the port, crashed,
or Ctrl-C) is ``partial`` and cannot certify: INCONCLUSIVE, with the reason first in
``verdict_reason`` — unless a MUST already failed, which stands; a backseat helmcheck started
that ended early fails the run (:mod:`.process`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Optional

from ...clauses import backseat_clauses
from ...judge.backseat import BS_CLAUSES
from ...judge.ledger import Ledger
from ...judge.runfacts import RunFacts
from ...line.reopen import gap_event
from ...profile import Profile
from ...reports import render_all
from ...reports.assemble import apply, assemble
from ...reports.results import add_event, add_mode, new_results, write_results_atomic
from .runner import RunRecord

__all__ = ["build_results", "write_reports"]


def build_results(outcome: Optional[RunRecord], *, profile: Profile, settings: dict[str, Any],
                  command: str, port: str, started: str, reason: str = "") -> dict[str, Any]:
    """The results document of a run (``outcome`` None: the run could not start at all)."""
    strict = bool(settings.get("strict", False))
    results = new_results("backseat", command=command, started=started,
                          implementation={"port": port, "protocol": profile.protocol},
                          profile=profile.as_dict(), settings=settings)
    why = outcome.reason if outcome is not None else reason
    if outcome is None:  # no record at all: the facts its notes would have given
        ledger = Ledger([c.id for c in backseat_clauses()])
        facts = RunFacts(not_judged={cid: f"not judged: {why}" for cid in BS_CLAUSES}, partial=why)
    else:
        ledger, facts = outcome.observer.ledger, outcome.facts
    # the lead: why a run was cut short (the outcome's words: they name a signal), or why a run that
    # finished is partial all the same (a scenario's moment did not reach the backseat)
    lead = why if facts.interrupted else (facts.partial or "")
    a = assemble("backseat", ledger, facts, strict=strict, lead=lead)
    if outcome is not None and outcome.status != "never-connected":
        for t, kind, label in outcome.events:
            add_event(results, round(t, 6), kind, label)
        seen: list[str] = []
        for t, mode in outcome.modes:
            add_mode(results, round(t, 6), mode)
            if mode not in seen:
                seen.append(mode)
        results["coverage"]["modes"] = seen
        results["coverage"]["scenarios"] = [dict(c) for c in outcome.coverage]
        results["scenarios"] = list(outcome.scenarios_run)
        results["run"] = {"status": outcome.status, "connected_at": outcome.connected_at,
                          "ended_at": round(outcome.ended_at, 3), "planned_s": round(outcome.planned, 3),
                          "bytes_from_backseat": outcome.observer.stats["bytes"],
                          "lines_from_backseat": outcome.observer.stats["lines"],
                          "vehicle": outcome.vehicle_stats, "overrun": outcome.overrun}
        if outcome.gaps:  # helmcheck's port gone and waited for (.runner, link life)
            results["link_gaps"] = [dict(g) for g in outcome.gaps]
            for g in outcome.gaps:
                ev = gap_event(g)
                add_event(results, ev["t"], ev["kind"], ev["label"])
    apply(results, a, duration_s=round(outcome.ended_at - (outcome.connected_at or 0.0), 3) if outcome else 0.0)
    return results


def write_reports(directory: Path, results: dict[str, Any]) -> list[Path]:
    """Write ``results.json`` atomically, then every report format (each atomically)."""
    path = write_results_atomic(directory, results)
    return [path, *render_all(directory)]
