"""What the emulator writes down: the main log, a CSV of the accepted ``$OLOGD`` rows under the
``$OLOGL`` labels (RH-LOG-1, RH-LOG-2), the live view's history entries, and the text they show
for a sentence sent (``$ACK`` accepted or refused, RH-ACK-1) and for a plant or model event.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass, fields as dc_fields
from typing import IO, Any, Optional

__all__ = ["HistoryEntry", "MainLog", "reply_label", "event_text"]


@dataclass(frozen=True, slots=True)
class HistoryEntry:
    """One line for a live view: wall seconds since start, direction, text, verdict."""

    t: float
    direction: str  #: ">" in, "<" out, "!" note
    text: str
    verdict: str = ""


class MainLog:
    """The vehicle's main log as CSV: a header row whenever the ``$OLOGL`` labels change,
    then one row per accepted ``$OLOGD`` (RH-LOG-1, RH-LOG-2)."""

    def __init__(self, stream: IO[str]):
        self._f = stream
        self._w = csv.writer(stream, lineterminator="\n")
        self._labels: Optional[tuple[str, ...]] = None

    def write(self, vehicle_t: float, utc: float, lat: float, lon: float, depth: float,
              labels: tuple[str, ...], values: tuple[str, ...]) -> None:
        if labels != self._labels:
            self._w.writerow(["vehicle_time_s", "utc", "lat", "lon", "depth_m", *labels])
            self._labels = labels
        self._w.writerow([f"{vehicle_t:.3f}", f"{utc:.3f}", f"{lat:.8f}", f"{lon:.8f}",
                          f"{depth:.2f}", *values])
        self._f.flush()

    def close(self) -> None:
        self._f.close()


def reply_label(raw: bytes) -> str:
    """What a live view says about a sentence the vehicle sent: an ``$ACK`` is ``accepted``
    (status 0) or ``refused (err N)`` (status 1, RH-ACK-1); other sentences say nothing."""
    if not raw.startswith(b"$ACK,"):
        return ""
    fields = raw[5:].split(b"*", 1)[0].split(b",")
    if len(fields) < 3:
        return ""
    if fields[1] == b"0":
        return "accepted"
    return f"refused (err {fields[2].decode('ascii', 'replace')})"


def event_text(e: Any) -> str:
    parts = [f"{f.name}={getattr(e, f.name)!r}" for f in dc_fields(e) if f.name != "at"]
    clause = getattr(e, "clause", "")
    inner = ", ".join(parts)
    return f"{type(e).__name__}({inner})" + (f" [{clause}]" if clause else "")
