"""A tolerant summary of a wire log (docs/contracts.md, wire-log format 1) for the reports.

Reports show the implementation's identity *as seen on the wire*: the recorder's header, how
many records went each way, and the first ``$OSI`` the vehicle sent, with the vehicle name it
carries (field 18, RH-OUT-1) and its field count. This module never raises on a bad log: lines
that do not parse are counted, not fatal. It does not judge anything.
"""

from __future__ import annotations

from typing import Any

__all__ = ["summarise", "WIRE_LOG_TAG"]

WIRE_LOG_TAG = "# helmcheck wire-log 1"
_DIRECTIONS = (">", "<", ">~", "<~", "!")
_OSI_NAME_FIELD = 18  # RH-OUT-1: field 18 is the vehicle name


def _osi_fields(payload: str) -> list[str]:
    """The fields of an ``$OSI`` sentence (field 1 first), checksum removed."""
    body = payload[1:]
    star = body.rfind("*")
    if star >= 0:
        body = body[:star]
    return body.split(",")[1:]


def summarise(data: bytes | None) -> dict[str, Any]:
    """Counts, time span, header comments and the first vehicle ``$OSI`` of a wire log."""
    summary: dict[str, Any] = {
        "present": data is not None,
        "format_ok": False,
        "header": [],
        "records": 0,
        "by_dir": {d: 0 for d in _DIRECTIONS},
        "unparsed": 0,
        "first_t": None,
        "last_t": None,
        "first_osi": None,
        "osi_vehicle_name": None,
        "osi_fields": None,
    }
    if data is None:
        return summary
    text = data.decode("utf-8", errors="replace")
    lines = text.splitlines()
    summary["format_ok"] = bool(lines) and lines[0].strip() == WIRE_LOG_TAG
    for line in lines:
        if not line.strip():
            continue
        if line.startswith("#"):
            if len(summary["header"]) < 8:
                summary["header"].append(line[1:].strip())
            continue
        parts = line.split(" ", 2)
        if len(parts) < 2 or parts[1] not in _DIRECTIONS:
            summary["unparsed"] += 1
            continue
        try:
            t = float(parts[0])
        except ValueError:
            summary["unparsed"] += 1
            continue
        payload = parts[2] if len(parts) > 2 else ""
        summary["records"] += 1
        summary["by_dir"][parts[1]] += 1
        if summary["first_t"] is None:
            summary["first_t"] = t
        summary["last_t"] = t
        if summary["first_osi"] is None and parts[1] == "<" and payload.startswith("$OSI,"):
            fields = _osi_fields(payload)
            summary["first_osi"] = payload
            summary["osi_fields"] = len(fields)
            if len(fields) >= _OSI_NAME_FIELD:
                summary["osi_vehicle_name"] = fields[_OSI_NAME_FIELD - 1]
    return summary
