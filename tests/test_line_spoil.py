"""A faulty line's damage and the repetition rule (``docs/contracts.md``, "A faulty line").

The form rule (:mod:`helmcheck.judge.spoil`): every sentence of the grammar, damaged once by
what a line does — a bit flipped, two bits flipped, a byte lost, a burst of noise inside it —
is explained as the line's doing, and named for what was done; what a vehicle does wrong on
purpose (commas in ``$C``, a checksum many bits off) is not. The repetition rule
(:mod:`helmcheck.judge.streaks`), on a real ledger: made again clean, a held observation is counted
and not judged; the same error in a row, as often as its form needs, or the same broken bytes
twice, is booked; never made again, it is INCONCLUSIVE naming the line; a relay's note makes it
the line's for certain. And the judges: a vehicle observer and a backseat observer fed hand-made
records (a single broken reply, the same one four times, the tester's re-run).
"""

from __future__ import annotations

import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

from helmcheck.clauses import vehicle_clauses
from helmcheck.grammar import checksum_hex, decode, format as format_sentence
from helmcheck.judge import Ledger, WireEvent
from helmcheck.judge.spoil import REPEAT, SHORTEST_COMMAND, explain, explain_discard, flips_to_frame, signature
from helmcheck.judge.streaks import OTHER_REPEAT, Streaks
from helmcheck.judge.vehicle import VehicleObserver
from helmcheck.profile import DEFAULT
from tests import strategies as gen

#: Sentences a vehicle sends, any of them
REPLY = st.one_of(*gen.REPLIES.values())


def line(body: str) -> bytes:
    return f"${body}*{checksum_hex(body)}\r\n".encode()


def _sentence(sentence) -> bytes:
    raw = format_sentence(sentence)
    assume(decode(raw, DEFAULT).valid and not decode(raw, DEFAULT).findings)
    return raw


# ============================================================ the form rule

@given(REPLY, st.data())
def test_one_bit_flipped_anywhere_is_explained_as_a_flip(sentence, data):
    raw = bytearray(_sentence(sentence))
    i = data.draw(st.integers(0, len(raw) - 1))
    raw[i] ^= 1 << data.draw(st.integers(0, 7))
    got = bytes(raw)
    assume(got.count(b"\n") == 1 and got.endswith(b"\n") and got.count(b"$") == 1 and got[:1] == b"$")
    d = decode(got, DEFAULT)
    assume(not (d.valid and not d.findings))
    spoil = explain(got, DEFAULT, d)
    assert spoil is not None and spoil.kind in ("flip", "drop", "noise", "torn"), got
    assert "the line" not in spoil.text  # what it names is the damage; the judge says whose


@given(REPLY, st.data())
def test_two_bits_flipped_with_the_frame_intact_are_explained(sentence, data):
    raw = bytearray(_sentence(sentence))
    star = raw.rindex(b"*")
    for _ in range(2):
        i = data.draw(st.integers(1, star - 1))
        raw[i] ^= 1 << data.draw(st.integers(0, 6))  # printable stays mostly printable
    got = bytes(raw)
    assume(b"$" not in got[1:] and b"*" not in got[1:star] and b"\n" not in got[:-1])
    d = decode(got, DEFAULT)
    assume(d.error is not None and d.error.clause == "RH-FRM-2")
    assert flips_to_frame(got) in (1, 2) and explain(got, DEFAULT, d).kind == "flip"


@given(REPLY, st.data())
def test_a_byte_lost_is_explained(sentence, data):
    raw = _sentence(sentence)
    i = data.draw(st.integers(0, len(raw) - 1))
    got = raw[:i] + raw[i + 1:]
    assume(got[:1] == b"$" and got.endswith(b"\n") and got.count(b"\n") == 1)
    d = decode(got, DEFAULT)
    assume(not (d.valid and not d.findings))
    assert explain(got, DEFAULT, d) is not None, got


@given(REPLY, st.data())
def test_a_burst_of_noise_inside_a_line_is_explained(sentence, data):
    raw = _sentence(sentence)
    i = data.draw(st.integers(1, len(raw) - 3))
    burst = data.draw(st.binary(min_size=1, max_size=8).filter(lambda b: b"$" not in b and b"\n" not in b))
    got = raw[:i] + burst + raw[i:]
    d = decode(got, DEFAULT)
    assume(not (d.valid and not d.findings))
    assert explain(got, DEFAULT, d) is not None, got


def test_what_a_vehicle_gets_wrong_on_purpose_is_not_a_line_fault():
    # commas in $C (RH-FRM-8), right checksum: no one fault of a line puts four commas in
    assert explain(line("C90.0,P0.00,R0.00,T20.0,D0.00"), DEFAULT) is None
    # a checksum five bits off: the line would need five flips in one line
    body = "ACK,8,0,0"
    wrong = f"${body}*{int(checksum_hex(body), 16) ^ 0x5B:02X}\r\n".encode()
    assert flips_to_frame(wrong) is None and explain(wrong, DEFAULT) is None
    command = f"$OSD,S*{int(checksum_hex('OSD,S'), 16) ^ 0x5B:02X}\r\n".encode()  # a backseat's, as short
    assert explain(command, DEFAULT, shortest=SHORTEST_COMMAND) is None


def test_what_is_named():
    osi = line("ACK,8,0,0")
    assert explain(osi[:5] + osi[6:], DEFAULT).text.startswith("a line with one byte")
    assert "CR missing" in explain(osi[:-2] + b"\n", DEFAULT).text
    assert explain(b"$ACK,8\r\n", DEFAULT).kind == "torn"
    assert "noise" in explain(osi[:6] + b"\x07\x99" + osi[6:], DEFAULT).text
    assert explain_discard(b"\x00\xffjunk", "RH-FRM-7", "", DEFAULT).kind == "noise"
    assert "'$' missing" in explain_discard(osi[1:], "RH-FRM-7", "", DEFAULT).text
    assert "LF missing" in explain_discard(osi[:-1], "RH-FRM-7", "", DEFAULT).text


def test_a_wrong_checksum_is_signed_by_the_bits_it_is_off_by():
    one = line("ACK,8,0,0").replace(b"*5D", b"*5C")
    other = line("ACK,9,0,0").replace(b"*5C", b"*5D")
    assert signature(one) == signature(other) == ("RH-FRM-2", 1)
    assert signature(line("ACK,8,0,0").replace(b"*5D", b"*59")) == ("RH-FRM-2", 4)


# ============================================================ the repetition rule

CLAUSES = [c.id for c in vehicle_clauses()]


def held(streaks: Streaks, key="k", sig=("s",), need=REPEAT, raw=None, known=False):
    return streaks.hold(key, sig, "a line one bit off", [("RH-FRM-2", "a wrong checksum", [], "V-01")],
                        need=need, raw=raw, known=known)


def test_made_again_clean_is_counted_and_not_judged():
    led = Ledger(CLAUSES)
    s = Streaks(led)
    held(s)
    led.passed("RH-FRM-2", "right")
    assert s.clean("k") == 1 and not s
    v = led.verdict("RH-FRM-2")
    assert v.verdict == "pass" and "1 observation(s) a faulty line may have spoilt" in v.reason


def test_the_same_error_in_a_row_as_often_as_its_form_needs_is_booked():
    for need in (REPEAT, OTHER_REPEAT):
        led = Ledger(CLAUSES)
        s = Streaks(led)
        for i in range(need - 1):
            assert held(s, need=need) is not None
        assert not led.has_failed("RH-FRM-2")
        assert held(s, need=need) is None  # the last one of the run: booked, all of them
        assert led.counts("RH-FRM-2")["fail"] == need
        assert held(s, need=need) is None and led.counts("RH-FRM-2")["fail"] == need + 1  # proven: at once


def test_another_error_between_breaks_the_run_and_a_relays_note_never_books():
    led = Ledger(CLAUSES)
    s = Streaks(led)
    for i in range(3 * REPEAT):
        held(s, sig=("s", i % 2))
        held(s, known=True)
    assert not led.has_failed("RH-FRM-2")
    s.conclude("the record ended")
    v = led.verdict("RH-FRM-2")
    assert v.verdict == "inconclusive" and "the line, not the implementation, may have done it" in v.reason


def test_the_same_broken_bytes_again_are_booked_clean_ones_between_or_not():
    led = Ledger(CLAUSES)
    s = Streaks(led)
    bad = line("OSD,G,C,S,P,,,,").replace(b"*5F", b"*5E")
    held(s, raw=bad)
    s.clean("k")  # made again clean: the first was counted as the line's
    assert held(s, raw=bad[:-3] + b"5C\r\n") is not None  # other bytes: held
    assert held(s, raw=bad) is None and led.has_failed("RH-FRM-2")  # the same bytes again: booked
    short = Streaks(Ledger(CLAUSES))  # a short line: three times
    assert held(short, key="a", raw=b"$ACK,8*00\r\n") and held(short, key="a", raw=b"$ACK,8*00\r\n")
    assert held(short, key="a", raw=b"$ACK,8*00\r\n") is None


# ============================================================ the vehicle observer

OSI = ("OSI,8080808080,S,0,41.52000000,-71.32000000,0.00,0.00,N,40.00,P0,-14.5000,conformance.mis,0.0000,"
       "75.5,0.00,95.0,False,IVER3-EMU,0.0,False,False")


def judge(records) -> Ledger:
    led = Ledger(CLAUSES)
    obs = VehicleObserver(DEFAULT, led, time_scale=1.0, baud=19200)
    for n, (t, d, data) in enumerate(records, 1):
        obs.feed(WireEvent(t, d, data if d != "!" else b"", data.decode() if d == "!" else "", n))
    obs.close()
    return led


def poll(t: float, osi: bytes = line(OSI)) -> list:
    return [(t, ">", line("OSD,S")), (t + 0.01, "<", osi), (t + 0.02, "<", line("ACK,8,0,0"))]


def test_a_report_the_line_broke_once_is_not_a_failure_and_asked_again_it_is_counted():
    flipped = bytearray(line(OSI))
    flipped[30] ^= 0x01
    led = judge(poll(0.0) + poll(0.5, bytes(flipped)) + poll(1.0))
    for cid in ("RH-FRM-2", "RH-ACK-5", "RH-OSD-1", "RH-OUT-4"):
        assert not led.has_failed(cid), led.verdict(cid).reason
    assert led.spoiled_count("RH-FRM-2") == 1 and led.verdict("RH-FRM-2").verdict == "pass"
    once = judge(poll(0.0) + poll(0.5, bytes(flipped)))
    assert once.verdict("RH-FRM-2").verdict == "inconclusive"
    assert "one bit from a well-framed line" in once.verdict("RH-FRM-2").reason


def test_a_report_broken_the_same_way_every_time_is_the_vehicles():
    bad = line(OSI)[:-5] + b"*" + line(OSI)[-4:-3] + b"\r\n"  # its checksum's first digit lost
    led = judge(poll(0.0) + poll(0.5, bad) + poll(1.0, bad))
    assert led.has_failed("RH-FRM-4") or led.has_failed("RH-FRM-2") or led.has_failed("RH-FRM-1"), \
        [led.verdict(c).reason for c in ("RH-FRM-1", "RH-FRM-2", "RH-FRM-4")]


def test_an_ack_lost_once_then_answered_was_the_lines_lost_every_time_is_the_vehicles():
    cmd = line("OPOS,41.52,-71.32,0.0,,")
    lost = poll(0.0) + [(1.0, ">", cmd)] + poll(5.0) + [(6.0, ">", cmd), (6.01, "<", line("ACK,6,0,0"))]
    led = judge(lost + poll(7.0))
    assert led.verdict("RH-ACK-1").verdict == "pass" and led.spoiled_count("RH-ACK-1") == 1
    never = poll(0.0)
    for i in range(REPEAT):
        never += [(1.0 + 5 * i, ">", cmd)] + poll(5.0 + 5 * i)
    led = judge(never)
    assert led.has_failed("RH-ACK-1") and led.counts("RH-ACK-1")["fail"] == REPEAT


def test_in_a_relays_record_a_note_makes_a_broken_report_the_lines_and_none_makes_it_the_vehicles():
    flipped = bytearray(line(OSI))
    flipped[30] ^= 0x01
    start = [(0.0, "!", b"relay started: backseat pty, vehicle pty; impair 'flip=1e-4', seed 0")]
    noted = start + poll(0.1) + [(0.5, "!", b"line fault < flip: byte 200 bit 0: 0x30 '0' -> 0x31 '1'")]
    led = judge(noted + poll(0.5, bytes(flipped)))
    v = led.verdict("RH-FRM-2")
    assert v.verdict == "inconclusive" and "the relay's note: line fault < flip" in v.reason, v.reason
    led = judge(start + poll(0.1) + poll(0.5, bytes(flipped)))
    assert led.has_failed("RH-FRM-2")  # no note touched it: the vehicle sent it so
