"""The plant interface: what the physical vehicle did, told to the model by its owner.

The model does not simulate motion. Its owner (the emulator, which does simulate it; a log
checker, which reads it from the log; a test) reports physical facts in two ways:

* :class:`PlantSnapshot` via ``VehicleModel.update_plant(snapshot)``: the measured values the
  data sentences report (position, speed, depth, heading, battery, …). Every default is
  physically valid (RH-OUT-3). The depth here is the one depth the model knows: it decides the
  GPS-fix rule (RH-POS-2, RH-RD-10) and "at the surface" for the safety episode (RH-SAF-4).
* plant events via ``VehicleModel.plant(event, now)``, each a small frozen dataclass below:

  ==========================  ===============================================================
  :class:`WaypointReached`    the running mission's next waypoint was reached (mode ``N``);
                              starts its mission park or advances / ends the mission (RH-MSN-4)
  :class:`OnStation`          within ``on_station_m`` of the ``$OPK`` position (starts the
                              countdown, RH-PK-2) or of the queued ``$OMW`` waypoint (same as
                              :class:`QueueWaypointReached`)
  :class:`QueueWaypointReached`  the first queued ``$OMW`` waypoint was reached (RH-OMW-4)
  :class:`AtSurface`          depth is now 0 (sets the snapshot depth; RH-SAF-4)
  :class:`Submerged`          depth is now ``depth_m`` (sets the snapshot depth; RH-RD-10)
  :class:`SafetyViolation`    a safety rule triggered on the vehicle (RH-SAF-1, RH-SAF-5)
  ==========================  ===============================================================

An event that does not fit the present state (a waypoint reached while the mission is frozen
under remote control, a queue waypoint outside ``W``, …) is ignored: the plant cannot move a
frozen mission (RH-RD-5).
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace
from typing import Optional

__all__ = [
    "PlantSnapshot", "PlantEvent", "WaypointReached", "OnStation", "QueueWaypointReached",
    "AtSurface", "Submerged", "SafetyViolation", "NEUTRAL",
]

#: Fins and motor at rest: every byte 0x80 (RH-OUT-1, RH-PRM-4).
NEUTRAL = "8080808080"


@dataclass(frozen=True, slots=True)
class PlantSnapshot:
    """Measured vehicle values. Units: degrees, knots, metres, °C, percent, m/s, mS/cm."""

    lat: float = 41.52
    lon: float = -71.32
    speed_kn: float = 0.0
    depth_m: float = 0.0
    heading: float = 90.0  #: magnetic heading, [0, 360) (RH-RD-14)
    declination: float = -14.5
    pitch: float = 0.0
    roll: float = 0.0
    compass_temp: float = 20.0
    altitude_m: float = 12.0  #: altimeter, height above bottom
    battery_pct: float = 90.0
    remaining_wh: float = 600.0
    watts: float = 45.0
    volts: float = 28.5
    amps: float = -1.6
    minutes: float = 800.0
    battery_state: str = "D"
    leak: int = 0
    vx: float = 0.0
    vy: float = 0.0
    vz: float = 0.0
    x_dist: float = 0.0
    y_dist: float = 0.0
    conductivity: float = 42.0
    temperature: float = 15.0
    ysi: tuple[tuple[str, float], ...] = (("Temp", 15.0), ("SpCond", 42.0), ("pH", 8.1))
    utc: float = 1_767_225_600.0  #: seconds since the Unix epoch, for ``$GPRMC``
    actuators: str = NEUTRAL  #: fins and motor the autopilot commands in N, P, mP, A, W
    remaining_mission_h: float = 0.0

    def with_(self, **changes) -> "PlantSnapshot":
        """A copy with ``changes`` (``dataclasses.replace``, without its per-call field walk and
        the frozen ``__init__``: an observer replaces the snapshot at nearly every report)."""
        setters = _SNAP_SETTERS
        if not changes.keys() <= setters.keys():
            return replace(self, **changes)  # an unknown field: replace's own TypeError
        new = _copy(self)
        for name, value in changes.items():
            setters[name](new, value)
        return new


_SNAP_NAMES = tuple(f.name for f in fields(PlantSnapshot))
#: each field's slot setter (the frozen class's own ``__setattr__`` refuses)
_SNAP_PUTS = tuple(getattr(PlantSnapshot, name).__set__ for name in _SNAP_NAMES)
_SNAP_SETTERS = dict(zip(_SNAP_NAMES, _SNAP_PUTS))


def _copier():
    """``copy(snapshot)``: a new snapshot with the same fields, generated from the field list
    (one slot store per field written out, not a loop over the fields: the judge copies the
    snapshot at nearly every report)."""
    env = {"_new": object.__new__, "cls": PlantSnapshot}
    lines = ["def copy(src):", "    o = _new(cls)"]
    for i, (name, put) in enumerate(zip(_SNAP_NAMES, _SNAP_PUTS)):
        env[f"put{i}"] = put
        lines.append(f"    put{i}(o, src.{name})")
    lines.append("    return o")
    exec(compile("\n".join(lines) + "\n", "<PlantSnapshot copy>", "exec"), env)
    return env["copy"]


_copy = _copier()


class PlantEvent:
    """Base of the plant events."""

    __slots__ = ()


@dataclass(frozen=True, slots=True)
class WaypointReached(PlantEvent):
    """The mission's next waypoint was reached. ``index`` (0-based), when given, must match."""

    index: Optional[int] = None


@dataclass(frozen=True, slots=True)
class OnStation(PlantEvent):
    """Within ``on_station_m`` of the present park position (``$OPK``) or queued waypoint."""


@dataclass(frozen=True, slots=True)
class QueueWaypointReached(PlantEvent):
    """The first waypoint of the ``$OMW`` queue was reached."""


@dataclass(frozen=True, slots=True)
class AtSurface(PlantEvent):
    """The vehicle is at the surface (depth 0)."""


@dataclass(frozen=True, slots=True)
class Submerged(PlantEvent):
    """The vehicle is at ``depth_m`` metres."""

    depth_m: float = 5.0


@dataclass(frozen=True, slots=True)
class SafetyViolation(PlantEvent):
    """A safety rule triggered; ``code`` is one of the §7 codes (``Sop`` … ``Sti``)."""

    code: str
