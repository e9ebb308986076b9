"""Value ranges: the checks a field's syntax alone cannot make, taken from the profile.

Each rule names its clause and field. Commands that fail answer with the command's
"incorrect values" error (RH-ACK-3); replies that fail break RH-OUT-1/RH-OUT-3. Bounds marked
``[D]`` in the reference profile come from the :class:`~helmcheck.profile.Profile`; the fixed
ones (heading below 360, pitch at most 45) are the profile's own text.

State-dependent checks (``$OJW`` against the mission length, ``$OPK`` distance) belong to the
model, not here: this module looks at one sentence and the profile only.
"""

from __future__ import annotations

import re
from decimal import Decimal
from functools import lru_cache
from typing import Callable, Iterator, Optional

from ..profile import Profile, SAFETY_CODES
from . import sentences as S
from .errors import RANGE, SentenceError

__all__ = ["check_ranges", "range_errors", "field_text", "mission_name_problem"]

_D = Decimal
Problem = tuple[str, str, str]  # (clause, field, message)

_DRIVE = re.compile(r"^[A-Za-z]:")


def mission_name_problem(name: str) -> Optional[str]:
    """Why a mission name may not be used, or None (RH-MSN-1, RH-RD-6).

    The name must resolve inside the vehicle's mission directory: no absolute path, no drive
    letter, no ``..`` component (with either slash), nothing empty.
    """
    if not name.strip():
        return "mission name is empty"
    if name.startswith(("/", "\\")):
        return "mission name is an absolute path"
    if _DRIVE.match(name):
        return "mission name has a drive letter"
    parts = re.split(r"[\\/]", name)
    if any(p == ".." for p in parts):
        return "mission name has a '..' component"
    return None


def _between(v, lo, hi, clause, field, hi_open=False) -> Iterator[Problem]:
    if v is None:
        return
    if v < lo or (v >= hi if hi_open else v > hi):
        right = ")" if hi_open else "]"
        yield clause, field, f"{field} {v} is outside [{lo}, {hi}{right}"


@lru_cache(maxsize=64)
def _num(x: float) -> Decimal:
    return _D(repr(float(x)))


def _oms(s: S.OMS, p: Profile) -> Iterator[Problem]:
    c = "RH-SRV-2"
    yield from _between(s.heading, 0, 360, c, "heading", hi_open=True)
    yield from _between(s.depth, 0, _num(p.max_depth), c, "depth")
    yield from _between(s.max_pitch, 0, 45, c, "max_pitch")
    yield from _between(s.speed, 0, _num(p.max_speed_kn), c, "speed")
    yield from _between(s.timeout, *p.timeout_range, c, "timeout")


def _omp(s: S.OMP, p: Profile) -> Iterator[Problem]:
    if s.reserved != "00":
        yield "RH-PRM-2", "reserved", f"reserved field must be 00, not {s.reserved!r} (RH-RD-9)"
    yield from _between(s.timeout, *p.timeout_range, "RH-PRM-2", "timeout")


def _ojw(s: S.OJW, p: Profile) -> Iterator[Problem]:
    if s.waypoint < p.waypoint_base:
        yield "RH-JW-1", "waypoint", f"waypoint {s.waypoint} is below the first waypoint {p.waypoint_base}"


def _omstop(s: S.OMSTOP, p: Profile) -> Iterator[Problem]:
    if s.flag != 0:
        yield "RH-MSN-3", "flag", f"flag must be 0, not {s.flag}"


def _omload(s: S.OMLOAD, p: Profile) -> Iterator[Problem]:
    why = mission_name_problem(s.name)
    if why:
        yield "RH-MSN-1", "name", why


def _omstart(s: S.OMSTART, p: Profile) -> Iterator[Problem]:
    for f in ("ignore_gps", "ignore_sounder", "calibrate_pressure", "mission_type"):
        v = getattr(s, f)
        if v not in (0, 1):
            yield "RH-RD-6", f, f"{f} must be 0 or 1, not {v}"
    why = mission_name_problem(s.name)
    if why:
        yield "RH-RD-6", "name", why
    if s.srp:
        why = mission_name_problem(s.srp)
        if why:
            yield "RH-RD-6", "srp", "SRP " + why


def _omstart_paper(s: S.OMSTARTPaper, p: Profile) -> Iterator[Problem]:
    if s.flag not in (0, 1, 2, 3):
        yield "RH-MSN-2", "flag", f"flag must be 0, 1, 2 or 3, not {s.flag}"


def _latlon(s, clause) -> Iterator[Problem]:
    yield from _between(s.lat, -90, 90, clause, "lat")
    yield from _between(s.lon, -180, 180, clause, "lon")


def _opos(s: S.OPOS, p: Profile) -> Iterator[Problem]:
    yield from _latlon(s, "RH-POS-1")
    yield from _between(s.speed, 0, _num(p.max_speed_kn), "RH-RD-9", "speed")
    yield from _between(s.conductivity, 0, 100, "RH-RD-9", "conductivity")
    yield from _between(s.temperature, -5, 50, "RH-RD-9", "temperature")


def _orwset(s: S.ORWSET, p: Profile) -> Iterator[Problem]:
    c = "RH-RD-8"
    if s.access == "R":
        if s.state is not None:
            yield c, "state", "a read ($ORWSET,<setting>,R) takes no further fields"
        return
    if s.state is None:
        yield c, "state", "a write needs a state 0 or 1"
        return
    if s.state not in (0, 1):
        yield c, "state", f"state must be 0 or 1, not {s.state}"
    if s.setting == "SafetyAction" and (len(s.values) != 1 or s.values[0] not in ("park", "srp")):
        yield c, "values", "SafetyAction takes exactly one value, park or srp"


def _odvl(s: S.ODVL, p: Profile) -> Iterator[Problem]:
    yield from _between(s.x, -5, 5, "RH-RD-9", "x")
    yield from _between(s.y, -5, 5, "RH-RD-9", "y")
    yield from _between(s.timeout, *p.timeout_range, "RH-DVL-1", "timeout")


def _opk(s: S.OPK, p: Profile) -> Iterator[Problem]:
    yield from _latlon(s, "RH-PK-1")
    yield from _between(s.minutes, 1, 1440, "RH-PK-1", "minutes")
    yield from _between(s.speed, 0, _num(p.max_speed_kn), "RH-PK-1", "speed")


def _omw(s: S.OMW, p: Profile) -> Iterator[Problem]:
    yield from _latlon(s, "RH-RD-9")
    yield from _between(s.depth1, -100, 100, "RH-RD-9", "depth1")
    yield from _between(s.depth2, -100, 100, "RH-RD-9", "depth2")
    yield from _between(s.max_pitch, 0, 45, "RH-RD-9", "max_pitch")
    yield from _between(s.speed, 0, _num(p.max_speed_kn), "RH-RD-9", "speed")
    yield from _between(s.park_s, 0, 86400, "RH-RD-9", "park_s")


def _omw_clear(s: S.OMWClear, p: Profile) -> Iterator[Problem]:
    allowed = {k.lower() for k in p.omw_clear_keywords}
    if s.keyword.lower() not in allowed:
        yield "RH-OMW-3", "keyword", f"keyword {s.keyword!r} is not one of {', '.join(p.omw_clear_keywords)}"
    if s.waypoint is not None:
        yield from _omw(s.waypoint, p)


# --------------------------------------------------------------------------- replies

def _ack(s: S.ACK, p: Profile) -> Iterator[Problem]:
    if not 1 <= s.type <= 17:
        yield "RH-ACK-1", "type", f"ACK type {s.type} is not one of 1..17"
    if s.status not in (0, 1):
        yield "RH-ACK-1", "status", f"status must be 0 or 1, not {s.status}"
    elif (s.status == 0) != (s.err == 0):
        yield "RH-ACK-1", "err", f"err must be 0 exactly when status is 0 (status {s.status}, err {s.err})"
    if s.extra and s.type != 12:
        yield "RH-ACK-1", "extra", "only the $ORWSET reply (type 12) carries extra fields"


def _osi(s: S.OSI, p: Profile) -> Iterator[Problem]:
    n = s.field_count
    if n != p.osi_fields:
        yield "RH-OUT-1", "fields", f"$OSI has {n} fields; profile {p.protocol} expects {p.osi_fields}"
    if s.actuators != s.actuators.upper():
        yield "RH-OUT-1", "actuators", "fins and motor must be upper-case hex"
    if s.mode == "Mp":
        yield "RH-OUT-1", "mode", "a vehicle emits mP, not Mp"
    yield from _latlon(s, "RH-OUT-3")
    yield from _between(s.speed, 0, _D("1e9"), "RH-OUT-3", "speed")
    yield from _between(s.distance, 0, _D("1e12"), "RH-OUT-3", "distance")
    yield from _between(s.true_heading, 0, 360, "RH-OUT-3", "true_heading", hi_open=True)
    if p.protocol == "rh5" and s.battery is not None:
        try:
            b = _D(s.battery)
        except ArithmeticError:
            yield "RH-OUT-1", "battery", f"battery {s.battery!r} is not a number"
        else:
            yield from _between(b, 0, 100, "RH-OUT-3", "battery")
    if s.error_state != "N" and s.error_state not in SAFETY_CODES:  # pragma: no cover - grammar
        yield "RH-OUT-1", "error_state", f"unknown error state {s.error_state!r}"


def _compass(s: S.Compass, p: Profile) -> Iterator[Problem]:
    yield from _between(s.heading, 0, 360, "RH-OUT-3", "heading", hi_open=True)
    yield from _between(s.pitch, -90, 90, "RH-OUT-3", "pitch")
    yield from _between(s.roll, -90, 90, "RH-OUT-3", "roll")


def _gprmc(s: S.GPRMC, p: Profile) -> Iterator[Problem]:
    # The grammar fixes the digit counts (ddmm.mmmm, dddmm.mmmm), so comparing the digit
    # strings is comparing the numbers: degrees at most 90 / 180, minutes below 60.
    lat, lon = s.lat, s.lon
    if lat and (lat[:2] > "90" or lat[2:4] > "59"):
        yield "RH-OUT-3", "lat", f"latitude {lat} is not a valid ddmm.mmmm"
    if lon and (lon[:3] > "180" or lon[3:5] > "59"):
        yield "RH-OUT-3", "lon", f"longitude {lon} is not a valid dddmm.mmmm"


def _opi(s: S.OPI, p: Profile) -> Iterator[Problem]:
    yield from _between(s.percent, 0, 100, "RH-OUT-3", "percent")


def _oins(s: S.OINS, p: Profile) -> Iterator[Problem]:
    yield from _latlon(s, "RH-OUT-3")
    yield from _between(s.heading, 0, 360, "RH-OUT-3", "heading", hi_open=True)


_RULES: dict[type, Callable[..., Iterator[Problem]]] = {
    S.OMS: _oms, S.OMP: _omp, S.OJW: _ojw, S.OMSTOP: _omstop, S.OMLOAD: _omload,
    S.OMSTART: _omstart, S.OMSTARTPaper: _omstart_paper, S.OPOS: _opos, S.ORWSET: _orwset,
    S.ODVL: _odvl, S.OPK: _opk, S.OMW: _omw, S.OMWClear: _omw_clear,
    S.ACK: _ack, S.OSI: _osi, S.Compass: _compass, S.GPRMC: _gprmc, S.OPI: _opi, S.OINS: _oins,
}


def _osi_fine(s: S.OSI, p: Profile) -> bool:
    """True only when :func:`_osi` finds nothing: the same tests, without a generator per field
    (a vehicle sends an ``$OSI`` at every poll). False sends the report through :func:`_osi`."""
    lat, lon, speed, distance, heading = s.lat, s.lon, s.speed, s.distance, s.true_heading
    if (s.field_count != p.osi_fields or s.actuators != s.actuators.upper() or s.mode == "Mp"
            or (lat is not None and (lat < -90 or lat > 90))
            or (lon is not None and (lon < -180 or lon > 180))
            or (speed is not None and (speed < 0 or speed > _SPEED_MAX))
            or (distance is not None and (distance < 0 or distance > _DISTANCE_MAX))
            or (heading is not None and (heading < 0 or heading >= 360))
            or (s.error_state != "N" and s.error_state not in SAFETY_CODES)):
        return False
    if p.protocol == "rh5" and s.battery is not None:
        b = _D(s.battery)
        return not (b < 0 or b > 100)
    return True


_SPEED_MAX, _DISTANCE_MAX = _D("1e9"), _D("1e12")


def check_ranges(s: S.Sentence, profile: Profile) -> Optional[SentenceError]:
    """The first range problem of ``s`` under ``profile`` as a :class:`SentenceError`, or None."""
    if type(s) is S.OSI:
        try:
            if _osi_fine(s, profile):
                return None
        except (ArithmeticError, TypeError):
            pass  # what the rule itself says of it
    for err in _errors(s, profile):
        return err
    return None


def range_errors(s: S.Sentence, profile: Profile) -> list[SentenceError]:
    """Every range problem of ``s`` under ``profile``, in field order (the first is
    :func:`check_ranges`'); each names its field, and ``value`` is that field's text as sent."""
    if check_ranges(s, profile) is None:
        return []
    return list(_errors(s, profile))


def _errors(s: S.Sentence, profile: Profile) -> Iterator[SentenceError]:
    rule = _RULES.get(type(s))
    if rule is None:
        return
    is_cmd = isinstance(s, S.Command)
    for clause, field, message in rule(s, profile):
        yield SentenceError(
            clause, f"${s.ID} {message}", None, RANGE, s.ID, field,
            getattr(s, "ACK_TYPE", None) if is_cmd else None,
            getattr(s, "ERR", None) if is_cmd else None, field_text(s, field),
        )


def field_text(s: S.Sentence, field: str) -> Optional[str]:
    """A scalar field's text as the sentence carries it (Decimals keep the digits sent), or None
    for a name that is no scalar field of ``s`` (``fields``, the field count)."""
    if field not in s.field_names():
        return None
    v = getattr(s, field)
    if v is None or isinstance(v, (tuple, S.Sentence)):
        return None
    if type(s) is S.OSI and field == "park_time":
        return f"P{v}"
    return format(v, "f") if isinstance(v, Decimal) else str(v)
