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
"""

from __future__ import annotations

import json
import re
from html import escape
from typing import Any, Iterable, Mapping

from ..judge.verdict import Verdict
from .identity import identity_rows
from .rundir import Run
from .scope import headline, scope_of
from .text import printable
from .timeline import MODE_ORDER, event_counts, timeline_svg
from .verdicts import describe_process
from .view import VERDICT_LABEL, clause_rows, counts, non_pass_rows, pass_rows, replay_for, sections

__all__ = ["render_html", "md_inline", "EVIDENCE_LIMIT"]

EVIDENCE_LIMIT = 200  # wire lines shown per finding
_REMOTE_MODES = ("A", "M", "mP", "W")

_CSP = "default-src 'none'; style-src 'unsafe-inline'; img-src data:; form-action 'none'; base-uri 'none'"

_CSS = """
:root{--pass:#1a7f37;--pass-bg:#dafbe1;--ns:#9a6700;--ns-bg:#fff8c5;--fail:#cf222e;--fail-bg:#ffebe9;
--inc:#8250df;--inc-bg:#fbefff;--nt:#57606a;--nt-bg:#f6f8fa;--line:#d0d7de}
*{box-sizing:border-box}
body{font:14px/1.45 system-ui,-apple-system,"Segoe UI",Roboto,sans-serif;color:#1f2328;margin:0 auto;
max-width:1180px;padding:16px 24px 48px}
h1{font-size:22px;margin:8px 0 12px}h2{font-size:18px;margin:28px 0 8px;border-bottom:1px solid var(--line);
padding-bottom:4px}h3{font-size:15px;margin:18px 0 6px}
table{border-collapse:collapse;width:100%;margin:6px 0}th,td{border:1px solid var(--line);padding:4px 8px;
text-align:left;vertical-align:top}th{background:#f6f8fa;font-weight:600}
table.kv{width:auto;min-width:50%}table.kv th{width:16em}
code,pre,.mono{font-family:ui-monospace,SFMono-Regular,Menlo,Consolas,monospace;font-size:12.5px}
code{background:#f6f8fa;padding:0 3px;border-radius:3px;word-break:break-all}
pre{background:#f6f8fa;border:1px solid var(--line);padding:8px;overflow-x:auto;white-space:pre-wrap;
word-break:break-all;margin:6px 0}
.banner{border-radius:8px;padding:14px 18px;margin:10px 0;border:2px solid}
.banner .word{font-size:28px;font-weight:800;letter-spacing:.04em}.banner .why{font-size:15px;margin-top:4px}
.partial{background:repeating-linear-gradient(45deg,#fff8c5,#fff8c5 12px,#ffe58f 12px,#ffe58f 24px);
border:3px solid #9a6700;border-radius:8px;padding:12px 18px;font-size:16px;font-weight:700;margin:10px 0}
.v-pass{color:var(--pass);background:var(--pass-bg)}
.v-non-strict{color:var(--ns);background:var(--ns-bg)}
.v-fail{color:var(--fail);background:var(--fail-bg)}
.v-inconclusive{color:var(--inc);background:var(--inc-bg)}
.v-not-tested{color:var(--nt);background:var(--nt-bg)}
.banner{border-color:currentColor}
td.verdict{font-weight:700;white-space:nowrap}
tr.clause[data-verdict=fail] td.id{box-shadow:inset 4px 0 var(--fail)}
tr.clause[data-verdict=inconclusive] td.id{box-shadow:inset 4px 0 var(--inc)}
tr.clause[data-verdict=non-strict] td.id{box-shadow:inset 4px 0 var(--ns)}
td.id,td.cases{white-space:nowrap}td.id{font-weight:600}td.level{white-space:nowrap}
.digest{font-family:ui-monospace,Menlo,Consolas,monospace;font-size:12.5px;background:#f6f8fa;
border:1px solid var(--line);border-radius:6px;padding:8px 12px;word-break:break-all}
.digest b{font-family:system-ui,sans-serif}
.counts td{text-align:center;font-weight:700}.counts th{text-align:center}
.finding{border:1px solid var(--line);border-left:6px solid;border-radius:6px;padding:4px 14px 10px;margin:12px 0;
background:#fff;color:#1f2328}
.finding.v-fail{border-left-color:var(--fail)}.finding.v-non-strict{border-left-color:var(--ns)}
.finding.v-inconclusive{border-left-color:var(--inc)}.finding.v-not-tested{border-left-color:var(--nt)}
ol.replay li{margin:2px 0}
.chip{display:inline-block;padding:2px 10px;margin:2px;border-radius:12px;border:1px solid var(--line);
font-weight:600}.chip.reached{background:var(--pass-bg);color:var(--pass);border-color:var(--pass)}
.chip.unreached{color:var(--nt);background:#fff;text-decoration:line-through}
table.pairs,table.transitions{width:auto}table.pairs td{text-align:center;min-width:3em}td.hit{background:var(--pass-bg);
color:var(--pass);font-weight:700}td.self{background:#f6f8fa}
.warn{color:var(--fail);font-weight:600}.muted{color:#57606a}
svg.timeline{border:1px solid var(--line);border-radius:6px;background:#fff;margin:6px 0}
svg .lane0{fill:#f6f8fa}svg .lane1{fill:#fff}svg .lane-label,svg .row-label{font:12px system-ui,sans-serif;
fill:#1f2328}svg .tick,svg .empty{font:11px system-ui,sans-serif;fill:#57606a}
svg .grid{stroke:#d0d7de;stroke-width:.5}svg .row-rule{stroke:#eaeef2}
svg .step{fill:none;stroke:#0969da;stroke-width:2}svg .seg{fill:#0969da;fill-opacity:.12}
svg .ev-command{fill:#0969da}svg .ev-ack-error{fill:#cf222e}svg .ev-lockout{fill:#bc4c00}
svg .ev-lockout-line{stroke:#bc4c00;stroke-dasharray:4 3}svg .ev-note{fill:#57606a}
footer{margin-top:32px;border-top:1px solid var(--line);padding-top:8px}
.banner.scope-partial{color:#3d444d;border-color:#8c959f;
background:repeating-linear-gradient(135deg,#f6f8fa,#f6f8fa 14px,#eaeef2 14px,#eaeef2 28px)}
.banner .word .vw{border-radius:4px}.banner.not-certificate .word{font-size:22px}
.banner ul.gaps{margin:6px 0 0;padding-left:20px;font-size:13.5px}.banner ul.gaps li{margin:1px 0}
.cert{display:grid;grid-template-columns:minmax(0,1.15fr) minmax(0,1fr);gap:14px;align-items:start;margin:10px 0}
.cert h2{font-size:15px;margin:0 0 4px;border:0;padding:0}
table.ident{width:100%;min-width:0;margin:0;table-layout:fixed}table.ident th{width:12.5em;font-weight:600}
table.ident td,table.ident th{padding:2px 8px}table.ident td{overflow-wrap:anywhere}
td.missing{color:var(--fail);font-style:italic}
.seal,.who{border:1px solid var(--line);border-radius:6px;padding:8px 12px;font-size:13px}
.seal .digest{margin:4px 0;padding:4px 8px;font-size:11.5px}
.sig-ok{color:var(--pass);font-weight:700}.sig-none{color:var(--ns);font-weight:700}
.pass-evidence{border-left:4px solid var(--pass);padding:0 12px;margin:8px 0}
.pass-evidence h3{margin:10px 0 2px;font-size:14px}.pass-evidence p{margin:2px 0}
svg .ev-negative{fill:#8c959f}
@page{size:A4;margin:14mm 12mm}
@media print{
.banner,.partial,.v-pass,.v-fail,.v-non-strict,.v-inconclusive,.v-not-tested,.scope-partial,td.hit,.chip{
-webkit-print-color-adjust:exact;print-color-adjust:exact}
body{max-width:none;padding:0;font-size:10pt;color:#000}
#certificate-page{break-after:page;page-break-after:always}
.cert{grid-template-columns:1fr;gap:8px}
h2{break-after:avoid;page-break-after:avoid}h3{break-after:avoid;page-break-after:avoid}
tr,.finding,.pass-evidence,pre,svg.timeline,.seal{break-inside:avoid;page-break-inside:avoid}
a{color:inherit;text-decoration:none}
details>summary{list-style:none}
pre{white-space:pre-wrap}
footer{break-before:avoid}
}
"""


def _e(value: object) -> str:
    """Escape any value for HTML text or a quoted attribute."""
    return escape(printable(value), quote=True)


def md_inline(markdown: str) -> str:
    """Profile Markdown (``code``, **bold**, *italic*) to escaped HTML."""
    parts = markdown.split("`")
    out = []
    for i, part in enumerate(parts):
        if i % 2 and i < len(parts) - 1:
            out.append(f"<code>{_e(part)}</code>")
            continue
        if i % 2:  # an unmatched backtick: keep it literally
            part = "`" + part
        text = _e(part)
        text = re.sub(r"\*\*(.+?)\*\*", r"<strong>\1</strong>", text)
        text = re.sub(r"(?<![\w*])\*(?!\s)(.+?)(?<!\s)\*(?![\w*])", r"<em>\1</em>", text)
        out.append(text)
    return "".join(out)


def _kv_table(rows: Iterable[tuple[str, Any]], cls: str = "kv") -> str:
    body = "".join(f"<tr><th>{_e(k)}</th><td>{_fmt_value(v)}</td></tr>" for k, v in rows)
    return f'<table class="{cls}"><tbody>{body}</tbody></table>' if body else '<p class="muted">none recorded</p>'


def _fmt_value(value: Any) -> str:
    if value is None:
        return '<span class="muted">—</span>'
    if isinstance(value, str):
        return _e(value)
    if isinstance(value, (bool, int, float)):
        return _e(json.dumps(value))
    if isinstance(value, (list, tuple)) and all(isinstance(v, (str, int, float)) for v in value):
        return _e(", ".join(str(v) for v in value))
    return f'<span class="mono">{_e(json.dumps(value, ensure_ascii=False))}</span>'


def _flatten(mapping: Mapping[str, Any], prefix: str = "") -> list[tuple[str, Any]]:
    rows: list[tuple[str, Any]] = []
    for key, value in mapping.items():
        name = f"{prefix}{key}"
        if isinstance(value, Mapping) and value:
            rows.extend(_flatten(value, f"{name}."))
        else:
            rows.append((name, value))
    return rows


def _verdict_cell(verdict: str) -> str:
    return f'<td class="verdict v-{_e(verdict)}">{_e(VERDICT_LABEL.get(verdict, verdict))}</td>'


# --------------------------------------------------------------------------- sections

def _banner(run: Run) -> str:
    r = run.results
    out = []
    if r["partial"]:
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
    gaps = "".join(f"<li>{_e(line)}</li>" for line in scope.why())
    out.append(f'<div class="{cls}" id="verdict" data-certificate="{str(scope.certificate).lower()}">'
               f'<div class="word" id="scope"><span class="vw v-{_e(r["verdict"])}">{_e(word)}</span> — '
               f'{_e(scope.statement)}{strict}</div>'
               f'<div class="why">{_e(r["verdict_reason"])}</div>'
               + (f'<ul class="gaps" id="scope-gaps">{gaps}</ul>' if gaps else "") + "</div>")
    return "\n".join(out)


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


def _certificate_page(run: Run) -> str:
    """Everything that belongs on the first page: verdict, scope, identity, digest, signature."""
    r = run.results
    name = next((v for label, v, missing in identity_rows(r, run.wire["osi_vehicle_name"])
                 if label in ("vehicle", "backseat") and not missing), None)
    kind = "certificate" if scope_of(r).certificate else "report"
    heading = f'helmcheck {r["role"]} {kind}' + (f" — {name}" if name else "")
    return "\n".join([
        '<div id="certificate-page">',
        f"<h1>{_e(heading)}</h1>",
        _banner(run),
        f'<div class="cert" id="certificate">{_identity_table(run)}{_seal(run)}</div>',
        _section("summary", "Summary", _counts(run)),
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


def _run_facts(run: Run) -> str:
    r = run.results
    rows = [("role", r["role"]), ("command", r["command"]), ("tool", f'{r["tool"]["name"]} {r["tool"]["version"]}'),
            ("started", r["started"]), ("finished", r["finished"]),
            ("duration", None if r["duration_s"] is None else f'{r["duration_s"]:.3f} s'),
            ("seed", r["seed"]), ("results directory", str(run.directory))]
    rows += [(f"settings.{k}", v) for k, v in _flatten(r["settings"])]
    return _kv_table(rows)


def _identity(run: Run) -> str:
    impl = run.results["implementation"]
    wire = run.wire
    out = ["<h3>Declared</h3>", _kv_table(_flatten(impl))]
    out.append("<h3>As seen on the wire</h3>")
    if not wire["present"]:
        out.append('<p class="warn">No wire log.</p>')
        return "\n".join(out)
    by_dir = wire["by_dir"]
    rows = [
        ("wire log", run.results["wire_log"] + ("" if wire["format_ok"] else " (no wire-log 1 format tag)")),
        ("recorder header", " | ".join(wire["header"]) or None),
        ("records", f'{wire["records"]} ({by_dir[">"] + by_dir[">~"]} to the vehicle, '
                    f'{by_dir["<"] + by_dir["<~"]} from the vehicle, {by_dir["!"]} notes'
                    f'{", " + str(wire["unparsed"]) + " unparsed" if wire["unparsed"] else ""})'),
        ("time span", None if wire["first_t"] is None else f'{wire["first_t"]:.6f} s – {wire["last_t"]:.6f} s'),
        ("first $OSI from the vehicle", wire["first_osi"]),
        ("$OSI field count", wire["osi_fields"]),
        ("vehicle name ($OSI field 18)", wire["osi_vehicle_name"]),
    ]
    out.append(_kv_table(rows))
    declared = impl.get("vehicle_name")
    seen = wire["osi_vehicle_name"]
    if declared and seen is not None and declared != seen:
        out.append(f'<p class="warn" id="identity-mismatch">The vehicle name on the wire ({_e(seen)}) differs '
                   f"from the declared one ({_e(declared)}).</p>")
    return "\n".join(out)


def _process(run: Run) -> str:
    """The implementation under test that helmcheck started (``--exec``): how it ended, its output."""
    proc = run.results.get("process")
    if not isinstance(proc, Mapping):
        return ""
    subject = run.results["role"]
    cls = "v-fail" if proc.get("ended_early") else "v-pass"
    out = [f'<div class="finding {cls}" id="process-end"><p>{_e(describe_process(proc, subject))}</p>']
    rows = [("command", proc.get("command")), ("pid", proc.get("pid")), ("exit code", proc.get("exit_code")),
            ("signal", proc.get("signal")),
            ("ended at", None if proc.get("ended_at_s") is None else f'{proc["ended_at_s"]:.3f} s'),
            ("ended before the run's end", "yes" if proc.get("ended_early") else "no")]
    out.append(_kv_table(rows))
    tail = [str(line) for line in proc.get("output_tail") or ()]
    if tail:
        out.append(f"<h3>Last output ({len(tail)} line(s))</h3><pre>{_e(chr(10).join(tail))}</pre>")
    logs = [name for name in (f"{subject}.stdout.log", f"{subject}.stderr.log")
            if (run.directory / name).is_file()]
    if logs:
        out.append("<p>Full output: " + ", ".join(f'<a href="{_e(n)}">{_e(n)}</a>' for n in logs) + "</p>")
    out.append("</div>")
    return "\n".join(out)


def _restore(run: Run) -> str:
    """The vehicle left as found: each setting before and after, the mode, what to do by hand."""
    rec = run.results.get("restore")
    if not isinstance(rec, Mapping):
        return ""
    ok = bool(rec.get("verified"))
    found = rec.get("found") or {}
    left = rec.get("left") or {}
    head = ("Every setting the run changed was written back and read again as found; the vehicle "
            "was stopped." if ok and rec.get("attempted") else
            "Nothing needed restoring." if ok else "The vehicle was NOT verified as restored.")
    out = [f'<div class="finding {"v-pass" if ok else "v-fail"}" id="restore-status"><p>{_e(head)}</p>']
    rows = [("found in mode", found.get("mode")), ("found running", found.get("mission")),
            ("left in mode", left.get("mode")), ("note", left.get("note"))]
    out.append(_kv_table([(k, v) for k, v in rows if v is not None]))
    settings = rec.get("settings") or []
    if settings:
        out.append('<table class="kv" id="restore-settings"><tr><th>setting</th><th>as found</th>'
                   '<th>written by the run</th><th>after the restore</th><th>verified</th></tr>')
        for st in settings:
            def show(v):
                return "—" if v is None else ",".join(map(str, v))
            out.append(f"<tr><td>{_e(st.get('name'))}</td><td>{_e(show(st.get('before')))}</td>"
                       f"<td>{'yes' if st.get('written') else 'no'}</td><td>{_e(show(st.get('after')))}</td>"
                       f"<td>{'yes' if st.get('verified') else ('—' if not st.get('written') else 'NO')}</td></tr>")
        out.append("</table>")
    for problem in rec.get("problems") or ():
        out.append(f"<p class=\"warn\">{_e(problem)}</p>")
    if rec.get("by_hand"):
        out.append("<p>Set by hand:</p><pre>" + _e("\n".join(rec["by_hand"])) + "</pre>")
    out.append("</div>")
    return "\n".join(out)


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


def _coverage(run: Run) -> str:
    cov = run.results["coverage"]
    reached = set(cov["modes"])
    modes = list(MODE_ORDER) + sorted(reached - set(MODE_ORDER))
    chips = "".join(f'<span class="chip {"reached" if m in reached else "unreached"}">{_e(m)}</span>' for m in modes)
    out = [f'<h3>Modes reached ({len(reached & set(modes))} of {len(modes)})</h3><p id="modes">{chips}</p>']
    out.append(f'<h3>Transitions exercised ({len(cov["transitions"])})</h3>')
    if cov["transitions"]:
        rows = "".join(f"<tr><td>{_e(a)}</td><td>{_e(b)}</td><td><code>{_e(via)}</code></td></tr>"
                       for a, b, via in cov["transitions"])
        out.append(f'<table class="transitions"><thead><tr><th>From</th><th>To</th><th>Via</th></tr></thead>'
                   f"<tbody>{rows}</tbody></table>")
    else:
        out.append('<p class="muted">none recorded</p>')
    pairs = {tuple(p) for p in cov["interrupt_pairs"]}
    axis = list(_REMOTE_MODES) + sorted({m for p in pairs for m in p} - set(_REMOTE_MODES))
    out.append(f"<h3>Interrupt pairs exercised ({len(pairs)}) — RH-INT-1</h3>")
    head = "".join(f"<th>{_e(m)}</th>" for m in axis)
    body = []
    for active in axis:
        cells = []
        for new in axis:
            hit = (active, new) in pairs
            cls = "hit" if hit else ("self" if active == new else "")
            cells.append(f'<td class="{cls}">{"✓" if hit else ""}</td>')
        body.append(f"<tr><th>{_e(active)}</th>{''.join(cells)}</tr>")
    out.append(f'<table class="pairs"><thead><tr><th>active ↓ / interrupted by →</th>{head}</tr></thead>'
               f"<tbody>{''.join(body)}</tbody></table>")
    return "\n".join(out)


def _events_table(run: Run) -> str:
    events = sorted(run.results["events"], key=lambda ev: ev["t"])
    if not events:
        return ""
    rows = "".join(f'<tr><td class="mono">{ev["t"]:.3f}</td><td>{_e(_kind(ev))}</td>'
                   f'<td class="mono">{_e(ev["label"])}</td></tr>' for ev in events[:2000])
    more = f'<p class="muted">… {len(events) - 2000} more events in results.json</p>' if len(events) > 2000 else ""
    return (f"<details><summary>Events ({len(events)})</summary><table><thead><tr><th>t (s)</th>"
            f"<th>kind</th><th>label</th></tr></thead><tbody>{rows}</tbody></table>{more}</details>")


def _kind(ev: Mapping[str, Any]) -> str:
    if ev.get("negative_test"):
        return "expected refusal (negative test)"
    return str(ev["kind"])


def _event_summary(run: Run) -> str:
    c = event_counts(run.results)
    return (f'<p id="event-counts">{c["ack-error"]} ACK error(s); {c["negative-test"]} expected refusal(s) '
            f'— negative tests the tester provoked on purpose, drawn in grey; {c["lockout"]} lockout event(s).</p>')


# --------------------------------------------------------------------------- document

def _section(anchor: str, title: str, body: str) -> str:
    return f'<section id="{anchor}">\n<h2>{_e(title)}</h2>\n{body}\n</section>'


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
