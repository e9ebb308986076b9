"""Data sentences a vehicle sends for ``$OSD`` (RH-OSD-1, RH-OUT-1..3).

``$OSI`` is built from the model's state (mode, next waypoint, distance to the navigation
target, error state, park time, mission name, SRP flag, actuators) plus the
:class:`~helmcheck.model.plant.PlantSnapshot`; the other sentences (``$C``, ``$GPRMC``, ``$OPI``,
``$DVL``, ``$OYSI``, ``$OCTD``, ``$OINS``) from the snapshot alone. Every emitted number is
clamped into its physical range (RH-OUT-3) and written with a fixed number of decimals.

Units (RH-RD-14): depth-like fields (``$C`` D, ``$OSI`` fields 9 and 15, ``$OCTD``/``$OINS``
depth) are metres for ``depth_unit = "m"`` and feet otherwise; ``$OSI`` field 14 is true heading
(magnetic + declination), ``$C`` shows magnetic heading. ``$OSI`` field 13 is hours.

Field count (RH-OUT-1): ``profile.osi_fields`` (21 for rh5). For rh4 and older (11–17 fields)
field 16 is the SRP flag, not the battery (public-evidence §2.2.1). Fields 19–21 (rh5,
unidentified) are emitted as ``0.0,False,False``.

:class:`DataCache` memoises the snapshot-only parts, since ``$OSD`` is the hottest command.
"""

from __future__ import annotations

import math
from datetime import datetime, timezone
from decimal import Decimal
from typing import Optional

from ..grammar import sentences as s
from ..profile import Profile
from .plant import PlantSnapshot

__all__ = ["DataCache", "CLASS_OF_LETTER", "dec", "park_seconds"]

_FT = 0.3048


def dec(x: float, places: int) -> Decimal:
    """``x`` as a Decimal with exactly ``places`` decimals (``-0`` written as ``0``)."""
    text = f"{x:.{places}f}"
    if text.startswith("-") and float(text) == 0.0:
        text = text[1:]
    return Decimal(text)


def _clamp(x: float, lo: float, hi: float) -> float:
    if x != x:
        return lo
    return lo if x < lo else hi if x > hi else x


def _heading(x: float) -> Decimal:
    h = round(x % 360.0, 1)
    if h >= 360.0:
        h = 0.0
    return dec(h, 1)


def _ddmm(value: float, width: int) -> str:
    v = abs(value)
    deg = int(v)
    minutes = (v - deg) * 60.0
    if round(minutes, 4) >= 60.0:
        deg, minutes = deg + 1, 0.0
    return f"{deg:0{width}d}{minutes:07.4f}"


class DataCache:
    """Data sentences for one snapshot, built once each (``$GPRMC`` once per fix state)."""

    __slots__ = ("profile", "snap", "_cache", "_osi_base", "_depth_factor")

    def __init__(self, profile: Profile, snap: PlantSnapshot) -> None:
        self.profile = profile
        self.snap = snap
        self._cache: dict[object, s.Reply] = {}
        self._osi_base: Optional[dict] = None
        self._depth_factor = 1.0 if profile.depth_unit == "m" else 1.0 / _FT

    def _depth(self, metres: float) -> Decimal:
        return dec(max(0.0, metres) * self._depth_factor, 2)

    # -------------------------------------------------------------- snapshot-only sentences

    def sentence(self, letter: str, fix: bool) -> s.Reply:
        """The reply for one ``$OSD`` letter other than ``S`` (RH-OSD-1, RH-OUT-2)."""
        key = (letter, fix) if letter == "G" else letter
        got = self._cache.get(key)
        if got is None:
            got = self._cache[key] = _BUILDERS[letter](self, fix)
        return got

    def _compass(self, fix: bool) -> s.Compass:
        p = self.snap
        return s.Compass(heading=_heading(p.heading), pitch=dec(_clamp(p.pitch, -90, 90), 2),
                         roll=dec(_clamp(p.roll, -90, 90), 2), temperature=dec(p.compass_temp, 1),
                         depth=self._depth(p.depth_m))

    def _gprmc(self, fix: bool) -> s.GPRMC:
        p = self.snap
        when = datetime.fromtimestamp(p.utc, tz=timezone.utc)
        lat = _clamp(p.lat, -90, 90)
        lon = _clamp(p.lon, -180, 180)
        true_heading = (p.heading + p.declination) % 360.0
        return s.GPRMC(
            time=when.strftime("%H%M%S.") + f"{when.microsecond // 10000:02d}",
            status="A" if fix else "V",
            lat=_ddmm(lat, 2), ns="N" if lat >= 0 else "S",
            lon=_ddmm(lon, 3), ew="E" if lon >= 0 else "W",
            sog=f"{max(0.0, p.speed_kn):.1f}", cog=f"{round(true_heading, 1) % 360.0:.1f}",
            date=when.strftime("%d%m%y"),
            magvar=f"{abs(p.declination):.1f}", magvar_ew="E" if p.declination >= 0 else "W",
            mode="A" if fix else "N")

    def _opi(self, fix: bool) -> s.OPI:
        p = self.snap
        return s.OPI(percent=dec(_clamp(p.battery_pct, 0, 100), 1),
                     remaining_wh=dec(max(0.0, p.remaining_wh), 1), watts=dec(p.watts, 1),
                     volts=dec(max(0.0, p.volts), 2), amps=dec(p.amps, 2),
                     minutes_left=dec(max(0.0, p.minutes), 0), battery_state=p.battery_state,
                     leak=1 if p.leak else 0)

    def _dvl(self, fix: bool) -> s.DVL:
        p = self.snap
        return s.DVL(vx=dec(p.vx, 3), vy=dec(p.vy, 3), vz=dec(p.vz, 3), x_dist=dec(p.x_dist, 2),
                     y_dist=dec(p.y_dist, 2), dfs=dec(max(0.0, p.depth_m), 2),
                     altitude=dec(max(0.0, p.altitude_m), 2))

    def _ysi(self, fix: bool) -> s.OYSI:
        return s.OYSI(readings=tuple((name, dec(v, 2)) for name, v in self.snap.ysi))

    def _ctd(self, fix: bool) -> s.OCTD:
        p = self.snap
        return s.OCTD(conductivity=dec(_clamp(p.conductivity, 0, 100), 2),
                      temperature=dec(p.temperature, 2), depth=self._depth(p.depth_m))

    def _ins(self, fix: bool) -> s.OINS:
        p = self.snap
        return s.OINS(lat=dec(_clamp(p.lat, -90, 90), 8), lon=dec(_clamp(p.lon, -180, 180), 8),
                      depth=self._depth(p.depth_m), heading=_heading(p.heading + p.declination))

    # -------------------------------------------------------------------------------- $OSI

    def osi(self, *, actuators: str, mode: str, next_waypoint: int, distance: float,
            error_state: str, park_time: int, mission_name: str, srp_active: bool) -> s.OSI:
        """``$OSI`` with ``profile.osi_fields`` fields (RH-OUT-1)."""
        b = self._osi_base
        if b is None:
            p = self.snap
            b = self._osi_base = {
                "lat": dec(_clamp(p.lat, -90, 90), 8), "lon": dec(_clamp(p.lon, -180, 180), 8),
                "speed": dec(max(0.0, p.speed_kn), 2),
                "altimeter": self._depth(p.altitude_m),
                "declination": dec(p.declination, 4),
                "remaining_time": dec(max(0.0, p.remaining_mission_h), 4),
                "true_heading": _heading(p.heading + p.declination),
                "depth": self._depth(p.depth_m),
                "battery": f"{_clamp(p.battery_pct, 0, 100):.1f}",
            }
        n = self.profile.osi_fields
        srp = "True" if srp_active else "False"
        rh5 = self.profile.protocol == "rh5"
        tail = [mission_name, b["remaining_time"], b["true_heading"], b["depth"],
                b["battery"] if rh5 else srp, srp, self.profile.vehicle_name]
        opt: list = [None] * 7
        for i in range(min(7, max(0, n - 11))):
            opt[i] = tail[i]
        reserved = ("0.0", "False", "False")[:max(0, n - 18)]
        return s.OSI(actuators, mode, next_waypoint, b["lat"], b["lon"], b["speed"],
                     dec(max(0.0, distance), 2), error_state, b["altimeter"], park_time,
                     b["declination"], opt[0], opt[1], opt[2], opt[3], opt[4], opt[5], opt[6],
                     reserved)


_BUILDERS = {"C": DataCache._compass, "G": DataCache._gprmc, "P": DataCache._opi,
             "D": DataCache._dvl, "Y": DataCache._ysi, "T": DataCache._ctd, "I": DataCache._ins}
#: The sentence class each ``$OSD`` letter is answered with (RH-OSD-1).
CLASS_OF_LETTER: dict[str, type] = {"S": s.OSI, "C": s.Compass, "G": s.GPRMC, "P": s.OPI, "D": s.DVL,
                                    "Y": s.OYSI, "T": s.OCTD, "I": s.OINS}


def park_seconds(remaining: Optional[float]) -> int:
    """``$OSI`` field 10 value: remaining park seconds rounded up, ``P0`` when none (RH-RD-5)."""
    if remaining is None or remaining <= 0:
        return 0
    return int(math.ceil(remaining - 1e-9))
