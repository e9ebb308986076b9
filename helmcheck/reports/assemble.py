"""The one way from judge to certificate: ledger + run facts → clause entries, run verdict, scope.

:func:`assemble` is called by every producer of a results document — ``certify vehicle``
(:mod:`helmcheck.certify.vehicle.runner`), ``certify backseat``
(:mod:`helmcheck.certify.backseat.report`), ``check-log``
(:mod:`helmcheck.checklog.report`) — and by ``helmcheck verify``
(:mod:`.verify`), which runs it again on the evidence and compares. Its inputs:

* the verdict ledger of the role's observer (:class:`helmcheck.judge.ledger.Ledger`), or the
  entries of one (``check-log`` returns entries);
* the run facts read from the wire log's notes (:class:`helmcheck.judge.runfacts.RunFacts`):
  the selection, the clauses not judged, a backseat scenario's observations not claimed
  (``not claimed``), the implementation under test's end (``process``), whether the run was cut
  short or a scenario not exercised (``run partial``), the line model (``line model:``), a line
  overrun (``line overrun:``, a remark the reason ends with).

Its outputs (:class:`Assembly`): the clause entries of ``results.json`` (the facts booked into
the ledger first: a clause not selected or not judged is NOT-TESTED unless a violation was
observed), ``partial``, the ``process`` object, ``line_model`` (whether the link could damage
bytes, and why: :mod:`helmcheck.judge.linemodel`), the run verdict
(:func:`~.verdicts.run_verdict`: an implementation that ended early is FAIL), its reason
(:func:`~.verdicts.describe_verdict`) and the scope (:func:`~.scope.scope_of`: the certificate
flag). :func:`apply` writes an assembly into a results document; nothing changes a verdict after
it.
"""

from __future__ import annotations

from dataclasses import dataclass
from datetime import datetime, timezone
from typing import Any, Iterable, Optional

from ..judge.runfacts import RunFacts
from .scope import Scope, scope_of
from .verdicts import describe_verdict, run_verdict

__all__ = ["Assembly", "assemble", "apply"]


@dataclass(frozen=True)
class Assembly:
    """Everything a results document says about the verdicts (module docstring)."""

    role: str
    clauses: list
    partial: bool
    process: Optional[dict]
    line_model: dict
    verdict: str
    verdict_reason: str
    scope: Scope

    @property
    def certificate(self) -> bool:
        return self.scope.certificate

    def verdicts(self) -> dict[str, str]:
        return {c["id"]: c["verdict"] for c in self.clauses}


def assemble(role: str, judged: Any, facts: Optional[RunFacts] = None, *, strict: bool = False,
             partial: Optional[bool] = None, lead: str = "") -> Assembly:
    """Assemble one run (module docstring).

    *judged*: a :class:`~helmcheck.judge.ledger.Ledger` (the facts are booked into it here) or
    its entries (already booked, as :func:`helmcheck.checklog.check_log` returns
    them). *partial*: ``None`` takes it from the facts (a ``run partial`` note); ``True`` for a
    run still in progress. *lead*: a sentence put before the verdict reason (why the run
    stopped; not when the implementation ended early, whose end the reason quotes); it changes
    no verdict. *role*: ``vehicle``, ``backseat`` or ``log``."""
    facts = facts if facts is not None else RunFacts()
    if hasattr(judged, "entries"):
        facts.book(judged)
        entries: Iterable[dict] = judged.entries()
    else:
        entries = judged
    clauses = [dict(e) for e in entries]
    cut = facts.partial is not None if partial is None else bool(partial)
    process = dict(facts.process) if facts.process is not None else None
    verdicts = [c["verdict"] for c in clauses]
    verdict = run_verdict(verdicts, strict=strict, partial=cut, process_failed=facts.ended_early)
    reason = describe_verdict(clauses, strict=strict, partial=cut, process=process,
                              subject=role if role in ("vehicle", "backseat") else "implementation",
                              interrupted=partial is not None or facts.partial is None or facts.interrupted)
    if lead and not facts.ended_early:  # an implementation that ended early: its end is the reason
        reason = f"{lead[:1].upper()}{lead[1:]}. {reason}"
    if facts.overrun:  # a remark: it changes no verdict (RH-BS-4 bounds what the backseat sends)
        reason += (f" Line overrun (a remark beside RH-BS-4, which bounds only the bytes the backseat sends): "
                   f"{facts.overrun}.")
    scope = scope_of({"role": role, "clauses": clauses, "partial": cut})
    return Assembly(role, clauses, cut, process, facts.line_model.as_dict(), verdict, reason, scope)


def apply(results: dict[str, Any], a: Assembly, *, final: bool = True, finished: Optional[str] = None,
          duration_s: Optional[float] = None) -> dict[str, Any]:
    """Write *a* into *results*: ``clauses``, ``partial``, ``process`` (removed when there is
    none), ``verdict``, ``verdict_reason``; with *final* also ``finished`` and ``duration_s``.
    Returns *results*."""
    results["clauses"] = a.clauses
    results["partial"] = a.partial
    if a.process is not None:
        results["process"] = a.process
    else:
        results.pop("process", None)
    results["line_model"] = a.line_model
    results["verdict"] = a.verdict
    results["verdict_reason"] = a.verdict_reason
    if final:
        results["finished"] = finished or datetime.now(timezone.utc).isoformat(timespec="seconds").replace(
            "+00:00", "Z")
        if duration_s is None:
            try:
                t0 = datetime.fromisoformat(results["started"])
                t1 = datetime.fromisoformat(results["finished"])
                duration_s = max(0.0, round((t1 - t0).total_seconds(), 3))
            except (KeyError, TypeError, ValueError):
                duration_s = None
        results["duration_s"] = duration_s
    return results
