"""The emulator's sans-IO core, plant and mission files, driven with explicit times (no sleeping)."""

from __future__ import annotations

import io
import os
import random
from decimal import Decimal

import pytest

from helmcheck.emulator.core import MAX_OUTBOX_BYTES, EmulatorCore, MainLog
from helmcheck.emulator.missionfile import (DirectoryCatalog, MissionFileError, builtin_dir,
                                                        format_mission, parse_mission)
from helmcheck.emulator.process import frame
from helmcheck.grammar import Framer, Line, decode
from helmcheck.grammar import sentences as s
from helmcheck.grammar.wirelog import WireLogWriter, read_records
from helmcheck.model.missions import BadMission, MissingMission, Mission
from helmcheck.profile import DEFAULT


def make_core(k: float = 10.0, baud: int = 0, **kw) -> EmulatorCore:
    profile = DEFAULT.replace(fault_injection="oxflt")
    return EmulatorCore(profile, DirectoryCatalog([builtin_dir()]), time_scale=k, baud=baud, **kw)


def replies(data: bytes) -> list[s.Sentence]:
    out = []
    for ev in Framer(4096).feed(data):
        assert isinstance(ev, Line), ev
        d = decode(ev.raw)
        assert d.sentence is not None, (ev.raw, d.error)
        out.append(d.sentence)
    return out


def acks(data: bytes) -> list[tuple[int, int, int]]:
    return [(r.type, r.status, r.err) for r in replies(data) if isinstance(r, s.ACK)]


def osi(core: EmulatorCore, now: float) -> s.OSI:
    got = [r for r in replies(core.feed(frame("OSD,S"), now)) if isinstance(r, s.OSI)]
    assert len(got) == 1
    return got[0]


def run_until(core: EmulatorCore, now: float, end: float, max_wakeups: int = 100_000) -> tuple[float, int]:
    """Follow next_wakeup() like the I/O loop would, up to wall time ``end``."""
    n = 0
    while n < max_wakeups:
        w = core.next_wakeup()
        if w is None or w > end:
            core.tick(end)
            return end, n
        now = max(now, w)
        core.tick(now)
        n += 1
    raise AssertionError("too many wakeups")


# ------------------------------------------------------------------------ mission files

def test_RH_MSN_1_builtin_missions_parse_and_fit_the_profile():
    cat = DirectoryCatalog([builtin_dir()])
    conf = cat.lookup("conformance.mis")
    assert isinstance(conf, Mission) and len(conf.waypoints) == 4
    assert any(w.park_s > 0 for w in conf.waypoints[:2])  # §10: a park on one of the first waypoints
    assert isinstance(cat.lookup("short.mis"), Mission)
    assert isinstance(cat.lookup("srp.mis"), Mission)
    assert isinstance(cat.lookup("nope.mis"), MissingMission)


def test_mission_file_round_trip_and_errors():
    m = parse_mission("helmcheck-mission 1\n# c\n\n41.5, -71.3, 2, 2.5, 30 # park\n1 2 3 4 0\n", "x.mis")
    assert m.waypoints[0].park_s == 30 and m.waypoints[1].speed == 4
    assert parse_mission(format_mission(m), "x.mis") == m
    for bad in ("", "helmcheck-mission 2\n1 2 3 4 5\n", "helmcheck-mission 1\n",
                "helmcheck-mission 1\n1 2 3 4\n", "helmcheck-mission 1\n91 0 0 1 0\n",
                "helmcheck-mission 1\n0 0 0 0 0\n", "helmcheck-mission 1\n0 0 x 1 0\n",
                "helmcheck-mission 1\n0 0 -1 1 0\n", "helmcheck-mission 1\n0 nan 1 1 0\n"):
        with pytest.raises(MissionFileError):
            parse_mission(bad, "bad.mis")


def test_RH_SAF_5_max_time_s_parses_round_trips_and_is_checked():
    m = parse_mission("helmcheck-mission 1\nmax_time_s 90 # Maximum Operation Time\n1 2 3 4 0\n", "t.mis")
    assert m.max_time_s == 90.0
    assert parse_mission(format_mission(m), "t.mis") == m
    assert parse_mission("helmcheck-mission 1\n1 2 3 4 0\n", "t.mis").max_time_s is None
    for bad in ("max_time_s 0", "max_time_s -5", "max_time_s", "max_time_s 1 2", "max_time_s x",
                "max_time_s 1\nmax_time_s 2"):
        with pytest.raises(MissionFileError):
            parse_mission(f"helmcheck-mission 1\n{bad}\n1 2 3 4 0\n", "bad.mis")


@pytest.mark.parametrize("limit", [15.0, 37.5])
def test_RH_SAF_5_a_missions_own_rule_trips_stl_at_its_time_and_once_per_start(tmp_path, limit):
    """The emulator raises Stl ``max_time_s`` vehicle seconds after the mission starts (not
    before, not twice); a new start runs the clock again; a stopped mission never trips."""
    (tmp_path / "t.mis").write_text(f"helmcheck-mission 1\nmax_time_s {limit}\n"
                                    "41.53 -71.32 10 2 0\n41.54 -71.32 10 2 0\n")
    k = 10.0
    core = EmulatorCore(DEFAULT.replace(baud=0), DirectoryCatalog([tmp_path, builtin_dir()]), time_scale=k,
                        baud=0)
    assert acks(core.feed(frame("OMSTART,0,0,0,0,t.mis,"), 0.0)) == [(3, 0, 0)]
    due = limit / k
    run_until(core, 0.0, due - 0.05)
    assert osi(core, due - 0.05).error_state == "N"
    run_until(core, due - 0.05, due + 0.05)
    assert osi(core, due + 0.05).error_state == "Stl"
    assert core.stats["faults"] == 1
    # after the lockout, a stop and a new start: the clock runs again from the new start
    t = due + 40 / k
    run_until(core, due + 0.05, t)
    assert acks(core.feed(frame("OMSTOP,0"), t)) == [(1, 0, 0)]
    assert acks(core.feed(frame("OMSTART,0,0,0,0,t.mis,"), t + 0.1)) == [(3, 0, 0)]
    assert acks(core.feed(frame("OMSTOP,0"), t + 0.2)) == [(1, 0, 0)]  # stopped before it trips
    run_until(core, t + 0.2, t + 0.2 + 2 * due)
    assert core.stats["faults"] == 1


def test_RH_MSN_1_catalogue_never_leaves_its_directory(tmp_path):
    root = tmp_path / "missions"
    (root / "sub").mkdir(parents=True)
    outside = tmp_path / "outside.mis"
    outside.write_text("helmcheck-mission 1\n1 2 3 4 0\n")
    (root / "sub" / "a.mis").write_text("helmcheck-mission 1\n1 2 3 4 0\n")
    (root / "bad.mis").write_text("not a mission\n")
    (root / "bin.mis").write_bytes(b"\xff\xfe")
    (root / "escape.mis").symlink_to(outside)
    os.mkfifo(root / "fifo.mis")  # opening it would block: it must never be opened
    (root / "conformance.mis").write_text("helmcheck-mission 1\n0 0 1 1 0\n")
    cat = DirectoryCatalog([root, builtin_dir()])
    for name in ("../outside.mis", "/etc/passwd", "C:\\x.mis", "sub/../../outside.mis", "", "a\x00b",
                 "escape.mis", "sub//a.mis"):
        assert isinstance(cat.lookup(name), MissingMission), name
    assert isinstance(cat.lookup("sub/a.mis"), Mission)
    assert isinstance(cat.lookup("sub\\a.mis"), Mission)
    assert cat.lookup("bad.mis") == BadMission("bad.mis", "unparseable")
    assert cat.lookup("bin.mis") == BadMission("bin.mis", "unreadable")
    assert cat.lookup("fifo.mis") == BadMission("fifo.mis", "unreadable")
    over = cat.lookup("conformance.mis")  # the first directory overrides the built-in one
    assert isinstance(over, Mission) and len(over.waypoints) == 1
    assert isinstance(cat.lookup("short.mis"), Mission)


# ------------------------------------------------------------------------ framing and replies

def test_RH_ACK_1_replies_do_not_depend_on_how_bytes_are_split():
    cmds = b"".join(frame(b) for b in ("OSD,C,S", "OMS,90,2,20,2,10", "OMSTART,0,0,0,0,conformance.mis",
                                       "ORWSET,Sle,R", "OMS,400,2,20,2,10", "OJW,1"))
    whole = make_core()
    want = acks(whole.feed(cmds, 0.5))
    assert want == [(8, 0, 0), (9, 1, 20), (3, 0, 0), (12, 1, 23), (9, 1, 20), (7, 0, 0)]
    rng = random.Random(7)
    for _ in range(5):
        core = make_core()
        out = b""
        i = 0
        while i < len(cmds):
            j = i + rng.randint(1, 9)
            out += core.feed(cmds[i:j], 0.5)
            i = j
        assert acks(out) == want


def test_RH_FRM_4_RH_FRM_5_bad_frames_get_no_ack():
    core = make_core()
    good = frame("OSD,S")
    bad_sum = good[:-4] + b"00\r\n"
    out = core.feed(bad_sum + b"$OSD,S\r\n" + frame("OZZ,1") + b"$OSD,S*2G\r\n", 0.1)
    assert out == b""
    assert acks(core.feed(frame("OMS,400,2,20,2,10"), 0.2)) == [(9, 1, 20)]  # RH-ACK-3


def test_RH_FRM_6_overlong_and_noise_do_not_stick():
    core = make_core()
    rng = random.Random(3)
    junk = bytes(rng.randrange(256) for _ in range(5000)) + b"$" + b"A" * 2000 + b"$OMS,12"
    core.feed(junk, 0.1)
    assert core.framer.pending <= core.profile.max_line_bytes
    assert acks(core.feed(frame("OSD,S"), 0.2)) == [(8, 0, 0)]


def test_RH_FRM_3_lowercase_checksum_and_bare_lf_accepted():
    core = make_core()
    raw = frame("OSD,S,P")  # checksum 5B: has a hex letter
    low = raw[:-4] + raw[-4:-2].lower() + b"\n"
    assert low != raw[:-2] + b"\n"
    assert acks(core.feed(low + frame("ORWSET,Sle,R")[:-2] + b"\n", 0.1)) == [(8, 0, 0), (12, 0, 0)]


# ------------------------------------------------------------------------ time scale and plant

def test_RH_TIM_2_servo_timeout_scaled_by_time_scale():
    core = make_core(k=10.0)
    assert acks(core.feed(frame("OMSTART,0,0,0,0,conformance.mis"), 0.0)) == [(3, 0, 0)]
    assert acks(core.feed(frame("OMS,90,2,20,2,10"), 1.0)) == [(9, 0, 0)]  # timeout 10 s = 1 s wall
    assert core.next_wakeup() is not None and core.next_wakeup() <= 2.0
    assert osi(core, 1.95).mode == "A"
    assert osi(core, 2.05).mode == "N"  # RH-SRV-4, RH-INT-2


def test_RH_MSN_4_short_mission_runs_to_the_end_on_plant_events():
    core = make_core(k=100.0)
    assert acks(core.feed(frame("OMSTART,0,0,0,0,short.mis"), 0.0)) == [(3, 0, 0)]
    now, wakeups = run_until(core, 0.0, 1.0)
    o = osi(core, now)
    assert (o.mode, o.next_waypoint) in (("N", 1), ("P", 1))
    now, more = run_until(core, now, 4.0)
    assert osi(core, now).mode == "S"  # ~205 s of vehicle time at x100
    assert wakeups + more < 3000  # sleeps between events, no busy polling
    notes = [h.text for h in core.history if h.direction == "!"]
    assert any("WaypointReached(index=2)" in n for n in notes)
    assert any("MissionEnded" in n for n in notes)


def test_plant_reports_physical_values_within_ranges():
    core = make_core(k=50.0)
    core.feed(frame("OMSTART,0,0,0,0,conformance.mis"), 0.0)
    now, _ = run_until(core, 0.0, 2.0)
    o = osi(core, now)
    assert o.depth is not None and Decimal("1.5") <= o.depth <= Decimal("2.0")
    assert 0 <= o.true_heading < 360 and o.speed >= 0
    assert 0 <= Decimal(o.battery) <= 100
    assert o.remaining_time is not None and Decimal("3") < o.remaining_time < Decimal("6")


def test_RH_PK_2_countdown_starts_on_station():
    core = make_core(k=20.0)
    core.feed(frame("OMSTART,0,0,0,0,conformance.mis"), 0.0)
    o = osi(core, 0.01)
    lat = float(o.lat) + 0.0001  # ~11 m north
    assert acks(core.feed(frame(f"OPK,{lat:.6f},{float(o.lon):.6f},1,2"), 0.02)) == [(11, 0, 0)]
    o = osi(core, 0.03)
    assert (o.mode, o.park_time) == ("mP", 60)
    now, _ = run_until(core, 0.03, 2.0)
    o = osi(core, now)
    assert o.mode == "mP" and 0 < o.park_time < 60


def test_RH_SAF_1_fault_key_lockout_ascent_and_surface_park():
    core = make_core(k=20.0)
    core.feed(frame("OMSTART,0,0,0,0,conformance.mis"), 0.0)
    run_until(core, 0.0, 0.5)  # dive to 2 m
    core.inject_fault("Sle", 0.5)
    assert any("SafetyRaised(code='Sle')" in h.text for h in core.history)
    o = osi(core, 0.51)
    assert (o.mode, o.error_state) == ("N", "Sle")
    assert acks(core.feed(frame("OMP,8080808080,00,5"), 0.52)) == [(10, 1, 26)]
    now, _ = run_until(core, 0.52, 3.0)  # lockout 1 s wall, then ascent to the surface
    o = osi(core, now)
    assert (o.mode, o.error_state, o.park_time) == ("P", "Sle", 0)  # RH-SAF-4 park, RH-RD-12
    assert o.depth is not None and o.depth <= Decimal("0.25")
    assert acks(core.feed(frame("OMSTOP,0"), now)) == [(1, 0, 0)]
    assert osi(core, now).error_state == "N"  # RH-RD-13


# ------------------------------------------------------------------------ pacing and bounds

def test_RH_ACK_2_output_paced_at_the_baud_rate():
    core = make_core(baud=9600)
    first = core.feed(frame("OSD,G,C,S,P"), 0.0)
    got = first
    now = 0.0
    while True:
        w = core.next_wakeup()
        if w is None:
            break
        assert w > now
        now = w
        got += core.tick(now)
    assert len(replies(got)) == 5
    assert len(first) < len(got)  # not everything at once
    # the last sentence starts after the earlier ones had time to go out at 960 bytes/s
    last = got.rstrip(b"\r\n").rsplit(b"\r\n", 1)[-1] + b"\r\n"
    assert now >= (len(got) - len(last)) * 10 / 9600 - 1e-6


def test_output_queue_is_bounded():
    core = make_core(baud=9600)
    for i in range(3000):
        core.feed(frame("OSD,S"), 0.0)
    assert core.pending_output <= MAX_OUTBOX_BYTES
    assert core.stats["dropped_out"] > 0


@pytest.mark.parametrize("reading", ["queue", "drop"])
def test_an_over_asked_line_queues_or_drops_as_its_overrun_reading_says(reading):
    """Ten ``$OSD,G,C,S,P`` a second on 19200 baud ask for about 3.2 kB/s of replies on a 1.92 kB/s
    line (RH-ACK-2's transmit time, 10 bits a byte). ``queue``: every request is answered, later
    and later; ``drop``: a poll whose replies could not start within the ACK window goes
    unanswered whole, every reply sent left about within it, and a command is still answered.
    Either way the meter names the overrun."""
    from helmcheck.emulator.freedoms import DEFAULT_SETTINGS
    from helmcheck.emulator.outload import describe

    core = make_core(k=1.0, baud=19200, settings=DEFAULT_SETTINGS.replace(overrun=reading))
    sent_at: dict[bytes, list[float]] = {}
    released: list[tuple[bytes, float, float]] = []
    core.on_release = lambda raw, queued, now: released.append((raw, queued, now))
    out = b""
    now = 0.0
    for i in range(200):  # 20 s of polls at 10 Hz, and a command every second
        now = i * 0.1
        out += core.feed(frame("OSD,G,C,S,P") + (frame("OPOS,41.52,-71.32,1.0,42,15") if i % 10 == 5 else b""), now)
        for w in range(50):
            nxt = core.next_wakeup()
            if nxt is None or nxt > now + 0.1:
                break
            out += core.tick(max(now, nxt))
    if reading == "drop":  # what was still queued goes out (the queue holds about a second)
        for w in range(100):
            nxt = core.next_wakeup()
            if nxt is None or nxt > now + 2.0:
                break
            out += core.tick(nxt)
    acks8 = [a for a in acks(out) if a[0] == 8]
    lags = [now_ - queued for raw, queued, now_ in released]
    summary = core.load.summary(ack_window_s=1.0)
    assert summary is not None and summary["over_capacity"], summary
    assert 2500 < summary["asked_Bps"] < 4000, summary  # about 3.2 kB/s asked of a 1.92 kB/s line
    if reading == "queue":
        assert core.stats["dropped_out"] == 0
        assert max(lags) > 5.0  # behind by more every second
        assert core.pending_output > 10_000
    else:
        assert core.stats["dropped_out"] > 0 and summary["dropped_bytes"] == core.stats["dropped_out"]
        # once ten seconds of over-asking made it an overrun, no poll waits past the ACK window (and
        # the replies of its own request on the line)
        assert max(now_ - queued for raw, queued, now_ in released if queued > 12.0) <= 1.0 + 0.2
        assert 100 < len(acks8) < 200  # some polls answered, not all
        assert len([a for a in acks(out) if a[0] == 6]) == 20  # every command answered
    text = describe(summary)
    assert "$OSD polls asked for" in text and "1.92 kB/s line (19200 baud)" in text
    assert ("were dropped" in text) == (reading == "drop")


def test_a_burst_of_polls_is_queued_not_dropped_and_is_no_overrun():
    """``overrun = "drop"`` sheds polls only while the requests of the last ten seconds ask for
    more than the line carries: a burst (a backseat's buffered polls arriving at once, a stalled
    reader) waits its turn, and the meter names no overrun for it."""
    from helmcheck.emulator.freedoms import DEFAULT_SETTINGS

    core = make_core(k=1.0, baud=19200, settings=DEFAULT_SETTINGS.replace(overrun="drop"))
    for i in range(10):
        core.feed(frame("OSD,G,C,S,P"), 5.0 + 0.001 * i)  # ten polls at once, after 5 s of nothing
    assert core.stats["dropped_out"] == 0 and core.backlog_s(5.01) > 1.0
    assert core.load.summary(ack_window_s=1.0) is None


def test_model_lists_trimmed_for_bounded_memory():
    core = make_core()
    for i in range(2000):
        core.feed(frame("OPOS,41.52,-71.32,1.5,42,15"), 0.0)
    assert len(core.model.opos_records) <= 512


# ------------------------------------------------------------------------ logs and settings

def test_wire_log_records_both_directions_and_notes():
    buf = io.StringIO()
    core = make_core(log=WireLogWriter(buf, meta="test"))
    core.feed(b"noise" + frame("OSD,S"), 0.25)
    core.feed(frame("OXFLT,Sop"), 0.5)
    core.disconnect(0.75, "test")
    recs = list(read_records(buf.getvalue().encode().splitlines()))
    dirs = [r.dir for r in recs]
    assert ">" in dirs and "<" in dirs and "!" in dirs
    assert any(r.data == b"noise" for r in recs if r.dir == ">")
    assert any("fault injected" in r.note for r in recs if r.dir == "!")
    assert any("SafetyRaised" in r.note for r in recs if r.dir == "!")


def test_RH_LOG_2_ologd_rows_go_to_the_main_log():
    buf = io.StringIO()
    core = make_core(main_log=MainLog(buf))
    assert acks(core.feed(frame("OLOGL,temp,sal"), 0.0)) == [(5, 0, 0)]
    core.feed(frame("OMSTART,0,0,0,0,conformance.mis"), 0.1)
    assert acks(core.feed(frame("OLOGD,12.5,33"), 0.2)) == [(4, 0, 0)]
    assert acks(core.feed(frame("OLOGD,12.6,"), 0.3)) == [(4, 0, 0)]
    lines = buf.getvalue().splitlines()
    assert lines[0] == "vehicle_time_s,utc,lat,lon,depth_m,temp,sal"
    assert lines[1].endswith(",12.5,33") and lines[2].endswith(",12.6,")
    assert len(lines) == 3


def test_RH_SET_2_settings_persist_across_runs(tmp_path):
    path = tmp_path / "settings.json"
    core = make_core(settings_path=path)
    ack = replies(core.feed(frame("ORWSET,Sed,W,0,50"), 0.0))[-1]
    assert (ack.type, ack.status, ack.extra) == (12, 0, ("Sed", "2", "0", "50"))
    again = make_core(settings_path=path)
    ack = replies(again.feed(frame("ORWSET,Sed,R"), 0.0))[-1]
    assert ack.extra == ("Sed", "2", "0", "50")


def test_disconnect_drops_a_partial_line():
    core = make_core()
    core.feed(b"$OMSTART,0,0,0,0,conf", 0.0)
    core.disconnect(0.1)
    out = core.feed(b"ormance.mis*4A\r\n" + frame("OSD,S"), 0.2)
    assert acks(out) == [(8, 0, 0)]
    assert osi(core, 0.3).mode == "S"


def test_live_view_renders_without_a_terminal():
    from rich.console import Console

    from helmcheck.emulator.tui import FAULT_KEYS, LiveView

    core = make_core()
    core.feed(frame("OMSTART,0,0,0,0,conformance.mis") + frame("OMS,90,2,20,2,10") + b"junk$X*00\r\n", 0.1)
    console = Console(file=io.StringIO(), width=140, height=40, record=True)
    view = LiveView(core, "/dev/pts/99", console=console)
    console.print(view.render())
    text = console.export_text()
    for word in ("Timeout", "Lockout", "Mode", "OMS", "discard", "/dev/pts/99", "Motor"):
        assert word in text, word

    class FakeServer:
        injected: list = []

        def inject_fault(self, code, source):
            self.injected.append(code)

        def stop(self, status=0):
            self.injected.append("stop")

    r, w = os.pipe()
    os.write(w, b"3q")
    view.fileno = lambda: r  # type: ignore[method-assign]
    fake = FakeServer()
    view.on_input(fake, 1.0)
    assert fake.injected == [FAULT_KEYS["3"], "stop"]
    os.close(r)
    os.close(w)


# ------------------------------------------------------------------------ tester hooks

def test_RH_MSN_3_end_mission_stops_the_running_mission_without_a_reply():
    core = make_core()
    assert core.end_mission(0.0) == b"" and not core.mission_running  # nothing to end
    assert acks(core.feed(frame("OMSTART,0,0,0,0,conformance.mis"), 0.0)) == [(3, 0, 0)]
    assert core.mission_running
    assert core.end_mission(0.5) == b""  # nobody on the line asked: no $ACK
    assert not core.mission_running and core.model.mode == "S"
    assert core.plant.target(core.model).kind == "hold"


def test_RH_ACK_6_queued_reply_goes_out_in_order_and_paced():
    core = make_core(baud=9600)
    first = core.feed(frame("OSD,S"), 0.0)
    assert first  # the first sentence goes at once, the rest waits for the line
    rest = core.queue_reply(s.ACK(9, 1, 20), 0.0)
    t, out = 0.0, first + rest
    while core.pending_output:
        t = core.next_wakeup()
        out += core.tick(t)
    got = replies(out)
    assert isinstance(got[0], s.OSI) and [(r.type, r.status, r.err) for r in got[1:]] == [(8, 0, 0), (9, 1, 20)]
    assert t >= (len(out) - len(frame("ACK,9,1,20"))) * 10 / 9600 - 1e-6


def test_RH_SAF_1_lockout_active_follows_the_model():
    core = make_core(k=10.0)
    assert not core.lockout_active
    core.inject_fault("Sop", 0.0)
    assert core.lockout_active
    core.tick(DEFAULT.lockout_s / 10.0 + 0.1)
    assert not core.lockout_active


def test_model_factory_builds_the_model():
    from helmcheck.model.vehicle import VehicleModel

    class Marked(VehicleModel):
        pass

    core = make_core(model_factory=Marked)
    assert type(core.model) is Marked
    assert acks(core.feed(frame("OSD,S"), 0.0)) == [(8, 0, 0)]
