"""JUnit XML for CI dashboards: one ``<testcase>`` per clause of the results, and the run verdict.

Mapping (classname = section of the reference profile, name = clause ID + short title):

* ``pass`` → a plain testcase;
* ``fail`` → ``<failure message="reason" type="MUST|SHOULD">`` with the wire evidence as text;
* ``inconclusive`` → ``<error message="reason" type="inconclusive">``;
* ``not-tested`` → ``<skipped message="reason">``;
* ``non-strict`` → passes with a ``<system-out>`` note, or ``<failure type="non-strict">`` when
  the run is strict (a SHOULD then counts as a MUST).

The suite's ``<properties>`` lead with the headline and scope ("PASS — partial: 4 of 60 claimed
clauses judged; not a certificate", ``helmcheck.certificate``), then what was tested
(``identity.*``), the certificate digest and the signing key, so a CI artefact can be matched to
its results directory. A passing testcase carries its wire evidence in ``<system-out>``. Built
with the standard library; text is stripped of characters XML forbids.

When helmcheck started the implementation (``process`` in the results, ``--exec``), one more
testcase (classname ``process``) says how it ended: a ``<failure type="process-ended">`` quoting
its last output when it ended before the run's end — a dashboard must not show a run whose
implementation died as a row of skipped clauses — else a plain testcase.

The last testcase (classname ``run``, name ``run-verdict``) carries the run verdict, so a
dashboard's totals never disagree with the exit status: ``fail`` (or ``non-strict`` in a strict
run) → ``<failure type="run-verdict">``, ``inconclusive`` (an interrupted run, a backseat that
never connected, a clause that could not be judged) → ``<error type="inconclusive">``, else a
plain testcase. The message is ``VERDICT: reason``. A run that is not a certificate (partial,
:mod:`.scope`) says so in the case's text (``<system-out>`` for a plain testcase) and in the
suite property ``helmcheck.not_a_certificate`` (the scope statement and why; absent for a
certificate).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import Any, Mapping

from ..judge.verdict import Verdict
from .identity import identity_rows
from .rundir import Run
from .scope import headline, scope_of
from .text import printable, section_name, short_title
from .verdicts import describe_process
from .view import VERDICT_LABEL, clause_rows

__all__ = ["render_junit"]

_EVIDENCE_LIMIT = 50


def _t(value: object) -> str:
    return printable(value)


def _evidence_text(row: Mapping[str, Any]) -> str:
    lines = [f'{ev["t"]:.6f} {ev["dir"]} {ev["line"]}' for ev in row["evidence"][:_EVIDENCE_LIMIT]]
    if len(row["evidence"]) > _EVIDENCE_LIMIT:
        lines.append(f'… {len(row["evidence"]) - _EVIDENCE_LIMIT} more lines in results.json')
    head = [f"{row['id']} ({row['level']}): {row['reason']}"]
    if row["cases"]:
        head.append("cases: " + ", ".join(row["cases"]))
    if row["replay"]:
        head.append(f"replay: {row['replay']}")
    return _t("\n".join(head + lines))


def _not_a_certificate(scope) -> str:
    """Why the run is not a certificate (the scope statement and its gaps), or "" if it is one."""
    if scope.certificate:
        return ""
    why = scope.why()
    return scope.statement + (" — " + "; ".join(why) if why else "")


def _run_verdict_case(suite: ET.Element, r: Mapping[str, Any], strict: bool, not_a_certificate: str,
                      tallies: dict[str, int]) -> None:
    """The ``run-verdict`` testcase (module docstring)."""
    tallies["tests"] += 1
    v = r["verdict"]
    case = ET.SubElement(suite, "testcase", classname="run", name="run-verdict", time=f'{r["duration_s"] or 0:.3f}')
    if not_a_certificate:
        props = ET.SubElement(case, "properties")
        ET.SubElement(props, "property", name="helmcheck.not_a_certificate", value=_t(not_a_certificate))
    message = f"{VERDICT_LABEL.get(v, str(v).upper())}: {r['verdict_reason']}"
    text = "\n".join(x for x in (message, headline(r), not_a_certificate and f"Not a certificate: {not_a_certificate}")
                     if x)
    if v == Verdict.FAIL or (v == Verdict.NON_STRICT and strict):
        el = ET.SubElement(case, "failure", message=_t(message), type="run-verdict")
        el.text = _t(text)
        tallies["failures"] += 1
    elif v == Verdict.INCONCLUSIVE:
        el = ET.SubElement(case, "error", message=_t(message), type=Verdict.INCONCLUSIVE)
        el.text = _t(text)
        tallies["errors"] += 1
    else:
        out = ET.SubElement(case, "system-out")
        out.text = _t(text)


def render_junit(run: Run, strict: bool | None = None) -> str:
    """The JUnit XML document (a string with an XML declaration). *strict* defaults to the run's."""
    r = run.results
    strict = run.strict if strict is None else strict
    rows = clause_rows(r)
    suite_name = f"helmcheck {r['role']}"
    tallies = {"tests": len(rows), "failures": 0, "errors": 0, "skipped": 0}

    suite = ET.Element("testsuite", name=suite_name, timestamp=_t(r["started"]),
                       time=f'{r["duration_s"] or 0:.3f}', hostname=_t(r["implementation"].get("port") or ""))
    props = ET.SubElement(suite, "properties")
    scope = scope_of(r)
    sig = r.get("signature") if isinstance(r.get("signature"), dict) else {}
    meta = [
        ("helmcheck.headline", headline(r)),
        ("helmcheck.certificate", "true" if scope.certificate else "false"),
        ("helmcheck.scope", scope.statement),
        ("helmcheck.scope_gaps", "; ".join(scope.why())),
    ] + [(f"identity.{label}", value) for label, value, _ in identity_rows(r, run.wire["osi_vehicle_name"])] + [
        ("helmcheck.signature_key_id", sig.get("key_id") or "not signed"),
        ("helmcheck.digest", run.digest.combined),
        ("helmcheck.results_sha256", run.digest.results),
        ("helmcheck.wire_sha256", run.digest.wire or "absent"),
        ("helmcheck.verdict", r["verdict"]),
        ("helmcheck.verdict_reason", r["verdict_reason"]),
        ("helmcheck.partial", "true" if r["partial"] else "false"),
        ("helmcheck.strict", "true" if strict else "false"),
        ("helmcheck.role", r["role"]),
        ("helmcheck.seed", "" if r["seed"] is None else str(r["seed"])),
        ("helmcheck.tool_version", r["tool"]["version"]),
        ("helmcheck.command", r["command"]),
    ] + [(f"implementation.{k}", "" if v is None else str(v)) for k, v in r["implementation"].items()]
    not_a_certificate = _not_a_certificate(scope)
    if not_a_certificate:
        meta.insert(4, ("helmcheck.not_a_certificate", not_a_certificate))
    for name, value in meta:
        ET.SubElement(props, "property", name=_t(name), value=_t(value))

    for row in rows:
        title = short_title(row["text"]) if row["text"] else "not in the reference profile"
        case = ET.SubElement(suite, "testcase",
                             classname=_t(section_name(row["section"], row["section_title"])),
                             name=_t(f"{row['id']} {title}"), time="0")
        v = row["verdict"]
        if v == Verdict.FAIL or (v == Verdict.NON_STRICT and strict):
            kind = Verdict.NON_STRICT if v == Verdict.NON_STRICT else row["level"]
            el = ET.SubElement(case, "failure", message=_t(row["reason"]), type=_t(kind))
            el.text = _evidence_text(row)
            tallies["failures"] += 1
        elif v == Verdict.INCONCLUSIVE:
            el = ET.SubElement(case, "error", message=_t(row["reason"]), type=Verdict.INCONCLUSIVE)
            el.text = _evidence_text(row)
            tallies["errors"] += 1
        elif v == Verdict.NOT_TESTED:
            ET.SubElement(case, "skipped", message=_t(row["reason"]))
            tallies["skipped"] += 1
        elif v == Verdict.NON_STRICT:
            out = ET.SubElement(case, "system-out")
            out.text = _t(f"{VERDICT_LABEL[v]} (SHOULD not met): {row['reason']}")
        elif v == Verdict.PASS:
            out = ET.SubElement(case, "system-out")
            out.text = _evidence_text(row) if row["evidence"] else _t(f"{row['reason']}\n(no wire evidence recorded)")
    proc = r.get("process")
    if isinstance(proc, Mapping):
        tallies["tests"] += 1
        case = ET.SubElement(suite, "testcase", classname="process", name=_t(f"{r['role']} under test"), time="0")
        if proc.get("ended_early"):
            el = ET.SubElement(case, "failure", message=_t(describe_process(proc, r["role"])), type="process-ended")
            el.text = _t("\n".join([f"command: {proc.get('command', '')}", *map(str, proc.get("output_tail") or [])]))
            tallies["failures"] += 1
    _run_verdict_case(suite, r, strict, not_a_certificate, tallies)
    for key, value in tallies.items():
        suite.set(key, str(value))

    root = ET.Element("testsuites", name="helmcheck", time=suite.get("time", "0"),
                      **{k: str(v) for k, v in tallies.items()})
    root.append(suite)
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
