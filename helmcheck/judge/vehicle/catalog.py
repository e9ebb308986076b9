"""What the observer knows of the vehicle's missions: names from the profile, the rest learnt.

A real vehicle's mission files are not on the wire. The observer knows:

* the profile's test mission (``mission``) by name, with ``mission_waypoints`` waypoints;
* the profile's other missions (``end_mission``, ``srp_mission``, ``violation_mission``) by
  name only, of unknown length;
* that names the tester made up to be absent (``helmcheck-missing…``, :data:`ABSENT_PREFIX`) are
  absent (err 1);
* nothing about any other name: the vehicle's answer is adopted and the clauses that depend on
  it are INCONCLUSIVE (:class:`UnknownMission`).

Waypoint positions are never known (the judges never read them: ``$OSI`` field 7 is the
vehicle's own report). Park times are learnt from the mission parks the vehicle shows (``None``
= not seen yet, taken as no park until then). A park first seen some time after it began is
known only within an interval: at least the time the report shows, at most that plus the time
since the park could have begun. A later report seen closer to a park's start (a mission
restarted on station at that waypoint, RH-MSN-2) narrows the interval (:meth:`StubMission.refine_park`);
a sighting outside it is not this park (the report is judged against the interval). The length
of a mission of unknown length is learnt when an ``S`` is explained by nothing but its end
(RH-MSN-4).

With the vehicle's mission files (``check-log --missions DIR``, or an emulator's own catalogue in
tests) the observer is given a real :class:`~helmcheck.model.missions.MissionCatalog` instead,
and nothing is learnt.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

from ...model.missions import Mission, MissingMission, OpenWaypoints, Waypoint, normalise_name
from ...profile import Profile

__all__ = ["KnownMissions", "StubMission", "UnknownMission", "ABSENT_PREFIX"]

#: Mission names with this prefix are made up by the tester to be absent (err 1 expected).
ABSENT_PREFIX = "helmcheck-missing"


@dataclass(frozen=True, slots=True)
class UnknownMission(MissingMission):
    """A mission name the observer knows nothing about: whether it exists is the vehicle's
    answer (adopted; the clauses that depend on it are INCONCLUSIVE)."""


class _LearntOpen(OpenWaypoints):
    """Open-length waypoints with the park times learnt so far."""

    __slots__ = ("parks",)
    _NONE = Waypoint(0.0, 0.0)

    def __init__(self, parks: dict):
        self.parks = dict(parks)

    def __getitem__(self, i: int) -> Waypoint:
        park = self.parks.get(i)
        return Waypoint(0.0, 0.0, park_s=float(park)) if park else self._NONE


@dataclass
class StubMission:
    """One mission known by name: its waypoint count when known, park times when learnt."""

    name: str
    waypoints: Optional[int] = None
    parks: dict = field(default_factory=dict)
    #: waypoint -> (shortest, longest) park the sightings so far allow (vehicle seconds)
    bounds: dict = field(default_factory=dict)
    _cache: Optional[Mission] = None

    def mission(self) -> Mission:
        if self._cache is None:
            if self.waypoints is None:
                self._cache = Mission(self.name, _LearntOpen(self.parks))
            else:
                self._cache = self.finite(self.waypoints)
        return self._cache

    def finite(self, n: int) -> Mission:
        """The mission with ``n`` waypoints (positions unknown: 0, 0) and the parks learnt."""
        return Mission(self.name, tuple(Waypoint(0.0, 0.0, park_s=float(self.parks.get(i) or 0.0))
                                        for i in range(n)))

    @property
    def is_open(self) -> bool:
        return self.waypoints is None

    def learn_end(self, last: int) -> None:
        """RH-MSN-4: the vehicle showed the end after waypoint ``last``."""
        if self.waypoints is None:
            self.waypoints = last + 1
            self._cache = None

    def learn_park(self, index: int, seconds: float, shortest: Optional[float] = None) -> None:
        """RH-RD-5: the mission parks ``seconds`` at waypoint ``index`` (first sighting wins); it
        may be as short as ``shortest`` (a park first seen after it began)."""
        if self.parks.get(index) is None:
            seconds = max(0.0, float(seconds))
            self.parks[index] = seconds
            self.bounds[index] = (seconds if shortest is None else min(seconds, max(0.0, shortest)), seconds)
            self._cache = None

    def park_known(self, index: int) -> bool:
        return self.parks.get(index) is not None

    def park_bounds(self, index: int) -> Optional[tuple[float, float]]:
        """The (shortest, longest) park at ``index`` the sightings allow, or None."""
        if self.parks.get(index) is None:
            return None
        return self.bounds.get(index, (self.parks[index], self.parks[index]))

    def refine_park(self, index: int, shortest: float, longest: float) -> bool:
        """A report showing the park at ``index`` between ``shortest`` and ``longest`` long:
        narrows what is known when the two agree (returns True), else changes nothing."""
        got = self.park_bounds(index)
        if got is None:
            return False
        lo, hi = max(got[0], shortest), min(got[1], longest)
        if lo > hi + 1e-9:
            return False
        if (lo, hi) != got:
            self.bounds[index] = (lo, hi)
            self.parks[index] = hi
            self._cache = None
        return True

    @property
    def park_waypoint(self) -> Optional[int]:
        """The first waypoint seen to have a mission park."""
        for i in sorted(self.parks):
            if self.parks[i]:
                return i
        return None


class KnownMissions:
    """The catalogue the observer's models look missions up in (module docstring)."""

    learns = True

    def __init__(self, profile: Profile):
        self.main = StubMission(normalise_name(profile.mission), max(1, profile.mission_waypoints))
        self.entries: dict[str, StubMission] = {self.main.name: self.main}
        for other in (profile.end_mission, profile.srp_mission, profile.violation_mission):
            if other:
                key = normalise_name(other)
                self.entries.setdefault(key, StubMission(key))

    def entry(self, name: str) -> Optional[StubMission]:
        return self.entries.get(normalise_name(name))

    def learn_present(self, name: str) -> StubMission:
        """The vehicle showed that ``name`` exists (it started or loaded it): know it by name."""
        key = normalise_name(name)
        return self.entries.setdefault(key, StubMission(key))

    def lookup(self, name: str):
        key = normalise_name(name)
        e = self.entries.get(key)
        if e is not None:
            return e.mission()
        if key.rsplit("/", 1)[-1].startswith(ABSENT_PREFIX):
            return MissingMission(name)
        return UnknownMission(name)

    def refresh(self, mission: Optional[Mission]) -> Optional[Mission]:
        """The newest version of ``mission`` (after something was learnt about it)."""
        if mission is None:
            return None
        e = self.entries.get(mission.name)
        if e is None:
            return mission
        if e.is_open and not mission.is_open:
            return mission  # a length assumed by a candidate stays with that candidate
        return e.mission()


class GivenMissions:
    """A real catalogue (the vehicle's mission files): nothing to learn."""

    learns = False

    def __init__(self, catalog):
        self.catalog = catalog

    def entry(self, name: str) -> Optional[StubMission]:
        return None

    def learn_present(self, name: str) -> None:
        return None

    def lookup(self, name: str):
        return self.catalog.lookup(normalise_name(name))

    def refresh(self, mission: Optional[Mission]) -> Optional[Mission]:
        return mission
