"""The impairment schedule: given the bytes each side sent and when, what the other side gets and
when, and the notes that say what the line did. Sans-IO: times are handed in, nothing is read
or written here (the relay, :mod:`.relay`, does the I/O); the same faults, seed and input give
the same output, whenever :meth:`ImpairedLine.due` is asked.

:class:`ImpairedLine` takes each chunk read (:meth:`~ImpairedLine.push`) and gives back, in time
order, :class:`Action` s: bytes to deliver to a side, notes (:mod:`helmcheck.grammar.faultnote`
text) and, for a cut, when to unplug and plug back the port. What it does to each direction
(:class:`~.impair_spec.DirectionFaults`, read from ``--impair`` by :mod:`.impair_spec`), in this
order — the order things happen between a sender's program and a receiver's:

1. **the sender's timing** — ``line-delay``/``line-jitter``: a line (up to LF; a run without LF
   once the sender has been quiet for :attr:`~.impair_spec.DirectionFaults.quiet_s`) is held until
   that long after its last byte; ``delay``/``jitter``: each byte later still. Nothing overtakes:
   a byte never goes before the one sent before it;
2. **the line's faults**, per byte in the order sent — ``noise``: a burst of random bytes before
   it; ``drop``: lost (its time on the line passes all the same); ``flip``: data bits inverted.
   Which bytes are touched depends on the byte count alone (one random stream per fault and
   direction, drawn as gaps between hits), so the same bytes get the same faults however they
   were chunked or timed;
3. **the UART** — ``baud``: a byte starts when the one before it has ended and takes 10 bit
   times; it is delivered when its stop bit ends. A ``stall`` holds the UART: a byte that would be
   on the line in the stall's window starts at its end. A ``cut``: a byte on the line in the cut's
   window is lost, and the port is unplugged at its start and plugged back at its end;
4. **the receiver** — ``rx-baud``: the bit stream sent at ``baud`` is read by a UART at
   ``rx-baud`` (:mod:`.uart`), and what it reads is delivered, when it reads it.

Notes (their time is the fault's on the line: when the byte touched would have been delivered):
each drop, flip and noise burst; a stall's start and end (with the bytes it held); a cut's start
and end (with the bytes lost each way); at the start, one note per direction for what applies to
every byte (its timing, a receiver at another baud).
"""

from __future__ import annotations

import heapq
import math
import random
from typing import NamedTuple, Optional

from ..grammar.faultnote import BOTH, byte_text, fault_note
from ..grammar.wirelog import FROM_VEHICLE, TO_VEHICLE, escape
from .impair_spec import DirectionFaults, LineFaults
from .uart import Receiver, SenderLine, Ticks

__all__ = ["Action", "ImpairedLine", "BYTES", "NOTE", "UNPLUG", "REPLUG", "DIRECTIONS"]

BYTES, NOTE, UNPLUG, REPLUG = "bytes", "note", "unplug", "replug"
DIRECTIONS = (TO_VEHICLE, FROM_VEHICLE)
_NEVER = 1 << 62  # a gap no stream reaches
_NOISE_SHOWN = 32  # noise bytes quoted in a note


class Action(NamedTuple):
    """What the line does at ``t``: deliver ``data`` going ``direction`` (:data:`BYTES`), write a
    note (:data:`NOTE`, ``text``), or unplug / plug back the port (:data:`UNPLUG`, :data:`REPLUG`;
    ``direction`` is :data:`~helmcheck.grammar.faultnote.BOTH`, ``length`` the cut's seconds)."""

    t: float
    kind: str
    direction: str
    data: bytes = b""
    text: str = ""
    length: float = 0.0


def _gap(rng: random.Random, p: float) -> int:
    """Bytes (or bits) passed before the next one hit, each hit with probability ``p``: geometric."""
    if p <= 0.0:
        return _NEVER
    if p >= 1.0:
        return 0
    return int(math.log1p(-rng.random()) / math.log1p(-p))


class _Direction:
    """One direction's pipeline (module docstring); its actions go to the line's queue."""

    def __init__(self, line: "ImpairedLine", d: str, f: DirectionFaults, seed: int):
        self.line, self.d, self.f = line, d, f
        self.start = line.start

        def rng(kind: str) -> random.Random:
            return random.Random(f"helmcheck-line-fault/{seed}/{d}/{kind}")

        self._r_drop, self._r_flip, self._r_noise = rng("drop"), rng("flip"), rng("noise")
        self._r_burst = rng("noise-bytes")  # a burst's length and bytes: apart, so where bursts fall
        # depends on noise= alone
        self._r_jitter, self._r_line = rng("jitter"), rng("line-jitter")
        self.next_drop = _gap(self._r_drop, f.drop)
        self.next_flip = _gap(self._r_flip, f.flip)  # a bit number: 8 per byte
        self.next_noise = _gap(self._r_noise, f.noise)
        self.sent = 0  # bytes through the line's faults (the byte numbers of the notes)
        self.pending = bytearray()  # a line not yet ended
        self.pending_last = 0.0
        self.last_release = -math.inf
        self.ticks: Optional[Ticks] = None
        if f.baud:
            self.ticks = Ticks(f.baud, f.rx_baud if f.reframed else f.baud)
        self.free = 0  # the tick the UART is free from
        self.wire: Optional[SenderLine] = SenderLine(self.ticks) if f.reframed else None
        self.receiver: Optional[Receiver] = Receiver(self.ticks) if f.reframed else None
        self.stalls = [(self._tick_of(self.start + w.at), self._tick_of(self.start + w.end)) for w in f.stalls]
        self.cuts = [(self._tick_of(self.start + w.at), self._tick_of(self.start + w.end)) for w in line.faults.cuts]
        self.held = [0] * len(f.stalls)  # bytes each stall held
        self.lost = [0] * len(line.faults.cuts)  # bytes each cut lost
        self.untouched = f.clean and not line.faults.cuts
        self.stats = {k: 0 for k in ("in", "out", "dropped", "flipped_bits", "noise_bursts", "noise_bytes",
                                     "stalled", "cut", "framing_errors")}

    # ----------------------------------------------------------------- time
    def _tick_of(self, t: float):
        """``t`` in this direction's UART ticks (seconds when unpaced)."""
        if self.ticks is None:
            return t
        return math.ceil((t - self.start) / self.ticks.unit - 1e-6)

    def _time_of(self, tick) -> float:
        return tick if self.ticks is None else self.start + tick * self.ticks.unit

    # ----------------------------------------------------------------- 1: the sender's timing
    def push(self, t: float, data: bytes) -> None:
        self.stats["in"] += len(data)
        f = self.f
        if self.untouched:  # nothing to do to these bytes: they pass as they came
            self.stats["out"] += len(data)
            self.line.queue(t, BYTES, self.d, data)
            return
        if not f.holds_lines:
            self._release(t, data)
            return
        self.advance(t)
        while data:
            nl = data.find(b"\n")
            piece, data = (data, b"") if nl < 0 else (data[:nl + 1], data[nl + 1:])
            self.pending += piece
            self.pending_last = t
            if nl >= 0:
                self._close(t + f.line_delay)

    def _close(self, release: float) -> None:
        if self.f.line_jitter > 0:
            release += self._r_line.random() * self.f.line_jitter
        data, self.pending = bytes(self.pending), bytearray()
        self._release(release, data)

    def _release(self, t: float, data: bytes) -> None:
        f = self.f
        base = t + f.delay
        for b in data:
            r = base + (self._r_jitter.random() * f.jitter if f.jitter > 0 else 0.0)
            if r < self.last_release:
                r = self.last_release
            self.last_release = r
            self._fault(r, b)

    # ----------------------------------------------------------------- 2: the line's faults
    def _fault(self, r: float, b: int) -> None:
        f, i = self.f, self.sent
        self.sent += 1
        if i == self.next_noise:
            self.next_noise = i + 1 + _gap(self._r_noise, f.noise)
            lo, hi = f.noise_len
            burst = bytes(self._r_burst.getrandbits(8) for _ in range(self._r_burst.randint(lo, hi)))
            self.stats["noise_bursts"] += 1
            self.stats["noise_bytes"] += len(burst)
            shown = escape(burst[:_NOISE_SHOWN]).replace(" ", "\\x20") + ("…" if len(burst) > _NOISE_SHOWN else "")
            first = True
            for nb in burst:
                self._uart(r, nb, note=("noise", f"{len(burst)} byte{'s' if len(burst) > 1 else ''} before byte {i}: "
                                                    f"{shown}") if first else None)
                first = False
        dropped = i == self.next_drop
        if dropped:
            self.next_drop = i + 1 + _gap(self._r_drop, f.drop)
        mask = 0
        while self.next_flip < 8 * (i + 1):
            mask |= 1 << (self.next_flip - 8 * i)
            self.next_flip += 1 + _gap(self._r_flip, f.flip)
        if dropped:
            self.stats["dropped"] += 1
            self._uart(r, b, note=("drop", f"byte {i} ({byte_text(b)})"), lost=True)
        elif mask:
            bits = [k for k in range(8) if mask >> k & 1]
            self.stats["flipped_bits"] += len(bits)
            self._uart(r, b ^ mask, note=("flip", f"byte {i} bit{'s' if len(bits) > 1 else ''} "
                                          f"{','.join(map(str, bits))}: {byte_text(b)} -> {byte_text(b ^ mask)}"))
        else:
            self._uart(r, b)

    # ----------------------------------------------------------------- 3: the UART
    def _uart(self, r: float, b: int, *, note: Optional[tuple[str, str]] = None, lost: bool = False) -> None:
        tk = self.ticks
        length = tk.tx_frame if tk is not None else 0
        s = r0 = self._tick_of(r)
        if s < self.free:
            s = self.free
        for a, e in self.stalls:
            if s < e and (s + length > a if length else s >= a):
                s = e
        for k, (a, e) in enumerate(self.stalls):
            if r0 < e <= s:  # it waited for this stall's end (in it, or behind bytes that did)
                self.held[k] += 1
                self.stats["stalled"] += 1
        self.free = s + length
        end = s + length
        for k, (a, e) in enumerate(self.cuts):
            if s < e and (end > a if length else s >= a):
                self.lost[k] += 1
                self.stats["cut"] += 1
                return  # a cut's note covers what the line lost in it
        t = self._time_of(end)
        if note is not None:
            self.line.queue(t, NOTE, self.d, text=fault_note(self.d, *note))
        if lost:
            return
        if self.wire is not None:
            self.wire.add(s, b)
            self._receive(self.free)
        else:
            self.stats["out"] += 1
            self.line.queue(t, BYTES, self.d, bytes([b]))

    # ----------------------------------------------------------------- 4: the receiver
    def _receive(self, known: int) -> None:
        for got in self.receiver.run(self.wire, known):  # type: ignore[union-attr]
            if any(a <= got.tick < e for a, e in self.cuts):
                continue
            if not got.framed:
                self.stats["framing_errors"] += 1
            self.stats["out"] += 1
            self.line.queue(self._time_of(got.tick), BYTES, self.d, bytes([got.byte]))

    # ----------------------------------------------------------------- time passing
    def advance(self, now: float) -> None:
        """What the passing of time up to ``now`` decides: a line ended by quiet, the receiver's
        frames read to their end."""
        if self.pending and self.pending_last + self.f.quiet_s <= now:
            self._close(self.pending_last + self.f.quiet_s)
        if self.wire is not None:
            self._receive(max(self._tick_of(now), self.free))

    def wake(self) -> Optional[float]:
        """When time passing next decides something here (None: only new bytes will)."""
        out = []
        if self.pending:
            out.append(self.pending_last + self.f.quiet_s)
        if self.receiver is not None:
            w = self.receiver.waiting_until()
            if w is not None:
                out.append(self._time_of(w))
        return min(out) if out else None

    def opening_notes(self) -> list[tuple[str, str]]:
        f, out = self.f, []
        timing = []
        if f.baud:
            timing.append(f"paced at {f.baud} baud 8N1")
        if f.line_delay or f.line_jitter:
            timing.append(f"every line held {f.line_delay:g} s after its last byte"
                          + (f" and a further 0 to {f.line_jitter:g} s" if f.line_jitter else ""))
        if f.delay or f.jitter:
            timing.append(f"every byte {f.delay:g} s late"
                          + (f" and a further 0 to {f.jitter:g} s" if f.jitter else ""))
        if timing:
            out.append(("timing", "; ".join(timing)))
        if f.reframed:
            out.append(("reframe", f"sent at {f.baud} baud, read by a receiver at {f.rx_baud} baud 8N1: "
                                   "every byte re-framed"))
        return out


class ImpairedLine:
    """Both directions of an impaired line, from ``start`` (the clock's time when the line
    began; the windows of ``stall`` and ``cut`` count from it). See the module docstring."""

    def __init__(self, faults: LineFaults, start: float = 0.0):
        self.faults = faults
        self.start = start
        self._heap: list[tuple[float, int, Action]] = []
        self._seq = 0
        self._ended: dict[int, tuple] = {}
        self.dirs = {d: _Direction(self, d, faults.direction(d), faults.seed) for d in DIRECTIONS}
        for d, dirn in self.dirs.items():
            for kind, text in dirn.opening_notes():
                self.queue(start, NOTE, d, text=fault_note(d, kind, text))
            for k, w in enumerate(dirn.f.stalls):
                self.queue(start + w.at, NOTE, d, text=fault_note(d, "stall", f"{w.length:g} s from {w.at:g} s: "
                                                                              "nothing passes"))
                self._later(start + w.end, ("stall", d, k))
        for k, w in enumerate(faults.cuts):
            self.queue(start + w.at, NOTE, BOTH, text=fault_note(BOTH, "cut", f"{w.length:g} s from {w.at:g} s: "
                                                                             "nothing passes, what is sent is lost"))
            self.queue(start + w.at, UNPLUG, BOTH, length=w.length)
            self.queue(start + w.end, REPLUG, BOTH, length=w.length)
            self._later(start + w.end, ("cut", BOTH, k))

    # ----------------------------------------------------------------- the queue
    def queue(self, t: float, kind: str, direction: str, data: bytes = b"", text: str = "",
              length: float = 0.0) -> None:
        self._seq += 1
        heapq.heappush(self._heap, (t, self._seq, Action(t, kind, direction, data, text, length)))

    def _later(self, t: float, what: tuple) -> None:
        """A note whose text is only known at ``t`` (what a stall held, what a cut lost)."""
        self._seq += 1
        self._ended[self._seq] = what
        heapq.heappush(self._heap, (t, self._seq, Action(t, "later", BOTH)))

    def _ended_note(self, a: Action, seq: int) -> Action:
        kind, d, k = self._ended.pop(seq)
        if kind == "stall":
            w = self.dirs[d].f.stalls[k]
            text = fault_note(d, "stall", f"over after {w.length:g} s: {self.dirs[d].held[k]} bytes held, now sent")
        else:
            w = self.faults.cuts[k]
            lost = ", ".join(f"{self.dirs[x].lost[k]} bytes {x}" for x in DIRECTIONS)
            text = fault_note(BOTH, "cut", f"over after {w.length:g} s: lost {lost}")
        return Action(a.t, NOTE, d, text=text)

    # ----------------------------------------------------------------- the interface
    def push(self, t: float, direction: str, data: bytes) -> None:
        """``data`` read from the side that sends ``direction`` at ``t`` (never before a time
        already handed to :meth:`push` or :meth:`due`)."""
        if data:
            self.dirs[direction].push(t, data)

    def due(self, now: float) -> list[Action]:
        """Every action due at or before ``now``, in time order; consecutive bytes one way are
        joined into one action."""
        for dirn in self.dirs.values():
            dirn.advance(now)
        out: list[Action] = []
        run: list[bytes] = []  # the bytes of out[-1] while it is a run of bytes one way
        heap = self._heap
        while heap and heap[0][0] <= now:
            t, seq, a = heapq.heappop(heap)
            if a.kind == "later":
                a = self._ended_note(a, seq)
            if a.kind == BYTES and run and out[-1].direction == a.direction:
                run.append(a.data)
                out[-1] = out[-1]._replace(t=a.t)
                continue
            if run:
                out[-1] = out[-1]._replace(data=b"".join(run))
            run = [a.data] if a.kind == BYTES else []
            out.append(a)
        if run:
            out[-1] = out[-1]._replace(data=b"".join(run))
        return out

    def next_due(self) -> Optional[float]:
        """When :meth:`due` next has something (None: not until more bytes come)."""
        times = [self._heap[0][0]] if self._heap else []
        times += [w for w in (d.wake() for d in self.dirs.values()) if w is not None]
        return min(times) if times else None

    @property
    def stats(self) -> dict:
        """Counts per direction: ``in``, ``out``, ``dropped``, ``flipped_bits``, ``noise_bursts``,
        ``noise_bytes``, ``stalled`` (bytes a stall held), ``cut`` (bytes a cut lost),
        ``framing_errors`` (bytes the receiver at another baud read without a stop bit)."""
        return {d: dict(x.stats) for d, x in self.dirs.items()}
