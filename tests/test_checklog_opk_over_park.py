"""RH-INT-2 with RH-RD-5 and RH-OUT-4: an ``$OPK`` over a running mission park, and the park resumed.

While the ``$OPK`` park runs, the mission park is frozen (RH-RD-5); when the ``$OPK`` time is up
the vehicle resumes the mission park with the time that was left (RH-INT-2) and counts it down
from the release. The judge knows neither of the two exactly: the time left is as uncertain as
its count of the park was when the ``$OPK`` came (a park first seen after it began, its length
learnt from the reports), and the release comes when the ``$OPK`` count, started at an on-station
moment nobody reports, runs out — anywhere within RH-TIM-1's tolerance of it. It used to start
the resumed count at its own estimate of the release as if that were exact, and the errors of
each ``$OPK`` over the same park added up: a conforming vehicle's ``P`` reports a second off were
FAILed. It also took a report that already showed the ``$OPK`` count running (``P59`` of 60) for
the count not yet begun (a count that does not run was widened like one that does), so the
on-station moment was placed after it happened.

The sessions are the reference emulator's core driven in virtual time: ``conformance.mis`` to
its mission park (waypoint 1, 300 s), a report every 0.5 s, then, again and again, an ``$OPK``
20 m away for a minute some seconds into the park, until the mission park runs again; checked
as ``check-log`` checks a recording (no emulator notes), without and with the mission files.
The profile leaves room for a vehicle that counts the resumed park only once back on station at
its waypoint (the paper: "once control is released the vehicle will park for the remaining
time"): the emulator's ``resumed_park = "on station"``, which heads back first; it PASSes too.
The faulty counterparts resume the mission park with the wrong time left, let it count down
during the ``$OPK`` park, or hold it and never count once back on station: still FAILed.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from helmcheck.checklog.checker import check_log
from helmcheck.emulator.freedoms import EmulatorSettings
from helmcheck.emulator.missionfile import DirectoryCatalog, builtin_dir
from helmcheck.profile import DEFAULT
from tests.faulty_vehicles.base import Model
from tests.virtual_vehicle import VirtualVehicle, osi_fields


def session(path: Path, phase: float, times: int = 3, model_factory=None, settings=None) -> list:
    """The session above (``phase``: a shift of the reports against the park's count); returns
    the reports' (v, mode, field 7, field 10)."""
    vv = VirtualVehicle(DEFAULT, model_factory, settings)
    m = vv.core.model
    seen = []

    def poll() -> list:
        f = osi_fields(vv.send("OSD,G,C,S"))
        seen.append((round(vv.now, 2), f[2], f[7], f[10]))
        return f

    vv.send("OMSTART,0,0,0,0,conformance.mis,")
    while m.mode != "P" and vv.now < 400:
        vv.now += 0.5
        poll()
    for _ in range(times):
        until = vv.now + 20.0
        while vv.now < until:
            vv.now += 0.5
            f = poll()
        vv.now += phase
        f = poll()
        vv.now += 0.05
        vv.send(f"OPK,{float(f[4]) + 20 / 111_320:.6f},{float(f[5]):.6f},1,2.0")
        while m.mode == "mP":
            vv.now += 0.5
            poll()
    until = vv.now + 60.0
    while vv.now < until and m.mode == "P":
        vv.now += 0.5
        poll()
    vv.write(path)  # without the emulator's own notes, as a real vehicle's line is recorded
    return seen


def judged(path: Path, missions: bool) -> dict:
    catalog = DirectoryCatalog([builtin_dir()]) if missions else None
    out = check_log(path, profile=DEFAULT, role="vehicle", catalog=catalog)
    return {c["id"]: (c["verdict"], c["reason"]) for c in out.clauses}


def resumed(seen: list) -> int:
    """How many times the reports show the mission park resumed after an ``$OPK`` park."""
    return sum(1 for a, b in zip(seen, seen[1:]) if (a[1], b[1]) == ("mP", "P"))


@pytest.mark.parametrize("missions", [False, True], ids=["learnt", "given"])
@pytest.mark.parametrize("phase", [0.0, 0.111, 0.222])
def test_an_opk_over_a_mission_park_and_the_park_resumed_is_not_a_violation(tmp_path, phase, missions):
    path = tmp_path / "wire.log"
    seen = session(path, phase)
    assert resumed(seen) == 3, seen[-4:]
    v = judged(path, missions)
    bad = {c: r for c, (verdict, r) in v.items() if verdict == "fail"}
    assert not bad, bad
    assert v["RH-INT-2"][0] == "pass" and v["RH-PK-3"][0] == "pass", (v["RH-INT-2"], v["RH-PK-3"])


def test_a_release_late_on_a_control_tick_resumes_the_park_late_and_is_not_a_violation(tmp_path):
    """A vehicle whose control loop acts on 0.4 s ticks (a freedom, ``control_tick_s``): the
    ``$OPK`` time runs out up to a tick late, and the resumed park counts from then."""
    path = tmp_path / "wire.log"
    seen = session(path, 0.0, settings=EmulatorSettings(control_tick_s=0.4))
    assert resumed(seen) == 3
    bad = {c: r for c, (verdict, r) in judged(path, False).items() if verdict == "fail"}
    assert not bad, bad


@pytest.mark.parametrize("times", [1, 3])
def test_a_resumed_park_that_counts_once_back_on_station_is_not_a_violation(tmp_path, times):
    """The profile's other reading (RH-INT-2; the paper: "the vehicle will park for the remaining
    time"): the resumed park counts only once the vehicle is back on station at its waypoint, which
    it heads for first (``resumed_park = "on station"``)."""
    path = tmp_path / "wire.log"
    seen = session(path, 0.0, times=times, settings=EmulatorSettings(resumed_park="on station"))
    i = next(i for i, (a, b) in enumerate(zip(seen, seen[1:])) if (a[1], b[1]) == ("mP", "P"))
    held = [x for x in seen[i + 1:i + 8]]
    assert len({x[3] for x in held}) == 1 and float(held[0][2]) > 10, held  # held while away
    for missions in (False, True):
        v = judged(path, missions)
        bad = {c: r for c, (verdict, r) in v.items() if verdict == "fail"}
        assert not bad, (missions, bad)


class ResumesWithLess(Model):
    """RH-INT-2: the mission park resumes with ``LESS`` s less than was left when the ``$OPK`` came."""

    LESS = 2.5

    def _release(self, row, now):
        super()._release(row, now)
        t = self.timers
        if self.mode == "P" and t.armed("park"):
            t.arm("park", now, max(1.0, t.duration("park") - self.LESS))


class ParkRunsUnderOpk(Model):
    """RH-RD-5: the mission park keeps counting while the ``$OPK`` park runs."""

    def _transition(self, row, now):
        left = self.park_left if self.mode == "P" else None
        armed = self.timers.armed("park") and self.timers.deadline("park")
        super()._transition(row, now)
        if armed and self.mode == "mP":  # frozen by the model: let it run on, behind the $OPK
            self.park_left = max(1.0, armed - now)
            self._ran_from = (now, self.park_left)
        elif self.mode == "P" and getattr(self, "_ran_from", None) is not None and self.timers.armed("park"):
            since, was = self._ran_from
            self._ran_from = None
            self.timers.arm("park", now, max(1.0, was - (now - since)))
        del left


class NeverResumes(Model):
    """RH-INT-2: a resumed park held until back on station (the other reading) that does not count
    down once there either."""

    def plant(self, event, now):
        if self.mode == "P" and self.park_waiting and type(event).__name__ == "OnStation":
            self._run_due(now)
            return []
        return super().plant(event, now)


@pytest.mark.parametrize("fault,clauses,settings", [
    (ResumesWithLess, {"RH-INT-2"}, None),
    (ParkRunsUnderOpk, {"RH-INT-2"}, None),
    (NeverResumes, {"RH-INT-2"}, EmulatorSettings(resumed_park="on station")),
], ids=["resumes-with-less", "runs-under-opk", "never-resumes"])
def test_a_mission_park_resumed_with_the_wrong_time_left_fails(tmp_path, fault, clauses, settings):
    path = tmp_path / "wire.log"
    session(path, 0.0, times=1, model_factory=fault, settings=settings)
    v = judged(path, True)
    failed = {c for c, (verdict, _) in v.items() if verdict == "fail"}
    assert clauses <= failed, {c: v[c] for c in failed}
