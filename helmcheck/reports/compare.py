"""Comparing two runs: which clauses regressed, which got fixed, what else changed.

Verdicts are ranked pass < non-strict < inconclusive < fail. A clause whose verdict moved up
that ranking *regressed*; one that moved down got *fixed*. A clause judged before (any verdict
but ``not-tested``) and not judged now (``not-tested``, or gone from the new run) is *lost
coverage* — as serious for a certificate as a regression, so it is counted next to it
(``report --compare OLD --fail-on-regression`` exits 1 on either); the reverse is *gained
coverage*. Clauses only in the new run are *added* (unless that is gained coverage); clauses only
in the old run that were not judged there either are *removed*. The scope of both runs
(certificate or partial, :mod:`helmcheck.reports.scope`) is compared too. The result is a plain
dict, rendered as plain text, Markdown or an HTML fragment.
"""

from __future__ import annotations

from html import escape
from typing import Any, Mapping

from .markdown import md_escape
from .rundir import Run
from ..judge.verdict import Verdict
from .scope import scope_of
from .text import printable
from .verdicts import SEVERITY as _RANK
from .view import VERDICT_LABEL

__all__ = ["compare", "compare_runs", "compare_text", "compare_markdown", "compare_html", "worsened"]

def compare(old: Mapping[str, Any], new: Mapping[str, Any]) -> dict[str, Any]:
    """Differences from results *old* to results *new*.

    Returns ``{"verdict": (old, new), "scope": (old statement, new statement), "certificate":
    (old, new), "regressed": [...], "lost": [...], "fixed": [...], "gained": [...], "changed":
    [...], "added": [...], "removed": [...], "unchanged": n}``; each list item is ``{"id", "old",
    "new", "reason"}`` (``old``/``new`` ``None`` for an absent clause; ``reason`` is the new
    run's, or the old one's for a clause gone from the new run), in the new run's clause order.
    """
    old_by = {c["id"]: c for c in old["clauses"]}
    new_by = {c["id"]: c for c in new["clauses"]}
    old_scope, new_scope = scope_of(old), scope_of(new)
    out: dict[str, Any] = {"verdict": (old["verdict"], new["verdict"]),
                           "scope": (old_scope.statement, new_scope.statement),
                           "certificate": (old_scope.certificate, new_scope.certificate),
                           "regressed": [], "lost": [], "fixed": [], "gained": [], "changed": [], "added": [],
                           "removed": [], "unchanged": 0}
    for cid, c in new_by.items():
        before = old_by.get(cid)
        item = {"id": cid, "old": before["verdict"] if before else None, "new": c["verdict"], "reason": c["reason"]}
        was_judged = before is not None and item["old"] != Verdict.NOT_TESTED
        if item["old"] == item["new"]:
            out["unchanged"] += 1
        elif was_judged and item["new"] == Verdict.NOT_TESTED:
            out["lost"].append(item)
        elif not was_judged and item["new"] != Verdict.NOT_TESTED:
            out["gained" if before is not None else "added"].append(item)
        elif before is None:
            out["added"].append(item)
        elif item["old"] in _RANK and item["new"] in _RANK:
            out["regressed" if _RANK[item["new"]] > _RANK[item["old"]] else "fixed"].append(item)
        else:
            out["changed"].append(item)
    for cid, c in old_by.items():
        if cid not in new_by:
            item = {"id": cid, "old": c["verdict"], "new": None, "reason": c["reason"]}
            out["lost" if c["verdict"] != Verdict.NOT_TESTED else "removed"].append(item)
    return out


def worsened(cmp: Mapping[str, Any]) -> bool:
    """Whether the new run regressed or lost coverage (``--fail-on-regression``)."""
    return bool(cmp["regressed"] or cmp["lost"])


def compare_runs(old: Run, new: Run) -> dict[str, Any]:
    """:func:`compare` plus both runs' directories and certificate digests."""
    out = compare(old.results, new.results)
    out["old_dir"], out["new_dir"] = str(old.directory), str(new.directory)
    out["old_digest"], out["new_digest"] = old.digest.combined, new.digest.combined
    return out


_GROUPS = (("regressed", "Regressed"), ("lost", "Lost coverage"), ("fixed", "Fixed"),
           ("gained", "Gained coverage"), ("changed", "Changed otherwise"), ("added", "Only in the new run"),
           ("removed", "Only in the old run"))


def _scope_line(cmp: Mapping[str, Any]) -> str | None:
    if "scope" not in cmp:
        return None
    old_s, new_s = cmp["scope"]
    return f"scope: {old_s} -> {new_s}" if old_s != new_s else f"scope: {new_s}"


def _word(v: str | None) -> str:
    return "—" if v is None else VERDICT_LABEL.get(v, v)


def _tally(cmp: Mapping[str, Any]) -> str:
    return ", ".join(f"{len(cmp[k])} {t.lower()}" for k, t in _GROUPS) + f", {cmp['unchanged']} unchanged"


def compare_text(cmp: Mapping[str, Any]) -> str:
    """A plain-text summary (for a terminal)."""
    old_v, new_v = cmp["verdict"]
    lines = [f"overall: {_word(old_v)} -> {_word(new_v)}"]
    if _scope_line(cmp):
        lines.append(_scope_line(cmp))
    lines.append(_tally(cmp))
    for key, title in _GROUPS:
        for item in cmp[key]:
            lines.append(f"  {title.lower()}: {item['id']} {_word(item['old'])} -> {_word(item['new'])}: "
                         f"{printable(item['reason'])}")
    return "\n".join(lines) + "\n"


def compare_markdown(cmp: Mapping[str, Any]) -> str:
    """A Markdown section (``### Compared with …``)."""
    old_v, new_v = cmp["verdict"]
    out = [f"### Compared with the earlier run: {_word(old_v)} → {_word(new_v)}", ""]
    if "old_digest" in cmp:
        out += [f"Earlier run digest `{cmp['old_digest']}`.", ""]
    if _scope_line(cmp):
        out += [md_escape(_scope_line(cmp)[0].upper() + _scope_line(cmp)[1:]) + ".", ""]
    out.append(_tally(cmp) + ".")
    out.append("")
    for key, title in _GROUPS:
        if not cmp[key]:
            continue
        out += [f"**{title}**", "", "| Clause | Before | Now | Reason |", "|---|---|---|---|"]
        out += [f"| {md_escape(i['id'])} | {_word(i['old'])} | {_word(i['new'])} | {md_escape(i['reason'])} |"
                for i in cmp[key]]
        out.append("")
    return "\n".join(out)


def compare_html(cmp: Mapping[str, Any]) -> str:
    """An HTML fragment (escaped) for the HTML report's comparison section."""
    def e(value: object) -> str:
        return escape(printable(value), quote=True)

    old_v, new_v = cmp["verdict"]
    out = [f'<p id="compare-verdict">Overall: <span class="v-{e(old_v)}">{e(_word(old_v))}</span> → '
           f'<span class="v-{e(new_v)}">{e(_word(new_v))}</span></p>']
    if "old_digest" in cmp:
        out.append(f'<p class="muted">Earlier run: <span class="mono">{e(cmp["old_dir"])}</span>, '
                   f'digest <span class="mono">{e(cmp["old_digest"])}</span></p>')
    if _scope_line(cmp):
        out.append(f'<p id="compare-scope">{e(_scope_line(cmp)[0].upper() + _scope_line(cmp)[1:])}.</p>')
    out.append(f'<p id="compare-tally">{e(_tally(cmp))}.</p>')
    for key, title in _GROUPS:
        if not cmp[key]:
            continue
        rows = "".join(
            f'<tr><td class="id">{e(i["id"])}</td>'
            f'<td class="v-{e(i["old"] or "none")}">{e(_word(i["old"]))}</td>'
            f'<td class="v-{e(i["new"] or "none")}">{e(_word(i["new"]))}</td><td>{e(i["reason"])}</td></tr>'
            for i in cmp[key])
        out.append(f'<h3 id="compare-{key}">{e(title)} ({len(cmp[key])})</h3>'
                   f'<table class="compare"><thead><tr><th>Clause</th><th>Before</th><th>Now</th>'
                   f"<th>Reason</th></tr></thead><tbody>{rows}</tbody></table>")
    return "\n".join(out)
