"""A report with one bad field is still a report (RH-OUT-1, RH-OUT-3).

The grammar reads a line whose fields are all there but one cannot be read, or is out of its
range, as a partial sentence: the bad field set aside (``None``) and named with its clause and its
text as sent (:attr:`helmcheck.grammar.Decoded.partial`, ``field_errors``). The vehicle judge books
the bad field on that clause and reads the rest of the ``$OSI`` for every other clause: on a
hand-made wire log whose every report carries the same bad field, every other clause gets the
verdict it gets on the same log without the fault. Only a line that cannot be split into its
fields (one too many, one missing) has no partial reading; an ``$OSI`` whose state fields (mode,
waypoint, park time, error state) cannot be read shows no state.
"""

from __future__ import annotations

from decimal import Decimal

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from helmcheck.grammar import checksum_hex, decode, format as format_sentence
from helmcheck.judge.spoil import REPEAT
from helmcheck.grammar import sentences as S
from helmcheck.profile import DEFAULT
from tests import strategies as gen
from tests.test_judge_vehicle_readings import LAT, LON, judge, osi

NAMES = S.OSI.field_names()


def line(body: str) -> bytes:
    return f"${body}*{checksum_hex(body.encode())}\r\n".encode()


def spoil(body: str, field: str, text: str) -> str:
    """``body`` (an ``$OSI`` body) with ``field`` written as ``text``."""
    parts = body.split(",")
    parts[NAMES.index(field) + 1] = text
    return ",".join(parts)


GOOD = osi(mode="N", dist=150.0, speed=2.0)


# ============================================================ the grammar: a partial reading

@pytest.mark.parametrize("field,text,clause", [
    ("true_heading", "-5.0", "RH-OUT-3"), ("true_heading", "360", "RH-OUT-3"), ("battery", "100.1", "RH-OUT-3"),
    ("speed", "-1", "RH-OUT-3"), ("lat", "90.5", "RH-OUT-3"), ("distance", "-0.01", "RH-OUT-3"),
    ("true_heading", "abc", "RH-OUT-1"), ("true_heading", "", "RH-OUT-1"), ("lon", "nan", "RH-OUT-1"),
    ("actuators", "8080808a8a", "RH-OUT-1"), ("battery", "n/a", "RH-OUT-1"), ("mode", "X", "RH-OUT-1"),
])
def test_one_bad_field_is_named_and_the_rest_is_read(field, text, clause):
    d = decode(line(spoil(GOOD, field, text)), DEFAULT)
    clean = decode(line(GOOD), DEFAULT).sentence
    assert not d.valid and d.partial is not None, d.error
    assert [(e.clause, e.field, e.value) for e in d.field_errors] == [(clause, field, text)]
    assert d.error == d.field_errors[0] and d.unread == {field}
    assert getattr(d.partial, field) is None
    assert all(getattr(d.partial, n) == getattr(clean, n) for n in NAMES if n != field)
    assert decode(line(spoil(GOOD, field, text)), DEFAULT, engine="lark") == d  # both engines agree


def test_two_bad_fields_are_both_named():
    d = decode(line(spoil(spoil(GOOD, "lat", "x"), "true_heading", "-1")), DEFAULT)
    assert [(e.clause, e.field) for e in d.field_errors] == [("RH-OUT-1", "lat"), ("RH-OUT-3", "true_heading")]
    assert d.partial.mode == "N" and d.partial.lat is None and d.partial.true_heading is None


@pytest.mark.parametrize("body", [
    GOOD.replace(",75.5,", ",75,5,"),  # one field too many: the fields are not where they seem
    GOOD.rsplit(",", 4)[0],  # fields missing at the end (an rh5 report of 17 fields is read: RH-OUT-1)
    GOOD.replace(",N,38.00,", ",N38.00,"),  # two fields run together
])
def test_a_report_that_cannot_be_split_into_its_fields_has_no_partial_reading(body):
    d = decode(line(body), DEFAULT)
    assert not d.valid
    if d.partial is not None:  # a short report reads with its count named (RH-OUT-1, "fields")
        assert [e.field for e in d.field_errors] == ["fields"] and not d.unread
    else:
        assert d.field_errors == ()


@given(gen.osi, st.sampled_from(NAMES[:18]), st.text(alphabet=gen.TEXT_ALPHABET, max_size=8))
def test_any_one_field_spoilt_leaves_every_other_field_read(sentence, field, text):
    """Whatever one field of a valid report is replaced by (no comma, no ``$`` or ``*``): the line
    is valid, or its partial reading sets aside that field alone and keeps every other."""
    body = format_sentence(sentence).decode()[1:].split("*")[0]
    d = decode(line(spoil(body, field, text)), DEFAULT)
    if d.valid:
        return
    assert d.partial is not None, d.error
    assert d.unread <= {field}, d.field_errors
    assert all(getattr(d.partial, n) == getattr(sentence, n) for n in NAMES if n != field)


# ============================================================ the judge: every other clause judged

def scenario(spoilt: str = "", text: str = "") -> list[tuple]:
    """A mission started, a servo, a primitive, a park, a queued waypoint, a stop and a refused
    jump; every ``$OSI`` with
    ``spoilt`` written as ``text`` (none when ``spoilt`` is empty)."""
    def poll(t: float, **fields) -> list[tuple]:
        body = osi(**fields)
        if spoilt:
            body = spoil(body, spoilt, text)
        return [(t, ">", "OSD,S"), (t + 0.01, "<", body), (t + 0.02, "<", "ACK,8,0,0")]

    def send(t: float, cmd: str, ack: str) -> list[tuple]:
        return [(t, ">", cmd), (t + 0.01, "<", ack)]

    return (poll(0.0, mode="S") + send(0.1, "OMSTART,0,0,0,0,conformance.mis,", "ACK,3,0,0")
            + poll(0.2, mode="N", dist=150.0, speed=2.0)
            + send(1.0, "OMS,90,2,20,1,30", "ACK,9,0,0") + poll(1.5, mode="A", dist=149.0, speed=1.0)
            + send(2.0, "OMP,8A8A767690,00,30", "ACK,10,0,0")
            + poll(2.5, mode="M", dist=149.0, speed=1.0, act="8A8A767690")
            + send(3.0, f"OPK,{LAT:.6f},{LON + 0.002:.6f},2,1", "ACK,11,0,0")
            + poll(3.5, mode="mP", park=120, dist=160.0, speed=1.0)
            + send(4.0, f"OMW,{LAT:.6f},{LON + 0.002:.6f},2,,15,1,0,", "ACK,16,0,0")
            + poll(4.5, mode="W", dist=160.0, speed=1.0) + poll(5.0, mode="W", dist=159.5, speed=1.0)
            + send(6.0, "OMSTOP,0", "ACK,1,0,0") + poll(6.5, mode="S")
            + send(7.0, "OJW,1", "ACK,7,1,19") + poll(7.5, mode="S"))


#: The clauses judged from the field itself besides its own: field 1 shows the commanded fins and
#: motor (RH-PRM-3) and neutral ones after a stop (RH-MSN-3); unread, they are not judged from it.
READ_FOR = {"actuators": {"RH-PRM-3", "RH-MSN-3"}}


@pytest.mark.parametrize("field,text,clause", [
    ("true_heading", "-5.0", "RH-OUT-3"), ("battery", "101", "RH-OUT-3"), ("speed", "-1", "RH-OUT-3"),
    ("distance", "-2", "RH-OUT-3"), ("lat", "91", "RH-OUT-3"), ("lon", "nan", "RH-OUT-1"),
    ("depth", "", "RH-OUT-1"), ("true_heading", "N/A", "RH-OUT-1"), ("actuators", "8080808080a", "RH-OUT-1"),
])
def test_a_bad_field_in_every_report_blinds_the_judge_to_nothing_else(tmp_path, field, text, clause):
    clean = judge(tmp_path, scenario())
    assert not [c for c, e in clean.items() if e["verdict"] == "fail"], clean
    got = judge(tmp_path, scenario(field, text))
    assert got[clause]["verdict"] == "fail" and field in got[clause]["reason"], got[clause]
    changed = {c: (clean[c]["verdict"], got[c]["verdict"], got[c]["reason"]) for c in clean
               if c not in ("RH-OUT-1", "RH-OUT-3") and clean[c]["verdict"] != got[c]["verdict"]}
    assert set(changed) <= READ_FOR.get(field, set()), changed
    assert all(g == "not-tested" for _, g, _ in changed.values()), changed
    judged = {c for c, e in clean.items() if e["verdict"] != "not-tested"}
    assert judged - set(changed) - {"RH-OUT-1", "RH-OUT-3"} <= {c for c, e in got.items() if e["verdict"] == "pass"}


@settings(max_examples=40)
@given(st.sampled_from(NAMES[:18]), st.text(alphabet=gen.TEXT_ALPHABET.replace("\\", ""), max_size=8))
def test_any_field_spoilt_in_every_report_fails_its_own_clause_alone(tmp_path_factory, field, text):
    """Whatever one field of every report is written as, the judge reads the log to its end, and
    nothing fails but the clause of the field's form or range. (No backslash: the hand-made log
    writes bodies unescaped.)"""
    assume(not decode(line(spoil(GOOD, field, text)), DEFAULT).valid)  # bad, not another good value
    got = judge(tmp_path_factory.mktemp("spoilt"), scenario(field, text))
    failed = {c for c, e in got.items() if e["verdict"] == "fail"}
    assert failed <= {"RH-OUT-1", "RH-OUT-3"}, {c: got[c]["reason"] for c in failed}


def test_a_report_whose_state_cannot_be_read_shows_none(tmp_path):
    """An ``$OSI`` whose mode is not a mode: booked on RH-OUT-1, and no state is read from it (the
    mirror is not told ``None``); the reports around it are judged as ever."""
    rec = scenario()
    i = next(i for i, r in enumerate(rec) if r[1] == "<" and ",A," in r[2])
    rec[i] = (rec[i][0], "<", rec[i][2].replace(",A,", ",X,"))
    t = rec[i][0]  # asked again at once, answered the same every time: the vehicle's, not the line's
    for k in range(1, REPEAT):  # (X is one flip from P: two flips of one bit could make it)
        at = t + 0.03 * k
        rec[i + 3 * k - 1:i + 3 * k - 1] = [(at - 0.01, ">", "OSD,S"), (at, "<", rec[i][2]), (at + 0.01, "<", "ACK,8,0,0")]
    got = judge(tmp_path, rec)
    assert got["RH-OUT-1"]["verdict"] == "fail" and "mode" in got["RH-OUT-1"]["reason"]
    assert {c for c, e in got.items() if e["verdict"] == "fail"} == {"RH-OUT-1"}, got
    assert got["RH-OUT-4"]["verdict"] == "pass"


def test_an_out_of_range_value_is_shown_as_sent():
    d = decode(line(spoil(GOOD, "true_heading", "-0.10")), DEFAULT)
    assert d.field_errors[0].value == "-0.10" and d.as_dict()["errors"][0]["value"] == "-0.10"
    assert d.as_dict()["partial"]["mode"] == "N"
    assert Decimal(d.field_errors[0].value) < 0
