"""The HTML report's clause sections: the clause matrix by section (one fold per section of the
reference profile, open when a clause in it failed or was inconclusive; fixed columns; the first
few cases of a clause shown and the rest folded), one finding per non-pass clause (replay steps,
wire excerpt), and the evidence of every passing clause (one fold each).
"""

from __future__ import annotations

from typing import Any, Mapping

from ..judge.verdict import Verdict
from .html_markup import _e, _verdict_cell, md_inline
from .rundir import Run
from .view import VERDICT_LABEL, non_pass_rows, pass_rows, replay_for, sections

EVIDENCE_LIMIT = 200  # wire lines shown per finding
REPLAY_OPEN = 12  # a finding's replay with at most this many steps is shown unfolded


#: Verdicts that open their section of the matrix (a NOT-TESTED clause is named in the banner).
_ATTENTION = (Verdict.FAIL, Verdict.NON_STRICT, Verdict.INCONCLUSIVE)
#: Case names shown in a matrix row before the rest fold behind "+N more".
CASES_SHOWN = 6
#: The matrix's columns: (class, heading). Every section's table has the same ``<colgroup>``
#: (widths in :mod:`~helmcheck.reports.html_style`, fixed layout), so the columns line up down
#: the page and a long cell wraps instead of widening the table.
_COLUMNS = (("id", "ID"), ("req", "Requirement"), ("level", "Level"), ("verdict", "Verdict"),
            ("reason", "Reason"), ("cases", "Cases"))


def _tally(rows: list[Mapping[str, Any]]) -> dict[str, int]:
    c: dict[str, int] = {}
    for row in rows:
        c[row["verdict"]] = c.get(row["verdict"], 0) + 1
    return c


def _tally_chips(c: Mapping[str, int]) -> str:
    return " ".join(f'<span class="tally v-{_e(v)}">{n} {_e(VERDICT_LABEL.get(v, v).lower())}</span>'
                    for v, n in c.items())


def _cases_cell(cases: list[str]) -> str:
    """The cases of one clause: the first :data:`CASES_SHOWN`, the rest folded."""
    if not cases:
        return '<td class="cases"><span class="muted">—</span></td>'
    shown, rest = (cases, []) if len(cases) <= CASES_SHOWN + 1 else (cases[:CASES_SHOWN], cases[CASES_SHOWN:])

    def names(part: list[str]) -> str:
        return ", ".join(f'<span class="case">{_e(c)}</span>' for c in part)

    out = names(shown)
    if rest:
        out += f'<details class="more"><summary>+{len(rest)} more</summary>{names(rest)}</details>'
    return f'<td class="cases mono">{out}</td>'


def _matrix(run: Run) -> str:
    """One fold per section of the reference profile, open when a clause in it failed or was
    inconclusive (:data:`_ATTENTION`)."""
    out = []
    cols = "".join(f'<col class="c-{cls}">' for cls, _ in _COLUMNS)
    head = "".join(f"<th>{title}</th>" for _, title in _COLUMNS)
    for section, title, rows in sections(run.results):
        c = _tally(rows)
        attention = any(v in _ATTENTION for v in c)
        out.append(f'<details class="group" id="section-{_e(section)}"{" open" if attention else ""}>'
                   f'<summary><h3>{_e(section)}. {md_inline(title)}</h3> {_tally_chips(c)}</summary>')
        out.append(f'<table class="matrix"><colgroup>{cols}</colgroup><thead><tr>{head}</tr></thead><tbody>')
        for row in rows:
            v = row["verdict"]
            text = md_inline(row["text"]) if row["text"] else '<span class="warn">not in the reference profile</span>'
            cid = _e(row["id"])
            if _has_finding(run, row):
                link = f'<a href="#finding-{cid}">{cid}</a>'
            elif v == Verdict.PASS:
                link = f'<a href="#evidence-{cid}">{cid}</a>'
            else:
                link = cid
            out.append(f'<tr class="clause" id="clause-{cid}" data-verdict="{_e(v)}">'
                       f'<td class="id">{link}</td><td class="req">{text}</td>'
                       f'<td class="level">{_e(row["level"])}</td>{_verdict_cell(v)}'
                       f'<td class="reason">{_e(row["reason"])}</td>{_cases_cell(list(row["cases"]))}</tr>')
        out.append("</tbody></table></details>")
    if not out:
        out.append('<p class="warn">The results list no clauses.</p>')
    return "\n".join(out)


def _has_finding(run: Run, row: Mapping[str, Any]) -> bool:
    if row["verdict"] == Verdict.PASS:
        return False
    return row["verdict"] != Verdict.NOT_TESTED or bool(row["evidence"]) or replay_for(run.results, row) is not None


def _replay_steps(replay: Mapping[str, Any]) -> str:
    items = []
    for step in replay["steps"]:
        t = f'<span class="muted">t={step["t"]:.3f} s</span> ' if isinstance(step.get("t"), (int, float)) else ""
        if "send" in step:
            items.append(f"<li>{t}send <code>{_e(step['send'])}</code></li>")
        elif "wait" in step:
            items.append(f"<li>{t}wait {_e(step['wait'])} s</li>")
        else:
            items.append(f"<li>{t}expect <code>{_e(step['expect'])}</code></li>")
    head = f'Replay <span class="mono">{_e(replay["file"])}</span> ({len(items)} step(s))'
    return (f'<details class="replay"{" open" if len(items) <= REPLAY_OPEN else ""}><summary>{head}</summary>'
            f'<ol class="replay">{"".join(items)}</ol></details>')


def _wire_excerpt(evidence: list[Mapping[str, Any]]) -> str:
    shown = evidence[:EVIDENCE_LIMIT]
    lines = "\n".join(f'{ev["t"]:12.6f} {ev["dir"]:<2} {ev["line"]}' for ev in shown)
    more = (f'<p class="muted">… {len(evidence) - EVIDENCE_LIMIT} more evidence lines in results.json</p>'
            if len(evidence) > EVIDENCE_LIMIT else "")
    return f'<pre class="wire">{_e(lines)}</pre>{more}'


def _findings(run: Run) -> str:
    out = []
    for row in non_pass_rows(run.results):
        if not _has_finding(run, row):
            continue
        cid, v = _e(row["id"]), row["verdict"]
        out.append(f'<section class="finding v-{_e(v)}" id="finding-{cid}">')
        out.append(f'<h3><a href="#clause-{cid}">{cid}</a> — <span class="v-{_e(v)}">'
                   f'{_e(VERDICT_LABEL.get(v, v))}</span> <span class="muted">({_e(row["level"])})</span></h3>')
        if row["text"]:
            out.append(f'<p class="req">{md_inline(row["text"])}</p>')
        out.append(f'<p><b>Reason:</b> {_e(row["reason"])}</p>')
        if row["cases"]:
            out.append(f'<p><b>Cases:</b> <span class="mono">{_e(", ".join(row["cases"]))}</span></p>')
        if row["offending_count"]:
            out.append(f'<p><b>Offending sentences:</b> {_e(row["offending_count"])}</p>')
        replay = replay_for(run.results, row)
        out.append(_replay_steps(replay) if replay else '<p class="muted">No replay recorded.</p>')
        if row["evidence"]:
            out.append(f"<p>Wire excerpt ({len(row['evidence'])} line(s), seconds since the log started):</p>")
            out.append(_wire_excerpt(row["evidence"]))
        else:
            out.append('<p class="muted">No wire evidence recorded.</p>')
        out.append("</section>")
    return "\n".join(out) if out else '<p>Every judged clause passes; nothing to show.</p>'


def _pass_evidence(run: Run) -> str:
    """The wire evidence of every passing clause (its first deciding exchange), one fold each."""
    out = []
    for row in pass_rows(run.results):
        cid = _e(row["id"])
        n = len(row["evidence"])
        out.append(f'<section class="pass-evidence" id="evidence-{cid}"><details><summary>'
                   f'<a href="#clause-{cid}">{cid}</a> <span class="muted">({_e(row["level"])}, '
                   f'{n} line(s))</span> {_e(row["reason"])}</summary>')
        if row["evidence"]:
            out.append(_wire_excerpt(row["evidence"]))
        else:
            out.append('<p class="muted">No wire evidence recorded for this clause.</p>')
        out.append("</details></section>")
    return "\n".join(out) if out else '<p class="muted">No clause passed.</p>'
