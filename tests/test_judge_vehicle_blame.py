"""Where the vehicle judge books a fault it sees: the clause that says what the vehicle did wrong.

Short hand-made wire logs (the exact bytes a vehicle and a backseat could exchange), checked
offline with ``check_log`` — the observer ``certify vehicle`` uses too. Each fault has a
conforming counterpart that passes the same clause:

* a command accepted with a field out of its range — whether the grammar (ten hex digits, an
  integer timeout) or the range check finds it — is booked on the clause that sets the range
  (docs/choices.md, "Error clauses"), not only on RH-ACK-3;
* an ``$OPK`` park that counts down before the vehicle is on station is RH-PK-2's FAIL, judged from
  what each report shows (field 7, the distance; field 10, the park time), even where the mirror
  has lost the vehicle's state; a vehicle that arrived between two reports and drifted a little
  since is not failed;
* released from remote control, a vehicle that heads for the waypoint after the one it was heading
  for (it cannot have reached that one in the time) fails RH-INT-2 — and not the clause of what
  released it, which it did; one still under remote control fails that clause, not RH-INT-2; one
  that was close to the waypoint, or was driven close to it under remote control, and reaches it
  passes.
"""

from __future__ import annotations


import pytest

from helmcheck.checklog.checker import check_log
from helmcheck.profile import DEFAULT
from tests.test_judge_vehicle_readings import LAT, LON, poll, write  # the hand-made wire logs

PROFILE = DEFAULT
#: a point about 166 m east of (LAT, LON)
FAR_LON = LON + 0.002


def send(t: float, body: str, ack: str) -> list[tuple]:
    return [(t, ">", body), (t + 0.01, "<", ack)]


def start(t: float = 0.0, dist: float = 150.0) -> list[tuple]:
    """The test mission started: N, heading for waypoint 0, ``dist`` metres from it."""
    return (poll(t, mode="S") + send(t + 0.1, "OMSTART,0,0,0,0,conformance.mis,", "ACK,3,0,0")
            + poll(t + 0.2, mode="N", dist=dist, speed=2.0))


def judge(tmp_path, records) -> dict:
    out = check_log(write(tmp_path, records), profile=PROFILE, role="vehicle")
    return {c["id"]: c for c in out.clauses}


def verdict(v: dict, cid: str) -> str:
    return v[cid]["verdict"]


def failed(v: dict) -> set:
    return {c for c, e in v.items() if e["verdict"] in ("fail", "non-strict")}


# ============================================================ a range's clause (RH-PRM-2 and kin)

@pytest.mark.parametrize("cmd,clause,mode", [
    ("OMP,808080808,00,10", "RH-PRM-2", "M"),      # nine hex digits (the grammar finds it)
    ("OMP,80808080GG,00,10", "RH-PRM-2", "M"),     # not hex
    ("OMP,8080808080,00,1.5", "RH-PRM-2", "M"),    # a timeout that is not an integer
    ("OMP,8080808080,01,10", "RH-PRM-2", "M"),     # field 2 is not 00 (the range check finds it)
    ("OMP,8080808080,00,0", "RH-PRM-2", "M"),
    ("OMP,8080808080,00,121", "RH-PRM-2", "M"),
    ("OMS,90,2,20,1,1.5", "RH-SRV-2", "A"),        # the analogous ranges
    ("OMS,90,2,20,1,121", "RH-SRV-2", "A"),
    (f"OPK,{LAT},{LON},1.5,1", "RH-PK-1", "mP"),
    (f"OPK,{LAT},{LON},0,1", "RH-PK-1", "mP"),
    ("OJW,1.5", "RH-JW-1", "N"),
    ("OJW,-1", "RH-JW-1", "N"),
])
def test_a_value_out_of_range_accepted_is_booked_on_the_clause_that_sets_the_range(tmp_path, cmd, clause, mode):
    ack_type = {"OMP": 10, "OMS": 9, "OPK": 11, "OJW": 7}[cmd[:3]]
    rec = start() + send(1.0, cmd, f"ACK,{ack_type},0,0") + poll(1.5, mode=mode, dist=150.0, speed=1.0)
    v = judge(tmp_path, rec)
    assert verdict(v, clause) == "fail", v[clause]
    assert "a conforming vehicle" in v[clause]["reason"]
    assert verdict(v, "RH-ACK-3") != "fail", v["RH-ACK-3"]  # the range's own clause, not only RH-ACK-3


@pytest.mark.parametrize("cmd,ack_type,mode", [
    ("OMP,8080808080,00", 10, "M"),                 # a field count: RH-ACK-3's own
    (f"OPOS,{LAT},{LON},9,,", 6, "N"),              # ranges only a reading sets (RH-RD-9)
    ("ODVL,9,0,5", 15, "N"),
    (f"OMW,{LAT},{LON},2,,15,1,-1,", 16, "W"),
])
def test_a_field_count_or_a_range_only_a_reading_sets_stays_RH_ACK_3(tmp_path, cmd, ack_type, mode):
    rec = start() + send(1.0, cmd, f"ACK,{ack_type},0,0") + poll(1.5, mode=mode, dist=150.0, speed=1.0)
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-ACK-3") == "fail", v["RH-ACK-3"]


@pytest.mark.parametrize("control,mode", [("OMP,8080808080,00,60", "M"), ("OMS,90,2,20,0,60", "A")])
def test_an_OJW_past_the_last_waypoint_accepted_under_remote_control_is_RH_JW_1(tmp_path, control, mode):
    """The range of n is RH-JW-1's, whatever control the $OJW meets (the row under M is RH-JW-2's:
    it ends remote control): a data check's clause, not the row's (the traceability table)."""
    ack = {"M": "ACK,10,0,0", "A": "ACK,9,0,0"}[mode]
    rec = start() + send(0.5, control, ack) + poll(0.7, mode=mode, dist=150.0, speed=1.0)
    v = judge(tmp_path, rec + send(1.0, "OJW,4", "ACK,7,0,0") + poll(1.5, mode="N", wp=3, dist=150.0, speed=1.0))
    assert verdict(v, "RH-JW-1") == "fail", v["RH-JW-1"]
    assert verdict(v, "RH-JW-2") != "fail", v["RH-JW-2"]


@pytest.mark.parametrize("labels,mission,cmd,ack_type,clause", [
    ("", False, "OLOGL,1,2,3,4,5,6,7,8,9,10,11,12,13", 5, "RH-LOG-1"),   # 13 labels: RH-LOG-1's 1–12
    ("", False, "OLOGL,a,,b", 5, "RH-LOG-1"),                              # an empty label (RH-RD-9)
    ("OLOGL,1,2,3,4,5,6,7,8,9,10,11,12", True, "OLOGD,1,2,3,4,5,6,7,8,9,10,11,12,13", 4, "RH-LOG-2"),
])
def test_a_count_a_clause_states_accepted_is_booked_on_that_clause(tmp_path, labels, mission, cmd, ack_type,
                                                                   clause):
    """A count the grammar refuses where a clause states it (``$OLOGL`` 1–12 labels, ``$OLOGD`` 12
    values) is that clause's rule broken, not only RH-ACK-3's "wrong number of fields" (the
    traceability table); a conforming refusal passes it."""
    rec = poll(0.0, mode="S")
    if labels:
        rec += send(0.1, labels, "ACK,5,0,0")
    rec += (send(0.2, "OMSTART,0,0,0,0,conformance.mis,", "ACK,3,0,0") + poll(0.3, mode="N", dist=150.0, speed=2.0)
            if mission else [])
    bad = rec + send(1.0, cmd, f"ACK,{ack_type},0,0") + poll(1.5, mode="N" if mission else "S", dist=150.0)
    v = judge(tmp_path, bad)
    assert verdict(v, clause) == "fail", v[clause]
    assert verdict(v, "RH-ACK-3") != "fail", v["RH-ACK-3"]
    assert "(related: RH-ACK-3)" in v[clause]["reason"], v[clause]["reason"]  # named, not booked
    ok = rec + send(1.0, cmd, f"ACK,{ack_type},1,{24 if ack_type == 5 else 25}") + poll(1.5, mode="N" if mission else "S",
                                                                                     dist=150.0)
    (tmp_path / "ok").mkdir()
    v = judge(tmp_path / "ok", ok)
    assert verdict(v, clause) != "fail", v[clause]


@pytest.mark.parametrize("cmd,answer,clause", [
    ("OMSTART,0,0,0,0,sub/../../conformance.mis,", "ACK,3,1,1", "RH-MSN-1"),   # followed out: not found
    ("OMSTART,0,0,0,0,../conformance.mis,", "ACK,3,0,0", "RH-MSN-1"),        # accepted
    ("OMSTART,0,0,0,0,conformance.mis,../srp.mis", "ACK,3,0,0", "RH-MSN-1"),  # the SRP name too (30 or 31:
    # both readings, helmcheck/model/readings.py srp_bad_path; accepted is neither)
    ("OMLOAD,sub/../../x.mis,0", "ACK,2,1,1", "RH-MSN-1"),
    ("OMLOAD,../conformance.mis,0", "ACK,2,0,0", "RH-MSN-1"),
    ("OMLOAD,/etc/x.mis,0", "ACK,2,1,30", "RH-ACK-3"),    # a wrong number only: RH-ACK-3, as elsewhere
    ("OMSTART,2,0,0,0,conformance.mis,", "ACK,3,0,0", "RH-MSN-2"),            # a flag not 0 or 1
])
def test_an_OMSTART_name_or_flag_the_reading_RH_RD_6_rules_out_is_booked_on_the_clause_it_reads(
        tmp_path, cmd, answer, clause):
    """RH-RD-6 spells out the rh5 ``$OMSTART``: its mission name follows RH-MSN-1's path rules (err
    30), its flags are RH-MSN-2's; an SRP name outside the directory may be refused with 30 or 31
    (the readings table), never accepted. A reading is not booked; the clause it reads is, not only
    RH-ACK-3. A name the path rules reject, answered with a look-up's error (1), was looked up, not
    rejected: RH-MSN-1; any other wrong number is RH-ACK-3's, as for every command."""
    rec = poll(0.0, mode="S") + send(0.1, cmd, answer) + poll(0.5, mode="S")
    v = judge(tmp_path, rec)
    assert verdict(v, clause) == "fail", v[clause]
    ok = poll(0.0, mode="S") + send(0.1, cmd, "ACK,2,1,29" if cmd.startswith("OMLOAD") else "ACK,3,1,30")
    ok += poll(0.5, mode="S")
    (tmp_path / "ok").mkdir()
    v = judge(tmp_path / "ok", ok)
    assert verdict(v, clause) != "fail", v[clause]


def test_inside_an_RH_ACK_3_case_the_same_fault_is_the_case_s(tmp_path):
    rec = start() + [(0.5, "!", "case V-12 RH-ACK-3: bad fields")]
    rec += send(1.0, "OMP,808080808,00,10", "ACK,10,0,0") + poll(1.5, mode="M", dist=150.0)
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-ACK-3") == "fail"
    assert verdict(v, "RH-PRM-2") != "fail"


def test_out_of_range_OMP_refused_with_err_21_passes_RH_PRM_2(tmp_path):
    rec = start()
    for i, cmd in enumerate(("OMP,808080808,00,10", "OMP,80808080GG,00,10", "OMP,8080808080,01,10",
                             "OMP,8080808080,00,0", "OMP,8080808080,00,121")):
        rec += send(1.0 + i, cmd, "ACK,10,1,21")
    rec += poll(7.0, mode="N", dist=140.0, speed=2.0)
    v = judge(tmp_path, rec)
    assert failed(v) == set()
    assert verdict(v, "RH-PRM-2") == "pass"


def test_out_of_range_OMP_refused_with_a_wrong_error_number_is_RH_ACK_3(tmp_path):
    rec = start() + send(1.0, "OMP,808080808,00,10", "ACK,10,1,20") + poll(1.5, mode="N", dist=148.0)
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-ACK-3") == "fail"  # refused, as RH-PRM-2 wants, with another command's error
    assert verdict(v, "RH-PRM-2") != "fail"


# ============================================================ RH-PK-2: counting before on station

def opk(t: float = 1.0, lon: float = FAR_LON, minutes: int = 2) -> list[tuple]:
    return send(t, f"OPK,{LAT:.6f},{lon:.6f},{minutes},1", "ACK,11,0,0")


def test_RH_PK_2_a_count_begun_off_station_fails_even_with_the_state_unknown(tmp_path):
    """The record begins with the vehicle under servo control (a capture started mid-run): the
    mirror cannot know its state, and the $OPK's acceptance and the reports are not judged
    against it. What each report shows still proves the fault: 166 m from the park position, no
    report on station since the $OPK, and field 10 has counted from it."""
    rec = poll(0.0, mode="A", dist=0.0, speed=2.0)
    rec += opk()
    rec += poll(1.5, mode="mP", park=120, dist=166.0, speed=2.0)
    rec += poll(5.5, mode="mP", park=116, dist=164.0, speed=2.0)
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-PK-2") == "fail", v["RH-PK-2"]
    assert "not on station" in v["RH-PK-2"]["reason"]


def test_RH_PK_2_a_count_begun_off_station_fails_and_is_not_explained_away(tmp_path):
    """In step with the vehicle, the mirror does not explain the count by an unseen "on station"
    the same report's field 7 rules out (RH-OUT-4 fails too)."""
    rec = start() + opk()
    rec += poll(1.5, mode="mP", park=120, dist=166.0, speed=2.0)
    rec += poll(3.5, mode="mP", park=118, dist=165.0, speed=2.0)
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-PK-2") == "fail"
    assert "not on station" in v["RH-PK-2"]["reason"]
    assert verdict(v, "RH-OUT-4") == "fail"


def test_RH_PK_2_a_count_begun_when_an_earlier_report_shows_the_vehicle_far_fails(tmp_path):
    """A minute of count shown 100 m away: the report alone allows that the vehicle arrived and
    drifted off at full speed since; the report made when the count began (166 m away) does not."""
    rec = start() + opk()
    rec += poll(1.5, mode="mP", park=120, dist=166.0, speed=4.0)
    rec += poll(61.5, mode="mP", park=60, dist=100.0, speed=4.0)
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-PK-2") == "fail", v["RH-PK-2"]
    assert "166 m away" in v["RH-PK-2"]["reason"]


def test_RH_PK_2_a_count_longer_than_the_time_since_the_OPK_fails(tmp_path):
    """On station at once, 20 s counted a second after the $OPK: the count did not begin at
    minutes×60. The $OPK's acceptance (RH-PK-1) was right: its ACK settled that."""
    rec = start(dist=150.0) + send(1.0, f"OPK,{LAT:.6f},{LON:.6f},2,1", "ACK,11,0,0")
    rec += poll(2.0, mode="mP", park=100, dist=0.5)
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-PK-2") == "fail"
    assert verdict(v, "RH-PK-1") != "fail", v["RH-PK-1"]


def test_RH_PK_2_the_first_report_after_the_OPK_counting_off_station_is_not_RH_PK_1(tmp_path):
    rec = start() + opk() + poll(21.0, mode="mP", park=100, dist=150.0, speed=1.0)
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-PK-2") == "fail"
    assert verdict(v, "RH-PK-1") != "fail", v["RH-PK-1"]


def test_RH_PK_2_arriving_then_counting_on_station_passes(tmp_path):
    """The conforming park: on its way (P120), on station (≤ 3 m, still P120 or just begun),
    then counting down."""
    rec = start() + opk()
    rec += poll(1.5, mode="mP", park=120, dist=166.0, speed=2.0)
    rec += poll(30.0, mode="mP", park=120, dist=110.0, speed=4.0)
    rec += poll(80.0, mode="mP", park=120, dist=2.9, lon=FAR_LON, speed=0.5)
    rec += poll(85.0, mode="mP", park=116, dist=1.0, lon=FAR_LON, speed=0.0)
    rec += poll(95.0, mode="mP", park=106, dist=3.5, lon=FAR_LON, speed=0.3)  # drifted a little
    v = judge(tmp_path, rec)
    assert failed(v) == set(), {c: v[c]["reason"] for c in failed(v)}
    assert verdict(v, "RH-PK-2") == "pass"


def test_RH_PK_2_arriving_between_two_reports_and_drifting_a_little_is_not_failed(tmp_path):
    """20 m away, then (20 s later) 10 s into the count and 3.8 m away: it can have arrived ~10 s
    ago and drifted — the profile does not say a vehicle must stay within 3 m while it counts."""
    rec = start() + opk()
    rec += poll(1.5, mode="mP", park=120, dist=20.0, speed=1.0)
    rec += poll(21.5, mode="mP", park=110, dist=3.8, speed=0.3)
    v = judge(tmp_path, rec)
    assert failed(v) == set(), {c: v[c]["reason"] for c in failed(v)}


# ============================================================ RH-INT-2: released to the same waypoint

def servo(t: float = 1.0, speed: int = 0) -> list[tuple]:
    """An $OMS of 10 s (released at about t + 10) polled twice in A."""
    return (send(t, f"OMS,90,2,20,{speed},10", "ACK,9,0,0") + poll(t + 1.0, mode="A", speed=speed)
            + poll(t + 9.5, mode="A", speed=speed))


def test_RH_INT_2_released_toward_the_next_waypoint_fails(tmp_path):
    """150 m from waypoint 0 when the servo took over, at most 4.5 kn and stopped under it: the
    report right after the release cannot be heading for waypoint 1 of a mission that resumed."""
    rec = start() + poll(0.5, mode="N", wp=0, dist=150.0, speed=2.0) + servo()
    rec += poll(12.0, mode="N", wp=1, dist=140.0, speed=2.0)
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-INT-2") == "fail", v["RH-INT-2"]
    assert verdict(v, "RH-OUT-4") == "fail"
    assert "next waypoint 1" in v["RH-INT-2"]["reason"]
    # the servo control did end, as RH-SRV-4 says: what it resumed is RH-INT-2's alone
    assert verdict(v, "RH-SRV-4") != "fail", v["RH-SRV-4"]


def clear(t: float) -> list[tuple]:
    """Under servo control (A, polled), ``$OMW,Clr`` accepted: a release (RH-OMW-3)."""
    return (send(t, "OMS,90,2,20,0,60", "ACK,9,0,0") + poll(t + 0.5, mode="A", speed=0)
            + send(t + 1.0, "OMW,Clr", "ACK,16,0,0"))


def test_RH_INT_2_released_by_OMW_Clr_toward_the_next_waypoint_is_RH_INT_2_not_RH_OMW_3(tmp_path):
    """``$OMW,Clr`` ended the servo control (mode N, as RH-OMW-3 says) but the vehicle heads for
    waypoint 1 where it was heading for waypoint 0, 150 m off: RH-INT-2 fails, RH-OMW-3 does not."""
    rec = start() + poll(0.5, mode="N", wp=0, dist=150.0, speed=2.0) + clear(1.0)
    rec += poll(2.5, mode="N", wp=1, dist=140.0, speed=2.0)
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-INT-2") == "fail", v["RH-INT-2"]
    assert verdict(v, "RH-OMW-3") != "fail", v["RH-OMW-3"]


def test_RH_OMW_3_still_under_servo_control_after_OMW_Clr_is_RH_OMW_3_not_RH_INT_2(tmp_path):
    """``$OMW,Clr`` accepted and the vehicle still in A: control did not end (RH-OMW-3); what it
    resumes when it ends (RH-INT-2) is not in question."""
    rec = start() + poll(0.5, mode="N", wp=0, dist=150.0, speed=2.0) + clear(1.0)
    rec += poll(2.5, mode="A", speed=0)
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-OMW-3") == "fail", v["RH-OMW-3"]
    assert verdict(v, "RH-INT-2") != "fail", v["RH-INT-2"]


def test_released_toward_the_next_waypoint_then_taken_again_by_OMS_is_still_RH_INT_2(tmp_path):
    """``$OMW,Clr`` released the servo control, and an ``$OMS`` right after it (no report between)
    took control again: the report in A shows the frozen waypoint 1 where 0 was owed. The vehicle
    is in a remote mode the release ends, but not still in it: RH-INT-2 stays among the clauses."""
    rec = start() + poll(0.5, mode="N", wp=0, dist=150.0, speed=2.0) + clear(1.0)
    rec += send(1.2, "OMS,90,2,20,0,60", "ACK,9,0,0") + poll(2.5, mode="A", wp=1, speed=0)
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-INT-2") == "fail", v["RH-INT-2"]


def test_RH_OMW_3_released_as_it_should_passes_both(tmp_path):
    """The conforming counterpart: released toward waypoint 0."""
    rec = start() + poll(0.5, mode="N", wp=0, dist=150.0, speed=2.0) + clear(1.0)
    rec += poll(2.5, mode="N", wp=0, dist=149.0, speed=2.0)
    v = judge(tmp_path, rec)
    assert failed(v) == set(), {c: v[c]["reason"] for c in failed(v)}
    assert verdict(v, "RH-OMW-3") == "pass" and verdict(v, "RH-INT-2") == "pass"


def test_RH_INT_2_released_toward_the_next_waypoint_fails_in_its_case(tmp_path):
    rec = start() + poll(0.5, mode="N", wp=0, dist=150.0, speed=2.0)
    rec += [(0.6, "!", "case V-22 RH-INT-2: Control released to the mission")] + servo()
    rec += poll(12.0, mode="N", wp=1, dist=140.0, speed=2.0) + [(12.5, "!", "case V-22 end")]
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-INT-2") == "fail"


def test_RH_OUT_4_a_mission_waypoint_skipped_between_two_reports_fails(tmp_path):
    """The same physics without remote control: 150 m from waypoint 0, a second later heading
    for waypoint 1."""
    rec = start() + poll(1.2, mode="N", wp=1, dist=140.0, speed=2.0)
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-OUT-4") == "fail"


@pytest.mark.parametrize("seen_at_0", [True, False], ids=["seen-heading-for-it", "reached-between-reports"])
def test_RH_INT_2_released_near_the_waypoint_and_reaching_it_passes(tmp_path, seen_at_0):
    """5 m from waypoint 0 at takeover: released, it reaches it (seen heading for it first, or
    not) and goes on to waypoint 1 — conforming."""
    rec = start(dist=5.0) + poll(0.5, mode="N", wp=0, dist=5.0, speed=2.0) + servo()
    if seen_at_0:
        rec += poll(11.5, mode="N", wp=0, dist=4.0, speed=2.0)
    rec += poll(14.0, mode="N", wp=1, dist=140.0, speed=2.0)
    v = judge(tmp_path, rec)
    assert failed(v) == set(), {c: v[c]["reason"] for c in failed(v)}
    assert verdict(v, "RH-INT-2") == "pass"


def test_RH_INT_2_driven_near_the_waypoint_under_remote_control_and_reaching_it_passes(tmp_path):
    """150 m from waypoint 0 at takeover, but a 70 s servo at 4.5 kn drove the vehicle 149.9 m
    east (its reported positions show it): released next to the waypoint, it reaches it at once.
    The mission is frozen under remote control (RH-RD-5), the vehicle is not: the time it had to
    get there runs from the report of its distance, not from the release."""
    east = LON + 0.0017962  # ~149.9 m east of LON at this latitude
    rec = start() + poll(0.5, mode="N", wp=0, dist=150.0, speed=2.0)
    rec += send(1.0, "OMS,90,2,20,4.5,70", "ACK,9,0,0") + poll(2.0, mode="A", speed=4.5, lon=LON + 0.00002)
    rec += poll(70.5, mode="A", speed=4.5, lon=east)
    rec += poll(72.0, mode="N", wp=1, dist=140.0, speed=2.0, lon=east)
    v = judge(tmp_path, rec)
    assert failed(v) == set(), {c: v[c]["reason"] for c in failed(v)}
    assert verdict(v, "RH-INT-2") == "pass"


# ============================================================ RH-INT-1: one remote control takes over from another

def test_RH_INT_1_an_OMP_refused_under_servo_control_is_booked_on_RH_INT_1(tmp_path):
    """Under ``$OMS`` control (A) a conforming vehicle accepts ``$OMP`` (any remote command
    interrupts any other, RH-INT-1); refusing it breaks RH-INT-1 first, not RH-PRM-1 (which says
    only that ``$OMP`` is accepted from ``S`` too)."""
    rec = start() + send(1.0, "OMS,90,2,20,1,30", "ACK,9,0,0") + poll(1.5, mode="A", dist=148.0, speed=2.0)
    rec += send(2.0, "OMP,8080808080,00,10", "ACK,10,1,21") + poll(2.5, mode="A", dist=147.0, speed=2.0)
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-INT-1") == "fail", v["RH-INT-1"]


def test_RH_PRM_1_an_OMP_refused_in_S_stays_RH_PRM_1(tmp_path):
    rec = poll(0.0, mode="S") + send(1.0, "OMP,8080808080,00,10", "ACK,10,1,21") + poll(1.5, mode="S")
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-PRM-1") == "fail", v["RH-PRM-1"]
    assert verdict(v, "RH-INT-1") != "fail"


# ============================================================ RH-SAF-1: field 8 in the lockout and after it

def test_RH_SAF_1_a_safety_code_cleared_while_every_explanation_keeps_it_is_booked_on_RH_SAF_1(tmp_path):
    """After ``$OXFLT`` field 8 shows the code in the lockout (RH-SAF-1) and keeps it after
    (RH-RD-13, a reading booked on RH-SAF-1); a report with ``N`` there, a few seconds in, breaks
    RH-SAF-1, not only RH-OUT-4 (the conforming counterpart keeps it and passes)."""
    from helmcheck.profile import emulator_profile

    def run(err_later: str) -> dict:
        rec = start() + [(1.0, ">", "OXFLT,Sle")] + poll(1.5, mode="N", dist=149.0, err="Sle", speed=2.0)
        rec += poll(5.0, mode="N", dist=149.0, err=err_later, speed=2.0)
        out = check_log(write(tmp_path, rec), profile=emulator_profile(), role="vehicle")
        return {c["id"]: c for c in out.clauses}

    v = run("N")
    assert verdict(v, "RH-SAF-1") == "fail", v["RH-SAF-1"]
    assert verdict(run("Sle"), "RH-SAF-1") != "fail"


def test_RH_SAF_4_a_violation_in_S_needs_no_visible_action_at_the_surface(tmp_path):
    """A violation raised in ``S`` under water: the lockout, the ascent, the surface — and ``S``
    all along, which is what a conforming vehicle shows (RH-SAF-4's action changes nothing a
    report shows there): no RH-SAF-4 finding however long it stays."""
    from helmcheck.profile import emulator_profile
    rec = poll(0.0, mode="S", depth=0.9) + [(0.5, ">", "OXFLT,Sop")]
    t = 1.0
    while t < 40.0:
        depth = 0.8 if t < 21.0 else max(0.0, 0.8 - (t - 21.0) * 0.3)
        rec += poll(t, mode="S", err="Sop", depth=depth)
        t += 0.5
    out = check_log(write(tmp_path, rec), profile=emulator_profile(), role="vehicle")
    v = {c["id"]: c for c in out.clauses}
    assert verdict(v, "RH-SAF-4") != "fail", v["RH-SAF-4"]
    assert not failed(v), {c: v[c]["reason"] for c in failed(v)}


# ============================================================ the clause that states the rule leads

def test_RH_PRM_2_an_OMP_in_lower_case_hex_refused_is_RH_PRM_2_s_not_the_case_s(tmp_path):
    """RH-PRM-2 says hex case is free on input: an ``$OMP`` in lower-case hex refused with its
    "incorrect values" error (21) breaks RH-PRM-2 — inside a case about RH-PRM-3 (which the
    refusal does not speak to) and outside one (not RH-PRM-1, the accepting row's first clause).
    The same line in upper case, accepted, fails nothing."""
    case = [(0.9, "!", "case V-31 RH-PRM-3: $OSI echoes the commanded fins and motor")]
    for within in ([], case):
        rec = poll(0.0, mode="S") + within + send(1.0, "OMP,8a8a767690,00,10", "ACK,10,1,21") + poll(1.5, mode="S")
        v = judge(tmp_path, rec)
        assert failed(v) == {"RH-PRM-2"}, {c: v[c]["reason"] for c in failed(v)}
    good = poll(0.0, mode="S") + case + send(1.0, "OMP,8A8A767690,00,10", "ACK,10,0,0") + poll(
        1.5, mode="M", act="8A8A767690")
    v = judge(tmp_path, good)
    assert not failed(v), {c: v[c]["reason"] for c in failed(v)}


def test_an_upper_case_OMP_refused_with_a_precondition_error_is_not_RH_PRM_2(tmp_path):
    """The form leads only where the line is written in it: an ``$OMP`` in upper case refused in
    ``S`` is RH-PRM-1's (accepted from S too), whatever its error number."""
    rec = poll(0.0, mode="S") + send(1.0, "OMP,8A8A767690,00,10", "ACK,10,1,21") + poll(1.5, mode="S")
    v = judge(tmp_path, rec)
    assert failed(v) == {"RH-PRM-1"}, {c: v[c]["reason"] for c in failed(v)}


def test_RH_SAF_1_an_OSD_refused_in_the_lockout_is_RH_SAF_1_s_then_RH_OSD_1_s(tmp_path):
    """RH-SAF-1: every command but ``$OSD`` is refused in the lockout; RH-OSD-1: ``$OSD`` is
    accepted in every mode, including the lockout. An ``$OSD`` refused there (26) breaks both,
    RH-SAF-1 first — not a neighbour the case is about (RH-ACK-5 here). Served, it fails nothing."""
    from helmcheck.profile import emulator_profile

    def run(answer: list) -> dict:
        rec = start() + [(1.0, ">", "OXFLT,Sle")] + poll(1.5, mode="N", dist=149.0, err="Sle", speed=2.0)
        rec += [(1.9, "!", "case V-99 RH-ACK-5: data before the ACK"), (2.0, ">", "OSD,S")] + answer
        out = check_log(write(tmp_path, rec), profile=emulator_profile(), role="vehicle")
        return {c["id"]: c for c in out.clauses}

    from tests.test_judge_vehicle_readings import osi
    v = run([(2.01, "<", "ACK,8,1,26")])
    assert failed(v) == {"RH-SAF-1", "RH-OSD-1"}, {c: v[c]["reason"] for c in failed(v)}
    assert "$ACK,8,1,26" in v["RH-SAF-1"]["reason"], v["RH-SAF-1"]["reason"]
    v = run([(2.01, "<", osi(mode="N", dist=149.0, err="Sle", speed=2.0)), (2.02, "<", "ACK,8,0,0")])
    assert not failed(v), {c: v[c]["reason"] for c in failed(v)}


def test_the_lockout_s_exception_is_derived_from_the_transition_table():
    """RH-SAF-1's "except $OSD" is read from the table's lockout rows (every command event but one
    refused with 26 under one clause), not written by hand; the ascent's refusals (some control
    commands, RH-SAF-3) name no exception."""
    from helmcheck.judge.vehicle.blame import phase_exceptions

    assert phase_exceptions() == {("OSD", "lockout"): ("RH-SAF-1", "RH-OSD-1")}


def test_RH_OMW_3_an_OMW_with_an_empty_depth_2_refused_is_RH_OMW_3_s(tmp_path):
    """RH-OMW-3 says depth 2 may be empty: an ``$OMW`` written so, refused with 36 while a mission
    runs, breaks RH-OMW-3 — not RH-OMW-1 (the accepting row's first clause: accepted while a
    mission runs, which it is)."""
    rec = start() + send(1.0, f"OMW,{LAT},{FAR_LON},2,,15,1,0,", "ACK,16,1,36") + poll(1.5, mode="N", dist=149.0,
                                                                                    speed=2.0)
    v = judge(tmp_path, rec)
    assert failed(v) == {"RH-OMW-3"}, {c: v[c]["reason"] for c in failed(v)}


# ===================================== a lockout's after-effect: RH-SAF-2's, also inside RH-SAF-1's case

@pytest.mark.parametrize("replayed", [True, False])
def test_a_command_refused_in_the_lockout_carried_out_after_it_is_RH_SAF_2_even_in_the_lockout_s_case(
        tmp_path, replayed):
    """Inside the lockout's own case (V-58, RH-SAF-1) a servo control that comes back after the
    lockout — the $OMS the lockout refused, carried out when it ended — broke RH-SAF-2's rule ("a
    command sent during the lockout has no effect even after the lockout ends"; the traceability
    table): booked there, RH-SAF-1 named as related, not failed. A vehicle that stays in N passes."""
    rec = start() + [(0.5, "!", "case V-58 RH-SAF-1: The lockout refuses everything but $OSD for lockout_s")]
    rec += poll(1.0, mode="N", err="Sfp", dist=150.0)  # a violation the vehicle raised by itself
    rec += [(1.5, ">", "OMS,90,2,20,0.5,60"), (1.51, "<", "ACK,9,1,26")]
    rec += poll(2.0, mode="N", err="Sfp", dist=150.0)
    rec += poll(30.0, mode="A" if replayed else "N", err="Sfp", dist=150.0, speed=0.5)  # the lockout over
    v = judge(tmp_path, rec)
    if replayed:
        assert verdict(v, "RH-SAF-2") == "fail", v["RH-SAF-2"]
        assert verdict(v, "RH-SAF-1") != "fail", v["RH-SAF-1"]
        related = v["RH-SAF-2"]["reason"].rpartition("(related: ")[2]
        assert "RH-SAF-1" in related, v["RH-SAF-2"]["reason"]
    else:
        assert not failed(v), {c: v[c]["reason"] for c in failed(v)}
