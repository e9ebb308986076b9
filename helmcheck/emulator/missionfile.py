"""Mission files and the emulator's mission directory (RH-MSN-1, RH-MSN-2, RH-RD-6).

This module owns the emulator's on-disk mission format and the catalogue that implements the
model's :class:`~helmcheck.model.missions.MissionCatalog` protocol over one or more
directories.

Mission file format, version 1
------------------------------
UTF-8 text. The first line is the header ``helmcheck-mission 1``. Every further line is blank,
a comment (first non-blank character ``#``), or one waypoint, in mission order (the first is
waypoint 0)::

    helmcheck-mission 1
    # lat        lon          depth_m  speed_kn  park_s
    41.521349   -71.320000    2.0      2.0       0
    41.522698   -71.320000    2.0      2.0       300

A line ``max_time_s <seconds>`` (at most one, anywhere after the header) gives the mission a
Maximum Operation Time safety rule: the vehicle raises ``Stl`` that many vehicle seconds after
the mission starts (RH-SAF-5; a bench vehicle's own rule that a certification can wait for,
profile ``violation_trigger = "mission-rule"``). The value is positive, at most 7 days.

Waypoint fields are separated by blanks or commas: latitude and longitude in signed decimal
degrees ([-90, 90], [-180, 180]), depth in metres from the surface ([0, 1000]), speed in knots
(> 0, at most 10), and the mission park time in seconds (>= 0; 0 = no park). A trailing
``# comment`` on a waypoint line is allowed. A file needs at least one waypoint and at most
10 000, and at most 1 MiB. Anything else makes the file *unparseable*: the model answers
err 3 (RH-RD-6). A file that exists but cannot be read (permissions, not a regular file, not
UTF-8) is *unreadable* (also err 3).

The catalogue (RH-MSN-1)
------------------------
:class:`DirectoryCatalog` looks a name up in its directories, first to last (so a directory
given with ``--missions`` overrides the built-in one). It never opens a file outside them:
names failing :func:`~helmcheck.model.missions.mission_name_problem` (absolute, drive letter,
``..``, empty component, control characters) are missing without touching the file system,
and a name whose resolved path (symbolic links followed) leaves the directory is missing too.
Only regular files are opened (a FIFO or device in the directory is unreadable, never opened).
Files are read at every look-up, so a mission edited on disk is seen by the next
``$OMLOAD``/``$OMSTART``.
"""

from __future__ import annotations

import os
import re
import stat
from importlib import resources
from pathlib import Path
from typing import Iterable, Optional, Union

from ..model.missions import (BadMission, LookupResult, MissingMission, Mission, Waypoint,
                               mission_name_problem, normalise_name)

__all__ = ["HEADER", "MissionFileError", "parse_mission", "format_mission", "DirectoryCatalog",
           "builtin_dir", "MAX_BYTES", "MAX_WAYPOINTS"]

HEADER = "helmcheck-mission 1"
MAX_BYTES = 1 << 20
MAX_WAYPOINTS = 10_000
_SPLIT = re.compile(r"[\s,]+")
_NUMBER = re.compile(r"^[+-]?(\d+(\.\d*)?|\.\d+)([eE][+-]?\d+)?$")


class MissionFileError(ValueError):
    """A mission file that does not follow the format; names the line."""


def _num(text: str, what: str, lineno: int) -> float:
    if not _NUMBER.match(text):
        raise MissionFileError(f"line {lineno}: {what} {text!r} is not a number")
    return float(text)


def parse_mission(text: str, name: str) -> Mission:
    """The mission in ``text``; raises :class:`MissionFileError` naming the bad line."""
    lines = text.splitlines()
    if not lines or lines[0].strip() != HEADER:
        raise MissionFileError(f"line 1: header must be {HEADER!r}")
    wps: list[Waypoint] = []
    max_time: Optional[float] = None
    for lineno, line in enumerate(lines[1:], 2):
        body = line.split("#", 1)[0].strip()
        if not body:
            continue
        parts = [p for p in _SPLIT.split(body) if p]
        if parts[0] == "max_time_s":
            if len(parts) != 2:
                raise MissionFileError(f"line {lineno}: want 'max_time_s <seconds>'")
            if max_time is not None:
                raise MissionFileError(f"line {lineno}: a second max_time_s")
            max_time = _num(parts[1], "max_time_s", lineno)
            if not 0 < max_time <= 7 * 86400:
                raise MissionFileError(f"line {lineno}: max_time_s {max_time} outside (0, 604800] s")
            continue
        if len(parts) != 5:
            raise MissionFileError(f"line {lineno}: want 5 fields 'lat lon depth_m speed_kn park_s', "
                                   f"got {len(parts)}")
        lat = _num(parts[0], "latitude", lineno)
        lon = _num(parts[1], "longitude", lineno)
        depth = _num(parts[2], "depth", lineno)
        speed = _num(parts[3], "speed", lineno)
        park = _num(parts[4], "park time", lineno)
        if not -90 <= lat <= 90:
            raise MissionFileError(f"line {lineno}: latitude {lat} outside [-90, 90]")
        if not -180 <= lon <= 180:
            raise MissionFileError(f"line {lineno}: longitude {lon} outside [-180, 180]")
        if not 0 <= depth <= 1000:
            raise MissionFileError(f"line {lineno}: depth {depth} outside [0, 1000] m")
        if not 0 < speed <= 10:
            raise MissionFileError(f"line {lineno}: speed {speed} outside (0, 10] kn")
        if not 0 <= park <= 7 * 86400:
            raise MissionFileError(f"line {lineno}: park time {park} outside [0, 604800] s")
        wps.append(Waypoint(lat, lon, depth, speed, park))
        if len(wps) > MAX_WAYPOINTS:
            raise MissionFileError(f"line {lineno}: more than {MAX_WAYPOINTS} waypoints")
    if not wps:
        raise MissionFileError("no waypoints")
    return Mission(name, tuple(wps), max_time_s=max_time)


def format_mission(mission: Mission) -> str:
    """The mission as file text (``parse_mission(format_mission(m), m.name) == m``)."""
    out = [HEADER, "# lat        lon          depth_m  speed_kn  park_s"]
    if mission.max_time_s is not None:
        out.append(f"max_time_s {mission.max_time_s!r}")
    for w in mission.waypoints:
        out.append(f"{w.lat!r} {w.lon!r} {w.depth!r} {w.speed!r} {w.park_s!r}")
    return "\n".join(out) + "\n"


def builtin_dir() -> Path:
    """The directory of the built-in missions (``conformance.mis``, ``short.mis``, ``srp.mis``)."""
    return Path(str(resources.files("helmcheck.emulator").joinpath("missions")))


class DirectoryCatalog:
    """Mission look-up over directories, first match wins; see the module docstring (RH-MSN-1)."""

    def __init__(self, dirs: Iterable[Union[str, Path]]):
        self.dirs: tuple[Path, ...] = tuple(Path(d).resolve() for d in dirs)

    def lookup(self, name: str) -> LookupResult:
        if not isinstance(name, str) or mission_name_problem(name) is not None:
            return MissingMission(str(name))
        key = normalise_name(name)
        for d in self.dirs:
            found = self._lookup_in(d, key)
            if found is not None:
                return found
        return MissingMission(name)

    def _lookup_in(self, d: Path, key: str) -> Union[Mission, BadMission, None]:
        candidate = d.joinpath(*key.split("/"))
        try:
            resolved = candidate.resolve(strict=True)
        except (OSError, RuntimeError):
            return None  # missing (or a symlink loop)
        if resolved != d and d not in resolved.parents:
            return None  # the name escapes the directory through a link: never opened
        try:
            st = os.stat(resolved)
        except OSError:
            return None
        if not stat.S_ISREG(st.st_mode):
            return BadMission(key, "unreadable")
        if st.st_size > MAX_BYTES:
            return BadMission(key, "unparseable")
        try:
            fd = os.open(resolved, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOFOLLOW", 0))
        except OSError:
            return BadMission(key, "unreadable")
        try:
            if not stat.S_ISREG(os.fstat(fd).st_mode):
                return BadMission(key, "unreadable")
            with os.fdopen(fd, "rb") as f:
                fd = -1
                raw = f.read(MAX_BYTES + 1)
        except OSError:
            return BadMission(key, "unreadable")
        finally:
            if fd >= 0:
                os.close(fd)
        if len(raw) > MAX_BYTES:
            return BadMission(key, "unparseable")
        try:
            text = raw.decode("utf-8")
        except UnicodeDecodeError:
            return BadMission(key, "unreadable")
        try:
            return parse_mission(text, key)
        except (MissionFileError, ValueError):
            return BadMission(key, "unparseable")

    def names(self) -> list[str]:
        """Mission files directly in the directories (for display)."""
        seen: dict[str, None] = {}
        for d in self.dirs:
            try:
                for p in sorted(d.iterdir()):
                    if p.suffix == ".mis" and p.is_file():
                        seen.setdefault(p.name, None)
            except OSError:
                continue
        return list(seen)
