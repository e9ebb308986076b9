"""The HTML report's model coverage (modes, transitions, interrupt pairs; the range edges of §4–8b
the run reached, ``stats.edges``, with those it did not and why; the exploration's own
coverage of the model's rows, interrupt pairs, timer boundaries and error codes, with what stayed
uncovered, listed in natural order: row 2 before row 10) beside the sentence saying what model
coverage means for the verdict (:func:`~helmcheck.reports.scope.model_coverage_note`), and the
event summary and event table that go with the mode timeline.
"""

from __future__ import annotations

import re
from typing import Any, Mapping

from .html_markup import _e
from .rundir import Run
from .scope import MODEL_DIMENSIONS, edge_coverage, edge_gist, model_coverage, model_coverage_note
from .timeline import MODE_ORDER, event_counts

_REMOTE_MODES = ("A", "M", "mP", "W")


def _coverage(run: Run) -> str:
    cov = run.results["coverage"]
    reached = set(cov["modes"])
    modes = list(MODE_ORDER) + sorted(reached - set(MODE_ORDER))
    chips = "".join(f'<span class="chip {"reached" if m in reached else "unreached"}">{_e(m)}</span>' for m in modes)
    out = [f'<h3>Modes reached ({len(reached & set(modes))} of {len(modes)})</h3><p id="modes">{chips}</p>']
    out.append(f'<h3>Transitions exercised ({len(cov["transitions"])})</h3>')
    if cov["transitions"]:
        items = "".join(f'<li><b>{_e(a)}</b> → <b>{_e(b)}</b> <span class="muted">via</span> <code>{_e(via)}</code></li>'
                        for a, b, via in cov["transitions"])
        out.append(f'<ul class="transitions">{items}</ul>')
    else:
        out.append('<p class="muted">none recorded</p>')
    pairs = {tuple(p) for p in cov["interrupt_pairs"]}
    # Rows: the active control modes. Columns: what interrupted them — modes (a square matrix)
    # or, as a vehicle run records them, the interrupting commands.
    actives = list(_REMOTE_MODES) + sorted({p[0] for p in pairs} - set(_REMOTE_MODES))
    news = {p[1] for p in pairs}
    others = sorted(news - set(_REMOTE_MODES))
    cols = [m for m in _REMOTE_MODES if m in news or not others] + others
    out.append(f"<h3>Interrupt pairs exercised ({len(pairs)}) — RH-INT-1</h3>")
    head = "".join(f"<th>{_e(m)}</th>" for m in cols)
    body = []
    for active in actives:
        cells = []
        for new in cols:
            hit = (active, new) in pairs
            cls = "hit" if hit else ("self" if active == new else "")
            cells.append(f'<td class="{cls}">{"✓" if hit else ""}</td>')
        body.append(f"<tr><th>{_e(active)}</th>{''.join(cells)}</tr>")
    out.append(f'<table class="pairs"><thead><tr><th>active ↓ / interrupted by →</th>{head}</tr></thead>'
               f"<tbody>{''.join(body)}</tbody></table>")
    out.append(_edge_coverage(run))
    out.append(_exploration_coverage(run))
    return "\n".join(out)


def _edge_coverage(run: Run) -> str:
    """The range edges reached (``stats.edges``): the count, per clause, and the edges not reached."""
    e = edge_coverage(run.results)
    if not e:
        return ""
    per = " · ".join(f"{_e(c)} {_e(d.get('reached'))}/{_e(d.get('of'))}" for c, d in
                     sorted((e.get("by_clause") or {}).items(), key=lambda x: natural_key(x[0])))
    missing = e.get("unreached") or []
    more = (f'<details><summary>{len(missing)} not reached</summary><ul class="uncovered">'
            + "".join(f"<li><code>{_e(u.get('edge'))}</code>{' — ' + _e(u['why']) if u.get('why') else ''}</li>"
                      for u in missing) + "</ul></details>") if missing else ""
    return (f'<h3 id="range-edges">Range edges reached ({_e(e.get("reached"))} of {_e(e.get("of"))})</h3>'
            f'<p class="note">{_e(edge_gist(run.results))} A value at a bound, and just past it, sent where the '
            f'answer turns on that bound alone.</p><p class="muted">{per}</p>{more}')


def natural_key(text: object) -> tuple:
    """Sort key that orders the numbers inside a text by value: ``row 2`` before ``row 10``."""
    return tuple((0, int(part), "") if part.isdigit() else (1, 0, part)
                 for part in re.split(r"(\d+)", str(text)) if part)


def exploration_coverage(run: Run) -> dict[str, Mapping[str, Any]]:
    """``stats.explore.model_coverage`` of a vehicle run (empty when the run recorded none)."""
    return model_coverage(run.results)


def _exploration_coverage(run: Run) -> str:
    """The exploration's model coverage (``stats.explore.model_coverage``), beside the clauses."""
    mc = exploration_coverage(run)
    if not mc:
        return ""
    rows = []
    for name, d in mc.items():
        missing = sorted((str(x) for x in d.get("uncovered") or []), key=natural_key)
        more = (f'<details><summary>{len(missing)} uncovered</summary><ul class="uncovered">'
                + "".join(f"<li><code>{_e(x)}</code></li>" for x in missing) + "</ul></details>") if missing else "—"
        both = d.get("with_cases")
        rows.append(f"<tr><td>{_e(MODEL_DIMENSIONS.get(name, name.replace('_', ' ')))}</td><td>{_e(d.get('covered'))} "
                    f"of {_e(d.get('of'))} ({_e(d.get('percent'))} %)</td>"
                    f"<td>{_e(both) if isinstance(both, int) else '—'}</td><td>{more}</td></tr>")
    return ('<h3 id="exploration-coverage">What the exploration reached of the model</h3>'
            f'<p class="note" id="model-coverage-note">{_e(model_coverage_note(run.results))}</p>'
            '<table class="exploration-coverage"><thead><tr><th>dimension</th><th>reached</th>'
            f"<th>with the cases</th><th>not reached</th></tr></thead><tbody>{''.join(rows)}</tbody></table>")


def _coverage_gist(run: Run) -> str:
    """One line for the folded coverage section: modes, transitions, pairs, the exploration's rows."""
    cov = run.results["coverage"]
    reached = set(cov["modes"])
    modes = set(MODE_ORDER) | reached
    parts = [f"{len(reached)} of {len(modes)} modes", f"{len(cov['transitions'])} transitions",
             f"{len({tuple(p) for p in cov['interrupt_pairs']})} interrupt pairs"]
    rows = exploration_coverage(run).get("rows")
    if rows:
        parts.append(f"exploration: {rows.get('covered')} of {rows.get('of')} transitions "
                     f"({rows.get('percent')} %), not part of the verdict")
    return _e(" · ".join(parts))


def _events_table(run: Run) -> str:
    events = sorted(run.results["events"], key=lambda ev: ev["t"])
    if not events:
        return ""
    rows = "".join(f'<tr><td class="mono">{ev["t"]:.3f}</td><td>{_e(_kind(ev))}</td>'
                   f'<td class="mono">{_e(ev["label"])}</td></tr>' for ev in events[:2000])
    more = f'<p class="muted">… {len(events) - 2000} more events in results.json</p>' if len(events) > 2000 else ""
    return (f'<details class="events"><summary>Events ({len(events)}; not printed)</summary><table><thead><tr><th>t (s)</th>'
            f"<th>kind</th><th>label</th></tr></thead><tbody>{rows}</tbody></table>{more}</details>")


def _kind(ev: Mapping[str, Any]) -> str:
    if ev.get("negative_test"):
        return "expected refusal (negative test)"
    return str(ev["kind"])


def _event_summary(run: Run) -> str:
    c = event_counts(run.results)
    return (f'<p id="event-counts">{c["ack-error"]} ACK error(s); {c["negative-test"]} expected refusal(s) '
            f'— negative tests the tester provoked on purpose, drawn in grey; {c["lockout"]} lockout event(s).</p>')
