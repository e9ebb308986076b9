"""RH-BS-5, resend spacing: after a rejection a backseat sends the same command at most once a second.

The rule (:mod:`helmcheck.judge.backseat.reaction`): a rejection starts a series for its command
text; of the sendings that follow the rejected one, only the first may be excused, and only if its
first byte came before the rejection could be known (arrival plus ``reaction_s``): it is the one
copy that may have been in flight. Every other sending is judged against the sending of the same
text just before it (1 s less the observer's jitter, widened by the timestamp step). The sans-IO
tests feed :class:`~helmcheck.judge.backseat.BackseatObserver` by hand; the live one runs a
faulty backseat (``tests/backseats/faulty_backseat.py --fault resend-burst``) through
``certify backseat`` on a pty and reads its report back with ``check-log``.
"""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from helmcheck.checklog.checker import check_log
from helmcheck.grammar import checksum_hex
from helmcheck.judge import Ledger, WireEvent
from helmcheck.judge.backseat import BS_CLAUSES, RESEND_SPACING_S, BackseatObserver
from helmcheck.judge.timing import JITTER_S, transmit_time
from helmcheck.profile import DEFAULT
from tests.test_certify_backseat import FAULTY, certify


def frame(body: str) -> bytes:
    return f"${body}*{checksum_hex(body)}".encode() + b"\r\n"


START = frame("OMSTART,0,0,0,0,conformance.mis,")
REJECTED = frame("ACK,3,1,1")  #: the vehicle refuses the $OMSTART
ACCEPTED = frame("ACK,3,0,0")
LIMIT = RESEND_SPACING_S - JITTER_S


class Run:
    """An observer and its ledger, fed by hand."""

    def __init__(self, resolution: float = 1e-6):
        self.ledger = Ledger(BS_CLAUSES)
        self.o = BackseatObserver(DEFAULT, self.ledger, time_scale=1.0, baud=DEFAULT.baud,
                                  resolution=resolution)
        self.n = 0

    def _ev(self, t: float, d: str, data: bytes = b"", note: str = "") -> "Run":
        self.n += 1
        self.o.feed(WireEvent(t, d, data, note, self.n))
        return self

    def bs(self, t: float, data: bytes = START) -> "Run":
        return self._ev(t, ">", data)

    def veh(self, t: float, data: bytes = REJECTED) -> "Run":
        return self._ev(t, "<", data)

    def close(self, t: float) -> "Run":
        self.o.close(t)
        return self

    @property
    def verdict(self) -> str:
        return self.ledger.verdict("RH-BS-5").verdict

    @property
    def fails(self) -> int:
        return self.ledger.counts("RH-BS-5")["fail"]


def known(t_ack: float, data: bytes = REJECTED) -> float:
    """When a rejection recorded at ``t_ack`` could be known to the backseat."""
    return t_ack + transmit_time(len(data), DEFAULT.baud) + DEFAULT.reaction_s


# ------------------------------------------------------------------ the burst (must not pass)

def test_RH_BS_5_four_resends_within_a_tenth_of_a_second_after_a_rejection_are_non_strict():
    """A rejected $OMSTART answered at once by four more copies within 0.1 s (each refused in
    turn), then sent again 5.3 s later: one copy may have been in flight, the other three came
    0.025 s after the copy before them."""
    r = Run().bs(0.0).veh(0.05)
    for i, t in enumerate((0.06, 0.085, 0.11, 0.135)):
        assert t < known(0.05)  # all within the reaction allowance
        r.bs(t).veh(t + 0.01 + 0.001 * i)
    r.bs(5.3).close(6.0)
    assert r.verdict == "non-strict"  # a SHOULD: a violation is NON-STRICT, not FAIL
    assert r.fails == 3
    v = r.ledger.verdict("RH-BS-5")
    assert v.evidence[0].t == 0.085 and v.evidence[0].text.startswith("$OMSTART")
    assert "0.025 s" in v.reason


def test_RH_BS_5_a_burst_in_one_write_is_judged_copy_by_copy():
    r = Run().bs(0.0).veh(0.05).bs(0.1, START * 4).close(3.0)
    assert r.verdict == "non-strict" and r.fails == 3


def test_RH_BS_5_copies_already_on_the_line_when_the_rejection_arrives_excuse_only_one():
    """Four copies sent before the first one's rejection had even arrived: one was in flight,
    the other three are resends of a rejected command 0.01 s apart."""
    r = Run().bs(0.0)
    for t in (0.01, 0.02, 0.03, 0.04):
        r.bs(t)
    r.veh(0.05).close(3.0)
    assert r.verdict == "non-strict" and r.fails == 3
    assert r.ledger.verdict("RH-BS-5").evidence[0].t == 0.02


def test_RH_BS_5_a_further_rejection_does_not_excuse_another_copy():
    """The in-flight copy is excused once per rejected text, not once per rejection."""
    r = Run().bs(0.0).veh(0.05)
    r.bs(0.1).veh(0.12)  # excused (in flight); its own rejection starts nothing new
    r.bs(0.15).close(3.0)  # 0.05 s after the copy before it
    assert r.verdict == "non-strict" and r.fails == 1


def test_RH_BS_5_the_first_resend_once_known_is_judged_against_the_rejected_sending():
    r = Run().bs(0.0).veh(0.05).bs(0.5).close(3.0)  # after the allowance: nothing excused
    assert r.verdict == "non-strict" and r.fails == 1


# ------------------------------------------------------------------ conforming backseats pass

def test_RH_BS_5_resent_once_1_2_s_after_the_rejection_passes():
    r = Run().bs(0.0).veh(0.05).bs(1.2).veh(1.25).bs(2.4).close(3.0)
    assert r.verdict == "pass" and r.fails == 0
    assert r.ledger.counts("RH-BS-5")["pass"] == 2


def test_RH_BS_5_one_copy_in_flight_before_the_rejection_then_a_one_second_wait_passes():
    r = Run().bs(0.0).bs(0.03).veh(0.05).veh(0.08)  # the copy at 0.03 crossed the rejection
    r.bs(0.05 + 1.0).close(3.0)  # 1 s after the rejection arrived: 1.02 s after the copy
    assert r.verdict == "pass" and r.fails == 0


def test_RH_BS_5_one_copy_within_the_reaction_allowance_then_a_one_second_wait_passes():
    r = Run().bs(0.0).veh(0.05).bs(0.2).veh(0.22).bs(1.2).close(3.0)
    assert r.verdict == "pass"


def test_RH_BS_5_a_rejected_command_never_resent_passes():
    r = Run().bs(0.0).veh(0.05).close(3.0)
    assert r.verdict == "pass"
    r = Run().bs(0.0).veh(0.05).bs(0.1).veh(0.15).close(3.0)  # only the in-flight copy
    assert r.verdict == "pass"


def test_RH_BS_5_an_accepted_sending_ends_the_rejection():
    r = Run().bs(0.0).veh(0.05).bs(1.2).veh(1.25, ACCEPTED).bs(1.3).close(3.0)
    assert r.verdict == "pass" and r.fails == 0


def test_RH_BS_5_other_commands_in_between_are_not_resends():
    oms = frame("OMS,10.0,2.0,20.0,1.0,10")
    r = Run().bs(0.0).veh(0.05).bs(0.1, oms).bs(0.2, oms).bs(1.1).close(3.0)
    assert r.verdict == "pass"


# ------------------------------------------------------------------ coarse timestamps

def test_RH_BS_5_coarse_timestamps_give_inconclusive_not_non_strict():
    """With a 0.1 s timestamp step, copies 0.9 s apart may have been 1 s apart: INCONCLUSIVE;
    0.8 s apart they certainly were not."""
    r = Run(resolution=0.1).bs(0.0).veh(0.0).bs(0.1).bs(1.0).close(3.0)
    assert r.verdict == "inconclusive" and r.fails == 0
    r = Run(resolution=0.1).bs(0.0).veh(0.0).bs(0.1).bs(0.9).close(3.0)
    assert r.verdict == "non-strict"


def test_RH_BS_5_a_first_copy_within_a_timestamp_step_of_the_known_time_is_inconclusive():
    """With a 0.1 s step the rejection (0.0) was known at about 0.26 s: a copy logged at 0.3 s may
    have been the one sent before it was known; one logged at 0.5 s certainly was not."""
    assert abs(known(0.0) - 0.26) < 0.01
    r = Run(resolution=0.1).bs(0.0).veh(0.0).bs(0.3).close(3.0)
    assert r.verdict == "inconclusive" and "before the refusal could be known" in \
        r.ledger.verdict("RH-BS-5").reason
    r = Run(resolution=0.1).bs(0.0).veh(0.0).bs(0.5).close(3.0)
    assert r.verdict == "non-strict"


# ------------------------------------------------------------------ the rule, generated

GAPS = (0.0, 0.01, 0.03, 0.2, 0.5, 0.9, 1.0, 1.2, 3.0)


@given(st.lists(st.sampled_from(GAPS), min_size=1, max_size=8))
def test_RH_BS_5_non_strict_iff_a_copy_other_than_one_in_flight_is_closer_than_a_second(gaps):
    """The first copy of a rejected $OMSTART sent before the rejection could be known is
    excused; every other copy is judged against the one before it."""
    t_ack = 0.05
    times, t = [], 0.0
    for g in gaps:
        t += g
        times.append(t)
    r = Run().bs(0.0)
    acked = False
    for t in times:
        if not acked and t > t_ack:
            r.veh(t_ack)
            acked = True
        r.bs(t)
    if not acked:
        r.veh(t_ack)
    r.close(times[-1] + 2.0)

    k = known(t_ack)
    expect_fail = any((i > 0 or t >= k) and t - prev < LIMIT
                      for i, (prev, t) in enumerate(zip([0.0] + times, times)))
    assert r.verdict == ("non-strict" if expect_fail else "pass"), (times, k)


# ------------------------------------------------------------------ live: certify backseat

def test_RH_BS_5_live_a_backseat_that_resends_in_a_burst_is_non_strict(tmp_path):
    """``certify backseat`` (time scale 5, one pty, ~20 s) with a backseat that answers its first
    refused ``$OMS`` by four copies within 0.1 s: NON-STRICT on RH-BS-5 and nowhere else, and
    ``check-log`` of its wire log agrees."""
    run = certify(tmp_path / "report", [FAULTY, "--fault", "resend-burst", "--time-scale", "5"])
    cs = {c["id"]: c for c in run["results"]["clauses"]}
    c = cs["RH-BS-5"]
    assert c["verdict"] == "non-strict", (c, run["backseat_err"])
    assert c["offending_count"] >= 3, c  # every copy after the one that may have been in flight
    assert c["evidence"] and all(e["dir"] == ">" and "$OMS," in e["line"] for e in c["evidence"]), c
    others = {cid: (x["verdict"], x["reason"]) for cid, x in cs.items()
              if cid != "RH-BS-5" and x["verdict"] not in ("pass", "not-tested")}
    assert not others, others
    assert run["results"]["verdict"] == "non-strict" and run["rc"] == 0
    out = check_log(run["dir"] / "wire.log", profile=DEFAULT, role="backseat")
    offline = {c["id"]: c for c in out.clauses}
    assert offline["RH-BS-5"]["verdict"] == "non-strict"
    assert offline["RH-BS-5"]["offending_count"] == c["offending_count"]
