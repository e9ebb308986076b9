"""The HTML reports' stylesheet and Content-Security-Policy: the inline CSS (screen and print) of
:mod:`~helmcheck.reports.html`, and the policy that forbids scripts and fetches.

Layout rules the stylesheet keeps: nothing is wider than the window, at 1280 px and at 800 px
(tests/test_report_layout_browser.py): every long word wraps, tables wrap their cells, the
clause matrix has fixed column widths and turns into one card per clause below 900 px, wire
excerpts wrap and a long one scrolls down inside its own box. Folded sections
(``details.fold``) show their title and gist. Printed, every fold is open (the run box keeps
its facts and leaves the coverage note to the coverage section) and the certificate is alone
on the first page.
"""

_CSP = "default-src 'none'; style-src 'unsafe-inline'; img-src data:; form-action 'none'; base-uri 'none'"

_CSS = """
:root{--pass:#1a7f37;--pass-bg:#dafbe1;--ns:#9a6700;--ns-bg:#fff8c5;--fail:#cf222e;--fail-bg:#ffebe9;
--inc:#8250df;--inc-bg:#fbefff;--nt:#57606a;--nt-bg:#f6f8fa;--line:#d0d7de}
*{box-sizing:border-box}
body{font:14px/1.45 system-ui,-apple-system,"Segoe UI",Roboto,sans-serif;color:#1f2328;margin:0 auto;
max-width:1180px;padding:16px 24px 48px;overflow-wrap:break-word}
h1{font-size:22px;margin:8px 0 12px}h2{font-size:18px;margin:28px 0 8px;border-bottom:1px solid var(--line);
padding-bottom:4px}h3{font-size:15px;margin:18px 0 6px}
table{border-collapse:collapse;width:100%;margin:6px 0}th,td{border:1px solid var(--line);padding:4px 8px;
text-align:left;vertical-align:top}th{background:#f6f8fa;font-weight:600}td{overflow-wrap:anywhere}
[id]{scroll-margin-top:44px}
table.kv{width:auto;min-width:50%;font-size:13px}table.kv th{width:16em}table.kv th,table.kv td{padding:2px 8px}
code,pre,.mono{font-family:ui-monospace,SFMono-Regular,Menlo,Consolas,monospace;font-size:12.5px}
code{background:#f6f8fa;padding:0 3px;border-radius:3px;overflow-wrap:anywhere}
pre{background:#f6f8fa;border:1px solid var(--line);padding:8px;overflow-x:auto;white-space:pre-wrap;
word-break:break-all;overflow-wrap:anywhere;margin:6px 0}
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
td.id{font-weight:600;white-space:nowrap}td.level{white-space:nowrap}td.verdict,td.level,td.id{overflow-wrap:normal}
table.matrix{table-layout:fixed;margin:4px 0 10px}col.c-id{width:7.6em}col.c-req{width:33%}col.c-level{width:4.7em}
col.c-verdict{width:8.6em}col.c-cases{width:11.5em}table.matrix td.req{font-size:13px}
td.cases{font-size:11.5px;line-height:1.5}span.case{display:inline-block;max-width:100%}td.reason{font-size:13px}
details.more{display:inline}details.more>summary{display:inline;cursor:pointer;color:#0969da;
font:12px system-ui,sans-serif;margin-left:4px}details.more[open]>summary{display:block;margin:2px 0 0}
details.fold{margin:22px 0 0}details.fold>summary,details.group>summary{cursor:pointer;list-style:none;
display:flex;flex-wrap:wrap;align-items:baseline;gap:2px 12px}
details.fold>summary{border-bottom:1px solid var(--line);padding:2px 0 4px}
details.fold>summary::-webkit-details-marker,details.group>summary::-webkit-details-marker{display:none}
details.fold>summary::before,details.group>summary::before{content:"\\25B8";color:#57606a;width:.9em;
margin-right:-6px}
details.fold[open]>summary::before,details.group[open]>summary::before{content:"\\25BE"}
details.fold>summary h2{margin:0;border:0;padding:0}details.fold>summary:hover h2{color:#0969da}
.gist{color:#57606a;font-size:13px}details.fold[open]>summary .gist{display:none}.fold-body{padding:4px 0 0}
details.group{margin:4px 0;border-bottom:1px solid #eaeef2}details.group>summary{padding:4px 0}
details.group>summary h3{margin:0;font-size:14.5px}details.group>summary:hover h3{color:#0969da}
.tally{display:inline-block;padding:0 8px;border-radius:10px;font-size:12px;font-weight:600;line-height:1.6}
nav.contents{position:sticky;top:0;z-index:2;background:#fff;display:flex;flex-wrap:wrap;gap:2px 16px;
padding:7px 0;margin:14px 0 0;border-top:1px solid var(--line);border-bottom:1px solid var(--line);font-size:13px}
nav.contents a{color:#0969da;text-decoration:none}nav.contents a:hover{text-decoration:underline}
pre.wire{max-height:26em;overflow:auto}
p.note{border-left:4px solid #0969da;background:#f6f8fa;padding:6px 12px;margin:6px 0 10px}
ul.transitions{columns:15em;column-gap:24px;margin:6px 0;padding-left:18px;font-size:13px}
ul.uncovered{columns:22em;column-gap:24px;margin:6px 0;padding-left:18px;font-size:12px}
details.replay>summary{cursor:pointer;margin:6px 0 2px}
.digest{font-family:ui-monospace,Menlo,Consolas,monospace;font-size:12.5px;background:#f6f8fa;
border:1px solid var(--line);border-radius:6px;padding:8px 12px;word-break:break-all}
.digest b{font-family:system-ui,sans-serif}
table.counts{margin:0}.counts td{text-align:center;font-weight:700;font-size:16px}
.counts th{text-align:center;font-size:11.5px;padding:4px 4px;white-space:nowrap}
.counts-box{border:1px solid var(--line);border-radius:6px;padding:8px 12px}.counts-box h2{margin:0 0 6px}
.finding{border:1px solid var(--line);border-left:6px solid;border-radius:6px;padding:4px 14px 10px;margin:12px 0;
background:#fff;color:#1f2328}
.finding.v-fail{border-left-color:var(--fail)}.finding.v-non-strict{border-left-color:var(--ns)}
.finding.v-inconclusive{border-left-color:var(--inc)}.finding.v-pass{border-left-color:var(--pass)}.finding.v-not-tested{border-left-color:var(--nt)}
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
.banner ul.failed{margin:6px 0 0;padding-left:20px;font-size:14.5px;overflow-wrap:anywhere}
.banner ul.failed li{margin:2px 0}.banner ul.failed a{color:inherit}
.banner .gaps-head{margin-top:8px;font-size:13.5px;font-weight:600}
.banner p.precision{margin:8px 0 0;font-size:13.5px}
.cert{display:grid;grid-template-columns:minmax(0,1.15fr) minmax(0,1fr);gap:14px;align-items:start;margin:10px 0}
.cert h2{font-size:15px;margin:0 0 4px;border:0;padding:0}
table.ident{width:100%;min-width:0;margin:0;table-layout:fixed}table.ident th{width:12.5em;font-weight:600}
table.ident td,table.ident th{padding:2px 8px}table.ident td{overflow-wrap:anywhere}
td.missing{color:var(--fail);font-style:italic}
.seal,.who,.when{border:1px solid var(--line);border-radius:6px;padding:8px 12px;font-size:13px}
.side{display:grid;gap:14px}.when p{margin:2px 0}.when p.note{margin:6px 0 2px;font-size:12.5px}
.seal .digest{margin:4px 0;padding:4px 8px;font-size:11.5px}
.sig-ok{color:var(--pass);font-weight:700}.sig-none{color:var(--ns);font-weight:700}
.pass-evidence{border-left:4px solid var(--pass);padding:1px 12px;margin:3px 0;font-size:13px}
.pass-evidence>details>summary{cursor:pointer;overflow-wrap:anywhere}.pass-evidence a{font-weight:600}
.pass-evidence p{margin:2px 0}
svg .ev-negative{fill:#8c959f}
@media (max-width:900px){
body{padding:12px 14px 40px}.cert{grid-template-columns:minmax(0,1fr)}
table.matrix,table.matrix tbody,table.matrix tr{display:block;width:auto}table.matrix thead{display:none}
table.matrix tr{border:1px solid var(--line);border-radius:6px;margin:8px 0;padding:4px 0;display:grid;
grid-template-columns:auto auto 1fr;grid-template-areas:"id verdict level" "req req req" "reason reason reason"
"cases cases cases"}
table.matrix td{display:block;border:0;padding:2px 10px}table.matrix td.id{grid-area:id}
table.matrix td.verdict{grid-area:verdict;justify-self:start}table.matrix td.level{grid-area:level}
table.matrix td.req{grid-area:req}table.matrix td.reason{grid-area:reason}table.matrix td.cases{grid-area:cases}
table.matrix td.reason::before{content:"Reason: ";font-weight:600}
table.matrix td.cases::before{content:"Cases: ";font:600 12px system-ui,sans-serif}
table.kv{min-width:0}table.kv th{width:auto}
}
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
details:not(.events)::details-content{content-visibility:visible;display:contents}
details>summary::before{content:none!important}details.more>summary{font-size:0;margin:0}
details.more>summary::after{content:", ";font-size:11.5px}
nav.contents{display:none}pre.wire{max-height:none;overflow:visible}
#coverage-beside{display:none}
pre{white-space:pre-wrap}
footer{break-before:avoid}
}
"""
