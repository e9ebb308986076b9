"""The HTML report's clause sections: the clause matrix by section, one finding per non-pass
clause (replay steps, wire excerpt), and the evidence of every passing clause.
"""

from __future__ import annotations

from typing import Any, Mapping

from ..judge.verdict import Verdict
from .html_markup import _e, _verdict_cell, md_inline
from .rundir import Run
from .view import VERDICT_LABEL, non_pass_rows, pass_rows, replay_for, sections

EVIDENCE_LIMIT = 200  # wire lines shown per finding


def _matrix(run: Run) -> str:
    out = []
    for section, title, rows in sections(run.results):
        c: dict[str, int] = {}
        for row in rows:
            c[row["verdict"]] = c.get(row["verdict"], 0) + 1
        tally = ", ".join(f"{n} {VERDICT_LABEL[v].lower()}" for v, n in c.items())
        out.append(f'<h3 id="section-{_e(section)}">{_e(section)}. {md_inline(title)} '
                   f'<span class="muted">({_e(tally)})</span></h3>')
        out.append('<table class="matrix"><thead><tr><th>ID</th><th>Requirement</th><th>Level</th>'
                   "<th>Verdict</th><th>Reason</th><th>Cases</th></tr></thead><tbody>")
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
                       f'<td class="reason">{_e(row["reason"])}</td>'
                       f'<td class="cases mono">{_e(", ".join(row["cases"]))}</td></tr>')
        out.append("</tbody></table>")
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
    return f'<p>Replay <span class="mono">{_e(replay["file"])}</span>:</p><ol class="replay">{"".join(items)}</ol>'


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
    """The wire evidence of every passing clause (its first deciding exchange)."""
    out = []
    for row in pass_rows(run.results):
        cid = _e(row["id"])
        out.append(f'<section class="pass-evidence" id="evidence-{cid}">')
        out.append(f'<h3><a href="#clause-{cid}">{cid}</a> — <span class="v-pass">PASS</span> '
                   f'<span class="muted">({_e(row["level"])})</span></h3>')
        out.append(f"<p>{_e(row['reason'])}</p>")
        if row["evidence"]:
            out.append(_wire_excerpt(row["evidence"]))
        else:
            out.append('<p class="muted">No wire evidence recorded for this clause.</p>')
        out.append("</section>")
    return "\n".join(out) if out else '<p class="muted">No clause passed.</p>'
