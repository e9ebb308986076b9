"""A serial line in virtual time, with the reference vehicle in-process at its far end.

:class:`VirtualLine` is a :class:`~helmcheck.line.transport.Link` whose other end is an
:class:`~helmcheck.emulator.core.EmulatorCore` (sans-IO: bytes in with a time, bytes
out) and whose time is its own :class:`VirtualClock`. A :class:`~.link.TesterLink` built on it
with ``clock=line.clock`` runs the real session and case interpreter unchanged: where the tester
would wait for bytes, the line advances the clock to the next thing that happens instead of
letting real time pass. No port is opened and no real time is spent waiting; ``certify vehicle
--plan`` (:mod:`.plan`) times the cases this way.

The line model (both directions 8N1 at ``baud``, 10 bits a byte):

* tester → vehicle: a write leaves when the line is free; each line of it (up to its LF)
  reaches the vehicle when its last byte has crossed, and the vehicle acts on it
  :data:`VEHICLE_DELAY_S` later (its reading and processing time), or a delay drawn per line by
  a callable (a vehicle whose answers come anywhere inside the ACK window), in arrival order
  all the same (RH-ACK-6);
* vehicle → tester: the vehicle's own pacing (:class:`~helmcheck.line.transport.LinePacer`)
  decides when a sentence starts; it reaches the tester once its last byte has crossed.

``baud = 0`` carries bytes in no time. What happens on the vehicle off the wire (a sensor an
operator trips) is scheduled with :meth:`VirtualLine.at`. Nothing here knows a case or a clause.
"""

from __future__ import annotations

import heapq
import math
from typing import Callable, Optional

from ...grammar.wirelog import transmit_time
from ...line.transport import Link, LinkEvent

__all__ = ["VirtualClock", "VirtualLine", "VEHICLE_DELAY_S"]

#: Seconds from the moment a line's last byte reaches the vehicle to the moment it acts on it.
VEHICLE_DELAY_S = 0.002
#: What a wait without a timeout stands for, in virtual seconds.
FOREVER_S = 86400.0


class VirtualClock:
    """A clock that only moves when told to; call it for the time (like ``time.monotonic``)."""

    __slots__ = ("t",)

    def __init__(self, t: float = 0.0):
        self.t = float(t)

    def __call__(self) -> float:
        return self.t

    def advance_to(self, t: float) -> None:
        if t > self.t:
            self.t = t


class VirtualLine(Link):
    """The tester's end of a line to ``core`` in virtual time. See the module docstring."""

    name = "virtual"
    description = "a virtual-time line to the in-process reference vehicle"

    def __init__(self, core, baud: int, clock: Optional[VirtualClock] = None,
                 vehicle_delay_s: "float | Callable[[], float]" = VEHICLE_DELAY_S):
        self.core = core
        self.baud = baud
        self.clock = clock if clock is not None else VirtualClock(core.start)
        self.per_byte = transmit_time(1, baud)
        self.vehicle_delay_s = vehicle_delay_s
        self._acts = -math.inf  #: when the vehicle acted on the last line (arrival order kept)
        self._seq = 0
        self._to_vehicle: list[tuple[float, int, bytes]] = []  #: (when the vehicle acts, order, bytes)
        self._to_tester: list[tuple[float, int, bytes]] = []  #: (when the tester has them, order, bytes)
        self._off_wire: list[tuple[float, int, Callable[[float], bytes]]] = []  #: (when, order, action)
        self._line_free = self.clock.t  #: when the tester → vehicle direction is free again
        self._core_t = self.clock.t  #: the last time given to the core (never goes back)
        self.closed = False

    # ------------------------------------------------------------------ the far end
    def _push(self, heap: list, t: float, data: bytes) -> None:
        self._seq += 1
        heapq.heappush(heap, (t, self._seq, data))

    def _from_core(self, out: bytes, now: float) -> None:
        if out:
            self._push(self._to_tester, now + len(out) * self.per_byte, out)

    def at(self, t: float, action: Callable[[float], bytes]) -> None:
        """Something that happens on the vehicle off the wire at virtual time ``t`` (a sensor an
        operator trips): ``action(now)`` calls the core and returns the bytes it sends now."""
        self._seq += 1
        heapq.heappush(self._off_wire, (t, self._seq, action))

    def _next_core_event(self) -> float:
        t = self._to_vehicle[0][0] if self._to_vehicle else math.inf
        if self._off_wire:
            t = min(t, max(self._off_wire[0][0], self._core_t))
        w = self.core.next_wakeup()
        if w is not None:
            t = min(t, max(w, self._core_t))
        return t

    def _step_core(self, t: float) -> None:
        """Run the core's next event, due at ``t``."""
        t = max(t, self._core_t)
        if self._off_wire and self._off_wire[0][0] <= t:
            _, _, action = heapq.heappop(self._off_wire)
            self._core_t = t
            self._from_core(action(t), t)
            return
        if self._to_vehicle and self._to_vehicle[0][0] <= t:
            _, _, data = heapq.heappop(self._to_vehicle)
            self._core_t = t
            self._from_core(self.core.feed(data, t), t)
            return
        before = self.core.next_wakeup()
        self._core_t = t
        self._from_core(self.core.tick(t), t)
        after = self.core.next_wakeup()
        if after is not None and before is not None and after <= t and after == before:
            # a wake-up that did nothing would repeat for ever: the core's time must move on
            self._core_t = t + 1e-6

    def _run(self, until: float) -> bool:
        """Run the far end up to ``until`` or the first arrival at the tester before it; the
        clock stops there. True when something arrived."""
        while True:
            arrival = self._to_tester[0][0] if self._to_tester else math.inf
            event = self._next_core_event()
            if arrival <= event and arrival <= until:
                self.clock.advance_to(arrival)
                return True
            if event <= until:
                self._step_core(event)
                continue
            self.clock.advance_to(until)
            return False

    # ------------------------------------------------------------------ Link
    def fileno(self) -> int:
        return -1

    def wait_readable(self, timeout: Optional[float]) -> bool:
        now = self.clock.t
        if self._to_tester and self._to_tester[0][0] <= now:
            return True
        if timeout is None:  # "for ever": a day of virtual time (the vehicle may never say anything)
            timeout = FOREVER_S
        until = now + max(0.0, timeout)
        if until <= now and timeout:
            until = math.nextafter(now, math.inf)  # a wait too short to move a float still moves
        return self._run(until)

    def poll(self, max_bytes: int = 65536) -> list[LinkEvent]:
        self._run(self.clock.t)
        out = []
        while self._to_tester and self._to_tester[0][0] <= self.clock.t:
            out.append(LinkEvent("data", heapq.heappop(self._to_tester)[2]))
        return out

    def write_some(self, data: bytes) -> int:
        self._run(self.clock.t)
        start = max(self.clock.t, self._line_free)
        sent = 0
        for line in data.splitlines(keepends=True):
            sent += len(line)
            delay = self.vehicle_delay_s() if callable(self.vehicle_delay_s) else self.vehicle_delay_s
            self._acts = max(self._acts, start + sent * self.per_byte + delay)
            self._push(self._to_vehicle, self._acts, line)
        self._line_free = start + len(data) * self.per_byte
        return len(data)

    def write_all(self, data: bytes, timeout: Optional[float] = 5.0) -> None:
        self.write_some(data)

    def close(self) -> None:
        self.closed = True
