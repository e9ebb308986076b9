"""Real strings quoted in public-evidence.md, and the known-bad client forms (issue: grammar)."""

from __future__ import annotations

import pytest

from helmcheck.grammar import decode, format, parse
from helmcheck.grammar import sentences as S
from helmcheck.profile import DEFAULT

CAPTURED = [
    "$ACK,8,0,0*5D",
    "$OMSTOP,0*06",
    "$OSI,FAFAD5D5C1,N,12,30.35313633,-89.62795283,3.12,37.97,N,15.404,P0,-1.5404,manualLownmoer,"
    "0.0792,139.5,0.3,66.5,False,IVER3-3089,3.0,True,False*69",
    "$C82.8P-3.89R-2.63T20.3D3.2*78",
    "$OMW,30.35197,-89.62897,0.0,,10,4.0,0, *64",
    "$OSD,G,C,S,P,,,,*5F",
    "$OSD,C,G,Y,S,D*3E",
    "$OSD,C,G,S,P,Y,D,T,I*5F",
]


@pytest.mark.parametrize("line", CAPTURED)
def test_RH_FRM_1_captured_strings_parse_and_reformat_byte_exact(line):
    s = parse(line + "\r\n")
    assert format(s) == (line + "\r\n").encode()


def test_RH_OUT_1_captured_osi_fields():
    s = parse(CAPTURED[2])
    assert isinstance(s, S.OSI)
    assert (s.mode, s.next_waypoint, s.error_state, s.park_time) == ("N", 12, "N", 0)
    assert s.vehicle_name == "IVER3-3089" and s.srp_active == "False" and s.field_count == 21
    assert s.reserved == ("3.0", "True", "False")


def test_RH_FRM_8_compass_has_no_commas():
    s = parse(CAPTURED[3])
    assert isinstance(s, S.Compass) and str(s.depth) == "3.2" and str(s.pitch) == "-3.89"


def test_RH_OMW_3_captured_omw_has_empty_depth2_and_space_sensors():
    s = parse(CAPTURED[4])
    assert isinstance(s, S.OMW) and s.depth2 is None and s.sensors == " "


def test_RH_FRM_2_unpadded_checksum_is_rejected():
    """A client that writes '%X' instead of '%02X' (public-evidence §2.0) is refused."""
    from helmcheck.grammar import checksum
    body = "OMP,0A80808080,00,10"
    assert checksum(body) < 0x10  # this body's checksum has one significant hex digit
    d = decode(f"${body}*{checksum(body):X}")
    assert d.error.clause == "RH-FRM-4" and "two hex digits" in d.error.message
    assert decode(f"${body}*{checksum(body):02X}").valid


def test_RH_FRM_4_unpadded_single_digit_checksum_is_malformed():
    d = decode("$OSD,G,C,S,P*5")
    assert d.error.clause == "RH-FRM-4" and d.error.ack_type is None


def test_RH_PRM_2_omp_with_nine_hex_digits_is_rejected_with_err_21():
    # an unpadded byte (0x8 instead of 08) loses a hex digit, as in public client code
    body = "OMP,808080880,00,10"
    from helmcheck.grammar import checksum_hex
    d = decode(f"${body}*{checksum_hex(body)}")
    assert d.error is not None and d.error.clause == "RH-ACK-3"
    assert (d.error.ack_type, d.error.ack_err, d.error.field) == (10, 21, "actuators")


def test_RH_FRM_3_lower_case_checksum_accepted_with_a_finding():
    d = decode("$ACK,8,0,0*5d")
    assert d.valid and [f.clause for f in d.findings] == ["RH-FRM-3"]
    strict = DEFAULT.replace(lowercase_checksum_in=False)
    assert decode("$ACK,8,0,0*5d", strict).error.clause == "RH-FRM-3"


def test_RH_FRM_2_wrong_checksum_names_both_values_and_column():
    d = decode("$ACK,8,0,0*5C")
    assert str(d.error) == "RH-FRM-2: checksum 5C does not match computed 5D at column 12"


def test_RH_FRM_4_missing_checksum_and_two_stars():
    assert decode("$OMSTOP,0").error.clause == "RH-FRM-4"
    assert "two '*'" in decode("$OMSTOP,0*06*06").error.message


def test_RH_FRM_5_unknown_and_lower_case_ids():
    from helmcheck.grammar import checksum_hex
    for body in ("OXYZ,1", "osd,G", "OMS2,1"):
        d = decode(f"${body}*{checksum_hex(body)}")
        assert d.error.clause == "RH-FRM-5", body
        assert d.error.ack_type is None  # discarded silently, never acknowledged


def test_RH_FRM_7_bare_lf_accepted_with_finding():
    d = decode(b"$ACK,8,0,0*5D\n")
    assert d.valid and d.terminator == "\n" and d.findings[0].clause == "RH-FRM-7"


def test_RH_FRM_6_overlong_line_rejected():
    from helmcheck.grammar import checksum_hex
    body = "OLOGL," + ",".join(["L" * 20] * 12)
    d = decode(f"${body}*{checksum_hex(body)}\r\n")
    assert d.error.clause == "RH-FRM-6"


@pytest.mark.parametrize("body,clause,err,field", [
    ("OMS,360,10,45,3,5", "RH-SRV-2", 20, "heading"),
    ("OMS,10,101,45,3,5", "RH-SRV-2", 20, "depth"),
    ("OMS,10,10,46,3,5", "RH-SRV-2", 20, "max_pitch"),
    ("OMS,10,10,45,4.6,5", "RH-SRV-2", 20, "speed"),
    ("OMS,10,10,45,3,121", "RH-SRV-2", 20, "timeout"),
    ("OMS,10,10,45,3,0", "RH-SRV-2", 20, "timeout"),
    ("OMP,8080808080,01,5", "RH-PRM-2", 21, "reserved"),
    ("OPK,10,10,0,1", "RH-PK-1", 22, "minutes"),
    ("OPOS,91,10,1,,", "RH-POS-1", 18, "lat"),
    ("ODVL,5.1,0,5", "RH-RD-9", 35, "x"),
    ("OMSTOP,1", "RH-MSN-3", 28, "flag"),
    ("OMLOAD,../../etc/passwd,0", "RH-MSN-1", 29, "name"),
    ("OMLOAD,C:\\x.mis,0", "RH-MSN-1", 29, "name"),
    ("OMSTART,0,0,0,2,a.mis", "RH-RD-6", 30, "mission_type"),
    ("ORWSET,SafetyAction,W,1,dive", "RH-RD-8", 23, "values"),
    ("ORWSET,Sop,R,1", "RH-RD-8", 23, "state"),
    ("OMW,1,1,101,,10,1,0,", "RH-RD-9", 36, "depth1"),
])
def test_RH_ACK_3_range_errors_name_field_and_ack_error(body, clause, err, field):
    from helmcheck.grammar import checksum_hex
    d = decode(f"${body}*{checksum_hex(body)}")
    assert d.error is not None, body
    assert (d.error.clause, d.error.ack_err, d.error.field) == (clause, err, field)
    assert d.error.message.startswith("$")


@pytest.mark.parametrize("body,err", [
    ("OMS,1,2,3,4", 20), ("OMP,80808080,00,5", 21), ("OJW,x", 19), ("OSD,Q", 27), ("OSD,GG", 27),
    ("OLOGL", 24), ("OMSTART,a", 30), ("OPOS,1,2", 18), ("ODVL,1,1", 35), ("OMW,,1,1,1,,10,1,0,", 36),
    ("ORWSET,Bogus,R", 23), ("OLOGD", 25), ("OMLOAD,x", 29), ("OPK,1,2,3", 22),
])
def test_RH_ACK_3_syntax_errors_map_to_the_commands_error(body, err):
    from helmcheck.grammar import checksum_hex
    d = decode(f"${body}*{checksum_hex(body)}")
    assert d.error is not None and d.error.clause == "RH-ACK-3"
    assert d.error.ack_err == err and d.error.column is not None


def test_RH_RD_4_omw_keywords_any_case_and_clear_with_waypoint():
    from helmcheck.grammar import checksum_hex
    for kw in ("Clr", "CLR", "clear", "Stop"):
        body = f"OMW,{kw}"
        assert isinstance(parse(f"${body}*{checksum_hex(body)}"), S.OMWClear)
    body = "OMW,CLEAR,30.1,-89.2,5,,10,2,0,"
    s = parse(f"${body}*{checksum_hex(body)}")
    assert isinstance(s, S.OMWClear) and s.waypoint.lat == S.Dec("30.1")


def test_RH_OUT_1_osi_field_count_is_a_profile_setting():
    line = "$OSI,8080808080,S,0,30.0,-89.0,0.0,0.0,N,0.0,P0,0.0"
    from helmcheck.grammar import checksum_hex
    body = line[1:]
    raw = f"{line}*{checksum_hex(body)}"
    assert decode(raw).error.clause == "RH-OUT-1"  # rh5 wants 21 fields
    from helmcheck.profile import profile_from_dict
    rh3 = profile_from_dict({"protocol": "rh3", "osi_fields": 11})
    assert decode(raw, rh3).valid
