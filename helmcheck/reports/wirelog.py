"""A tolerant summary of a wire log (docs/contracts.md, wire-log format 1) for the reports.

Reports show the implementation's identity *as seen on the wire*: the recorder's header, how
many records went each way, and the first ``$OSI`` the vehicle sent, with the vehicle name it
carries (field 18, RH-OUT-1) and its field count. The log is read by the one wire-log reader
(:func:`helmcheck.grammar.wirelog.read_wire_log`), which never raises on a bad log: lines that
are not records are counted, not fatal. This module does not judge anything.
"""

from __future__ import annotations

import io
from typing import Any

from ..grammar.wirelog import (DIRECTIONS, FROM_VEHICLE, HEADER, NOTE, UNREADABLE, column, escape, is_line,
                               read_wire_log)

__all__ = ["summarise"]

_OSI_NAME_FIELD = 18  # RH-OUT-1: field 18 is the vehicle name


def _osi_fields(payload: str) -> list[str]:
    """The fields of an ``$OSI`` sentence (field 1 first), checksum removed."""
    body = payload[1:]
    star = body.rfind("*")
    if star >= 0:
        body = body[:star]
    return body.split(",")[1:]


def summarise(data: bytes | None) -> dict[str, Any]:
    """Counts (``by_dir``: per direction column as written), time span, header comments and the
    first vehicle ``$OSI`` of a wire log."""
    summary: dict[str, Any] = {
        "present": data is not None,
        "format_ok": False,
        "header": [],
        "records": 0,
        "by_dir": {d: 0 for d in DIRECTIONS},
        "unparsed": 0,
        "first_t": None,
        "last_t": None,
        "first_osi": None,
        "osi_vehicle_name": None,
        "osi_fields": None,
    }
    if data is None:
        return summary
    summary["format_ok"] = data.split(b"\n", 1)[0].strip() == HEADER.encode()
    header, by_dir = summary["header"], summary["by_dir"]

    def comment(text: str) -> None:
        if len(header) < 8:
            header.append(text[1:].strip())

    records = unparsed = 0
    osi: bytes | None = None
    for rec in read_wire_log(io.BytesIO(data), comment=comment):
        d = rec.dir
        if d == UNREADABLE:
            unparsed += 1
            continue
        if not records:
            summary["first_t"] = rec.t
        records += 1
        summary["last_t"] = rec.t
        if d == NOTE:
            by_dir[NOTE] += 1
            continue
        by_dir[column(d, rec.data)] += 1
        if osi is None and d == FROM_VEHICLE and rec.data.startswith(b"$OSI,") and is_line(rec.data):
            osi = rec.data[:-2]
    summary["records"], summary["unparsed"] = records, unparsed
    if osi is not None:
        payload = escape(osi)
        fields = _osi_fields(payload)
        summary["first_osi"] = payload
        summary["osi_fields"] = len(fields)
        if len(fields) >= _OSI_NAME_FIELD:
            summary["osi_vehicle_name"] = fields[_OSI_NAME_FIELD - 1]
    return summary
