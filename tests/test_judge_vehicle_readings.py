"""The vehicle observer on hand-made sessions: how it reads what the wire shows.

Each test is a short wire log written by hand — the exact bytes a vehicle and a backseat could
exchange — checked offline with ``check_log`` (the observer ``certify vehicle`` uses too). The
cases are the readings an observer gets wrong easily: motion it cannot see, happening between
two polls; a violation the vehicle raises by itself; an answer that comes after the tester gave
up; a line that must be discarded but is answered; an ``$OSD`` letter outside the alphabet.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from helmcheck.judge.spoil import REPEAT

from helmcheck.checklog.checker import check_log
from helmcheck.grammar import checksum_hex
from helmcheck.grammar.wirelog import escape
from helmcheck.profile import DEFAULT

PROFILE = DEFAULT  # no $OXFLT: a violation can only come from the vehicle itself
LAT, LON = 41.520000, -71.320000


def osi(mode: str, wp: int = 0, park: int = 0, err: str = "N", lat: float = LAT, lon: float = LON,
        dist: float = 0.0, depth: float = 0.0, act: str = "8080808080", speed: float = 0.0,
        mission: str = "conformance.mis") -> str:
    return (f"OSI,{act},{mode},{wp},{lat:.8f},{lon:.8f},{speed:.2f},{dist:.2f},{err},38.00,P{park},-14.5000,"
            f"{mission},4.5,75.5,{depth:.2f},94.3,False,IVER3-EMU,0.0,False,False")


def write(tmp_path: Path, records: list[tuple], scale: float = 1.0) -> Path:
    """A wire log from (t, dir, body) records; '>'/'<' bodies are framed with their checksum."""
    lines = ["# helmcheck wire-log 1", f"# hand-made  baud 19200  time_scale {scale:g}"]
    for t, d, body in records:
        text = body if d in ("!",) or body.startswith("$") else f"${body}*{checksum_hex(body)}"
        lines.append(f"{t:.6f} {d} {text}")
    p = tmp_path / "made.log"
    p.write_text("\n".join(lines) + "\n")
    return p


def poll(t: float, **fields) -> list[tuple]:
    """``$OSD,S`` at ``t`` answered 10 ms later with the ``$OSI`` and 20 ms later with its ACK."""
    return [(t, ">", "OSD,S"), (t + 0.01, "<", osi(**fields)), (t + 0.02, "<", "ACK,8,0,0")]


def start(t: float = 0.0) -> list[tuple]:
    return (poll(t, mode="S") + [(t + 0.1, ">", "OMSTART,0,0,0,0,conformance.mis,"), (t + 0.11, "<", "ACK,3,0,0")]
            + poll(t + 0.2, mode="N", dist=150.0, speed=2.0))


def judge(tmp_path, records, **kw) -> dict:
    out = check_log(write(tmp_path, records), profile=kw.pop("profile", PROFILE), role="vehicle", **kw)
    return {c["id"]: c for c in out.clauses}


def verdict(v: dict, cid: str) -> str:
    return v[cid]["verdict"]


def no_fail(v: dict) -> list:
    return [(c, e["reason"]) for c, e in v.items() if e["verdict"] in ("fail", "non-strict")]


# ------------------------------------------------------------------------- unseen motion

def test_RH_PK_2_a_countdown_that_began_between_two_polls_is_accepted(tmp_path):
    """On station happened somewhere between two polls 30 s apart: the park time shown is what a
    vehicle that arrived in that window shows — not a FAIL (the event is placed in its window)."""
    rec = start() + [(1.0, ">", f"OPK,{LAT:.6f},{LON + 0.002:.6f},2,1"), (1.01, "<", "ACK,11,0,0")]
    rec += poll(1.5, mode="mP", park=120, dist=160.0, speed=1.0)
    rec += poll(31.5, mode="mP", park=100, dist=1.0, lon=LON + 0.002)
    v = judge(tmp_path, rec)
    assert no_fail(v) == []
    assert verdict(v, "RH-OUT-4") == "pass"
    assert verdict(v, "RH-PK-2") == "pass"


def test_RH_PK_2_a_countdown_far_from_the_park_position_fails(tmp_path):
    rec = start() + [(1.0, ">", f"OPK,{LAT:.6f},{LON + 0.002:.6f},2,1"), (1.01, "<", "ACK,11,0,0")]
    rec += poll(1.5, mode="mP", park=120, dist=160.0, speed=1.0)
    rec += poll(31.5, mode="mP", park=100, dist=150.0, speed=1.0)
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-PK-2") == "fail"
    assert "not on station" in v["RH-PK-2"]["reason"]


def test_RH_PK_2_on_station_without_counting_fails(tmp_path):
    rec = start() + [(1.0, ">", f"OPK,{LAT:.6f},{LON:.6f},2,1"), (1.01, "<", "ACK,11,0,0")]
    for t in (1.5, 3.0, 4.5, 6.0):
        rec += poll(t, mode="mP", park=120, dist=0.5)
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-PK-2") == "fail"  # the park time a vehicle on station shows is counting


@pytest.mark.parametrize("dist,want", [(1.0, "fail"), (PROFILE.on_station_m, "fail"),
                                       (PROFILE.on_station_m + 0.01, "not fail")])
def test_RH_MSN_4_at_the_last_waypoint_without_ending_fails(tmp_path, dist, want):
    """The profile's test mission has 4 waypoints; the vehicle reports itself ``dist`` from the
    last one, in N, for 10 s: within ``on_station_m`` (inclusive, RH-RD-5: a vehicle that stopped
    2.996 m away reports 3.00) a conforming vehicle has reached it and ended the mission; just
    outside it the vehicle has not arrived, and nothing is proven."""
    rec = start() + [(1.0, ">", "OJW,3"), (1.01, "<", "ACK,7,0,0")]
    for t in (2.0, 4.0, 6.0, 8.0, 10.0, 12.0):
        rec += poll(t, mode="N", wp=3, dist=dist, speed=0.0)
    v = judge(tmp_path, rec)
    assert (verdict(v, "RH-MSN-4") == "fail") == (want == "fail"), v["RH-MSN-4"]


@pytest.mark.parametrize("shown,want", [("other.mis", "pass"), ("conformance.mis", "inconclusive"),
                                        (None, "inconclusive")])
def test_RH_MSN_2_a_start_by_an_unknown_name_is_judged_by_the_mission_seen_running(tmp_path, shown, want):
    """The observer has no file named other.mis: accepting its start is right only if the
    vehicle has it. The vehicle's later report running other.mis (field 12) shows it has; a
    report showing another mission, or none before the record ends, proves nothing."""
    rec = poll(0.0, mode="S") + [(0.1, ">", "OMSTART,0,0,0,0,other.mis,"), (0.11, "<", "ACK,3,0,0")]
    if shown is not None:
        rec += poll(0.3, mode="N", dist=150.0, speed=2.0, mission=shown)
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-MSN-2") == want, v["RH-MSN-2"]


def test_RH_SAF_1_a_violation_the_vehicle_raises_by_itself_is_adopted_not_failed(tmp_path):
    """No $OXFLT anywhere: a bench vehicle trips "no forward progress" on its own. The report
    showing the code is explained by that unseen event; the lockout is judged (RH-SAF-1)."""
    rec = start() + poll(5.0, mode="N", err="Sfp", dist=150.0)
    rec += [(5.5, ">", "OMS,90,2,20,0.5,10"), (5.51, "<", "ACK,9,1,26")]
    rec += [(6.0, ">", "ORWSET,Sle,R"), (6.01, "<", "ACK,12,1,26")]
    v = judge(tmp_path, rec)
    assert no_fail(v) == []
    assert verdict(v, "RH-OUT-4") == "pass"
    assert verdict(v, "RH-SAF-1") == "pass"


def test_RH_OUT_4_a_waypoint_jump_nothing_explains_is_caught(tmp_path):
    rec = start() + [(1.0, ">", "OMS,90,2,20,0.5,10"), (1.01, "<", "ACK,9,0,0")]
    rec += poll(1.5, mode="A", wp=3)
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-OUT-4") == "fail"


def test_RH_OUT_4_a_waypoint_then_a_mission_park_between_two_polls_is_adopted(tmp_path):
    """Between two polls 200 s apart the vehicle reached waypoint 0, went on to waypoint 1 and
    began its mission park there (not known yet): a conforming sequence, not a FAIL; the park
    then counts down from what was shown."""
    rec = start() + poll(200.0, mode="P", wp=1, park=273, dist=2.0)
    rec += poll(210.0, mode="P", wp=1, park=263, dist=2.0)
    v = judge(tmp_path, rec)
    assert no_fail(v) == []
    assert verdict(v, "RH-OUT-4") == "pass"


def test_RH_INT_1_a_waypoint_reached_just_before_a_takeover_is_accepted(tmp_path):
    """The vehicle reached waypoint 0 unseen just before the $OMS: A with the frozen waypoint 1
    (it was 4 m from it half a second before: it can have got there)."""
    rec = start() + poll(0.5, mode="N", dist=4.0, speed=2.0) + [(1.0, ">", "OMS,90,2,20,0.5,10"),
                                                                (1.01, "<", "ACK,9,0,0")]
    rec += poll(1.5, mode="A", wp=1)
    v = judge(tmp_path, rec)
    assert no_fail(v) == []


def test_RH_INT_1_a_waypoint_it_cannot_have_reached_before_a_takeover_is_not_assumed(tmp_path):
    """150 m from waypoint 0 0.8 s before the $OMS: it cannot have reached it (RH-RD-5: the
    mission is frozen under remote control), so A with waypoint 1 is a finding."""
    rec = start() + [(1.0, ">", "OMS,90,2,20,0.5,10"), (1.01, "<", "ACK,9,0,0")]
    rec += poll(1.5, mode="A", wp=1)
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-OUT-4") == "fail"


# ------------------------------------------------------------------------- blame

def test_RH_ACK_2_an_answer_after_the_tester_gave_up_belongs_to_its_command(tmp_path):
    """The $OMS gets its ACK 4.5 s late, after a later $OSD was answered: RH-ACK-2 for the $OMS
    (a stall of the line holds everything up in order: it cannot put one answer behind a later
    one); not RH-ACK-6 for anybody, and not RH-ACK-1 (an ACK came)."""
    rec = start() + [(1.0, ">", "OMS,90,2,20,0.5,10")]
    rec += poll(5.0, mode="A")
    rec += [(5.5, "<", "ACK,9,0,0")] + poll(6.0, mode="A")
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-ACK-2") == "fail" and v["RH-ACK-2"]["lines"][0] == 11
    assert verdict(v, "RH-ACK-6") != "fail"
    assert verdict(v, "RH-ACK-1") != "fail"


def test_RH_ACK_2_one_late_answer_may_be_a_stall_two_in_a_row_are_not(tmp_path):
    """An $ACK 2.5 s late with nothing else on the line meanwhile: a stall of the line (or the
    host) can do that once — INCONCLUSIVE, saying so. Sent again once that ACK came back, and late
    again, it is the vehicle's: FAIL. An answer on time in between (sent after the late one came
    back) shows the line flowing: the two late ones are not a run."""
    late = start() + [(1.0, ">", "OMS,90,2,20,0.5,10"), (3.5, "<", "ACK,9,0,0")]
    v = judge(tmp_path, late + poll(4.0, mode="A"))
    assert verdict(v, "RH-ACK-2") == "inconclusive" and "stall" in v["RH-ACK-2"]["reason"], v["RH-ACK-2"]
    again = late + [(3.6, ">", "OMS,90,2,20,0.5,10"), (6.1, "<", "ACK,9,0,0")] + poll(7.0, mode="A")
    v = judge(tmp_path, again)
    assert verdict(v, "RH-ACK-2") == "fail" and v["RH-ACK-2"]["offending_count"] == 2, v["RH-ACK-2"]
    between = late + poll(4.0, mode="A") + [(5.0, ">", "OMS,90,2,20,0.5,10"), (7.5, "<", "ACK,9,0,0")]
    v = judge(tmp_path, between + poll(8.0, mode="A"))
    assert verdict(v, "RH-ACK-2") == "inconclusive", v["RH-ACK-2"]


@pytest.mark.parametrize("line,clause", [
    ("$OMSTOP,0*07", "RH-FRM-4"),  # wrong checksum: RH-FRM-4's discard (RH-FRM-2 defines the right one)
    ("$OMSTOP,0", "RH-FRM-4"),  # no checksum
    ("$omstop,0*06", "RH-FRM-5"),  # lower-case ID
])
def test_any_answer_to_a_line_that_must_be_discarded_fails_its_discard_clause(tmp_path, line, clause):
    """Even an error ACK (status 1) is an answer: the discard clause fails, whatever else."""
    rec = start() + [(1.0, ">", line), (1.01, "<", "ACK,1,1,28")] + poll(2.0, mode="N", dist=150.0)
    v = judge(tmp_path, rec)
    assert verdict(v, clause) == "fail"


def test_RH_FRM_6_data_answering_an_overlong_osd_fails_the_discard_not_RH_ACK_5(tmp_path):
    """A 257-byte $OSD,S the vehicle must discard, answered with its $OSI and $ACK,8: the data is
    an answer to the discarded line (RH-FRM-6), not a data sentence without a request (RH-ACK-5)."""
    body = "OSD,S" + "," * (DEFAULT.max_line_bytes + 1 - len("$OSD,S*hh\r\n"))
    assert len(f"${body}*{checksum_hex(body)}\r\n") == DEFAULT.max_line_bytes + 1
    rec = start() + [(1.0, ">", body), (1.01, "<", osi(mode="N", dist=150.0)), (1.02, "<", "ACK,8,0,0")]
    rec += poll(2.0, mode="N", dist=150.0)
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-FRM-6") == "fail"
    assert "answered $OSI" in v["RH-FRM-6"]["reason"]
    assert verdict(v, "RH-ACK-5") != "fail"


@pytest.mark.parametrize("compass", ["C90.0,P0.00,R0.00,T20.0,D0.00", "C90.0R0.00P0.00T20.0D0.00"])
def test_RH_FRM_8_a_compass_sentence_out_of_its_form_fails_RH_FRM_8(tmp_path, compass):
    """$C with commas, or its letter fields out of order, breaks the $C form of RH-FRM-8 — once
    asked again and answered the same (once, a faulty line could have done it: INCONCLUSIVE)."""
    rec = start() + [(1.0, ">", "OSD,C"), (1.005, "<", compass), (1.01, "<", "ACK,8,0,0")]
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-FRM-8") == "inconclusive" and "the line" in v["RH-FRM-8"]["reason"]
    for i in range(1, REPEAT):  # asked again, the same every time (P and R are one bit apart: a
        t = 1.0 + 0.5 * i       # swap could be two flips of one bit, which needs the most repeats)
        rec += [(t, ">", "OSD,C"), (t + 0.005, "<", compass), (t + 0.01, "<", "ACK,8,0,0")]
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-FRM-8") == "fail"
    assert "$C" in v["RH-FRM-8"]["reason"]


def test_RH_FRM_9_sentences_with_a_parity_bit_fail_RH_FRM_9_not_RH_FRM_1(tmp_path):
    """A vehicle whose UART is set to 7E1: read as 8N1, bit 7 of each byte is its even parity
    (CR becomes 0x8D). The sentences under it are fine; the serial settings are not."""
    def seven_e1(body: str) -> str:
        line = f"${body}*{checksum_hex(body)}\r\n".encode()
        return escape(bytes(b | (0x80 if bin(b).count("1") % 2 else 0) for b in line))

    rec = [(0.0, ">", "OSD,S"), (0.01, "<~", seven_e1(osi(mode="S"))), (0.02, "<~", seven_e1("ACK,8,0,0"))]
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-FRM-9") == "fail"
    assert "7E1" in v["RH-FRM-9"]["reason"]
    assert verdict(v, "RH-FRM-1") != "fail"
    hit = "$ACK,8,0,0*5D".replace("8", "\\xb8", 1) + "\\r\\n"  # one byte hit by noise: not a UART setting
    v = judge(tmp_path, [(0.0, ">", "OSD,S"), (0.01, "<", osi(mode="S")), (0.02, "<~", hit)])
    assert verdict(v, "RH-FRM-9") != "fail"


def test_RH_OSD_2_a_letter_outside_the_alphabet_is_judged_under_its_own_clause(tmp_path):
    rec = start() + [(1.0, ">", "OSD,Q"), (1.01, "<", "ACK,8,1,27")]
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-OSD-2") == "pass"
    rec = start() + [(1.0, ">", "OSD,Q"), (1.005, "<", osi(mode="N", dist=150.0)), (1.01, "<", "ACK,8,1,27")]
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-OSD-2") == "fail"


def test_RH_ACK_3_a_wrong_error_number_for_a_bad_field_blames_the_error_number(tmp_path):
    rec = start() + [(1.0, ">", "OMS,400,2,20,0.5,10"), (1.01, "<", "ACK,9,1,21")]
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-ACK-3") == "fail"
    assert verdict(v, "RH-SRV-2") != "fail"


def test_the_first_report_of_a_record_gives_the_state_it_starts_in(tmp_path):
    """A capture that starts mid-mission: nothing before it is known, and nothing is failed for it."""
    rec = poll(0.0, mode="N", wp=2, dist=300.0, speed=2.0) + [(1.0, ">", "OMS,90,2,20,0.5,10"),
                                                             (1.01, "<", "ACK,9,0,0")]
    rec += poll(1.5, mode="A", wp=2)
    v = judge(tmp_path, rec)
    assert no_fail(v) == []
    assert verdict(v, "RH-OUT-4") == "pass"


def test_RH_SRV_3_a_servo_that_ends_on_its_first_timeout_after_a_refresh_blames_the_refresh(tmp_path):
    """An $OMS refreshed 6 s into its 10 s timeout, and the vehicle back in N at 11 s: the refresh
    did not restart the timeout (RH-SRV-3). No safety code is shown, so it is not RH-SAF-1."""
    rec = start() + [(1.0, ">", "OMS,90,2,20,0.5,10"), (1.01, "<", "ACK,9,0,0")]
    rec += poll(1.5, mode="A")
    rec += [(7.0, ">", "OMS,90,2,20,0.5,10"), (7.01, "<", "ACK,9,0,0")]
    rec += poll(7.5, mode="A")
    rec += poll(12.0, mode="N", dist=150.0, speed=2.0)
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-SRV-3") == "fail", v.get("RH-SRV-3")
    assert verdict(v, "RH-SAF-1") != "fail"


def test_RH_INT_3_a_park_back_just_before_the_observers_deadline_is_blamed_on_the_park(tmp_path):
    """$OPK, then $OMS (10 s): the vehicle shows the park again 0.2 s before the observer's own
    deadline (its ACK left a little before it was read), within the timeout's tolerance. The
    servo may have ended there; what the vehicle did wrong is to bring the interrupted park back."""
    rec = start() + [(1.0, ">", f"OPK,{LAT:.6f},{LON:.6f},5,0.5"), (1.01, "<", "ACK,11,0,0")]
    rec += poll(1.5, mode="mP", park=300)
    rec += [(2.0, ">", "OMS,90,2,20,0.5,10"), (2.01, "<", "ACK,9,0,0")]
    rec += poll(2.5, mode="A")
    rec += poll(11.6, mode="A")
    rec += poll(11.8, mode="mP", park=300)
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-INT-3") == "fail", v.get("RH-INT-3")


# ------------------------------------------------------------------------- timing brackets

@pytest.mark.parametrize("early", [0.0, 0.003, 0.3])
def test_RH_PRM_4_a_timeout_reported_just_before_the_model_deadline_is_still_timed(tmp_path, early):
    """The $OMP's 10 s timeout ends within its tolerance but a little *before* the observer's own
    deadline: the last report showing the primitive still starts the bracket (RH-TIM-1), so the
    timer is judged PASS, not left NOT-TESTED."""
    rec = poll(0.0, mode="S") + [(0.1, ">", "OMP,8a8a767690,00,10"), (0.11, "<", "ACK,10,0,0")]
    rec += poll(0.2, mode="M", act="8A8A767690", speed=0.57)
    rec += poll(9.5, mode="M", act="8A8A767690", speed=0.57)
    rec += poll(10.11 - early, mode="S")  # the ACK came at 0.11: the deadline is 10.11
    rec += poll(10.4, mode="S")  # the next report, after the deadline, closes the bracket
    v = judge(tmp_path, rec)
    assert no_fail(v) == []
    assert verdict(v, "RH-PRM-4") == "pass", v["RH-PRM-4"]["reason"]
    assert verdict(v, "RH-TIM-1") == "pass"


def test_RH_PRM_4_a_timeout_far_before_its_deadline_fails(tmp_path):
    rec = poll(0.0, mode="S") + [(0.1, ">", "OMP,8a8a767690,00,10"), (0.11, "<", "ACK,10,0,0")]
    rec += poll(0.2, mode="M", act="8A8A767690", speed=0.57)
    rec += poll(7.0, mode="S")
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-OUT-4") == "fail" or verdict(v, "RH-PRM-4") == "fail"


# ------------------------------------------------------------------------- prefixed replies

def _prefixed(records: list[tuple], prefix: bytes) -> list[tuple]:
    """The same session with ``prefix`` in front of every vehicle line (a modem's, say)."""
    out = []
    for t, d, body in records:
        if d == "<":
            out.append((t, "<raw", escape(prefix + f"${body}*{checksum_hex(body)}".encode())))
        else:
            out.append((t, d, body))
    return out


def _write_raw(tmp_path: Path, records: list[tuple]) -> Path:
    """A wire log whose records are whole lines (the log adds each one's CR LF)."""
    lines = ["# helmcheck wire-log 1", "# hand-made  baud 19200  time_scale 1"]
    for t, d, body in records:
        if d == "<raw":
            lines.append(f"{t:.6f} < {body}")
        else:
            lines.append(f"{t:.6f} {d} ${body}*{checksum_hex(body)}")
    p = tmp_path / "prefixed.log"
    p.write_text("\n".join(lines) + "\n")
    return p


@pytest.mark.parametrize("prefix,want", [(b"AT>", "fail"), (b"", "pass")])
def test_RH_FRM_1_the_same_bytes_before_every_reply_are_a_finding_quoting_them(tmp_path, prefix, want):
    """Bytes that precede reply after reply the same way are not line noise: an RH-FRM-1 FAIL that
    quotes them (a vehicle, or a radio modem in between, prefixing its output)."""
    rec = []
    for t in (0.0, 1.0, 2.0, 3.0):
        rec += poll(t, mode="S")
    out = check_log(_write_raw(tmp_path, _prefixed(rec, prefix)), profile=PROFILE, role="vehicle")
    v = {c["id"]: c for c in out.clauses}
    assert verdict(v, "RH-FRM-1") == want, v["RH-FRM-1"]
    if want == "fail":
        assert "AT>" in v["RH-FRM-1"]["reason"], v["RH-FRM-1"]["reason"]


def test_RH_FRM_2_a_zero_padded_checksum_must_be_read(tmp_path):
    """RH-FRM-2: "two hex digits, zero-padded" — a request whose checksum is 0X is read like any
    other: answered, it passes RH-FRM-2; left unanswered, RH-FRM-2 is the clause that fails."""
    from helmcheck.certify.vehicle.interpreter import zero_padded

    body = zero_padded("OSD,S", DEFAULT)
    assert checksum_hex(body).startswith("0") and body.startswith("OSD,S")
    rec = start() + [(1.0, ">", body), (1.01, "<", osi(mode="N", dist=150.0)), (1.02, "<", "ACK,8,0,0")]
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-FRM-2") == "pass", v["RH-FRM-2"]["reason"]
    rec = start() + [(1.0, ">", body)] + poll(6.0, mode="N", dist=150.0)
    v = judge(tmp_path, rec)  # once: a faulty line may have lost it or its answer
    assert verdict(v, "RH-FRM-2") == "inconclusive", v["RH-FRM-2"]["reason"]
    for t in (7.0, 13.0, 19.0):  # sent again, unanswered each time (spoil.REPEAT in a row)
        rec += [(t, ">", body)] + poll(t + 5.0, mode="N", dist=150.0)
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-FRM-2") == "fail", v["RH-FRM-2"]["reason"]


def test_RH_OSD_2_data_for_a_request_it_must_refuse_is_a_finding_not_a_tester_error(tmp_path):
    """``$OSD,S,Q`` answered with the ``$OSI`` and an accepting ACK: RH-OSD-2 fails (a conforming
    vehicle sends no data and err 27), and judging goes on."""
    rec = start() + [(1.0, ">", "OSD,S,Q"), (1.005, "<", osi(mode="N", dist=150.0)), (1.01, "<", "ACK,8,0,0")]
    rec += poll(2.0, mode="N", dist=150.0)
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-OSD-2") == "fail", v["RH-OSD-2"]["reason"]


def test_RH_SAF_5_a_violation_after_unseen_way_is_adopted_with_the_way(tmp_path):
    """Between two polls 120 s apart the vehicle reached its waypoint, began the mission park
    there, then raised a violation by itself: the lockout shows the frozen mission mode P with
    the park time left (RH-RD-11). Both unseen events are adopted together — no FAIL."""
    rec = start() + poll(120.0, mode="P", park=256, err="Sfp", dist=2.0)
    rec += [(121.0, ">", "OMS,90,2,20,0.5,10"), (121.01, "<", "ACK,9,1,26")]
    v = judge(tmp_path, rec)
    assert no_fail(v) == []
    assert verdict(v, "RH-OUT-4") == "pass"


def test_RH_INT_1_an_interrupted_control_that_comes_back_is_no_stack_in_its_case(tmp_path):
    """Inside RH-INT-1's case: $OMW (W), interrupted by $OMS (A); when the servo times out the
    vehicle goes back to W. There is no stack of remote controls: booked on RH-INT-1 (and the
    queue's own RH-OMW-5 outside that case)."""
    rec = start() + [(0.5, "!", "case V-21 RH-INT-1: no stack of remote controls")]
    rec += [(1.0, ">", f"OMW,{LAT + 0.001:.6f},{LON:.6f},2,,15,1,0,"), (1.01, "<", "ACK,16,0,0")]
    rec += poll(1.5, mode="W", dist=111.0, speed=1.0)
    rec += [(2.0, ">", "OMS,90,2,20,1,5"), (2.01, "<", "ACK,9,0,0")]
    rec += poll(2.5, mode="A", dist=111.0, speed=1.0)
    rec += poll(10.0, mode="W", dist=111.0, speed=1.0)
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-INT-1") == "fail", v["RH-INT-1"]["reason"]


def test_RH_MSN_4_a_mission_that_loops_after_its_last_waypoint_fails_in_its_case(tmp_path):
    """Inside RH-MSN-4's case: heading for the last waypoint, the vehicle is next seen heading for
    waypoint 0 again — it did not end the mission there (booked on RH-MSN-4, not only RH-OUT-4)."""
    from helmcheck.model.testing import catalog, conformance_mission

    last = conformance_mission().waypoints[-1]
    rec = start() + [(0.5, "!", "case V-47 RH-MSN-4: the mission ends at its last waypoint")]
    rec += [(1.0, ">", "OJW,3"), (1.01, "<", "ACK,7,0,0")]
    rec += poll(1.5, mode="N", wp=3, dist=40.0, speed=2.0)
    rec += poll(60.0, mode="N", wp=0, dist=150.0, speed=2.0, lat=last.lat, lon=last.lon)
    v = judge(tmp_path, rec, catalog=catalog())
    assert verdict(v, "RH-MSN-4") == "fail", v["RH-MSN-4"]["reason"]


@pytest.mark.parametrize("heads_for, want", [(0, "pass"), (1, "fail")])
def test_RH_OMW_2_field_7_in_W_shows_the_first_queued_waypoint(tmp_path, heads_for, want):
    """Two $OMW queued: a vehicle in W heads for the first (field 7 the distance to it from the
    reported position); one that heads for the second at once has not kept the arrival order."""
    from helmcheck.model.geo import distance_m

    wps = [(LAT + 0.001, LON), (LAT + 0.001, LON + 0.0012)]
    dist = distance_m(LAT, LON, *wps[heads_for])
    rec = start()
    for i, (lat, lon) in enumerate(wps):
        rec += [(1.0 + i, ">", f"OMW,{lat:.6f},{lon:.6f},2,,15,1,0,"), (1.01 + i, "<", "ACK,16,0,0")]
    rec += poll(3.0, mode="W", dist=round(dist, 2), speed=1.0)
    v = judge(tmp_path, rec)
    assert verdict(v, "RH-OMW-2") == want, v["RH-OMW-2"]["reason"]
