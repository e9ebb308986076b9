"""``helmcheck certify vehicle --plan``: the estimate agrees with a real run; it opens and writes nothing.

The agreement test compares the plan with the suite's full certification of the emulator (every
case — lines the vehicle must discard, servo timers waited on and settled, park countdowns polled,
a mission run to its end — on ``helmcheck emulate`` at time scale 25), case by case.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import helmcheck
from helmcheck.cli import main as cli_main
from helmcheck.emulator.core import EmulatorCore
from helmcheck.emulator.missionfile import builtin_dir
from helmcheck.certify.vehicle.catalogue import select_cases
from helmcheck.certify.vehicle.plan import OPERATOR_REACTION_S
from helmcheck.certify.vehicle.session import frame
from helmcheck.certify.vehicle.virtual import VEHICLE_DELAY_S, VirtualLine
from helmcheck.profile import DEFAULT, EMULATOR_PROFILE
from helmcheck.reports.results import load_results

#: The emulator's own profile (it names the end mission RH-MSN-4's case waits for).
K = 20.0
EMU = str(Path(helmcheck.__file__).parent / EMULATOR_PROFILE)


def _plan(capsys, *args) -> dict:
    code = cli_main(["certify", "vehicle", "--plan", "--json", *args])
    out = capsys.readouterr().out
    assert code == 0, out
    return json.loads(out)


@pytest.mark.xdist_group("full-emulator-run")
def test_plan_is_within_20_percent_of_a_real_certification_case_by_case(full_emulator_run, capsys):
    """The suite's full certification of the emulator (every case, time scale 25,
    :func:`tests.conftest.full_emulator_run`) against the plan of the same command, told the
    latency the run measured (the emulator answers at once; the plan's default assumes a vehicle
    50 ms slower per line, which an exchange-heavy case, V-68, would count dozens of times): the
    cases that ran to their end, one total against the other."""
    root, code, _alive = full_emulator_run
    assert code in (0, 2)  # on a busy machine a timing clause may be INCONCLUSIVE: not the time taken
    real_run = load_results(root / "full")
    latency = real_run["settings"]["line_budget"]["latency_p50_s"]
    k = real_run["settings"]["time_scale"]
    plan = _plan(capsys, "--profile", str(root / "emu.toml"), "--time-scale", f"{k:g}", "--examples", "0",
                 "--latency", f"{max(latency, 0.001):g}")
    planned = {c["id"]: c for c in plan["cases"] if c["kind"] == "case"}
    assert all(c["outcome"] == "ran" for c in planned.values()), planned
    done = {c["id"]: c["wall_s"] for c in real_run["cases"] if c["verdict"] == "pass" and c["id"] in planned}
    assert set(planned) >= {c["id"] for c in real_run["cases"] if c["id"].startswith("V-")}, "a case ran unplanned"
    assert len(done) >= 0.8 * len(planned), f"too little ran to its end: {sorted(set(planned) - set(done))}"
    est, real = sum(planned[x]["wall_s"] for x in done), sum(done.values())
    assert abs(est - real) <= 0.2 * real, f"plan {est:.1f} s, real {real:.1f} s"


def test_plan_json_totals_are_the_sums_of_its_cases(capsys):
    plan = _plan(capsys, "--time-scale", "20")
    lines = plan["cases"]
    assert [x["id"] for x in lines if x["kind"] == "exploration"] == ["explore"]  # its own line
    assert plan["total_wall_s"] == pytest.approx(sum(x["wall_s"] for x in lines), abs=1e-6)
    assert plan["total_vehicle_s"] == pytest.approx(sum(x["vehicle_s"] for x in lines), abs=1e-6)
    assert plan["total_wall_s"] > 0 and plan["total_vehicle_s"] > plan["total_wall_s"]
    for x in lines:  # the vehicle's clock runs K times faster all along (RH-TIM-2)
        assert x["vehicle_s"] == pytest.approx(K * x["wall_s"], abs=0.01), x
    assert plan["time_scale"] == K and plan["assumptions"]


def test_plan_opens_no_port_and_writes_nothing(tmp_path, capsys, monkeypatch):
    import helmcheck.commands.ports as ports
    import helmcheck.line.transport as transport

    def refuse(*a, **kw):
        raise AssertionError("a port was opened")
    monkeypatch.setattr(ports, "open_port", refuse)
    monkeypatch.setattr(transport, "open_link", refuse)
    monkeypatch.chdir(tmp_path)
    code = cli_main(["certify", "vehicle", "--plan", "--port", "/dev/ttyUSB0", "--report-dir", "out",
                     "--wire-log", "wire.log", "--select", "RH-FRM-2"])
    out = capsys.readouterr().out
    assert code == 0
    assert "V-02" in out and "total" in out
    assert list(tmp_path.iterdir()) == []
    code = cli_main(["certify", "vehicle", "--plan", "--json", "--select", "RH-FRM-1"])  # no --port at all
    assert code == 0 and json.loads(capsys.readouterr().out)["cases"]
    assert list(tmp_path.iterdir()) == []


def test_plan_select_shrinks_it(capsys):
    full = _plan(capsys, "--time-scale", "20", "--examples", "0")
    some = _plan(capsys, "--time-scale", "20", "--examples", "0", "--select", "RH-SRV-*,RH-ACK-2")
    assert [x["id"] for x in some["cases"] if x["kind"] == "case"] == ["V-11", "V-25", "V-26", "V-27", "V-28", "V-65",
                                                                              "V-80", "V-81", "V-86", "V-90"]
    assert len(full["cases"]) > len(some["cases"])
    assert 0 < some["total_wall_s"] < full["total_wall_s"] / 5
    assert some["select"] == ["RH-SRV-*", "RH-ACK-2"]


def test_plan_text_shows_every_case_the_exploration_budget_and_the_total(capsys):
    assert cli_main(["certify", "vehicle", "--plan", "--time-scale", "20", "--hypothesis-profile", "patient"]) == 0
    out = capsys.readouterr().out
    rows = {ln.split()[0] for ln in out.splitlines() if ln[:2] in ("V-", "ex", "to", "li", "re")}
    assert {"link", "explore", "restore", "total"} <= rows
    assert {c.id for c in select_cases(None, DEFAULT)} < rows
    explore = next(ln for ln in out.splitlines() if ln.startswith("explore"))
    # the patient profile's budget is 600 s of vehicle time (900 s wall): 30 s at x20, as its own line
    assert explore.split()[-3] == "30.0", explore
    assert "V-57" in out and "not run" in out  # rh5 declares no $OXFLT: said, not timed
    assert "built-in" in out  # the missions it assumes


def test_plan_follows_the_time_scale(capsys):
    slow = _plan(capsys, "--time-scale", "1", "--examples", "0", "--select", "RH-SRV-4,RH-FRM-4")
    fast = _plan(capsys, "--time-scale", "20", "--examples", "0", "--select", "RH-SRV-4,RH-FRM-4")
    by = {k: {x["id"]: x for x in p["cases"]} for k, p in (("slow", slow), ("fast", fast))}
    # the servo timeout is the shortest the observer can time on the line at that time scale (the
    # line budget): each plan waits it out in vehicle seconds ÷ k; the ACK windows sat out do not scale
    for name, plan, k in (("slow", slow, 1.0), ("fast", fast, 20.0)):
        to = float(plan["line"]["durations"]["to"])
        assert by[name]["V-28"]["protocol_wait_s"] >= to / k * 0.9, (name, to, by[name]["V-28"])
    assert float(fast["line"]["durations"]["to"]) > float(slow["line"]["durations"]["to"])
    assert by["slow"]["V-04"]["wall_s"] == pytest.approx(by["fast"]["V-04"]["wall_s"], rel=0.15)
    assert by["fast"]["V-04"]["wall_s"] > 2 * DEFAULT.ack_window_s


def test_plan_uses_the_missions_given(tmp_path, capsys):
    """RH-MSN-4's case runs the end mission to its end: a longer park in it is a longer case."""
    (tmp_path / "short.mis").write_text((builtin_dir() / "short.mis").read_text().replace(
        "1.0      2.0       30", "1.0      2.0       330"))
    base = _plan(capsys, "--profile", EMU, "--time-scale", "20", "--examples", "0", "--select", "RH-MSN-4")
    given = _plan(capsys, "--profile", EMU, "--time-scale", "20", "--examples", "0", "--select", "RH-MSN-4",
                  "--missions", str(tmp_path))
    v47 = {p["missions"]["given"]: next(x for x in p["cases"] if x["id"] == "V-47") for p in (base, given)}
    assert v47[True]["vehicle_s"] - v47[False]["vehicle_s"] == pytest.approx(300.0, abs=15.0)
    assert str(tmp_path) in " ".join(given["assumptions"])


def test_plan_stands_in_for_a_mission_it_does_not_have(tmp_path, capsys):
    prof = tmp_path / "vehicle.toml"
    prof.write_text('mission = "survey-7.mis"\n')
    plan = _plan(capsys, "--profile", str(prof), "--time-scale", "20", "--examples", "0", "--select", "RH-SRV-4")
    assert plan["missions"]["stand_ins"] == {"survey-7.mis": "conformance.mis"}
    assert any("survey-7.mis" in a and "stands in" in a for a in plan["assumptions"])
    assert all(x["outcome"] == "ran" for x in plan["cases"])


def test_plan_times_the_violation_cases_whatever_raises_the_violation(tmp_path, capsys):
    """RH-SAF-5: with an operator, the plan waits for their trip; with a mission's own rule, for the
    rule (the built-in test mission stands in for the profile's violation_mission, with its time)."""
    (tmp_path / "op.toml").write_text('violation_trigger = "operator"\n')
    (tmp_path / "rule.toml").write_text('violation_trigger = "mission-rule"\nviolation_mission = "mot.mis"\n'
                                        'violation_after_s = 60\n')
    sel = ("--time-scale", "20", "--examples", "0", "--select", "RH-SAF-1")
    op = _plan(capsys, "--profile", str(tmp_path / "op.toml"), *sel)
    rule = _plan(capsys, "--profile", str(tmp_path / "rule.toml"), *sel)
    v58 = {name: next(x for x in p["cases"] if x["id"] == "V-58") for name, p in (("op", op), ("rule", rule))}
    assert v58["op"]["outcome"] == v58["rule"]["outcome"] == "ran", v58
    assert v58["op"]["wall_s"] > OPERATOR_REACTION_S + DEFAULT.lockout_s / 20  # the trip, then the lockout
    assert any("trips a sensor" in a for a in op["assumptions"])
    assert rule["missions"]["stand_ins"] == {"mot.mis": "conformance.mis (max_time_s 60)"}
    assert v58["rule"]["vehicle_s"] > 60 + DEFAULT.lockout_s  # the rule's 60 s, then the lockout


@pytest.mark.parametrize("argv, says", [
    (["--json"], "--json goes with --plan"),
    (["--missions", "x"], "--missions goes with --plan"),
    (["--plan", "--missions", "/nonexistent-dir"], "is not a directory"),
    (["--plan", "--select", "RH-NOPE-1"], "match no vehicle clause"),
    (["--plan", "--examples", "-1"], "--examples must be 0 or more"),
    (["--plan", "--time-scale", "0"], "--time-scale must be a positive number"),
])
def test_plan_usage_errors_are_64_with_one_line(argv, says, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert cli_main(["certify", "vehicle", *argv]) == 64
    err = capsys.readouterr().err
    assert says in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert list(tmp_path.iterdir()) == []


def test_virtual_line_carries_each_byte_at_the_baud():
    """A command reaches the vehicle after its transmit time; the answer reaches the tester after
    its own (10 bits a byte, RH-ACK-2's transmit time)."""
    profile = DEFAULT.replace(baud=9600)
    core = EmulatorCore(profile, start=0.0, time_scale=1.0, baud=9600)
    line = VirtualLine(core, 9600)
    cmd = frame("OSD,S")
    line.write_all(cmd)
    got, first = b"", None
    while b"$ACK" not in got:
        assert line.wait_readable(1.0)
        for ev in line.poll():
            first = line.clock() if first is None else first
            got += ev.data
    osi = got.split(b"\n")[0] + b"\n"
    assert first == pytest.approx((len(cmd) + len(osi)) * 10 / 9600 + VEHICLE_DELAY_S, abs=1e-6)
    assert line.clock() == pytest.approx((len(cmd) + len(got)) * 10 / 9600 + VEHICLE_DELAY_S, abs=1e-6)
    t = line.clock()
    assert not line.wait_readable(0.5)  # nothing more is due: the clock moves on, no real time passes
    assert line.clock() == pytest.approx(t + 0.5)
