"""RH-POS-2 with RH-OUT-4: an ``$OPOS`` that moves a submerged vehicle onto its next waypoint.

Without a GPS fix an accepted ``$OPOS`` position is applied (RH-POS-2): the vehicle is where the
fix says at once, however far that is from where its reports put it. When that puts it on the
mission waypoint it was heading for, its next report shows the waypoint reached (here a mission
park) although no speed could have carried it there in the time. A conforming vehicle: the judge
must not book RH-OUT-4 on it. The session is the reference emulator's core, driven in virtual
time by a short script (poll, then the fix two metres from the park waypoint when the vehicle is
about five metres out), recorded as a wire log without the emulator's own notes (as a real
vehicle's line is recorded) and checked as ``check-log`` checks one.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from helmcheck.checklog.checker import check_log
from helmcheck.profile import DEFAULT
from tests.virtual_vehicle import VirtualVehicle, osi_fields

PARK_WP = (41.522698, -71.320000)  # conformance.mis waypoint 1 (a 300 s mission park)


def session(path: Path, *, fix_metres: float) -> list:
    """Drive the emulator to the park waypoint; ``$OPOS`` ``fix_metres`` south of it when the
    vehicle reports 4.5–6 m to go. Returns the reports' (mode, waypoint, distance)."""
    vv = VirtualVehicle(DEFAULT)
    send = vv.send
    seen = []
    sent_fix, after = False, None

    send("OMSTART,0,0,0,0,conformance.mis,")
    while vv.now < 600 and (after is None or vv.now < after):
        vv.now += 0.5
        f = osi_fields(send("OSD,G,C,S"))
        if f is None:
            continue
        mode, wp, dist = f[2], int(f[3]), float(f[7])
        seen.append((mode, wp, dist))
        if not sent_fix and mode == "N" and wp == 1 and 4.5 <= dist <= 6.0:
            vv.now += 0.02
            send(f"OPOS,{PARK_WP[0] - fix_metres / 111_320:.6f},{PARK_WP[1]:.6f},2.0,30.71,9.0")
            sent_fix, after = True, vv.now + 5.0
    vv.write(path)  # without the emulator's own notes, as a real vehicle's line is recorded
    return seen


def test_an_opos_that_puts_a_submerged_vehicle_on_its_waypoint_is_not_a_violation(tmp_path):
    path = tmp_path / "wire.log"
    seen = session(path, fix_metres=2.0)
    assert ("P", 1) in [(m, w) for m, w, _ in seen], seen[-8:]  # the fix put it on station: the park began
    out = check_log(path, profile=DEFAULT, role="vehicle")
    verdicts = {c["id"]: (c["verdict"], c["reason"]) for c in out.clauses}
    assert verdicts["RH-POS-2"][0] != "fail", verdicts["RH-POS-2"]
    assert verdicts["RH-OUT-4"][0] != "fail", verdicts["RH-OUT-4"]


def surfacing_session(path: Path, delay: float) -> list:
    """The mission dives, ``$OMSTOP``: the vehicle floats up; a report every 0.2 s until it is
    just under the GPS-fix depth, then ``$OPOS`` 110 m away ``delay`` s later — when it may have
    reached the surface (a fix: not applied) or not (applied) — then reports for 10 s."""
    vv = VirtualVehicle(DEFAULT)
    send = vv.send
    seen = []

    send("OMSTART,0,0,0,0,conformance.mis,")
    while vv.now < 300 and float(osi_fields(send("OSD,S"))[15]) < 1.0:
        vv.now += 0.5
    send("OMSTOP,0")
    fix = DEFAULT.gps_fix_depth_m
    while vv.now < 400:
        vv.now += 0.2
        f = osi_fields(send("OSD,S"))
        seen.append((round(vv.now, 1), float(f[15])))
        if fix < float(f[15]) <= fix + 0.1:
            break
    vv.now += delay
    send(f"OPOS,{float(f[4]) + 0.001:.6f},{float(f[5]):.6f},0,,")
    seen.append(("OPOS", delay))
    end = vv.now + 10.0
    while vv.now < end:
        vv.now += 0.5
        f = osi_fields(send("OSD,S"))
        seen.append((round(vv.now, 1), float(f[15])))
    vv.write(path)  # without the emulator's own notes, as a real vehicle's line is recorded
    return seen


@pytest.mark.parametrize("delay", [0.2, 0.6, 1.0, 1.5])
def test_an_opos_while_the_vehicle_crosses_the_gps_fix_depth_is_not_a_violation(tmp_path, delay):
    """RH-POS-2 with RH-RD-10: the last report before the ``$OPOS`` shows the vehicle just under
    the GPS-fix depth and rising; by the ``$OPOS`` it may have a fix (and leave the position) or
    not yet (and apply it): a conforming vehicle either way."""
    seen = surfacing_session(tmp_path / "wire.log", delay)
    out = check_log(tmp_path / "wire.log", profile=DEFAULT, role="vehicle")
    bad = {c["id"]: c["reason"] for c in out.clauses if c["verdict"] == "fail"}
    assert not bad, (bad, seen[-12:])
