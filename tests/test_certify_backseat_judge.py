"""The sans-IO backseat judge (RH-BS-1..8) on synthetic byte schedules: no ports, no clocks."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from helmcheck.conformance.backseat.judge import (BS_CLAUSES, POLL_INTERVAL_S, BackseatJudge,
                                                  line_budget, window_violations)
from helmcheck.conformance.backseat.scenarios import SCENARIOS, make_plan
from helmcheck.grammar import checksum_hex
from helmcheck.profile import DEFAULT

LEVELS = {c: ("MUST" if int(c.rsplit("-", 1)[1]) <= 4 else "SHOULD") for c in BS_CLAUSES}


def frame(body: str, *, lower: bool = False, term: bytes = b"\r\n") -> bytes:
    cks = checksum_hex(body)
    return f"${body}*{cks.lower() if lower else cks}".encode() + term


def judge(**kw) -> BackseatJudge:
    return BackseatJudge(DEFAULT.replace(**kw.pop("profile", {})), **kw)


def verdicts(j: BackseatJudge) -> dict[str, str]:
    return {r.id: r.verdict for r in j.results(LEVELS)}


POLL = frame("OSD,G,C,S,P,,,,")
OSI_S = frame("OSI,8080808080,S,0,41.52,-71.32,0.00,0.00,N,0.00,P0,-14.5,,0.0,0.0,0.00,95.0,False,IVER3-EMU,0.0,False,False")


def osi(mode: str, error: str = "N") -> bytes:
    body = ("OSI,8080808080,%s,0,41.52,-71.32,0.00,0.00,%s,0.00,P0,-14.5,,0.0,0.0,0.00,95.0,False,"
            "IVER3-EMU,0.0,False,False") % (mode, error)
    return frame(body)


# ------------------------------------------------------------------ RH-BS-4 line budget

@given(st.lists(st.tuples(st.integers(0, 24), st.integers(1, 400)), min_size=1, max_size=40))
def test_line_budget_violation_iff_some_window_exceeds(schedule):
    """RH-BS-4: for any send schedule, an offence is reported iff some 1 s window holds more
    than baud/10 bytes (times in 1/16 s steps so that window edges are exact)."""
    j = judge(profile={"baud": 9600})
    stream = POLL * 2000
    pos, t, arrivals = 0, 0.0, []
    for dt16, n in schedule:
        t += dt16 / 16
        j.backseat_bytes(stream[pos:pos + n], t)
        arrivals.append((t, n))
        pos += n
    j.close(t + 0.5)
    expected = window_violations(arrivals, line_budget(9600))
    assert (j.counts["RH-BS-4"] > 0) == expected
    assert j.max_window_bytes <= line_budget(9600) or expected


def test_line_budget_counts_each_offending_sentence():
    j = judge(profile={"baud": 9600})
    j.backseat_bytes(frame("OSD") * 200, 1.0)  # 1800 bytes at once; the line drains 960
    j.close(2.0)
    assert j.counts["RH-BS-4"] > 100
    assert verdicts(j)["RH-BS-4"] == "fail"


# ------------------------------------------------------------------ RH-BS-1, -2, -7 per line

def test_framing_fields_and_style_are_judged_per_line():
    j = judge()
    j.backseat_bytes(POLL, 0.0)
    j.backseat_bytes(b"$OSD,G,C,S,P,,,,*5E\r\n", 0.5)  # wrong checksum: RH-BS-1
    j.backseat_bytes(b"$OSD,,,S,,,,,*B\r\n", 0.6)  # unpadded: RH-BS-1
    j.backseat_bytes(frame("OMP,808088080,00,5"), 0.7)  # nine hex digits: RH-BS-2
    j.backseat_bytes(frame("OSD,G,C,S,P,,,,", lower=True), 0.8)  # lower-case hex: RH-BS-7
    j.backseat_bytes(frame("OSD,G,C,S,P,,,,", term=b"\n"), 0.9)  # bare LF: RH-BS-7
    j.backseat_bytes(b"noise", 1.0)
    j.backseat_bytes(POLL, 1.1)  # the noise is discarded when '$' comes: RH-BS-1
    j.close(2.0)
    assert j.counts["RH-BS-1"] == 3
    assert j.counts["RH-BS-2"] == 1
    assert j.counts["RH-BS-7"] == 2
    v = verdicts(j)
    assert v["RH-BS-1"] == v["RH-BS-2"] == "fail" and v["RH-BS-7"] == "non-strict"
    ev = {r.id: r.evidence for r in j.results(LEVELS)}
    assert ev["RH-BS-1"][0] == {"t": 0.5, "dir": ">", "line": "$OSD,G,C,S,P,,,,*5E"}


@given(st.lists(st.sampled_from([POLL, b"$OSD,,,S,,,,,*B\r\n", frame("OMP,808088080,00,5"),
                                 frame("OSD", lower=True), frame("OSD", term=b"\n"), b"xx\x00",
                                 frame("OMS,10.0,2.0,20.0,1.0,10")]), max_size=20),
       st.data())
def test_line_verdicts_do_not_depend_on_how_bytes_are_split(lines, data):
    """RH-BS-1/2/7 and the pieces handed to the vehicle are the same however the stream is cut."""
    stream = b"".join(lines)
    whole, split = judge(), judge()
    whole.backseat_bytes(stream, 0.0)
    cuts = sorted(data.draw(st.lists(st.integers(0, len(stream)), max_size=10)))
    prev = 0
    pieces = []
    for c in cuts + [len(stream)]:
        pieces += split.backseat_bytes(stream[prev:c], 0.0)
        prev = c
    whole.close(0.0)
    pieces += split.close(0.0)
    for c in ("RH-BS-1", "RH-BS-2", "RH-BS-7"):
        assert whole.counts[c] == split.counts[c]
    assert b"".join(p.raw for p in pieces) == stream  # every byte handed on once, in order


# ------------------------------------------------------------------ RH-BS-3 preconditions

def test_oms_while_reported_stopped_offends_but_not_in_flight():
    j = judge()
    j.backseat_bytes(POLL, 0.0)
    j.vehicle_bytes(OSI_S, 0.1)
    j.backseat_bytes(frame("OMS,10.0,2.0,20.0,1.0,10"), 0.3)  # within the reaction time: unknown
    j.backseat_bytes(frame("OMS,11.0,2.0,20.0,1.0,10"), 1.0)  # S reported 0.9 s ago: offence
    assert j.counts["RH-BS-3"] == 1


def test_command_behind_an_unanswered_start_is_judged_by_its_outcome():
    j = judge()
    j.backseat_bytes(POLL, 0.0)
    j.vehicle_bytes(OSI_S, 0.1)
    j.backseat_bytes(frame("OMSTART,0,0,0,0,conformance.mis,"), 2.0)
    j.backseat_bytes(frame("OMS,10.0,2.0,20.0,1.0,10"), 2.01)
    j.vehicle_bytes(frame("ACK,3,0,0") + frame("ACK,9,0,0"), 2.05)
    assert j.counts["RH-BS-3"] == 0
    j.backseat_bytes(frame("ORWSET,SafetyAction,R"), 3.0)  # mission reported running
    assert j.counts["RH-BS-3"] == 1


def test_mission_end_in_flight_is_not_blamed():
    j = judge()
    j.vehicle_bytes(osi("A"), 0.0)
    j.vehicle_bytes(osi("S"), 1.0)
    j.backseat_bytes(frame("OMS,10.0,2.0,20.0,1.0,10"), 1.2)
    assert j.counts["RH-BS-3"] == 0
    j.backseat_bytes(frame("OMS,10.0,2.0,20.0,1.0,10"), 2.0)
    assert j.counts["RH-BS-3"] == 1


# ------------------------------------------------------------------ RH-BS-5 rejections, lockout

def test_resend_of_a_rejected_command_within_a_second():
    j = judge()
    body = "OMS,10.0,2.0,20.0,1.0,10"
    j.backseat_bytes(frame(body), 0.0)
    j.vehicle_bytes(frame("ACK,9,1,20"), 0.05)
    j.backseat_bytes(frame(body), 0.3)  # before it could react: not judged
    j.backseat_bytes(frame(body), 0.6)  # knew for 0.55 s, 0.3 s after the previous: offence
    j.backseat_bytes(frame(body), 1.7)  # 1.1 s later: fine
    j.backseat_bytes(frame("OMS,11.0,2.0,20.0,1.0,10"), 1.8)  # another command: fine
    assert j.counts["RH-BS-5"] == 1
    assert verdicts(j)["RH-BS-5"] == "non-strict"


def test_only_osd_during_a_lockout_once_known():
    j = judge()
    j.lockout(True, 1.0)
    j.backseat_bytes(frame("OMS,10.0,2.0,20.0,1.0,10"), 1.1)  # not known yet
    j.vehicle_bytes(frame("ACK,9,1,26"), 1.15)
    j.backseat_bytes(frame("OMS,11.0,2.0,20.0,1.0,10"), 1.4)  # within the reaction time
    j.backseat_bytes(POLL, 1.8)
    j.backseat_bytes(frame("OMSTOP,0"), 1.9)  # offence
    j.lockout(False, 3.0)
    j.backseat_bytes(frame("OMSTOP,0"), 3.1)
    assert j.counts["RH-BS-5"] == 1


# ------------------------------------------------------------------ RH-BS-6 servo refresh

def test_servo_refresh_after_the_timeout_ran_out():
    j = judge(time_scale=5.0)  # timeout 10 s of vehicle time = 2 s of wall time
    j.backseat_bytes(frame("OMS,10.0,2.0,20.0,1.0,10"), 0.0)
    j.vehicle_bytes(frame("ACK,9,0,0"), 0.01)
    j.backseat_bytes(frame("OMS,11.0,2.0,20.0,1.0,10"), 1.5)
    j.vehicle_bytes(frame("ACK,9,0,0"), 1.51)
    assert j.counts["RH-BS-6"] == 0
    j.backseat_bytes(frame("OMS,12.0,2.0,20.0,1.0,10"), 4.0)  # 2.49 s after: lapsed
    assert j.counts["RH-BS-6"] == 1
    j.vehicle_bytes(frame("ACK,9,0,0"), 4.01)
    j.backseat_bytes(frame("OMP,8080808080,00,5"), 4.5)  # another control: tracking ends
    j.backseat_bytes(frame("OMS,12.0,2.0,20.0,1.0,10"), 9.0)
    assert j.counts["RH-BS-6"] == 1


def test_refresh_in_time_counts_even_when_its_ack_is_late():
    """A refresh that arrives in time keeps control even if the ACK is held up by the line."""
    j = judge(time_scale=5.0)
    j.backseat_bytes(frame("OMS,10.0,2.0,20.0,1.0,10"), 0.0)
    j.vehicle_bytes(frame("ACK,9,0,0"), 0.01)
    for i, t in enumerate((1.5, 3.0, 4.5)):  # their ACKs come only at 5.0
        j.backseat_bytes(frame(f"OMS,{11 + i}.0,2.0,20.0,1.0,10"), t)
    j.vehicle_bytes(frame("ACK,9,0,0") * 3, 5.0)
    j.backseat_bytes(frame("OMS,20.0,2.0,20.0,1.0,10"), 6.0)
    assert j.counts["RH-BS-6"] == 0


# ------------------------------------------------------------------ RH-BS-8 polling

@given(st.lists(st.integers(1, 130), max_size=12), st.integers(0, 130))
def test_polling_offence_iff_some_gap_exceeds_five_seconds(gaps10, tail10):
    """RH-BS-8: with polls at the given gaps (tenths of a second) after the first byte and the
    run ending ``tail`` later, an offence is reported iff some gap exceeds 5 s (+ jitter)."""
    j = judge()
    j.backseat_bytes(frame("OPOS,41.5,-71.3,0,,"), 0.0)
    t = 0.0
    for g in gaps10:
        t += g / 10
        j.backseat_bytes(POLL, t)
    j.close(t + tail10 / 10)
    limit = POLL_INTERVAL_S + j.jitter_s
    expected = any(g / 10 > limit for g in gaps10 + [tail10])
    assert (j.counts["RH-BS-8"] > 0) == expected


# ------------------------------------------------------------------ verdict words and plan

def test_clean_backseat_passes_and_untested_rules_say_why():
    j = judge()
    j.backseat_bytes(POLL, 0.0)
    j.vehicle_bytes(osi("S"), 0.05)
    j.backseat_bytes(POLL, 1.0)
    j.close(2.0)
    v = verdicts(j)
    assert v["RH-BS-1"] == v["RH-BS-4"] == v["RH-BS-7"] == v["RH-BS-8"] == "pass"
    assert v["RH-BS-5"] == v["RH-BS-6"] == "not-tested"


def test_plan_fits_the_lockout_and_keeps_the_order():
    p = make_plan(list(SCENARIOS), 60, time_scale=1.0, lockout_s=20.0)
    assert [s.name for s in p.slots] == list(SCENARIOS)
    lock = next(s for s in p.slots if s.name == "lockout")
    assert lock.end - lock.start >= 20 + 2
    assert abs(p.total - 60) < 1e-6 and not p.note
    short = make_plan(["lockout"], 5, time_scale=1.0, lockout_s=20.0)
    assert short.total > 20 and "lengthened" in short.note


def test_results_document_strict_and_partial():
    """SHOULD missed: non-strict (exit 0), fail with --strict (exit 1); a cut-short run is
    inconclusive with its reason first; every document validates (schema 1, role backseat)."""
    from helmcheck.conformance.backseat.report import build_results
    from helmcheck.conformance.backseat.runner import Outcome
    from helmcheck.reports.results import exit_code, validate

    j = judge()
    j.backseat_bytes(frame("OSD,G,C,S,P,,,,", lower=True), 0.0)
    j.close(1.0)
    for strict, verdict, code in ((False, "non-strict", 0), (True, "fail", 1)):
        r = build_results(Outcome("complete", "the run completed", j, 0.0, 1.0, 1.0), profile=DEFAULT,
                          settings={"strict": strict, "time_scale": 1.0}, command="x", port="pty",
                          started="2026-01-01T00:00:00Z")
        assert not validate(r) and r["role"] == "backseat"
        assert r["verdict"] == verdict and exit_code(verdict, strict) == code
        bs7 = next(c for c in r["clauses"] if c["id"] == "RH-BS-7")
        assert bs7["offending_count"] == 1 and bs7["evidence"][0]["line"] == "$OSD,G,C,S,P,,,,*5f"
    cut = build_results(Outcome("disconnected", "the backseat closed the port or crashed after 0.5 s", j,
                                0.0, 1.0, 10.0), profile=DEFAULT, settings={}, command="x", port="pty",
                        started="2026-01-01T00:00:00Z")
    assert not validate(cut) and cut["verdict"] == "inconclusive" and cut["partial"]
    assert cut["verdict_reason"].startswith("The backseat closed the port")
    never = build_results(None, profile=DEFAULT, settings={}, command="x", port="/dev/ttyX",
                          started="2026-01-01T00:00:00Z", reason="cannot open /dev/ttyX: no such file")
    assert not validate(never) and never["verdict"] == "inconclusive"
