"""Missions as data, and the catalogue the model looks them up in (RH-MSN-1, RH-MSN-2, RH-RD-6).

The model never touches a file. Whoever owns the model (the emulator, a log checker, a test)
hands it a :class:`MissionCatalog`: an object with ``lookup(name)`` that answers a
:class:`Mission`, a :class:`MissingMission` (err 1; err 31 for an SRP) or a :class:`BadMission`
(``unparseable`` → err 3, ``unreadable`` → err 3; err 31 for an SRP). :class:`InMemoryCatalog` is
the implementation for tests and for emulators that load their directory up front.

Name rules (RH-MSN-1, RH-RD-6): :func:`mission_name_problem` rejects an empty name, an absolute
path (``/x``, ``\\x``), a drive letter (``C:``), a ``..`` component, an empty path component and
control characters, *before* any look-up, so no name can reach outside the mission directory.
Relative sub-directories (``sub/a.mis`` or ``sub\\a.mis``) are allowed; :func:`normalise_name`
turns both separators into ``/`` and is the key a catalogue is asked for.

Decision (spec open): a mission needs at least one waypoint; :class:`Mission` refuses an empty
list, and a catalogue should report such a file as ``BadMission("unparseable")``.

Missions of unknown length: an observer that knows a mission only by name (a log checked
without the vehicle's mission files) uses :meth:`Mission.open`. Its waypoints are
:class:`OpenWaypoints`: :data:`OPEN_LENGTH` of them, all at (0, 0) without a park, so every
``$OJW`` index is in range (RH-JW-1) and the mission never ends on its own (RH-MSN-4). They can
be indexed and counted but not iterated; :attr:`Mission.is_open` tells such a mission apart.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Mapping, Optional, Protocol, Union, runtime_checkable

__all__ = [
    "Waypoint", "Mission", "MissingMission", "BadMission", "LookupResult", "MissionCatalog",
    "InMemoryCatalog", "mission_name_problem", "normalise_name", "OpenWaypoints", "OPEN_LENGTH",
]

#: How many waypoints a mission of unknown length (:meth:`Mission.open`) reports.
OPEN_LENGTH = 1_000_000


@dataclass(frozen=True, slots=True)
class Waypoint:
    """One mission waypoint: position (signed decimal degrees), depth (m), speed (kn), park (s)."""

    lat: float
    lon: float
    depth: float = 0.0
    speed: float = 2.0
    park_s: float = 0.0


class OpenWaypoints:
    """The waypoints of a mission of unknown length: :data:`OPEN_LENGTH` of them, each at (0, 0)
    with no park. Indexing and ``len`` work; iterating is refused (there is no finite list)."""

    __slots__ = ()
    _WP = Waypoint(0.0, 0.0)

    def __len__(self) -> int:
        return OPEN_LENGTH

    def __getitem__(self, i: int) -> Waypoint:
        return self._WP

    def __iter__(self):
        raise TypeError("an open mission has no finite list of waypoints")


@dataclass(frozen=True, slots=True)
class Mission:
    """A mission file's content: its name and its waypoints, in order (index 0 first).

    :meth:`open` makes a mission of unknown length (see the module docstring).
    """

    name: str
    waypoints: Union[tuple[Waypoint, ...], OpenWaypoints]
    #: The mission's Maximum Operation Time safety rule, in vehicle seconds from its start, or
    #: ``None``. The vehicle raises ``Stl`` when it trips (RH-SAF-5); the model does not time it
    #: (a violation is the vehicle's own event, told to the model as a plant event).
    max_time_s: Optional[float] = None

    def __post_init__(self) -> None:
        if isinstance(self.waypoints, OpenWaypoints):
            return
        if not self.waypoints:
            raise ValueError(f"mission {self.name!r} has no waypoints")
        object.__setattr__(self, "waypoints", tuple(self.waypoints))

    @classmethod
    def open(cls, name: str) -> "Mission":
        """A mission known only by name: :class:`OpenWaypoints` (module docstring)."""
        return cls(name, OpenWaypoints())

    @property
    def is_open(self) -> bool:
        """True for a mission of unknown length (:meth:`open`)."""
        return isinstance(self.waypoints, OpenWaypoints)

    @property
    def last(self) -> int:
        """Index of the last waypoint."""
        return len(self.waypoints) - 1


@dataclass(frozen=True, slots=True)
class MissingMission:
    """No such file in the mission directory (err 1; err 31 for an SRP name)."""

    name: str


@dataclass(frozen=True, slots=True)
class BadMission:
    """The file exists but cannot be used: ``reason`` is ``"unparseable"`` or ``"unreadable"``."""

    name: str
    reason: str = "unparseable"


LookupResult = Union[Mission, MissingMission, BadMission]


@runtime_checkable
class MissionCatalog(Protocol):
    """What the model asks about mission files. ``name`` has passed :func:`mission_name_problem`
    and been through :func:`normalise_name`."""

    def lookup(self, name: str) -> LookupResult: ...


@dataclass
class InMemoryCatalog:
    """A catalogue held in memory: name → :class:`Mission` or :class:`BadMission`."""

    entries: Mapping[str, Union[Mission, BadMission]] = field(default_factory=dict)

    @classmethod
    def of(cls, *missions: Union[Mission, BadMission]) -> "InMemoryCatalog":
        return cls({normalise_name(m.name): m for m in missions})

    def lookup(self, name: str) -> LookupResult:
        found = self.entries.get(normalise_name(name))
        return found if found is not None else MissingMission(name)


_DRIVE = re.compile(r"^[A-Za-z]:")
_CONTROL = re.compile(r"[\x00-\x1f\x7f]")


def mission_name_problem(name: str) -> Optional[str]:
    """Why ``name`` may not be looked up (RH-MSN-1), or ``None`` when it is a safe relative name."""
    if not name or not name.strip():
        return "empty mission name"
    if _CONTROL.search(name):
        return "control character in mission name"
    if name[0] in "/\\":
        return "absolute path"
    if _DRIVE.match(name):
        return "drive letter"
    parts = re.split(r"[\\/]", name)
    if any(p == ".." for p in parts):
        return "'..' component"
    if any(p == "" for p in parts):
        return "empty path component"
    return None


def normalise_name(name: str) -> str:
    """The catalogue key for a safe name: both separators become ``/``."""
    return name.replace("\\", "/")
