"""RH-SAF-1 with RH-OUT-4: a violation raised with ``$OXFLT`` just after an unseen waypoint arrival.

A violation freezes the mission (RH-RD-11), as a remote control does. When the vehicle reached its
next mission waypoint after its last report and before the ``$OXFLT``, the frozen mission heads
for the waypoint after it, and the next report says so. A conforming vehicle: the judge must not
book RH-OUT-4 or RH-SAF-1 on it. The session is the reference emulator's core (its profile
declares ``$OXFLT``), driven in virtual time: the mission started where its first waypoint is a
few metres off, the violation raised after each of a range of delays (so that some land just
after the unseen arrival), then polled; recorded as a wire log without the emulator's own notes
and checked as ``check-log`` checks one.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from helmcheck.checklog.checker import check_log
from helmcheck.profile import emulator_profile
from tests.virtual_vehicle import VirtualVehicle, osi_fields

PROFILE = emulator_profile()


def session(path: Path, delay: float) -> list:
    """``$OMSTART``; reports every 0.5 s until the first waypoint is 3.0–3.6 m off (on station at
    3 m: reached within a second), ``$OXFLT`` ``delay`` s after that report, then reports for 40 s."""
    vv = VirtualVehicle(PROFILE)
    send = vv.send
    seen = []

    send("OMSTART,0,0,0,0,conformance.mis,")
    while vv.now < 600:
        vv.now += 0.5
        f = osi_fields(send("OSD,S"))
        seen.append((f[2], int(f[3]), float(f[7])))
        if f[2] == "N" and int(f[3]) == 0 and 3.0 < float(f[7]) <= 3.6:
            break
    vv.now += delay
    send("OXFLT,Sle")
    seen.append(("OXFLT", delay, 0.0))
    end = vv.now + 40.0
    while vv.now < end:
        vv.now += 0.5
        f = osi_fields(send("OSD,S"))
        if f is not None:
            seen.append((f[2], int(f[3]), float(f[7])))
    vv.write(path)
    return seen


@pytest.mark.parametrize("delay", [0.05, 0.2, 0.4, 0.6, 0.8, 1.0, 1.5])
def test_a_violation_just_after_an_unseen_waypoint_arrival_is_not_a_failure(tmp_path, delay):
    path = tmp_path / "wire.log"
    seen = session(path, delay)
    out = check_log(path, profile=PROFILE, role="vehicle")
    bad = {c["id"]: c["reason"] for c in out.clauses if c["verdict"] == "fail"}
    assert not bad, (bad, seen[:4])


def test_the_delays_straddle_the_arrival(tmp_path):
    """The range of delays is where it must be: the first waypoint is reached within it (the
    report after the violation heads for waypoint 0 with the shortest delay, 1 with the longest)."""
    def after(seen):
        i = next(i for i, x in enumerate(seen) if x[0] == "OXFLT")
        return seen[i + 1][1]
    assert after(session(tmp_path / "a.log", 0.05)) == 0
    assert after(session(tmp_path / "b.log", 1.5)) == 1
