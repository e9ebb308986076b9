"""The HTML compliance report: one self-contained file, inline CSS and SVG, no script, no network.

Contents, top to bottom. The first screen (and, printed, the first page) is the certificate: a
PARTIAL warning when the run was interrupted; the verdict banner, which leads with the scope
(:func:`helmcheck.reports.scope.headline`, "PASS — partial: 4 of 60 claimed clauses judged; not
a certificate"), then what failed (each failed clause with its reason), then why clauses were not
judged, then what timing judged coarser than nominal precision means; what was tested
(:func:`helmcheck.reports.identity.identity_rows`: implementation, serial, version, name on the
wire, operator, site, profile SHA-256, tester version and revision); the digest and the
signature; clause counts. Under it a line of links to every section, then what needs attention:
one finding per non-pass clause (worst first) with its replay steps and wire excerpt. When
helmcheck started the implementation (``--exec``) a "Process under test" section says how it
ended, with its last output; a vehicle run says how the vehicle was restored. Then the clause
matrix by section of the reference profile (requirement text from ``helmcheck.clauses``), each
section folded unless a clause in it failed or was inconclusive; a backseat run's scenarios
(:mod:`~helmcheck.reports.html_scenarios`: what each exercised and for how long, open when one is
not claimed in full). The rest is folded behind a title
and a one-line gist (:func:`~helmcheck.reports.html_markup._fold`): the evidence of every passing
clause; the implementation as declared and as seen on the wire (first ``$OSI``, RH-OUT-1 field
18); the run (command, times, settings); the profile; model coverage, with what it means for the
verdict; then the mode timeline (:mod:`helmcheck.reports.timeline`, open), where the tester's
deliberate negative tests are drawn apart from real ACK errors; an optional comparison; the
digest again. Folding keeps a passing certificate to a few screens
and never hides a problem (a link into a fold opens it). Printed, every fold is open (but the event
table) and the certificate is alone on the first page.

Everything that comes from the results file or the device is escaped with ``html.escape`` after
control characters are made visible; a Content-Security-Policy forbids scripts and fetches in
case anything ever slips through.

This module assembles the page (:func:`render_html`); the parts are
:mod:`~helmcheck.reports.html_style` (CSS, CSP), :mod:`~helmcheck.reports.html_markup` (escaping,
tables, folds), :mod:`~helmcheck.reports.html_certificate` (the first page),
:mod:`~helmcheck.reports.html_clauses` (matrix, findings, evidence),
:mod:`~helmcheck.reports.html_run` (implementation, run, process, restore),
:mod:`~helmcheck.reports.html_coverage` (coverage, events) and
:mod:`~helmcheck.reports.html_scenarios` (a backseat run's scenarios).
"""

from __future__ import annotations

from typing import Mapping

from .html_certificate import _certificate_page, _digest
from .html_clauses import EVIDENCE_LIMIT, _findings, _has_finding, _matrix, _pass_evidence
from .html_coverage import _coverage, _coverage_gist, _event_summary, _events_table
from .html_markup import _e, _flatten, _fold, _kv_table, _section, md_inline
from .html_run import _identity, _process, _restore, _run_facts, restore_headline
from .identity import backseat_name
from .html_scenarios import scenarios_section
from .html_style import _CSP, _CSS
from .rundir import Run
from .scope import headline
from .timeline import event_counts, timeline_svg
from .verdicts import describe_process
from .view import clause_rows, pass_rows

__all__ = ["render_html", "md_inline", "EVIDENCE_LIMIT"]


def render_html(run: Run, comparison_html: str | None = None) -> str:
    """The complete HTML report for *run* (optionally with a comparison section)."""
    r = run.results
    title = f'helmcheck {r["role"]} report — {headline(r)}'
    if r["partial"]:
        title += " (PARTIAL)"
    rows = clause_rows(r)
    findings = sum(1 for row in rows if _has_finding(run, row))
    passed = len(pass_rows(r))
    body = [
        _section("findings", f"Findings ({findings})", _findings(run)),
        *([_fold("process", "Process under test", _process(run), _e(describe_process(r["process"], r["role"])),
                 open_=bool(r["process"].get("ended_early")))] if isinstance(r.get("process"), Mapping) else []),
        *([_fold("restore", "Vehicle restored", _restore(run), _e(restore_headline(r["restore"])),
                 open_=not r["restore"].get("verified"))] if isinstance(r.get("restore"), Mapping) else []),
        _section("matrix", f"Clauses ({len(rows)})", _matrix(run)),
        *([scenarios_section(run)] if scenarios_section(run) else []),
        _fold("evidence", "Evidence for passing clauses", _pass_evidence(run),
              _e(f"the wire evidence of {passed} passing clause(s)")),
        _fold("implementation", "Implementation", _identity(run), _implementation_gist(run),
              open_=_name_mismatch(run)),
        _fold("run", "Run", _run_facts(run), _run_gist(run)),
        _fold("profile", "Profile", _kv_table(_flatten(r["profile"])),
              _e(f"{len(_flatten(r['profile']))} settings")),
        _fold("coverage", "Model coverage", _coverage(run), _coverage_gist(run)),
        _fold("timeline", "Mode timeline", _event_summary(run) + "\n" + timeline_svg(r) + "\n" + _events_table(run),
              _timeline_gist(run), open_=True),
    ]
    if comparison_html:
        body.append(_section("comparison", "Comparison with an earlier run", comparison_html))
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f'<meta http-equiv="Content-Security-Policy" content="{_CSP}">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        f'<meta name="helmcheck-digest" content="{run.digest.combined}">',
        f"<title>{_e(title)}</title><style>{_CSS}</style></head><body>",
        _certificate_page(run),
        _contents(run, findings, comparison_html is not None),
        *body,
        "<footer>",
        _digest(run, "digest-footer"),
        f'<p class="muted">Rebuilt from {_e(run.directory / "results.json")} and {_e(run.wire_path.name)} by '
        f'<span class="mono">helmcheck report</span>; any edit to either file changes the digest.</p>',
        "</footer></body></html>",
    ]
    return "\n".join(parts) + "\n"


def _contents(run: Run, findings: int, comparison: bool) -> str:
    """The page's table of contents: one line of links under the certificate."""
    r = run.results
    links = [("findings", f"Findings ({findings})" if findings else "Findings"),
             *([("process", "Process")] if isinstance(r.get("process"), Mapping) else []),
             *([("restore", "Restore")] if isinstance(r.get("restore"), Mapping) else []),
             ("matrix", "Clauses"), *([("scenarios", "Scenarios")] if scenarios_section(run) else []),
             ("evidence", "Evidence"), ("implementation", "Implementation"),
             ("run", "Run"), ("profile", "Profile"), ("coverage", "Coverage"), ("timeline", "Timeline"),
             *([("comparison", "Comparison")] if comparison else [])]
    return ('<nav class="contents" id="contents">'
            + "".join(f'<a href="#{a}">{_e(text)}</a>' for a, text in links) + "</nav>")


def _name_mismatch(run: Run) -> bool:
    if run.results["role"] == "backseat":
        return False  # the $OSI name is the vehicle helmcheck played
    declared, seen = run.results["implementation"].get("vehicle_name"), run.wire["osi_vehicle_name"]
    return bool(declared and seen is not None and declared != seen)


def _implementation_gist(run: Run) -> str:
    seen = run.wire["osi_vehicle_name"]
    if _name_mismatch(run):
        return ('<span class="warn">the vehicle name on the wire differs from the declared one</span>')
    if run.results["role"] == "backseat":
        name = backseat_name(run.results)[0]
        first = f"backseat: {name}" if name else "backseat: not named (--implementation)"
    else:
        first = f"name on the wire: {seen}" if seen is not None else ""
    parts = [first, f"{run.wire['records']} wire-log records" if run.wire["present"] else "no wire log"]
    return _e(" · ".join(p for p in parts if p))


def _run_gist(run: Run) -> str:
    r = run.results
    parts = [f"started {r['started']}",
             "" if r["duration_s"] is None else f"{r['duration_s']:.1f} s",
             "" if r["seed"] is None else f"seed {r['seed']}"]
    return _e(" · ".join(p for p in parts if p))


def _timeline_gist(run: Run) -> str:
    c = event_counts(run.results)
    return _e(f"{len(run.results['timeline'])} mode change(s) · {c['ack-error']} ACK error(s) · "
              f"{c['negative-test']} expected refusal(s) · {c['lockout']} lockout event(s)")
