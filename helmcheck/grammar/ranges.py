"""Value ranges: the checks a field's syntax alone cannot make, taken from the profile.

Each rule names its clause and field. Commands that fail answer with the command's
"incorrect values" error (RH-ACK-3); replies that fail break RH-OUT-1/RH-OUT-3. Bounds marked
``[D]`` in the reference profile come from the :class:`~helmcheck.profile.Profile`; the fixed
ones (heading below 360, pitch at most 45) are the profile's own text.

A command's checks are data: :data:`COMMAND_CHECKS` holds, per sentence class and in field order,
its numeric ranges (:class:`Bound`), its closed sets of values (:class:`Choice`) and its mission
names (:class:`NameRule`); the checks run from those rows, and the range edges a certification
must reach (:mod:`helmcheck.certify.vehicle.edges`) are generated from the same rows.

State-dependent checks (``$OJW`` against the mission length, ``$OPK`` distance) belong to the
model, not here: this module looks at one sentence and the profile only.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from decimal import Decimal
from functools import lru_cache
from typing import Callable, Iterator, Optional

from ..profile import Profile, SAFETY_CODES
from . import sentences as S
from .errors import RANGE, SentenceError

__all__ = ["check_ranges", "range_errors", "field_text", "mission_name_problem", "COMMAND_CHECKS", "Bound", "Choice",
           "NameRule"]

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


def _between(v, lo, hi, clause, field, hi_open=False, lo_name="") -> Iterator[Problem]:
    if v is None:
        return
    if hi is None:
        if v < lo:
            yield clause, field, f"{field} {v} is below {lo_name or 'the lowest allowed'} {lo}"
    elif v < lo or (v >= hi if hi_open else v > hi):
        right = ")" if hi_open else "]"
        yield clause, field, f"{field} {v} is outside [{lo}, {hi}{right}"


def _latlon(s, clause) -> Iterator[Problem]:
    yield from _between(s.lat, -90, 90, clause, "lat")
    yield from _between(s.lon, -180, 180, clause, "lon")


@lru_cache(maxsize=64)
def _num(x: float) -> Decimal:
    return _D(repr(float(x)))


# --------------------------------------------------------------------------- commands, as data
#
# Every value check of a command field is one row below, in field order: a numeric range
# (:class:`Bound`), a closed set of values (:class:`Choice`) or the mission-name path rules
# (:class:`NameRule`). The checks run from these rows, and the list of range edges a certification
# must reach (:mod:`helmcheck.certify.vehicle.edges`) is generated from the same rows, so a range
# added here is an edge there.


@dataclass(frozen=True)
class Bound:
    """A command field's numeric range: ``[lo, hi]`` (``[lo, hi)`` with ``hi_open``); ``limits(profile)``
    gives ``(lo, hi)``, either ``None`` where that side has no bound here (``$OJW``'s upper bound is
    the mission's length: the model's)."""

    sentence: type
    field: str
    clause: str
    limits: Callable[[Profile], tuple]
    hi_open: bool = False
    lo_name: str = ""  #: what the lower bound is, for a one-sided bound's message


@dataclass(frozen=True)
class Choice:
    """A command field whose value must be one of ``allowed(profile)`` (compared as text; ``fold``:
    regardless of case, RH-RD-4). ``refused``: values just outside the set — a neighbour of an
    allowed one — that the edge list probes; ``message(value, allowed)`` is the problem's words."""

    sentence: type
    field: str
    clause: str
    allowed: Callable[[Profile], tuple]
    refused: tuple
    message: Callable[[object, tuple], str]
    fold: bool = False
    single: bool = False  #: the field is a tuple of values of which exactly one is allowed

    def problem(self, value, profile: Profile) -> Optional[str]:
        allowed = tuple(str(a) for a in self.allowed(profile))
        if self.single:
            ok = len(value) == 1 and str(value[0]) in allowed
        elif self.fold:
            ok = str(value).lower() in {a.lower() for a in allowed}
        else:
            ok = str(value) in allowed
        return None if ok else self.message(value, allowed)


@dataclass(frozen=True)
class NameRule:
    """A mission name that must resolve inside the mission directory (:func:`mission_name_problem`);
    ``optional``: an absent or empty field is no name (``$OMSTART``'s SRP)."""

    sentence: type
    field: str
    clause: str
    prefix: str = ""
    optional: bool = False


def _ms(p: Profile) -> tuple:
    return (0, _num(p.max_speed_kn))


def _to(p: Profile) -> tuple:
    return tuple(p.timeout_range)


def _lat(cls, clause) -> tuple:
    return (Bound(cls, "lat", clause, lambda p: (-90, 90)), Bound(cls, "lon", clause, lambda p: (-180, 180)))


_FLAGS = ("ignore_gps", "ignore_sounder", "calibrate_pressure", "mission_type")

_OMW = (*_lat(S.OMW, "RH-RD-9"),
        Bound(S.OMW, "depth1", "RH-RD-9", lambda p: (-100, 100)),
        Bound(S.OMW, "depth2", "RH-RD-9", lambda p: (-100, 100)),
        Bound(S.OMW, "max_pitch", "RH-RD-9", lambda p: (0, 45)),
        Bound(S.OMW, "speed", "RH-RD-9", _ms),
        Bound(S.OMW, "park_s", "RH-RD-9", lambda p: (0, 86400)))

#: sentence class -> its value checks, in field order (module comment above).
COMMAND_CHECKS: dict[type, tuple] = {
    S.OMS: (Bound(S.OMS, "heading", "RH-SRV-2", lambda p: (0, 360), hi_open=True),
            Bound(S.OMS, "depth", "RH-SRV-2", lambda p: (0, _num(p.max_depth))),
            Bound(S.OMS, "max_pitch", "RH-SRV-2", lambda p: (0, 45)),
            Bound(S.OMS, "speed", "RH-SRV-2", _ms),
            Bound(S.OMS, "timeout", "RH-SRV-2", _to)),
    S.OMP: (Choice(S.OMP, "reserved", "RH-PRM-2", lambda p: ("00",), ("01",),
                   lambda v, a: f"reserved field must be 00, not {v!r} (RH-RD-9)"),
            Bound(S.OMP, "timeout", "RH-PRM-2", _to)),
    S.OJW: (Bound(S.OJW, "waypoint", "RH-JW-1", lambda p: (p.waypoint_base, None),
                  lo_name="the first waypoint"),),
    S.OMSTOP: (Choice(S.OMSTOP, "flag", "RH-MSN-3", lambda p: (0,), (1,), lambda v, a: f"flag must be 0, not {v}"),),
    S.OMLOAD: (NameRule(S.OMLOAD, "name", "RH-MSN-1"),),
    S.OMSTART: (*(Choice(S.OMSTART, f, "RH-RD-6", lambda p: (0, 1), (2,),
                         (lambda f: lambda v, a: f"{f} must be 0 or 1, not {v}")(f)) for f in _FLAGS),
                NameRule(S.OMSTART, "name", "RH-RD-6"),
                NameRule(S.OMSTART, "srp", "RH-RD-6", prefix="SRP ", optional=True)),
    S.OMSTARTPaper: (Choice(S.OMSTARTPaper, "flag", "RH-MSN-2", lambda p: (0, 1, 2, 3), (4,),
                            lambda v, a: f"flag must be 0, 1, 2 or 3, not {v}"),),
    S.OPOS: (*_lat(S.OPOS, "RH-POS-1"),
             Bound(S.OPOS, "speed", "RH-RD-9", _ms),
             Bound(S.OPOS, "conductivity", "RH-RD-9", lambda p: (0, 100)),
             Bound(S.OPOS, "temperature", "RH-RD-9", lambda p: (-5, 50))),
    S.ORWSET: (Choice(S.ORWSET, "state", "RH-RD-8", lambda p: (0, 1), (2,),
                      lambda v, a: f"state must be 0 or 1, not {v}"),
               Choice(S.ORWSET, "values", "RH-RD-8", lambda p: ("park", "srp"), ("Park", "dive"),
                      lambda v, a: "SafetyAction takes exactly one value, park or srp", single=True)),
    S.ODVL: (Bound(S.ODVL, "x", "RH-RD-9", lambda p: (-5, 5)),
             Bound(S.ODVL, "y", "RH-RD-9", lambda p: (-5, 5)),
             Bound(S.ODVL, "timeout", "RH-DVL-1", _to)),
    S.OPK: (*_lat(S.OPK, "RH-PK-1"),
            Bound(S.OPK, "minutes", "RH-PK-1", lambda p: (1, 1440)),
            Bound(S.OPK, "speed", "RH-PK-1", _ms)),
    S.OMW: _OMW,
    S.OMWClear: (Choice(S.OMWClear, "keyword", "RH-OMW-3", lambda p: tuple(p.omw_clear_keywords), ("CLEARS",),
                        lambda v, a: f"keyword {v!r} is not one of {', '.join(a)}", fold=True),),
}


def _check(row, s, p: Profile) -> Iterator[Problem]:
    v = getattr(s, row.field)
    if isinstance(row, Bound):
        lo, hi = row.limits(p)
        yield from _between(v, lo, hi, row.clause, row.field, row.hi_open, row.lo_name)
    elif isinstance(row, NameRule):
        if row.optional and not v:
            return
        why = mission_name_problem(v)
        if why:
            yield row.clause, row.field, row.prefix + why
    elif v is not None:
        why = row.problem(v, p)
        if why:
            yield row.clause, row.field, why


def _command(s: S.Command, p: Profile) -> Iterator[Problem]:
    for row in COMMAND_CHECKS[type(s)]:
        yield from _check(row, s, p)


def _orwset(s: S.ORWSET, p: Profile) -> Iterator[Problem]:
    c = "RH-RD-8"
    if s.access == "R":
        if s.state is not None:
            yield c, "state", "a read ($ORWSET,<setting>,R) takes no further fields"
        return
    if s.state is None:
        yield c, "state", "a write needs a state 0 or 1"
        return
    state, values = COMMAND_CHECKS[S.ORWSET]
    yield from _check(state, s, p)
    if s.setting == "SafetyAction":
        yield from _check(values, s, p)


def _omw_clear(s: S.OMWClear, p: Profile) -> Iterator[Problem]:
    yield from _command(s, p)
    if s.waypoint is not None:
        yield from _command(s.waypoint, p)


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
    **{cls: _command for cls in COMMAND_CHECKS}, S.ORWSET: _orwset, S.OMWClear: _omw_clear,
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
