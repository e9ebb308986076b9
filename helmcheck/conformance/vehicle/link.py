"""The tester's side of the serial line (RH-FRM-9): send, collect timestamped replies, log.

:class:`TesterLink` wraps a client :class:`~helmcheck.conformance.transport.Link`. It owns:

* the one send function, :meth:`TesterLink.send`, where the bench-safety interlock
  (:mod:`.safety`) sees every byte before it leaves;
* the receive side: bytes are cut into lines by the grammar's framer (with a generous limit, so
  an overlong vehicle line is still seen and judged), every line is decoded against the
  profile, and each arrives as an :class:`Rx` with its wall time;
* the wire log (``helmcheck wire-log 1``) of both directions plus notes, and an in-memory
  transcript from which the judge cuts evidence excerpts;
* link-fault detection: :class:`LinkLost` when the device vanishes (EIO, closed socket);
  counters of valid and garbage input so the runner can tell "silent" and "garbage" apart.

Times are wall seconds since the link was opened (``t``); nothing here knows a time scale.
"""

from __future__ import annotations

import time
from collections import deque
from dataclasses import dataclass
from typing import IO, Optional

from ...grammar import Decoded, Discard, Framer, decode
from ...grammar.capture import FROM_VEHICLE, NOTE, TO_VEHICLE, WireLogWriter, escape, format_record
from ...profile import Profile
from ..transport import Link, LinkClosed
from .safety import BenchGuard, BenchSafetyRefused

__all__ = ["TesterLink", "Rx", "LinkLost", "Entry"]

#: Transcript entries kept in memory for evidence (the wire log on disk keeps everything).
_TRANSCRIPT_MAX = 200_000


class LinkLost(Exception):
    """The device or connection is gone (a link fault: INCONCLUSIVE, never FAIL)."""


@dataclass(frozen=True, slots=True)
class Rx:
    """One run of bytes from the vehicle: a line (``decoded`` set) or a discarded run."""

    t: float
    raw: bytes
    decoded: Optional[Decoded]  #: None for bytes the framer threw away (noise, torn, overlong)
    reason: str = ""

    @property
    def sentence(self):
        return self.decoded.sentence if self.decoded is not None else None

    @property
    def valid(self) -> bool:
        return self.decoded is not None and self.decoded.sentence is not None


@dataclass(frozen=True, slots=True)
class Entry:
    """A transcript line: wall time, wire-log direction, text (escaped as in the wire log)."""

    t: float
    dir: str
    line: str

    def as_evidence(self) -> dict:
        return {"t": round(self.t, 6), "dir": self.dir, "line": self.line}


class TesterLink:
    """A synchronous backseat link with a wire log. See the module docstring."""

    def __init__(self, link: Link, profile: Profile, *, log: Optional[IO[str]] = None,
                 meta: str = "", guard: Optional[BenchGuard] = None, clock=time.monotonic):
        self.link = link
        self.profile = profile
        self.clock = clock
        self.t0 = clock()
        self.guard = guard if guard is not None else BenchGuard(profile)
        self.framer = Framer(max(4096, 4 * profile.max_line_bytes))
        self.inbox: deque[Rx] = deque()
        self.transcript: deque[Entry] = deque(maxlen=_TRANSCRIPT_MAX)
        self.wire = WireLogWriter(log, meta) if log is not None else None
        self.bytes_in = 0
        self.bytes_out = 0
        self.valid_in = 0
        self.garbage_in = 0
        self.lost: Optional[str] = None
        self.per_byte = 10.0 / profile.baud if profile.baud else 0.0

    # ------------------------------------------------------------------ time
    def now(self) -> float:
        return self.clock() - self.t0

    def transmit_time(self, n: int) -> float:
        """Seconds the line needs for ``n`` bytes at the profile's baud (8N1)."""
        return n * self.per_byte

    # ------------------------------------------------------------------ log
    def _record(self, t: float, direction: str, raw: bytes = b"", note: str = "") -> None:
        text = format_record(t, direction, raw, note)
        _, d, line = (text.split(" ", 2) + [""])[:3]
        self.transcript.append(Entry(t, d, line))
        if self.wire is not None:
            if direction == NOTE:
                self.wire.note(t, note)
            else:
                self.wire.bytes(t, direction, raw)

    def note(self, text: str) -> float:
        t = self.now()
        self._record(t, NOTE, note=text)
        return t

    def excerpt(self, t0: float, t1: float, limit: int = 16) -> list[dict]:
        """Evidence: the transcript lines between ``t0`` and ``t1`` (the last ``limit`` of them)."""
        out = [e for e in self.transcript if t0 - 1e-6 <= e.t <= t1 + 1e-6]
        if len(out) > limit:
            out = out[:4] + out[-(limit - 4):]
        return [e.as_evidence() for e in out]

    # ------------------------------------------------------------------ send
    def send(self, raw: bytes) -> float:
        """Write ``raw`` (bench safety first); returns the wall time the last byte was handed over.

        Raises :class:`~.safety.BenchSafetyRefused` (nothing is sent) or :class:`LinkLost`.
        """
        if self.lost:
            raise LinkLost(self.lost)
        why = self.guard.problem(raw)
        if why:
            self.guard.refused += 1
            self.note(f"bench safety: not sent: {why}: {escape(raw)}")
            raise BenchSafetyRefused(why)
        self.pump(0)  # bytes that arrived before this send are timestamped before it
        t = self.now()
        self._record(t, TO_VEHICLE, raw)
        try:
            self.link.write_all(raw, timeout=max(2.0, 3 * self.transmit_time(len(raw))))
        except (LinkClosed, OSError) as e:
            self._lose(f"write failed: {e}")
        self.bytes_out += len(raw)
        return self.now()

    def _lose(self, why: str) -> None:
        if not self.lost:
            self.lost = why
            self.note(f"link lost: {why}")
            for ev in self.framer.close():
                self._add(Rx(self.now(), ev.raw, None, ev.reason))
        raise LinkLost(self.lost)

    # ------------------------------------------------------------------ receive
    def pump(self, timeout: float) -> bool:
        """Wait up to ``timeout`` seconds for bytes; frame them into :attr:`inbox`."""
        if self.lost:
            raise LinkLost(self.lost)
        try:
            if timeout > 0:
                self.link.wait_readable(timeout)
            events = self.link.poll()
        except LinkClosed as e:
            self._lose(str(e))
        except OSError as e:
            self._lose(f"read failed: {e}")
        got = False
        for ev in events:
            if ev.kind == "disconnect":
                self._lose(f"disconnected {ev.info}".strip())
            if ev.kind != "data" or not ev.data:
                continue
            t = self.now()
            self.bytes_in += len(ev.data)
            for fe in self.framer.feed(ev.data):
                got = True
                if isinstance(fe, Discard):
                    self._add(Rx(t, fe.raw, None, str(fe)))
                else:
                    self._add(Rx(t, fe.raw, decode(fe.raw, self.profile)))
        return got

    def _add(self, rx: Rx) -> None:
        self._record(rx.t, FROM_VEHICLE, rx.raw)
        if rx.valid:
            self.valid_in += 1
        else:
            self.garbage_in += 1
        self.inbox.append(rx)

    def next(self, deadline: float) -> Optional[Rx]:
        """The next received run, waiting until wall time ``deadline`` (link time) at most."""
        while not self.inbox:
            left = deadline - self.now()
            if left <= 0:
                self.pump(0)
                if not self.inbox:
                    return None
                break
            self.pump(min(left, 0.25))
        return self.inbox.popleft()

    def drain(self) -> list[Rx]:
        """Everything received so far, without waiting."""
        self.pump(0)
        out = list(self.inbox)
        self.inbox.clear()
        return out

    def sleep(self, seconds: float) -> None:
        """Wait ``seconds`` while still reading (replies keep their true arrival times)."""
        end = self.now() + seconds
        while True:
            left = end - self.now()
            if left <= 0:
                return
            self.pump(min(left, 0.25))

    def close(self) -> None:
        try:
            self.link.close()
        except Exception:  # noqa: BLE001
            pass
        if self.wire is not None:
            try:
                self.wire.close()
            except Exception:  # noqa: BLE001
                pass
            self.wire = None
