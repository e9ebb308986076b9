"""The reference vehicle: a sans-IO model of what a conforming UVC does (§2–8 of the profile).

Inputs, all with the model-clock time ``now`` in seconds (never read from a clock):

* ``receive(item, now) -> list[Reply]`` — a parsed command or a
  :class:`~helmcheck.grammar.errors.SentenceError`; returns exactly the replies due, in order.
* ``advance(now) -> list[ModelEvent]`` and ``next_deadline()`` — timeouts (``$OMS``, ``$OMP``,
  ``$ODVL``), park expiry (mission, ``$OPK``, queued ``$OMW``), lockout end (aioquic style:
  the owner arms one timer at ``next_deadline()`` and calls ``advance``).
* ``drain_events() -> list[ModelEvent]`` — the events an input produced (``receive`` keeps
  them; ``advance``, ``plant`` and ``update_plant`` return them), without running any timer.
* ``plant(event, now)`` and ``update_plant(snapshot)`` — what the physical vehicle did
  (:mod:`helmcheck.model.plant`).

Every mode and phase change goes through :data:`~helmcheck.model.transitions.TABLE` via
:func:`~helmcheck.model.transitions.select`; the handlers here only do the data part.

This module keeps the inputs, the timer and table dispatch, clones and the checkpoint; the class
takes what its state reads as (``$OSI``, data sentences, field 7, park time, invariants) from
:mod:`~helmcheck.model.status` and the state changes the handlers share from
:mod:`~helmcheck.model.effects`.

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
state); the events they produce wait for the next ``advance`` (or ``drain_events``).

Bounded history: ``log_rows`` (RH-LOG-2) and ``opos_records`` (RH-POS-1/2) keep the last
:attr:`VehicleModel.HISTORY` entries; ``log_row_count`` counts every row ever written, and
``log_rows_since(count)`` gives the rows an owner has not yet seen (its main log).

Observation helpers (for emulators and observers; none changes the state): ``event_of`` and
``row_for`` (the table row a command would meet now), ``navigation_target()`` (what ``$OSI``
field 7 measures, RH-RD-5), ``control_generation`` (changes whenever the remote-control goal
may have changed, so a replacing ``$OPK``/``$OMW`` is a new goal), ``opk_counting``,
``timer(name)`` and the expectation ``checkpoint`` (:mod:`~helmcheck.model.observe`). Two calls
let an observer adopt what it saw: ``drop_checkpoint()``, ``await_on_station()`` (RH-PK-2) and
``await_park_station()`` (RH-INT-2).

Decisions (spec open), besides those in :mod:`~helmcheck.model.transitions`:

* ``$OJW`` numbers are offset by ``profile.waypoint_base``; ``$OSI`` field 3 is always 0-based.
* ``$OPK`` accepted while the snapshot position is within ``on_station_m`` of the target counts
  down at once; otherwise when the plant reports :class:`~helmcheck.model.plant.OnStation`.
  Before that, field 10 shows the full park time. A replacing ``$OPK`` (RH-RD-3) starts over.
* A mission park resumed after remote control (RH-INT-2) counts from the release, wherever the
  vehicle is. The profile leaves room to count only once back on station at the park's waypoint
  (the paper: "once control is released the vehicle will park for the remaining time"):
  ``await_park_station()`` holds the count until :class:`~helmcheck.model.plant.OnStation`.
* "At the surface" means snapshot depth ≤ ``gps_fix_depth_m`` (the RH-RD-10 threshold).
* ``$OXFLT`` is honoured only when ``profile.fault_injection == "oxflt"``; otherwise it is an
  unknown ID. The plant event :class:`~helmcheck.model.plant.SafetyViolation` always works.
* ``$OPOS`` conductivity and temperature replace the snapshot's (they feed ``$OCTD``); position
  and speed replace the snapshot's only without a GPS fix (RH-POS-2, RH-RD-10).
* Mission name in ``$OSI`` field 12: the running mission, else the loaded one, else empty.
"""

from __future__ import annotations

from collections import deque
from typing import NamedTuple, Optional, Union

from ..grammar import sentences as s
from ..grammar.errors import SentenceError
from ..profile import DEFAULT, SAFETY_CODES, Profile
from . import events as ev
from .data import DataCache
from .effects import StateEffects
from .missions import BadMission, InMemoryCatalog, Mission, MissingMission, MissionCatalog, normalise_name
from .plant import (AtSurface, OnStation, PlantEvent, PlantSnapshot, QueueWaypointReached, SafetyViolation,
                    Submerged, WaypointReached)
from .records import LogRow, OposRecord
from .handlers import APPLY as _APPLY, CHECKS as _CHECKS, EXPIRE as _EXPIRE, ack as _ack, reading_field_error, reading_flag_error, reading_repair
from .settings import SettingsStore
from .status import VehicleStatus
from .timers import Timers
from .transitions import ERRORS, EVENT_OF_ACK_TYPE, Row, rows_for, select
from .readings import DEFAULTS as READINGS_DEFAULTS
from .validate import field_error

__all__ = ["VehicleModel", "LogRow", "OposRecord", "Item", "Step"]

Item = Union[s.Command, SentenceError]

_EVENT_OF_CLASS: dict[type, str] = {
    s.OMS: "OMS", s.OMP: "OMP", s.OJW: "OJW", s.OPK: "OPK", s.OMW: "OMW", s.OMSTOP: "OMSTOP",
    s.OMLOAD: "OMLOAD", s.OMSTART: "OMSTART", s.OMSTARTPaper: "OMSTART", s.OPOS: "OPOS",
    s.OSD: "OSD", s.OLOGL: "OLOGL", s.OLOGD: "OLOGD", s.ORWSET: "ORWSET", s.ODVL: "ODVL",
}
_SAFETY = frozenset(SAFETY_CODES)


class Step(NamedTuple):
    """One table row the model applied (``VehicleModel.trace``): the row, the model time, and —
    for a row a timer fired — the timer's name and duration (RH-TIM-1 judges that duration)."""

    row: Row
    at: float
    timer: str = ""
    duration: float = 0.0


class VehicleModel(VehicleStatus, StateEffects):
    """The reference vehicle state machine. See the module docstring."""

    #: How many ``log_rows`` and ``opos_records`` the model keeps (the oldest are dropped).
    HISTORY = 256

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
        #: the loaded mission has run and was stopped (``$OMSTOP``) or ended since it was loaded or
        #: started: whether it is still loaded then is a reading (``stop_unloads``, :mod:`.readings`)
        self.stopped_loaded = False
        self.mission: Optional[Mission] = None
        self.mission_mode = "N"
        self.mission_wp = 0
        self.park_left: Optional[float] = None  #: mission park seconds left when not counting
        #: a resumed mission park waits to be back on station to count (:meth:`await_park_station`)
        self.park_waiting = False
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
        self.log_rows: deque[LogRow] = deque(maxlen=self.HISTORY)
        self.log_row_count = 0  #: rows ever written to the main log (monotonic, RH-LOG-2)
        self.opos_records: deque[OposRecord] = deque(maxlen=self.HISTORY)
        self._history_shared = False  #: ``log_rows``/``opos_records`` shared with a clone (copy on write)
        #: changes whenever the remote-control goal may have changed (see the module docstring)
        self.control_generation = 0
        self.settings = SettingsStore(profile)
        self.last_row: Optional[Row] = None
        self.timers = Timers()
        self._pending: list[ev.ModelEvent] = []
        self._base: Optional["VehicleModel"] = None
        #: keep a copy of the state before the first timer fires after an input (for observers)
        self.checkpoints = True
        #: when a list, every table row applied is appended as a :class:`Step` (for observers)
        self.trace: Optional[list] = None
        #: when a dict, how many times each table row was applied (row id -> count), copied into
        #: clones and never drained: what a model has been through, for coverage counts
        self.applied: Optional[dict] = None
        #: ``$OSD`` answers carry each data sentence's class name (``"OSI"``), not the sentence:
        #: for observers that judge which sentences come and in what order, not their values
        self.data_names = False
        self._firing: Optional[tuple[str, float]] = None
        self._snap = snapshot if snapshot is not None else PlantSnapshot()
        self._data = DataCache(profile, self._snap)
        #: the profile's open questions as this vehicle answers them (:mod:`.readings`; never
        #: changed in place: a clone shares it, a new reading replaces it)
        self.readings: dict[str, str] = READINGS_DEFAULTS

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

    def next_deadline(self) -> Optional[float]:
        """The model time of the next timer expiry, or ``None`` when no timer runs."""
        return self.timers.due

    def timer(self, name: Optional[str] = None) -> Optional[tuple[float, float, str]]:
        """``(deadline, duration, name)`` of the named timer, or of the next one to expire;
        ``None`` when it is not armed (RH-TIM-1 tolerances are taken on the duration)."""
        t = self.timers
        if name is None:
            got = t.next_timer()
            return None if got is None else (got[0], got[1] or 0.0, got[2])
        d = t.deadline(name)
        if d is None:
            return None
        return d, t.duration(name) or 0.0, name

    def advance(self, now: float) -> list[ev.ModelEvent]:
        """Run every timer due at or before ``now``; return the events since the last call."""
        self._run_due(now)
        return self.drain_events()

    def drain_events(self) -> list[ev.ModelEvent]:
        """The events produced since the last call (by ``receive`` or a timer it ran first),
        in order; runs no timer. ``advance``, ``plant`` and ``update_plant`` drain too."""
        out, self._pending = self._pending, []
        return out

    @staticmethod
    def event_of(item: Item) -> Optional[str]:
        """The table event (:data:`~helmcheck.model.transitions.TABLE`) of a parsed command;
        ``None`` for a sentence error, ``$OXFLT`` or a class the table does not know."""
        cls = type(item)
        event = _EVENT_OF_CLASS.get(cls)
        if event is None and cls is s.OMWClear:
            event = "OMW_CLEAR" if item.waypoint is None else "OMW_CLEAR_WP"  # type: ignore[union-attr]
        return event

    def row_for(self, item: Item) -> Optional[Row]:
        """The transition row ``receive(item)`` would meet in the present state (RH-ACK-4,
        RH-SAF-1), before field checks; ``None`` when the table has no event for ``item``.
        Changes nothing: call ``advance`` first to bring the timers up to the command's time."""
        event = self.event_of(item)
        return None if event is None else select(self.mode, self.phase, event, self)

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
            if cls is s.OXFLT:
                if self._oxflt:
                    self._violation(item.code, now)  # type: ignore[union-attr]
                return []
            event = self.event_of(item)
            if event is None:
                return []
        if cls.ID not in self._commands:
            return []
        row = select(self.mode, self.phase, event, self)
        assert row is not None, (self.mode, self.phase, event)
        t = item.ACK_TYPE  # type: ignore[union-attr]
        if row.error == 26 and not (self.phase == "ascent" and self.readings["ascent_refusal_order"] != "first"):
            return [_ack(t, 26)]
        err = field_error(item, self.profile)  # type: ignore[arg-type]
        if err is not None:
            err = reading_field_error(self, item, err)
        elif cls is s.OMLOAD and self.readings["omload_flag"] != "any":
            err = reading_flag_error(self, item)
        if err is None:
            err = row.error
        if err is None:
            check = _CHECKS.get(event)
            if check is not None:
                err = check(self, item)
        if err is not None:
            return [_ack(t, err)]
        self.last_row = row
        if self.trace is not None:
            self.trace.append(Step(row, now))
        if self.applied is not None:
            self.applied[row.id] = self.applied.get(row.id, 0) + 1
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
            elif self.mode == "P" and self.park_waiting and self.phase == "none":
                self.park_waiting = False
                left = self.park_left or 0.0
                self.timers.arm("park", now, left)
                self.park_left = None
                self._pending.append(ev.ParkStarted(now, "mission", left))
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
            if self.phase != "ascent":
                self._base = None  # reaching the surface is an input: what came before is past
        out, self._pending = self._pending, []
        return out

    # ------------------------------------------------------------------ observers' checkpoint

    @property
    def checkpoint(self) -> Optional["VehicleModel"]:
        """The copy taken before the first timer fired since the last input, or ``None``
        (the start of the expectation shadows, :mod:`~helmcheck.model.observe`)."""
        return self._base

    def drop_checkpoint(self) -> None:
        """Forget the checkpoint: the present state is the start of what may be expected
        (an observer that adopted a state the checkpoint predates)."""
        self._base = None

    def await_on_station(self) -> None:
        """RH-PK-2: undo a started ``$OPK`` countdown; it starts at the next
        :class:`~helmcheck.model.plant.OnStation` (an observer that cannot see the position
        adopts the countdown only when the vehicle shows it)."""
        self.timers.disarm("opk")

    def await_park_station(self) -> bool:
        """RH-INT-2, read the other way the profile allows: a mission park resumed after remote
        control "parks for the remaining time" once back on station at its waypoint, not at once.
        Undo the resumed count (the time left as at the release) until the next
        :class:`~helmcheck.model.plant.OnStation` (an emulator that returns to the park waypoint
        first; an observer adopting what the vehicle shows). False when no park was resumed."""
        t = self.timers
        if self.mode != "P" or self.phase != "none" or not t.armed("park"):
            return False
        self.park_left = t.duration("park")
        t.disarm("park")
        self.park_waiting = True
        return True

    def clone(self) -> "VehicleModel":
        """An independent copy (for shadows and what-if questions)."""
        new = type(self).__new__(type(self))
        new.__dict__.update(self.__dict__)
        new.queue = list(self.queue)
        self._history_shared = new._history_shared = True  # both copy before their next append
        new.settings = self.settings.copy()
        new.timers = self.timers.copy()
        new._pending = []
        new._base = None
        new.trace = [] if self.trace is not None else None
        new.applied = dict(self.applied) if self.applied is not None else None
        return new

    def expectation(self, now: float, slack: float = 0.0):
        """What a conforming vehicle may report at ``now`` (see :mod:`helmcheck.model.observe`)."""
        from .observe import expectation
        return expectation(self, now, slack)

    # ========================================================================= internals

    def _receive_error(self, err: SentenceError) -> list[s.Reply]:
        t = err.ack_type
        if t is None:
            return []
        if err.partial is not None and self.readings is not READINGS_DEFAULTS:
            fixed = reading_repair(self, err)  # a field the vehicle's readings take otherwise
            if fixed is not None:
                return self.receive(fixed, self.now if self.now is not None else 0.0)
        event = EVENT_OF_ACK_TYPE.get(t)
        if event is None or event not in self._commands:
            return []
        rows = rows_for(self.mode, self.phase, event)
        if rows and rows[0].error == 26 and not (self.phase == "ascent"
                                                 and self.readings["ascent_refusal_order"] != "first"):
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
            self._firing = (name, timers.duration(name) or 0.0)
            timers.disarm(name)
            try:
                _EXPIRE[name](self, deadline)
            finally:
                self._firing = None
        if self.now is None or now > self.now:
            self.now = now

    def _fire(self, event: str, now: float) -> Optional[Row]:
        """Apply a time or plant event through the table; ``None`` when it does not apply."""
        row = select(self.mode, self.phase, event, self)
        if row is None:
            return None
        self.last_row = row
        if self.trace is not None:
            timer, duration = self._firing if self._firing is not None else ("", 0.0)
            self.trace.append(Step(row, now, timer, duration))
        if self.applied is not None:
            self.applied[row.id] = self.applied.get(row.id, 0) + 1
        _APPLY[event](self, row, None, now)
        return row

    def _violation(self, code: str, now: float) -> None:
        """RH-SAF-1, RH-RD-11: show the code, end remote control for good, lock out."""
        if code not in _SAFETY:
            return
        row = select(self.mode, self.phase, "violation", self)
        assert row is not None
        self._base = None
        self.last_row = row
        if self.trace is not None:
            self.trace.append(Step(row, now))
        if self.applied is not None:
            self.applied[row.id] = self.applied.get(row.id, 0) + 1
        self._end_remote()
        self.error_state = code
        self.timers.arm("lockout", now, self.profile.lockout_s)
        self._transition(row, now)
        self._pending.append(ev.SafetyRaised(now, code))

    def _lookup(self, name: str) -> Union[Mission, MissingMission, BadMission]:
        return self.missions.lookup(normalise_name(name))
