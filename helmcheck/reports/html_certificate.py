"""The HTML report's first page, the certificate: the verdict banner — the scope, the verdict's
reason, what failed (each failed clause with its reason, linked to its finding), what was not
judged and why, what timing judged coarser than nominal precision means — then what was tested,
the digest and the signature, when and how the run ran (with the exploration's model coverage
and what it means for the verdict), clause counts. A backseat's page is headed with the backseat
(``--implementation``, else the command ``--exec`` ran), never the vehicle helmcheck played.
"""

from __future__ import annotations

import re
from typing import Mapping

from ..judge.verdict import Verdict
from .html_markup import _e
from .identity import backseat_name, identity_rows
from .rundir import Run
from .scope import failures, model_coverage, model_coverage_note, precision_note, reach_text, scope_of

_CLAUSE_ID = re.compile(r"RH-[A-Z]+-\d+[a-z]?")
from .view import VERDICT_LABEL, counts


def _banner(run: Run) -> str:
    r = run.results
    out = []
    if r["partial"] and scope_of(r).unexercised:
        out.append('<div class="partial" id="partial">PARTIAL RUN — the run finished, but not every scenario '
                   'was exercised: a moment it exists for did not reach the backseat in time, and its '
                   'observations there are not claimed (<a href="#scenarios">Scenarios</a>); this is not a '
                   "complete certificate.</div>")
    elif r["partial"]:
        out.append('<div class="partial" id="partial">PARTIAL RUN — the run was interrupted before it '
                   "finished. Clauses it did not reach are missing or NOT-TESTED; this is not a "
                   "complete certificate.</div>")
    if not run.wire["present"]:
        out.append(f'<div class="partial" id="no-wire-log">The wire log {_e(r["wire_log"])} is missing '
                   "from the results directory: the evidence below cannot be checked against it.</div>")
    strict = ' <span class="muted">(strict: SHOULD clauses count as MUST)</span>' if run.strict else ""
    scope = scope_of(r)
    word = VERDICT_LABEL.get(r["verdict"], r["verdict"])
    partial_scope = not scope.certificate and r["verdict"] in (Verdict.PASS, Verdict.NON_STRICT)
    cls = (f'banner v-{_e(r["verdict"])}' + ("" if scope.certificate else " not-certificate")
           + (" scope-partial" if partial_scope else ""))
    failed = "".join(f"<li>{_failed_item(line)}</li>" for line in failures(r))
    gaps = "".join(f"<li>{_e(line)}</li>" for line in scope.why())
    precision = precision_note(r)
    out.append(f'<div class="{cls}" id="verdict" data-certificate="{str(scope.certificate).lower()}">'
               f'<div class="word" id="scope"><span class="vw v-{_e(r["verdict"])}">{_e(word)}</span> — '
               f'{_e(scope.statement)}{strict}</div>'
               f'<div class="why">{_e(r["verdict_reason"])}</div>'
               + (f'<ul class="failed" id="failed">{failed}</ul>' if failed else "")
               + (f'<div class="gaps-head">Not judged:</div><ul class="gaps" id="scope-gaps">{gaps}</ul>'
                  if gaps else "")
               + (f'<p class="precision" id="precision">{_e(precision)}</p>' if precision else "") + "</div>")
    return "\n".join(out)


def _failed_item(line: str) -> str:
    """A line of :func:`~helmcheck.reports.scope.failures`: its clause ID leads, linked to the finding."""
    cid, _, rest = line.partition(" ")
    if _CLAUSE_ID.fullmatch(cid):
        return f'<a href="#finding-{_e(cid)}"><b>{_e(cid)}</b></a> {_e(rest)}'
    return _e(line)


def _identity_table(run: Run) -> str:
    rows = []
    for label, value, missing in identity_rows(run.results, run.wire["osi_vehicle_name"]):
        cls = ' class="missing"' if missing else ""
        rows.append(f"<tr><th>{_e(label)}</th><td{cls}>{_e(value)}</td></tr>")
    return (f'<div class="who"><h2>What was tested</h2><table class="kv ident" id="identity"><tbody>'
            f'{"".join(rows)}</tbody></table></div>')


def _seal(run: Run) -> str:
    sig = run.results.get("signature")
    if isinstance(sig, Mapping):
        signed = (f'<p id="signature"><span class="sig-ok">Signed</span> ({_e(sig.get("algorithm"))}, '
                  f'<span class="mono">{_e(sig.get("file"))}</span>) by key '
                  f'<span class="mono">{_e(sig.get("key_id"))}</span>. Check it with '
                  f'<span class="mono">helmcheck verify DIR --public-key KEY.pub</span>.</p>')
    else:
        signed = ('<p id="signature"><span class="sig-none">Not signed.</span> The digest below can be '
                  "recomputed by anyone, so on its own it proves nothing; "
                  '<span class="mono">helmcheck verify DIR</span> re-judges the wire log.</p>')
    return f'<div class="seal"><h2>Digest and signature</h2>{signed}{_digest(run, "digest")}</div>'


def _run_box(run: Run) -> str:
    """When and how the run ran, on one line; a vehicle run's model coverage with its note."""
    r = run.results
    settings = r.get("settings") or {}
    facts = [f"started {r['started']}",
             "" if r["duration_s"] is None else f"{r['duration_s']:.1f} s",
             "" if settings.get("time_scale") is None else f"time scale {settings['time_scale']:g}",
             "" if r["seed"] is None else f"seed {r['seed']}",
             "" if not (r.get("profile") or {}).get("name") else f"profile {r['profile']['name']}"]
    mc = model_coverage(r)
    cov = mc.get("rows")
    note = (f'<p class="note" id="coverage-beside">Exploration: {_e(cov.get("covered"))} of {_e(cov.get("of"))} '
            f'transitions ({_e(cov.get("percent"))} %); {_e(reach_text({k: v for k, v in mc.items() if k != "rows"}))}. '
            f'{_e(model_coverage_note(r))}</p>' if cov else "")
    return (f'<div class="when"><h2>Run</h2><p id="run-summary">{_e(" · ".join(f for f in facts if f))}</p>'
            f"{note}</div>")


def _certificate_page(run: Run) -> str:
    """Everything that belongs on the first page: verdict, scope, identity, digest, signature."""
    r = run.results
    if r["role"] == "backseat":
        name = backseat_name(r)[0]
    else:
        name = next((v for label, v, missing in identity_rows(r, run.wire["osi_vehicle_name"])
                     if label == "vehicle" and not missing), None)
    kind = "certificate" if scope_of(r).certificate else "report"
    heading = f'helmcheck {r["role"]} {kind}' + (f" — {name}" if name else "")
    return "\n".join([
        '<div id="certificate-page">',
        f"<h1>{_e(heading)}</h1>",
        _banner(run),
        f'<div class="cert" id="certificate"><div class="side">{_identity_table(run)}'
        f'<section id="summary" class="counts-box"><h2>Clauses</h2>{_counts(run)}</section></div>'
        f'<div class="side">{_seal(run)}{_run_box(run)}</div></div>',
        "</div>",
    ])


def _digest(run: Run, anchor: str) -> str:
    d = run.digest
    return (f'<div class="digest" id="{anchor}">'
            f"<div><b>Certificate digest (SHA-256):</b> {d.combined}</div>"
            f"<div><b>results.json SHA-256:</b> {d.results}</div>"
            f"<div><b>wire log SHA-256:</b> {d.wire or 'absent'}</div></div>")


def _counts(run: Run) -> str:
    c = counts(run.results)
    head = "".join(f'<th class="v-{v}">{VERDICT_LABEL[v]}</th>' for v in c)
    body = "".join(f'<td class="v-{v}" id="count-{v}">{n}</td>' for v, n in c.items())
    total = sum(c.values())
    return (f'<table class="counts"><thead><tr>{head}<th>total</th></tr></thead>'
            f"<tbody><tr>{body}<td>{total}</td></tr></tbody></table>")
