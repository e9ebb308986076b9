"""Every range edge of §4–8 and §8b is reached by a numbered case, both sides of each bound.

The edge list is generated (:func:`helmcheck.certify.vehicle.edges.edge_list`: the command checks
of ``grammar/ranges.py``, the grammar's counts and widths, the model's state checks, the profile);
nothing here lists an edge by hand. What reaches an edge is read from the cases by running them:
the whole catalogue against the reference vehicle over a line in virtual time (the machinery of
``certify vehicle --plan``, seconds of CPU and no real waiting), each line tallied as the run
sends it (:class:`~helmcheck.certify.vehicle.edges.EdgeTally`) — on the emulator's own profile in
the water, on one whose every ``[D]`` bound is moved (the cases follow the profile, not the
defaults), and on the bench, where only the motion speeds above the bench ceiling stay unsent.
The shared full certification shows the same count in ``results.json`` and the reports.
"""

from __future__ import annotations

import dataclasses
from decimal import Decimal

import pytest
from hypothesis import given, strategies as st

from helmcheck.certify.vehicle.edges import STATE_CHECKED, edge_list, edge_values
from helmcheck.certify.vehicle.plan import estimate
from helmcheck.grammar import sentences as S
from helmcheck.grammar.ranges import COMMAND_CHECKS, Bound, range_errors
from helmcheck.model.handlers import CHECKS
from helmcheck.profile import BenchSafety, Profile, emulator_profile
from tests.strategies import COMMANDS

IN_WATER = emulator_profile().replace(bench_safety=BenchSafety(in_water=True))
#: Every [D] bound of §4–8b moved off its default (the emulator runs the same profile).
MOVED = IN_WATER.replace(timeout_range=(2, 60), max_depth_m=50.0, max_speed_kn=3.0, opk_max_distance_m=10000.0,
                         omw_clear_keywords=("Clr", "STOP"), waypoint_base=1, osd_letters="GCSPD")
#: The §4–8b profile keys that move no edge, and why (a new key must move edges or be named here).
NOT_BOUNDS = {
    "osd_letters": "every letter of GCSPYDTI is an edge, served (its data) or not (skipped, RH-OSD-2)",
    "gps_fix_depth_m": "the depth the GPS-fix edges (at the surface, under water) are told apart by",
    "time_scale": "a clock (RH-TIM-2), not a bound",
    "lockout_s": "a duration, judged by RH-TIM-1 at RH-SAF-1's deadline, not a value a command carries",
    "safety_action": "the vehicle's own setting at the surface (RH-SAF-4), not a bound",
    "on_station_m": "where a park starts counting (RH-RD-5, RH-PK-2): judged by V-37 and V-64's countdown",
    "mission_waypoints": "the test mission's length: $OJW's upper edge is read from the mission the model runs",
    "fault_injection": "how a violation is raised (RH-SAF-5)", "violation_trigger": "how a violation is raised",
    "violation_mission": "how a violation is raised", "violation_after_s": "how a violation is raised",
    "srp_mission": "a mission present on the vehicle", "end_mission": "a mission present on the vehicle",
    "mission": "a mission present on the vehicle",
}
#: §4–8b: the clause families whose profile keys are looked at.
_FAMILIES = ("§4", "RH-SRV", "RH-PRM", "RH-JW", "RH-PK", "RH-OMW", "RH-INT", "RH-MSN", "RH-POS", "RH-OSD", "RH-LOG",
             "RH-SET", "RH-DVL", "RH-SAF", "RH-TIM", "RH-RD", "§10")


def _plan(profile: Profile):
    plan = estimate(profile, 20.0, examples=0)
    stopped = {x.id: x.note for x in plan.lines if x.kind == "case" and x.outcome == "stopped"}
    assert not stopped, stopped  # every case ran to its end on the reference vehicle
    return plan


@pytest.mark.parametrize("profile", [IN_WATER, MOVED], ids=["emulator-in-water", "every-bound-moved"])
def test_every_edge_is_reached_by_a_numbered_case(profile):
    plan = _plan(profile)
    assert plan.edges["of"] == len(edge_list(profile)) > 150
    assert plan.edges["unreached"] == []
    outside = {e: c for e, c in plan.edge_cases.items() if not c.startswith("V-")}
    assert not outside, outside  # reached inside a numbered case, not by the link check
    assert {v for v in plan.verdicts.values()} <= {"pass", "not-tested"}, plan.verdicts


def test_on_the_bench_only_the_motion_speeds_above_its_ceiling_are_not_sent():
    plan = _plan(emulator_profile())
    unreached = {u["edge"]: u.get("why") for u in plan.edges["unreached"]}
    speeds = {e.id for e in edge_list(emulator_profile()) if e.field == "speed" and e.command in ("OMS", "OPK", "OMW")
              and e.bound.startswith("<=")}
    assert unreached == {e: "bench safety" for e in speeds}


def test_the_edges_follow_the_profile():
    """Each range key moved moves its edges: the list is the profile's, not the defaults'."""
    ids = {e.id for e in edge_list(MOVED)}
    assert "$OMS timeout >=2 out 1" in ids and "$OMS timeout <=60 out 61" in ids
    assert "$OMS depth <=50 in 50" in ids and "$OPK speed <=3 out 3.1" in ids
    assert "$OJW waypoint >=1 out 0" in ids and "$OPK distance <=10000 m out just outside" in ids
    assert "$OMW keyword {Clr,STOP} out CLEAR" in ids  # a keyword of the grammar the profile leaves out
    assert not any("clear" in i.lower() and " in " in i for i in ids if "keyword" in i)
    assert edge_values(MOVED)["to_under"] == "1" and edge_values(MOVED)["speed_out"] == "3.1"


def test_every_range_key_of_the_profile_has_edges_or_says_why_not():
    """A §4–8b key of the profile either moves the edge list when changed or is named in
    :data:`NOT_BOUNDS` with the reason: a new bound cannot be forgotten."""
    base = {e.id for e in edge_list(IN_WATER)}
    unexplained = []
    for f in dataclasses.fields(Profile):
        clause = f.metadata.get("clause", "")
        if f.metadata.get("not_a_key") or not any(fam in clause for fam in _FAMILIES):
            continue
        moved = _moved(f.name, getattr(IN_WATER, f.name))
        changes = moved is not None and {e.id for e in edge_list(IN_WATER.replace(**{f.name: moved}))} != base
        if changes and f.name in NOT_BOUNDS:
            unexplained.append(f"{f.name} has edges but is listed as no bound")
        if not changes and f.name not in NOT_BOUNDS:
            unexplained.append(f"{f.name} ({clause}) moves no edge")
    assert not unexplained, unexplained


def _moved(name: str, value):
    if name == "timeout_range":
        return (value[0] + 1, value[1] - 1)
    if name == "omw_clear_keywords":
        return tuple(value[:-1])
    if name == "osd_letters":
        return value[:-1]
    if name == "commands":
        return tuple(value[:-1])
    if isinstance(value, bool):
        return not value
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return type(value)(value / 2 if value else 1)
    if name == "depth_unit":
        return "ft"
    return None


def test_every_command_check_has_both_sides_of_each_bound():
    """The rows of ``grammar/ranges.py`` become edges: each end of a range inside and out; a set of
    values each inside and its neighbours out; a mission name inside the directory and out."""
    edges = edge_list(IN_WATER)
    for cls, rows in COMMAND_CHECKS.items():
        for row in rows:
            mine = [e for e in edges if e.command == cls.ID and e.field == row.field and e.kind != "count"]
            if isinstance(row, Bound):
                lo, hi = row.limits(IN_WATER)
                ends = [(">=", lo)] + ([("<", hi)] if hi is not None else [])
                for op, _ in ends:
                    assert {e.side for e in mine if e.bound.startswith(op)} == {"in", "out"}, (cls, row.field, op)
            else:
                assert {e.side for e in mine} == {"in", "out"}, (cls, row.field)


def test_the_model_checks_with_a_bound_have_state_edges():
    """The model's checks after the table (``handlers.CHECKS``): those with a bound have edges on
    both sides; the others look files up (err 1, 3, 17, 31)."""
    assert set(CHECKS) - set(STATE_CHECKED) == {"OMLOAD", "OMSTART"}
    edges = edge_list(IN_WATER)
    for cmd in STATE_CHECKED:
        assert {e.side for e in edges if e.command == cmd and e.kind == "state"} == {"in", "out"}, cmd
    assert {e.side for e in edges if e.command == "OPOS" and e.kind == "state"} == {"fix", "no-fix"}


@given(st.sampled_from(sorted(COMMAND_CHECKS, key=lambda c: c.__name__)).flatmap(lambda c: COMMANDS[c]),
       st.data())
def test_every_range_problem_is_of_a_field_with_edges(sentence, data):
    """Whatever value a command carries, a range problem ``grammar/ranges.py`` finds in it is of a
    field the edge list has edges for (a check made outside the rows would have none)."""
    edges = {(e.command, e.field) for e in edge_list(IN_WATER)}
    field = data.draw(st.sampled_from([f for f in sentence.field_names()
                                       if isinstance(getattr(sentence, f), (Decimal, int)) and
                                       not isinstance(getattr(sentence, f), bool)] or [None]))
    if field is not None:
        sentence = dataclasses.replace(sentence, **{field: getattr(sentence, field) * -7 + 999})
    for err in range_errors(sentence, IN_WATER):
        if isinstance(sentence, S.ORWSET) and sentence.access == "R":
            continue  # a read that carries a state: its form, not a bound
        assert (sentence.ID, err.field) in edges, (sentence, err)


@pytest.mark.xdist_group("full-emulator-run")
def test_the_full_certification_reports_the_edges_it_reached(full_emulator_run):
    """The shared full certification of the emulator (on the bench): every edge reached but the
    motion speeds above the bench ceiling, in ``results.json`` and both reports."""
    import json

    root, _code, _alive = full_emulator_run
    r = json.loads((root / "full" / "results.json").read_text())
    e = r["stats"]["edges"]
    assert e["of"] == len(edge_list(emulator_profile())) and e["reached"] == e["of"] - 6
    assert {u.get("why") for u in e["unreached"]} == {"bench safety"}
    line = f"Range edges reached (§4–8b, both sides of every bound): {e['reached']} of {e['of']}"
    assert line in (root / "full" / "report.md").read_text()
    assert "Range edges reached" in (root / "full" / "report.html").read_text()
