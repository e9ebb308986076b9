"""The emulator's output queue: :class:`Outbox`, a mixin of :class:`~.core.EmulatorCore`. Replies
wait in order (RH-ACK-6) and leave when the line is free at ``baud`` (10 bits a byte: RH-ACK-2's
transmit time), each logged as sent. What one request asked for is queued together
(:meth:`Outbox._send_set`), and when requests ask for more than the line carries the vehicle
does what its ``overrun`` setting says (:mod:`.freedoms`; the profile leaves it open):

* ``"queue"`` — every reply waits its turn, however long the queue grows (queue and lag), up to
  :data:`MAX_OUTBOX_BYTES`, beyond which a request's replies are dropped (memory stays bounded);
* ``"drop"`` — while the requests of the last :data:`~.outload.WINDOW_S` seconds ask for more than
  the line carries (a sustained overrun, not a burst), a poll (``$OSD``) whose replies could not
  start within the ACK window (the queue ahead takes longer than ``ack_window_s`` to drain) is not
  answered: its data sentences and its ``$ACK,8`` are dropped whole. A command is always answered,
  in order: it changes the vehicle's state, and its ``$ACK`` is a few bytes. The queue then never
  holds much more than the ACK window's worth, so what is sent leaves about when RH-ACK-2 says.

Either way the demand, the longest wait and what was dropped are metered
(:class:`~.outload.OutputLoad`, :attr:`Outbox.load`) and the first drop is noted in the wire log.
"""

from __future__ import annotations

from typing import Callable, Iterable, Optional

from ..grammar.wirelog import FROM_VEHICLE, escape
from .logs import HistoryEntry, reply_label

__all__ = ["Outbox", "MAX_OUTBOX_BYTES", "OVERRUN_READINGS"]

#: Replies waiting for the line are capped; beyond this a flood's replies are dropped (noted).
MAX_OUTBOX_BYTES = 64 * 1024
#: The readings of a line over-asked (``overrun``): queue and lag, or drop.
OVERRUN_READINGS = ("queue", "drop")


class Outbox:
    """The replies :class:`~.core.EmulatorCore` has queued for the line, and their release.
    ``on_release(raw, queued_at, released_at)`` (optional) sees every sentence as it leaves."""

    on_release: Optional[Callable[[bytes, float, float], None]] = None

    @property
    def pending_output(self) -> int:
        return self._out_bytes

    def backlog_s(self, now: float) -> float:
        """Wall seconds until everything queued now has left the line."""
        pacer = self.pacer
        if not pacer.baud:
            return 0.0
        return max(0.0, pacer.free_at - now) + pacer.transmit_time(self._out_bytes)

    def _send(self, raw: bytes, now: float) -> None:
        """One sentence into the queue (a test's faulty vehicle rewrites its sentences here)."""
        if self._out_bytes + len(raw) > MAX_OUTBOX_BYTES:
            self._dropped(now, len(raw), f"more than {MAX_OUTBOX_BYTES // 1024} KiB of replies were waiting "
                                         f"for the line")
            return
        self._out.append((raw, now))
        self._out_bytes += len(raw)

    def _send_set(self, raws: Iterable[bytes], now: float, sid: str = "") -> None:
        """The replies to one request (``sid``: its sentence ID), queued together (one by one,
        :meth:`_send`) or, when the line cannot take them (module docstring), dropped together."""
        raws = [r for r in raws if r]
        if not raws:
            return
        n = sum(len(r) for r in raws)
        self.load.asked(now - self.start, n, sid)
        if (self.settings.overrun == "drop" and sid == "OSD" and self.backlog_s(now) > self.profile.ack_window_s
                and self.load.recent_rate(now - self.start) > self.load.capacity):
            self._dropped(now, n, f"the replies queued before a poll's took {self.backlog_s(now):.2f} s to leave, "
                                  f"longer than the {self.profile.ack_window_s:g} s ACK window, while the requests "
                                  f"asked for {self.load.recent_rate(now - self.start):.0f} bytes a second of a "
                                  f"line that carries {self.load.capacity:.0f} (overrun = \"drop\")")
            return
        for raw in raws:
            self._send(raw, now)

    def _dropped(self, now: float, n: int, why: str) -> None:
        if not self.stats["dropped_out"]:
            self._note(now, f"output overflow: replies dropped (the line is slower than the requests): {why}")
        self.stats["dropped_out"] += n
        self.load.dropped(now - self.start, n)

    def _release(self, now: float) -> bytes:
        if not self._out:
            return b""
        out = bytearray()
        pacer = self.pacer
        while self._out:
            if pacer.baud and pacer.free_at > now + 1e-9:
                break
            raw, queued = self._out.popleft()
            self._out_bytes -= len(raw)
            pacer.reserve(len(raw), now)
            out += raw
            self.stats["sentences_out"] += 1
            self.load.lagged(now - self.start, now - queued)
            if self.on_release is not None:
                self.on_release(raw, queued, now)
            if self.log is not None:
                self.log.bytes(now - self.start, FROM_VEHICLE, raw)
            self.history.append(HistoryEntry(now - self.start, "<", escape(raw.rstrip(b"\r\n")[:160]),
                                             reply_label(raw)))
        self.stats["bytes_out"] += len(out)
        return bytes(out)
