"""The pytest plugin (``helmcheck/pytest_plugin.py``) run by pytest itself (pytester).

Each test runs a real ``pytest`` in a subprocess against a real implementation: the emulator
started by ``--helm-vehicle-exec``, a faulty vehicle served on a pty by this process
(``tests/faulty_vehicles``), example backseats started by ``--helm-backseat-exec``. It checks the
collected item names, their outcomes, the failure text, ``-k``, ``-x``, the JUnit XML, and that
without an option the plugin does nothing.
"""

from __future__ import annotations

import shlex
import subprocess
import sys
import xml.etree.ElementTree as ET
from importlib.metadata import entry_points
from pathlib import Path

import pytest

from helmcheck.clauses import backseat_clauses, vehicle_clauses
from tests.faulty_vehicles import MUTANTS, make_core, serve

pytest_plugins = ["pytester"]

HERE = Path(__file__).resolve().parent
PY = shlex.quote(sys.executable)
GOOD = shlex.quote(str(HERE / "backseats" / "good_backseat.py"))
FAULTY = shlex.quote(str(HERE / "backseats" / "faulty_backseat.py"))
EMU_TOML = ('fault_injection = "oxflt"\nbaud = 115200\ntime_scale = 25.0\n'
            'end_mission = "short.mis"\nsrp_mission = "srp.mis"\n')  # the emulator's missions
VEHICLE_IDS = [c.id for c in vehicle_clauses()]
BACKSEAT_IDS = [c.id for c in backseat_clauses()]


def _junit(path: Path) -> dict[str, dict]:
    """testcase name -> {classname, outcome, message, text, properties}."""
    out = {}
    for case in ET.parse(path).getroot().iter("testcase"):
        outcome, message, text = "passed", "", ""
        for tag in ("failure", "error", "skipped"):
            el = case.find(tag)
            if el is not None:
                outcome, message, text = tag, el.get("message", ""), el.text or ""
        props = {p.get("name"): p.get("value") for p in case.iter("property")}
        out[case.get("name")] = {"classname": case.get("classname"), "outcome": outcome, "message": message,
                                 "text": text, "properties": props}
    return out


def _run(pytester: pytest.Pytester, *args: str):
    return pytester.runpytest_subprocess("-p", "no:cacheprovider", "--junitxml=junit.xml", *args, timeout=240)


# --------------------------------------------------------------------------- dormant

def test_registered_as_a_pytest11_entry_point():
    eps = {ep.name: ep.value for ep in entry_points(group="pytest11")}
    assert eps.get("helmcheck") == "helmcheck.pytest_plugin"


def test_importing_the_plugin_loads_no_protocol_code():
    code = ("import sys, helmcheck.pytest_plugin\n"
            "heavy = [m for m in sys.modules if m.split('.')[0] in ('lark', 'serial', 'hypothesis', 'rich')\n"
            "         or (m.startswith('helmcheck.') and m != 'helmcheck.pytest_plugin')]\n"
            "print(sorted(heavy))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


def test_without_its_options_the_plugin_does_nothing(pytester):
    pytester.makepyfile("def test_one():\n    assert True\n")
    result = pytester.runpytest_subprocess("-p", "no:cacheprovider", "-v")
    result.assert_outcomes(passed=1)
    assert "helmcheck" not in result.stdout.str().split("plugins:", 1)[1].split("\n", 1)[1]
    assert not (pytester.path / "helmcheck-reports").exists()
    assert "--helm-vehicle=URL" in pytester.runpytest_subprocess("--help").stdout.str()


def test_collect_only_lists_one_item_per_clause_and_runs_nothing(pytester):
    pytester.makepyfile("def test_mine():\n    pass\n")
    result = pytester.runpytest_subprocess("-p", "no:cacheprovider", "--collect-only", "-q",
                                           "--helm-vehicle", "/dev/pts/doesnotexist")
    ids = [line for line in result.stdout.lines if "::" in line]
    assert ids == ["test_collect_only_lists_one_item_per_clause_and_runs_nothing.py::test_mine",
                   *[f"helmcheck.vehicle::{cid}" for cid in VEHICLE_IDS], "helmcheck.vehicle::run-verdict"]
    result = pytester.runpytest_subprocess("-p", "no:cacheprovider", "--collect-only", "-q",
                                           "--helm-backseat-exec", f"{PY} {GOOD}")
    ids = [line for line in result.stdout.lines if line.startswith("helmcheck.")]
    assert ids == [*[f"helmcheck.backseat::{cid}" for cid in BACKSEAT_IDS], "helmcheck.backseat::run-verdict"]
    assert not (pytester.path / "helmcheck-reports").exists()


@pytest.mark.parametrize("args, message", [
    (("--helm-vehicle", "/dev/pts/1", "--helm-backseat-exec", "true"), "give one of --helm-vehicle"),
    (("--helm-vehicle", "/dev/pts/1", "--helm-profile", "missing.toml"), "--helm-profile"),
    (("--helm-backseat-exec", "no-such-backseat-xyz"), "--helm-backseat-exec: no-such-backseat-xyz: command not found"),
    (("--helm-backseat-exec", "true", "--helm-scenario", "party"), "--helm-scenario: unknown party"),
])
def test_bad_options_are_usage_errors(pytester, args, message):
    result = pytester.runpytest_subprocess("-p", "no:cacheprovider", *args)
    assert result.ret == pytest.ExitCode.USAGE_ERROR
    assert message in result.stderr.str() and "Traceback" not in result.stderr.str()


# --------------------------------------------------------------------------- against the emulator

def test_emulator_with_k_selection_passes_and_is_certified_once(pytester):
    """``-k`` deselects items and shortens the certification; the vehicle is started once."""
    count = pytester.path / "starts.txt"
    cmd = (f"sh -c 'echo started >> {shlex.quote(str(count))}; exec {PY} -m helmcheck emulate --port \"$1\" "
           f"--time-scale 25 --baud 115200' sh {{port}}")
    result = _run(pytester, "--helm-vehicle-exec", cmd, "--helm-time-scale", "25", "--helm-examples", "0",
                  "-k", "RH-FRM or RH-ACK-1 or run-verdict", "-v")
    selected = [cid for cid in VEHICLE_IDS if cid.startswith("RH-FRM") or cid == "RH-ACK-1"]
    result.assert_outcomes(passed=len(selected) + 1, deselected=len(VEHICLE_IDS) - len(selected))
    assert count.read_text() == "started\n"
    cases = _junit(pytester.path / "junit.xml")
    assert list(cases) == [*selected, "run-verdict"]
    assert {c["classname"] for c in cases.values()} == {"helmcheck.vehicle"}
    assert all(c["outcome"] == "passed" for c in cases.values())
    assert cases["RH-FRM-2"]["properties"] == {
        "report": str(pytester.path / "helmcheck-reports" / "vehicle" / "report.html"),
        "verdict": "pass", "level": "MUST"}
    results = (pytester.path / "helmcheck-reports" / "vehicle" / "results.json").read_text()
    assert '"RH-SRV-4"' in results and "not selected (--select)" in results  # only the selection was run
    assert "helmcheck vehicle" in result.stdout.str() and "PASS: All" in result.stdout.str()


def _served_mutant(name: str, k: float = 25.0):
    """The mutant served at ``k``, the time scale ``EMU_TOML`` declares (a vehicle at another
    scale stops the run at its clock check)."""
    m = next(m for m in MUTANTS if m.name == name)
    assert k in m.time_scales, (name, m.time_scales)
    return serve(lambda start: make_core(m, k, start))


def test_faulty_vehicle_fails_its_clause_with_reason_and_evidence(pytester):
    pytester.makefile(".toml", emu=EMU_TOML)
    with _served_mutant("servo-timeout-ignored") as port:
        result = _run(pytester, f"--helm-vehicle={port}", "--helm-profile", "emu.toml", "--helm-examples", "0",
                      "-k", "RH-SRV-1 or RH-SRV-4 or run-verdict")
    result.assert_outcomes(passed=1, failed=2, deselected=len(VEHICLE_IDS) - 2)
    cases = _junit(pytester.path / "junit.xml")
    assert [n for n, c in cases.items() if c["outcome"] == "failure"] == ["RH-SRV-4", "run-verdict"]
    srv4 = cases["RH-SRV-4"]
    assert srv4["message"].startswith("FAIL: ") and srv4["properties"]["verdict"] == "fail"
    assert srv4["text"].startswith("RH-SRV-4 FAIL (MUST): ")
    assert "evidence (t, direction, line):" in srv4["text"] and " <  line " in srv4["text"] and ": $OSI," in srv4["text"]
    assert "report: " in srv4["text"]
    assert cases["run-verdict"]["message"] == "FAIL: 1 clause(s) failed: RH-SRV-4."
    out = result.stdout.str()
    assert "FAILED helmcheck.vehicle::RH-SRV-4 - FAIL: " in out and "V-28: " in out
    assert "RH-SRV-4 FAIL (MUST):" in out  # the failure section shows the same text


def test_x_stops_at_the_first_failing_clause(pytester):
    pytester.makefile(".toml", emu=EMU_TOML)
    with _served_mutant("servo-timeout-ignored") as port:
        result = _run(pytester, f"--helm-vehicle={port}", "--helm-profile", "emu.toml", "--helm-examples", "0",
                      "-k", "RH-SRV-1 or RH-SRV-4 or RH-PRM-1 or run-verdict", "-x")
    result.assert_outcomes(passed=1, failed=1, deselected=len(VEHICLE_IDS) - 3)
    assert list(_junit(pytester.path / "junit.xml")) == ["RH-SRV-1", "RH-SRV-4"]  # RH-PRM-1 and the run: not run


def test_an_unreachable_vehicle_is_inconclusive_never_green(pytester):
    args = (f"--helm-vehicle={pytester.path / 'no-such-port'}", "-k", "RH-FRM-1 or RH-ACK-1 or run-verdict")
    result = _run(pytester, *args)
    result.assert_outcomes(failed=3, deselected=len(VEHICLE_IDS) - 2)
    cases = _junit(pytester.path / "junit.xml")
    assert all(c["message"].startswith("INCONCLUSIVE: ") for c in cases.values())
    assert "cannot open" in cases["RH-FRM-1"]["message"]
    assert result.ret == pytest.ExitCode.TESTS_FAILED
    result = _run(pytester, *args, "--helm-inconclusive", "skip")
    result.assert_outcomes(skipped=3, deselected=len(VEHICLE_IDS) - 2)
    assert _junit(pytester.path / "junit.xml")["RH-ACK-1"]["message"].startswith("INCONCLUSIVE: ")


# --------------------------------------------------------------------------- backseats

BS_ARGS = ("--helm-time-scale", "5", "--helm-duration", "4", "--helm-scenario", "nominal")


def test_non_strict_backseat_passes_with_a_warning_and_fails_under_strict(pytester):
    cmd = f"{PY} {FAULTY} {{port}} --fault lowercase-hex --time-scale {{time_scale}}"
    result = _run(pytester, "--helm-backseat-exec", cmd, *BS_ARGS, "-W", "always")
    cases = _junit(pytester.path / "junit.xml")
    assert list(cases) == [*BACKSEAT_IDS, "run-verdict"]
    assert {c["classname"] for c in cases.values()} == {"helmcheck.backseat"}
    assert cases["RH-BS-7"]["outcome"] == "passed" and cases["RH-BS-7"]["properties"]["verdict"] == "non-strict"
    assert "HelmcheckNonStrict: RH-BS-7 NON-STRICT (SHOULD)" in result.stdout.str()
    assert result.ret == pytest.ExitCode.OK
    skipped = [n for n, c in cases.items() if c["outcome"] == "skipped"]
    assert all(cases[n]["message"].startswith("NOT-TESTED: ") for n in skipped)

    result = _run(pytester, "--helm-backseat-exec", cmd, *BS_ARGS, "--helm-strict")
    cases = _junit(pytester.path / "junit.xml")
    assert cases["RH-BS-7"]["outcome"] == "failure" and cases["RH-BS-7"]["message"].startswith("NON-STRICT: ")
    assert cases["run-verdict"]["outcome"] == "failure"
    assert result.ret == pytest.ExitCode.TESTS_FAILED


def test_backseat_that_crashes_fails_the_run_item_with_its_last_output(pytester):
    cmd = f"{PY} {GOOD} {{port}} --time-scale {{time_scale}} --crash-after 1"
    result = _run(pytester, "--helm-backseat-exec", cmd, *BS_ARGS)
    cases = _junit(pytester.path / "junit.xml")
    assert cases["run-verdict"]["outcome"] == "failure"
    assert cases["run-verdict"]["message"].startswith("FAIL: The backseat under test exited with code 3")
    assert "good_backseat: crashing on purpose after 1 s" in cases["run-verdict"]["text"]
    assert all(cases[cid]["outcome"] == "skipped" and "the backseat exited with code 3" in cases[cid]["message"]
               for cid in BACKSEAT_IDS)
    assert result.ret == pytest.ExitCode.TESTS_FAILED
