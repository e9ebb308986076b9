"""Every choice the reference profile leaves a conforming vehicle PASSes (``docs/freedoms.md``).

The judge must not have learnt the reference emulator's own choices where the profile leaves
room. ``helmcheck emulate`` spans those freedoms as settings (the ``[emulator]`` table of its
profile file, ``--set KEY=VALUE``; :mod:`helmcheck.emulator.freedoms`), and:

* the sans-IO tests check each setting does what it says on :class:`EmulatorCore`, and that the
  defaults are the reference emulator's behaviour;
* the property test draws a combination of conforming choices, starts ``helmcheck emulate`` with
  them on a real pty, certifies the clauses those choices touch at time scale 20 or 5 (the
  scales the suite uses for vehicles it did not write) and asserts exit code 0 with no clause
  FAIL or INCONCLUSIVE. ``make test`` runs three explicit examples (:data:`EXAMPLES`), ``make
  matrix`` all of them and two derandomised draws, ``make fuzz`` many random ones;
* the bound tests put a timer just past RH-TIM-1's ``max(0.5 s, 5 %)`` (FAIL) and just inside
  (PASS), so the settings are shown to reach the bound and the judge to hold it.
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from helmcheck.emulator.core import EmulatorCore, plant_params
from helmcheck.emulator.freedoms import (DEFAULT_SETTINGS, EmulatorSettings, SettingsError,
                                                     SkewedTimers, nonconforming, parse_assignment,
                                                     settings_from_dict)
from helmcheck.emulator.missionfile import DirectoryCatalog, builtin_dir
from helmcheck.emulator.plant import PlantParams
from helmcheck.emulator.process import EmulatorProcess, frame
from helmcheck.certify.vehicle.runner import Options, certify
from helmcheck.grammar import Framer, Line
from helmcheck.grammar import sentences as s
from helmcheck.profile import load_emulator_table, load_profile
from tests.faulty_vehicles import EMU_PROFILE
from tests.test_emulator_core import replies as sentences  # every line decoded

# ============================================================================ sans-IO


def core(st: EmulatorSettings = DEFAULT_SETTINGS, k: float = 10.0, baud: int = 0) -> EmulatorCore:
    return EmulatorCore(EMU_PROFILE, DirectoryCatalog([builtin_dir()]), time_scale=k, baud=baud, settings=st)


def osi_of(data: bytes) -> s.OSI:
    got = [x for x in sentences(data) if isinstance(x, s.OSI)]
    assert len(got) == 1, data
    return got[0]


def follow(c: EmulatorCore, now: float, end: float) -> bytes:
    """Run the core's wakeups up to wall time ``end`` like the I/O loop; the bytes it sent."""
    out = b""
    for _ in range(100_000):
        w = c.next_wakeup()
        if w is None or w > end:
            return out + c.tick(end)
        now = max(now, w)
        out += c.tick(now)
    raise AssertionError("too many wakeups")


def test_the_defaults_are_the_reference_emulator():
    assert plant_params(DEFAULT_SETTINGS) == PlantParams()
    assert DEFAULT_SETTINGS.is_default and DEFAULT_SETTINGS.assignments() == []
    assert nonconforming(DEFAULT_SETTINGS, EMU_PROFILE) == []
    c = core()
    assert type(c.model.timers) is not SkewedTimers and c.tick_v == 0 and not c._shaper.active
    a, b = core(), EmulatorCore(EMU_PROFILE, DirectoryCatalog([builtin_dir()]), time_scale=10.0, baud=0)
    for t, body in ((0.0, "OSD,G,C,S,P,Y,D,T,I"), (0.1, "OMSTART,0,0,0,0,conformance.mis,"),
                    (0.2, "OMS,90,2,20,1,10"), (3.0, "OSD,S,G")):
        assert a.feed(frame(body), t) == b.feed(frame(body), t)


def test_settings_come_from_the_profile_table_and_set_flags(tmp_path):
    """The ``[emulator]`` table rides in the profile file: the tester's loader accepts the file and
    never sees the table; ``--set`` overrides it; unknown or bad settings are refused by name."""
    prof = tmp_path / "p.toml"
    prof.write_text('baud = 115200\n[emulator]\nreply_delay_s = [0.1, 0.4]\ncontrol_tick_s = 0.25\n'
                    'decimals = { lat = 6, speed = 1 }\nfactory_settings = { Sle = [0, "30"] }\n')
    p = load_profile(prof)
    assert p.baud == 115200 and not hasattr(p, "emulator")
    got = settings_from_dict(load_emulator_table(prof))
    assert got.reply_delay_s == (0.1, 0.4) and got.control_tick_s == 0.25
    assert got.decimals_map() == {"lat": 6, "speed": 1} and got.factory_settings == (("Sle", 0, ("30",)),)
    got = settings_from_dict(parse_assignment("decimals.lon=7"), base=got)
    got = settings_from_dict(parse_assignment("pacing=burst"), base=got)
    assert got.decimals_map() == {"lat": 6, "lon": 7, "speed": 1} and got.pacing == "burst"
    assert settings_from_dict(parse_assignment("reply_delay_s=0.3")).reply_delay_s == (0.3, 0.3)
    back = DEFAULT_SETTINGS
    for a in got.assignments():
        back = settings_from_dict(parse_assignment(a), base=back)
    assert back == got
    for bad in ("bogus=1", "pacing=fast", "timer_factor=0", "reply_delay_s=[0.5, 0.1]", "decimals.nope=2",
                "factory_settings.SafetyAction=[1]", "osi_reserved=[\"a\"]", "gprmc_time_decimals=4"):
        with pytest.raises(SettingsError):
            settings_from_dict(parse_assignment(bad))


def test_helmcheck_emulate_reads_the_table_and_warns_outside_the_bounds(tmp_path):
    """``helmcheck emulate --profile`` takes the ``[emulator]`` table, ``--set`` overrides it, and a
    setting past a bound is obeyed with a warning naming the clause."""
    from helmcheck.emulator.process import HelmClient

    prof = tmp_path / "p.toml"
    prof.write_text('[emulator]\nosi_reserved = ["a", "b", "c"]\ndecimals = { lat = 3 }\n')
    with EmulatorProcess(["--profile", str(prof), "--set", "decimals.lat=4", "--set", "timer_factor=1.2"],
                         time_scale=10.0, baud=0) as emu:
        link = emu.connect()
        try:
            o = HelmClient(link).osi()
        finally:
            link.close()
        time.sleep(0.2)
        err = emu.stderr_text()
    assert o.reserved == ("a", "b", "c") and str(o.lat) == "41.5200"
    assert "warning: not a conforming vehicle" in err and "RH-TIM-1" in err, err


def test_the_bounds_are_named_where_a_setting_leaves_them():
    assert not nonconforming(EmulatorSettings(reply_delay_s=(0.0, 0.9), timer_factor=1.04,
                                              control_tick_s=0.05), EMU_PROFILE)
    assert "RH-ACK-2" in " ".join(nonconforming(EmulatorSettings(reply_delay_s=(0.0, 1.0)), EMU_PROFILE))
    for late in (EmulatorSettings(timer_factor=1.06), EmulatorSettings(timer_offset_s=0.6),
                 EmulatorSettings(timer_offset_s=0.3, control_tick_s=0.3), EmulatorSettings(timer_factor=0.94)):
        assert "RH-TIM-1" in " ".join(nonconforming(late, EMU_PROFILE)), late


def test_a_reply_delay_processes_each_command_later_in_arrival_order():
    """RH-ACK-2, RH-ACK-6, RH-RD-15: nothing is answered before its delay; the OMS timeout starts
    when its ACK goes out, not when the command arrived."""
    c = core(EmulatorSettings(reply_delay_s=(0.3, 0.3)), k=10.0)
    c.feed(frame("OMSTART,0,0,0,0,conformance.mis,"), 0.0)
    assert follow(c, 0.0, 0.29) == b""
    assert [x.type for x in sentences(follow(c, 0.29, 0.31)) if isinstance(x, s.ACK)] == [3]
    assert c.feed(frame("OMS,90,2,20,1,10") + frame("OSD,S"), 1.0) == b""
    out = sentences(follow(c, 1.0, 1.31))
    assert [type(x).__name__ for x in out] == ["ACK", "OSI", "ACK"] and out[1].mode == "A"
    assert c.model.timers.deadline("remote") == pytest.approx(23.0, abs=0.5)  # 10 s from the ACK at v = 13


def test_oxflt_raises_its_violation_at_once():
    c = core(EmulatorSettings(reply_delay_s=(0.5, 0.5)))
    c.feed(frame("OMSTART,0,0,0,0,conformance.mis,"), 0.0)
    follow(c, 0.0, 1.0)
    c.feed(frame("OXFLT,Sle"), 1.0)
    assert c.lockout_active


def test_a_burst_loop_processes_at_its_turns_and_writes_at_once():
    c = core(EmulatorSettings(pacing="burst", burst_interval_s=0.25), baud=115200)
    assert c.feed(frame("OSD,G,C,S,P,Y,D,T,I"), 0.1) == b""
    out = follow(c, 0.1, 0.26)
    assert len(sentences(out)) == 9  # all at once at the loop's turn, 0.25 s
    assert c.pacer.baud == 0


def test_a_control_tick_lands_timer_expiries_on_a_tick():
    c = core(EmulatorSettings(control_tick_s=0.5), k=1.0)
    c.feed(frame("OMSTART,0,0,0,0,conformance.mis,"), 0.0)
    c.feed(frame("OMS,90,2,20,1,1"), 0.1)  # 1 s timeout from 0.1 s: due 1.1 s, seen at the 1.5 s tick
    follow(c, 0.1, 1.45)
    assert c.model.mode == "A"
    follow(c, 1.45, 1.5)
    assert c.model.mode == "N"
    assert c.v == pytest.approx(1.5)


def test_skewed_timers_last_longer_and_count_down_to_zero():
    t = SkewedTimers(1.04, 0.2)
    t.arm("opk", 10.0, 60.0)
    assert t.deadline("opk") == pytest.approx(10.0 + 62.6)
    assert t.remaining("opk", 10.0) == pytest.approx(60.0)
    assert t.remaining("opk", 10.0 + 62.6) == pytest.approx(0.0)
    assert type(t.copy()) is SkewedTimers and t.copy().deadline("opk") == t.deadline("opk")
    c = core(EmulatorSettings(timer_factor=0.96))
    c.feed(frame("OMSTART,0,0,0,0,conformance.mis,"), 0.0)
    c.feed(frame("OMS,90,2,20,1,10"), 0.1)
    assert c.model.timers.deadline("remote") == pytest.approx(1.0 + 9.6)


def test_reports_spelt_the_vehicle_s_own_way():
    """Decimals, field 7 with no target (RH-RD-5), fields 19–21, $C extras (RH-FRM-8), the $GPRMC
    time, and the factory settings (RH-SET-2)."""
    st_ = EmulatorSettings(decimals=(("depth", 0), ("lat", 5), ("speed", 1), ("true_heading", 0)),
                           idle_distance="last", osi_reserved=("7", "", "x"), compass_extra=("Mx", "A"),
                           gprmc_time_decimals=0, factory_settings=(("Sle", 0, ("30",)),))
    c = core(st_)
    o = osi_of(c.feed(frame("OSD,S"), 0.0))
    assert str(o.lat) == "41.52000" and str(o.depth) == "0" and str(o.speed) == "0.0"
    assert o.reserved == ("7", "", "x") and o.distance == 0
    comp = next(x for x in sentences(c.feed(frame("OSD,C,G"), 0.1)) if isinstance(x, s.Compass))
    assert [k for k, _ in comp.extra] == ["Mx", "A"]
    gp = next(x for x in sentences(c.feed(frame("OSD,G"), 0.2)) if isinstance(x, s.GPRMC))
    assert "." not in gp.time
    ack = [x for x in sentences(c.feed(frame("ORWSET,Sle,R"), 0.3)) if isinstance(x, s.ACK)][0]
    assert ack.extra == ("Sle", "2", "0", "30")
    c.feed(frame("OMSTART,0,0,0,0,conformance.mis,"), 0.4)
    follow(c, 0.4, 3.0)
    c.feed(frame("OMSTOP,0"), 3.0)
    o = osi_of(c.feed(frame("OSD,S"), 3.1))
    assert o.mode == "S" and o.distance > 0  # the distance to the last target, the vehicle's choice


# ============================================================================ certification

#: Clauses each group of freedoms touches (certified when the group is drawn).
TOUCHES = {
    "line": ["RH-ACK-1", "RH-ACK-2", "RH-ACK-5", "RH-ACK-6", "RH-OSD-1", "RH-SRV-3", "RH-SRV-4", "RH-PK-1"],
    "clock": ["RH-SRV-4", "RH-PRM-4", "RH-TIM-1", "RH-SAF-1", "RH-PK-3", "RH-SAF-4"],
    "plant": ["RH-PK-2", "RH-OMW-4", "RH-SAF-3", "RH-SAF-4", "RH-MSN-2"],
    "report": ["RH-OUT-1", "RH-OUT-2", "RH-OUT-3", "RH-FRM-8", "RH-PRM-1", "RH-PRM-4", "RH-MSN-3",
               "RH-SET-1", "RH-SET-2", "RH-PK-2"],
    "start": ["RH-MSN-2", "RH-POS-2", "RH-OMW-4"],
}
#: Certified whatever is drawn (none: a finding on any clause is booked even when it is not selected).
ALWAYS: list[str] = []
#: Wall seconds the selection may take in the plan (virtual time, on the reference vehicle, plus the
#: drawn reply latency on every line sent), so that an example, with the emulator's start, the
#: clock check and a slow vehicle's own cost, stays under ~40 s.
BUDGET_S = 14.0
SCALES = (20.0, 5.0)
#: Under ``make fuzz`` (20 × the examples), examples stop being run after this many wall seconds.
FUZZ_BUDGET_S = 1800.0
PROFILE = os.environ.get("HYPOTHESIS_PROFILE", "default")
_STARTED: list[float] = []  #: when this test's first example ran


def plan_cost(select: list[str], k: float, latency: float) -> float:
    """Planned wall seconds of certifying ``select`` at ``k`` (virtual time, on the reference
    vehicle), plus ``latency`` for every line the tester sends (a vehicle that answers later)."""
    from helmcheck.certify.vehicle.plan import estimate

    lines = [0]
    feed = EmulatorCore.feed

    def counting(self, data, now):
        lines[0] += data.count(b"\n")
        return feed(self, data, now)

    EmulatorCore.feed = counting  # type: ignore[method-assign]
    try:
        wall = estimate(EMU_PROFILE.replace(time_scale=k), k, select=select, examples=0).total_wall_s
    finally:
        EmulatorCore.feed = feed  # type: ignore[method-assign]
    return wall + lines[0] * latency


def selection(groups: list[str], k: float, latency: float = 0.0) -> list[str]:
    """The clauses ``groups`` touch (names starting ``RH-`` are clauses, taken as they are), cheapest
    first, within :data:`BUDGET_S` of :func:`plan_cost` at ``k``."""
    if all(g.startswith("RH-") for g in groups):
        return sorted(set(groups))
    want = list(dict.fromkeys(ALWAYS + [c for g in groups for c in TOUCHES[g]]))
    cost = {c: plan_cost([c], k, latency) for c in want}
    chosen: list[str] = []
    for c in sorted(want, key=lambda c: (cost[c], want.index(c))):
        if plan_cost(chosen + [c], k, latency) <= BUDGET_S:
            chosen.append(c)
    return sorted(chosen)


@st.composite
def choices(draw) -> tuple:
    """(``--set`` assignments, time scale, groups): conforming choices of one to three groups."""
    k = draw(st.sampled_from(SCALES))
    groups = draw(st.lists(st.sampled_from(sorted(TOUCHES)), min_size=1, max_size=3, unique=True))
    sets: list[str] = []
    if "line" in groups:
        loop = 0.0
        if draw(st.booleans()):
            loop = draw(st.sampled_from([0.0, 0.05, 0.1]))
            sets += ["pacing=burst", f"burst_interval_s={loop}"]
        if draw(st.booleans()):  # the ACK window less the serial loop and the replies' line time
            lo = draw(st.floats(0.0, 0.84 - loop))
            hi = draw(st.floats(lo, 0.84 - loop))
            sets += [f"reply_delay_s=[{lo:.3f}, {hi:.3f}]", f"seed={draw(st.integers(0, 9))}"]
    if "clock" in groups:
        # every duration d >= 1 s ends between d(1 + f) + o and that + tick, within max(0.5, 5 % d)
        # (0.45 s kept for the worst of 1 and 10 s, where it binds): the tick, the rate, then the
        # offsets left (certify_with checks the result with nonconforming())
        tick = draw(st.sampled_from([0.0, 0.05, 0.1, 0.2, 0.25]))
        f = round(draw(st.floats(-0.04, 0.04)), 4)
        o = draw(st.floats(-0.45 - min(f, 10 * f), 0.45 - tick - max(f, 10 * f)))
        sets += [f"control_tick_s={tick}", f"timer_factor={1 + f:.4f}", f"timer_offset_s={o:.3f}"]
    if "plant" in groups:
        sets += [f"speed_factor={draw(st.floats(0.6, 1.4)):.3f}",
                 f"turn_rate_dps={draw(st.floats(5.0, 60.0)):.1f}",
                 f"dive_pitch_deg={draw(st.floats(8.0, 45.0)):.1f}",
                 f"ascent_mps={draw(st.floats(0.05, 2.0)):.3f}"]
    if "report" in groups:
        for name, lo, hi in (("lat", 5, 10), ("lon", 5, 10), ("distance", 0, 4), ("speed", 0, 4),
                             ("depth", 0, 4), ("true_heading", 0, 3), ("altimeter", 0, 3),
                             ("battery", 0, 2), ("remaining_time", 1, 6), ("heading", 0, 3)):
            if draw(st.booleans()):
                sets.append(f"decimals.{name}={draw(st.integers(lo, hi))}")
        sets.append(f"idle_distance={draw(st.sampled_from(['zero', 'last']))}")
        res = draw(st.lists(st.sampled_from(["", "0", "0.0", "False", "True", "x1"]), min_size=3, max_size=3))
        sets.append("osi_reserved=" + json.dumps(res))
        sets.append("compass_extra=" + json.dumps(draw(st.lists(st.sampled_from(["Mx", "My", "Mz", "A"]),
                                                                 max_size=3, unique=True))))
        sets.append(f"gprmc_time_decimals={draw(st.integers(0, 3))}")
        if draw(st.booleans()):
            sets.append('factory_settings.Sle=[0, "30"]')
        sets.append(f"start_battery_pct={draw(st.floats(15.0, 100.0)):.1f}")
    if "start" in groups:
        sets += [f"start_lat={41.52 + draw(st.floats(-0.0015, 0.0015)):.6f}",
                 f"start_lon={-71.32 + draw(st.floats(-0.002, 0.002)):.6f}",
                 f"start_heading={draw(st.floats(0.0, 359.9)):.1f}",
                 f"declination={draw(st.floats(-20.0, 20.0)):.1f}",
                 f"water_depth_m={draw(st.floats(8.0, 200.0)):.1f}"]
    return sets, k, sorted(groups)


def settings_of(sets: list[str]) -> EmulatorSettings:
    st_ = DEFAULT_SETTINGS
    for a in sets:
        st_ = settings_from_dict(parse_assignment(a), base=st_)
    return st_


def certify_with(sets: list[str], k: float, groups: list[str], out: Path) -> dict:
    """``helmcheck emulate --set …`` on a pty, certified on the clauses ``groups`` touch; the run
    is then re-judged offline from its wire log (live and offline must agree, as for every run)."""
    try:
        from helmcheck.commands.verify_cmd import verify_run
    except ImportError:  # pragma: no cover - where it lived before
        from helmcheck.reports.verify import verify_run

    st_ = settings_of(sets)
    assert not nonconforming(st_, EMU_PROFILE), (sets, nonconforming(st_, EMU_PROFILE))
    args = [x for a in sets for x in ("--set", a)]
    lo, hi = st_.reply_delay_s
    select = selection(groups, k, latency=(lo + hi) / 2 + (st_.burst_interval_s / 2 if st_.pacing == "burst" else 0))
    t0 = time.monotonic()
    with EmulatorProcess(args, time_scale=k, baud=EMU_PROFILE.baud) as emu:
        got = certify(Options(port=emu.port, profile=EMU_PROFILE.replace(time_scale=k), time_scale=k,
                              report_dir=out, select=select, examples=0, progress=False,
                              render=False, seed=1))
    agree = verify_run(out)
    return {"exit": got.exit_code, "verdict": got.verdict, "select": select, "wall_s": round(time.monotonic() - t0, 1),
            "agree": agree.ok, "disagree": [str(f) for f in agree.findings[:4]],
            "bad": {c["id"]: f'{c["verdict"]}: {c["reason"]}' for c in got.results["clauses"]
                    if c["verdict"] != "pass" and (c["verdict"] != "not-tested" or c["id"] in select)}}




#: Findings already reported (docs/freedoms.md, "Findings") that a random draw may still meet: (id,
#: clause or None, words of the reason, the choices it needs). None is open: F3–F7 (the cases'
#: durations on a slow line, motion after a release, ``$OXFLT`` with a latency, RH-SAF-3 under
#: water, a takeover's timeout widened by an unseen waypoint) were fixed with the line budget.
#: An INCONCLUSIVE that names the observer's own uncertainty fails the test like any other: the
#: tester chooses durations it can time on the line it measured (:mod:`helmcheck.judge.linebudget`).
KNOWN: tuple = ()


class FindingWarning(UserWarning):
    """A draw met a finding already reported (:data:`KNOWN`)."""


def judge(got: dict, st_: EmulatorSettings, strict: bool) -> dict:
    """The clauses of ``got`` that fail the test: everything but PASS (and NOT-TESTED outside the
    selection; every selected clause can be exercised on the emulator), but (for a random draw) a
    finding already reported."""
    import warnings

    left = {}
    for cid, why in got["bad"].items():
        known = next((fid for fid, c, words, needs in KNOWN
                      if (c is None or c == cid) and words in why and needs(st_)), None)
        if known is not None and not strict:
            warnings.warn(FindingWarning(f"{known}: {cid}: {why[:200]}"))
            continue
        left[cid] = why
    return left


#: Each group of freedoms with choices far from the reference emulator's (strict: no finding
#: excused), and the findings fixed since, kept as regressions. ``make test`` runs those of
#: :data:`IN_MAKE_TEST` (one per kind of freedom: the line's pacing, the clock, the plant; the line at
#: its bound is tests/test_slow_line.py's), each a test of its own; ``make matrix`` (``HELMCHECK_MATRIX=1``) and ``make fuzz``
#: all of them and the draws.
EXAMPLES = {
    "pacing": (["pacing=burst", "burst_interval_s=0.1"], 20.0, ["RH-ACK-2", "RH-ACK-5", "RH-ACK-6", "RH-OSD-1"], True),
    "clock": (["control_tick_s=0.2", "timer_factor=0.975", "timer_offset_s=-0.1"], 5.0, ["RH-SRV-4", "RH-PRM-4"],
              True),
    "plant": (["speed_factor=0.7", "turn_rate_dps=6", "dive_pitch_deg=12", "ascent_mps=2.0"], 20.0,
              ["RH-PK-2", "RH-OMW-4", "RH-SAF-3", "RH-SAF-4"], True),
    "report": (["decimals.lat=5", "decimals.lon=5", "decimals.distance=0", "decimals.speed=0", "decimals.depth=0",
                "decimals.true_heading=0", "decimals.battery=0", "idle_distance=last", 'osi_reserved=["x", "", "7"]',
                'compass_extra=["Mx", "My", "Mz"]', "gprmc_time_decimals=0", 'factory_settings.Sle=[0, "30"]'],
               20.0, ["RH-OUT-1", "RH-OUT-2", "RH-FRM-8", "RH-PRM-4", "RH-MSN-3", "RH-SET-2", "RH-PK-2"], True),
    "start": (["start_lat=41.5215", "start_lon=-71.3185", "start_heading=270", "declination=10",
               "water_depth_m=8"], 20.0, ["RH-MSN-2", "RH-POS-2", "RH-OMW-4"], True),
    # F1, fixed: a lockout the vehicle ends late within RH-TIM-1's tolerance (answered from the state before it)
    "F1-late-lockout": (["timer_factor=1.04"], 5.0, ["RH-SAF-1"], True),
    # F2, fixed: an $OPK accepted while the vehicle moved on from the last report waits for on station
    "F2-opk-moved-on": (["reply_delay_s=0.2"], 20.0, ["RH-PK-1"], True),
    # F3, fixed: the cases' durations against a slow line (the line budget chooses them)
    "F3-slow-line": (["reply_delay_s=0.2"], 20.0, ["RH-SRV-3"], True),
    # F7, fixed: a waypoint reached unseen just before a takeover no longer widens the takeover's timeout
    "F7-unseen-waypoint": (["reply_delay_s=0.3", "start_lat=41.52125"], 20.0, ["RH-SRV-4"], True),
    # the line at its bound: replies 0.6 s after each line, timers late by what the tick leaves (strict)
    "line-bound": (["reply_delay_s=0.6", "control_tick_s=0.2", "timer_offset_s=0.3"], 20.0,
                   ["RH-SRV-3", "RH-SRV-4", "RH-PRM-4", "RH-SAF-1", "RH-TIM-1"], True),
}
IN_MAKE_TEST = ("pacing", "clock", "plant")
MATRIX = os.environ.get("HELMCHECK_MATRIX") == "1"


def _passes_whatever_it_chooses(tmp_path_factory, case) -> None:
    sets, k, groups, strict = case if len(case) == 4 else (*case, False)
    got = certify_with(sets, k, groups, tmp_path_factory.mktemp("freedoms") / "r")
    left = judge(got, settings_of(sets), strict)
    assert got["agree"], (sets, got["disagree"])
    assert not left, (sets, k, got["select"], left)
    assert got["exit"] == 0 or got["bad"], (sets, k, got)  # a run inconclusive for an excused reason only


@pytest.mark.parametrize("name", [n if n in IN_MAKE_TEST or MATRIX or PROFILE == "fuzz" else
                                  pytest.param(n, marks=pytest.mark.skip(reason="make matrix's (HELMCHECK_MATRIX=1)"))
                                  for n in EXAMPLES])
def test_a_conforming_vehicle_passes_these_choices(tmp_path_factory, name):
    """The explicit choices of :data:`EXAMPLES`: certified on the clauses they touch, nothing but PASS."""
    _passes_whatever_it_chooses(tmp_path_factory, EXAMPLES[name])


@pytest.mark.skipif(not (MATRIX or PROFILE == "fuzz"), reason="make matrix's and make fuzz's (random draws)")
@settings(max_examples=2, deadline=None, suppress_health_check=list(HealthCheck))
@given(choices())
def test_a_conforming_vehicle_passes_whatever_it_chooses(tmp_path_factory, case):
    """Drawn choices (:func:`choices`): certified on the clauses they touch, nothing but PASS."""
    _STARTED[:] = _STARTED or [time.monotonic()]
    if PROFILE == "fuzz" and time.monotonic() - _STARTED[0] > FUZZ_BUDGET_S:
        return  # make fuzz: this test's share of the wall time is spent
    _passes_whatever_it_chooses(tmp_path_factory, case)


# ============================================================================ the bound


def time_a_servo_timeout(sets: list[str], k: float, timeout: int) -> tuple:
    """``$OMS`` with ``timeout`` on an emulator with ``sets``, polled every ~20 ms across its end;
    the exchange judged by the vehicle observer (as live): its ledger, and how late (vehicle s)
    the mode was first seen to leave A."""
    from helmcheck.clauses import vehicle_clauses
    from helmcheck.judge.ledger import Ledger
    from helmcheck.judge.vehicle import VehicleObserver
    from helmcheck.judge.wire import WireEvent

    recs: list[tuple[float, str, bytes]] = []
    left_at = t_ack = None
    with EmulatorProcess([x for a in sets for x in ("--set", a)], time_scale=k, baud=EMU_PROFILE.baud) as emu:
        link = emu.connect(EMU_PROFILE.baud)
        framer = Framer(4096)
        t0 = time.monotonic()

        def ask(body: str) -> list[bytes]:
            recs.append((time.monotonic() - t0, ">", frame(body)))
            link.write_all(frame(body))
            lines: list[bytes] = []
            until = time.monotonic() + 3.0
            while time.monotonic() < until:
                data = link.read(0.5)
                if data:
                    recs.append((time.monotonic() - t0, "<", data))
                    lines += [e.raw for e in framer.feed(data) if isinstance(e, Line)]
                    if any(x.startswith(b"$ACK") for x in lines):
                        return lines
            raise AssertionError(f"no $ACK to ${body}")

        try:
            for body in ("OMSTOP,0", "OSD,S", "OMSTART,0,0,0,0,conformance.mis,", "OSD,S"):
                ask(body)
            ask(f"OMS,90,2,20,0.5,{timeout}")
            t_ack = time.monotonic()
            quiet_until = t_ack + timeout * 0.85 / k
            while time.monotonic() < quiet_until:
                ask("OSD,S")
                time.sleep(0.25)
            end = t_ack + timeout * 1.15 / k + 1.0
            while time.monotonic() < end:
                modes = [x.split(b",")[2] for x in ask("OSD,S") if x.startswith(b"$OSI")]
                if modes and modes[0] != b"A" and left_at is None:
                    left_at = time.monotonic()
                if left_at is not None and time.monotonic() - left_at > 0.3:
                    break
                time.sleep(0.02)
            ask("OMSTOP,0")
        finally:
            link.close()
    ledger = Ledger([c.id for c in vehicle_clauses()])
    obs = VehicleObserver(EMU_PROFILE.replace(time_scale=k), ledger, time_scale=k, baud=EMU_PROFILE.baud)
    for i, (t, d, data) in enumerate(recs, 1):
        obs.feed(WireEvent(t, d, data, "", i))
    obs.close()
    late = None if left_at is None else (left_at - t_ack) * k - timeout
    return ledger, late


#: A 120 s servo timeout at time scale 10 (12 s of wall time): RH-TIM-1 allows 6 s either way;
#: the observer's own slack there is under 1 vehicle s (10 × its ~20 ms poll and 30 ms jitter),
#: so a clock 6.5 % slow (7.8 s late) is beyond what any observation can excuse, and one 3.5 % slow
#: (4.2 s late) is inside by more than it. The catalogue's own case (V-28) uses a 10 s timeout,
#: whose 0.5 s tolerance is within one poll at the suite's time scales.
BOUND_K, BOUND_TIMEOUT = 10.0, 120


@pytest.mark.parametrize("factor,want", [(1.065, "fail"), (1.035, "pass")], ids=["just-past", "just-inside"])
def test_a_servo_timeout_just_past_RH_TIM_1_fails_and_just_inside_passes(factor, want):
    st_ = EmulatorSettings(timer_factor=factor)
    assert bool(nonconforming(st_, EMU_PROFILE)) == (want == "fail")
    ledger, late = time_a_servo_timeout([f"timer_factor={factor}"], BOUND_K, BOUND_TIMEOUT)
    assert late is not None and late == pytest.approx(BOUND_TIMEOUT * (factor - 1), abs=1.0), late
    v = ledger.verdict("RH-SRV-4")
    assert v.verdict == want, (factor, late, v.reason)
    if want == "pass":
        assert ledger.verdict("RH-TIM-1").verdict == "pass", ledger.verdict("RH-TIM-1").reason
        assert not [c.id for c in ledger.verdicts() if c.verdict == "fail"]
    else:
        assert "a conforming vehicle reports N" in v.reason, v.reason
