"""Clause-by-clause tests of the reference vehicle model (helmcheck.model.vehicle)."""

from __future__ import annotations

import ast
from decimal import Decimal
from pathlib import Path

import pytest

from helmcheck.grammar import sentences as s
from helmcheck.grammar.errors import SentenceError
from helmcheck.grammar.ranges import check_ranges
from helmcheck.model import events as ev
from helmcheck.model.missions import InMemoryCatalog, Mission, Waypoint, mission_name_problem
from helmcheck.model.plant import (AtSurface, OnStation, PlantSnapshot, QueueWaypointReached,
                                   SafetyViolation, Submerged, WaypointReached)
from helmcheck.model.testing import (catalog, odvl, ojw, ologd, ologl, omload, omp, oms, omstart,
                                     omstart_paper, omstop, omw, omw_clear, opk, opos, orwset, osd,
                                     oxflt, oxflt_profile, started)
from helmcheck.model.data import CLASS_OF_LETTER
from helmcheck.model.vehicle import VehicleModel
from helmcheck.profile import DEFAULT, SAFETY_CODES


def ack(t, err=0, extra=()):
    return s.ACK(t, 1 if err else 0, err, tuple(extra))


def fresh(**changes):
    return VehicleModel(oxflt_profile(**changes), catalog())


def fingerprint(m: VehicleModel):
    return (m.state(), m.phase, m.mission_mode, m.mission_wp, m.loaded, m.servo, m.primitive,
            m.opk, tuple(m.queue), m.dvl, m.log_labels, len(m.log_rows), m.settings.as_dict(),
            m.timers.names(), m.snapshot)


# ----------------------------------------------------------------------------- §2 ACK


@pytest.mark.parametrize("cmd,t", [
    (oms(), 9), (omp(), 10), (ojw(1), 7), (opk(), 11), (omw(), 16), (omw_clear(), 16),
    (omstop(), 1), (omload(), 2), (omstart(), 3), (omstart_paper(), 3), (opos(), 6), (osd(), 8),
    (ologl("a"), 5), (ologd("1"), 4), (orwset("Sop"), 12), (odvl(), 15),
])
def test_RH_ACK_1_exactly_one_ack_of_its_own_type(cmd, t):
    for m in (fresh(), started()):
        replies = m.receive(cmd, 1.0)
        acks = [r for r in replies if isinstance(r, s.ACK)]
        assert len(acks) == 1 and acks[0].type == t and replies[-1] is acks[0]


def test_RH_ACK_2_replies_are_due_at_once_no_deferred_acks():
    m = started()
    assert m.receive(oms(), 5.0) == [ack(9)]
    assert m.advance(5.0) == []  # nothing held back for later


@pytest.mark.parametrize("cmd", [
    oms(heading=360), oms(depth=101), oms(pitch=46), oms(speed=4.6), oms(timeout=0), oms(timeout=121),
    omp("80808080", 5), omp("8080808G80", 5), omp(reserved="01"), omp(timeout=0),
    opk(lat=91), opk(minutes=0), opk(minutes=1441), opk(speed=5),
    omw(depth1=101), omw(park_s=86401), omw(pitch=46), omw_clear("CLEARX"),
    omw_clear("Clr", omw(lat=95)), omstop(1), omload("/etc/passwd"), omload("C:\\Missions\\a.mis"),
    omload("../a.mis"), omstart(ignore_gps=2), omstart("a/../../b.mis"), omstart(srp="/x.mis"),
    omstart_paper(4), opos(lat=-91), opos(speed=-1), opos(cond=101), opos(temp=51),
    osd("X"), osd("s"), osd("GG"), ologl(), ologl(""), ologl(*["a"] * 13), ologd(),
    orwset("Nope"), orwset("sop"), orwset("Sop", "R", 1), orwset("Sop", "W"), orwset("Sop", "W", 2),
    orwset("Sop", "W", 1, "1", "2", "3", "4"), orwset("SafetyAction", "W", 1, "swim"),
    odvl(x=6), odvl(y=-6), odvl(timeout=200),
])
def test_RH_ACK_3_incorrect_values_rejected_with_own_error_and_no_state_change(cmd):
    for m in (fresh(), started()):
        m.receive(ologl("a"), 0.5) if not m.running else None
        before = fingerprint(m)
        assert m.receive(cmd, 1.0) == [ack(cmd.ACK_TYPE, cmd.ERR)]
        assert fingerprint(m) == before


def test_RH_ACK_3_sentence_error_is_answered_with_its_error():
    m = started()
    bad = SentenceError("RH-SRV-2", "bad", None, "range", "OMS", "heading", 9, 20)
    assert m.receive(bad, 1.0) == [ack(9, 20)]
    framing = SentenceError("RH-FRM-2", "bad checksum")
    assert m.receive(framing, 1.0) == []


@pytest.mark.parametrize("cmd", [oms(), ojw(1), opk(), omw(), omw_clear(), ologd("1")])
def test_RH_ACK_4_precondition_failure_uses_incorrect_values_error(cmd):
    m = fresh()
    m.receive(ologl("a"), 0.0)
    assert m.receive(cmd, 1.0) == [ack(cmd.ACK_TYPE, cmd.ERR)]
    assert m.mode == "S"


def test_RH_ACK_4_mission_commands_refused_while_running():
    m = started()
    for cmd in (omload(), omstart(), omstart_paper(), ologl("a"), orwset("Sop")):
        assert m.receive(cmd, 1.0) == [ack(cmd.ACK_TYPE, cmd.ERR)]
    assert m.mode == "N"


def test_RH_ACK_5_osd_data_before_its_ack():
    m = started()
    out = m.receive(osd("S", "C"), 1.0)
    assert [type(x) for x in out] == [s.OSI, s.Compass, s.ACK] and out[-1] == ack(8)


def test_RH_ACK_6_replies_follow_arrival_order():
    m = started()
    cmds = [osd("G"), oms(), ojw(2), osd("S"), omstop()]
    replies = [r for c in cmds for r in m.receive(c, 1.0)]
    assert [r.type for r in replies if isinstance(r, s.ACK)] == [8, 9, 7, 8, 1]


# ------------------------------------------------------------------------- §3 outputs


def test_RH_OUT_1_osi_has_21_fields_and_state_fields():
    m = started()
    m.receive(omp("a0b0c0d0e0", 10), 1.0)
    o = m.osi()
    assert o.field_count == 21 and o.actuators == "A0B0C0D0E0" and o.mode == "M"
    assert o.next_waypoint == 0 and o.error_state == "N" and o.park_time == 0
    assert o.mission_name == "conformance.mis" and o.srp_active == "False"
    assert o.vehicle_name == DEFAULT.vehicle_name
    assert check_ranges(o, m.profile) is None


def test_RH_OUT_1_older_profile_field_count():
    p = DEFAULT.replace(protocol="rh4", osi_fields=17, depth_unit="ft")
    m = VehicleModel(p, catalog())
    o = m.osi(0.0)
    assert o.field_count == 17 and o.battery == "False"


def test_RH_OUT_2_data_sentences_for_every_letter():
    m = started()
    out = m.receive(osd("G", "C", "S", "P", "Y", "D", "T", "I"), 1.0)
    assert [type(x) for x in out] == [s.GPRMC, s.Compass, s.OSI, s.OPI, s.OYSI, s.DVL, s.OCTD,
                                      s.OINS, s.ACK]
    for x in out:
        assert check_ranges(x, m.profile) is None, x


@pytest.mark.parametrize("snap", [
    PlantSnapshot(),
    PlantSnapshot(heading=359.97, declination=0.04, pitch=120, roll=-95, battery_pct=130,
                  lat=95.0, lon=-200.0, speed_kn=-1),
])
def test_RH_OUT_3_every_emitted_number_in_physical_range(snap):
    m = VehicleModel(DEFAULT, catalog(), snapshot=snap)
    for x in m.receive(osd(*"GCSPYDTI"), 0.0):
        assert check_ranges(x, m.profile) is None, x
    o = m.osi()
    assert 0 <= o.true_heading < 360 and -90 <= o.lat <= 90 and o.speed >= 0
    c = m.data("C")
    assert 0 <= c.heading < 360 and -90 <= c.pitch <= 90 and -90 <= c.roll <= 90


def test_RH_OUT_4_reported_state_follows_the_model():
    m = started()
    m.plant(WaypointReached(), 5.0)
    m.plant(WaypointReached(), 9.0)
    o = m.receive(osd("S"), 19.2)[0]
    assert (o.mode, o.next_waypoint, o.park_time) == ("P", 1, 50)
    assert m.expectation(19.2, 0.05).check(o) == []


# ---------------------------------------------------------------------- §4 interrupts


def test_RH_INT_1_each_control_command_replaces_the_active_one():
    m = started()
    seq = [(oms(), "A"), (omp(), "M"), (opk(), "mP"), (omw(), "W"), (oms(), "A"), (ojw(3), "N")]
    for cmd, mode in seq:
        assert m.receive(cmd, 1.0) == [ack(cmd.ACK_TYPE)]
        assert m.mode == mode and m.check_invariants() == []
    assert m.queue == [] and m.servo is None


def test_RH_INT_2_release_resumes_mission_behaviour_at_first_takeover():
    m = started()
    m.plant(WaypointReached(), 1.0)
    m.plant(WaypointReached(), 2.0)  # mission park of 60 s at waypoint 1
    m.receive(oms(timeout=5), 12.0)  # 50 s left
    m.receive(omp(timeout=5), 14.0)  # another control: still the same frozen park
    m.receive(opk(minutes=2), 15.0)
    m.receive(omw(), 16.0)
    m.receive(omp(timeout=3), 17.0)
    m.advance(20.0)
    assert m.state(20.0) == ("P", 1, "N", 50, False)
    assert any(isinstance(e, ev.ControlReleased) for e in m.advance(20.0)) or m.mode == "P"


def test_RH_INT_2_without_mission_back_to_S():
    m = fresh()
    m.receive(omp(timeout=2), 0.0)
    assert m.mode == "M"
    events = m.advance(2.0)
    assert m.mode == "S" and [type(e) for e in events] == [ev.PrimitiveTimeout, ev.ControlReleased]


def test_RH_INT_3_interrupted_opk_is_abandoned():
    m = started()
    m.plant(WaypointReached(), 1.0)
    m.receive(opk(minutes=10), 2.0)
    m.plant(OnStation(), 3.0)
    m.receive(oms(timeout=4), 30.0)
    m.advance(34.0)
    assert m.mode == "N" and m.mission_wp == 1 and m.opk is None


# ------------------------------------------------------------------------------ servo


def test_RH_SRV_1_servo_needs_a_running_mission():
    assert fresh().receive(oms(), 0.0) == [ack(9, 20)]
    m = fresh()
    m.receive(omp(), 0.0)
    assert m.receive(oms(), 0.5) == [ack(9, 20)] and m.mode == "M"


@pytest.mark.parametrize("field,good,bad", [
    ("heading", 359.9, 360), ("depth", 100, 100.1), ("pitch", 45, 45.5), ("speed", 4.5, 4.51),
    ("timeout", 120, 121),
])
def test_RH_SRV_2_servo_ranges(field, good, bad):
    m = started()
    assert m.receive(oms(**{field: good}), 1.0) == [ack(9)]
    assert m.receive(oms(**{field: bad}), 1.0) == [ack(9, 20)]


def test_RH_SRV_3_each_accepted_oms_restarts_the_timeout():
    m = started()
    m.receive(oms(timeout=5), 0.0)
    m.receive(oms(timeout=5), 4.0)
    assert m.next_deadline() == 9.0
    m.advance(8.9)
    assert m.mode == "A"


def test_RH_SRV_4_servo_timeout_resumes_mission():
    m = started()
    m.plant(WaypointReached(), 1.0)
    m.receive(oms(timeout=5), 2.0)
    assert m.advance(6.99) == [] and m.mode == "A"
    events = m.advance(7.0)
    assert [type(e) for e in events] == [ev.ServoTimeout, ev.ControlReleased]
    assert m.state() == ("N", 1, "N", 0, False)


# -------------------------------------------------------------------------- primitive


def test_RH_PRM_1_primitive_before_and_after_mission_start():
    assert fresh().receive(omp(), 0.0) == [ack(10)]
    assert started().receive(omp(), 0.0) == [ack(10)]


def test_RH_PRM_2_primitive_fields():
    m = started()
    assert m.receive(omp("ffFF00aa80", 1), 0.0) == [ack(10)]
    for bad in (omp("ffFF00aa8", 1), omp("ffFF00aa80", 1, "0"), omp(timeout=121)):
        assert m.receive(bad, 0.0) == [ack(10, 21)]


def test_RH_PRM_3_mode_M_and_osi_echoes_bytes_upper_case():
    m = started()
    m.receive(omp("0aff8080c1", 10), 0.0)
    assert m.mode == "M" and m.osi().actuators == "0AFF8080C1"


def test_RH_PRM_4_timeout_from_S_returns_to_S_neutral():
    m = fresh()
    m.receive(omp("0aff8080c1", 3), 0.0)
    m.advance(3.0)
    assert m.mode == "S" and m.osi().actuators == "8080808080"


# ------------------------------------------------------------------------------- jump


def test_RH_JW_1_jump_needs_mission_and_index_in_range():
    assert fresh().receive(ojw(0), 0.0) == [ack(7, 19)]
    m = started()
    assert m.receive(ojw(4), 0.0) == [ack(7, 19)]
    assert m.receive(ojw(-1), 0.0) == [ack(7, 19)]
    assert m.receive(ojw(3), 0.0) == [ack(7)] and m.osi_waypoint == 3


def test_RH_JW_1_waypoint_base_one():
    m = started(oxflt_profile(waypoint_base=1))
    assert m.receive(ojw(0), 0.0) == [ack(7, 19)]
    assert m.receive(ojw(4), 0.0) == [ack(7)] and m.osi_waypoint == 3


@pytest.mark.parametrize("setup", [oms(), omp(), opk(), omw()])
def test_RH_JW_2_jump_ends_remote_control(setup):
    m = started()
    m.receive(setup, 0.0)
    m.receive(ojw(2), 1.0)
    assert m.state() == ("N", 2, "N", 0, False) and m.check_invariants() == []


def test_RH_JW_2_jump_ends_mission_park():
    m = started()
    m.plant(WaypointReached(), 1.0)
    m.plant(WaypointReached(), 2.0)
    assert m.mode == "P"
    m.receive(ojw(3), 3.0)
    assert m.state() == ("N", 3, "N", 0, False) and m.next_deadline() is None


# ------------------------------------------------------------------------------- park


def test_RH_PK_1_park_needs_mission_ranges_and_distance():
    assert fresh().receive(opk(), 0.0) == [ack(11, 22)]
    m = started()
    assert m.receive(opk(minutes=0), 0.0) == [ack(11, 22)]
    assert m.receive(opk(lat=41.52 + 0.15), 0.0) == [ack(11, 40)]  # ~16.7 km
    assert m.receive(opk(lat=41.52 + 0.14), 0.0) == [ack(11)]  # ~15.6 km


def test_RH_PK_2_countdown_starts_on_station():
    m = started()
    m.receive(opk(minutes=2), 0.0)
    assert m.state(10.0) == ("mP", 0, "N", 120, False)
    m.plant(OnStation(), 10.0)
    assert m.osi(40.5).park_time == 90


def test_RH_PK_2_already_on_station_counts_at_once():
    m = started()
    m.receive(opk(lat=41.52, lon=-71.32, minutes=1), 0.0)
    assert m.osi(0.5).park_time == 60 and m.next_deadline() == 60.0


def test_RH_PK_3_park_time_up_resumes_mission():
    m = started()
    m.receive(opk(minutes=1), 0.0)
    m.plant(OnStation(), 5.0)
    events = m.advance(65.0)
    assert [type(e) for e in events] == [ev.ManualParkExpired, ev.ControlReleased]
    assert m.mode == "N"


# ------------------------------------------------------------------------------- $OMW


def test_RH_OMW_1_needs_mission():
    assert fresh().receive(omw(), 0.0) == [ack(16, 36)]
    assert fresh().receive(omw_clear(), 0.0) == [ack(16, 36)]


def test_RH_OMW_2_queue_in_arrival_order():
    m = started()
    a, b = omw(lat=41.53), omw(lat=41.54)
    m.receive(a, 0.0)
    m.receive(b, 1.0)
    assert m.mode == "W" and m.queue == [a, b]


@pytest.mark.parametrize("kw", ["Clr", "clr", "CLEAR", "Clear", "STOP", "stop"])
def test_RH_OMW_3_clear_keywords_release_control(kw):
    m = started()
    m.receive(omw(), 0.0)
    assert m.receive(omw_clear(kw), 1.0) == [ack(16)]
    assert m.mode == "N" and m.queue == []


def test_RH_OMW_3_clear_with_waypoint_replaces_queue_and_empty_depth2():
    m = started()
    m.receive(omw(), 0.0)
    m.receive(omw(), 0.0)
    wp = omw(lat=41.55, depth1=-3, depth2=None)
    m.receive(omw_clear("CLEAR", wp), 1.0)
    assert m.mode == "W" and m.queue == [wp]


def test_RH_OMW_3_keyword_in_N_or_P_changes_nothing():
    m = started()
    before = fingerprint(m)
    assert m.receive(omw_clear("STOP"), 1.0) == [ack(16)]
    assert fingerprint(m) == before


def test_RH_OMW_4_queue_done_resumes_mission():
    m = started()
    m.receive(omw(park_s=10), 0.0)
    m.receive(omw(), 0.0)
    m.plant(QueueWaypointReached(), 5.0)
    assert m.state(5.0) == ("W", 0, "N", 10, False)
    m.advance(15.0)
    assert m.mode == "W" and len(m.queue) == 1
    events = m.plant(QueueWaypointReached(), 20.0)
    assert [type(e) for e in events] == [ev.QueueDone, ev.ControlReleased] and m.mode == "N"


@pytest.mark.parametrize("cmd,mode", [(oms(), "A"), (omp(), "M"), (opk(), "mP"), (ojw(1), "N")])
def test_RH_OMW_5_other_control_clears_queue(cmd, mode):
    m = started()
    m.receive(omw(), 0.0)
    m.receive(cmd, 1.0)
    assert m.mode == mode and m.queue == []


# ---------------------------------------------------------------------------- missions


def test_RH_MSN_1_omload_only_in_S_and_name_rules():
    m = fresh()
    assert m.receive(omload("missing.mis"), 0.0) == [ack(2, 1)]
    assert m.receive(omload("broken.mis"), 0.0) == [ack(2, 3)]
    for bad in ("/abs.mis", "\\abs.mis", "C:x.mis", "a/../b.mis", "..\\b.mis", ""):
        assert m.receive(omload(bad), 0.0) == [ack(2, 29)], bad
    assert m.receive(omload(), 0.0) == [ack(2)] and m.loaded.name == "conformance.mis"
    m.receive(omstart_paper(0), 0.0)
    assert m.receive(omload(), 1.0) == [ack(2, 29)]


def test_RH_MSN_1_name_problem_never_reaches_catalogue():
    seen = []

    class Spy:
        def lookup(self, name):
            seen.append(name)
            return InMemoryCatalog().lookup(name)

    m = VehicleModel(DEFAULT, Spy())
    m.receive(omload("../../etc/passwd"), 0.0)
    m.receive(omstart("C:\\Missions\\a.mis"), 0.0)
    assert seen == [] and mission_name_problem("sub/ok.mis") is None


def test_RH_MSN_2_both_start_forms():
    m = fresh()
    assert m.receive(omstart_paper(0), 0.0) == [ack(3, 17)]  # nothing loaded (RH-RD-6)
    m.receive(omload(), 0.0)
    assert m.receive(omstart_paper(1), 0.0) == [ack(3)]
    assert m.state() == ("N", 0, "N", 0, False) and m.ignore_gps
    m2 = fresh()
    assert m2.receive(omstart("missing.mis"), 0.0) == [ack(3, 1)]
    assert m2.receive(omstart("broken.mis"), 0.0) == [ack(3, 3)]
    assert m2.receive(omstart("locked.mis"), 0.0) == [ack(3, 3)]
    assert m2.receive(omstart(srp="nosrp.mis"), 0.0) == [ack(3, 31)]
    assert m2.receive(omstart(srp="broken.mis"), 0.0) == [ack(3, 31)]
    assert m2.receive(omstart(srp="srp.mis", mission_type=1), 0.0) == [ack(3)]
    assert m2.state() == ("N", 0, "N", 0, True)


def test_RH_MSN_2_start_ends_primitive_from_S():
    m = fresh()
    m.receive(omp(), 0.0)
    assert m.receive(omstart(), 1.0) == [ack(3)] and m.mode == "N" and m.primitive is None


@pytest.mark.parametrize("setup", [[], [oms()], [omp()], [opk()], [omw(), omw()]])
def test_RH_MSN_3_stop_from_any_mode(setup):
    m = started()
    for c in setup:
        m.receive(c, 0.0)
    assert m.receive(omstop(), 1.0) == [ack(1)]
    assert m.state() == ("S", 0, "N", 0, False) and m.osi().actuators == "8080808080"
    assert m.queue == [] and m.next_deadline() is None


def test_RH_MSN_4_last_waypoint_ends_mission():
    m = started()
    for i in range(4):
        m.plant(WaypointReached(i), float(i))
        if m.mode == "P":
            m.advance(100.0)
    assert m.mode == "S" and not m.running
    assert m.receive(oms(), 101.0) == [ack(9, 20)]


def test_RH_MSN_4_waypoint_event_for_another_index_is_ignored():
    m = started()
    m.plant(WaypointReached(2), 1.0)
    assert m.mission_wp == 0


# ------------------------------------------------------------------------- read/write


def test_RH_POS_1_opos_in_any_mode_with_optional_fields():
    for m in (fresh(), started()):
        assert m.receive(opos(), 0.0) == [ack(6)]
        assert m.receive(s.OPOS(Decimal("41.5"), Decimal("-71.3"), Decimal("1"), None, None, True), 0.0) == [ack(6)]


def test_RH_POS_2_position_applied_only_without_gps_fix():
    m = started()
    m.receive(opos(lat=41.6, cond=30, temp=10), 0.0)
    assert m.snapshot.lat == 41.52 and m.snapshot.conductivity == 30.0
    assert m.opos_records[-1].position_applied is False
    m.plant(Submerged(4.0), 1.0)
    m.receive(opos(lat=41.6), 1.0)
    assert m.snapshot.lat == 41.6 and m.opos_records[-1].position_applied
    g = started(ignore_gps=1)
    g.receive(opos(lat=41.7), 0.0)  # at the surface but started with ignore-GPS
    assert g.snapshot.lat == 41.7


def test_RH_OSD_1_osd_order_repeats_positional_and_in_lockout():
    m = started()
    m.receive(oxflt("Sop"), 0.0)
    out = m.receive(osd("", "C", "S", "", "", "", "", ""), 1.0)
    assert [type(x) for x in out] == [s.Compass, s.OSI, s.ACK]
    out = m.receive(osd("S", "G", "S"), 1.0)
    assert [type(x) for x in out] == [s.OSI, s.GPRMC, s.OSI, s.ACK]
    assert m.receive(osd(), 1.0) == [ack(8)]


def test_RH_OSD_1_answers_by_class_name_name_the_classes_sent():
    """An observer's model answers ``$OSD`` by class name: the names must be those of the
    sentences a model answering in full sends, letter by letter, with a fix and without."""
    letters = ("S", "G", "C", "P", "D", "Y", "T", "I")
    full = VehicleModel(DEFAULT.replace(osd_letters="".join(letters)), catalog())
    named = VehicleModel(DEFAULT.replace(osd_letters="".join(letters)), catalog())
    named.data_names = True
    for m in (full, named):
        m.receive(omstart(), 0.0)
    for depth in (0.0, 4.0):  # at the surface (a fix) and submerged
        for m in (full, named):
            m.plant(Submerged(depth), 1.0)
        want = [type(x).__name__ for x in full.receive(osd(*letters), 1.0)[:-1]]
        assert named.receive(osd(*letters), 1.0)[:-1] == want
        assert want == [CLASS_OF_LETTER[x].__name__ for x in letters]


def test_RH_OSD_2_bad_letter_rejects_missing_sensor_skipped():
    m = VehicleModel(DEFAULT.replace(osd_letters="GCSP"), catalog())
    assert m.receive(osd("S", "Q"), 0.0) == [ack(8, 27)]
    out = m.receive(osd("Y", "S", "D", "T", "I"), 0.0)
    assert [type(x) for x in out] == [s.OSI, s.ACK]


def test_RH_LOG_1_labels_only_before_start():
    m = fresh()
    assert m.receive(ologl(*[f"c{i}" for i in range(12)]), 0.0) == [ack(5)]
    m.receive(omstart(), 0.0)
    assert m.receive(ologl("x"), 1.0) == [ack(5, 24)]


def test_RH_LOG_2_data_needs_labels_mission_and_count():
    m = fresh()
    m.receive(omstart(), 0.0)
    assert m.receive(ologd("1"), 0.0) == [ack(4, 25)]  # no labels
    m = fresh()
    m.receive(ologl("a", "b"), 0.0)
    assert m.receive(ologd("1"), 0.0) == [ack(4, 25)]  # no mission
    m.receive(omstart(), 0.0)
    assert m.receive(ologd("1", "", "3"), 1.0) == [ack(4, 25)]  # more values than labels
    assert m.receive(ologd("1", ""), 2.0) == [ack(4)]
    assert m.log_rows[-1].values == ("1", "") and m.log_rows[-1].labels == ("a", "b")


def test_RH_SET_1_orwset_only_before_start_and_reply_shape():
    m = fresh()
    assert m.receive(orwset("SafetyAction"), 0.0) == [ack(12, extra=("SafetyAction", "2", "1", "park"))]
    assert m.receive(orwset("Sle"), 0.0) == [ack(12, extra=("Sle", "1", "1"))]
    m.receive(omstart(), 0.0)
    assert m.receive(orwset("Sle"), 0.0) == [ack(12, 23)]


@pytest.mark.parametrize("name", SAFETY_CODES)
def test_RH_SET_2_write_then_read_returns_written(name):
    m = fresh()
    w = m.receive(orwset(name, "W", 0, "5", "x"), 0.0)
    assert w == [ack(12, extra=(name, "3", "0", "5", "x"))]
    assert m.receive(orwset(name), 1.0) == w


def test_RH_SET_2_safety_action_and_unknown_setting():
    m = fresh()
    assert m.receive(orwset("SafetyAction", "W", 1, "srp"), 0.0) == [
        ack(12, extra=("SafetyAction", "2", "1", "srp"))]
    assert m.settings.safety_action == "srp"
    assert m.receive(orwset("MaxDepth"), 0.0) == [ack(12, 23)]


def test_RH_DVL_1_dvl_any_mode_timeout_and_lockout():
    m = started()
    assert m.receive(odvl(timeout=3), 0.0) == [ack(15)]
    assert m.dvl is not None and not m.dvl_in_use  # at the surface (RH-RD-10)
    m.plant(Submerged(3.0), 1.0)
    assert m.dvl_in_use
    assert [type(e) for e in m.advance(3.0)] == [ev.DvlTimeout] and m.dvl is None
    m.receive(oxflt(), 4.0)
    assert m.receive(odvl(), 5.0) == [ack(15, 26)]
    assert fresh().receive(odvl(), 0.0) == [ack(15)]


# ------------------------------------------------------------------------------ safety


@pytest.mark.parametrize("cmd", [oms(), omp(), ojw(1), opk(), omw(), omw_clear(), omstop(), omload(),
                                 omstart(), opos(), ologl("a"), ologd("1"), orwset("Sop"), odvl()])
def test_RH_SAF_1_lockout_refuses_everything_but_osd(cmd):
    m = started()
    m.receive(oxflt("Sed"), 1.0)
    before = fingerprint(m)
    assert m.receive(cmd, 2.0) == [ack(cmd.ACK_TYPE, 26)]
    assert fingerprint(m) == before and m.osi(2.0).error_state == "Sed"


def test_RH_SAF_1_lockout_answers_26_even_for_malformed_commands():
    m = started()
    m.receive(oxflt("Sle"), 1.0)
    bad = SentenceError("RH-SRV-2", "bad", None, "range", "OMS", "heading", 9, 20)
    assert m.receive(bad, 2.0) == [ack(9, 26)]
    assert m.receive(oms(heading=999), 2.0) == [ack(9, 26)]
    bad_osd = SentenceError("RH-OSD-2", "bad", None, "syntax", "OSD", "letters", 8, 27)
    assert m.receive(bad_osd, 2.0) == [ack(8, 27)]


def test_RH_SAF_2_command_during_lockout_has_no_effect_after():
    m = started()
    m.plant(Submerged(6.0), 0.0)
    m.receive(oms(timeout=60), 0.0)
    m.receive(oxflt("Sfp"), 1.0)
    assert m.mode == "N" and m.servo is None  # control ended for good (RH-RD-11)
    m.receive(oms(), 5.0)
    m.advance(21.0)
    assert m.mode == "N" and m.servo is None


def test_RH_SAF_3_after_lockout_only_primitive_released():
    m = started()
    m.plant(Submerged(10.0), 0.0)
    m.receive(oxflt("Sup"), 1.0)
    assert m.receive(omp(), 20.9) == [ack(10, 26)]
    assert [type(e) for e in m.advance(21.0)] == [ev.SafetyRaised, ev.LockoutEnded]
    assert m.phase == "ascent"
    for cmd in (oms(), ojw(1), opk(), omw(), omw_clear()):
        assert m.receive(cmd, 22.0) == [ack(cmd.ACK_TYPE, 26)]
    assert m.receive(odvl(), 22.0) == [ack(15)]
    assert m.receive(omp(timeout=5), 22.0) == [ack(10)] and m.mode == "M"


@pytest.mark.parametrize("action,srp,expect", [
    ("park", "srp.mis", ("P", 0, "Sle", 0, False)),
    ("srp", "srp.mis", ("N", 0, "Sle", 0, True)),
    ("srp", None, ("P", 0, "Sle", 0, False)),
])
def test_RH_SAF_4_at_surface_safety_action(action, srp, expect):
    m = fresh()
    m.receive(orwset("SafetyAction", "W", 1, action), 0.0)
    m.receive(omstart(srp=srp), 0.0)
    m.plant(Submerged(8.0), 0.0)
    m.receive(oxflt("Sle"), 1.0)
    m.advance(21.0)
    assert m.phase == "ascent"
    events = m.plant(AtSurface(), 30.0)
    assert [type(e) for e in events][-1] is ev.SurfaceAction
    assert m.state(30.0) == expect and m.phase == "none"
    assert m.receive(oms(), 31.0) == [ack(9)]  # judged as in §4-6 again


def test_RH_SAF_4_no_mission_episode_ends_in_S():
    m = fresh()
    m.receive(oxflt("Spw"), 0.0)
    assert m.mode == "S" and m.phase == "lockout"
    m.advance(20.0)  # already at the surface
    assert m.phase == "none" and m.mode == "S" and m.error_state == "Spw"
    assert m.receive(omstart(), 21.0) == [ack(3)] and m.error_state == "N"


def test_RH_SAF_5_oxflt_only_when_declared_and_codes_checked():
    m = VehicleModel(DEFAULT, catalog())
    m.receive(omstart(), 0.0)
    assert m.receive(oxflt("Sle"), 0.0) == [] and m.phase == "none"
    m.plant(SafetyViolation("Sle"), 1.0)  # the vehicle itself can always raise one
    assert m.phase == "lockout"
    x = started()
    assert x.receive(oxflt("Sxx"), 0.0) == [] and x.phase == "none"
    assert x.receive(oxflt("Sti"), 0.0) == [] and x.phase == "lockout"
    assert x.receive(oxflt("Sop"), 10.0) == [] and x.error_state == "Sop"
    assert x.next_deadline() == 30.0  # a new violation restarts the lockout (RH-RD-11)


# -------------------------------------------------------------------------------- time


def test_RH_TIM_1_durations_count_from_processing_instant():
    m = started()
    m.receive(oms(timeout=7), 3.25)
    assert m.next_deadline() == pytest.approx(10.25)
    m.receive(oxflt(), 11.0)
    assert m.next_deadline() == pytest.approx(31.0)


def test_RH_TIM_2_model_runs_on_vehicle_time_unscaled():
    """An emulator at time scale k passes k × wall seconds; durations in the model never scale."""
    m = started(oxflt_profile(time_scale=20.0))
    m.receive(oms(timeout=10), 0.0)
    assert m.next_deadline() == 10.0


def test_model_package_does_no_io_and_reads_no_clock():
    forbidden = {"time", "serial", "threading", "asyncio", "socket", "os", "subprocess"}
    for path in Path(__import__("helmcheck.model").model.__file__).parent.glob("*.py"):
        if path.name == "docs.py":
            continue  # the docs generator writes files; it is not part of the model
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            names = []
            if isinstance(node, ast.Import):
                names = [a.name.split(".")[0] for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module.split(".")[0]]
            assert not forbidden & set(names), (path.name, names)


def test_time_never_goes_backwards():
    m = started()
    m.receive(oms(timeout=5), 10.0)
    m.receive(osd("S"), 3.0)  # taken as t=10
    assert m.now == 10.0 and m.next_deadline() == 15.0


def test_missions_need_waypoints():
    with pytest.raises(ValueError):
        Mission("empty.mis", ())
    assert Mission("one.mis", [Waypoint(0, 0)]).last == 0


def test_a_clone_and_its_original_keep_their_own_histories():
    """``clone`` shares the bounded histories until one side writes (copy on write): an
    ``$OPOS`` or a log row on either side never shows on the other (RH-POS-1, RH-LOG-2)."""
    m = started()
    m.receive(opos(), 1.0)
    c = m.clone()
    c.receive(opos(), 2.0)
    m.receive(ologl("a", "b"), 2.0)
    assert (len(m.opos_records), len(c.opos_records)) == (1, 2)
    m2 = fresh()
    m2.receive(ologl("a", "b"), 0.0)
    m2.receive(omstart(), 0.5)
    d = m2.clone()
    d.receive(ologd("1", "2"), 1.0)
    assert (len(m2.log_rows), len(d.log_rows)) == (0, 1)
    m2.receive(ologd("3", "4"), 1.0)
    assert [r for r in m2.log_rows] != [r for r in d.log_rows] and len(m2.log_rows) == 1
