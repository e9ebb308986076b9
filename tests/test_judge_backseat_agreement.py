"""One judge for live and offline: generated sessions give identical RH-BS-1..8 entries whether
the backseat observer is fed as the events happen or through the wire log ``check-log`` reads.

"Live" is what ``certify backseat`` does: every event goes through a
:class:`~helmcheck.line.recorder.Recorder`, which writes the wire log and feeds the
observer. "Offline" is ``check_log(..., role="backseat")`` on that very file. The sessions are
generated (commands good and bad, split anywhere; state reports, answers, lockout signs; the
recorder's notes; times from a microsecond to several seconds apart), at two time scales and
two baud rates.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

from hypothesis import given, settings
from hypothesis import strategies as st

from helmcheck.checklog.checker import check_log
from helmcheck.line.recorder import Recorder
from helmcheck.grammar import checksum_hex
from helmcheck.judge import Ledger
from helmcheck.judge.backseat import BS_CLAUSES, BackseatObserver
from helmcheck.profile import DEFAULT


def frame(body: str, *, lower: bool = False, term: bytes = b"\r\n") -> bytes:
    cks = checksum_hex(body)
    return f"${body}*{cks.lower() if lower else cks}".encode() + term


def osi(mode: str, err: str = "N") -> bytes:
    return frame(f"OSI,8080808080,{mode},0,41.52,-71.32,0.00,0.00,{err},0.00,P0,-14.5,,0.0,0.0,0.00,95.0,"
                 f"False,IVER3-EMU,0.0,False,False")


BACKSEAT = [frame("OSD,G,C,S,P,,,,"), frame("OSD,G,C"), frame("OMS,10.0,2.0,20.0,1.0,10"),
            frame("OMS,11.0,2.0,20.0,1.0,5"), frame("OMS,12.0,2.0,20.0,1.0,1"),
            frame("OMSTART,0,0,0,0,conformance.mis,"), frame("OMSTOP,0"), frame("ORWSET,SafetyAction,R"),
            frame("OLOGL,depth,heading"), frame("OMP,8080808090,00,5"), frame("OJW,2"),
            frame("OMP,808088080,00,5"), b"$OSD,G,C,S,P,,,,*5E\r\n", frame("OSD,S", lower=True),
            frame("OSD,S", term=b"\n"), b"noise\x00\xff", b"$OPOS," + b"1" * 300 + b"\r\n",
            frame("OSD,S") * 40, frame("OXFLT,Sop")]
VEHICLE = [osi("S"), osi("N"), osi("A"), osi("M"), osi("N", "Sop"), osi("P", "Sop"), osi("N", "Sle"),
           frame("ACK,3,0,0"), frame("ACK,1,0,0"), frame("ACK,9,0,0"), frame("ACK,9,1,20"),
           frame("ACK,9,1,26"), frame("ACK,8,0,0"), frame("ACK,10,0,0"), frame("ACK,3,1,1"),
           frame("ACK,12,1,34"), frame("ACK,7,0,0")]
NOTES = ["scenario nominal starts", "scenario lockout starts", "lockout starts (Sop)", "lockout ends",
         "silence starts", "silence ends", "reject: every command but $OSD is refused",
         "reject: window ends", "model: Something(x=1)", "link: 9600 baud 8N1 /dev/pts/9"]
STEPS = [0.0, 0.001, 0.01, 0.05, 0.2, 0.26, 0.7, 1.0, 2.5, 5.3, 11.0]

event = st.one_of(
    st.tuples(st.just(">"), st.sampled_from(BACKSEAT), st.integers(0, 400)),
    st.tuples(st.just("<"), st.lists(st.sampled_from(VEHICLE), min_size=1, max_size=3).map(b"".join),
              st.integers(0, 400)),
    st.tuples(st.just("!"), st.sampled_from(NOTES), st.just(0)),
)
session = st.lists(st.tuples(st.sampled_from(STEPS), event), min_size=1, max_size=60)


def _live_and_offline(events, k: float, baud: int, directory: Path):
    ledger = Ledger(BS_CLAUSES)
    observer = BackseatObserver(DEFAULT, ledger, time_scale=k, baud=baud)
    path = directory / "wire.log"
    with open(path, "w", encoding="utf-8") as f:
        rec = Recorder(f, [f"generated  baud {baud}  time_scale {k:g}"], observers=[observer])
        t = 0.123457  # keeps the microsecond digit, as a real recorder's times do
        last = rec.bytes(t, ">", frame("OSD,G,C,S,P,,,,"))
        for dt, (d, payload, cut) in events:
            t += dt
            if d == "!":
                last = rec.note(t, payload)
            else:  # split anywhere: two records, the second 0 or a little later
                cut = min(cut, len(payload))
                last = rec.bytes(t, d, payload[:cut])
                last = rec.bytes(t + (0.000003 if cut % 2 else 0.0), d, payload[cut:])
        rec.close()
    observer.close(last)
    offline = check_log(path, profile=DEFAULT, role="backseat")
    return ledger.entries(), offline.clauses


@settings(derandomize=True, max_examples=80, deadline=None)
@given(session, st.sampled_from([1.0, 5.0]), st.sampled_from([9600, 19200]))
def test_rh_bs_entries_are_identical_live_and_through_the_wire_log(events, k, baud):
    """RH-BS-1..8: the same records give the same entries — verdicts, reasons, cases, evidence,
    log lines, counts — live and offline."""
    with tempfile.TemporaryDirectory() as d:
        live, offline = _live_and_offline(events, k, baud, Path(d))
    assert [c["id"] for c in offline] == list(BS_CLAUSES)
    for a, b in zip(live, offline):
        assert a == b


def test_a_fixed_session_judges_every_clause_the_same_way_live_and_offline(tmp_path):
    """A hand-picked session that exercises RH-BS-1..8 (none left not-tested) agrees too."""
    poll, oms = frame("OSD,G,C,S,P,,,,"), frame("OMS,10.0,2.0,20.0,1.0,10")
    events = [(0.01, ("<", osi("S") + frame("ACK,8,0,0"), 0)), (0.6, (">", oms, 0)),
              (0.01, ("<", frame("ACK,9,1,20"), 0)), (0.4, (">", oms, 5)),
              (0.2, (">", frame("OMSTART,0,0,0,0,conformance.mis,"), 0)), (0.01, ("<", frame("ACK,3,0,0"), 0)),
              (0.5, (">", oms, 0)), (0.01, ("<", frame("ACK,9,0,0"), 0)), (10.3, (">", oms, 0)),
              (0.01, ("<", frame("ACK,9,0,0"), 0)), (0.2, (">", b"xx" + poll, 0)),
              (0.2, (">", frame("OSD,S", lower=True) * 60, 0)), (6.0, (">", poll, 0))]
    live, offline = _live_and_offline(events, 1.0, 19200, tmp_path)
    assert live == offline
    assert all(c["verdict"] != "not-tested" for c in live), [(c["id"], c["reason"]) for c in live]
