"""Comparing two runs: which clauses regressed, which got fixed, what else changed.

Verdicts are ranked pass < non-strict < inconclusive < fail. A clause whose verdict moved up
that ranking *regressed*; one that moved down got *fixed*; a move to or from ``not-tested``
(coverage gained or lost) is *changed*. Clauses present in only one run are *added* or
*removed*. The result is a plain dict, rendered as plain text, Markdown or an HTML fragment.
"""

from __future__ import annotations

from html import escape
from typing import Any, Mapping

from .markdown import md_escape
from .rundir import Run
from .text import printable
from .view import VERDICT_LABEL

__all__ = ["compare", "compare_runs", "compare_text", "compare_markdown", "compare_html"]

_RANK = {"pass": 0, "non-strict": 1, "inconclusive": 2, "fail": 3}


def compare(old: Mapping[str, Any], new: Mapping[str, Any]) -> dict[str, Any]:
    """Differences from results *old* to results *new*.

    Returns ``{"verdict": (old, new), "regressed": [...], "fixed": [...], "changed": [...],
    "added": [...], "removed": [...], "unchanged": n}``; each list item is
    ``{"id", "old", "new", "reason"}`` (``old``/``new`` ``None`` for an absent clause; ``reason``
    is the new run's, or the old one's for a removed clause), in the new run's clause order.
    """
    old_by = {c["id"]: c for c in old["clauses"]}
    new_by = {c["id"]: c for c in new["clauses"]}
    out: dict[str, Any] = {"verdict": (old["verdict"], new["verdict"]),
                           "regressed": [], "fixed": [], "changed": [], "added": [], "removed": [],
                           "unchanged": 0}
    for cid, c in new_by.items():
        before = old_by.get(cid)
        item = {"id": cid, "old": before["verdict"] if before else None, "new": c["verdict"], "reason": c["reason"]}
        if before is None:
            out["added"].append(item)
        elif item["old"] == item["new"]:
            out["unchanged"] += 1
        elif item["old"] in _RANK and item["new"] in _RANK:
            out["regressed" if _RANK[item["new"]] > _RANK[item["old"]] else "fixed"].append(item)
        else:
            out["changed"].append(item)
    for cid, c in old_by.items():
        if cid not in new_by:
            out["removed"].append({"id": cid, "old": c["verdict"], "new": None, "reason": c["reason"]})
    return out


def compare_runs(old: Run, new: Run) -> dict[str, Any]:
    """:func:`compare` plus both runs' directories and certificate digests."""
    out = compare(old.results, new.results)
    out["old_dir"], out["new_dir"] = str(old.directory), str(new.directory)
    out["old_digest"], out["new_digest"] = old.digest.combined, new.digest.combined
    return out


_GROUPS = (("regressed", "Regressed"), ("fixed", "Fixed"), ("changed", "Changed otherwise"),
           ("added", "Only in the new run"), ("removed", "Only in the old run"))


def _word(v: str | None) -> str:
    return "—" if v is None else VERDICT_LABEL.get(v, v)


def compare_text(cmp: Mapping[str, Any]) -> str:
    """A plain-text summary (for a terminal)."""
    old_v, new_v = cmp["verdict"]
    lines = [f"overall: {_word(old_v)} -> {_word(new_v)}"]
    tally = ", ".join(f"{len(cmp[k])} {k}" for k, _ in _GROUPS) + f", {cmp['unchanged']} unchanged"
    lines.append(tally)
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
    out.append(", ".join(f"{len(cmp[k])} {t.lower()}" for k, t in _GROUPS) + f", {cmp['unchanged']} unchanged.")
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
    tally = ", ".join(f"{len(cmp[k])} {t.lower()}" for k, t in _GROUPS) + f", {cmp['unchanged']} unchanged"
    out.append(f"<p>{e(tally)}.</p>")
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
