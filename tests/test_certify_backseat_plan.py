"""``certify backseat``'s plan: each scenario as long as what it must show needs, at the time scale and on the line.

No ports and no backseat, but for the last test, which opens a pty for a second: these are cheap.
The lengths come from the profile (the lockout, the ACK window, the reaction time, the longest
timeout), the test mission (the ascent from its deepest waypoint) and the baud (a reply's
transmit time, 10 bits a byte); ``--plan`` prints them; the default ``--duration`` is their sum;
a shorter one is named before the run starts and the plan kept; a longer one is shared out.
"""

from __future__ import annotations

import argparse
import subprocess
import sys

import pytest
from hypothesis import given
from hypothesis import strategies as st

from helmcheck.certify.backseat.certifier import Options, plan_for
from helmcheck.certify.backseat.scenarios import (LEAD_S, NOMINAL_S, REPLY_BYTES, SCENARIOS, SILENCE_S, TAIL_S,
                                                  make_plan, reach_s)
from helmcheck.commands import certify_backseat_cmd as cli
from helmcheck.judge.timing import transmit_time
from helmcheck.profile import DEFAULT

BAUDS = (9600, 19200, 57600, 115200)


@given(k=st.sampled_from([1.0, 2.0, 5.0, 10.0, 20.0, 40.0]), baud=st.sampled_from(BAUDS),
       names=st.lists(st.sampled_from(SCENARIOS), min_size=1, max_size=5, unique=True))
def test_each_scenario_lasts_what_it_must_show_at_the_time_scale_and_on_the_line(k, baud, names):
    """The lockout's slot holds the lead, the lockout and the ascent at ×k, and a report's reach
    (ACK window, a reply's transmit time at the baud, the reaction time); every slot is in the
    order asked, back to back; with no ``--duration`` the run is exactly what they need."""
    p = make_plan(names, None, time_scale=k, lockout_s=20.0, baud=baud, ack_window_s=1.0, reaction_s=0.25,
                  ascent_depth_m=3.0, ascent_mps=0.3)
    reach = 1.0 + transmit_time(REPLY_BYTES, baud) + 0.25
    assert reach == pytest.approx(reach_s(baud, 1.0, 0.25))
    assert [s.name for s in p.slots] == names
    assert p.slots[0].start == 0.0 and all(a.end == pytest.approx(b.start) for a, b in zip(p.slots, p.slots[1:]))
    assert p.total == pytest.approx(p.needed) and p.total == pytest.approx(sum(s.length for s in p.slots))
    assert not p.short and not p.note
    want = {"nominal": NOMINAL_S, "reject": LEAD_S + 5.0 + reach + 1.0 + TAIL_S,
            "lockout": LEAD_S + 20.0 / k + 10.0 / k + reach, "mission-end": LEAD_S + reach + 1.0,
            "silence": LEAD_S + SILENCE_S + TAIL_S}
    for s in p.slots:
        assert s.length == pytest.approx(want[s.name]), s
        assert s.needs == pytest.approx(s.length) and s.why and s.limit >= 10.0
    # the staged steps come inside their slots: the lockout LEAD_S in, the windows end TAIL_S early
    for a in p.actions:
        slot = next(s for s in p.slots if s.name == a.name)
        assert slot.start - 1e-9 <= a.at <= slot.end + 1e-9
    lengths = {s.name: s.length for s in p.slots}
    if "lockout" in lengths:  # a slower line or a smaller time scale never shortens it
        slower = make_plan(["lockout"], None, time_scale=k, lockout_s=20.0, baud=9600, ascent_depth_m=3.0)
        assert slower.total >= make_plan(["lockout"], None, time_scale=k, lockout_s=20.0, baud=115200,
                                         ascent_depth_m=3.0).total
        assert make_plan(["lockout"], None, time_scale=k / 2, lockout_s=20.0, baud=baud).total > \
            make_plan(["lockout"], None, time_scale=k, lockout_s=20.0, baud=baud).total


@given(k=st.sampled_from([1.0, 10.0, 20.0]), factor=st.floats(0.2, 3.0))
def test_a_duration_shares_out_its_surplus_and_one_too_short_is_named(k, factor):
    need = make_plan(list(SCENARIOS), None, time_scale=k, lockout_s=20.0).needed
    p = make_plan(list(SCENARIOS), need * factor, time_scale=k, lockout_s=20.0)
    if factor > 1.0 + 1e-6:  # longer: every slot keeps what it needs and gets its share of the rest
        assert p.total == pytest.approx(need * factor) and not p.short
        assert all(s.length == pytest.approx(s.needs * factor) for s in p.slots)
    elif factor < 1.0 - 1e-6:  # shorter: named, scenario by scenario, and the plan kept
        assert p.total == pytest.approx(need) and len(p.short) == len(SCENARIOS)
        assert f"--duration {need * factor:g} s is too short at ×{k:g}" in p.note
        assert all(s.length == pytest.approx(s.needs) for s in p.slots)
        assert any(x.startswith("lockout (needs ") for x in p.short)


def test_the_plan_at_x1_holds_a_20_s_lockout_and_the_ascent_from_the_test_missions_deepest_waypoint():
    """The profile's test mission dives to 3 m; the vehicle ascends at 0.3 m/s after a lockout:
    at ×1 the lockout scenario is over 31 s, at ×10 about 6 s."""
    p1 = plan_for(Options(profile=DEFAULT, report_dir=".", time_scale=1.0))
    p10 = plan_for(Options(profile=DEFAULT, report_dir=".", time_scale=10.0))
    lock1 = next(s for s in p1.slots if s.name == "lockout")
    lock10 = next(s for s in p10.slots if s.name == "lockout")
    assert lock1.length > 20.0 + 10.0 + 1.0 and "ascent from 3 m" in lock1.why and "20 s lockout" in lock1.why
    assert 5.0 < lock10.length < 7.0
    assert p1.total > p10.total > 25.0


def _args(*argv: str) -> argparse.Namespace:
    p = argparse.ArgumentParser()
    cli.add_arguments(p)
    return p.parse_args(list(argv))


def test_plan_prints_each_scenarios_length_and_why_and_opens_no_port(capsys):
    code = cli.run(_args("--plan", "--time-scale", "1", "--baud", "19200"))
    out = capsys.readouterr().out
    assert code == 0
    lines = out.strip().splitlines()
    assert lines[0].startswith("plan at ×1 on 19200 baud: ") and "s of judged run" in lines[0]
    total = float(lines[0].split(": ", 1)[1].split(" s ", 1)[0])
    assert total == pytest.approx(plan_for(Options(profile=DEFAULT, report_dir=".", time_scale=1.0)).total, abs=0.05)
    assert [ln.split()[0] for ln in lines[1:]] == list(SCENARIOS)
    assert "port:" not in out
    assert sum(float(ln.split()[1]) for ln in lines[1:]) == pytest.approx(total, abs=0.3)


def test_a_too_short_duration_is_named_before_the_run_starts(tmp_path):
    """``--duration 5`` at ×10: named on standard error, before the ``port:`` line's backseat would
    even connect (here none does: exit 2, never connected)."""
    proc = subprocess.run([sys.executable, "-m", "helmcheck", "certify", "backseat", "--time-scale", "10",
                           "--duration", "5", "--connect-timeout", "0.5", "--no-progress",
                           "--report-dir", str(tmp_path / "r")], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2, proc.stderr
    err = proc.stderr
    assert "--duration 5 s is too short at ×10 on 19200 baud" in err, err
    assert "lockout" in err.split("too short", 1)[1] and "Traceback" not in err
    assert proc.stdout.startswith("port: ")
