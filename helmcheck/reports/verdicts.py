"""The verdict rules: one clause verdict per clause, one verdict per run, one exit status.

Reference profile, preamble: a MUST not met gives FAIL, a SHOULD not met gives NON-STRICT. The
words are :class:`helmcheck.judge.verdict.Verdict`'s; :data:`VERDICTS` and :data:`CLAUSE_VERDICTS`
are the same words as plain strings (for messages and the schema).

* :func:`overall_verdict` — any ``fail`` → ``fail``; else any ``inconclusive`` →
  ``inconclusive``; else any ``non-strict`` → ``non-strict`` (``fail`` when *strict*: a SHOULD
  is then held to a MUST); else ``pass``. ``not-tested`` never lowers the verdict.
* :func:`run_verdict` — the verdict written into ``results.json``: :func:`overall_verdict`,
  except that a run that was interrupted (``partial``) or that judged no clause at all cannot
  certify ``pass``/``non-strict`` and is ``inconclusive`` instead. An observed ``fail`` stays.
  A run whose implementation under test was started by helmcheck (``--exec``) and ended before
  the run's end (``process_failed``: exited with any code, or killed by a signal) is ``fail``
  whatever its clauses say: an implementation that dies during certification cannot be
  certified, and the death is a finding about it, not a link fault.
* :func:`describe_process` — one sentence quoting such an exit and its last output.
* :func:`exit_code` — pass → 0, non-strict → 0 (1 when strict), fail → 1, inconclusive → 2.
"""

from __future__ import annotations

from typing import Any, Iterable, Mapping

from ..judge.verdict import CLAUSE_VERDICTS as ALL_CLAUSE_VERDICTS, RUN_VERDICTS, Verdict

__all__ = ["VERDICTS", "CLAUSE_VERDICTS", "SEVERITY", "overall_verdict", "run_verdict", "exit_code", "describe_verdict",
           "describe_process", "ended_early"]

#: the words of :data:`helmcheck.judge.verdict.RUN_VERDICTS` and ``CLAUSE_VERDICTS``, as plain strings
VERDICTS = tuple(v.value for v in RUN_VERDICTS)
CLAUSE_VERDICTS = tuple(v.value for v in ALL_CLAUSE_VERDICTS)

#: how bad a run verdict is (higher is worse): the precedence of :func:`overall_verdict`
SEVERITY = {Verdict.PASS: 0, Verdict.NON_STRICT: 1, Verdict.INCONCLUSIVE: 2, Verdict.FAIL: 3}


def overall_verdict(clause_verdicts: Iterable[str], strict: bool = False) -> str:
    """The verdict of a set of clause verdicts (precedence fail > inconclusive > non-strict > pass).

    ``not-tested`` does not lower the verdict. With *strict*, a ``non-strict`` clause (a SHOULD
    not met) counts as ``fail``. An unknown verdict word raises ``ValueError``.
    """
    worst = Verdict.PASS
    for v in clause_verdicts:
        if v == Verdict.NOT_TESTED:
            continue
        if v not in SEVERITY:
            raise ValueError(f"unknown clause verdict {v!r}; expected one of {CLAUSE_VERDICTS}")
        if strict and v == Verdict.NON_STRICT:
            v = Verdict.FAIL
        if SEVERITY[v] > SEVERITY[worst]:
            worst = v
    return worst


def run_verdict(clause_verdicts: Iterable[str], *, strict: bool = False, partial: bool = False,
                process_failed: bool = False) -> str:
    """The verdict a run records: :func:`overall_verdict`, made ``inconclusive`` when the run was
    interrupted or judged nothing and would otherwise claim ``pass`` or ``non-strict``; ``fail``
    when the implementation under test ended early (*process_failed*, see the module docstring)."""
    verdicts = list(clause_verdicts)
    if process_failed:
        for v in verdicts:  # still refuse unknown words
            if v not in CLAUSE_VERDICTS:
                raise ValueError(f"unknown clause verdict {v!r}; expected one of {CLAUSE_VERDICTS}")
        return Verdict.FAIL
    verdict = overall_verdict(verdicts, strict)
    judged = any(v != Verdict.NOT_TESTED for v in verdicts)
    if verdict in (Verdict.PASS, Verdict.NON_STRICT) and (partial or not judged):
        return Verdict.INCONCLUSIVE
    return verdict


def exit_code(verdict: str, strict: bool = False) -> int:
    """Process exit status for a run verdict: pass 0, non-strict 0 (1 if strict), fail 1,
    inconclusive 2."""
    if verdict == Verdict.PASS:
        return 0
    if verdict == Verdict.NON_STRICT:
        return 1 if strict else 0
    if verdict == Verdict.FAIL:
        return 1
    if verdict == Verdict.INCONCLUSIVE:
        return 2
    raise ValueError(f"unknown verdict {verdict!r}; expected one of {VERDICTS}")


def _id_list(ids: list[str], limit: int = 5) -> str:
    shown = ", ".join(ids[:limit])
    return shown if len(ids) <= limit else f"{shown} and {len(ids) - limit} more"


def ended_early(results: Mapping[str, Any]) -> bool:
    """Did the implementation under test of this results document end before the run's end?"""
    process = results.get("process")
    return isinstance(process, Mapping) and process.get("ended_early") is True


_OUTPUT_QUOTE = 200  #: characters of the last output line quoted in a verdict reason


def describe_process(process: Mapping[str, Any], subject: str = "implementation") -> str:
    """One sentence on how a started implementation ended: code or signal, when, its last output.

    ``subject`` names it (``backseat``, ``vehicle``). Used for the verdict reason of a run whose
    implementation ended early, and by the reports.
    """
    if process.get("signal"):
        how = f"was killed by {process['signal']}"
    elif process.get("exit_code") is not None:
        how = f"exited with code {process['exit_code']}"
    else:
        how = "ended"
    at = process.get("ended_at_s")
    when = f" at {at:.1f} s" if isinstance(at, (int, float)) and not isinstance(at, bool) else ""
    text = f"The {subject} under test {how}{when}"
    text += ", before the run's end" if process.get("ended_early") else ", when helmcheck stopped it"
    tail = [line.strip() for line in process.get("output_tail") or () if isinstance(line, str) and line.strip()]
    if tail:
        last = tail[-1]
        if len(last) > _OUTPUT_QUOTE:
            last = last[: _OUTPUT_QUOTE - 1] + "…"
        text += f"; its last output: “{last}”"
    else:
        text += "; it wrote no output"
    return text + "."


def describe_verdict(clauses: list[Mapping[str, Any]], *, strict: bool = False, partial: bool = False,
                     process: Mapping[str, Any] | None = None, subject: str = "implementation",
                     interrupted: bool = True) -> str:
    """One sentence explaining :func:`run_verdict` for these clause entries (and *process*, the
    implementation under test when helmcheck started it). *interrupted*: a partial run was cut
    short (False: it finished, but not everything it exists for was exercised)."""
    if process is not None and process.get("ended_early") is True:
        judged = [c for c in clauses if c["verdict"] != Verdict.NOT_TESTED]
        failed = [c["id"] for c in clauses if c["verdict"] == Verdict.FAIL]
        text = (f"{describe_process(process, subject)} An implementation that dies during certification "
                f"cannot be certified ({len(judged)} clause(s) judged before it ended")
        text += f", {len(failed)} of them failed: {_id_list(failed)})." if failed else ")."
        return text
    text = _describe(clauses, strict=strict, partial=partial, interrupted=interrupted)
    if partial and interrupted and "interrupted" not in text:
        text += " The run was interrupted before it finished."
    return text


def _describe(clauses: list[Mapping[str, Any]], *, strict: bool, partial: bool, interrupted: bool = True) -> str:
    by: dict[str, list[str]] = {v: [] for v in CLAUSE_VERDICTS}
    for c in clauses:
        by.setdefault(c["verdict"], []).append(c["id"])
    verdict = run_verdict([c["verdict"] for c in clauses], strict=strict, partial=partial)
    judged = len(clauses) - len(by[Verdict.NOT_TESTED])
    if verdict == Verdict.FAIL:
        if by[Verdict.FAIL]:
            return f"{len(by['fail'])} clause(s) failed: {_id_list(by['fail'])}."
        return f"Strict run: {len(by['non-strict'])} SHOULD clause(s) not met: {_id_list(by['non-strict'])}."
    if verdict == Verdict.INCONCLUSIVE:
        if by[Verdict.INCONCLUSIVE]:
            return (f"No clause failed, but {len(by['inconclusive'])} could not be judged: "
                    f"{_id_list(by['inconclusive'])}.")
        if partial and not interrupted:
            worst = overall_verdict([c["verdict"] for c in clauses], strict)
            found = (f"; {len(by['non-strict'])} SHOULD clause(s) not met: {_id_list(by['non-strict'])}"
                     if worst == Verdict.NON_STRICT else "")
            return (f"No MUST failed in {judged} judged clause(s){found}; not a certificate, as not every "
                    f"scenario was exercised.")
        if partial:
            return f"The run was interrupted after judging {judged} clause(s); nothing failed before it stopped."
        return "No clause was judged."
    if verdict == Verdict.NON_STRICT:
        return (f"Every MUST judged is met; {len(by['non-strict'])} SHOULD clause(s) not met: "
                f"{_id_list(by['non-strict'])}.")
    untested = f" ({len(by['not-tested'])} not tested)" if by[Verdict.NOT_TESTED] else ""
    return f"All {judged} judged clause(s) pass{untested}."
