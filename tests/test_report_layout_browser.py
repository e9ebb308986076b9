"""The HTML report fits a laptop: no horizontal scroll bar at 1280×800 (nor at 800 px), folded
and unfolded, in a real browser (headless Chromium, :mod:`tests.browser`).

Two reports are measured: the demo certificate (``reports/demo``, a real run of the emulator,
re-rendered by the present code) and a worst case made from the failing fixture — 65 cases a
clause, reasons and wire lines with 300-character tokens, long identity, profile, restore,
process and coverage values — the content that used to widen the page. For each, the page is
measured as it loads (folds closed), then with every ``<details>`` opened: the document is no
wider than its window (``scrollWidth <= clientWidth``) and no box inside scrolls sideways.
Folding is measured too: the demo certificate is at most four screens long, and a failing
report shows its findings, and the rows of its failing clauses, before anything folded.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from helmcheck.reports.render import render_all
from helmcheck.reports.results import write_results_atomic
from tests.browser import measure, needs_chromium

ROOT = Path(__file__).resolve().parent.parent
DEMO = ROOT / "reports" / "demo"
FIXTURES = Path(__file__).parent / "fixtures" / "reports"
HEIGHT = 800

pytestmark = [needs_chromium, pytest.mark.xdist_group("report-layout-browser")]  # one worker measures each page once

_MEASURE = r"""
const doc = document.documentElement;
function name(el) {
  return el.tagName.toLowerCase() + (el.id ? "#" + el.id : "")
    + (el.getAttribute("class") ? "." + el.getAttribute("class").split(" ").join(".") : "");
}
function state() {
  const wide = [], scrolling = [];
  for (const el of document.querySelectorAll("body *")) {
    const r = el.getBoundingClientRect();
    if (r.width && r.right > doc.clientWidth + 1) wide.push(name(el) + " right=" + Math.round(r.right));
    else if (!el.closest("svg") && el.clientWidth && el.scrollWidth > el.clientWidth + 1)
      wide.push(name(el) + " text " + el.scrollWidth + ">" + el.clientWidth);
    const x = getComputedStyle(el).overflowX;
    if ((x === "auto" || x === "scroll") && el.scrollWidth > el.clientWidth + 1)
      scrolling.push(name(el) + " " + el.scrollWidth + ">" + el.clientWidth);
  }
  return {scrollWidth: doc.scrollWidth, clientWidth: doc.clientWidth, height: doc.scrollHeight,
          wide: wide.slice(0, 8), scrolling: scrolling.slice(0, 8)};
}
function pageTop(id) {
  const el = document.getElementById(id);
  return el && el.checkVisibility() ? el.getBoundingClientRect().top + scrollY : null;
}
out.viewport = [innerWidth, innerHeight];
out.folded = state();
out.tops = {};
for (const id of ["verdict", "findings", "matrix"]) out.tops[id] = pageTop(id);
out.rows = {};
for (const row of document.querySelectorAll("tr.clause"))
  out.rows[row.id.slice(7)] = [row.dataset.verdict, row.checkVisibility()];
for (const d of document.querySelectorAll("details")) d.open = true;
out.unfolded = state();
"""


def _demo(tmp_path: Path) -> Path:
    """The committed demo certificate, re-rendered (its results and wire log only: the copy is
    not a results directory the suite re-judges)."""
    assert (DEMO / "results.json").is_file(), f"the demo report is not at {DEMO}"
    d = tmp_path / "demo"
    d.mkdir()
    for name in ("results.json", "wire.log"):
        shutil.copy(DEMO / name, d / name)
    render_all(d, formats=("html",))
    return d / "report.html"


def _worst_case(tmp_path: Path) -> Path:
    """The failing fixture with everything that can be long made long."""
    d = tmp_path / "worst"
    shutil.copytree(FIXTURES / "fail_run", d)
    doc = json.loads((d / "results.json").read_text(encoding="utf-8"))
    token = "$OSD," + "." * 300 + "*5C"
    for c in doc["clauses"]:
        c["cases"] = [f"V-{i:02d}" for i in range(1, 65)] + ["explore-" + "x" * 60]
        c["reason"] += f" first: {token} was answered"
        c["evidence"] = [*c["evidence"], {"t": 9.5, "dir": "<", "line": f"line 2364: {token}"}]
    doc["implementation"]["vehicle_name"] = "IVER3-" + "W" * 120
    doc["profile"]["mission"] = "m" * 200 + ".mis"
    doc["command"] += " --report-dir " + "/very-long-directory" * 20
    doc["events"].append({"t": 9.9, "kind": "note", "label": "n" * 300})
    rows = [f"row {i}: S/N/P/mP/A/M/W OMW_CLEAR_WP [running and mission_parking] -> err 26" for i in range(91)]
    doc["stats"] = {"explore": {"model_coverage": {
        "rows": {"covered": 30, "of": 91, "percent": 33.0, "uncovered": sorted(rows)},
        "boundaries": {"covered": 0, "of": 1, "percent": 0.0, "uncovered": ["b" * 200]}}}}
    doc["restore"] = {"found": {"mode": "S", "mission": "c" * 200 + ".mis"}, "left": {"mode": "S", "note": None},
                      "settings": [{"name": "SafetyAction", "before": ["1", "p" * 200], "written": True,
                                    "after": ["1", "p" * 200], "verified": True}],
                      "attempted": True, "verified": True, "problems": [], "by_hand": []}
    doc["process"] = {"command": "./vehicle " + "--flag " * 60 + "z" * 200, "pid": 4242, "exit_code": 3,
                      "signal": None, "ended_at_s": 4.0, "ended_early": True,
                      "output_tail": ["Traceback: " + "q" * 300, "done"]}
    write_results_atomic(d, doc)
    render_all(d, formats=("html",))
    return d / "report.html"


def _no_sideways_scroll(state: dict, what: str) -> None:
    assert state["scrollWidth"] <= state["clientWidth"], (what, state)
    assert not state["scrolling"], (what, state)


@pytest.fixture(scope="module")
def measured(tmp_path_factory):
    """``measured(report, width)``: the measurements of one report at one width, made once."""
    pages: dict[str, Path] = {}
    done: dict[tuple[str, int], dict] = {}

    def get(report: str, width: int) -> dict:
        if report not in pages:
            where = tmp_path_factory.mktemp(report.replace(" ", "-"))
            pages[report] = _demo(where) if report == "demo" else _worst_case(where)
        if (report, width) not in done:
            done[report, width] = measure(pages[report], _MEASURE, width, HEIGHT)
        return done[report, width]

    return get


@pytest.mark.parametrize("width", [1280, 800])
@pytest.mark.parametrize("report", ["demo", "worst case"])
def test_no_horizontal_scroll_bar(measured, report, width):
    m = measured(report, width)
    assert m["viewport"][0] == width
    _no_sideways_scroll(m["folded"], f"{report} at {width} px, folds closed")
    _no_sideways_scroll(m["unfolded"], f"{report} at {width} px, every fold open")
    assert m["unfolded"]["height"] > m["folded"]["height"]  # there was something to fold


def test_the_demo_certificate_is_a_few_screens_long(measured):
    m = measured("demo", 1280)
    assert m["folded"]["height"] <= 4 * HEIGHT, m["folded"]
    assert all(verdict == "pass" for verdict, _ in m["rows"].values())
    assert not any(shown for _, shown in m["rows"].values())  # every section passed: all folded


def test_failing_clauses_come_first_and_are_not_folded(measured):
    m = measured("worst case", 1280)
    tops = m["tops"]
    assert tops["verdict"] < tops["findings"] < tops["matrix"], tops
    rows = m["rows"]
    attention = {cid for cid, (v, _) in rows.items() if v in ("fail", "non-strict", "inconclusive")}
    assert attention and all(rows[cid][1] for cid in attention), rows
    assert any(not shown for _, shown in rows.values())  # sections where everything passed are folded
