"""The reference vehicle: a sans-IO model of what a conforming UVC does (§2–8 of the profile).

Inputs, all with the model-clock time ``now`` in seconds (never read from a clock):

* ``receive(item, now) -> list[Reply]`` — a parsed command or a
  :class:`~helmcheck.grammar.errors.SentenceError`; returns exactly the replies due, in order.
* ``advance(now) -> list[ModelEvent]`` and ``next_deadline()`` — timeouts (``$OMS``, ``$OMP``,
  ``$ODVL``), park expiry (mission, ``$OPK``, queued ``$OMW``), lockout end (aioquic style:
  the owner arms one timer at ``next_deadline()`` and calls ``advance``).
* ``plant(event, now)`` and ``update_plant(snapshot)`` — what the physical vehicle did
  (:mod:`helmcheck.model.plant`).

Every mode and phase change goes through :data:`~helmcheck.model.transitions.TABLE` via
:func:`~helmcheck.model.transitions.select`; the handlers here only do the data part.

Order of checks for a command (RH-RD-2): unknown ID → no reply (RH-FRM-5; a command the
profile's ``commands`` lacks counts as unknown); lockout rows (err 26, also for a malformed
command); field syntax and ranges (the ``SentenceError``'s error, or
:func:`~helmcheck.model.validate.field_error`); the table's precondition rows (RH-ACK-4); the
handler's data checks (``$OJW`` index, ``$OLOGD`` count, no mission loaded 17); file look-ups
(1, 3, 31); the ``$OPK`` distance (40). A rejected command changes nothing (RH-ACK-3).

Time (RH-TIM-2, RH-RD-15): ``now`` is *vehicle* time. An emulator running k times faster than
real time passes ``k × wall seconds``; the model's durations are never scaled. Time never goes
backwards: a ``now`` earlier than the last one is taken as the last one. Every input first runs
the timers due at or before ``now`` (a command arriving exactly at a deadline meets the expired
state); the events they produce wait for the next ``advance``.

Decisions (spec open), besides those in :mod:`~helmcheck.model.transitions`:

* ``$OJW`` numbers are offset by ``profile.waypoint_base``; ``$OSI`` field 3 is always 0-based.
* ``$OPK`` accepted while the snapshot position is within ``on_station_m`` of the target counts
  down at once; otherwise when the plant reports :class:`~helmcheck.model.plant.OnStation`.
  Before that, field 10 shows the full park time. A replacing ``$OPK`` (RH-RD-3) starts over.
* "At the surface" means snapshot depth ≤ ``gps_fix_depth_m`` (the RH-RD-10 threshold).
* ``$OXFLT`` is honoured only when ``profile.fault_injection == "oxflt"``; otherwise it is an
  unknown ID. The plant event :class:`~helmcheck.model.plant.SafetyViolation` always works.
* ``$OPOS`` conductivity and temperature replace the snapshot's (they feed ``$OCTD``); position
  and speed replace the snapshot's only without a GPS fix (RH-POS-2, RH-RD-10).
* Mission name in ``$OSI`` field 12: the running mission, else the loaded one, else empty.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass
from decimal import Decimal
from typing import Callable, Optional, Union

from ..grammar import sentences as s
from ..grammar.errors import SentenceError
from ..profile import DEFAULT, SAFETY_CODES, Profile
from . import events as ev
from .data import DataCache, park_seconds
from .geo import distance_m
from .missions import BadMission, InMemoryCatalog, Mission, MissingMission, MissionCatalog, normalise_name
from .plant import (NEUTRAL, AtSurface, OnStation, PlantEvent, PlantSnapshot, QueueWaypointReached,
                    SafetyViolation, Submerged, WaypointReached)
from .settings import SettingsStore
from .timers import Timers
from .transitions import ERRORS, EVENT_OF_ACK_TYPE, REMOTE_MODES, STAY, Row, rows_for, select
from .validate import field_error

__all__ = ["VehicleModel", "LogRow", "OposRecord", "Item"]

Item = Union[s.Command, SentenceError]

_EVENT_OF_CLASS: dict[type, str] = {
    s.OMS: "OMS", s.OMP: "OMP", s.OJW: "OJW", s.OPK: "OPK", s.OMW: "OMW", s.OMSTOP: "OMSTOP",
    s.OMLOAD: "OMLOAD", s.OMSTART: "OMSTART", s.OMSTARTPaper: "OMSTART", s.OPOS: "OPOS",
    s.OSD: "OSD", s.OLOGL: "OLOGL", s.OLOGD: "OLOGD", s.ORWSET: "ORWSET", s.ODVL: "ODVL",
}
_SAFETY = frozenset(SAFETY_CODES)
_ACKS: dict[tuple[int, int, int], s.ACK] = {}


def _ack(t: int, err: int = 0) -> s.ACK:
    key = (t, 1 if err else 0, err)
    a = _ACKS.get(key)
    if a is None:
        a = _ACKS[key] = s.ACK(t, key[1], err)
    return a


@dataclass(frozen=True, slots=True)
class LogRow:
    """One accepted ``$OLOGD``: when, the labels in force and the values (RH-LOG-2)."""

    at: float
    labels: tuple[str, ...]
    values: tuple[str, ...]


@dataclass(frozen=True, slots=True)
class OposRecord:
    """One accepted ``$OPOS`` and whether its position and speed were applied (RH-POS-2)."""

    at: float
    command: s.OPOS
    position_applied: bool


class VehicleModel:
    """The reference vehicle state machine. See the module docstring."""

    def __init__(self, profile: Profile = DEFAULT, missions: Optional[MissionCatalog] = None,
                 snapshot: Optional[PlantSnapshot] = None) -> None:
        self.profile = profile
        self.missions: MissionCatalog = missions if missions is not None else InMemoryCatalog()
        self._commands = frozenset(profile.commands)
        self._oxflt = profile.fault_injection == "oxflt"
        self._letters = frozenset(profile.osd_letters)
        self.now: Optional[float] = None
        #: ``$OSI`` field 2 and the safety phase: the state the table works on.
        self.mode = "S"
        self.phase = "none"
        # mission sub-state (frozen while remote control or a safety episode is active)
        self.loaded: Optional[Mission] = None
        self.mission: Optional[Mission] = None
        self.mission_mode = "N"
        self.mission_wp = 0
        self.park_left: Optional[float] = None  #: mission park seconds left when not counting
        self.ignore_gps = False
        self.srp_mission: Optional[Mission] = None
        self.srp_active = False
        # remote-helm control
        self.servo: Optional[s.OMS] = None
        self.primitive: Optional[s.OMP] = None
        self.opk: Optional[s.OPK] = None
        self.opk_seconds = 0
        self.queue: list[s.OMW] = []
        self.queue_parking = False
        self.dvl: Optional[s.ODVL] = None
        # safety, logs, settings
        self.error_state = "N"
        self.log_labels: Optional[tuple[str, ...]] = None
        self.log_rows: list[LogRow] = []
        self.opos_records: list[OposRecord] = []
        self.settings = SettingsStore(profile)
        self.last_row: Optional[Row] = None
        self.timers = Timers()
        self._pending: list[ev.ModelEvent] = []
        self._base: Optional["VehicleModel"] = None
        #: keep a copy of the state before the first timer fires after an input (for observers)
        self.checkpoints = True
        self._snap = snapshot if snapshot is not None else PlantSnapshot()
        self._data = DataCache(profile, self._snap)

    # ================================================================ guard atoms (table)

    @property
    def running(self) -> bool:
        return self.mission is not None

    @property
    def mission_parking(self) -> bool:
        return self.mission_mode == "P"

    @property
    def wp_parks(self) -> bool:
        m = self.mission
        return m is not None and m.waypoints[self.mission_wp].park_s > 0

    @property
    def more_wps(self) -> bool:
        m = self.mission
        return m is not None and self.mission_wp < m.last

    @property
    def head_parks(self) -> bool:
        return bool(self.queue) and self.queue[0].park_s > 0

    @property
    def queue_more(self) -> bool:
        return len(self.queue) > 1

    @property
    def logging(self) -> bool:
        return self.log_labels is not None

    @property
    def srp_ready(self) -> bool:
        return self.settings.safety_action == "srp" and self.srp_mission is not None

    # ======================================================================== public API

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

    def next_deadline(self) -> Optional[float]:
        """The model time of the next timer expiry, or ``None`` when no timer runs."""
        return self.timers.due

    def advance(self, now: float) -> list[ev.ModelEvent]:
        """Run every timer due at or before ``now``; return the events since the last call."""
        self._run_due(now)
        out, self._pending = self._pending, []
        return out

    def receive(self, item: Item, now: float) -> list[s.Reply]:
        """The replies a conforming vehicle sends for ``item``, in order (RH-ACK-1..6)."""
        if self.now is None or now > self.now:
            if self.timers.due is not None and self.timers.due <= now:
                self._run_due(now)
            self.now = now
        else:
            now = self.now
        if type(item) is SentenceError or isinstance(item, SentenceError):
            return self._receive_error(item)  # type: ignore[arg-type]
        cls = type(item)
        event = _EVENT_OF_CLASS.get(cls)
        if event is None:
            if cls is s.OMWClear:
                event = "OMW_CLEAR" if item.waypoint is None else "OMW_CLEAR_WP"  # type: ignore[union-attr]
            elif cls is s.OXFLT:
                if self._oxflt:
                    self._violation(item.code, now)  # type: ignore[union-attr]
                return []
            else:
                return []
        if cls.ID not in self._commands:
            return []
        row = select(self.mode, self.phase, event, self)
        assert row is not None, (self.mode, self.phase, event)
        t = item.ACK_TYPE  # type: ignore[union-attr]
        if row.error == 26:
            return [_ack(t, 26)]
        err = field_error(item, self.profile)  # type: ignore[arg-type]
        if err is None:
            err = row.error
        if err is None:
            check = _CHECKS.get(event)
            if check is not None:
                err = check(self, item)
        if err is not None:
            return [_ack(t, err)]
        self.last_row = row
        replies = _APPLY[event](self, row, item, now)
        if event != "OSD":
            self._base = None
        return replies

    def plant(self, event: PlantEvent, now: float) -> list[ev.ModelEvent]:
        """Tell the model what the physical vehicle did (see :mod:`~helmcheck.model.plant`)."""
        self._run_due(now)
        now = self.now if self.now is not None else now
        self._base = None
        t = type(event)
        if t is WaypointReached:
            if event.index is None or event.index == self.mission_wp:  # type: ignore[attr-defined]
                self._fire("wp_reached", now)
        elif t is OnStation:
            if self.mode == "mP" and not self.timers.armed("opk") and self.phase == "none":
                self.timers.arm("opk", now, self.opk_seconds)
                self._pending.append(ev.ParkStarted(now, "opk", self.opk_seconds))
            elif self.mode == "W" and not self.queue_parking:
                self._fire("queue_wp_reached", now)
        elif t is QueueWaypointReached:
            if self.mode == "W" and not self.queue_parking:
                self._fire("queue_wp_reached", now)
        elif t is AtSurface:
            self._set_snapshot(self._snap.with_(depth_m=0.0))
            self._maybe_surface(now)
        elif t is Submerged:
            self._set_snapshot(self._snap.with_(depth_m=float(event.depth_m)))  # type: ignore[attr-defined]
            self._maybe_surface(now)
        elif t is SafetyViolation:
            self._violation(event.code, now)  # type: ignore[attr-defined]
        out, self._pending = self._pending, []
        return out

    def update_plant(self, snapshot: PlantSnapshot) -> list[ev.ModelEvent]:
        """Replace the measured values; reaching the surface during the ascent acts (RH-SAF-4)."""
        self._set_snapshot(snapshot)
        if self.phase == "ascent" and self.now is not None:
            self._maybe_surface(self.now)
        out, self._pending = self._pending, []
        return out

    # ------------------------------------------------------------------ observable state

    def park_remaining(self, now: Optional[float] = None) -> Optional[float]:
        """Seconds of park left as ``$OSI`` field 10 would show them (before rounding up)."""
        now = self.now if now is None else now
        t = self.timers
        if self.mode == "P":
            if t.armed("park"):
                return t.remaining("park", now)
            return self.park_left
        if self.mode == "mP":
            if t.armed("opk"):
                return t.remaining("opk", now)
            return float(self.opk_seconds)
        if self.mode == "W" and self.queue_parking:
            return t.remaining("qpark", now)
        return None

    @property
    def osi_waypoint(self) -> int:
        """``$OSI`` field 3: the (frozen) mission waypoint, 0 in ``S`` (RH-RD-5)."""
        return self.mission_wp if self.mission is not None else 0

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
        """The data sentence for one ``$OSD`` letter (RH-OSD-1)."""
        if letter == "S":
            return self.osi(now)
        return self._data.sentence(letter, self.gps_fix)

    def clone(self) -> "VehicleModel":
        """An independent copy (for shadows and what-if questions)."""
        new = copy.copy(self)
        new.queue = list(self.queue)
        new.log_rows = list(self.log_rows)
        new.opos_records = list(self.opos_records)
        new.settings = self.settings.copy()
        new.timers = self.timers.copy()
        new._pending = []
        new._base = None
        return new

    def expectation(self, now: float, slack: float = 0.0):
        """What a conforming vehicle may report at ``now`` (see :mod:`helmcheck.model.observe`)."""
        from .observe import expectation
        return expectation(self, now, slack)

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

    # ========================================================================= internals

    def _set_snapshot(self, snap: PlantSnapshot) -> None:
        if snap is not self._snap:
            self._snap = snap
            self._data = DataCache(self.profile, snap)

    def _distance(self) -> float:
        p = self._snap
        target = None
        if self.mode == "mP" and self.opk is not None:
            target = (float(self.opk.lat), float(self.opk.lon))
        elif self.mode == "W" and self.queue:
            target = (float(self.queue[0].lat), float(self.queue[0].lon))
        elif self.mode in ("N", "P") and self.mission is not None and not (
                self.mode == "P" and self.park_left is None and not self.timers.armed("park")):
            w = self.mission.waypoints[self.mission_wp]
            target = (w.lat, w.lon)
        if target is None:
            return 0.0
        return distance_m(p.lat, p.lon, target[0], target[1])

    def _receive_error(self, err: SentenceError) -> list[s.Reply]:
        t = err.ack_type
        if t is None:
            return []
        event = EVENT_OF_ACK_TYPE.get(t)
        if event is None or event not in self._commands:
            return []
        rows = rows_for(self.mode, self.phase, event)
        if rows and rows[0].error == 26:
            return [_ack(t, 26)]
        return [_ack(t, err.ack_err if err.ack_err else ERRORS[event])]

    def _run_due(self, now: float) -> None:
        timers = self.timers
        while timers.due is not None and timers.due <= now:
            if self._base is None and self.checkpoints:
                self._base = self.clone()
            deadline, name = timers.earliest()  # type: ignore[misc]
            if self.now is None or deadline > self.now:
                self.now = deadline
            timers.disarm(name)
            _EXPIRE[name](self, deadline)
        if self.now is None or now > self.now:
            self.now = now

    def _fire(self, event: str, now: float) -> Optional[Row]:
        """Apply a time or plant event through the table; ``None`` when it does not apply."""
        row = select(self.mode, self.phase, event, self)
        if row is None:
            return None
        self.last_row = row
        _APPLY[event](self, row, None, now)
        return row

    def _transition(self, row: Row, now: float) -> None:
        """Set mode and phase from ``row``; keep the mission park counting only in P (RH-RD-5)."""
        if row.target != STAY:
            self.mode = row.target
        if row.phase_to is not None:
            self.phase = row.phase_to
        counting = self.mode == "P" and self.phase == "none" and self.mission is not None
        armed = self.timers.armed("park")
        if counting and not armed and self.park_left is not None:
            self.timers.arm("park", now, self.park_left)
            self.park_left = None
        elif armed and not counting:
            self.park_left = self.timers.remaining("park", now)
            self.timers.disarm("park")

    def _end_remote(self) -> None:
        """RH-INT-1: end whatever remote control is active (there is no stack)."""
        self.servo = None
        self.primitive = None
        self.opk = None
        self.queue = []
        self.queue_parking = False
        t = self.timers
        t.disarm("remote")
        t.disarm("opk")
        t.disarm("qpark")

    def _release(self, row: Row, now: float) -> None:
        """RH-INT-2: remote control ended; resume the frozen mission behaviour."""
        self._end_remote()
        self._transition(row, now)
        self._pending.append(ev.ControlReleased(now, self.mode))

    def _violation(self, code: str, now: float) -> None:
        """RH-SAF-1, RH-RD-11: show the code, end remote control for good, lock out."""
        if code not in _SAFETY:
            return
        row = select(self.mode, self.phase, "violation", self)
        assert row is not None
        self._base = None
        self.last_row = row
        self._end_remote()
        self.error_state = code
        self.timers.arm("lockout", now, self.profile.lockout_s)
        self._transition(row, now)
        self._pending.append(ev.SafetyRaised(now, code))

    def _maybe_surface(self, now: float) -> None:
        if self.phase == "ascent" and self.at_surface:
            self._fire("surfaced", now)

    def _start(self, mission: Mission, row: Row, now: float, *, ignore_gps: bool,
               srp: Optional[Mission], as_srp: bool) -> None:
        self._end_remote()
        self.loaded = mission
        self.mission = mission
        self.mission_mode = "N"
        self.mission_wp = 0
        self.park_left = None
        self.ignore_gps = ignore_gps
        self.srp_mission = srp
        self.srp_active = as_srp
        self.error_state = "N"
        self.timers.disarm("lockout")
        self.timers.disarm("park")
        self._transition(row, now)

    def _lookup(self, name: str) -> Union[Mission, MissingMission, BadMission]:
        return self.missions.lookup(normalise_name(name))


# ============================================================ data checks after the table


def _chk_ojw(m: VehicleModel, c: s.OJW) -> Optional[int]:
    n = c.waypoint - m.profile.waypoint_base
    return None if m.mission is not None and 0 <= n <= m.mission.last else 19


def _chk_ologd(m: VehicleModel, c: s.OLOGD) -> Optional[int]:
    return None if m.log_labels is not None and len(c.values) <= len(m.log_labels) else 25


def _chk_omload(m: VehicleModel, c: s.OMLOAD) -> Optional[int]:
    found = m._lookup(c.name)
    if isinstance(found, MissingMission):
        return 1
    if isinstance(found, BadMission):
        return 3
    return None


def _chk_omstart(m: VehicleModel, c: Union[s.OMSTART, s.OMSTARTPaper]) -> Optional[int]:
    if isinstance(c, s.OMSTARTPaper):
        return None if m.loaded is not None else 17
    found = m._lookup(c.name)
    if isinstance(found, MissingMission):
        return 1
    if isinstance(found, BadMission):
        return 3
    if c.srp:
        if not isinstance(m._lookup(c.srp), Mission):
            return 31
    return None


def _chk_opk(m: VehicleModel, c: s.OPK) -> Optional[int]:
    p = m.snapshot
    d = distance_m(p.lat, p.lon, float(c.lat), float(c.lon))
    return 40 if d > m.profile.opk_max_distance_m else None


_CHECKS: dict[str, Callable[[VehicleModel, object], Optional[int]]] = {
    "OJW": _chk_ojw, "OLOGD": _chk_ologd, "OMLOAD": _chk_omload, "OMSTART": _chk_omstart,
    "OPK": _chk_opk,
}


# ======================================================================= applying events


def _do_oms(m: VehicleModel, row: Row, c: s.OMS, now: float) -> list[s.Reply]:
    """RH-SRV-3, RH-RD-3: mode A; every accepted ``$OMS`` restarts the timeout."""
    m._end_remote()
    m.servo = c
    m.timers.arm("remote", now, c.timeout)
    m._transition(row, now)
    return [_ack(9)]


def _do_omp(m: VehicleModel, row: Row, c: s.OMP, now: float) -> list[s.Reply]:
    """RH-PRM-1, RH-PRM-3, RH-RD-3: mode M, field 1 echoes the bytes upper-cased."""
    m._end_remote()
    m.primitive = c
    m.timers.arm("remote", now, c.timeout)
    m._transition(row, now)
    return [_ack(10)]


def _do_ojw(m: VehicleModel, row: Row, c: s.OJW, now: float) -> list[s.Reply]:
    """RH-JW-2: end remote control and any mission park; mode N toward waypoint n."""
    m._end_remote()
    m.timers.disarm("park")
    m.park_left = None
    m.mission_mode = "N"
    m.mission_wp = c.waypoint - m.profile.waypoint_base
    m._transition(row, now)
    return [_ack(7)]


def _do_opk(m: VehicleModel, row: Row, c: s.OPK, now: float) -> list[s.Reply]:
    """RH-PK-2, RH-RD-3: mode mP; the countdown starts once on station."""
    m._end_remote()
    m.opk = c
    m.opk_seconds = c.minutes * 60
    m._transition(row, now)
    p = m.snapshot
    if distance_m(p.lat, p.lon, float(c.lat), float(c.lon)) <= m.profile.on_station_m:
        m.timers.arm("opk", now, m.opk_seconds)
    return [_ack(11)]


def _do_omw(m: VehicleModel, row: Row, c: s.OMW, now: float) -> list[s.Reply]:
    """RH-OMW-2, RH-RD-3: queue in arrival order; a new ``W`` replaces other remote control."""
    if m.mode != "W":
        m._end_remote()
    m.queue.append(c)
    m._transition(row, now)
    return [_ack(16)]


def _do_omw_clear(m: VehicleModel, row: Row, c: s.OMWClear, now: float) -> list[s.Reply]:
    """RH-OMW-3, RH-RD-4: the keyword alone ends remote control; in N or P it changes nothing."""
    if row.target != STAY:
        m._release(row, now)
    return [_ack(16)]


def _do_omw_clear_wp(m: VehicleModel, row: Row, c: s.OMWClear, now: float) -> list[s.Reply]:
    """RH-RD-4: ``CLEAR,<waypoint>`` clears, then queues that waypoint."""
    m._end_remote()
    m.queue.append(c.waypoint)  # type: ignore[arg-type]
    m._transition(row, now)
    return [_ack(16)]


def _do_omstop(m: VehicleModel, row: Row, c: s.OMSTOP, now: float) -> list[s.Reply]:
    """RH-MSN-3, RH-RD-13: stop; remote control and queue cleared; error state back to N."""
    m._end_remote()
    m.mission = None
    m.mission_mode = "N"
    m.mission_wp = 0
    m.park_left = None
    m.srp_active = False
    m.srp_mission = None
    m.ignore_gps = False
    m.error_state = "N"
    m.timers.disarm("lockout")
    m.timers.disarm("park")
    m._transition(row, now)
    return [_ack(1)]


def _do_omload(m: VehicleModel, row: Row, c: s.OMLOAD, now: float) -> list[s.Reply]:
    """RH-MSN-1: the mission becomes the loaded one."""
    m.loaded = m._lookup(c.name)  # type: ignore[assignment]
    return [_ack(2)]


def _do_omstart(m: VehicleModel, row: Row, c: Union[s.OMSTART, s.OMSTARTPaper],
                now: float) -> list[s.Reply]:
    """RH-MSN-2, RH-RD-6: start (paper form: the loaded mission; rh5 form: by name)."""
    if isinstance(c, s.OMSTARTPaper):
        m._start(m.loaded, row, now, ignore_gps=c.flag == 1, srp=None, as_srp=False)  # type: ignore[arg-type]
    else:
        srp = m._lookup(c.srp) if c.srp else None
        m._start(m._lookup(c.name), row, now, ignore_gps=c.ignore_gps == 1,  # type: ignore[arg-type]
                 srp=srp, as_srp=c.mission_type == 1)  # type: ignore[arg-type]
    return [_ack(3)]


def _do_opos(m: VehicleModel, row: Row, c: s.OPOS, now: float) -> list[s.Reply]:
    """RH-POS-2, RH-RD-10: C and T always applied; position and speed only without a GPS fix."""
    changes: dict[str, float] = {}
    if c.conductivity is not None and c.conductivity != "":
        changes["conductivity"] = float(c.conductivity)
    if c.temperature is not None and c.temperature != "":
        changes["temperature"] = float(c.temperature)
    applied = not m.gps_fix
    if applied:
        changes.update(lat=float(c.lat), lon=float(c.lon), speed_kn=float(c.speed))
    if changes:
        m._set_snapshot(m.snapshot.with_(**changes))
    m.opos_records.append(OposRecord(now, c, applied))
    return [_ack(6)]


def _do_osd(m: VehicleModel, row: Row, c: s.OSD, now: float) -> list[s.Reply]:
    """RH-OSD-1/2, RH-ACK-5, RH-RD-7: data in request order (repeats twice), then ``$ACK,8``."""
    out: list[s.Reply] = []
    letters = m._letters
    for x in c.letters:
        if x and x in letters:
            out.append(m.data(x, now))
    out.append(_ack(8))
    return out


def _do_ologl(m: VehicleModel, row: Row, c: s.OLOGL, now: float) -> list[s.Reply]:
    """RH-LOG-1: store the column labels."""
    m.log_labels = tuple(c.labels)
    return [_ack(5)]


def _do_ologd(m: VehicleModel, row: Row, c: s.OLOGD, now: float) -> list[s.Reply]:
    """RH-LOG-2: write one row to the main log."""
    m.log_rows.append(LogRow(now, m.log_labels or (), tuple(c.values)))
    return [_ack(4)]


def _do_orwset(m: VehicleModel, row: Row, c: s.ORWSET, now: float) -> list[s.Reply]:
    """RH-SET-1/2, RH-RD-8: a write stores state and values; both are answered like a read."""
    if c.access == "W":
        m.settings.write(c.setting, c.state, tuple(c.values))  # type: ignore[arg-type]
    return [s.ACK(12, 0, 0, m.settings.reply_extra(c.setting))]


def _do_odvl(m: VehicleModel, row: Row, c: s.ODVL, now: float) -> list[s.Reply]:
    """RH-DVL-1: use the velocities for dead reckoning for ``timeout`` seconds."""
    m.dvl = c
    m.timers.arm("dvl", now, c.timeout)
    return [_ack(15)]


def _do_release(m: VehicleModel, row: Row, c: None, now: float) -> list[s.Reply]:
    m._release(row, now)
    return []


def _do_queue_wp_reached(m: VehicleModel, row: Row, c: None, now: float) -> list[s.Reply]:
    """RH-OMW-4: park on the reached queued waypoint, or drop it and go on / resume."""
    if row.guard == ("head_parks",):
        m.queue_parking = True
        secs = m.queue[0].park_s
        m.timers.arm("qpark", now, secs)
        m._pending.append(ev.ParkStarted(now, "queue", secs))
        return []
    return _queue_next(m, row, now)


def _do_queue_park_expired(m: VehicleModel, row: Row, c: None, now: float) -> list[s.Reply]:
    m._pending.append(ev.QueueParkExpired(now))
    return _queue_next(m, row, now)


def _queue_next(m: VehicleModel, row: Row, now: float) -> list[s.Reply]:
    m.queue_parking = False
    if row.target == "W":
        m.queue.pop(0)
        m._transition(row, now)
    else:
        m._pending.append(ev.QueueDone(now))
        m._release(row, now)
    return []


def _do_wp_reached(m: VehicleModel, row: Row, c: None, now: float) -> list[s.Reply]:
    """RH-RD-5, RH-MSN-4: park at the waypoint, go on to the next, or end the mission."""
    if row.target == "P":
        m.mission_mode = "P"
        m.park_left = float(m.mission.waypoints[m.mission_wp].park_s)  # type: ignore[union-attr]
        m._transition(row, now)
        m._pending.append(ev.ParkStarted(now, "mission", m.timers.duration("park") or 0.0))
    else:
        _next_waypoint(m, row, now)
    return []


def _do_park_expired(m: VehicleModel, row: Row, c: None, now: float) -> list[s.Reply]:
    m._pending.append(ev.MissionParkExpired(now))
    m.mission_mode = "N"
    m.park_left = None
    _next_waypoint(m, row, now)
    return []


def _next_waypoint(m: VehicleModel, row: Row, now: float) -> None:
    if row.target == "S":
        m.mission = None
        m.mission_mode = "N"
        m.mission_wp = 0
        m.srp_active = False
        m._transition(row, now)
        m._pending.append(ev.MissionEnded(now))
    else:
        m.mission_wp += 1
        m._transition(row, now)
        m._pending.append(ev.WaypointAdvanced(now, m.mission_wp))


def _do_lockout_end(m: VehicleModel, row: Row, c: None, now: float) -> list[s.Reply]:
    """RH-SAF-3, RH-RD-12: ``$OMP`` released; the ascent goes on to the surface."""
    m._transition(row, now)
    m._pending.append(ev.LockoutEnded(now))
    m._maybe_surface(now)
    return []


def _do_surfaced(m: VehicleModel, row: Row, c: None, now: float) -> list[s.Reply]:
    """RH-SAF-4, RH-RD-12: at the surface do what SafetyAction says."""
    if row.target == "N":
        action = "srp"
        m.mission = m.srp_mission
        m.mission_mode = "N"
        m.mission_wp = 0
        m.park_left = None
        m.srp_active = True
    elif row.target == "P":
        action = "park"
        m.timers.disarm("park")
        m.mission_mode = "P"
        m.park_left = None  # no end time
    else:
        action = "stop"
    m._transition(row, now)
    m._pending.append(ev.SurfaceAction(now, action))
    return []


_APPLY: dict[str, Callable[..., list[s.Reply]]] = {
    "OMS": _do_oms, "OMP": _do_omp, "OJW": _do_ojw, "OPK": _do_opk, "OMW": _do_omw,
    "OMW_CLEAR": _do_omw_clear, "OMW_CLEAR_WP": _do_omw_clear_wp, "OMSTOP": _do_omstop,
    "OMLOAD": _do_omload, "OMSTART": _do_omstart, "OPOS": _do_opos, "OSD": _do_osd,
    "OLOGL": _do_ologl, "OLOGD": _do_ologd, "ORWSET": _do_orwset, "ODVL": _do_odvl,
    "servo_timeout": _do_release, "primitive_timeout": _do_release, "opk_expired": _do_release,
    "queue_wp_reached": _do_queue_wp_reached, "queue_park_expired": _do_queue_park_expired,
    "wp_reached": _do_wp_reached, "park_expired": _do_park_expired,
    "lockout_end": _do_lockout_end, "surfaced": _do_surfaced,
}


# ===================================================================== timer expiries


def _exp_remote(m: VehicleModel, at: float) -> None:
    if m.mode == "A":
        m._pending.append(ev.ServoTimeout(at))
        m._fire("servo_timeout", at)
    elif m.mode == "M":
        m._pending.append(ev.PrimitiveTimeout(at))
        m._fire("primitive_timeout", at)
        m._maybe_surface(at)


def _exp_opk(m: VehicleModel, at: float) -> None:
    m._pending.append(ev.ManualParkExpired(at))
    m._fire("opk_expired", at)


def _exp_qpark(m: VehicleModel, at: float) -> None:
    m._fire("queue_park_expired", at)


def _exp_park(m: VehicleModel, at: float) -> None:
    m._fire("park_expired", at)


def _exp_dvl(m: VehicleModel, at: float) -> None:
    m.dvl = None
    m._pending.append(ev.DvlTimeout(at))


def _exp_lockout(m: VehicleModel, at: float) -> None:
    m._fire("lockout_end", at)


_EXPIRE: dict[str, Callable[[VehicleModel, float], None]] = {
    "remote": _exp_remote, "opk": _exp_opk, "qpark": _exp_qpark, "park": _exp_park,
    "dvl": _exp_dvl, "lockout": _exp_lockout,
}

# Decimal is re-exported for callers building commands by hand.
_ = Decimal
