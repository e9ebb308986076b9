"""The ``process`` object of ``results.json``: the verdict rule for an implementation under test
that ended early, the schema, the builder, and how the reports show it."""

from __future__ import annotations

import copy

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from helmcheck.reports.render import render_all
from helmcheck.reports.results import (
    CLAUSE_VERDICTS, add_clause, add_process, finish, new_results, run_verdict, validate, write_results_atomic,
)
from helmcheck.reports.verdicts import describe_process

HOSTILE = "<script>alert(1)</script>"


def _process(**changes) -> dict:
    p = {"command": "python3 bs.py /dev/pts/4", "pid": 4242, "exit_code": 3, "signal": None,
         "ended_at_s": 2.1, "ended_early": True, "output_tail": ["starting", "Traceback: boom"]}
    p.update(changes)
    return p


def _run(process: dict | None, verdicts=("pass", "pass", "not-tested")) -> dict:
    res = new_results("backseat", started="2026-11-22T10:00:00Z")
    for cid, v in zip(("RH-BS-1", "RH-BS-2", "RH-BS-3"), verdicts):
        add_clause(res, cid, v, f"reason {v}")
    if process is not None:
        add_process(res, process, not_run=["RH-BS-2"], reason="the backseat exited with code 3 at 2.1 s, before …")
    finish(res, finished="2026-11-22T10:00:05Z")
    return res


@settings(derandomize=True)
@given(st.lists(st.sampled_from(CLAUSE_VERDICTS), max_size=8), st.booleans(), st.booleans())
def test_an_implementation_that_ended_early_always_fails_the_run(verdicts, strict, partial):
    """However good its clauses, a run whose implementation died is FAIL; otherwise unchanged."""
    assert run_verdict(verdicts, strict=strict, partial=partial, process_failed=True) == "fail"
    assert run_verdict(verdicts, strict=strict, partial=partial, process_failed=False) == \
        run_verdict(verdicts, strict=strict, partial=partial)


def test_unknown_verdict_words_are_still_refused():
    with pytest.raises(ValueError):
        run_verdict(["pass", "great"], process_failed=True)


def test_ended_early_makes_unrun_clauses_not_tested_and_keeps_judged_ones():
    res = _run(_process())
    by = {c["id"]: c for c in res["clauses"]}
    assert by["RH-BS-1"]["verdict"] == "pass"  # judged before the end: kept
    assert by["RH-BS-2"]["verdict"] == "not-tested" and by["RH-BS-2"]["reason"].startswith("the backseat exited")
    assert res["verdict"] == "fail"
    assert res["verdict_reason"].startswith("The backseat under test exited with code 3 at 2.1 s, before the run's end")
    assert "“Traceback: boom”" in res["verdict_reason"]
    assert validate(res) == []


def test_stopped_at_the_end_changes_nothing():
    res = _run(_process(ended_early=False, exit_code=None, signal="SIGTERM"))
    assert res["verdict"] == "pass" and {c["verdict"] for c in res["clauses"]} == {"pass", "not-tested"}
    assert validate(res) == []
    assert "when helmcheck stopped it" in describe_process(res["process"], "backseat")


def test_the_validator_holds_the_verdict_to_the_rule():
    res = _run(_process())
    forged = copy.deepcopy(res)
    forged["verdict"] = "pass"
    errors = validate(forged)
    assert errors and errors[0].startswith("verdict:") and "ended early" in errors[0]
    innocent = copy.deepcopy(res)
    innocent["process"]["ended_early"] = False
    assert any(e.startswith("verdict:") for e in validate(innocent))


@pytest.mark.parametrize("change, path", [
    ({"exit_code": "3"}, "process.exit_code"),
    ({"signal": "KILL"}, "process.signal"),
    ({"ended_early": "yes"}, "process.ended_early"),
    ({"output_tail": ["ok", 7]}, "process.output_tail[1]"),
    ({"command": None}, "process.command"),
    ({"ended_at_s": float("inf")}, "process.ended_at_s"),
])
def test_a_bad_process_object_is_named_by_its_path(change, path):
    res = _run(_process(ended_early=False, **{k: v for k, v in change.items() if k != "ended_early"}))
    res["process"].update(change)
    errors = validate(res)
    assert any(e.startswith(path + ":") for e in errors), errors


def test_missing_keys_are_named():
    res = _run(_process(ended_early=False))
    del res["process"]["signal"]
    assert "process.signal: missing (use null when unknown)" in validate(res)
    res["process"] = ["not", "an", "object"]
    assert any(e.startswith("process: expected an object") for e in validate(res))


def test_reports_show_the_process_and_escape_its_output(tmp_path):
    res = _run(_process(output_tail=["fine", HOSTILE], command=f"bs {HOSTILE}"))
    write_results_atomic(tmp_path, res)
    (tmp_path / "wire.log").write_text("# helmcheck wire-log 1\n")
    (tmp_path / "backseat.stderr.log").write_text(HOSTILE + "\n")
    render_all(tmp_path)
    html = (tmp_path / "report.html").read_text()
    assert 'id="process-end"' in html and "exited with code 3" in html
    assert HOSTILE not in html and "&lt;script&gt;alert(1)&lt;/script&gt;" in html
    assert '<a href="backseat.stderr.log">' in html and "backseat.stdout.log" not in html
    md = (tmp_path / "report.md").read_text()
    assert "Process under test:" in md and "<script>" not in md.replace("`bs <script>alert(1)</script>`", "")
    assert "exited with code 3" in md


def test_junit_has_a_process_testcase_that_fails_when_it_ended_early(tmp_path):
    import xml.etree.ElementTree as ET

    for early in (True, False):
        d = tmp_path / str(early)
        write_results_atomic(d, _run(_process(ended_early=early)))
        render_all(d, formats=("junit",))
        suite = ET.parse(d / "junit.xml").getroot().find("testsuite")
        case = [c for c in suite.iter("testcase") if c.get("classname") == "process"]
        assert len(case) == 1 and case[0].get("name") == "backseat under test"
        failure = case[0].find("failure")
        assert (failure is not None) is early
        # 3 clauses, the process and the run verdict (FAIL when it ended early: a second failure)
        assert suite.get("tests") == "5" and suite.get("failures") == ("2" if early else "0")
        if early:
            assert failure.get("type") == "process-ended" and "exited with code 3" in failure.get("message")
            assert failure.text.endswith("Traceback: boom")
