"""The HTML report's scenarios section (a backseat run): what each scenario exercised, and for how long.

One row per scenario of ``coverage.scenarios`` (:mod:`helmcheck.certify.backseat.stage`): its
planned and actual length (and how long the run held it open for its moments), each moment with
when it happened and how long after it the report of it reached the backseat, what the scenario
exercised, and — when a moment did not reach the backseat in time — which clauses' observations
in it are not claimed, and why. :func:`scenarios_section` returns the section (folded, open when
something is not claimed), or ``""`` for a run that has none (a vehicle run, a log check, an
older results file). Self-contained: it only reads the results document.
"""

from __future__ import annotations

from typing import Any, Mapping

from .html_markup import _e, _fold
from .rundir import Run

__all__ = ["scenarios_section", "scenario_rows"]


def scenario_rows(results: Mapping[str, Any]) -> list[Mapping[str, Any]]:
    cov = results.get("coverage")
    rows = cov.get("scenarios") if isinstance(cov, Mapping) else None
    return [r for r in rows if isinstance(r, Mapping)] if isinstance(rows, list) else []


def _s(x: Any) -> str:
    return f"{x:.1f} s" if isinstance(x, (int, float)) and not isinstance(x, bool) else "—"


def _moment(m: Mapping[str, Any]) -> str:
    what = str(m.get("what", ""))
    after = m.get("after_s")
    if after is None:
        return f'{_e(what)}: <span class="warn">never reached the backseat</span>'
    late = m.get("in_time") is False
    text = f"{what}: reached the backseat {after:.2f} s after it"
    if m.get("limit_s") is not None:
        text += f" (in time: within {m['limit_s']:.2f} s)" if not late else f" (later than {m['limit_s']:.2f} s)"
    return f'<span class="warn">{_e(text)}</span>' if late else _e(text)


def scenarios_section(run: Run) -> str:
    rows = scenario_rows(run.results)
    if not rows:
        return ""
    body = ['<table class="scenarios"><thead><tr><th>scenario</th><th>planned</th><th>ran</th>'
            "<th>its moments</th><th>exercised</th><th>claimed</th></tr></thead><tbody>"]
    missing = 0
    for r in rows:
        ran = _s(r.get("ran_s")) if r.get("finished") else f"{_s(r.get('ran_s'))} (cut short)"
        ext = r.get("extended_s") or 0.0
        if ext > 0.005:
            ran += f"<br><span class=\"muted\">held open {ext:.1f} s (at most {_s(r.get('limit_s'))})</span>"
        moments = "<br>".join(_moment(m) for m in r.get("moments") or []) or '<span class="muted">—</span>'
        nots = r.get("not_claimed") or []
        if nots:
            missing += 1
            claimed = "<br>".join(f'<span class="warn">not claimed: {_e(", ".join(n.get("clauses", [])))} — '
                                  f'{_e(n.get("reason", ""))}</span>' for n in nots)
        elif not r.get("finished"):
            claimed = '<span class="warn">the run ended before it finished</span>'
        else:
            claimed = "yes"
        body.append(f"<tr><th>{_e(r.get('name', ''))}</th><td>{_s(r.get('planned_s'))}</td><td>{ran}</td>"
                    f"<td>{moments}</td><td>{_e(r.get('exercised', ''))}</td><td>{claimed}</td></tr>")
    body.append("</tbody></table>")
    body.append('<p class="muted">Each scenario lasts what it must show needs at the run\'s time scale and on its '
                "line (<span class=\"mono\">helmcheck certify backseat --plan</span>) and is held open, up to a "
                "stated limit, until its moments have reached the backseat; a moment that did not leaves the "
                "scenario's observations of its clauses out of the claim.</p>")
    total = sum(r.get("ran_s") or 0.0 for r in rows)
    gist = f"{len(rows)} scenario(s), {total:.1f} s" + (f" · {missing} not claimed in full" if missing else
                                                         " · every moment reached the backseat")
    return _fold("scenarios", "Scenarios", "\n".join(body), _e(gist), open_=bool(missing))
