"""The overview of several runs: implementations (or builds) as columns, clauses as rows.

Pure functions: a list of :class:`MatrixRun` (a results document, where its report is, and
where it came from) in, one self-contained HTML page or one Markdown table out. Nothing is read
or written here (``helmcheck matrix`` does that, :mod:`helmcheck.commands.matrix_cmd`).

* Rows: every clause of the reference profile (:func:`helmcheck.clauses.catalogue`), in profile
  order, grouped by section; a clause a run has no entry for (a backseat run has no vehicle
  clauses) shows ``—``. Clause IDs a run lists that the profile does not know are not shown
  (the schema refuses them anyway).
* Columns, in the order given: labelled by the run's identity (:func:`column_label`), with its
  role, start date, run verdict and counts. A label shared by two columns gets the source
  (the results directory) appended, so every column can be told apart.
* Cells: the clause verdict, coloured, linking to that clause in the run's ``report.html``
  (``#clause-ID``), with the reason as a tooltip (HTML ``title``; no script).

Decisions: the label is ``results["identity"]`` when present (name and version keys, in the
order :data:`NAME_KEYS`, :data:`VERSION_KEYS`), else the declared ``implementation`` (vehicle
name, UVC version, serial), else the last component of the source (teams name their results
directories after what they test: ``uvc-3.2``, ``moos-ivp-nightly``); the start date (UTC,
``YYYY-MM-DD``) is always added. Every string from a results file
is escaped (HTML: ``html.escape`` after control characters are made visible; Markdown:
:func:`~helmcheck.reports.markdown.md_escape`); link targets are percent-encoded.
"""

from __future__ import annotations

from dataclasses import dataclass
from html import escape
from pathlib import PurePosixPath
from typing import Any, Mapping, Optional, Sequence
from urllib.parse import quote

from helmcheck.clauses import catalogue

from .html import md_inline
from .markdown import md_escape
from .text import printable
from .view import VERDICT_LABEL, counts

__all__ = ["MatrixRun", "Column", "columns", "column_label", "render_matrix_html", "render_matrix_markdown",
           "NAME_KEYS", "VERSION_KEYS", "ABSENT"]

NAME_KEYS = ("implementation", "name", "product", "vehicle_name", "vehicle", "backseat")
VERSION_KEYS = ("version", "build", "firmware", "uvc_version", "commit", "vehicle_serial", "serial")
ABSENT = "—"  #: a clause the run has no entry for


@dataclass(frozen=True)
class MatrixRun:
    """One run to show: its results document, the link to its ``report.html`` (relative to the
    matrix file, ``/``-separated; None: no link) and where it came from (a directory name)."""

    results: Mapping[str, Any]
    href: Optional[str] = None
    source: str = ""


@dataclass(frozen=True)
class Column:
    label: str
    detail: str  #: role, date, verdict
    run: MatrixRun


def _text(value: Any) -> str:
    return " ".join(printable(value).split()) if value is not None else ""


def _first(mapping: Mapping[str, Any], keys: Sequence[str]) -> str:
    for key in keys:
        value = mapping.get(key)
        if isinstance(value, (str, int, float)) and not isinstance(value, bool) and _text(value):
            return _text(value)
    return ""


def column_label(results: Mapping[str, Any], source: str = "") -> str:
    """The run's identity for a column heading (module docstring), without the date."""
    identity = results.get("identity")
    name = version = ""
    if isinstance(identity, Mapping):
        name, version = _first(identity, NAME_KEYS), _first(identity, VERSION_KEYS)
    impl = results.get("implementation")
    if not name and isinstance(impl, Mapping):
        name = _first(impl, ("vehicle_name",))
        version = version or _first(impl, ("uvc_version", "vehicle_serial"))
    if not name:
        name = _text(PurePosixPath(source.replace("\\", "/").rstrip("/")).name if source else "") or "run"
    return f"{name} {version}".strip()


def _date(results: Mapping[str, Any]) -> str:
    started = results.get("started")
    return started[:10] if isinstance(started, str) else ""


def columns(runs: Sequence[MatrixRun]) -> list[Column]:
    """One column per run, labels made distinct (module docstring)."""
    labels = [f"{column_label(r.results, r.source)} ({_date(r.results)})" if _date(r.results)
              else column_label(r.results, r.source) for r in runs]
    seen: dict[str, int] = {}
    for label in labels:
        seen[label] = seen.get(label, 0) + 1
    out = []
    for label, run in zip(labels, runs):
        if seen[label] > 1 and run.source:
            label = f"{label} [{_text(run.source)}]"
        r = run.results
        verdict = VERDICT_LABEL.get(r.get("verdict", ""), _text(r.get("verdict")))
        partial = " (partial)" if r.get("partial") else ""
        out.append(Column(label, f"{_text(r.get('role'))} · {_text(r.get('started'))} · {verdict}{partial}", run))
    return out


def _verdicts(results: Mapping[str, Any]) -> dict[str, Mapping[str, Any]]:
    return {c["id"]: c for c in results.get("clauses", ()) if isinstance(c, Mapping) and "id" in c}


def _sections() -> list[tuple[str, str, list[str]]]:
    grouped: dict[str, tuple[str, str, list[str]]] = {}
    for cid, clause in catalogue().items():
        grouped.setdefault(clause.section, (clause.section, clause.section_title, []))[2].append(cid)
    return list(grouped.values())


def _href(run: MatrixRun, cid: str | None = None) -> Optional[str]:
    if not run.href:
        return None
    target = quote(run.href, safe="/")
    return f"{target}#clause-{quote(cid)}" if cid else target


# --------------------------------------------------------------------------- HTML

def _e(value: Any) -> str:
    return escape(printable(value), quote=True)


_CSS = """
:root{--pass:#1a7f37;--pass-bg:#dafbe1;--ns:#9a6700;--ns-bg:#fff8c5;--fail:#cf222e;--fail-bg:#ffebe9;
--inc:#8250df;--inc-bg:#fbefff;--nt:#57606a;--nt-bg:#f6f8fa;--line:#d0d7de}
body{font:14px/1.45 system-ui,-apple-system,"Segoe UI",Roboto,sans-serif;color:#1f2328;margin:0;padding:16px 24px 48px}
h1{font-size:22px;margin:8px 0 12px}
table{border-collapse:collapse}th,td{border:1px solid var(--line);padding:3px 8px;text-align:left;vertical-align:top}
thead th{background:#f6f8fa;position:sticky;top:0}th.col{min-width:8em}th.col .detail{font-weight:400;color:#57606a;
font-size:12px}tr.section th{background:#eaeef2;text-align:left}td.id{font-weight:600;white-space:nowrap}
td.v{font-weight:700;white-space:nowrap;text-align:center}td.v a{color:inherit;text-decoration:none}
td.v a:hover{text-decoration:underline}
.v-pass{color:var(--pass);background:var(--pass-bg)}.v-non-strict{color:var(--ns);background:var(--ns-bg)}
.v-fail{color:var(--fail);background:var(--fail-bg)}.v-inconclusive{color:var(--inc);background:var(--inc-bg)}
.v-not-tested{color:var(--nt);background:var(--nt-bg)}.v-absent{color:#8c959f;background:#fff}
.muted{color:#57606a}td.level{font-size:12px;color:#57606a}
"""
_CSP = "default-src 'none'; style-src 'unsafe-inline'; img-src data:; form-action 'none'; base-uri 'none'"


def _cell_html(run: MatrixRun, cid: str, entry: Optional[Mapping[str, Any]]) -> str:
    if entry is None:
        return f'<td class="v v-absent" data-clause="{_e(cid)}" data-verdict="absent">{ABSENT}</td>'
    verdict = _text(entry.get("verdict"))
    word = _e(VERDICT_LABEL.get(verdict, verdict))
    href = _href(run, cid)
    inner = f'<a href="{_e(href)}">{word}</a>' if href else word
    return (f'<td class="v v-{_e(verdict)}" data-clause="{_e(cid)}" data-verdict="{_e(verdict)}" '
            f'title="{_e(entry.get("reason", ""))}">{inner}</td>')


def render_matrix_html(runs: Sequence[MatrixRun], *, title: str = "helmcheck conformance matrix") -> str:
    """One self-contained HTML page (inline CSS, no script, no network): see the module docstring."""
    cols = columns(runs)
    known = catalogue()
    head = ['<tr><th rowspan="2">Clause</th><th rowspan="2">Level</th>']
    for i, col in enumerate(cols):
        href = _href(col.run)
        label = f'<a href="{_e(href)}">{_e(col.label)}</a>' if href else _e(col.label)
        head.append(f'<th class="col" id="col-{i}">{label}<div class="detail">{_e(col.detail)}</div></th>')
    head.append("</tr><tr>")
    for col in cols:
        c = counts(col.run.results) if isinstance(col.run.results.get("clauses"), list) else {}
        tally = " · ".join(f"{n} {VERDICT_LABEL[v].lower()}" for v, n in c.items() if n)
        verdict = _text(col.run.results.get("verdict"))
        head.append(f'<th class="v v-{_e(verdict)}" data-run-verdict="{_e(verdict)}">'
                    f'{_e(VERDICT_LABEL.get(verdict, verdict))}<div class="detail">{_e(tally)}</div></th>')
    head.append("</tr>")
    tables = [_verdicts(col.run.results) for col in cols]
    body = []
    for section, stitle, ids in _sections():
        body.append(f'<tr class="section"><th colspan="{2 + len(cols)}" id="section-{_e(section)}">'
                    f"{_e(section)}. {md_inline(stitle)}</th></tr>")
        for cid in ids:
            cells = "".join(_cell_html(col.run, cid, t.get(cid)) for col, t in zip(cols, tables))
            body.append(f'<tr class="clause" id="clause-{_e(cid)}"><td class="id">{_e(cid)}</td>'
                        f'<td class="level">{_e(known[cid].level)}</td>{cells}</tr>')
    sources = "".join(f"<li>{_e(col.label)}: <span class=\"muted\">{_e(col.run.source)}</span></li>"
                      for col in cols)
    return "\n".join([
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f'<meta http-equiv="Content-Security-Policy" content="{_CSP}">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        f"<title>{_e(title)}</title><style>{_CSS}</style></head><body>",
        f"<h1>{_e(title)}</h1>",
        f'<p class="muted">{len(cols)} run(s) × {len(known)} clauses of the reference profile. Each cell links '
        f"to that clause in the run's report; hover for the reason. {ABSENT}: the run has no entry for the "
        "clause.</p>",
        f'<table class="matrix"><thead>{"".join(head)}</thead><tbody>',
        "\n".join(body),
        "</tbody></table>",
        f"<h2>Runs</h2><ul>{sources}</ul>",
        "</body></html>",
    ]) + "\n"


# --------------------------------------------------------------------------- Markdown

def _md_link(text: str, href: Optional[str]) -> str:
    return f"[{text}](<{href}>)" if href else text


def render_matrix_markdown(runs: Sequence[MatrixRun], *, title: str = "helmcheck conformance matrix") -> str:
    """The same matrix as one GitHub-flavoured Markdown table (section rows in bold)."""
    cols = columns(runs)
    known = catalogue()
    out = [f"## {md_escape(title)}", ""]
    out.append("| Clause | " + " | ".join(_md_link(md_escape(c.label), _href(c.run)) for c in cols) + " |")
    out.append("|---|" + ":---:|" * len(cols))
    out.append("| **verdict** | " + " | ".join(
        f"**{VERDICT_LABEL.get(_text(c.run.results.get('verdict')), md_escape(c.run.results.get('verdict')))}**"
        for c in cols) + " |")
    tables = [_verdicts(c.run.results) for c in cols]
    for section, stitle, ids in _sections():
        title_md = md_escape(stitle).replace("\\`", "`")  # the profile's own `code` spans
        out.append(f"| **{md_escape(section)}. {title_md}** |" + " |" * len(cols))
        for cid in ids:
            cells = []
            for col, t in zip(cols, tables):
                entry = t.get(cid)
                if entry is None:
                    cells.append(ABSENT)
                    continue
                verdict = _text(entry.get("verdict"))
                cells.append(_md_link(VERDICT_LABEL.get(verdict, md_escape(verdict)), _href(col.run, cid)))
            out.append(f"| {md_escape(cid)} ({known[cid].level}) | " + " | ".join(cells) + " |")
    out.append("")
    for col in cols:
        out.append(f"- {md_escape(col.label)}: {md_escape(col.detail)} — {md_escape(col.run.source)}")
    out.append("")
    return "\n".join(out)
