"""The exploration's per-clause confirmation on the wire (``helmcheck/judge/wire.py``,
``helmcheck/judge/ledger.py``): ``confirmed RH-X: …`` books only RH-X's held violations as
violations and holding goes on for the rest; ``unconfirmed RH-Y: …`` books RH-Y's INCONCLUSIVE;
a note without clauses releases what is left and ends the holding."""

from helmcheck.judge.ledger import Ledger
from helmcheck.judge.wire import parse_note


def test_release_notes_name_their_clauses():
    n = parse_note("confirmed RH-ACK-3,RH-SRV-2: reproduced 2 of 2 re-runs after shrinking")
    assert (n.kind, n.clauses, n.text) == ("confirmed", ("RH-ACK-3", "RH-SRV-2"),
                                          "reproduced 2 of 2 re-runs after shrinking")
    n = parse_note("unconfirmed RH-INT-3: reproduced 1 of 2 re-runs after shrinking")
    assert (n.kind, n.clauses) == ("unconfirmed", ("RH-INT-3",))
    n = parse_note("unconfirmed: not confirmed")
    assert (n.kind, n.clauses, n.text) == ("unconfirmed", (), "not confirmed")
    assert parse_note("confirmedRH-ACK-3: x") is None


def test_a_clause_release_books_that_clause_only_and_holding_goes_on():
    led = Ledger(["RH-ACK-3", "RH-SRV-2", "RH-INT-3"])
    led.hold()
    led.failed("RH-ACK-3", "wrong err")
    led.failed("RH-SRV-2", "360 accepted")
    led.failed("RH-INT-3", "park came back")
    assert not any(led.has_failed(c) for c in ("RH-ACK-3", "RH-SRV-2", "RH-INT-3"))
    assert led.held_clauses() == {"RH-ACK-3", "RH-SRV-2", "RH-INT-3"}
    led.release(True, "reproduced 2 of 2", ["RH-ACK-3"])
    assert led.has_failed("RH-ACK-3") and led.holding
    assert led.held_clauses() == {"RH-SRV-2", "RH-INT-3"}
    assert not led.has_failed("RH-SRV-2")
    led.release(False, "reproduced 1 of 2", ["RH-SRV-2"])
    assert led.verdict("RH-SRV-2").verdict == "inconclusive" and led.holding
    assert "reproduced 1 of 2: 360 accepted" in led.verdict("RH-SRV-2").reason
    led.failed("RH-SRV-2", "held again")  # still holding: not booked yet
    assert not led.has_failed("RH-SRV-2")
    led.release(False, "seen between sequences")
    assert not led.holding
    assert led.verdict("RH-INT-3").verdict == "inconclusive"
    assert not led.has_failed("RH-INT-3") and not led.has_failed("RH-SRV-2")
    led.failed("RH-INT-3", "after holding")
    assert led.has_failed("RH-INT-3")
