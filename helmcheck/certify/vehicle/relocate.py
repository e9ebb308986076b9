"""A replay's positions moved to where the vehicle begins it.

The exploration drives one vehicle through many sequences, and the vehicle moves: a sequence's
``$OPOS``, ``$OPK`` and ``$OMW`` positions are drawn relative to where the vehicle was when the
sequence began (:func:`.interpreter.context`: its own position, 100 m north, 1.1 km north, 15 m
north, …). Re-driven where the vehicle is somewhere else — a fresh vehicle at its start point, or
the same one after the sequence moved it — the same bytes would ask for other things (a park 30 km
off is refused for its distance; an ``$OPOS`` at the vehicle's present position shows nothing).
So a replay carries the position it began at (``origin``). A re-drive first drives the vehicle
back there when it can (more than 1 m off, near enough, ``$OMW`` claimed:
:func:`.replay._return`; what the steps do against the mission, a waypoint reached or not,
depends on where the vehicle is), and :func:`shift_line` moves every position a line gives by
what is left of the difference: the line asks, relative to the vehicle, what it asked when
recorded.

Only lines a vehicle reads as written are moved: a well-framed sentence with a right checksum
whose position fields are decimal numbers within range (a value drawn at or past a range's edge,
``91`` or ``181``, is an edge, not a position, and stays; a line mutated in its framing or
checksum stays byte for byte). Each moved value keeps its number of decimals, at least six (about
0.1 m); the checksum is written afresh.
"""

from __future__ import annotations

import re

from ...grammar import checksum_hex

__all__ = ["shift_line", "POSITION_FIELDS"]

#: Sentence ID → the indexes (after the ID) of its latitude and longitude fields; ``$OMW`` with a
#: clear keyword first (``$OMW,CLEAR,lat,lon,…``) has them one further on.
POSITION_FIELDS = {"OPOS": (0, 1), "OPK": (0, 1), "OMW": (0, 1)}

_LINE = re.compile(rb"^\$([A-Z]+),([^*\r\n]*)\*([0-9A-F]{2})\r\n$")
_DECIMAL = re.compile(r"^-?\d+\.(\d+)$")


def _moved(value: str, by: float, bound: float) -> str:
    m = _DECIMAL.match(value)
    if m is None or abs(float(value)) > bound:
        return value
    return f"{float(value) + by:.{max(6, len(m.group(1)))}f}"  # at least 0.1 m


def _one(line: bytes, dlat: float, dlon: float) -> bytes:
    m = _LINE.match(line)
    if m is None or m.group(1).decode() not in POSITION_FIELDS:
        return line
    sid, body = m.group(1).decode(), m.group(2).decode("ascii", "replace")
    if checksum_hex(f"{sid},{body}") != m.group(3).decode():
        return line
    fields = body.split(",")
    i, j = POSITION_FIELDS[sid]
    if sid == "OMW" and fields and _DECIMAL.match(fields[0]) is None and len(fields) > 2:
        i, j = i + 1, j + 1
    if j >= len(fields):
        return line
    fields[i], fields[j] = _moved(fields[i], dlat, 90.0), _moved(fields[j], dlon, 180.0)
    new = f"{sid},{','.join(fields)}"
    return f"${new}*{checksum_hex(new)}\r\n".encode()


def shift_line(raw: bytes, dlat: float, dlon: float) -> bytes:
    """``raw`` (one line, or lines written back to back) with every position moved by ``dlat``,
    ``dlon`` degrees (module docstring)."""
    if not dlat and not dlon:
        return raw
    parts = raw.split(b"\r\n")
    out = [_one(p + b"\r\n", dlat, dlon)[:-2] if k < len(parts) - 1 else p for k, p in enumerate(parts)]
    return b"\r\n".join(out)
