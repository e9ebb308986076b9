"""The verdict rules: one clause verdict per clause, one verdict per run, one exit status.

Reference profile, preamble: a MUST not met gives FAIL, a SHOULD not met gives NON-STRICT.

* :func:`overall_verdict` — any ``fail`` → ``fail``; else any ``inconclusive`` →
  ``inconclusive``; else any ``non-strict`` → ``non-strict`` (``fail`` when *strict*: a SHOULD
  is then held to a MUST); else ``pass``. ``not-tested`` never lowers the verdict.
* :func:`run_verdict` — the verdict written into ``results.json``: :func:`overall_verdict`,
  except that a run that was interrupted (``partial``) or that judged no clause at all cannot
  certify ``pass``/``non-strict`` and is ``inconclusive`` instead. An observed ``fail`` stays.
* :func:`exit_code` — pass → 0, non-strict → 0 (1 when strict), fail → 1, inconclusive → 2.
"""

from __future__ import annotations

from typing import Any, Iterable, Mapping

__all__ = ["VERDICTS", "CLAUSE_VERDICTS", "overall_verdict", "run_verdict", "exit_code", "describe_verdict"]

VERDICTS = ("pass", "non-strict", "fail", "inconclusive")
CLAUSE_VERDICTS = VERDICTS + ("not-tested",)

_RANK = {"pass": 0, "non-strict": 1, "inconclusive": 2, "fail": 3}


def overall_verdict(clause_verdicts: Iterable[str], strict: bool = False) -> str:
    """The verdict of a set of clause verdicts (precedence fail > inconclusive > non-strict > pass).

    ``not-tested`` does not lower the verdict. With *strict*, a ``non-strict`` clause (a SHOULD
    not met) counts as ``fail``. An unknown verdict word raises ``ValueError``.
    """
    worst = "pass"
    for v in clause_verdicts:
        if v == "not-tested":
            continue
        if v not in _RANK:
            raise ValueError(f"unknown clause verdict {v!r}; expected one of {CLAUSE_VERDICTS}")
        if strict and v == "non-strict":
            v = "fail"
        if _RANK[v] > _RANK[worst]:
            worst = v
    return worst


def run_verdict(clause_verdicts: Iterable[str], *, strict: bool = False, partial: bool = False) -> str:
    """The verdict a run records: :func:`overall_verdict`, made ``inconclusive`` when the run was
    interrupted or judged nothing and would otherwise claim ``pass`` or ``non-strict``."""
    verdicts = list(clause_verdicts)
    verdict = overall_verdict(verdicts, strict)
    judged = any(v != "not-tested" for v in verdicts)
    if verdict in ("pass", "non-strict") and (partial or not judged):
        return "inconclusive"
    return verdict


def exit_code(verdict: str, strict: bool = False) -> int:
    """Process exit status for a run verdict: pass 0, non-strict 0 (1 if strict), fail 1,
    inconclusive 2."""
    if verdict == "pass":
        return 0
    if verdict == "non-strict":
        return 1 if strict else 0
    if verdict == "fail":
        return 1
    if verdict == "inconclusive":
        return 2
    raise ValueError(f"unknown verdict {verdict!r}; expected one of {VERDICTS}")


def _id_list(ids: list[str], limit: int = 5) -> str:
    shown = ", ".join(ids[:limit])
    return shown if len(ids) <= limit else f"{shown} and {len(ids) - limit} more"


def describe_verdict(clauses: list[Mapping[str, Any]], *, strict: bool = False, partial: bool = False) -> str:
    """One sentence explaining :func:`run_verdict` for these clause entries."""
    text = _describe(clauses, strict=strict, partial=partial)
    if partial and "interrupted" not in text:
        text += " The run was interrupted before it finished."
    return text


def _describe(clauses: list[Mapping[str, Any]], *, strict: bool, partial: bool) -> str:
    by: dict[str, list[str]] = {v: [] for v in CLAUSE_VERDICTS}
    for c in clauses:
        by.setdefault(c["verdict"], []).append(c["id"])
    verdict = run_verdict([c["verdict"] for c in clauses], strict=strict, partial=partial)
    judged = len(clauses) - len(by["not-tested"])
    if verdict == "fail":
        if by["fail"]:
            return f"{len(by['fail'])} clause(s) failed: {_id_list(by['fail'])}."
        return f"Strict run: {len(by['non-strict'])} SHOULD clause(s) not met: {_id_list(by['non-strict'])}."
    if verdict == "inconclusive":
        if by["inconclusive"]:
            return (f"No clause failed, but {len(by['inconclusive'])} could not be judged: "
                    f"{_id_list(by['inconclusive'])}.")
        if partial:
            return f"The run was interrupted after judging {judged} clause(s); nothing failed before it stopped."
        return "No clause was judged."
    if verdict == "non-strict":
        return (f"Every MUST judged is met; {len(by['non-strict'])} SHOULD clause(s) not met: "
                f"{_id_list(by['non-strict'])}.")
    untested = f" ({len(by['not-tested'])} not tested)" if by["not-tested"] else ""
    return f"All {judged} judged clause(s) pass{untested}."
