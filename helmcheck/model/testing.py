"""Fixtures for driving the model by hand: a test mission, a catalogue, command builders.

The profile's test mission (§10) has at least 4 waypoints and a mission park on one of its
first waypoints; :func:`conformance_mission` is such a mission (park of 60 s on waypoint 1),
and :func:`catalog` holds it under the profile's default name plus an SRP mission, a mission
that does not parse and one that cannot be read. The builders take plain numbers and make
sentence objects with :class:`~decimal.Decimal` fields, as the parser would.
"""

from __future__ import annotations

from decimal import Decimal
from typing import Optional

from ..grammar import sentences as s
from .missions import BadMission, InMemoryCatalog, Mission, Waypoint

__all__ = [
    "conformance_mission", "srp_mission", "catalog", "D", "oms", "omp", "ojw", "opk", "omw",
    "omw_clear", "omstop", "omload", "omstart", "omstart_paper", "opos", "osd", "ologl", "ologd",
    "orwset", "odvl", "oxflt", "BASE_LAT", "BASE_LON", "oxflt_profile", "started",
]

BASE_LAT = 41.52
BASE_LON = -71.32


def D(x: object) -> Decimal:
    return x if isinstance(x, Decimal) else Decimal(str(x))


def conformance_mission(name: str = "conformance.mis", park_s: float = 60.0) -> Mission:
    """Four waypoints ~200 m apart; waypoint 1 parks ``park_s`` seconds."""
    return Mission(name, (
        Waypoint(BASE_LAT + 0.0018, BASE_LON, 2.0, 2.0, 0.0),
        Waypoint(BASE_LAT + 0.0036, BASE_LON, 2.0, 2.0, park_s),
        Waypoint(BASE_LAT + 0.0036, BASE_LON + 0.0024, 2.0, 2.0, 0.0),
        Waypoint(BASE_LAT, BASE_LON + 0.0024, 0.0, 2.0, 0.0),
    ))


def srp_mission(name: str = "srp.mis") -> Mission:
    return Mission(name, (Waypoint(BASE_LAT, BASE_LON, 0.0, 2.0, 0.0),
                          Waypoint(BASE_LAT - 0.001, BASE_LON, 0.0, 2.0, 0.0)))


def catalog() -> InMemoryCatalog:
    return InMemoryCatalog.of(conformance_mission(), srp_mission(),
                              BadMission("broken.mis", "unparseable"),
                              BadMission("locked.mis", "unreadable"))


def oms(heading=90, depth=2, pitch=20, speed=2, timeout=10) -> s.OMS:
    return s.OMS(D(heading), D(depth), D(pitch), D(speed), timeout)


def omp(actuators: str = "8080808090", timeout: int = 10, reserved: str = "00") -> s.OMP:
    return s.OMP(actuators, reserved, timeout)


def ojw(n: int) -> s.OJW:
    return s.OJW(n)


def opk(lat=BASE_LAT + 0.001, lon=BASE_LON, minutes=1, speed=2) -> s.OPK:
    return s.OPK(D(lat), D(lon), minutes, D(speed))


def omw(lat=BASE_LAT + 0.002, lon=BASE_LON + 0.001, depth1=2, depth2=None, pitch=15, speed=2,
        park_s=0, sensors="") -> s.OMW:
    return s.OMW(D(lat), D(lon), D(depth1), None if depth2 is None else D(depth2), D(pitch),
                 D(speed), park_s, sensors)


def omw_clear(keyword: str = "Clr", waypoint: Optional[s.OMW] = None) -> s.OMWClear:
    return s.OMWClear(keyword, waypoint)


def omstop(flag: int = 0) -> s.OMSTOP:
    return s.OMSTOP(flag)


def omload(name: str = "conformance.mis", flag: int = 0) -> s.OMLOAD:
    return s.OMLOAD(name, flag)


def omstart(name: str = "conformance.mis", srp: Optional[str] = None, ignore_gps: int = 0,
            mission_type: int = 0) -> s.OMSTART:
    return s.OMSTART(ignore_gps, 0, 0, mission_type, name, srp)


def omstart_paper(flag: int = 0) -> s.OMSTARTPaper:
    return s.OMSTARTPaper(flag)


def opos(lat=BASE_LAT, lon=BASE_LON, speed=1.5, cond=None, temp=None) -> s.OPOS:
    return s.OPOS(D(lat), D(lon), D(speed), None if cond is None else D(cond),
                  None if temp is None else D(temp))


def osd(*letters: str) -> s.OSD:
    return s.OSD(tuple(letters))


def ologl(*labels: str) -> s.OLOGL:
    return s.OLOGL(tuple(labels))


def ologd(*values: str) -> s.OLOGD:
    return s.OLOGD(tuple(values))


def orwset(setting: str, access: str = "R", state: Optional[int] = None, *values: str) -> s.ORWSET:
    return s.ORWSET(setting, access, state, tuple(values))


def odvl(x=0.5, y=0.0, timeout=5) -> s.ODVL:
    return s.ODVL(D(x), D(y), timeout)


def oxflt(code: str = "Sle") -> s.OXFLT:
    return s.OXFLT(code)


def oxflt_profile(**changes):
    """The default profile with the ``$OXFLT`` test extension declared (RH-SAF-5)."""
    from ..profile import DEFAULT
    return DEFAULT.replace(fault_injection="oxflt", **changes)


def started(profile=None, now: float = 0.0, **start):
    """A model (``$OXFLT`` enabled) whose test mission was started at ``now``."""
    from .vehicle import VehicleModel
    m = VehicleModel(profile or oxflt_profile(), catalog())
    replies = m.receive(omstart(**start), now)
    assert replies == [s.ACK(3, 0, 0)], replies
    return m
