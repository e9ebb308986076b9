"""Events the model reports from ``advance()`` and ``plant()``: what changed without a command.

Each is a small frozen dataclass with ``at`` (model time, seconds, the instant it happened) and
a class attribute ``clause`` naming the clause it implements. They are notifications for the
owner (an emulator logs them, a checker correlates them with the wire); the model's state has
already changed when they are returned.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

__all__ = [
    "ModelEvent", "ServoTimeout", "PrimitiveTimeout", "DvlTimeout", "ManualParkExpired",
    "QueueParkExpired", "QueueDone", "MissionParkExpired", "ParkStarted", "WaypointAdvanced",
    "MissionEnded", "ControlReleased", "SafetyRaised", "LockoutEnded", "SurfaceAction",
]


class ModelEvent:
    __slots__ = ()
    clause: ClassVar[str]
    at: float


@dataclass(frozen=True, slots=True)
class ServoTimeout(ModelEvent):
    """No ``$OMS`` within its timeout (RH-SRV-4)."""

    clause: ClassVar[str] = "RH-SRV-4"
    at: float


@dataclass(frozen=True, slots=True)
class PrimitiveTimeout(ModelEvent):
    """No ``$OMP`` within its timeout (RH-PRM-4)."""

    clause: ClassVar[str] = "RH-PRM-4"
    at: float


@dataclass(frozen=True, slots=True)
class DvlTimeout(ModelEvent):
    """The ``$ODVL`` velocities are no longer used (RH-DVL-1)."""

    clause: ClassVar[str] = "RH-DVL-1"
    at: float


@dataclass(frozen=True, slots=True)
class ManualParkExpired(ModelEvent):
    """The ``$OPK`` park time is up (RH-PK-3)."""

    clause: ClassVar[str] = "RH-PK-3"
    at: float


@dataclass(frozen=True, slots=True)
class QueueParkExpired(ModelEvent):
    """The park on a queued ``$OMW`` waypoint is over; the waypoint leaves the queue (RH-OMW-4)."""

    clause: ClassVar[str] = "RH-OMW-4"
    at: float


@dataclass(frozen=True, slots=True)
class QueueDone(ModelEvent):
    """The last queued waypoint was reached (and parked) (RH-OMW-4)."""

    clause: ClassVar[str] = "RH-OMW-4"
    at: float


@dataclass(frozen=True, slots=True)
class MissionParkExpired(ModelEvent):
    """A mission park is over; the mission goes on to its next waypoint (RH-RD-5)."""

    clause: ClassVar[str] = "RH-RD-5"
    at: float


@dataclass(frozen=True, slots=True)
class ParkStarted(ModelEvent):
    """A park countdown started: ``kind`` is ``mission``, ``opk`` or ``queue`` (RH-PK-2, RH-RD-5)."""

    clause: ClassVar[str] = "RH-PK-2"
    at: float
    kind: str
    seconds: float


@dataclass(frozen=True, slots=True)
class WaypointAdvanced(ModelEvent):
    """The mission's next waypoint is now ``index`` (RH-OUT-1 field 3)."""

    clause: ClassVar[str] = "RH-OUT-4"
    at: float
    index: int


@dataclass(frozen=True, slots=True)
class MissionEnded(ModelEvent):
    """The mission's last waypoint was reached: mode ``S`` (RH-MSN-4)."""

    clause: ClassVar[str] = "RH-MSN-4"
    at: float


@dataclass(frozen=True, slots=True)
class ControlReleased(ModelEvent):
    """Remote control ended; the mission behaviour in ``mode`` resumed (RH-INT-2)."""

    clause: ClassVar[str] = "RH-INT-2"
    at: float
    mode: str


@dataclass(frozen=True, slots=True)
class SafetyRaised(ModelEvent):
    """A safety rule triggered: lockout starts with ``code`` (RH-SAF-1, RH-RD-11)."""

    clause: ClassVar[str] = "RH-SAF-1"
    at: float
    code: str


@dataclass(frozen=True, slots=True)
class LockoutEnded(ModelEvent):
    """The lockout is over: ``$OMP`` is released, the ascent goes on (RH-SAF-3, RH-RD-12)."""

    clause: ClassVar[str] = "RH-SAF-3"
    at: float


@dataclass(frozen=True, slots=True)
class SurfaceAction(ModelEvent):
    """At the surface after a violation: ``action`` is ``park``, ``srp`` or ``stop`` (RH-SAF-4)."""

    clause: ClassVar[str] = "RH-SAF-4"
    at: float
    action: str
