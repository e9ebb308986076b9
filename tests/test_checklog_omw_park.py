"""RH-OMW-4 with RH-OUT-4 and RH-RD-5: the end of a park on a queued ``$OMW`` waypoint.

Nobody reports the moment the vehicle is on station at a queued waypoint: the judge places it in
the window between the last report that showed it not there and the first that shows it parked,
narrows that by the park time the reports show, and carries what is left of the window as
uncertainty on the park's timer. A vehicle that arrived at the window's very end shows ``P1``
until its own park ends — after the moment the judge's placement puts the end at, but within that
uncertainty. The judge must accept it (it rejected ``P1`` outright once its own count reached 0:
the count was widened by the report's uncertainty only while it was above 0), and still FAIL a
park that shows ``P1`` past the bound.

The session is the reference emulator's core driven in virtual time: two waypoints queued, the
first with a 14 s park; reports every 0.5 s on the way, then the plant alone until it is on
station, a report just after that, reports a whole number of seconds apart (so none narrows the
start: each shows the count at the same phase), one just before the park's end, then a few more.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from helmcheck.checklog.checker import check_log
from helmcheck.profile import DEFAULT
from tests.faulty_vehicles.base import Model
from tests.virtual_vehicle import VirtualVehicle, osi_fields

PARK_S = 14


def session(path: Path, before_end: float, model_factory=None, every: float = 1.0) -> list:
    """The session above; the report near the end comes ``before_end`` s before the park asked
    for ends, counted from when the vehicle's own model began it (negative: after it). Returns the reports' (v, mode, field 7,
    field 10)."""
    vv = VirtualVehicle(DEFAULT, model_factory)
    seen = []

    def poll() -> None:
        f = osi_fields(vv.send("OSD,G,C,S"))
        seen.append((round(vv.now, 2), f[2], f[7], f[10]))

    vv.send("OMSTART,0,0,0,0,conformance.mis,")
    vv.now += 5.0
    f = osi_fields(vv.send("OSD,G,C,S"))
    lat, lon = float(f[4]) + 30 / 111_320, float(f[5])
    vv.send(f"OMW,{lat:.6f},{lon:.6f},2.0,,20,2.0,{PARK_S},")
    vv.send(f"OMW,{lat + 0.0004:.6f},{lon:.6f},2.0,,20,2.0,0,")
    m = vv.core.model
    while not m.queue_parking:
        vv.now += 0.5
        poll()
        if float(seen[-1][2]) < 4.5:
            break
    while not m.queue_parking:  # the plant alone: on station between two reports
        vv.now += 0.01
        vv.core.tick(vv.now)
    vv.now += 0.01
    poll()
    end = m.timers.deadline("qpark") - m.timers.duration("qpark") + PARK_S  # the park as asked
    while vv.now + every < end - before_end:
        vv.now += every
        poll()
    vv.now = end - before_end
    poll()
    for _ in range(4):
        vv.now += 0.5
        poll()
    vv.write(path)  # without the emulator's own notes: the arrival is unseen
    return seen


@pytest.mark.parametrize("before_end", [0.02, 0.2, 0.4])
def test_a_queued_park_that_began_at_the_end_of_its_window_is_not_a_violation(tmp_path, before_end):
    path = tmp_path / "wire.log"
    seen = session(path, before_end)
    near_end = seen[-5]
    assert near_end[1] == "W" and near_end[3] == "P1", seen[-6:]  # the case in question is in the log
    out = check_log(path, profile=DEFAULT, role="vehicle")
    bad = {c["id"]: c["reason"] for c in out.clauses if c["verdict"] == "fail"}
    assert not bad, (bad, seen[-8:])
    verdicts = {c["id"]: c["verdict"] for c in out.clauses}
    assert verdicts["RH-OMW-4"] == "pass"


class QueueParkOverstays(Model):
    """RH-OMW-4: the park on a queued waypoint shows its count as asked but holds ``P1`` for
    ``OVER`` s more before it ends (a park longer than asked, by more than RH-TIM-1 allows)."""

    OVER = 2.0

    def _fire(self, event, now):
        row = super()._fire(event, now)
        if event == "queue_wp_reached" and self.timers.armed("qpark"):
            self.timers.arm("qpark", now, self.timers.duration("qpark") + self.OVER)
        return row

    def park_remaining(self, now=None, *args, **kw):
        left = super().park_remaining(now, *args, **kw)
        if left is not None and self.mode == "W" and self.queue_parking:
            return max(min(left, 1.0), left - self.OVER)
        return left


def test_a_queued_park_that_overstays_fails_RH_OMW_4(tmp_path):
    """Past the bound: ``P1`` shown 1.5 s after the park should have ended (the tolerance of a
    14 s park is 0.5 s, the observer's own uncertainty here under a second)."""
    path = tmp_path / "wire.log"
    seen = session(path, -1.5, model_factory=QueueParkOverstays)
    assert ("W", "P1") in [(x[1], x[3]) for x in seen[-5:]], seen[-6:]
    out = check_log(path, profile=DEFAULT, role="vehicle")
    verdicts = {c["id"]: (c["verdict"], c["reason"]) for c in out.clauses}
    assert verdicts["RH-OMW-4"][0] == "fail", verdicts["RH-OMW-4"]
