"""The tester's side of the serial line (RH-FRM-9): send, receive, record — and nothing else.

:class:`TesterLink` wraps a client :class:`~helmcheck.line.transport.Link`. It owns:

* the one send function, :meth:`TesterLink.send`, where the bench-safety interlock
  (:mod:`.safety`) sees every byte before it leaves;
* the receive side: bytes are cut into runs by a framer with a generous limit (so a wire-log
  record is one line, and an overlong vehicle line still arrives whole for the judge) and each
  arrives as an :class:`Rx` with its wall time;
* recording: every byte each way, and every note, goes through the run's
  :class:`~helmcheck.line.recorder.Recorder` — which writes the wire log and feeds the
  judges — stamped *before* a write and *after* a read, so the times bracket what the vehicle
  did;
* link-fault detection: :class:`~.flow.LinkLost` when the device vanishes (EIO, closed socket).

Times are wall seconds since the link was opened; nothing here knows a time scale or a clause.
"""

from __future__ import annotations

import time
from collections import deque
from dataclasses import dataclass
from typing import Optional

from ...grammar import Discard, Framer
from ...grammar.wirelog import FROM_VEHICLE, TO_VEHICLE, escape, transmit_time
from ...profile import Profile
from ...line.recorder import Recorder
from ...signals import deferred
from ...line.transport import Link, LinkClosed
from .flow import LinkLost
from .safety import BenchGuard, BenchSafetyRefused

__all__ = ["TesterLink", "Rx", "LinkLost"]


@dataclass(frozen=True, slots=True)
class Rx:
    """One run of bytes from the vehicle: a line, or bytes the framer set aside."""

    t: float
    raw: bytes
    line: bool  #: a run from ``$`` to LF within the limit


class TesterLink:
    """A synchronous backseat link that records everything. See the module docstring."""

    def __init__(self, link: Link, profile: Profile, recorder: Recorder, *,
                 guard: Optional[BenchGuard] = None, clock=time.monotonic, start_at: float = 0.0):
        self.link = link
        self.profile = profile
        self.rec = recorder
        self.clock = clock
        self.t0 = clock() - start_at  #: ``start_at``: the record's time now (a resumed run goes on)
        self.guard = guard if guard is not None else BenchGuard(profile)
        self.framer = Framer(max(4096, 4 * profile.max_line_bytes))
        self.inbox: deque[Rx] = deque()
        self.bytes_in = 0
        self.bytes_out = 0
        self.lines_in = 0
        self.lost: Optional[str] = None
        self.lost_t: Optional[float] = None  #: the record's time of the ``link lost`` note
        self.per_byte = transmit_time(1, profile.baud)

    # ------------------------------------------------------------------ time
    def now(self) -> float:
        return self.clock() - self.t0

    def transmit_time(self, n: int) -> float:
        """Seconds the line needs for ``n`` bytes at the profile's baud (8N1)."""
        return n * self.per_byte

    def note(self, text: str) -> float:
        return self.rec.note(self.now(), text)

    # ------------------------------------------------------------------ send
    def send(self, raw: bytes) -> float:
        """Write ``raw`` (bench safety first); returns the time it was recorded with.

        Raises :class:`~.safety.BenchSafetyRefused` (nothing is sent) or :class:`LinkLost`.
        """
        if self.lost:
            raise LinkLost(self.lost)
        why = self.guard.problem(raw)
        if why:
            self.guard.refused += 1
            self.note(f"bench safety: not sent: {why}: {escape(raw)}")
            raise BenchSafetyRefused(why)
        self.pump(0)  # what arrived before this send is recorded before it
        # Stamped before the write, recorded (and judged) after it: the observer's own work on
        # the line must not sit between the stamp and the bytes leaving, or it would widen every
        # round trip the judge measures (RH-TIM-1's slack) by the tester's CPU time.
        t0 = self.now()
        failed = None
        # the write and its record are one step: an interruption (Ctrl-C, SIGTERM) that came while
        # the bytes left raises after they are recorded, never between (the vehicle's answer to a
        # line the record lacks would be judged an answer to nothing)
        with deferred():
            try:
                self.link.write_all(raw, timeout=max(2.0, 3 * self.transmit_time(len(raw))))
            except (LinkClosed, OSError) as e:
                failed = e
            t = self.rec.bytes(t0, TO_VEHICLE, raw)
        if failed is not None:
            self._lose(f"write failed: {failed}")
        self.bytes_out += len(raw)
        return t

    def _lose(self, why: str) -> None:
        if not self.lost:
            self.lost = why
            for ev in self.framer.close():
                self._add(self.now(), ev.raw, False)
            self.lost_t = self.note(f"link lost: {why}")
        raise LinkLost(self.lost)

    # ------------------------------------------------------------------ receive
    def pump(self, timeout: float) -> bool:
        """Wait up to ``timeout`` seconds for bytes; record them and queue them in :attr:`inbox`."""
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
                self._add(t, fe.raw, not isinstance(fe, Discard))
        return got

    def _add(self, t: float, raw: bytes, line: bool) -> None:
        t = self.rec.bytes(t, FROM_VEHICLE, raw)
        if line:
            self.lines_in += 1
        self.inbox.append(Rx(t, raw, line))

    def next(self, deadline: float) -> Optional[Rx]:
        """The next received run, waiting until link time ``deadline`` at most."""
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

    def reattach(self, link: Link, why: str) -> None:
        """Carry on over a newly opened link (the old one was lost); noted in the record."""
        try:
            self.link.close()
        except Exception:  # noqa: BLE001
            pass
        self.link = link
        self.lost = self.lost_t = None
        self.framer = Framer(max(4096, 4 * self.profile.max_line_bytes))
        self.inbox.clear()
        self.note(why)

    def close(self) -> None:
        try:
            self.link.close()
        except Exception:  # noqa: BLE001
            pass
