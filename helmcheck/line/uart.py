"""A UART's bit stream, and a receiving UART that samples it at another baud rate.

What a wrong baud rate does to bytes: the sender's UART puts each byte on the line as a frame of
10 bits at its rate (8N1, RH-FRM-9: a start bit 0, the 8 data bits least significant first, a
stop bit 1; the line rests at 1 between frames); a receiver at another rate finds a start bit
where the line falls, samples the middle of each of its own 10 bit times, and makes a byte of
whatever it read. This module owns that model, sans-IO and exact:

* :class:`Ticks` — integer time: one tick is ``1 / (64 · tx · rx)`` s, so both rates' bit times,
  half bit times and the receiver's sampling offset are whole numbers of ticks (no rounding
  decides which bit a sample falls in);
* :class:`SenderLine` — the line as the sender drives it: frames at given start ticks;
* :class:`Receiver` — the receiving UART, fed the line as far as it is known;
* :func:`reframe` — bytes sent back to back (or with given gaps), as the receiver reads them.

The receiver's rules (a 16550-like UART, and Linux's raw mode): it hunts for the line at 0 from
the middle of the last stop bit (so after a stop bit read as 0 — a framing error — the line may
already be low and the next frame starts at once); it starts its bit clock :data:`DETECT` of a
bit after the fall (a 16-times oversampling receiver sees a fall up to a sixteenth of a bit late:
half of that); a start bit read as 1 in its middle is a false start and the hunt goes on from
there; every frame with a true start bit gives a byte, a framing error or not (raw mode without
``INPCK`` passes the byte read; a break reads as 0x00, which is what its bits say anyway). A
byte is the receiver's at the middle of its stop bit.
"""

from __future__ import annotations

from bisect import bisect_right
from typing import Iterable, NamedTuple, Optional

__all__ = ["Ticks", "SenderLine", "Receiver", "Received", "reframe", "BITS", "DETECT"]

BITS = 10  #: a frame: start, 8 data bits, stop (8N1)
DETECT = 1 / 32  #: how far into its start bit the receiver's bit clock starts, in its bit times


def frame_bit(byte: int, j: int) -> int:
    """Bit ``j`` (0-9) of the frame of ``byte``: the start bit, data least significant first, the stop bit."""
    if j == 0:
        return 0
    if j == 9:
        return 1
    return (byte >> (j - 1)) & 1


class Ticks:
    """Integer time for a sender at ``tx`` baud and a receiver at ``rx`` baud (module docstring)."""

    __slots__ = ("tx", "rx", "unit", "tx_bit", "rx_bit", "rx_half", "detect")

    def __init__(self, tx: int, rx: int):
        if tx <= 0 or rx <= 0:
            raise ValueError("baud rates are above zero")
        self.tx, self.rx = tx, rx
        self.unit = 1.0 / (64 * tx * rx)  #: seconds a tick
        self.tx_bit = 64 * rx  #: the sender's bit time
        self.rx_bit = 64 * tx  #: the receiver's bit time
        self.rx_half = 32 * tx
        self.detect = 2 * tx  #: DETECT of the receiver's bit

    @property
    def tx_frame(self) -> int:
        return BITS * self.tx_bit


class SenderLine:
    """The line as the sender drives it: frames added in time order, never overlapping; 1 (idle)
    between them. Old frames are let go once the receiver is past them (:meth:`forget`)."""

    def __init__(self, ticks: Ticks):
        self.t = ticks
        self._starts: list[int] = []
        self._bytes: list[int] = []
        self._first = 0  # frames before this index are forgotten

    @property
    def end(self) -> int:
        """The tick the last frame ends at (0 before the first)."""
        return self._starts[-1] + self.t.tx_frame if self._starts else 0

    def add(self, start: int, byte: int) -> None:
        if self._starts and start < self.end:
            raise ValueError("a frame starts before the one before it has ended")
        self._starts.append(start)
        self._bytes.append(byte)

    def _at(self, tick: int) -> int:
        """Index of the last frame starting at or before ``tick`` (-1: none)."""
        return bisect_right(self._starts, tick, self._first) - 1

    def level(self, tick: int) -> int:
        i = self._at(tick)
        if i < self._first:
            return 1
        j = (tick - self._starts[i]) // self.t.tx_bit
        return frame_bit(self._bytes[i], j) if j < BITS else 1

    def next_low(self, tick: int) -> Optional[int]:
        """The first tick at or after ``tick`` where the line is 0, or None (none known)."""
        i = self._at(tick)
        if i >= self._first:
            s, b = self._starts[i], self._bytes[i]
            j = (tick - s) // self.t.tx_bit
            if j < BITS:
                if frame_bit(b, j) == 0:
                    return tick
                for k in range(j + 1, BITS):
                    if frame_bit(b, k) == 0:
                        return s + k * self.t.tx_bit
        nxt = max(i + 1, self._first)
        return self._starts[nxt] if nxt < len(self._starts) else None

    def forget(self, before: int) -> None:
        """Let go of the frames that end at or before ``before``."""
        while self._first < len(self._starts) and self._starts[self._first] + self.t.tx_frame <= before:
            self._first += 1
        if self._first > 4096:
            del self._starts[:self._first]
            del self._bytes[:self._first]
            self._first = 0


class Received(NamedTuple):
    """A byte the receiver read: at tick ``tick`` (its stop bit's middle); ``framed`` is False
    for a framing error (the stop bit read as 0)."""

    tick: int
    byte: int
    framed: bool


class Receiver:
    """The receiving UART (module docstring). :meth:`run` reads as far as the line is known."""

    def __init__(self, ticks: Ticks):
        self.t = ticks
        self.hunt = 0  #: the tick from which it looks for a start bit
        self.fall: Optional[int] = None  #: the fall that began the frame it is reading

    def run(self, line: SenderLine, known: int) -> list[Received]:
        """The bytes whose every sample lies before ``known`` (the line is final before it)."""
        out: list[Received] = []
        t = self.t
        while True:
            if self.fall is None:
                low = line.next_low(self.hunt)
                if low is None or low >= known:
                    self.hunt = max(self.hunt, known)
                    line.forget(self.hunt)
                    return out
                self.fall = low
            base = self.fall + t.detect
            stop = base + 19 * t.rx_half
            if stop >= known:
                return out
            mid_start = base + t.rx_half
            if line.level(mid_start):
                self.hunt, self.fall = mid_start, None  # a false start
                continue
            v = 0
            for k in range(1, 9):
                if line.level(base + (2 * k + 1) * t.rx_half):
                    v |= 1 << (k - 1)
            out.append(Received(stop, v, bool(line.level(stop))))
            self.hunt, self.fall = stop, None
            line.forget(stop)

    def waiting_until(self) -> Optional[int]:
        """The tick the line must be known past for the frame being read to end (None: hunting)."""
        if self.fall is None:
            return None
        return self.fall + self.t.detect + 19 * self.t.rx_half + 1


def reframe(data: bytes, tx: int, rx: int, gaps: Optional[Iterable[int]] = None) -> list[Received]:
    """``data`` sent at ``tx`` baud, read by a receiver at ``rx`` baud. Back to back, or with
    ``gaps`` (idle sender bit times before each byte). The line is idle after the last byte."""
    t = Ticks(tx, rx)
    line = SenderLine(t)
    rcv = Receiver(t)
    at = t.tx_bit  # a bit of idle line first
    gap_iter = iter(gaps) if gaps is not None else None
    for b in data:
        if gap_iter is not None:
            at += next(gap_iter, 0) * t.tx_bit
        line.add(at, b)
        at += t.tx_frame
    return rcv.run(line, at + 20 * t.rx_bit)
