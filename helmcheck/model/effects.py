"""The state changes the model's handlers share: :class:`StateEffects`, a mixin of
:class:`~helmcheck.model.vehicle.VehicleModel`.

Setting mode and phase from a table row (the mission park counts only in ``P``, RH-RD-5), ending
remote control (RH-INT-1) and resuming the mission (RH-INT-2), reaching the surface in the ascent
(RH-SAF-4), the mission state ``$OMSTART`` and ``$OMSTOP`` leave (RH-MSN-2/3, RH-RD-13), the plant
snapshot, and the bounded histories a clone shares until one of them writes (RH-LOG-2).
"""

from __future__ import annotations

from collections import deque
from typing import Optional

from . import events as ev
from .data import DataCache
from .missions import Mission
from .plant import PlantSnapshot
from .records import LogRow
from .transitions import STAY, Row

__all__ = ["StateEffects"]


class StateEffects:
    """The shared state changes of :class:`~helmcheck.model.vehicle.VehicleModel`."""

    def _set_snapshot(self, snap: PlantSnapshot) -> None:
        if snap is not self._snap:
            self._snap = snap
            self._data = DataCache(self.profile, snap)

    def _own_history(self) -> None:
        """Take a private copy of the bounded histories before changing them (a clone shares them)."""
        if self._history_shared:
            self.log_rows = deque(self.log_rows, maxlen=self.HISTORY)
            self.opos_records = deque(self.opos_records, maxlen=self.HISTORY)
            self._history_shared = False

    def _write_log_row(self, row: LogRow) -> None:
        """RH-LOG-2: keep ``row`` in the bounded history and count it."""
        self._own_history()
        self.log_rows.append(row)
        self.log_row_count += 1

    def _control_changed(self) -> None:
        """The remote-control goal (set-points, ``$OPK`` position, queue head) may have changed."""
        self.control_generation += 1

    def _transition(self, row: Row, now: float) -> None:
        """Set mode and phase from ``row``; keep the mission park counting only in P (RH-RD-5), and
        not while a resumed park waits to be back on station (:meth:`await_park_station`)."""
        if row.target != STAY:
            self.mode = row.target
        if row.phase_to is not None:
            self.phase = row.phase_to
        counting = self.mode == "P" and self.phase == "none" and self.mission is not None
        if self.mode != "P":
            self.park_waiting = False
        counting = counting and not self.park_waiting
        armed = self.timers.armed("park")
        if counting and not armed and self.park_left is not None:
            self.timers.arm("park", now, self.park_left)
            self.park_left = None
        elif armed and not counting:
            self.park_left = self.timers.remaining("park", now)
            self.timers.disarm("park")

    def _end_remote(self) -> None:
        """RH-INT-1: end whatever remote control is active (there is no stack)."""
        self._control_changed()
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

    def _maybe_surface(self, now: float) -> None:
        if self.phase == "ascent" and self.at_surface:
            self._fire("surfaced", now)

    def _start(self, mission: Mission, row: Row, now: float, *, ignore_gps: bool,
               srp: Optional[Mission], as_srp: bool) -> None:
        self.loaded = mission
        self._reset_mission(mission, ignore_gps=ignore_gps, srp=srp, as_srp=as_srp)
        self._transition(row, now)

    def _reset_mission(self, mission: Optional[Mission], *, ignore_gps: bool = False,
                       srp: Optional[Mission] = None, as_srp: bool = False) -> None:
        """Mission state as ``$OMSTART`` leaves it (``mission`` given) or ``$OMSTOP`` (None):
        remote control and the queue ended, the safety episode over (RH-MSN-2/3, RH-RD-13)."""
        self.stopped_loaded = mission is None and (self.mission is not None or self.stopped_loaded)
        self._end_remote()
        self.mission = mission
        self.mission_mode = "N"
        self.mission_wp = 0
        self.park_left = None
        self.park_waiting = False
        self.ignore_gps = ignore_gps
        self.srp_mission = srp
        self.srp_active = as_srp
        self.error_state = "N"
        self.timers.disarm("lockout")
        self.timers.disarm("park")
