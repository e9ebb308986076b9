"""The emulator's output queue: :class:`Outbox`, a mixin of :class:`~.core.EmulatorCore`. Replies
wait in order (RH-ACK-6) and leave when the line is free at ``baud`` (RH-ACK-2's transmit time),
each logged as sent; the queue is capped (:data:`MAX_OUTBOX_BYTES`, beyond it replies are dropped).
"""

from __future__ import annotations

from ..grammar.wirelog import FROM_VEHICLE, escape
from .logs import HistoryEntry, reply_label

__all__ = ["Outbox", "MAX_OUTBOX_BYTES"]

#: Replies waiting for the line are capped; beyond this a flood's replies are dropped (noted).
MAX_OUTBOX_BYTES = 64 * 1024


class Outbox:
    """The replies :class:`~.core.EmulatorCore` has queued for the line, and their release."""

    @property
    def pending_output(self) -> int:
        return self._out_bytes

    def _send(self, raw: bytes, now: float) -> None:
        if self._out_bytes + len(raw) > MAX_OUTBOX_BYTES:
            self.stats["dropped_out"] += len(raw)
            if self.stats["dropped_out"] == len(raw):
                self._note(now, "output overflow: replies dropped (the line is slower than the requests)")
            return
        self._out.append(raw)
        self._out_bytes += len(raw)

    def _release(self, now: float) -> bytes:
        if not self._out:
            return b""
        out = bytearray()
        pacer = self.pacer
        while self._out:
            if pacer.baud and pacer.free_at > now + 1e-9:
                break
            raw = self._out.popleft()
            self._out_bytes -= len(raw)
            pacer.reserve(len(raw), now)
            out += raw
            self.stats["sentences_out"] += 1
            if self.log is not None:
                self.log.bytes(now - self.start, FROM_VEHICLE, raw)
            self.history.append(HistoryEntry(now - self.start, "<", escape(raw.rstrip(b"\r\n")[:160]),
                                             reply_label(raw)))
        self.stats["bytes_out"] += len(out)
        return bytes(out)
