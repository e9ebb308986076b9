"""What the requests asked of the vehicle's output line: :class:`OutputLoad`, kept by the outbox.

A backseat's requests can ask for more reply bytes than the line carries (10 bits a byte at the
baud): ten ``$OSD,G,C,S,P`` a second ask for about 3.2 kB/s of replies, a 19200-baud line drains
1.92 kB/s. What the vehicle does then is a reading the profile leaves open (``overrun`` in
:mod:`.freedoms`: queue and lag, or drop); either way this meter says how far the line was
over-asked, so a report can name it:

* :meth:`OutputLoad.asked` — the reply bytes one request asked for at a wall time (queued or
  dropped), by the request's sentence ID;
* :meth:`OutputLoad.dropped` — reply bytes not sent (the ``drop`` reading, or the outbox's cap);
* :meth:`OutputLoad.lagged` — how long a reply waited in the queue before its first byte left;
* :meth:`OutputLoad.summary` — the worst :data:`WINDOW_S`-second window's demand against the
  line's capacity, the longest wait, what was dropped; :func:`describe` puts it in one sentence.

Pure: no clock, no I/O; memory is one counter per wall second.
"""

from __future__ import annotations

import math
from collections import Counter
from typing import Optional

__all__ = ["OutputLoad", "WINDOW_S", "describe"]

#: Seconds over which the demand on the line is averaged (a burst shorter than this is what a
#: queue is for; a rate sustained this long is an overrun).
WINDOW_S = 10


class OutputLoad:
    """The demand on the vehicle's output line (module docstring)."""

    def __init__(self, baud: int):
        self.baud = baud
        self._per_s: Counter[int] = Counter()  #: wall second -> reply bytes asked for
        self._by_id: Counter[str] = Counter()  #: request ID -> reply bytes asked for
        self.asked_bytes = 0
        self.dropped_bytes = 0
        self.dropped_sets = 0
        self.first_drop: Optional[float] = None
        self.max_lag_s = 0.0
        self.max_lag_at: Optional[float] = None
        self._first: Optional[int] = None

    @property
    def capacity(self) -> float:
        """Bytes a second the line carries (8N1: 10 bits a byte); infinite when unpaced."""
        return self.baud / 10.0 if self.baud else math.inf

    def asked(self, t: float, nbytes: int, sid: str = "") -> None:
        sec = int(math.floor(t))
        if self._first is None:
            self._first = sec
        self._per_s[sec] += nbytes
        self._by_id[sid or "?"] += nbytes
        self.asked_bytes += nbytes

    def dropped(self, t: float, nbytes: int) -> None:
        self.dropped_bytes += nbytes
        self.dropped_sets += 1
        if self.first_drop is None:
            self.first_drop = t

    def lagged(self, t: float, lag: float) -> None:
        if lag > self.max_lag_s:
            self.max_lag_s, self.max_lag_at = lag, t

    def recent_rate(self, t: float) -> float:
        """Bytes a second asked over the last :data:`WINDOW_S` seconds up to ``t``: a demand the line
        cannot carry for that long is an overrun, a burst it carries in that time is not."""
        if self._first is None:
            return 0.0
        sec = int(math.floor(t))
        lo = max(self._first, sec - WINDOW_S + 1)
        return sum(self._per_s.get(s, 0) for s in range(lo, sec + 1)) / WINDOW_S

    def worst_rate(self) -> tuple[float, Optional[int]]:
        """The highest demand (bytes a second) over any :data:`WINDOW_S` whole seconds, and the
        second that window starts at (a record shorter than that is averaged over the window too:
        what the line carries in that time is no overrun)."""
        if not self._per_s:
            return 0.0, None
        lo, hi = min(self._per_s), max(self._per_s)
        span = min(WINDOW_S, hi - lo + 1)
        best, at = -1.0, None
        total = sum(self._per_s.get(s, 0) for s in range(lo, lo + span))
        for start in range(lo, hi - span + 2):
            if start > lo:
                total += self._per_s.get(start + span - 1, 0) - self._per_s.get(start - 1, 0)
            if total > best:
                best, at = float(total), start
        return best / WINDOW_S, at

    def main_request(self) -> str:
        """The request ID that asked for most of the replies ('' if none)."""
        if not self._by_id:
            return ""
        sid, n = self._by_id.most_common(1)[0]
        return sid if n * 2 >= self.asked_bytes else ""

    def summary(self, *, ack_window_s: float = 1.0) -> Optional[dict]:
        """The overrun, or None when the line carried what was asked: the demand of the worst
        window was over the line's capacity, or something was dropped. (A reply that waited
        longer than ``ack_window_s`` behind a burst is no overrun: the queue is for bursts.)"""
        rate, at = self.worst_rate()
        over = rate > self.capacity
        if not (over or self.dropped_bytes):
            return None
        return {"asked_Bps": round(rate, 1), "window_start_s": at, "line_Bps": self.capacity,
                "baud": self.baud, "max_lag_s": round(self.max_lag_s, 3),
                "max_lag_at_s": None if self.max_lag_at is None else round(self.max_lag_at, 3),
                "dropped_bytes": self.dropped_bytes, "dropped_sets": self.dropped_sets,
                "first_drop_s": None if self.first_drop is None else round(self.first_drop, 3),
                "by": self.main_request(), "over_capacity": over}


def _kb(n: float) -> str:
    return f"{n / 1000:.2f} kB" if n < 10_000 else f"{n / 1000:.1f} kB"


def describe(s: dict, subject: str = "the backseat") -> str:
    """One sentence for a summary of :meth:`OutputLoad.summary`: "the backseat's $OSD polls asked
    for 3.20 kB/s of replies on a 1.92 kB/s line (19200 baud); replies lagged up to 16.3 s and
    6.7 kB were dropped"."""
    who = f"{subject}'s ${s['by']} polls" if s.get("by") == "OSD" else (
        f"{subject}'s ${s['by']} requests" if s.get("by") else f"{subject}'s requests")
    line = f"{s['line_Bps'] / 1000:.2f} kB/s line ({s['baud']} baud)"
    text = f"{who} asked for {s['asked_Bps'] / 1000:.2f} kB/s of replies on a {line}"
    if not s.get("over_capacity"):
        text = f"{who} asked for more replies at once than the {line} carries in time"
    parts = []
    if s["max_lag_s"] > 0.0005:
        parts.append(f"replies lagged up to {s['max_lag_s']:.1f} s")
    if s["dropped_bytes"]:
        parts.append(f"{_kb(s['dropped_bytes'])} of replies ({s['dropped_sets']} request(s)) were dropped")
    else:
        parts.append("no reply was dropped")
    return text + "; " + " and ".join(parts)
