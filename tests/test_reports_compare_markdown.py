"""The Markdown summary and the comparison of two runs."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

from helmcheck.reports.compare import compare, compare_html, compare_markdown, compare_text
from helmcheck.reports.digest import digest_dir
from helmcheck.reports.markdown import md_escape
from helmcheck.reports.render import render_all
from helmcheck.reports.results import finish, load_results, write_results_atomic

FIXTURES = Path(__file__).parent / "fixtures" / "reports"


def copy_run(tmp_path: Path, name: str, as_name: str | None = None) -> Path:
    d = tmp_path / (as_name or name)
    shutil.copytree(FIXTURES / name, d)
    return d


def set_verdicts(d: Path, changes: dict[str, tuple[str, str]]) -> dict:
    doc = load_results(d)
    for c in doc["clauses"]:
        if c["id"] in changes:
            c["verdict"], c["reason"] = changes[c["id"]]
            if c["verdict"] == "pass":
                c["replay"] = None
    doc["replays"] = [r for r in doc["replays"] if any(c["replay"] == r["file"] for c in doc["clauses"])]
    finish(doc, finished=doc["finished"], duration_s=doc["duration_s"])
    write_results_atomic(d, doc)
    return doc


# --------------------------------------------------------------------------- markdown

def test_markdown_summary_lists_non_pass_clauses_and_digest(tmp_path):
    d = copy_run(tmp_path, "fail_run")
    render_all(d, formats=("md",))
    md = (d / "report.md").read_text(encoding="utf-8")
    doc = load_results(d)
    assert md.splitlines()[0] == ("## helmcheck vehicle report: "
                                  "**FAIL — partial: 57 of 60 claimed clauses judged; not a certificate**")
    assert "- RH-FRM-9 not tested: " in md  # why the run is not a certificate, right under the headline
    assert "| 69 | 0 | 3 | 1 | 3 | 76 |" in md
    not_passed, passed = md.split("### Passed, with evidence", 1)
    for c in doc["clauses"]:
        assert (f"| {c['id']} |" in not_passed) == (c["verdict"] != "pass"), c["id"]
        assert (f"| {c['id']} |" in passed) == (c["verdict"] == "pass"), c["id"]
    assert digest_dir(d).combined in md
    assert "<script>" not in md and "<img" not in md and "<b>" not in md


def test_markdown_marks_partial_runs(tmp_path):
    d = copy_run(tmp_path, "pass_run")
    doc = load_results(d)
    finish(doc, finished=doc["finished"], partial=True, duration_s=3.0)
    write_results_atomic(d, doc)
    render_all(d, formats=("md",))
    md = (d / "report.md").read_text(encoding="utf-8")
    assert "**PARTIAL RUN**" in md and "**INCONCLUSIVE**" in md


def test_md_escape_keeps_table_cells_intact():
    cell = md_escape("a | b\nc `d` *e* [f](g) $x$ <h> & i")
    assert "\n" not in cell
    unescaped_pipes = [i for i, ch in enumerate(cell) if ch == "|" and cell[i - 1] != "\\"]
    assert unescaped_pipes == []
    for raw in ("`d`", "*e*", "[f]", "$x$", "<h>", " & "):
        assert raw not in cell


# --------------------------------------------------------------------------- compare

def test_compare_finds_regressions_fixes_and_other_changes(tmp_path):
    old = copy_run(tmp_path, "fail_run", "old")
    new = copy_run(tmp_path, "fail_run", "new")
    set_verdicts(new, {
        "RH-SRV-4": ("pass", "released on time"),          # fail -> pass: fixed
        "RH-OUT-1": ("fail", "$OSI had 20 fields"),         # pass -> fail: regressed
        "RH-TIM-1": ("fail", "release 0.9 s late"),         # inconclusive -> fail: regressed
        "RH-ACK-2": ("inconclusive", "jitter too large"),   # fail -> inconclusive: fixed (improved)
        "RH-FRM-9": ("pass", "checked on real serial"),     # not-tested -> pass: gained coverage
        "RH-OSD-1": ("not-tested", "not selected"),         # pass -> not-tested: lost coverage
    })
    cmp = compare(load_results(old), load_results(new))
    assert [i["id"] for i in cmp["regressed"]] == ["RH-OUT-1", "RH-TIM-1"]
    assert sorted(i["id"] for i in cmp["fixed"]) == ["RH-ACK-2", "RH-SRV-4"]
    assert [i["id"] for i in cmp["gained"]] == ["RH-FRM-9"]
    assert [i["id"] for i in cmp["lost"]] == ["RH-OSD-1"]
    assert cmp["added"] == cmp["removed"] == cmp["changed"] == []
    assert cmp["unchanged"] == 76 - 6
    assert cmp["verdict"] == ("fail", "fail")
    srv = next(i for i in cmp["fixed"] if i["id"] == "RH-SRV-4")
    assert (srv["old"], srv["new"], srv["reason"]) == ("fail", "pass", "released on time")

    text = compare_text(cmp)
    assert "regressed: RH-OUT-1 PASS -> FAIL" in text and "fixed: RH-SRV-4 FAIL -> PASS" in text
    md = compare_markdown(cmp)
    assert "**Regressed**" in md and "**Fixed**" in md and "| RH-OUT-1 | PASS | FAIL |" in md
    html = compare_html(cmp)
    assert 'id="compare-regressed"' in html and 'id="compare-fixed"' in html


def test_compare_added_and_removed_clauses():
    """A clause judged before and gone now is lost coverage; one never judged is just removed."""
    old = {"verdict": "pass", "clauses": [{"id": "RH-SRV-3", "verdict": "pass", "reason": "a"},
                                          {"id": "RH-SRV-2", "verdict": "not-tested", "reason": "c"}]}
    new = {"verdict": "pass", "clauses": [{"id": "RH-SRV-4", "verdict": "pass", "reason": "b"}]}
    cmp = compare(old, new)
    assert [i["id"] for i in cmp["added"]] == ["RH-SRV-4"]
    assert [i["id"] for i in cmp["lost"]] == ["RH-SRV-3"]
    assert [i["id"] for i in cmp["removed"]] == ["RH-SRV-2"]
    assert cmp["regressed"] == cmp["fixed"] == []


def test_render_all_with_compare_puts_the_comparison_in_html_and_markdown(tmp_path):
    old = copy_run(tmp_path, "pass_run", "old")
    new = copy_run(tmp_path, "fail_run", "new")
    render_all(new, compare_dir=old)
    html = (new / "report.html").read_text(encoding="utf-8")
    md = (new / "report.md").read_text(encoding="utf-8")
    assert 'id="comparison"' in html and 'id="compare-regressed"' in html
    assert "### Compared with the earlier run: PASS → FAIL" in md
    assert digest_dir(old).combined in md and digest_dir(old).combined in html
    assert "| RH-SRV-4 | PASS | FAIL |" in md
    assert json.loads((new / "results.json").read_text(encoding="utf-8"))["verdict"] == "fail"
