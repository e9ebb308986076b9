"""Field syntax and ranges of each command, as the vehicle judges them (RH-ACK-3, RH-RD-9).

The parser already rejects most bad fields with a :class:`~helmcheck.grammar.errors.SentenceError`;
this module checks the sentence *objects* again, against the profile's ``[D]`` bounds, so that
the model is right for objects built by hand, by Hypothesis or by a parser with a different
profile. :func:`field_error` answers the command's "incorrect values" error or ``None``.

Bounds: ``$OMS`` RH-SRV-2; ``$OMP`` RH-PRM-2; ``$OPK`` RH-PK-1; ``$OMW`` RH-OMW-3, RH-RD-4, RH-RD-9;
``$OMSTART`` RH-MSN-2, RH-RD-6; ``$OMLOAD`` RH-MSN-1; ``$OPOS`` RH-POS-1, RH-RD-9; ``$OSD`` RH-OSD-2,
RH-RD-7; ``$OLOGL``/``$OLOGD`` RH-LOG-1/2, RH-RD-9; ``$ORWSET`` RH-SET-1/2, RH-RD-8; ``$ODVL``
RH-DVL-1, RH-RD-9.

Decisions (spec open): the ``$OMSTOP`` flag must be 0 (the ``$OMLOAD`` flag is not judged); a bad path in the ``$OMSTART``
SRP name is err 30 like the mission name (a field value), while a missing or unusable SRP file
is err 31 (a look-up); ``$ORWSET,<s>,R`` must carry no state and no values.
"""

from __future__ import annotations

from decimal import Decimal
from typing import Optional

from ..grammar import sentences as s
from ..profile import SAFETY_CODES, Profile
from .missions import mission_name_problem

__all__ = ["field_error", "SETTING_NAMES", "SAFETY_ACTIONS"]

#: ``$ORWSET`` setting names (RH-RD-8): the §7 safety codes plus ``SafetyAction``.
SETTING_NAMES = frozenset(SAFETY_CODES) | {"SafetyAction"}
SAFETY_ACTIONS = ("park", "srp")
_OSD_LETTERS = frozenset("GCSPYDTI")
_HEX = frozenset("0123456789abcdefABCDEF")


def _num(x: object) -> bool:
    if isinstance(x, Decimal):
        return x.is_finite()
    if isinstance(x, bool):
        return False
    if isinstance(x, int):
        return True
    if isinstance(x, float):
        return x == x and abs(x) != float("inf")
    return False


def _between(x: object, lo: float, hi: float) -> bool:
    return _num(x) and lo <= x <= hi  # type: ignore[operator]


def _int_between(x: object, lo: int, hi: int) -> bool:
    return isinstance(x, int) and not isinstance(x, bool) and lo <= x <= hi


def _timeout(x: object, p: Profile) -> bool:
    lo, hi = p.timeout_range
    return _int_between(x, lo, hi)


def _lat_lon(lat: object, lon: object) -> bool:
    return _between(lat, -90, 90) and _between(lon, -180, 180)


def _omw_ok(c: s.OMW, p: Profile) -> bool:
    return (_lat_lon(c.lat, c.lon) and _between(c.depth1, -100, 100)
            and (c.depth2 is None or c.depth2 == "" or _between(c.depth2, -100, 100))
            and _between(c.max_pitch, 0, 45) and _between(c.speed, 0, p.max_speed_kn)
            and _int_between(c.park_s, 0, 86400) and isinstance(c.sensors, str))


def _oms(c: s.OMS, p: Profile) -> bool:
    return (_num(c.heading) and 0 <= c.heading < 360 and _between(c.depth, 0, p.max_depth)
            and _between(c.max_pitch, 0, 45) and _between(c.speed, 0, p.max_speed_kn)
            and _timeout(c.timeout, p))


def _omp(c: s.OMP, p: Profile) -> bool:
    a = c.actuators
    return (isinstance(a, str) and len(a) == 10 and all(ch in _HEX for ch in a)
            and c.reserved == "00" and _timeout(c.timeout, p))


def _ojw(c: s.OJW, p: Profile) -> bool:
    return isinstance(c.waypoint, int) and not isinstance(c.waypoint, bool)


def _opk(c: s.OPK, p: Profile) -> bool:
    return (_lat_lon(c.lat, c.lon) and _int_between(c.minutes, 1, 1440)
            and _between(c.speed, 0, p.max_speed_kn))


def _omw_clear(c: s.OMWClear, p: Profile) -> bool:
    kw = c.keyword.lower() if isinstance(c.keyword, str) else None
    if kw not in {k.lower() for k in p.omw_clear_keywords}:
        return False
    return c.waypoint is None or (isinstance(c.waypoint, s.OMW) and _omw_ok(c.waypoint, p))


def _omstop(c: s.OMSTOP, p: Profile) -> bool:
    return c.flag == 0 and isinstance(c.flag, int) and not isinstance(c.flag, bool)


def _omload(c: s.OMLOAD, p: Profile) -> bool:
    return isinstance(c.name, str) and mission_name_problem(c.name) is None


def _omstart(c: s.OMSTART, p: Profile) -> bool:
    flags = (c.ignore_gps, c.ignore_sounder, c.calibrate_pressure, c.mission_type)
    if not all(_int_between(f, 0, 1) for f in flags):
        return False
    if not isinstance(c.name, str) or mission_name_problem(c.name) is not None:
        return False
    return c.srp in (None, "") or (isinstance(c.srp, str) and mission_name_problem(c.srp) is None)


def _omstart_paper(c: s.OMSTARTPaper, p: Profile) -> bool:
    return _int_between(c.flag, 0, 3)


def _opos(c: s.OPOS, p: Profile) -> bool:
    return (_lat_lon(c.lat, c.lon) and _between(c.speed, 0, p.max_speed_kn)
            and (c.conductivity is None or _between(c.conductivity, 0, 100))
            and (c.temperature is None or _between(c.temperature, -5, 50)))


def _osd(c: s.OSD, p: Profile) -> bool:
    return all(x == "" or x in _OSD_LETTERS for x in c.letters)


def _ologl(c: s.OLOGL, p: Profile) -> bool:
    return (1 <= len(c.labels) <= 12
            and all(isinstance(x, str) and x.strip() != "" for x in c.labels))


def _ologd(c: s.OLOGD, p: Profile) -> bool:
    return 1 <= len(c.values) <= 12 and all(isinstance(x, str) for x in c.values)


def _orwset(c: s.ORWSET, p: Profile) -> bool:
    if c.setting not in SETTING_NAMES:
        return False
    if c.access == "R":
        return c.state is None and not c.values
    if c.access != "W" or not _int_between(c.state, 0, 1) or len(c.values) > 3:
        return False
    if c.setting == "SafetyAction":
        return len(c.values) == 1 and c.values[0] in SAFETY_ACTIONS
    return all(isinstance(v, str) for v in c.values)


def _odvl(c: s.ODVL, p: Profile) -> bool:
    return _between(c.x, -5, 5) and _between(c.y, -5, 5) and _timeout(c.timeout, p)


_CHECKS = {
    s.OMS: _oms, s.OMP: _omp, s.OJW: _ojw, s.OPK: _opk, s.OMW: _omw_ok, s.OMWClear: _omw_clear,
    s.OMSTOP: _omstop, s.OMLOAD: _omload, s.OMSTART: _omstart, s.OMSTARTPaper: _omstart_paper,
    s.OPOS: _opos, s.OSD: _osd, s.OLOGL: _ologl, s.OLOGD: _ologd, s.ORWSET: _orwset,
    s.ODVL: _odvl,
}


def field_error(cmd: s.Command, profile: Profile) -> Optional[int]:
    """The command's "incorrect values" error when a field is bad (RH-ACK-3), else ``None``."""
    check = _CHECKS.get(type(cmd))
    if check is None:
        return None
    try:
        ok = check(cmd, profile)
    except (TypeError, ValueError, ArithmeticError):
        ok = False
    return None if ok else cmd.ERR
