"""The HTML compliance report: one self-contained file, inline CSS and SVG, no script, no network.

Contents, top to bottom. The first screen (and, printed, the first page) is the certificate: a
PARTIAL warning when the run was interrupted; the verdict banner, which leads with the scope
(:func:`helmcheck.reports.scope.headline`, "PASS — partial: 4 of 60 claimed clauses judged; not
a certificate") and lists why clauses were not judged; what was tested
(:func:`helmcheck.reports.identity.identity_rows`: implementation, serial, version, name on the
wire, operator, site, profile SHA-256, tester version and revision); the digest and the
signature; clause counts. Then the clause matrix grouped by section of the reference profile
(requirement text from ``helmcheck.clauses``); one finding per non-pass clause with its replay
steps and wire excerpt; the evidence of every passing clause; the implementation as declared and
as seen on the wire (first ``$OSI``, RH-OUT-1 field 18); the run (command, times, settings); the
profile table; model coverage; the mode timeline (:mod:`helmcheck.reports.timeline`), where the
tester's deliberate negative tests are drawn apart from real ACK errors; an optional comparison;
the digest again. A print stylesheet puts the certificate alone on the first page. When helmcheck started the implementation (``--exec``) a
"Process under test" section says how it ended, with its last output.

Everything that comes from the results file or the device is escaped with ``html.escape`` after
control characters are made visible; a Content-Security-Policy forbids scripts and fetches in
case anything ever slips through.

This module assembles the page (:func:`render_html`); the parts are
:mod:`~helmcheck.reports.html_style` (CSS, CSP), :mod:`~helmcheck.reports.html_markup` (escaping,
tables), :mod:`~helmcheck.reports.html_certificate` (the first page),
:mod:`~helmcheck.reports.html_clauses` (matrix, findings, evidence),
:mod:`~helmcheck.reports.html_run` (implementation, run, process, restore) and
:mod:`~helmcheck.reports.html_coverage` (coverage, events).
"""

from __future__ import annotations

from .html_certificate import _certificate_page, _digest
from .html_clauses import EVIDENCE_LIMIT, _findings, _matrix, _pass_evidence
from .html_coverage import _coverage, _event_summary, _events_table
from .html_markup import _e, _flatten, _kv_table, _section, md_inline
from .html_run import _identity, _process, _restore, _run_facts
from .html_style import _CSP, _CSS
from .rundir import Run
from .scope import headline
from .timeline import timeline_svg
from .view import clause_rows

__all__ = ["render_html", "md_inline", "EVIDENCE_LIMIT"]


def render_html(run: Run, comparison_html: str | None = None) -> str:
    """The complete HTML report for *run* (optionally with a comparison section)."""
    r = run.results
    title = f'helmcheck {r["role"]} report — {headline(r)}'
    if r["partial"]:
        title += " (PARTIAL)"
    n = len(clause_rows(r))
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f'<meta http-equiv="Content-Security-Policy" content="{_CSP}">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        f'<meta name="helmcheck-digest" content="{run.digest.combined}">',
        f"<title>{_e(title)}</title><style>{_CSS}</style></head><body>",
        _certificate_page(run),
        *([_section("process", "Process under test", _process(run))] if run.results.get("process") else []),
        *([_section("restore", "Vehicle restored", _restore(run))] if run.results.get("restore") else []),
        _section("matrix", f"Clauses ({n})", _matrix(run)),
        _section("findings", "Findings", _findings(run)),
        _section("evidence", "Evidence for passing clauses", _pass_evidence(run)),
        _section("implementation", "Implementation", _identity(run)),
        _section("run", "Run", _run_facts(run)),
        _section("profile", "Profile", _kv_table(_flatten(r["profile"]))),
        _section("coverage", "Model coverage", _coverage(run)),
        _section("timeline", "Mode timeline",
                 _event_summary(run) + "\n" + timeline_svg(r) + "\n" + _events_table(run)),
    ]
    if comparison_html:
        parts.append(_section("comparison", "Comparison with an earlier run", comparison_html))
    parts += [
        "<footer>",
        _digest(run, "digest-footer"),
        f'<p class="muted">Rebuilt from {_e(run.directory / "results.json")} and {_e(run.wire_path.name)} by '
        f'<span class="mono">helmcheck report</span>; any edit to either file changes the digest.</p>',
        "</footer></body></html>",
    ]
    return "\n".join(parts) + "\n"
