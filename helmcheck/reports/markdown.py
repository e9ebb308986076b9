"""A short Markdown summary for pull requests and CI job pages.

A headline that leads with the scope ("PASS — partial: 4 of 60 claimed clauses judged; not a
certificate", :func:`helmcheck.reports.scope.headline`), a PARTIAL warning if the run was
interrupted, the verdict's reason, then what failed (each failed clause with its reason,
:func:`~helmcheck.reports.scope.failures`), then why clauses were not judged, then what timing
judged coarser than nominal precision means (:func:`~helmcheck.reports.scope.precision_note`);
the implementation under test (a backseat by its ``--implementation``, else the command
``--exec`` ran — never the vehicle helmcheck played), what was tested (identity), the port's line error
counters (:mod:`helmcheck.reports.linecounters`), a counts table, the
exploration's model coverage with what it means for the verdict, the clauses that did not pass
with their reasons (worst first), every passing clause with its first evidence line, real ACK
errors counted apart from the tester's negative tests, and the digest and signature. Strings
from the results file or the device are escaped for GitHub-flavoured Markdown, including the
HTML it renders: ``<``, ``>`` and ``&`` become entities and Markdown punctuation is
backslash-escaped.
"""

from __future__ import annotations

import re

from .identity import backseat_name, identity_rows
from .linecounters import counters_summary, line_model_summary
from .rundir import Run
from .scope import (MODEL_DIMENSIONS, edge_gist, failures, headline, model_coverage, model_coverage_note,
                    precision_note, reach_text, scope_of)
from .text import printable
from .timeline import event_counts
from .verdicts import describe_process
from .view import VERDICT_LABEL, counts, non_pass_rows, pass_rows

__all__ = ["render_markdown", "md_escape", "md_code", "ROW_LIMIT"]

ROW_LIMIT = 60  # non-pass rows listed before "… and N more"
PASS_ROW_LIMIT = 200  # passing rows (each with its first evidence line)

# Markdown punctuation that can start markup inline; ``$`` because GitHub renders $…$ as math.
_MD_SPECIAL = re.compile(r"([\\`*_\[\]|~$])")


def md_escape(value: object) -> str:
    """Any value as inline Markdown text: one line, no markup, no HTML."""
    text = " ".join(printable(value).split())
    text = text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
    return _MD_SPECIAL.sub(r"\\\1", text)


def md_code(value: object) -> str:
    """Any value as the inside of an inline code span: one line, no backticks."""
    return " ".join(printable(value).split()).replace("`", "'")


def digest_markdown(run: Run) -> str:
    d = run.digest
    sig = run.results.get("signature")
    signed = (f"Signed ({md_escape(sig.get('algorithm'))}) by key `{md_escape(sig.get('key_id'))}`; check with "
              f"`helmcheck verify DIR --public-key KEY.pub`." if isinstance(sig, dict)
              else "Not signed: `helmcheck verify DIR` re-judges the wire log.")
    return (f"Certificate digest (SHA-256): `{d.combined}`  \n"
            f"results.json `{d.results}` · wire log `{d.wire or 'absent'}`  \n{signed}")


def _evidence_line(ev: dict) -> str:
    return md_escape(f'{ev["t"]:.6f} {ev["dir"]} {ev["line"]}')


def render_markdown(run: Run, comparison_md: str | None = None) -> str:
    """The Markdown summary of *run* (optionally followed by a comparison section)."""
    r = run.results
    word = VERDICT_LABEL.get(r["verdict"], r["verdict"])
    impl = r["implementation"]
    scope = scope_of(r)
    out = [f"## helmcheck {md_escape(r['role'])} report: **{md_escape(headline(r))}**", ""]
    if r["partial"] and scope.unexercised:
        out += ["> **PARTIAL RUN**: the run finished, but not every scenario was exercised (a moment it "
                "exists for did not reach the backseat in time); this is not a complete certificate.", ""]
    elif r["partial"]:
        out += ["> **PARTIAL RUN**: the run was interrupted before it finished; "
                "this is not a complete certificate.", ""]
    if not run.wire["present"]:
        out += [f"> **Wire log missing**: {md_escape(r['wire_log'])} is not in the results directory.", ""]
    strict = " (strict)" if run.strict else ""
    out += [f"**{word}**{strict}: {md_escape(r['verdict_reason'])}", ""]
    failed = failures(r)
    if failed:
        out += [f"- {md_escape(line)}" for line in failed] + [""]
    if scope.gaps:
        out += ["Not judged:", ""] + [f"- {md_escape(line)}" for line in scope.why()] + [""]
    precision = precision_note(r)
    if precision:
        out += [md_escape(precision), ""]

    facts = []
    if r["role"] == "backseat":  # the backseat under test; the vehicle helmcheck played is not named
        name, by_exec = backseat_name(r)
        label = "Backseat"
        if name:
            facts.append(f"`{md_code(name)}` (the command --exec ran)" if by_exec else md_escape(name))
    else:
        label = "Implementation"
        if impl.get("vehicle_name"):
            facts.append(md_escape(impl["vehicle_name"]))
    if impl.get("port"):
        facts.append(f"on {md_escape(impl['port'])}")
    if impl.get("protocol"):
        facts.append(f"protocol {md_escape(impl['protocol'])}")
    seen = run.wire["osi_vehicle_name"]
    if r["role"] != "backseat" and seen is not None and seen != impl.get("vehicle_name"):
        facts.append(f"(name on the wire: {md_escape(seen)})")
    when = f"started {md_escape(r['started'])}"
    if r["duration_s"] is not None:
        when += f", {r['duration_s']:.1f} s"
    seed = f", seed {md_escape(r['seed'])}" if r["seed"] is not None else ""
    out += [f"{label}: {' '.join(facts) or 'not recorded'}; {when}{seed}.", ""]
    out += ["| What was tested | |", "|---|---|"]
    out += [f"| {md_escape(label)} | {'**' + md_escape(value) + '**' if missing else md_escape(value)} |"
            for label, value, missing in identity_rows(r, run.wire["osi_vehicle_name"])]
    out.append("")
    proc = r.get("process")
    if isinstance(proc, dict):
        out += [f"Process under test: `{md_code(proc.get('command', ''))}`. "
                f"{md_escape(describe_process(proc, r['role']))}", ""]

    rec = r.get("restore")
    if isinstance(rec, dict):
        if rec.get("verified"):
            names = [st["name"] for st in rec.get("settings") or () if st.get("written")]
            out += ["Vehicle restored: stopped" + (f"; {', '.join(names)} written back and read again as found"
                                                     if names else "") + ".", ""]
        else:
            out += ["**Vehicle NOT verified as restored**: " + md_escape("; ".join(rec.get("problems") or []))
                    + ". Set by hand: " + md_escape("; ".join(rec.get("by_hand") or [])) + ".", ""]

    model = line_model_summary(r)
    if model is not None:
        out += [f"Line model: {md_escape(model)}.", ""]
    counters = counters_summary(r)
    if counters is not None:
        out += [f"Line error counters: {md_escape(counters)}.", ""]

    c = counts(r)
    out.append("| " + " | ".join(VERDICT_LABEL[v] for v in c) + " | total |")
    out.append("|" + "---:|" * (len(c) + 1))
    out.append("| " + " | ".join(str(n) for n in c.values()) + f" | {sum(c.values())} |")
    out.append("")
    if edge_gist(r):
        out += [md_escape(edge_gist(r)), ""]
    mc = model_coverage(r)
    if mc:
        out.append("Exploration's model coverage: " + md_escape(reach_text(mc, with_cases=True)) + ". "
                   + md_escape(model_coverage_note(r)))
        missing = [f"{MODEL_DIMENSIONS.get(k, k)}: " + "; ".join(str(x) for x in d.get("uncovered") or [])
                   for k, d in mc.items() if d.get("uncovered")]
        if missing:
            out += ["", "<details><summary>Not reached by the exploration</summary>", ""]
            out += [f"- {md_escape(m)}" for m in missing] + ["", "</details>"]
        out.append("")

    rows = non_pass_rows(r)
    if rows:
        out += [f"### Not passed ({len(rows)})", "", "| Clause | Level | Verdict | Reason |", "|---|---|---|---|"]
        for row in rows[:ROW_LIMIT]:
            out.append(f"| {md_escape(row['id'])} | {md_escape(row['level'])} | "
                       f"{VERDICT_LABEL.get(row['verdict'], md_escape(row['verdict']))} | {md_escape(row['reason'])} |")
        if len(rows) > ROW_LIMIT:
            out.append(f"\n… and {len(rows) - ROW_LIMIT} more; see report.html.")
        out.append("")
    else:
        out += ["Every clause passes.", ""]

    passed = pass_rows(r)
    if passed:
        out += [f"### Passed, with evidence ({len(passed)})", "", "| Clause | Reason | First evidence line |",
                "|---|---|---|"]
        for row in passed[:PASS_ROW_LIMIT]:
            first = _evidence_line(row["evidence"][0]) if row["evidence"] else "no wire evidence recorded"
            more = f" (+{len(row['evidence']) - 1} more)" if len(row["evidence"]) > 1 else ""
            out.append(f"| {md_escape(row['id'])} | {md_escape(row['reason'])} | {first}{more} |")
        if len(passed) > PASS_ROW_LIMIT:
            out.append(f"\n… and {len(passed) - PASS_ROW_LIMIT} more; see report.html.")
        out.append("")
    ev = event_counts(r)
    out += [f"Events: {ev['ack-error']} ACK error(s); {ev['negative-test']} expected refusal(s) (negative tests "
            f"the tester provoked on purpose); {ev['lockout']} lockout event(s).", ""]

    if comparison_md:
        out += [comparison_md.rstrip(), ""]
    out += [digest_markdown(run), ""]
    return "\n".join(out)
