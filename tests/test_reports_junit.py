"""JUnit XML, read back with junitparser: one testcase per clause and one ``run-verdict`` testcase,
verdicts mapped, digest kept."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from junitparser import Error, Failure, JUnitXml, Skipped

from helmcheck.clauses import catalogue
from helmcheck.reports.digest import digest_dir
from helmcheck.reports.render import render_all
from helmcheck.reports.results import finish, write_results_atomic

FIXTURES = Path(__file__).parent / "fixtures" / "reports"


def junit_of(tmp_path: Path, name: str, mutate=None):
    d = tmp_path / name
    shutil.copytree(FIXTURES / name, d)
    if mutate is not None:
        doc = json.loads((d / "results.json").read_text(encoding="utf-8"))
        mutate(doc)
        write_results_atomic(d, doc)
    render_all(d, formats=("junit",))
    xml = JUnitXml.fromfile(str(d / "junit.xml"))
    suites = list(xml) if isinstance(xml, JUnitXml) else [xml]
    cases = [case for suite in suites for case in suite if case.classname != "run"]  # the clauses
    doc = json.loads((d / "results.json").read_text(encoding="utf-8"))
    return d, suites, {case.name.split(" ", 1)[0]: case for case in cases}, cases, doc


def run_case(suites):
    [case] = [case for suite in suites for case in suite if case.classname == "run"]
    assert case.name == "run-verdict"
    return case


@pytest.mark.parametrize("name", ["pass_run", "fail_run", "backseat_run"])
def test_one_testcase_per_clause(tmp_path, name):
    _, suites, by_id, cases, doc = junit_of(tmp_path, name)
    assert len(cases) == len(doc["clauses"]) == len(by_id)
    assert set(by_id) == {c["id"] for c in doc["clauses"]}
    known = catalogue()
    for c in doc["clauses"]:
        case = by_id[c["id"]]
        assert case.classname.startswith(f"§{known[c['id']].section} ")
        assert len(case.name) > len(c["id"]) + 3  # id + short title


def test_verdicts_map_to_junit_results(tmp_path):
    _, suites, by_id, _, doc = junit_of(tmp_path, "fail_run")
    for c in doc["clauses"]:
        results = by_id[c["id"]].result
        if c["verdict"] == "fail":
            [res] = results
            assert isinstance(res, Failure) and res.message == c["reason"]
            for ev in c["evidence"]:
                assert ev["line"] in res.text
        elif c["verdict"] == "inconclusive":
            [res] = results
            assert isinstance(res, Error) and res.message == c["reason"]
        elif c["verdict"] == "not-tested":
            [res] = results
            assert isinstance(res, Skipped) and res.message == c["reason"]
        else:
            assert results == []
    suite = suites[0]
    counts = {v: sum(c["verdict"] == v for c in doc["clauses"]) for v in ("fail", "inconclusive", "not-tested")}
    # the run-verdict testcase counts too: the run is FAIL
    assert doc["verdict"] == "fail" and isinstance(run_case(suites).result[0], Failure)
    assert (suite.failures, suite.errors, suite.skipped) == (counts["fail"] + 1, counts["inconclusive"],
                                                             counts["not-tested"])


def test_hostile_reason_survives_as_text(tmp_path):
    _, _, by_id, _, doc = junit_of(tmp_path, "fail_run")
    [res] = by_id["RH-FRM-4"].result
    assert "<b>from A</b>" in res.message and "&" in res.message
    assert "<script>alert(1)</script>" in res.text


def test_non_strict_passes_with_a_note_or_fails_when_strict(tmp_path):
    _, _, by_id, _, _ = junit_of(tmp_path, "backseat_run")
    case = by_id["RH-BS-7"]
    assert case.result == [] and "NON-STRICT" in (case.system_out or "")

    def strict(doc):
        doc["settings"]["strict"] = True
        finish(doc, finished=doc["finished"], duration_s=doc["duration_s"])

    _, suites, by_id, _, doc = junit_of(tmp_path / "strict", "backseat_run", strict)
    [res] = by_id["RH-BS-7"].result
    assert isinstance(res, Failure) and res.type == "non-strict"
    assert suites[0].failures == 3  # two clauses and the run verdict


def test_digest_and_verdict_are_properties(tmp_path):
    d, suites, _, _, doc = junit_of(tmp_path, "fail_run")
    props = {p.name: p.value for p in suites[0].properties()}
    assert props["helmcheck.digest"] == digest_dir(d).combined
    assert props["helmcheck.verdict"] == doc["verdict"] == "fail"
    assert props["implementation.vehicle_name"] == doc["implementation"]["vehicle_name"]


def test_control_characters_do_not_break_the_xml(tmp_path):
    def nasty(doc):
        doc["clauses"][0]["verdict"] = "fail"
        doc["clauses"][0]["reason"] = "NUL\x00 and ESC\x1b in a reason"
        finish(doc, finished=doc["finished"], duration_s=doc["duration_s"])

    _, _, by_id, _, doc = junit_of(tmp_path, "pass_run", nasty)
    [res] = by_id[doc["clauses"][0]["id"]].result
    assert res.message == "NUL\\x00 and ESC\\x1b in a reason"
