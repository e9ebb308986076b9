"""The HTML report's sections about the run: the implementation as declared and as seen on the
wire (a backseat by its own name, never the vehicle helmcheck played), the run's facts (the line model and the port's line error counters among them), the process under test (``--exec``) and the vehicle's restore.
"""

from __future__ import annotations

from typing import Mapping

from .html_markup import _e, _flatten, _kv_table
from .identity import EXEC_NAMED, backseat_name
from .linecounters import counters_summary, line_model_summary
from .rundir import Run
from .verdicts import describe_process


def _run_facts(run: Run) -> str:
    r = run.results
    rows = [("role", r["role"]), ("command", r["command"]), ("tool", f'{r["tool"]["name"]} {r["tool"]["version"]}'),
            ("started", r["started"]), ("finished", r["finished"]),
            ("duration", None if r["duration_s"] is None else f'{r["duration_s"]:.3f} s'),
            ("seed", r["seed"]), ("results directory", str(run.directory))]
    rows += [(f"settings.{k}", v) for k, v in _flatten(r["settings"])]
    model = line_model_summary(r)
    if model is not None:
        rows.append(("line model", model))
    counters = counters_summary(r)
    if counters is not None:
        rows.append(("line error counters", counters))
    return _kv_table(rows)


def _identity(run: Run) -> str:
    """The implementation under test, as declared and as seen on the wire. A backseat is named by
    its ``--implementation`` or the command ``--exec`` ran; what the vehicle helmcheck played
    said of itself (its ``$OSI``) is not the implementation's and is not shown as such."""
    impl = run.results["implementation"]
    wire = run.wire
    backseat = run.results["role"] == "backseat"
    declared = _flatten(impl)
    if backseat:  # its port and protocol; what else an older record holds is the vehicle helmcheck played
        name, by_exec = backseat_name(run.results)
        declared = [("backseat", None if name is None else f"{name} ({EXEC_NAMED})" if by_exec else name),
                    *((k, v) for k, v in declared if k in ("port", "protocol"))]
    out = ["<h3>Declared</h3>", _kv_table(declared)]
    out.append("<h3>As seen on the wire</h3>")
    if not wire["present"]:
        out.append('<p class="warn">No wire log.</p>')
        return "\n".join(out)
    by_dir = wire["by_dir"]
    to_v, from_v = by_dir[">"] + by_dir[">~"], by_dir["<"] + by_dir["<~"]
    records = (f'{to_v} from the backseat, {from_v} from the vehicle helmcheck played' if backseat
               else f'{to_v} to the vehicle, {from_v} from the vehicle')
    rows = [
        ("wire log", run.results["wire_log"] + ("" if wire["format_ok"] else " (no wire-log 1 format tag)")),
        ("recorder header", " | ".join(wire["header"]) or None),
        ("records", f'{wire["records"]} ({records}, {by_dir["!"]} notes'
                    f'{", " + str(wire["unparsed"]) + " unparsed" if wire["unparsed"] else ""})'),
        ("time span", None if wire["first_t"] is None else f'{wire["first_t"]:.6f} s – {wire["last_t"]:.6f} s'),
    ]
    if not backseat:
        rows += [("first $OSI from the vehicle", wire["first_osi"]), ("$OSI field count", wire["osi_fields"]),
                 ("vehicle name ($OSI field 18)", wire["osi_vehicle_name"])]
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


def restore_headline(rec: Mapping) -> str:
    """The restore in one sentence (the section's first line, and its gist while folded)."""
    ok = bool(rec.get("verified"))
    return ("Every setting the run changed was written back and read again as found; the vehicle "
            "was stopped." if ok and rec.get("attempted") else
            "Nothing needed restoring." if ok else "The vehicle was NOT verified as restored.")


def _restore(run: Run) -> str:
    """The vehicle left as found: each setting before and after, the mode, what to do by hand."""
    rec = run.results.get("restore")
    if not isinstance(rec, Mapping):
        return ""
    ok = bool(rec.get("verified"))
    found = rec.get("found") or {}
    left = rec.get("left") or {}
    head = restore_headline(rec)
    out = [f'<div class="finding {"v-pass" if ok else "v-fail"}" id="restore-status"><p>{_e(head)}</p>']
    # The mission is what the first $OSI named (field 12): in S it is loaded, not running.
    rows = [("found in mode", found.get("mode")), ("mission named in its first $OSI", found.get("mission")),
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
