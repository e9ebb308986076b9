"""What each accepted command, timer and plant event does to the model's data (§4–7).

The transition table (:mod:`~helmcheck.model.transitions`) decides *whether* and *to which mode
and phase*; the functions here do the rest: set-points, the queue, timers, missions, logs,
settings and the replies. ``CHECKS`` are the data-dependent checks that run after the table has
accepted a command and before anything changes (``$OJW`` index RH-JW-1, ``$OLOGD`` count
RH-LOG-2, no mission loaded 17 and look-ups 1/3/31 RH-RD-6, ``$OPK`` distance 40 RH-PK-1);
``APPLY`` maps each event to its effect; ``EXPIRE`` maps each timer to its expiry;
:func:`reading_field_error` is a field error as the vehicle's readings (:mod:`.readings`) have it.
Each function names the clauses it implements in its docstring.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Callable, Optional, Union

import dataclasses

from ..grammar import sentences as s
from ..grammar.ranges import mission_name_problem
from . import events as ev
from .geo import distance_m
from .missions import BadMission, Mission, MissingMission
from .records import LogRow, OposRecord
from .transitions import STAY, Row

if TYPE_CHECKING:  # pragma: no cover
    from .vehicle import VehicleModel

__all__ = ["CHECKS", "APPLY", "EXPIRE", "ack", "reading_field_error", "reading_repair", "reading_flag_error"]

_ACKS: dict[tuple[int, int, int], s.ACK] = {}


def _ack(t: int, err: int = 0) -> s.ACK:
    key = (t, 1 if err else 0, err)
    a = _ACKS.get(key)
    if a is None:
        a = _ACKS[key] = s.ACK(t, key[1], err)
    return a


ack = _ack


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
        if m.loaded is None or (m.stopped_loaded and m.readings["stop_unloads"] == "unloaded"):
            return 17
        return None
    found = m._lookup(c.name)
    if isinstance(found, MissingMission):
        return 1
    if isinstance(found, BadMission):
        return 3
    if c.srp:
        if mission_name_problem(c.srp) is not None:
            return 31  # the path rules read as a look-up (reading srp_bad_path = 31): never opened
        if not isinstance(m._lookup(c.srp), Mission):
            return 31
    return None


def reading_repair(m: VehicleModel, err) -> Optional[s.Command]:
    """The command a line the grammar refuses for one field is, read as the vehicle's readings
    read that field (``srp_bad_path = 31``: an SRP name that breaks the path rules;
    ``omw_pitch_speed = unbounded``: an ``$OMW`` pitch or speed beyond ``$OMS``'s ranges), or None
    (the line is refused for its field, as the grammar says)."""
    part, name = err.partial, err.field
    if part is None or not name or err.value is None:
        return None
    if any(getattr(part, f) is None for f in part.field_names() if f != name and f not in ("srp", "depth2")):
        return None  # another field is bad too
    r = m.readings
    if type(part) is s.OMSTART and name == "srp" and r["srp_bad_path"] == "31":
        return dataclasses.replace(part, srp=err.value)
    if type(part) is s.OMW and name in ("max_pitch", "speed") and r["omw_pitch_speed"] == "unbounded":
        from decimal import Decimal, InvalidOperation
        try:
            value = Decimal(err.value)
        except (InvalidOperation, ValueError):
            return None
        return dataclasses.replace(part, **{name: value}) if value.is_finite() and value >= 0 else None
    return None


def reading_flag_error(m: VehicleModel, c: s.OMLOAD) -> Optional[int]:
    """An ``$OMLOAD`` flag outside the flags the vehicle takes (``omload_flag``: any, 0-3 or 0): 29."""
    allowed = {"0-3": (0, 1, 2, 3), "0": (0,)}.get(m.readings["omload_flag"])
    return 29 if allowed is not None and int(c.flag) not in allowed else None


def reading_field_error(m: VehicleModel, c: s.Command, err: int) -> Optional[int]:
    """``err`` (the command's field error) as the vehicle's readings have it (:mod:`.readings`):
    None where a reading takes the bad field elsewhere (an SRP name's path to the look-up,
    ``srp_bad_path = 31``) or not as bad at all (``$OMW`` pitch and speed, ``omw_pitch_speed =
    unbounded``), when no other field is bad."""
    from .validate import field_error
    r = m.readings
    if type(c) is s.OMSTART and c.srp and r["srp_bad_path"] == "31" and mission_name_problem(c.srp) is not None:
        return field_error(dataclasses.replace(c, srp="srp.mis"), m.profile)
    if type(c) is s.OMW and r["omw_pitch_speed"] == "unbounded":
        pitch = min(c.max_pitch, 45) if c.max_pitch >= 0 else c.max_pitch
        top = m.profile.max_speed_kn
        speed = min(c.speed, type(c.speed)(str(top))) if c.speed >= 0 else c.speed
        if (pitch, speed) != (c.max_pitch, c.speed):
            return field_error(dataclasses.replace(c, max_pitch=pitch, speed=speed), m.profile)
    return err


def _chk_opk(m: VehicleModel, c: s.OPK) -> Optional[int]:
    p = m.snapshot
    d = distance_m(p.lat, p.lon, float(c.lat), float(c.lon))
    return 40 if d > m.profile.opk_max_distance_m else None


CHECKS: dict[str, Callable[[VehicleModel, object], Optional[int]]] = {
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
    m._control_changed()
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
    m._reset_mission(None)
    m._transition(row, now)
    return [_ack(1)]


def _do_omload(m: VehicleModel, row: Row, c: s.OMLOAD, now: float) -> list[s.Reply]:
    """RH-MSN-1: the mission becomes the loaded one."""
    m.loaded = m._lookup(c.name)  # type: ignore[assignment]
    m.stopped_loaded = False
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
    reported = m.readings["opos_ctd"] == "reported"  # else used inside, $OCTD its own sensor's
    if reported and c.conductivity is not None and c.conductivity != "":
        changes["conductivity"] = float(c.conductivity)
    if reported and c.temperature is not None and c.temperature != "":
        changes["temperature"] = float(c.temperature)
    applied = not m.gps_fix
    if applied:
        changes.update(lat=float(c.lat), lon=float(c.lon), speed_kn=float(c.speed))
    if changes:
        m._set_snapshot(m.snapshot.with_(**changes))
    m._own_history()
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
    m._write_log_row(LogRow(now, m.log_labels or (), tuple(c.values)))
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
        m._control_changed()
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
        m.stopped_loaded = True
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


APPLY: dict[str, Callable[..., list[s.Reply]]] = {
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


EXPIRE: dict[str, Callable[[VehicleModel, float], None]] = {
    "remote": _exp_remote, "opk": _exp_opk, "qpark": _exp_qpark, "park": _exp_park,
    "dvl": _exp_dvl, "lockout": _exp_lockout,
}

