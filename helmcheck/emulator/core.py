"""The emulator's sans-IO core: bytes and wall-clock times in, bytes out.

:class:`EmulatorCore` owns one emulated vehicle: the reference model
(:class:`~helmcheck.model.vehicle.VehicleModel`, which alone decides every reply), the plant
(:mod:`.plant`), the line framer, output pacing, the wire log and the main log. It never reads a
clock and never touches a descriptor: the I/O loop (:mod:`.server`) passes ``now`` (wall
seconds, any monotonic origin) into every call and writes what comes back.

* ``feed(data, now) -> bytes`` — bytes from the backseat; returns the bytes the line can carry
  now (the rest waits for :meth:`tick`).
* ``tick(now) -> bytes`` — time passed: runs model timers and plant events due by ``now``.
* ``next_wakeup() -> float | None`` — the wall time at which ``tick`` has something to do.
* ``inject_fault(code, now)`` and ``end_mission(now)`` — what happens on the vehicle off the
  wire: a safety violation (RH-SAF-1, RH-SAF-5), the running mission stopped (RH-MSN-3).
* ``queue_reply(reply, now)`` — a sentence in the vehicle's place (a tester's staged answer),
  sent in order behind the replies already waiting and paced like them.
* ``mission_running``, ``lockout_active`` — what a tester driving the core needs to know.

The model is built by ``model_factory(profile, missions)`` (default
:class:`~helmcheck.model.vehicle.VehicleModel`; a test may pass a deliberately faulty one).
This module keeps input, the hand-over to the model, the off-wire events and the live view; the
clocks and catching up are :mod:`.timeline`'s, the output queue :mod:`.outbox`'s, the log
records :mod:`.logs`' and the settings file :mod:`.settingsfile`'s.

Freedoms (``settings``, :class:`~.freedoms.EmulatorSettings`; defaults: the behaviour described
here): where the profile lets a conforming vehicle choose, the core can choose otherwise — a
reply delay (lines wait in an inbox until their processing time, in arrival order), a serial
loop that turns periodically (``pacing = "burst"``), a control tick (the vehicle clock the model
and plant reach is rounded down to a tick, timer deadlines up to one, plant events land on the
next tick), skewed timers (:class:`~.freedoms.SkewedTimers` in place of the model's), the
plant's physics, and the spelling of its reports (:class:`~.freedoms.ReplyShaper`).

Input handling: the framer cuts lines (RH-FRM-6/7); each line is decoded against the profile.
A valid command goes to the model; a well-framed known command with bad fields goes to the
model as its :class:`~helmcheck.grammar.errors.SentenceError` so it is answered with the
error ACK (RH-ACK-3); framing errors and unknown IDs are discarded silently (RH-FRM-4/5).

Time (RH-TIM-2, :mod:`.timeline`): vehicle time is ``time_scale × (now - start)``; the model and
the plant run on vehicle time, so every protocol duration shrinks by the time scale in wall
time. Output pacing (10 bits per byte at ``baud``, RH-ACK-2's transmit time) is wall time.
``baud = 0`` sends everything at once.

Logs: the wire log (``helmcheck.grammar.wirelog`` format) records every input line or
discarded run (``>``/``>~``), every sentence sent (``<``) and notes (``!``) for plant and model
events, injected faults and link changes; times are wall seconds since ``start``. Accepted
``$OLOGD`` rows (RH-LOG-2) go to the main log, a CSV file (:class:`~.logs.MainLog`). Memory
stays bounded: the model keeps only its last rows and ``$OPOS`` records
(:attr:`VehicleModel.HISTORY`), the core asks it for the rows written since it last looked
(``log_rows_since``), and the output queue (:mod:`.outbox`) is capped
(:data:`~.outbox.MAX_OUTBOX_BYTES`).
"""

from __future__ import annotations

import math
from collections import deque
from pathlib import Path
from typing import Any, Callable, Optional

from ..grammar import Decoded, Discard, Framer, decode, prepare
from ..grammar import format as format_sentence
from ..grammar import sentences as s
from ..grammar.wirelog import NOTE, TO_VEHICLE, WireLogWriter, escape
from ..grammar.errors import SentenceError
from ..model import events as ev
from ..model.geo import distance_m
from ..model.missions import MissionCatalog
from ..model.plant import SafetyViolation
from ..model.vehicle import VehicleModel
from ..profile import SAFETY_CODES, Profile
from ..line.transport import LinePacer
from .freedoms import DEFAULT_SETTINGS, EmulatorSettings, ReplyDelay, ReplyShaper, SkewedTimers, model_readings
from .logs import HistoryEntry, MainLog, event_text
from .outbox import MAX_OUTBOX_BYTES, Outbox
from .outload import OutputLoad
from .plant import Plant, PlantParams
from .rules import OperationTimeRule
from .settingsfile import load_settings, save_settings
from .timeline import Timeline

__all__ = ["EmulatorCore", "HistoryEntry", "MainLog", "MAX_OUTBOX_BYTES", "DEFAULT_UTC0", "plant_params"]

DEFAULT_UTC0 = 1_767_225_600.0  # 2026-01-01T00:00:00Z


def plant_params(st: EmulatorSettings) -> PlantParams:
    """The plant's physics for the emulator settings ``st`` (defaults: :class:`PlantParams`'s)."""
    return PlantParams(home_lat=st.start_lat, home_lon=st.start_lon, declination=st.declination,
                       turn_rate_dps=st.turn_rate_dps, default_max_pitch_deg=st.dive_pitch_deg,
                       buoyancy_rise_mps=st.buoyancy_rise_mps, ascent_mps=st.ascent_mps,
                       water_depth_m=st.water_depth_m, start_battery_pct=st.start_battery_pct,
                       start_heading=st.start_heading, speed_factor=st.speed_factor)


class EmulatorCore(Timeline, Outbox):
    """One emulated vehicle behind a byte stream. See the module docstring."""

    def __init__(self, profile: Profile, missions: Optional[MissionCatalog] = None, *,
                 start: float = 0.0, time_scale: Optional[float] = None, baud: Optional[int] = None,
                 log: Optional[WireLogWriter] = None, main_log: Optional[MainLog] = None,
                 settings_path: Optional[Path] = None, utc0: float = DEFAULT_UTC0,
                 params: Optional[PlantParams] = None, history: int = 400,
                 on_error: Optional[Callable[[str], None]] = None,
                 model_factory: Callable[[Profile, Optional[MissionCatalog]], VehicleModel] = VehicleModel,
                 settings: Optional[EmulatorSettings] = None):
        prepare()  # the first malformed line is answered within the ACK window too (RH-ACK-2)
        self.profile = profile
        st = self.settings = settings if settings is not None else DEFAULT_SETTINGS
        self.time_scale = float(time_scale if time_scale is not None else profile.time_scale)
        if self.time_scale <= 0:
            raise ValueError("time scale must be positive")
        self.start = start
        self.utc0 = utc0
        self.plant = Plant(profile, params or plant_params(st))
        self.model = model_factory(profile, missions)
        self.model.readings = model_readings(st)  # the profile's open questions, as this vehicle reads them
        if st.timer_factor != 1.0 or st.timer_offset_s != 0.0:  # RH-TIM-1: a vehicle's own clock
            self.model.timers = SkewedTimers(st.timer_factor, st.timer_offset_s)
        for name, state, values in st.factory_settings:  # the vehicle's own settings (RH-SET-2)
            self.model.settings.write(name, state, values)
        #: vehicle seconds between control-loop ticks (0: continuous; :mod:`.freedoms`)
        self.tick_v = st.control_tick_s
        self._shaper = ReplyShaper(st)
        self._delay = ReplyDelay(st)
        self._inbox: deque[tuple[float, Any]] = deque()  #: (wall time to process, framer event)
        self._burst = st.burst_interval_s if st.pacing == "burst" else 0.0
        self._last_target: Optional[tuple[float, float]] = None  #: for ``idle_distance = "last"``
        self.rules = OperationTimeRule()  #: a mission's own Maximum Operation Time (RH-SAF-5)
        self.framer = Framer(profile.max_line_bytes)
        self.pacer = LinePacer(0 if st.pacing == "burst" else profile.baud if baud is None else baud)
        self.log = log
        self.main_log = main_log
        self.settings_path = settings_path
        self.history: deque[HistoryEntry] = deque(maxlen=history)
        self.v = 0.0  #: vehicle time the model and plant have reached
        self._out: deque[tuple[bytes, float]] = deque()  #: (sentence, wall time it was queued)
        self._out_bytes = 0
        self.load = OutputLoad(self.pacer.baud)  #: what the requests asked of the line (:mod:`.outload`)
        self._on_error = on_error
        self.stats = {"lines_in": 0, "commands": 0, "answered_errors": 0, "discarded": 0,
                      "sentences_out": 0, "bytes_in": 0, "bytes_out": 0, "dropped_out": 0,
                      "model_errors": 0, "faults": 0}
        self.last_command: Optional[s.Command] = None
        self.last_command_v: float = 0.0
        self._log_written = 0  #: the model's ``log_row_count`` already in the main log
        if settings_path is not None:
            load_settings(self.model.settings, settings_path)
        self._push_snapshot()

    # ================================================================ public API
    def feed(self, data: bytes, now: float) -> bytes:
        """Bytes from the backseat at wall time ``now``; returns bytes to send now."""
        self.stats["bytes_in"] += len(data)
        v = self._catch_up(now)
        for ev in self.framer.feed(data):
            if self._delay.active or self._burst or self.settings.process_when_idle:
                # processed later, in arrival order (RH-ACK-2, RH-ACK-6)
                self._inbox.append((self._due(ev, now), ev))
            elif isinstance(ev, Discard):
                self._discard(ev, now)
            else:
                self._line(ev.raw, now, self._command_v(v, now))
        self._process_inbox(now)
        return self._release(now)

    def tick(self, now: float) -> bytes:
        """Run whatever is due by ``now``; returns bytes to send now."""
        self._catch_up(now)
        self._process_inbox(now)
        return self._release(now)

    def _due(self, ev: Any, now: float) -> float:
        """When a line that arrived at ``now`` is processed: after the reply delay, at the serial
        loop's next turn (burst pacing), never before a line that came earlier (RH-ACK-6).
        ``$OXFLT`` raises its violation at once (RH-SAF-5): it waits only for the lines before it."""
        last = self._inbox[-1][0] if self._inbox else now
        if not isinstance(ev, Discard) and ev.raw.startswith(b"$OXFLT"):
            return max(now, last)
        due = now + (self._delay.draw() if self._delay.active else 0.0)
        if self._burst:
            due = self.start + math.ceil((due - self.start) / self._burst - 1e-9) * self._burst
        return max(due, last)

    def _process_inbox(self, now: float) -> None:
        """Lines whose processing time has come (``reply_delay_s``), oldest first."""
        idle_first = self.settings.process_when_idle
        while self._inbox and self._inbox[0][0] <= now:
            if idle_first and (self._out or (self.pacer.baud and self.pacer.free_at > now + 1e-9)):
                break  # processed once the replies before it have left: its ACK goes out at once
            _, ev = self._inbox.popleft()
            v = self._catch_up(now)
            if isinstance(ev, Discard):
                self._discard(ev, now)
            else:
                self._line(ev.raw, now, self._command_v(v, now))

    def _command_v(self, v: float, now: float) -> float:
        """The vehicle time a command is processed at: the instant itself, also between two
        control ticks (RH-RD-15), never before what the model has reached."""
        return max(v, self.vehicle_time(now)) if self.tick_v else v

    def inject_fault(self, code: str, now: float, source: str = "key") -> bytes:
        """Raise safety violation ``code`` on the vehicle at once (RH-SAF-1, RH-SAF-5)."""
        if code not in SAFETY_CODES:
            raise ValueError(f"unknown safety code {code!r}")
        v = self._catch_up(now)
        self.stats["faults"] += 1
        self._note(now, f"fault injected ({source}): {code}")
        for e in self._model_call(lambda: self.model.plant(SafetyViolation(code), v), now) or ():
            self._note(now, f"model: {event_text(e)}")
        self._after_model(now)
        return self._release(now)

    def end_mission(self, now: float) -> bytes:
        """The running mission stops on the vehicle, off the wire (RH-MSN-3: as an operator's
        stop; the model takes it as an ``$OMSTOP`` nobody on the line asked for, so its reply is
        not sent). Nothing happens when no mission runs; returns bytes to send now."""
        v = self._catch_up(now)
        if self.model.running:
            self._model_call(lambda: self.model.receive(s.OMSTOP(0), v), now)
            self._after_model(now)
        return self._release(now)

    def queue_reply(self, reply: s.Reply, now: float) -> bytes:
        """Send ``reply`` in the vehicle's place, behind the replies already waiting and paced
        like them (RH-ACK-2's transmit time, RH-ACK-6's order); returns bytes to send now."""
        self._catch_up(now)
        self._send_set([format_sentence(reply)], now)
        return self._release(now)

    @property
    def mission_running(self) -> bool:
        """A mission runs on the vehicle (modes other than ``S``, RH-MSN-2)."""
        return self.model.running

    @property
    def lockout_active(self) -> bool:
        """The lockout after a safety violation runs (RH-SAF-1)."""
        return self.model.lockout_active

    def connect(self, now: float, info: str = "") -> None:
        """A peer connected (TCP); the model's state carries on."""
        self._note(now, f"link: client connected {info}".rstrip())

    def disconnect(self, now: float, info: str = "") -> None:
        """The peer went away: pending input is discarded, unsent replies are dropped."""
        for ev in self.framer.close():
            self._discard(ev, now)
        if self._inbox:
            self._note(now, f"link: {len(self._inbox)} unprocessed lines dropped")
            self._inbox.clear()
        if self._out:
            self._note(now, f"link: {len(self._out)} unsent sentences dropped")
            self.stats["dropped_out"] += self._out_bytes
            self.load.dropped(now - self.start, self._out_bytes)
        self._out.clear()
        self._out_bytes = 0
        self.pacer.reset(now)
        self._note(now, f"link: client disconnected {info}".rstrip())

    def note(self, now: float, text: str) -> None:
        """Write a ``!`` note in the wire log (and the live history)."""
        self._note(now, text)

    # ================================================================ input
    def _discard(self, ev: Discard, now: float) -> None:
        self.stats["discarded"] += 1
        if self.log is not None:
            self.log.bytes(now - self.start, TO_VEHICLE, ev.raw)
            if ev.length > len(ev.raw):
                self.log.note(now - self.start, f"{ev.clause}: {ev.length} bytes discarded, "
                                                f"first {len(ev.raw)} logged")
        self.history.append(HistoryEntry(now - self.start, ">", escape(ev.raw[:120]),
                                         f"discard {ev.clause}: {ev.reason}"))

    def _line(self, raw: bytes, now: float, v: float) -> None:
        self.stats["lines_in"] += 1
        if self.log is not None:
            self.log.bytes(now - self.start, TO_VEHICLE, raw)
        d: Decoded = decode(raw, self.profile)
        item: Any = None
        if d.sentence is not None:
            if isinstance(d.sentence, s.Command):
                item = d.sentence
                verdict = f"ok {type(item).__name__}"
            else:
                verdict = f"ignored: {type(d.sentence).__name__} is not a command"
        elif d.error is not None and d.error.answered:
            item = d.error
            verdict = f"error ACK: {d.error}"
        else:
            verdict = f"discard {d.error}" if d.error is not None else "discard"
        text = escape(raw.rstrip(b"\r\n")[:160])
        entry = HistoryEntry(now - self.start, ">", text, verdict)
        self.history.append(entry)
        if item is None:
            self.stats["discarded"] += 1
            return
        if isinstance(item, SentenceError):
            self.stats["answered_errors"] += 1
        else:
            self.stats["commands"] += 1
        ack = self._command(item, now, v)
        if ack is not None and ack.status != 0:
            why = f": {item}" if isinstance(item, SentenceError) else ""
            self._relabel(entry, f"refused (err {ack.err}){why}")

    def _relabel(self, entry: HistoryEntry, verdict: str) -> None:
        """A command the vehicle refused (``$ACK`` status 1) is shown as refused, not ok."""
        h = self.history
        for i in range(len(h) - 1, max(-1, len(h) - 64), -1):
            if h[i] is entry:
                h[i] = HistoryEntry(entry.t, entry.direction, entry.text, verdict)
                return

    def _command(self, item: Any, now: float, v: float) -> Optional[s.ACK]:
        """Hand one command to the model and queue its replies; returns its ``$ACK``, if any."""
        m = self.model
        snap_before = m.snapshot
        if isinstance(item, s.OXFLT):
            if self.profile.fault_injection == "oxflt":
                self.stats["faults"] += 1
                self._note(now, f"fault injected ($OXFLT): {item.code}")
        replies = self._model_call(lambda: m.receive(item, v), now)
        if replies is None:
            return None
        if isinstance(item, s.Command) and type(item) is not s.OSD:
            self.last_command = item
            self.last_command_v = v
        accepted = bool(replies) and isinstance(replies[-1], s.ACK) and replies[-1].status == 0
        if accepted:
            if isinstance(item, s.OPOS) and m.snapshot is not snap_before:
                self.plant.apply_fix(m.snapshot)
            elif isinstance(item, s.OLOGD):
                self._write_main_log()
            elif isinstance(item, s.ORWSET) and item.access == "W" and self.settings_path is not None:
                self._save_settings(self.settings_path)
        if self._shaper.active:
            replies = [self._shaper.shape(r, self._idle_distance(), m.snapshot.utc) for r in replies]
        self._send_set([format_sentence(r) for r in replies], now, getattr(item, "ID", None) or getattr(item, "sentence_id", None) or "")
        self._after_model(now)
        return next((r for r in reversed(replies) if isinstance(r, s.ACK)), None)

    def _model_call(self, fn: Callable[[], Any], now: float) -> Any:
        """Call into the model; a model exception is logged, never fatal to the emulator. The
        mission's own rule sees every change (a mission started or stopped at ``self.v``)."""
        try:
            return fn()
        except Exception as e:  # noqa: BLE001 - keep serving; the note names the failure
            self.stats["model_errors"] += 1
            text = f"model error: {type(e).__name__}: {e}"
            self._note(now, text)
            if self._on_error is not None:
                self._on_error(text)
            return None
        finally:
            self.rules.observe(self.model, self.v)

    def _after_model(self, now: float) -> None:
        """Flush the model's pending events to the log and let the plant see the new goal. A
        mission park resumed after remote control waits to be back on station when the settings
        say so (``resumed_park``, RH-INT-2)."""
        evs = self._model_call(self.model.drain_events, now) or ()
        for e in evs:
            self._model_event(e, now)
        self.plant.sync(self.model)

    def _model_event(self, e, wall: float) -> None:
        """Log a model event; a mission park resumed after remote control waits to be back on
        station at its waypoint when the settings say so (``resumed_park``, RH-INT-2)."""
        self._note(wall, f"model: {event_text(e)}")
        if type(e) is ev.ControlReleased and e.mode == "P" and self.settings.resumed_park == "on station":
            m = self.model
            target = m.navigation_target()
            away = target is None or distance_m(self.plant.lat, self.plant.lon, *target) > self.profile.on_station_m
            if away and m.await_park_station():
                self._note(wall, "model: the resumed park waits to be back on station")

    def _write_main_log(self) -> None:
        """RH-LOG-2: the rows the model wrote since the last call go to the main log."""
        m = self.model
        if self.main_log is not None:
            p = self.plant
            for row in m.log_rows_since(self._log_written):
                self.main_log.write(row.at, self.utc0 + row.at, p.lat, p.lon, p.depth,
                                    row.labels, row.values)
        self._log_written = m.log_row_count

    # ================================================================ output
    def _idle_distance(self) -> Optional[float]:
        """``$OSI`` field 7 where the profile leaves it to the vehicle (RH-RD-5: no navigation
        target, in ``S`` or an ``M`` entered from ``S``): the distance to the last target, for
        ``idle_distance = "last"``; ``None`` elsewhere (the model's value stands)."""
        m = self.model
        if self._last_target is None or m.running or m.mode not in ("S", "M"):
            return None
        from ..model.geo import distance_m
        p = self.plant
        return distance_m(p.lat, p.lon, *self._last_target)

    def _note(self, now: float, text: str) -> None:
        if self.log is not None:
            self.log.note(now - self.start, text)
        self.history.append(HistoryEntry(now - self.start, NOTE, text))

    # ================================================================ settings store
    def _save_settings(self, path: Path) -> None:
        """Keep the ``$ORWSET`` settings across runs (RH-SET-2, :func:`.settingsfile.save_settings`).
        A file that cannot be written stops the emulator with
        :class:`~helmcheck.failures.OutputLost` naming it: a vehicle that acknowledged a write it
        cannot keep must not go on serving as if it had."""
        from ..failures import OutputLost

        try:
            save_settings(self.model.settings, path)
        except OSError as e:
            self._note(self.wall_time(self.v), f"settings not saved: {e}")
            raise OutputLost(f"cannot write settings {path}: {e.strerror or e}") from None

    # ================================================================ live view
    def view(self) -> dict[str, Any]:
        """What a live display shows (mode, set-points, countdowns, position)."""
        m = self.model
        t = m.timers
        v = self.v
        osi = None
        try:
            osi = m.osi(v)
        except Exception:  # noqa: BLE001
            pass
        remote_left = t.remaining("remote", v) if t.armed("remote") else None
        lockout_left = t.remaining("lockout", v) if t.armed("lockout") else None
        p = self.plant
        return {
            "v": v, "time_scale": self.time_scale, "mode": m.mode, "phase": m.phase,
            "error_state": m.error_state, "next_wp": m.osi_waypoint,
            "mission": (m.mission or m.loaded).name if (m.mission or m.loaded) else "",
            "actuators": osi.actuators if osi is not None else "",
            "park_left": m.park_remaining(v), "remote_left": remote_left,
            "lockout_left": lockout_left, "queue": len(m.queue),
            "lat": p.lat, "lon": p.lon, "depth": p.depth, "heading": p.heading,
            "speed": p.speed_kn, "battery": 100.0 * p.energy_wh / p.params.capacity_wh,
            "distance": float(osi.distance) if osi is not None else 0.0,
            "last_command": self.last_command, "stats": dict(self.stats),
        }
