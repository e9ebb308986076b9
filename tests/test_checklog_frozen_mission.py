"""RH-INT-1 with RH-RD-5, RH-RD-11 and RH-SAF-1: which mission behaviour a remote control froze,
when no report can tell.

An ``$OPK`` accepted just after the vehicle reached its next mission waypoint, unseen (the last
report showed it 3.2 m short of a waypoint with a mission park): the park began, and the ``$OPK``
froze it, with its whole time left (RH-RD-5) — or the ``$OPK`` came first and froze the mission on
its way. Both are conforming; no ``mP`` report tells them apart, so the judge follows both. It
used to keep only one of them each time it adopted an unseen event for the ``$OPK`` park (on
station at its position; the leak sensor tripping, seen first as a command refused with err 26),
and FAILed the vehicle when the lockout showed the frozen mission mode ``P`` with the park's whole
time (RH-RD-11) where the one it kept says ``N``.

The session is the reference emulator's core driven in virtual time; the leak sensor trips by
itself (an operator on the bench), as the realistic sessions' vehicle does; checked with the
mission files (the realistic session that found it had learnt the park from an earlier run).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from helmcheck.checklog.checker import check_log
from helmcheck.emulator.missionfile import DirectoryCatalog, builtin_dir
from helmcheck.profile import DEFAULT
from tests.virtual_vehicle import VirtualVehicle, osi_fields


def session(path: Path, reached: bool) -> list:
    """To 3.25–3.8 m short of waypoint 1 (its 300 s park), then the plant alone until it reaches
    it (``reached``) or not, the ``$OPK`` 20 m off; reports every 0.5 s for 60 s; the leak sensor
    trips, an ``$OMW,Clr`` is refused (26) before any report, then reports for 5 s."""
    vv = VirtualVehicle(DEFAULT)
    m = vv.core.model
    seen = []

    def poll() -> list:
        f = osi_fields(vv.send("OSD,G,C,S"))
        seen.append((round(vv.now, 2), f[2], f[8], f[10]))
        return f

    vv.send("OMSTART,0,0,0,0,conformance.mis,")
    f = poll()
    while not (f[2] == "N" and int(f[3]) == 1 and float(f[7]) <= 3.8):
        vv.now += 0.5
        f = poll()
    if reached:
        while m.mode != "P":
            vv.now += 0.01
            vv.core.tick(vv.now)
    vv.now += 0.01
    assert m.mode == ("P" if reached else "N")
    vv.send(f"OPK,{float(f[4]) + 20 / 111_320:.6f},{float(f[5]):.6f},3,2.0")
    until = vv.now + 60.0
    while vv.now < until:
        vv.now += 0.5
        poll()
    vv.now += 0.1
    vv.core.inject_fault("Sle", vv.now, source="leak sensor")
    vv.now += 0.2
    vv.send("OMW,Clr")
    for _ in range(10):
        vv.now += 0.5
        poll()
    vv.write(path)  # without the emulator's own notes (the trip's among them)
    return seen


@pytest.mark.parametrize("reached", [True, False], ids=["park-frozen", "on-the-way-frozen"])
def test_the_mission_behaviour_an_opk_froze_is_followed_both_ways(tmp_path, reached):
    path = tmp_path / "wire.log"
    seen = session(path, reached)
    lockout = [x for x in seen if x[2] == "Sle"]
    assert lockout and lockout[0][1] == ("P" if reached else "N"), seen[-12:]
    if reached:
        assert lockout[0][3] == "P300", lockout[0]  # the park's whole time, frozen
    # with the mission files: the judge knows the park at waypoint 1 (a park it has not learnt yet
    # is not among what it follows after an unseen arrival — README, open)
    out = check_log(path, profile=DEFAULT, role="vehicle", catalog=DirectoryCatalog([builtin_dir()]))
    bad = {c["id"]: c["reason"] for c in out.clauses if c["verdict"] == "fail"}
    assert not bad, bad


def park_violation_session(path: Path, phase: float) -> list:
    """To the mission park of ``conformance.mis``, reports every 0.5 s for 20 s of it, then a
    violation the vehicle raises by itself ``phase`` s after a report (no report between), and
    reports for 5 s: the lockout shows the mission park frozen with the time left then (RH-RD-11)."""
    vv = VirtualVehicle(DEFAULT)
    m = vv.core.model
    seen = []

    def poll() -> list:
        f = osi_fields(vv.send("OSD,S"))
        seen.append((round(vv.now, 2), f[2], f[8], f[10]))
        return f

    vv.send("OMSTART,0,0,0,0,conformance.mis,")
    while m.mode != "P" and vv.now < 400:
        vv.now += 0.5
        poll()
    until = vv.now + 20.0
    while vv.now < until:
        vv.now += 0.5
        poll()
    vv.now += phase
    vv.core.inject_fault("Sfp", vv.now, source="the vehicle's own rule")
    for _ in range(10):
        vv.now += 0.5
        poll()
    vv.write(path)
    return seen


@pytest.mark.parametrize("phase", [0.25])
def test_a_violation_in_a_mission_park_shows_its_time_left_frozen(tmp_path, phase):
    """The park's time left frozen at a moment the observer places in a window (the violation is
    unseen until the next report) is as uncertain as that moment: field 10 may show it a second
    either way of the window's start."""
    path = tmp_path / "wire.log"
    seen = park_violation_session(path, phase)
    assert seen[-1][1:3] == ("P", "Sfp"), seen[-3:]
    out = check_log(path, profile=DEFAULT, role="vehicle")
    bad = {c["id"]: c["reason"] for c in out.clauses if c["verdict"] == "fail"}
    assert not bad, bad
