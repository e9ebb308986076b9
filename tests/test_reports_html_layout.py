"""What the HTML report puts first and what it folds, and the content details a reader tripped on:
model coverage in numeric order with one sentence on what it means for the verdict, long case
lists folded (never dropped), and a restore's mission line that says what the vehicle reported.
The browser's view of the same page is ``tests/test_report_layout_browser.py``.
"""

from __future__ import annotations

import re

from hypothesis import given, strategies as st

from helmcheck.reports.html_coverage import natural_key
from helmcheck.reports.render import render_all
from helmcheck.reports.scope import scope_of
from tests.test_reports_html import render

NUMBERS = [0, 1, 2, 3, 9, 10, 11, 19, 20, 21, 90, 100]


def _coverage(doc, numbers=NUMBERS):
    rows = [f"row {n}: S/N/P OMS -> err 26" for n in numbers]
    doc["stats"] = {"explore": {"model_coverage": {
        "rows": {"covered": 30, "of": 91, "percent": 33.0, "uncovered": sorted(rows)},  # text order, as recorded
        "error_codes": {"covered": 22, "of": 32, "percent": 68.8, "uncovered": ["OMS err 26", "OMS err 20"]}}}}


def _certificate(doc):
    """The passing fixture with its NOT-TESTED clauses judged: every claimed clause judged."""
    for c in doc["clauses"]:
        if c["verdict"] == "not-tested":
            c.update(verdict="pass", reason="met")
    _coverage(doc)


@given(st.lists(st.integers(min_value=0, max_value=10**6), unique=True))
def test_natural_order_sorts_the_numbers_in_a_text_by_value(numbers):
    texts = [f"row {n}: S OMS -> A" for n in numbers]
    assert sorted(texts, key=natural_key) == [f"row {n}: S OMS -> A" for n in sorted(numbers)]


def test_uncovered_rows_are_listed_by_number(tmp_path):
    """RH-INT-1's exploration coverage: the rows it did not reach read row 2, row 3, … row 10."""
    _, _, page, doc = render(tmp_path, "pass_run", _coverage)
    text = page.text_of("coverage")
    listed = [int(n) for n in re.findall(r"row (\d+):", text)]
    assert listed == NUMBERS
    recorded = doc["stats"]["explore"]["model_coverage"]["rows"]["uncovered"]
    assert [int(re.match(r"row (\d+)", x).group(1)) for x in recorded] != NUMBERS  # recorded in text order


def test_model_coverage_says_what_it_means_for_a_certificate(tmp_path):
    d, _, page, doc = render(tmp_path, "pass_run", _certificate)
    assert scope_of(doc).certificate
    note = page.text_of("model-coverage-note")
    assert "not part of the verdict" in note and "certificate rests on the clause verdicts" in note
    assert "each of the 60 claimed clauses" in note
    assert "model-coverage-note" in [a.get("id") for a in page.find("p", inside="coverage")]
    assert "not part of the verdict" in page.text_of("coverage") and "30 of 91" in page.text_of("coverage")
    beside = page.text_of("coverage-beside")  # on the first page, beside the digest
    assert "30 of 91 transitions (33.0 %)" in beside and "22 of 32 error codes" in beside and note in beside
    assert "coverage-beside" in [a.get("id") for a in page.find("p", inside="certificate-page")]
    render_all(d, formats=("md",))
    md = (d / "report.md").read_text(encoding="utf-8")
    line = next(ln for ln in md.splitlines() if ln.startswith("Exploration's model coverage"))
    assert "30 of 91 transitions, 22 of 32 error codes" in line and "not part of the verdict" in line
    assert "certificate" in line


def test_model_coverage_beside_a_partial_run_claims_no_certificate(tmp_path):
    _, _, page, doc = render(tmp_path, "fail_run", _coverage)
    assert not scope_of(doc).certificate
    note = page.text_of("model-coverage-note")
    assert "not part of the verdict" in note and "certificate" not in note


def test_a_restore_mission_line_says_what_the_vehicle_reported(tmp_path):
    """Found in S with a mission named in its $OSI: the mission is loaded, not running."""
    def found_stopped(doc):
        doc["restore"] = {"found": {"mode": "S", "mission": "conformance.mis"}, "left": {"mode": "S", "note": None},
                          "settings": [], "attempted": True, "verified": True, "problems": [], "by_hand": []}

    _, _, page, _ = render(tmp_path, "pass_run", found_stopped)
    text = page.text_of("restore")
    assert "running" not in text
    assert "found in modeS" in text and "mission named in its first $OSIconformance.mis" in text


def test_long_case_lists_are_folded_not_dropped(tmp_path):
    cases = [f"V-{i:02d}" for i in range(1, 65)]

    def many(doc):
        doc["clauses"][0]["cases"] = cases
        doc["clauses"][1]["cases"] = cases[:7]

    _, raw, page, doc = render(tmp_path, "pass_run", many)
    first, second = (f"clause-{doc['clauses'][i]['id']}" for i in (0, 1))
    assert all(c in page.text_of(first) for c in cases)
    row = raw.split(f'id="{first}"', 1)[1].split("</tr>", 1)[0]
    shown, folded = row.split('<details class="more">', 1)
    assert re.findall(r"V-\d\d", shown) == cases[:6] and "+58 more" in folded
    assert re.findall(r"V-\d\d", folded) == cases[6:]
    assert "+1 more" not in raw.split(f'id="{second}"', 1)[1].split("</tr>", 1)[0]  # seven fit: none folded


def test_what_needs_attention_comes_first_and_the_rest_is_folded(tmp_path):
    _, raw, page, doc = render(tmp_path, "fail_run")
    assert raw.index('id="verdict"') < raw.index('id="findings"') < raw.index('id="matrix"')
    folds = {a["id"]: "open" in a for a in page.find("details", "fold")}
    assert folds == {"evidence": False, "implementation": False, "run": False, "profile": False,
                     "coverage": False, "timeline": True}
    attention = {c["id"] for c in doc["clauses"] if c["verdict"] in ("fail", "non-strict", "inconclusive")}
    for group in page.find("details", "group"):
        rows = {a["id"][len("clause-"):] for a in page.find("tr", "clause", inside=group["id"])}
        assert rows and ("open" in group) == bool(rows & attention), group["id"]


def test_every_fold_has_a_gist_and_the_page_has_its_contents(tmp_path):
    _, _, page, _ = render(tmp_path, "fail_run")
    for fold in page.find("details", "fold"):
        assert page.find("span", "gist", inside=fold["id"]), fold["id"]
    links = [a["href"] for a in page.find("a", inside="contents")]
    assert links[:2] == ["#findings", "#matrix"] and "#timeline" in links
    assert all(page.find(tag=None, inside=href[1:]) for href in links)
