"""results.json schema 1: builder, validator, loader, atomic write, verdict rules."""

from __future__ import annotations

import copy
import json
import os
import shutil
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from helmcheck.reports import results as R
from helmcheck.reports.results import (
    CLAUSE_VERDICTS, ReportError, add_clause, add_event, add_mode, add_replay, exit_code, finish,
    load_results, new_results, overall_verdict, run_verdict, validate, write_results_atomic,
)

FIXTURES = Path(__file__).parent / "fixtures" / "reports"


def fixture_doc(name: str) -> dict:
    return json.loads((FIXTURES / name / "results.json").read_text(encoding="utf-8"))


# --------------------------------------------------------------------------- builder

def test_new_results_is_valid_and_claims_nothing_until_finished():
    res = new_results("vehicle", command="helmcheck certify vehicle", settings={"seed": 7})
    assert validate(res) == []
    assert res["partial"] is True and res["verdict"] == "inconclusive"
    assert res["seed"] == 7
    with pytest.raises(ValueError):
        new_results("frontseat")


@pytest.mark.parametrize("name, verdict", [("pass_run", "pass"), ("fail_run", "fail"),
                                           ("backseat_run", "non-strict")])
def test_fixtures_are_valid(name, verdict):
    doc = fixture_doc(name)
    assert validate(doc) == []
    assert doc["verdict"] == verdict


def test_finish_computes_verdict_and_names_failed_clauses():
    res = new_results("vehicle", started="2026-11-21T19:50:00Z")
    add_clause(res, "RH-SRV-3", "pass", "ok")
    add_clause(res, "RH-SRV-4", "fail", "late release")
    add_clause(res, "RH-FRM-9", "not-tested", "pty")
    assert finish(res, finished="2026-11-21T19:51:00Z") == "fail"
    assert res["partial"] is False and res["duration_s"] == 60.0
    assert "RH-SRV-4" in res["verdict_reason"] and "RH-SRV-3" not in res["verdict_reason"]
    assert validate(res) == []


def test_add_clause_takes_level_from_profile_and_replaces_by_id():
    res = new_results("backseat")
    add_clause(res, "RH-BS-7", "pass", "first")
    add_clause(res, "RH-BS-7", "non-strict", "second", offending_count=2)
    assert [c["reason"] for c in res["clauses"]] == ["second"]
    assert res["clauses"][0]["level"] == "SHOULD"
    with pytest.raises(KeyError, match="RH-NOPE-1"):
        add_clause(res, "RH-NOPE-1", "pass", "x")


def test_add_replay_links_clause_and_add_mode_skips_repeats():
    res = new_results("vehicle")
    add_clause(res, "RH-SRV-4", "fail", "late")
    add_replay(res, "RH-SRV-4", [{"send": "$OMSTOP,0*06"}, {"wait": 1.0}])
    assert res["clauses"][0]["replay"] == "replays/RH-SRV-4.json"
    add_mode(res, 0.0, "S")
    add_mode(res, 1.0, "S")
    add_mode(res, 2.0, "N")
    assert [p["mode"] for p in res["timeline"]] == ["S", "N"]
    add_event(res, 1.0, "lockout", "$OXFLT,Sle")
    with pytest.raises(ValueError):
        add_event(res, 1.0, "explosion", "x")
    finish(res)
    assert validate(res) == []


def test_partial_run_never_certifies_a_pass_but_keeps_a_fail():
    res = new_results("vehicle")
    add_clause(res, "RH-SRV-3", "pass", "ok")
    assert finish(res, partial=True) == "inconclusive"
    assert "interrupted" in res["verdict_reason"]
    add_clause(res, "RH-SRV-4", "fail", "late")
    assert finish(res, partial=True) == "fail"


def test_a_run_that_judged_nothing_is_inconclusive():
    res = new_results("vehicle")
    add_clause(res, "RH-FRM-9", "not-tested", "pty")
    assert finish(res) == "inconclusive"


def test_strict_setting_turns_should_misses_into_fail():
    doc = fixture_doc("backseat_run")
    doc["settings"]["strict"] = True
    assert any(e.startswith("verdict:") for e in validate(doc))
    assert finish(doc, finished=doc["finished"], duration_s=doc["duration_s"]) == "fail"
    assert "Strict" in doc["verdict_reason"]
    assert validate(doc) == []


# --------------------------------------------------------------------------- validator

def test_validate_names_the_json_path_of_each_error():
    doc = fixture_doc("fail_run")
    del doc["role"]
    doc["schema"] = 2
    doc["clauses"][2]["verdict"] = "passed"
    doc["clauses"][0]["evidence"] = [{"t": 1.0, "dir": "?", "line": "x"}]
    doc["clauses"][5]["offending_count"] = -1
    doc["timeline"][2]["t"] = 0.5
    doc["events"][0]["kind"] = "boom"
    doc["replays"][0]["steps"][0]["wait"] = 1.0  # now has send and wait
    doc["wire_log"] = "../../etc/passwd"
    doc["started"] = "yesterday"
    doc["partial"] = "no"
    errors = validate(doc)
    expected_prefixes = ["role: missing", "schema: expected 1", "clauses[2].verdict: 'passed'",
                         "clauses[0].evidence[0].dir:", "clauses[5].offending_count:",
                         "timeline[2].t:", "events[0].kind: 'boom'", "replays[0].steps[0]: needs exactly one",
                         "wire_log:", "started:", "partial: expected a boolean"]
    for prefix in expected_prefixes:
        assert any(e.startswith(prefix) for e in errors), (prefix, errors)


def test_validate_rejects_a_non_object():
    assert validate([1, 2]) == ["$: expected an object, got an array"]


def test_validate_checks_clauses_against_the_profile():
    doc = fixture_doc("pass_run")
    doc["clauses"][0]["id"] = "RH-ZZZ-1"
    doc["clauses"][1]["level"] = "SHOULD"  # RH-FRM-2 is a MUST
    doc["clauses"][3]["id"] = doc["clauses"][4]["id"]
    doc["clauses"][6]["replay"] = "replays/nowhere.json"
    errors = validate(doc)
    assert any(e.startswith("clauses[0].id:") and "not a clause" in e for e in errors)
    assert any(e.startswith("clauses[1].level:") for e in errors)
    assert any(e.startswith("clauses[4].id:") and "more than once" in e for e in errors)
    assert any(e.startswith("clauses[6].replay:") for e in errors)


def test_validate_rejects_a_verdict_that_does_not_follow():
    doc = fixture_doc("fail_run")
    doc["verdict"] = "pass"
    errors = validate(doc)
    assert len(errors) == 1 and errors[0].startswith("verdict:") and "'fail'" in errors[0]


def test_validate_rejects_booleans_and_non_finite_numbers_where_numbers_belong():
    doc = fixture_doc("pass_run")
    doc["duration_s"] = True
    doc["timeline"][0]["t"] = float("nan")
    errors = validate(doc)
    assert any(e.startswith("duration_s:") for e in errors)
    assert any(e.startswith("timeline[0].t:") for e in errors)


# --------------------------------------------------------------------------- loading

def test_load_results_reads_a_fixture():
    assert load_results(FIXTURES / "pass_run")["verdict"] == "pass"


@pytest.mark.parametrize("content, words", [
    (b"{not json", "not valid JSON"),
    (b"", "not valid JSON"),
    (b"\xff\xfe{}", "not UTF-8"),
    (b'{"schema": NaN}', "not valid JSON"),
    (b"[" * 100_000, "not valid JSON"),
    (b'{"schema": 1}', "not a valid helmcheck results document"),
])
def test_load_results_turns_bad_files_into_one_line_report_errors(tmp_path, content, words):
    (tmp_path / "results.json").write_bytes(content)
    with pytest.raises(ReportError) as info:
        load_results(tmp_path)
    message = str(info.value)
    assert str(tmp_path / "results.json") in message
    assert words in message
    assert "\n" not in message


def test_load_results_missing_file_and_directory(tmp_path):
    with pytest.raises(ReportError, match="results.json: no such file"):
        load_results(tmp_path)
    with pytest.raises(ReportError, match="no such results directory"):
        load_results(tmp_path / "absent")


def test_load_results_schema_errors_are_kept(tmp_path):
    doc = fixture_doc("pass_run")
    doc["clauses"][0]["verdict"] = "great"
    (tmp_path / "results.json").write_text(json.dumps(doc), encoding="utf-8")
    with pytest.raises(ReportError) as info:
        load_results(tmp_path)
    assert any(e.startswith("clauses[0].verdict") for e in info.value.errors)
    assert load_results(tmp_path, check=False)["clauses"][0]["verdict"] == "great"


# --------------------------------------------------------------------------- atomic write

def test_write_results_atomic_round_trips_and_leaves_no_temp_file(tmp_path):
    doc = fixture_doc("fail_run")
    path = write_results_atomic(tmp_path / "run", doc)
    assert sorted(os.listdir(tmp_path / "run")) == ["results.json"]
    assert load_results(path.parent) == doc
    write_results_atomic(tmp_path / "run", doc)  # overwrite
    assert sorted(os.listdir(tmp_path / "run")) == ["results.json"]


def test_write_results_atomic_failure_keeps_the_old_file(tmp_path, monkeypatch):
    doc = fixture_doc("pass_run")
    write_results_atomic(tmp_path, doc)
    before = (tmp_path / "results.json").read_bytes()
    changed = copy.deepcopy(doc)
    changed["command"] = "something else"

    def broken_replace(src, dst):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "replace", broken_replace)
    with pytest.raises(ReportError, match="No space left"):
        write_results_atomic(tmp_path, changed)
    assert (tmp_path / "results.json").read_bytes() == before
    assert sorted(os.listdir(tmp_path)) == ["results.json"]


def test_write_results_atomic_refuses_an_invalid_document(tmp_path):
    doc = fixture_doc("pass_run")
    doc["verdict"] = "excellent"
    with pytest.raises(ReportError) as info:
        write_results_atomic(tmp_path, doc)
    assert any(e.startswith("verdict:") for e in info.value.errors)
    assert not (tmp_path / "results.json").exists()


def test_fixture_copy_in_tmp_is_loadable(tmp_path):
    shutil.copytree(FIXTURES / "backseat_run", tmp_path / "b")
    assert load_results(tmp_path / "b" / "results.json")["role"] == "backseat"


# --------------------------------------------------------------------------- verdict rules

def _oracle(verdicts: list[str], strict: bool) -> str:
    judged = [v for v in verdicts if v != "not-tested"]
    if "fail" in judged or (strict and "non-strict" in judged):
        return "fail"
    if "inconclusive" in judged:
        return "inconclusive"
    if "non-strict" in judged:
        return "non-strict"
    return "pass"


verdict_lists = st.lists(st.sampled_from(CLAUSE_VERDICTS), max_size=30)


@given(verdict_lists, st.booleans())
def test_overall_verdict_follows_the_precedence_rule(verdicts, strict):
    assert overall_verdict(verdicts, strict) == _oracle(verdicts, strict)


@given(verdict_lists, st.booleans(), st.randoms())
def test_overall_verdict_ignores_order_and_not_tested(verdicts, strict, rnd):
    shuffled = list(verdicts)
    rnd.shuffle(shuffled)
    base = overall_verdict(verdicts, strict)
    assert overall_verdict(shuffled, strict) == base
    assert overall_verdict(verdicts + ["not-tested"] * 3, strict) == base
    assert overall_verdict(verdicts + ["pass"], strict) == base
    assert overall_verdict(verdicts + ["fail"], strict) == "fail"


@given(verdict_lists, st.booleans(), st.booleans())
def test_run_verdict_never_passes_an_interrupted_or_empty_run(verdicts, strict, partial):
    v = run_verdict(verdicts, strict=strict, partial=partial)
    if partial or all(x == "not-tested" for x in verdicts):
        assert v in ("fail", "inconclusive")
    else:
        assert v == overall_verdict(verdicts, strict)


@given(verdict_lists, st.booleans())
def test_exit_code_mapping(verdicts, strict):
    v = overall_verdict(verdicts, False)
    expected = {"pass": 0, "non-strict": 1 if strict else 0, "fail": 1, "inconclusive": 2}[v]
    assert exit_code(v, strict) == expected


def test_exit_code_table_and_unknown_words():
    assert [exit_code(v) for v in R.VERDICTS] == [0, 0, 1, 2]
    assert [exit_code(v, True) for v in R.VERDICTS] == [0, 1, 1, 2]
    with pytest.raises(ValueError):
        exit_code("not-tested")
    with pytest.raises(ValueError):
        overall_verdict(["pass", "PASS"])
