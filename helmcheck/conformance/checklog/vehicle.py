"""The vehicle side of a log check: replay the backseat's commands through the reference model
and judge every vehicle sentence against what the model says a conforming vehicle sends.

This module owns :class:`VehicleJudge`. Each backseat command (or answered malformed command)
goes into :class:`~helmcheck.model.vehicle.VehicleModel` at its recorded time (vehicle time =
wall seconds × time scale, RH-TIM-2); the model's replies become a pending expectation that the
vehicle's next sentences must meet:

* RH-ACK-1 — every command that the model answers gets exactly one ``$ACK`` of its own type; an
  ``$ACK`` that answers nothing, or a command whose ``$ACK`` never comes, is a violation.
* RH-ACK-3 / RH-ACK-4 / RH-SAF-1 / RH-SAF-3 and the command clauses (RH-SRV-1, RH-JW-1, …) —
  status and err of the ``$ACK`` are the model's; the clause charged is the one the model's
  transition row names (a lockout row, a precondition row, a field error).
* RH-ACK-2 — the ``$ACK`` comes within ``ack_window_s`` plus the serial transmit time of the
  replies at the line's baud (wall time, never scaled); with timestamps coarser than a tenth of
  the window the verdict is INCONCLUSIVE (RH-TIM-1) unless the delay is certainly too long.
* RH-ACK-5 / RH-OSD-1 / RH-OSD-2 — ``$OSD`` data come before its ``$ACK,8``, one per letter the
  vehicle serves, in request order; a rejected request carries none.
* RH-ACK-6 — ``$ACK``s come back in command order.
* RH-OUT-4 (and RH-SRV-4, RH-PRM-4, RH-PK-3, RH-SAF-1, RH-INT-2 when a timer or release is the
  cause) — the mode, next waypoint, error state, park time and SRP flag of each ``$OSI`` are what
  the model allows between the request's arrival and the ``$OSI``'s, within the RH-TIM-1
  tolerance (:mod:`helmcheck.model.observe`). With coarse timestamps a mismatch that only the
  timing could explain is INCONCLUSIVE.
* RH-FRM-4 / RH-FRM-5 — a line the vehicle must discard silently gets no ``$ACK``.

Plant events (what the vehicle physically did) are not on the wire. A log written by
``helmcheck emulate`` carries them as recorder notes (``! plant: WaypointReached(index=0) at
v=…``); they are applied as they come. Otherwise they are *inferred* from the vehicle's own
``$OSI`` reports: position and depth update the model's plant snapshot (GPS fix and surface
rules, ``$OPK`` distance), and a mismatch that one or more plant events would explain (a
waypoint reached, on station, a queued waypoint reached) applies them. An inferred event cannot
be wrong by construction, so the clauses it touches are not failed on its account; the report
says inference was used.

Without the vehicle's mission files (``--missions``) every mission name is taken to exist with an
unknown number of waypoints; answers that depend on the mission (``$OMSTART``/``$OMLOAD`` look-ups,
the ``$OJW`` range, a mission park or end) are INCONCLUSIVE, and the vehicle's answer is adopted.
"""

from __future__ import annotations

import ast
import re
from collections import deque
from dataclasses import dataclass, field
from typing import Any, Callable, Optional

from ...grammar import sentences as s
from ...grammar.errors import SentenceError
from ...model import events as mev
from ...model.missions import Mission, MissionCatalog
from ...model.observe import quick_expectation
from ...model.plant import (AtSurface, OnStation, PlantEvent, QueueWaypointReached, SafetyViolation,
                            Submerged, WaypointReached)
from ...model.vehicle import VehicleModel
from ...profile import SAFETY_CODES, Profile
from .accounting import ClauseBook, Evidence

__all__ = ["VehicleJudge", "OpenCatalog", "VEHICLE_CLAUSES", "parse_plant_note"]

#: The vehicle clauses a log can speak to (§1–8); the rest are reported NOT-TESTED with a reason.
VEHICLE_CLAUSES = (
    "RH-FRM-1", "RH-FRM-2", "RH-FRM-3", "RH-FRM-4", "RH-FRM-5", "RH-FRM-6", "RH-FRM-7", "RH-FRM-8",
    "RH-FRM-9", "RH-ACK-1", "RH-ACK-2", "RH-ACK-3", "RH-ACK-4", "RH-ACK-5", "RH-ACK-6",
    "RH-OUT-1", "RH-OUT-2", "RH-OUT-3", "RH-OUT-4",
    "RH-INT-1", "RH-INT-2", "RH-INT-3", "RH-SRV-1", "RH-SRV-2", "RH-SRV-3", "RH-SRV-4",
    "RH-PRM-1", "RH-PRM-2", "RH-PRM-3", "RH-PRM-4", "RH-JW-1", "RH-JW-2", "RH-PK-1", "RH-PK-2",
    "RH-PK-3", "RH-OMW-1", "RH-OMW-2", "RH-OMW-3", "RH-OMW-4", "RH-OMW-5",
    "RH-MSN-1", "RH-MSN-2", "RH-MSN-3", "RH-MSN-4", "RH-POS-1", "RH-POS-2", "RH-OSD-1", "RH-OSD-2",
    "RH-LOG-1", "RH-LOG-2", "RH-SET-1", "RH-SET-2", "RH-DVL-1",
    "RH-SAF-1", "RH-SAF-2", "RH-SAF-3", "RH-SAF-4", "RH-SAF-5", "RH-TIM-1", "RH-TIM-2",
)

#: Why some clauses cannot be judged from a wire log at all.
UNJUDGEABLE = {
    "RH-FRM-9": "Serial settings (data bits, parity, stop bits, baud) are not visible in a byte log.",
    "RH-POS-2": "Whether $OPOS position was applied needs the vehicle's internal position; a log "
                "cannot tell it from dead reckoning.",
    "RH-LOG-2": "The vehicle's main log is not part of the wire log; only the $ACK is judged "
                "(under RH-ACK-1/RH-ACK-4).",
    "RH-SAF-5": "A declaration of the implementation (fault injection), not behaviour on the wire.",
    "RH-TIM-2": "The time scale is a setting of the run (taken from the log header or --time-scale).",
}

_MISSION_ERRS = frozenset({1, 3, 17, 19, 31, 40})
_MISSION_CMDS = (s.OMSTART, s.OMSTARTPaper, s.OMLOAD, s.OJW)
_CONTROL_OF_EVENT = {mev.ServoTimeout: "RH-SRV-4", mev.PrimitiveTimeout: "RH-PRM-4",
                     mev.ManualParkExpired: "RH-PK-3", mev.QueueDone: "RH-OMW-4",
                     mev.QueueParkExpired: "RH-OMW-4", mev.LockoutEnded: "RH-SAF-3",
                     mev.MissionParkExpired: "RH-OUT-4", mev.MissionEnded: "RH-MSN-4"}
_LETTER_CLASS = {"G": s.GPRMC, "C": s.Compass, "S": s.OSI, "P": s.OPI, "D": s.DVL, "Y": s.OYSI,
                 "T": s.OCTD, "I": s.OINS}
_ID_CLASS = {cls.ID: cls for cls in (s.GPRMC, s.Compass, s.OSI, s.OPI, s.DVL, s.OYSI, s.OCTD, s.OINS)}


class OpenCatalog:
    """The catalogue used without ``--missions``: every safe name is a mission of unknown length
    (:meth:`~helmcheck.model.missions.Mission.open`).

    Answers that depend on it are judged INCONCLUSIVE by :class:`VehicleJudge`.
    """

    def lookup(self, name: str):
        return Mission.open(name)


_NOTE_RE = re.compile(r"^plant: (\w+)\((.*?)\)(?: \[[^\]]*\])? at v=([-0-9.eE]+)\s*$")
_FAULT_RE = re.compile(r"^fault injected \((?!\$OXFLT)[^)]*\): (\w+)\s*$")
_PLANT = {"WaypointReached": WaypointReached, "OnStation": OnStation,
          "QueueWaypointReached": QueueWaypointReached, "AtSurface": AtSurface, "Submerged": Submerged,
          "SafetyViolation": SafetyViolation}


def parse_plant_note(note: str) -> Optional[tuple[PlantEvent, Optional[float]]]:
    """A plant event from a recorder note (``plant: Submerged(depth_m=2.0) at v=3.1``, or
    ``fault injected (key): Sle``), with the vehicle time it names; None for other notes."""
    m = _NOTE_RE.match(note)
    if m:
        cls = _PLANT.get(m.group(1))
        if cls is None:
            return None
        kwargs: dict[str, Any] = {}
        for part in filter(None, (p.strip() for p in m.group(2).split(","))):
            k, _, v = part.partition("=")
            try:
                kwargs[k.strip()] = ast.literal_eval(v.strip())
            except (ValueError, SyntaxError):
                return None
        try:
            return cls(**kwargs), float(m.group(3))
        except (TypeError, ValueError):
            return None
    m = _FAULT_RE.match(note)
    if m and m.group(1) in SAFETY_CODES:
        return SafetyViolation(m.group(1)), None
    return None


@dataclass
class _Pending:
    """A command the vehicle owes an answer to."""

    t: float
    lineno: int
    text: str
    ack: s.ACK
    data: tuple  #: expected data sentence classes, in order
    clauses: tuple
    mission_dependent: bool
    pre: Optional[VehicleModel]
    cmd: Any
    got: list = field(default_factory=list)
    snapshot: Optional[VehicleModel] = None  #: the model as this command left it (pipelining)
    fed_after: bool = False
    tx_bytes: int = 0


def _ack_text(a: s.ACK) -> str:
    return f"$ACK,{a.type},{a.status},{a.err}"


class VehicleJudge:
    """Judges the vehicle's side of a log. See the module docstring."""

    def __init__(self, book: ClauseBook, profile: Profile, catalog: Optional[MissionCatalog], *,
                 time_scale: float, resolution: float, baud: int,
                 on_mode: Optional[Callable[[float, str], None]] = None,
                 on_event: Optional[Callable[[float, str, str], None]] = None):
        self.book = book
        self.profile = profile
        self.mission_known = catalog is not None
        self.model = VehicleModel(profile, catalog if catalog is not None else OpenCatalog())
        self.scale = time_scale
        self.r = resolution
        self.baud = baud
        #: timestamps fine enough to judge timing (RH-TIM-1): a step under a fifth of the
        #: smallest tolerance (0.5 s of vehicle time)
        self.precise = resolution * time_scale <= 0.1
        self.ack_precise = resolution <= profile.ack_window_s / 10
        self.pending: deque[_Pending] = deque()
        self.on_mode = on_mode
        self.on_event = on_event
        self.on_answer: Optional[Callable[[Any, s.ACK], None]] = None
        self.pre_command: list = []  # evidence of vehicle sentences before the first command
        self.pre_command_count = 0
        self.recorder_plant = False
        self.inferred = 0
        self.inferred_safety = 0
        self.lockout_inferred = False
        self.saw_commands = False
        self.saw_vehicle = False
        self.first_command_t: Optional[float] = None
        self.recent_release: Optional[tuple[str, str, float]] = None  # clause, mode before, v
        self.last_accept: Optional[tuple[tuple, str, float]] = None  # clauses, mode before, v
        self.mission_desync = False
        self.unmatched: list = []  # deferred: (reason, evidence) until we know commands exist
        self.unmatched_count = 0
        self.missing_bucket: list = []
        self.missing_count = 0
        self.recent_missing: deque = deque(maxlen=16)
        self.silent_recent: deque = deque(maxlen=4)  # lines the vehicle must not answer
        self._mode = self.model.mode
        self.last_t = 0.0

    # ---------------------------------------------------------------- time
    def v(self, t: float) -> float:
        return t * self.scale

    def advance(self, t: float) -> None:
        """Run the model's timers up to ``t``; remember what a timer released (for blame)."""
        self.last_t = max(self.last_t, t)
        m = self.model
        due = m.next_deadline()
        if due is None or due > self.v(t):
            return
        before = m.mode
        evs = m.advance(self.v(t))
        cause = None
        for e in evs:
            c = _CONTROL_OF_EVENT.get(type(e))
            if c is not None:
                cause = c
            if isinstance(e, mev.LockoutEnded) and self.on_event:
                self.on_event(e.at / self.scale, "lockout", "lockout ended")
        if cause is not None:
            self.recent_release = (cause, before, self.v(t))
        self._mode_changed(t)

    def _mode_changed(self, t: float) -> None:
        if self.model.mode != self._mode:
            self._mode = self.model.mode
            if self.on_mode:
                self.on_mode(t, self._mode)

    # ---------------------------------------------------------------- plant
    def plant_note(self, event: PlantEvent, v: Optional[float], t: float) -> None:
        """A plant event the recorder reported (exact; switches inference off)."""
        self.recorder_plant = True
        self.advance(t)
        vv = self.v(t) if v is None else max(v, self.model.now or 0.0)
        before = self.model.mode
        evs = self.model.plant(event, vv)
        for e in evs:
            if isinstance(e, mev.SafetyRaised) and self.on_event:
                self.on_event(t, "lockout", f"safety violation {e.code}")
        if self.model.mode != before:
            self.recent_release = None
        self._mode_changed(t)

    # ---------------------------------------------------------------- commands
    def command(self, item: Any, t: float, lineno: int, text: str) -> None:
        """A backseat line that decoded to a command or an answered error (RH-ACK-3)."""
        self.saw_commands = True
        if self.first_command_t is None:
            self.first_command_t = t
        self.advance(t)
        m = self.model
        if self.pending:
            last = self.pending[-1]
            if last.snapshot is None and s.OSI in last.data and len(last.got) < len(last.data):
                last.snapshot = m.clone()
                last.snapshot.checkpoints = True
            for p in self.pending:
                p.fed_after = True
        clauses: tuple = ()
        is_err = isinstance(item, SentenceError)
        if not is_err:
            row = m.row_for(item)
            if row is not None:
                clauses = tuple(c for c in row.clauses if not c.startswith("RH-RD"))
                if row.error is None:
                    clauses = (clauses[0],) if clauses else ()
        else:
            rows_phase = m.phase
            clauses = ("RH-SAF-1",) if rows_phase == "lockout" else ("RH-ACK-3",)
        mission_dep = (not self.mission_known) and isinstance(item, _MISSION_CMDS)
        mission_dep = mission_dep or isinstance(item, s.OPK)  # distance from an inferred position
        pre = m.clone() if mission_dep else None
        mode_before = m.mode
        replies = m.receive(item, self.v(t))
        if isinstance(item, s.OXFLT):
            self.lockout_inferred = False
        if isinstance(item, s.OXFLT) and m.phase == "lockout" and self.on_event:
            self.on_event(t, "lockout", f"$OXFLT,{item.code}")
        if not replies:
            if is_err or item.ACK_TYPE is not None:
                self.silent_recent.append((t, lineno, text, getattr(item, "ack_type", None)))
            self._mode_changed(t)
            return
        ack = replies[-1]
        if ack.status == 0 and ack.err == 0 and not is_err and type(item) is not s.OSD:
            self.last_accept = (clauses, mode_before, self.v(t))
            if m.mode != mode_before:
                self.recent_release = None
        if ack.status == 1:
            if is_err:
                clauses = ("RH-SAF-1",) if ack.err == 26 else ("RH-ACK-3",)
            elif ack.err == 26:
                clauses = ("RH-SAF-3",) if m.phase == "ascent" else ("RH-SAF-1",)
            elif "RH-ACK-4" in clauses:
                clauses = ("RH-ACK-4",) + tuple(c for c in clauses if c != "RH-ACK-4")[:1]
            elif type(item) is s.OSD and ack.err == 27:
                clauses = ("RH-OSD-2",)
            else:
                clauses = ("RH-ACK-3",)
            if self.on_event:
                self.on_event(t, "ack-error", f"{text[:40]} → err {ack.err}")
        elif self.on_event and type(item) is not s.OSD:
            self.on_event(t, "command", text.split(",", 1)[0].split("*", 1)[0][:32])
        data = tuple(type(r) for r in replies[:-1])
        nbytes = sum(len(r.ID) + 16 for r in replies) + (150 if s.OSI in data else 0)
        self.pending.append(_Pending(t, lineno, text, ack, data, clauses, mission_dep, pre, item,
                                     tx_bytes=nbytes))
        if len(self.pending) > 256:
            old = self.pending.popleft()
            if self.saw_vehicle:
                self._missing(old, "no $ACK while 256 later commands were sent")
        self._mode_changed(t)

    # ---------------------------------------------------------------- vehicle sentences
    def ack(self, a: s.ACK, t: float, lineno: int, text: str) -> None:
        """RH-ACK-1/2/3/4/5/6 and the command clauses, for one ``$ACK`` from the vehicle."""
        self.saw_vehicle = True
        self.advance(t)
        ev = Evidence(t, "<", lineno, text)
        if a.type in (13, 14):
            self.book.ok("RH-ACK-1")
            return
        idx = next((i for i, p in enumerate(self.pending) if p.ack.type == a.type), None)
        if idx is None:
            self._unmatched(a, t, ev)
            return
        if idx:
            for _ in range(idx):
                self._missing(self.pending.popleft(), f"no $ACK before the $ACK of a later command (line {lineno})")
        else:
            self.book.ok("RH-ACK-6")
        p = self.pending.popleft()
        if self.on_answer is not None:
            self.on_answer(p, a)
        cev = Evidence(p.t, ">", p.lineno, p.text)
        self.book.ok("RH-ACK-1")
        # RH-ACK-2: within the window plus transmit time (wall time, RH-TIM-2)
        dt = t - p.t
        window = self.profile.ack_window_s + (p.tx_bytes * 10.0 / self.baud if self.baud else 0.0)
        if self.ack_precise:
            if dt <= window + 2 * self.r:
                self.book.ok("RH-ACK-2")
            else:
                self.book.fail("RH-ACK-2", f"$ACK after {dt:.3f} s; window {window:.3f} s "
                                           f"(ack_window_s + transmit time)", [ev, cev])
        elif dt - 2 * self.r > window:
            self.book.fail("RH-ACK-2", f"$ACK after at least {dt - 2 * self.r:.3f} s; window {window:.3f} s", [ev, cev])
        else:
            self.book.inconclusive("RH-ACK-2", f"timestamps step {self.r:g} s cannot bound a {window:.3f} s "
                                               f"window (RH-TIM-1)", [ev, cev])
        # data before ACK (RH-ACK-5, RH-OSD-1/2)
        if p.ack.type == 8:
            self._judge_osd_data(p, a, cev, ev)
        want = (p.ack.status, p.ack.err)
        got = (a.status, a.err)
        if want == got:
            for c in p.clauses:
                self.book.ok(c)
            if a.status == 0 and a.extra and not isinstance(p.cmd, s.ORWSET):
                self.book.fail("RH-ACK-1", "extra fields on an $ACK that is not an $ORWSET reply", [ev, cev])
            return
        mission_related = p.mission_dependent and (a.err in _MISSION_ERRS or p.ack.err in _MISSION_ERRS
                                                    or isinstance(p.cmd, _MISSION_CMDS))
        reason = f"{p.text.split('*')[0][:60]} answered {_ack_text(a)}; the model expects {_ack_text(p.ack)}"
        if mission_related:
            for c in p.clauses or ("RH-ACK-3",):
                self.book.inconclusive(c, "the answer depends on the vehicle's mission files, which the "
                                          "log does not carry (use --missions)", [ev, cev])
            self._adopt(p, a)
            return
        if p.ack.err == 26 and self.lockout_inferred:
            for c in p.clauses:
                self.book.inconclusive(c, "the lockout was inferred from an $OSI report; its start, and "
                                          "so its end, is not known precisely", [ev, cev])
            return
        for c in p.clauses or ("RH-ACK-3",):
            self.book.fail(c, reason, [ev, cev])

    def _adopt(self, p: _Pending, a: s.ACK) -> None:
        """Follow the vehicle where only the mission files could decide."""
        if a.status == 1 and p.ack.status == 0 and p.pre is not None and not p.fed_after:
            self.model = p.pre
            self._mode_changed(p.t)
        elif a.status == 0 and p.ack.status == 1:
            self.mission_desync = True

    def _judge_osd_data(self, p: _Pending, a: s.ACK, cev: Evidence, ev: Evidence) -> None:
        got = tuple(p.got)
        if a.status == 1:
            if got:
                self.book.fail("RH-OSD-2", f"a rejected $OSD carried {len(got)} data sentence(s)", [ev, cev])
            return
        want = p.data if p.ack.status == 0 else ()
        if got == want:
            self.book.ok("RH-ACK-5")
            self.book.ok("RH-OSD-1")
            return
        names = lambda xs: ",".join("$" + c.ID for c in xs) or "none"  # noqa: E731
        if len(got) < len(want) and got == want[:len(got)]:
            self.book.fail("RH-ACK-5", f"$ACK,8 came before all requested data: got {names(got)}, "
                                       f"expected {names(want)}", [ev, cev])
        else:
            self.book.fail("RH-OSD-1", f"$OSD replies {names(got)}; expected {names(want)} in request order",
                           [ev, cev])

    def data(self, cls: type, sentence: Optional[s.Reply], t: float, lineno: int, text: str) -> None:
        """A data sentence from the vehicle: belongs to the oldest unanswered ``$OSD``."""
        self.saw_vehicle = True
        self.advance(t)
        ev = Evidence(t, "<", lineno, text)
        p = next((q for q in self.pending if q.ack.type == 8), None)
        if p is None:
            self._unmatched_data(cls, t, ev)
            return
        p.got.append(cls)
        if isinstance(sentence, s.OSI):
            self._judge_osi(p, sentence, t, ev)

    # ---------------------------------------------------------------- $OSI
    def _judge_osi(self, p: _Pending, osi: s.OSI, t: float, ev: Evidence) -> None:
        """RH-OUT-4 (and the clause whose timer or command explains a mismatch)."""
        live = p.snapshot is None
        m = self.model if live else p.snapshot
        if live and not self.recorder_plant:
            self._update_snapshot(osi)
            if (osi.error_state in SAFETY_CODES and m.error_state == "N" and m.phase == "none"):
                m.plant(SafetyViolation(osi.error_state), max(self.v(p.t), m.now or 0.0))
                self.inferred_safety += 1
                self.lockout_inferred = True
                if self.on_event:
                    self.on_event(p.t, "lockout", f"safety violation {osi.error_state} (inferred)")
                self._mode_changed(t)
        t0 = p.t
        now_v = self.v((t0 + t) / 2)
        slack_v = self.v((t - t0) / 2 + self.r)
        exp = quick_expectation(m, now_v, slack_v)
        findings = exp.check(osi)
        if findings and live and not self.recorder_plant:
            findings = self._infer(osi, now_v, slack_v, findings)
            exp = quick_expectation(self.model, now_v, slack_v)
        cev = Evidence(p.t, ">", p.lineno, p.text)
        if not findings:
            rr = self.recent_release
            if rr is not None and osi.mode != rr[1]:
                self.book.ok(rr[0])
            if m.error_state != "N":
                self.book.ok("RH-SAF-1")  # field 8 shows the violation's code
            if self.precise or (len(exp.states) == 1 and exp.states[0].park_lo >= exp.states[0].park_hi - 1):
                self.book.ok("RH-OUT-4")
            else:
                self.book.inconclusive("RH-OUT-4", f"timestamps step {self.r:g} s (×{self.scale:g}) cannot "
                                                   f"bound the timing tolerance (RH-TIM-1)", [ev, cev])
            return
        mission_modes = ("N", "P", "S")
        if not self.mission_known and osi.mode in mission_modes and all(
                a.mode in mission_modes for a in exp.states):
            self.book.inconclusive("RH-OUT-4", f"{findings[0][1]} — depends on the mission file, which the "
                                               f"log does not carry (use --missions)", [ev, cev])
            return
        msg = findings[0][1]
        if not self.precise:
            msg += " (mismatch beyond the widest timing the coarse timestamps allow)"
        self.book.fail("RH-OUT-4", msg, [ev, cev])
        blame = self._blame(osi, m)
        if blame:
            self.book.fail(blame, msg, [ev, cev])

    def _blame(self, osi: s.OSI, m: VehicleModel) -> Optional[str]:
        if osi.error_state != m.error_state:
            return "RH-SAF-1" if m.error_state != "N" or osi.error_state != "N" else None
        rr = self.recent_release
        if rr is not None and osi.mode == rr[1] and osi.mode != m.mode:
            return rr[0]
        la = self.last_accept
        if la is not None and la[0] and osi.mode == la[1] and osi.mode != m.mode:
            return la[0][0]
        if osi.mode == m.mode and m.mode == "mP" and osi.park_time != m.state()[3]:
            return "RH-PK-2"
        return None

    def _update_snapshot(self, osi: s.OSI) -> None:
        """Inference: the vehicle's reported position and depth become the plant snapshot."""
        m = self.model
        snap = m.snapshot
        depth = float(osi.depth) if osi.depth is not None else snap.depth_m
        if self.profile.depth_unit != "m":
            depth *= 0.3048
        lat, lon = float(osi.lat), float(osi.lon)
        surf_now = depth <= self.profile.gps_fix_depth_m
        surf_was = snap.depth_m <= self.profile.gps_fix_depth_m
        if surf_now != surf_was or abs(lat - snap.lat) > 1e-3 or abs(lon - snap.lon) > 1e-3:
            before = m.mode
            m.update_plant(snap.with_(lat=lat, lon=lon, depth_m=depth))
            if m.mode != before:
                self.inferred += 1

    def _infer(self, osi: s.OSI, now_v: float, slack_v: float, findings: list) -> list:
        """Apply the plant events that explain ``osi``, if any (bounded search)."""
        m = self.model
        cands: list[PlantEvent] = []
        if m.mode == "N":
            cands = [WaypointReached()]
        elif m.mode == "mP":
            cands = [OnStation()]
        elif m.mode == "W":
            cands = [QueueWaypointReached()]
        if not cands or m.phase != "none":
            return findings
        trial = m.clone()
        for step in range(64):
            trial.plant(cands[0], trial.now if trial.now is not None else now_v)
            got = quick_expectation(trial, now_v, slack_v).check(osi)
            if not got:
                for _ in range(step + 1):
                    self.model.plant(cands[0], self.model.now if self.model.now is not None else now_v)
                self.inferred += step + 1
                self.recent_release = None
                return []
            if trial.mode not in ("N", "mP", "W") or (cands[0].__class__ is not WaypointReached):
                break
        return findings

    # ---------------------------------------------------------------- bookkeeping
    def _unmatched(self, a: s.ACK, t: float, ev: Evidence) -> None:
        if self.first_command_t is None:
            self._pre_command("RH-ACK-1", ev)
            return
        for (_t, ln, txt, at) in reversed(self.silent_recent):
            if at == a.type or at is None:
                self.book.fail("RH-FRM-4", "a line the vehicle must discard silently was answered",
                               [Evidence(_t, ">", ln, txt), ev])
                break
        for (ln, at) in self.recent_missing:
            if at == a.type:
                self.book.fail("RH-ACK-6", "an $ACK came back after the $ACK of a later command", [ev])
                return
        self.unmatched_count += 1
        if len(self.unmatched) < 5:
            self.unmatched.append(ev)
        self.book.fail("RH-ACK-1", f"{_ack_text(a)} answers no outstanding command of type {a.type}", [ev])

    def _unmatched_data(self, cls: type, t: float, ev: Evidence) -> None:
        if self.first_command_t is None:
            self._pre_command("RH-ACK-5", ev)
            return
        self.book.fail("RH-ACK-5", f"${cls.ID} with no outstanding $OSD (data must precede its $ACK,8)", [ev])

    def _pre_command(self, cid: str, ev: Evidence) -> None:
        self.pre_command_count += 1
        if len(self.pre_command) < 5:
            self.pre_command.append((cid, ev))

    def _missing(self, p: _Pending, why: str) -> None:
        self.recent_missing.append((p.lineno, p.ack.type))
        self.book.fail("RH-ACK-1", f"{p.text.split('*')[0][:60]}: {why}; expected {_ack_text(p.ack)}",
                       [Evidence(p.t, ">", p.lineno, p.text)])

    def finish(self, t_end: float) -> None:
        """End of log: commands still waiting are missing, unless the log ended too soon."""
        self.advance(t_end)
        while self.pending:
            p = self.pending.popleft()
            if t_end - p.t > self.profile.ack_window_s + 2 * self.r:
                self._missing(p, "no $ACK before the log ended")
            else:
                self.book.inconclusive("RH-ACK-1", "the log ended inside the command's $ACK window",
                                       [Evidence(p.t, ">", p.lineno, p.text)])
        if self.saw_commands:
            for cid, ev in self.pre_command:
                self.book.inconclusive(cid, "a vehicle sentence before the first command in the log (its "
                                            "command may predate the capture)", [ev])
        for c in self.book.order:
            if c in UNJUDGEABLE:
                self.book.untested(c, UNJUDGEABLE[c])
        if self.inferred:
            self.book.note("RH-OUT-4", f"{self.inferred} plant event(s) were inferred from $OSI reports "
                                       f"(the log carries no plant notes).")
        if self.inferred_safety:
            self.book.note("RH-SAF-1", f"{self.inferred_safety} safety violation(s) were inferred from "
                                       f"$OSI field 8; their start (and the lockout's end) is known only "
                                       f"to the request before the report.")
        if not self.mission_known:
            for c in ("RH-OUT-4", "RH-MSN-4", "RH-JW-1"):
                self.book.note(c, "Mission files were not given (--missions): mission-dependent answers "
                                  "are not judged.")
            self.book.untested("RH-MSN-4", "Mission end depends on the mission file (use --missions).")

