"""A re-drive runs its steps only from the verified reset they were recorded from (``replay.redrive``).

The steps of a replay were recorded from ``S`` (``$OMSTOP,0`` accepted, then ``S`` seen). A vehicle
that a fault the run already found left elsewhere — here in ``A``, its ``$OMSTOP,0`` acknowledged
but ignored in servo mode (RH-MSN-3) — answers the steps as a vehicle in ``A`` does, and whatever
the judge then says of them is about another state than the recorded one: a pass here (the judge
saw ``A``), a failure on RH-ACK-3 in an exploration run (an ``$OMSTOP,0`` between made it expect
``S``), counted there as the replay failing again. With the clauses already found ignored (as
the exploration's confirmation ignores them), the reset's own failure stops nothing; the re-drive
must still not run the steps: INCONCLUSIVE, not faithful (:func:`helmcheck.certify.vehicle.explore.counts` does not count it). The vehicle is the
emulator's core with that fault, in virtual time, behind the certifier's own link and observer.
"""

from __future__ import annotations

from helmcheck.certify.vehicle.explore import counts
from helmcheck.certify.vehicle.replay import redrive
from helmcheck.certify.vehicle.session import frame
from tests.faulty_vehicles import MUTANTS, make_core
from tests.virtual_vehicle import certifier_session

K = 20.0
STEPS = [{"send": "$OMLOAD,helmcheck-missing.mis,1*4F\\r\\n", "t": 0.0}, {"expect": "$ACK,2,1,1"}]


def _session(name):
    mutant = next(m for m in MUTANTS if m.name == name) if name else None
    return certifier_session(make_core(mutant, K, 0.0), K)


def _left_in_servo(name):
    ses = _session(name)
    ses.reset(mission=True)
    sent = ses.exchange(frame("OMS,90,0,20,0.5,120"))  # servo for 120 vehicle seconds (RH-SRV-1: in a mission)
    assert sent.accepted and ses.poll().mode == "A"
    ses.ignore = frozenset({"RH-OUT-4", "RH-MSN-3"})  # found already: the confirmation ignores them
    return ses


def test_steps_are_not_run_when_the_reset_does_not_reach_S():
    ses = _left_in_servo("omstop-ignored-in-servo")
    mark = ses.ledger.mark()
    got = redrive({"steps": STEPS, "time_scale": K}, ses)
    assert got.verdict == "inconclusive" and not got.faithful, got
    assert got.reason.startswith("the verified reset before the steps failed"), got
    assert counts(got, ("RH-ACK-3",)) is None
    assert all(cid != "RH-ACK-3" for cid, _ in ses.ledger.failures_since(mark)), ses.ledger.failures_since(mark)


def test_on_a_conforming_vehicle_the_same_steps_run_and_pass():
    ses = _left_in_servo(None)
    got = redrive({"steps": STEPS, "time_scale": K}, ses)
    assert got.verdict == "pass" and got.faithful, got
    assert counts(got, ("RH-ACK-3",)) is False
