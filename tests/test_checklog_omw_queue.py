"""RH-OMW-2: the ``$OMW`` queue in arrival order, judged from field 7 — only on evidence that
excludes every conforming explanation.

No report says which queued waypoint the vehicle has reached (the mode stays ``W``); the judge
follows the waypoints it may be heading for from field 7 (:mod:`helmcheck.judge.vehicle.queuetarget`).
It used to follow one guess, and to start over, as if the vehicle had set out for the first
queued waypoint again, whenever the queue changed — also when an ``$OMW`` in ``W`` only appended
a waypoint (RH-RD-3). A vehicle that had passed its first waypoint unseen and was heading for the
second was then "seen" heading for the second before it could have reached the first: RH-OMW-2
FAILed on a conforming vehicle (a distance taken as proof of which waypoint it heads for).

The sessions are the reference emulator's core driven in virtual time: two waypoints queued
(the second 80 m beyond the first), reports every 0.5 s, a third waypoint appended when the
vehicle is well on its way to the second, reports on; recorded without the emulator's notes and
checked as ``check-log`` checks a recording. An ``$OPOS`` that puts the submerged vehicle on its
head waypoint at once (RH-POS-2) is no disorder either. The faulty counterpart takes an appended
waypoint first: still RH-OMW-2's FAIL.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from helmcheck.checklog.checker import check_log
from helmcheck.grammar import sentences as s
from helmcheck.profile import DEFAULT
from tests.faulty_vehicles.base import Model
from tests.virtual_vehicle import VirtualVehicle, osi_fields

M_PER_DEG = 111_320.0


def session(path: Path, on_the_way_m: float, model_factory=None) -> list:
    """The session above: the third waypoint appended ``on_the_way_m`` metres after the vehicle
    passed the first (as the vehicle's own model has it). Returns the reports' (v, mode, field 7)."""
    vv = VirtualVehicle(DEFAULT, model_factory)
    m = vv.core.model
    seen = []

    def poll() -> list:
        f = osi_fields(vv.send("OSD,G,C,S"))
        seen.append((round(vv.now, 2), f[2], float(f[7])))
        return f

    vv.send("OMSTART,0,0,0,0,conformance.mis,")
    vv.now += 5.0
    f = poll()
    lat, lon = float(f[4]), float(f[5])
    w1 = (lat + 20 / M_PER_DEG, lon)
    w2 = (w1[0], lon + 80 / (M_PER_DEG * 0.75))
    w3 = (w2[0] + 40 / M_PER_DEG, w2[1])
    for w in (w1, w2):
        vv.send(f"OMW,{w[0]:.6f},{w[1]:.6f},2.0,,20,2.0,0,")
    while len(m.queue) == 2 and vv.now < 200:
        vv.now += 0.5
        poll()
    until = vv.now + on_the_way_m / 1.03  # 2 kn
    while vv.now < until:
        vv.now += 0.5
        poll()
    vv.now += 0.1
    vv.send(f"OMW,{w3[0]:.6f},{w3[1]:.6f},2.0,,20,2.0,0,")
    while m.mode == "W" and vv.now < until + 200:
        vv.now += 0.5
        poll()
    vv.write(path)  # without the emulator's own notes: no waypoint reached is seen
    return seen


def judged(path: Path) -> dict:
    out = check_log(path, profile=DEFAULT, role="vehicle")
    return {c["id"]: (c["verdict"], c["reason"]) for c in out.clauses}


@pytest.mark.parametrize("on_the_way_m", [5.0, 20.0, 50.0])
def test_a_waypoint_appended_after_an_unseen_arrival_is_no_disorder(tmp_path, on_the_way_m):
    path = tmp_path / "wire.log"
    seen = session(path, on_the_way_m)
    assert seen[-1][1] == "N", seen[-3:]  # the whole queue was followed, and the mission resumed
    v = judged(path)
    bad = {c: r for c, (verdict, r) in v.items() if verdict == "fail"}
    assert not bad, bad
    assert v["RH-OMW-2"][0] == "pass", v["RH-OMW-2"]


def opos_session(path: Path) -> list:
    """Two waypoints queued 40 m apart; when the vehicle (submerged: no GPS fix) is 12 m short of
    the first, an ``$OPOS`` puts it on it (RH-POS-2 applies it at once); reports on."""
    vv = VirtualVehicle(DEFAULT)
    m = vv.core.model
    seen = []

    def poll() -> list:
        f = osi_fields(vv.send("OSD,G,C,S"))
        seen.append((round(vv.now, 2), f[2], float(f[7])))
        return f

    vv.send("OMSTART,0,0,0,0,conformance.mis,")
    vv.now += 5.0
    f = poll()
    w1 = (float(f[4]) + 40 / M_PER_DEG, float(f[5]))
    w2 = (w1[0] + 40 / M_PER_DEG, w1[1])
    for w in (w1, w2):
        vv.send(f"OMW,{w[0]:.6f},{w[1]:.6f},2.0,,20,2.0,0,")
    while (m.mode != "W" or float(f[7]) > 12.0 or m.gps_fix) and vv.now < 200:
        vv.now += 0.5
        f = poll()
    vv.now += 0.2
    vv.send(f"OPOS,{w1[0]:.6f},{w1[1]:.6f},2.0,33.0,12.0")
    for _ in range(6):
        vv.now += 0.5
        poll()
    vv.write(path)
    return seen


def test_an_opos_that_puts_the_vehicle_on_a_queued_waypoint_is_no_disorder(tmp_path):
    """RH-POS-2 with RH-OMW-2: the fix moved the vehicle onto its head waypoint at once; it heads
    for the next (its next report's field 7 is the distance to it), which no speed explains."""
    path = tmp_path / "wire.log"
    seen = opos_session(path)
    assert any(d > 30 for _, mode, d in seen[-6:]), seen[-8:]  # heading for the second at once
    v = judged(path)
    bad = {c: r for c, (verdict, r) in v.items() if verdict == "fail"}
    assert not bad, bad


class AppendedFirst(Model):
    """RH-OMW-2: an ``$OMW`` accepted in ``W`` goes to the head of the queue (newest first)."""

    def receive(self, item, now):
        was = self.mode == "W" and len(self.queue)
        out = super().receive(item, now)
        if was and isinstance(item, s.OMW) and len(self.queue) > was:
            self.queue.insert(0, self.queue.pop())
            self._control_changed()
        return out


def test_a_vehicle_that_takes_the_appended_waypoint_first_fails_RH_OMW_2(tmp_path):
    path = tmp_path / "wire.log"
    session(path, 20.0, model_factory=AppendedFirst)
    v = judged(path)
    assert v["RH-OMW-2"][0] == "fail", v["RH-OMW-2"]
    assert "not kept in arrival order" in v["RH-OMW-2"][1]


def test_heads_that_may_have_been_the_popped_waypoint_go_on_to_the_next():
    """Sans-IO, on :class:`~helmcheck.judge.vehicle.queuetarget.QueueTarget` with the reference model:
    where the vehicle may have been heading for the first queued waypoint or a later one (an
    ``$OPOS`` applied made every later one reachable, and field 7 fitted two), and the mirror then
    drops the first (its park ended), the vehicle may now head for the new first one: a report
    that fits it is no disorder (the heads kept only the later one, shifted, and a report fitting
    the new first one, then one further on, was booked as out of order)."""
    from helmcheck.grammar import parse
    from helmcheck.grammar.checksum import checksum_hex
    from helmcheck.judge.ledger import Ledger
    from helmcheck.judge.vehicle.queuetarget import QueueTarget
    from helmcheck.model.geo import distance_m
    from helmcheck.model.plant import QueueWaypointReached
    from helmcheck.model.testing import catalog
    from helmcheck.model.vehicle import VehicleModel

    def cmd(body: str):
        return parse(f"${body}*{checksum_hex(body)}".encode())

    lat0, lon0 = 41.52, -71.32
    wps = [(lat0 + 20 / M_PER_DEG, lon0), (lat0, lon0 + 60 / 83_500), (lat0 + 20 / M_PER_DEG, lon0 + 3 / 83_500)]
    m = VehicleModel(DEFAULT, catalog())
    m.receive(cmd("OMSTART,0,0,0,0,conformance.mis,"), 0.0)
    m.receive(cmd(f"OMW,{wps[0][0]:.6f},{wps[0][1]:.6f},2.0,,20,2.0,10,"), 1.0)
    for w in wps[1:]:
        m.receive(cmd(f"OMW,{w[0]:.6f},{w[1]:.6f},2.0,,20,2.0,0,"), 1.0)
    booked = []
    q = QueueTarget(Ledger(["RH-OMW-2"]), DEFAULT.on_station_m, DEFAULT.max_speed_kn)

    def report(v: float, at: tuple, head: int) -> None:
        d = distance_m(*at, *wps[head])
        body = (f"OSI,8080808080,W,0,{at[0]:.8f},{at[1]:.8f},0.00,{d:.2f},N,38.00,P0,-14.5000,"
                f"conformance.mis,4.5,0.0,2.00,94.7,False,IVER3-EMU,0.0,False,False")
        q.report(parse(f"${body}*{checksum_hex(body)}".encode()), m, v, v + 0.1, [], "",
                 lambda verdict, clauses, reason: booked.append(reason))

    report(2.0, (lat0, lon0), 0)
    q.moved()  # an $OPOS applied: every later waypoint reachable by the next report
    report(2.5, (lat0 + 1 / M_PER_DEG, lon0), 0)  # fits waypoints 1 and 3 (as far as each)
    assert set(q.heads) == {0, 2}, q.heads
    m.plant(QueueWaypointReached(), 3.0)  # the first reached, its park begun ...
    m.advance(14.0)                       # ... and over: the mirror drops it
    assert len(m.queue) == 2
    report(14.5, wps[0], 1)  # heading for the second queued (now the first)
    assert booked == [], booked
    assert 0 in q.heads, q.heads


def test_a_report_of_a_queued_park_s_last_moment_says_nothing_of_the_next_head():
    """Sans-IO: the mirror has ended the park on the first queued waypoint at its nominal end; the
    vehicle, within RH-TIM-1's tolerance, still parks (``W``, ``P1``, field 7 its distance to the
    parked waypoint), and a later queued waypoint happens to be as far. That report says nothing of
    which waypoint the vehicle heads for next (it was taken for the later one, and the next report,
    heading for the new first one, was booked as out of order)."""
    from helmcheck.grammar import parse
    from helmcheck.grammar.checksum import checksum_hex
    from helmcheck.judge.ledger import Ledger
    from helmcheck.judge.vehicle.queuetarget import QueueTarget
    from helmcheck.model.geo import distance_m
    from helmcheck.model.plant import QueueWaypointReached
    from helmcheck.model.testing import catalog
    from helmcheck.model.vehicle import VehicleModel

    def cmd(body: str):
        return parse(f"${body}*{checksum_hex(body)}".encode())

    lat0, lon0 = 41.52, -71.32
    # the parked waypoint, one 60 m east, one as far from where the vehicle parks (3.9 m north of
    # it) as the parked one, and one as far from there as the one 60 m east
    # with one 50 m north of it between the last two
    wps = [(lat0, lon0), (lat0, lon0 + 60 / 83_500), (lat0 + 3.9 / M_PER_DEG, lon0 + 3.9 / 83_500),
           (lat0 + 54 / M_PER_DEG, lon0), (lat0 + 3.9 / M_PER_DEG, lon0 - 60.1 / 83_500)]
    m = VehicleModel(DEFAULT, catalog())
    m.receive(cmd("OMSTART,0,0,0,0,conformance.mis,"), 0.0)
    m.receive(cmd(f"OMW,{wps[0][0]:.6f},{wps[0][1]:.6f},2.0,,20,2.0,10,"), 1.0)
    for w in wps[1:]:
        m.receive(cmd(f"OMW,{w[0]:.6f},{w[1]:.6f},2.0,,20,2.0,0,"), 1.0)
    booked = []
    q = QueueTarget(Ledger(["RH-OMW-2"]), DEFAULT.on_station_m, DEFAULT.max_speed_kn)
    here = (lat0 + 3.9 / M_PER_DEG, lon0)  # parked 3.9 m north of it (on station: within tolerance)

    def report(v: float, d: float, park: int) -> None:
        body = (f"OSI,8080808080,W,0,{here[0]:.8f},{here[1]:.8f},0.00,{d:.2f},N,38.00,P{park},-14.5000,"
                f"conformance.mis,4.5,0.0,2.00,94.7,False,IVER3-EMU,0.0,False,False")
        q.report(parse(f"${body}*{checksum_hex(body)}".encode()), m, v, v + 0.1, [], "",
                 lambda verdict, clauses, reason: booked.append(reason))

    m.plant(QueueWaypointReached(), 3.0)  # parks 10 s
    q.moved()  # an $OPOS applied: any later waypoint reachable by the next report
    report(12.0, distance_m(*here, *wps[0]), 1)
    m.advance(13.05)  # the mirror ends the park at its nominal end
    assert len(m.queue) == 4
    report(13.05, distance_m(*here, *wps[0]), 1)  # the vehicle's last moment of the park
    report(13.5, distance_m(*here, *wps[1]), 0)   # heading for the next queued, in order
    assert booked == [], booked
