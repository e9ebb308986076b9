"""RH-MSN-3 with RH-LOG-1 (and kin): an answer that names two faults, booked on what the evidence supports.

``$OMSTOP,0`` accepted, then, with no report between, an ``$OLOGL`` refused as a *running* vehicle
refuses it (err 24: accepted only in ``S``, RH-LOG-1). A conforming vehicle in ``S`` accepts it, so
something is wrong — but either of two things: the refusal (a vehicle that stopped and refuses
``$OLOGL`` anyway), or the ``$OMSTOP`` (a vehicle that acknowledged it and did not stop, RH-MSN-3,
for which refusing the ``$OLOGL`` is right). The judge booked the refused command's clause alone.
Now the next report tells them apart — still running: the ``$OMSTOP``'s clause, not the
``$OLOGL``'s; stopped: the ``$OLOGL``'s — and with no report before the record ends (or before
another command) both are booked, each naming the other.

The sessions are the reference emulator's core, driven in virtual time, with its model made
faulty one way or the other (or not at all), recorded without the emulator's notes and checked
as ``check-log`` checks a recording.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from helmcheck.checklog.checker import check_log
from helmcheck.grammar import sentences as s
from helmcheck.profile import DEFAULT
from tests.faulty_vehicles.base import Model
from tests.virtual_vehicle import VirtualVehicle, osi_fields


class OmstopIgnored(Model):
    """RH-MSN-3: ``$OMSTOP,0`` is acknowledged (``$ACK,1,0,0``) and does nothing."""

    def receive(self, item, now):
        if isinstance(item, s.OMSTOP) and self.running and item.flag == 0:
            self.advance(now)
            return [s.ACK(1, 0, 0)]
        return super().receive(item, now)


class OloglRefusedInS(Model):
    """RH-LOG-1: ``$OLOGL`` is refused (err 24) also where it must be accepted, in ``S``."""

    def receive(self, item, now):
        if isinstance(item, s.OLOGL):
            self.advance(now)
            return [s.ACK(5, 1, 24)]
        return super().receive(item, now)


def session(path: Path, model_factory=None, report_after: bool = True) -> list:
    """Start the mission, report for 5 s; ``$OMSTOP,0``; 0.2 s later ``$OLOGL``; then reports for
    3 s (``report_after``) or the record ends. Returns the answers to the two commands."""
    vv = VirtualVehicle(DEFAULT, model_factory)
    vv.send("OMSTART,0,0,0,0,conformance.mis,")
    for _ in range(10):
        vv.now += 0.5
        osi_fields(vv.send("OSD,G,C,S"))
    vv.now += 0.2
    answers = [vv.send("OMSTOP,0")]
    vv.now += 0.2
    answers.append(vv.send("OLOGL,temp,cond"))
    if report_after:
        for _ in range(6):
            vv.now += 0.5
            osi_fields(vv.send("OSD,G,C,S"))
    vv.write(path)
    return answers


def failed(path: Path) -> dict:
    out = check_log(path, profile=DEFAULT, role="vehicle")
    return {c["id"]: c["reason"] for c in out.clauses if c["verdict"] == "fail"}


def test_a_conforming_vehicle_stops_and_accepts_OLOGL(tmp_path):
    path = tmp_path / "wire.log"
    answers = session(path)
    assert [a.split(b"*")[0] for a in answers] == [b"$ACK,1,0,0", b"$ACK,5,0,0"]
    assert failed(path) == {}


def test_an_OMSTOP_not_carried_out_is_booked_on_RH_MSN_3_not_on_the_refusal(tmp_path):
    """The next report shows the vehicle still running: the refusal was right for it."""
    path = tmp_path / "wire.log"
    answers = session(path, OmstopIgnored)
    assert answers[1].startswith(b"$ACK,5,1,24*")
    bad = failed(path)
    assert "RH-MSN-3" in bad and "RH-LOG-1" not in bad, bad
    assert "$OMSTOP,0" in bad["RH-MSN-3"]


def test_a_refusal_in_S_is_booked_on_its_own_clause_not_on_RH_MSN_3(tmp_path):
    """The next report shows the vehicle stopped: the refusal was wrong, the $OMSTOP carried out."""
    path = tmp_path / "wire.log"
    session(path, OloglRefusedInS)
    bad = failed(path)
    assert "RH-LOG-1" in bad and "RH-MSN-3" not in bad, bad


@pytest.mark.parametrize("fault", [OmstopIgnored, OloglRefusedInS], ids=["omstop-ignored", "ologl-refused"])
def test_with_no_report_after_it_the_refusal_names_both(tmp_path, fault):
    """The record ends after the refusal: nothing tells the two apart, both are booked."""
    path = tmp_path / "wire.log"
    session(path, fault, report_after=False)
    bad = failed(path)
    assert {"RH-LOG-1", "RH-MSN-3"} <= set(bad), bad
    assert "may not have been carried out" in bad["RH-MSN-3"], bad["RH-MSN-3"]
    assert "no report tells which" in bad["RH-LOG-1"], bad["RH-LOG-1"]
