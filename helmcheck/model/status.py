"""What the vehicle model's state reads as, changing nothing: :class:`VehicleStatus`, a mixin of
:class:`~helmcheck.model.vehicle.VehicleModel`.

The ``$OSI`` a conforming vehicle reports now and its judged fields (RH-OUT-1, RH-OUT-4), the data
sentence for one ``$OSD`` letter (RH-OSD-1), the navigation target ``$OSI`` field 7 measures
(RH-RD-5), the park time field 10 shows (RH-PK-2), the surface, GPS-fix and DVL predicates
(RH-RD-10, RH-DVL-1), the main-log rows an owner has not yet seen (RH-LOG-2), and the internal
consistency of the state.
"""

from __future__ import annotations

from typing import Optional

from ..grammar import sentences as s
from .data import CLASS_OF_LETTER, park_seconds
from .geo import distance_m
from .plant import NEUTRAL, PlantSnapshot
from .records import LogRow
from .transitions import REMOTE_MODES

__all__ = ["VehicleStatus"]


class VehicleStatus:
    """The read-only views of :class:`~helmcheck.model.vehicle.VehicleModel`'s state."""

    @property
    def snapshot(self) -> PlantSnapshot:
        return self._snap

    @property
    def gps_fix(self) -> bool:
        """RH-RD-10: a fix needs the surface and a mission not started with ignore-GPS."""
        return self._snap.depth_m <= self.profile.gps_fix_depth_m and not (
            self.mission is not None and self.ignore_gps)

    @property
    def at_surface(self) -> bool:
        return self._snap.depth_m <= self.profile.gps_fix_depth_m

    @property
    def dvl_in_use(self) -> bool:
        """RH-DVL-1, RH-RD-10: ``$ODVL`` velocities are used while active and submerged."""
        return self.dvl is not None and not self.at_surface

    @property
    def remote_active(self) -> bool:
        return self.mode in REMOTE_MODES

    @property
    def opk_counting(self) -> bool:
        """RH-PK-2: the ``$OPK`` park countdown runs (the vehicle is on station)."""
        return self.timers.armed("opk")

    @property
    def lockout_active(self) -> bool:
        """RH-SAF-1: the lockout after a safety violation runs (commands but ``$OSD`` get 26)."""
        return self.phase == "lockout"

    def navigation_target(self) -> Optional[tuple[float, float]]:
        """RH-RD-5: the position ``$OSI`` field 7 measures the distance to, or ``None`` (field 7
        is 0): the ``$OPK`` position in ``mP``, the first queued ``$OMW`` waypoint in ``W``, the
        mission's next waypoint in ``N`` and in ``P`` (not while a frozen park has no time set)."""
        if self.mode == "mP" and self.opk is not None:
            return float(self.opk.lat), float(self.opk.lon)
        if self.mode == "W" and self.queue:
            return float(self.queue[0].lat), float(self.queue[0].lon)
        if self.mode in ("N", "P") and self.mission is not None and not (
                self.mode == "P" and self.park_left is None and not self.timers.armed("park")):
            w = self.mission.waypoints[self.mission_wp]
            return w.lat, w.lon
        return None

    def _distance(self) -> float:
        """``$OSI`` field 7 (RH-RD-5): metres to :meth:`navigation_target`, else 0."""
        target = self.navigation_target()
        if target is None:
            return 0.0
        p = self._snap
        return distance_m(p.lat, p.lon, target[0], target[1])

    def log_rows_since(self, count: int) -> list[LogRow]:
        """The main-log rows written after the first ``count`` (RH-LOG-2), oldest first; rows
        already dropped from the bounded history (:attr:`HISTORY`) are not returned."""
        new = min(self.log_row_count - count, len(self.log_rows))
        if new <= 0:
            return []
        return list(self.log_rows)[-new:]

    def park_remaining(self, now: Optional[float] = None, clip: bool = True) -> Optional[float]:
        """Seconds of park left as ``$OSI`` field 10 would show them (before rounding up); None
        when no park is shown. ``clip=False``: a running count past its end is negative
        (:meth:`~helmcheck.model.timers.Timers.remaining`)."""
        now = self.now if now is None else now
        t = self.timers
        if self.mode == "P":
            if t.armed("park"):
                return t.remaining("park", now, clip)
            return self.park_left
        if self.mode == "mP":
            if t.armed("opk"):
                return t.remaining("opk", now, clip)
            return float(self.opk_seconds)
        if self.mode == "W" and self.queue_parking:
            return t.remaining("qpark", now, clip)
        return None

    @property
    def osi_waypoint(self) -> int:
        """``$OSI`` field 3: the (frozen) mission waypoint, 0 in ``S`` (RH-RD-5); in a mission park the
        waypoint parked on, or the one after it (the readings table's ``park_waypoint``)."""
        if self.mission is None:
            return 0
        if self.readings["park_waypoint"] == "next" and (self.mode == "P" or self.mission_mode == "P"):
            return self.mission_wp + 1  # the index moved on at the arrival, also while the park is frozen
        return self.mission_wp

    def state(self, now: Optional[float] = None) -> tuple[str, int, str, int, bool]:
        """(mode, field 3, error state, field 10 seconds, SRP active): the judged ``$OSI`` fields."""
        return (self.mode, self.osi_waypoint, self.error_state,
                park_seconds(self.park_remaining(now)), self.srp_active)

    def osi(self, now: Optional[float] = None) -> s.OSI:
        """The ``$OSI`` a conforming vehicle reports now (RH-OUT-1, RH-OUT-4)."""
        m = self.mission or self.loaded
        if self.mode == "M":
            act = self.primitive.actuators.upper()  # type: ignore[union-attr]
        elif self.mode == "S":
            act = NEUTRAL
        else:
            act = self._snap.actuators
        return self._data.osi(
            actuators=act, mode=self.mode, next_waypoint=self.osi_waypoint,
            distance=self._distance(), error_state=self.error_state,
            park_time=park_seconds(self.park_remaining(now)),
            mission_name=m.name if m is not None else "", srp_active=self.srp_active)

    def data(self, letter: str, now: Optional[float] = None) -> s.Reply:
        """The data sentence for one ``$OSD`` letter (RH-OSD-1); its class name only when
        :attr:`data_names` is set."""
        if self.data_names:
            return CLASS_OF_LETTER[letter].__name__  # type: ignore[return-value]
        if letter == "S":
            return self.osi(now)
        return self._data.sentence(letter, self.gps_fix)

    def check_invariants(self) -> list[str]:
        """Internal consistency of the model's state; an empty list when all hold."""
        bad = []
        m = self.mode
        if (m == "A") != (self.servo is not None):
            bad.append("A iff servo set-points")
        if (m == "M") != (self.primitive is not None):
            bad.append("M iff primitive")
        if (m == "mP") != (self.opk is not None):
            bad.append("mP iff $OPK")
        if (m == "W") != bool(self.queue):
            bad.append("W iff queue non-empty")
        if m in ("N", "P", "mP", "A", "W") and self.mission is None:
            bad.append(f"{m} without a running mission")
        if m == "S" and self.mission is not None:
            bad.append("S with a running mission")
        if m in ("N", "P") and self.mission_mode != m:
            bad.append(f"mode {m} but mission behaviour {self.mission_mode}")
        if self.phase == "lockout" and (m not in ("S", "N", "P") or not self.timers.armed("lockout")):
            bad.append("lockout outside S/N/P or without its timer")
        if self.phase == "ascent" and m not in ("S", "N", "P", "M"):
            bad.append(f"ascent in {m}")
        if self.phase != "none" and self.error_state == "N":
            bad.append("safety phase without a code")
        if self.timers.armed("park") and not (m == "P" and self.phase == "none"):
            bad.append("mission park counting outside P")
        if self.mission is not None and not 0 <= self.mission_wp <= self.mission.last:
            bad.append("mission waypoint out of range")
        return bad
