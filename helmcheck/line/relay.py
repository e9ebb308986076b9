"""The relay between two links (:class:`Relay`): one thread that reads both sides of a live line
with one clock, forwards every byte in line, and hands a copy of each chunk on. It is the I/O
core of ``helmcheck monitor`` and of ``helmcheck relay`` (the line-fault relay).

It owns the bytes on the wire while it runs, and nothing above them: no framing, no judging, no
log format (the callbacks do that). Three modes:

* **in line** (``forward=True``, ``--between``): every chunk read from one side is written to
  the other at once, unchanged, in arrival order (no line buffering). It never alters, delays on
  purpose, drops, reorders or injects a byte. When the far side cannot take the bytes now, they
  wait in a per-direction buffer, in order, and are written as soon as its descriptor is
  writable. The only bytes not delivered (counted in :attr:`Relay.stats` as ``undelivered``) are
  those going to a side that has closed for good or to a TCP server with no client (like bytes
  sent down an unplugged line), including what waited for a client that left;
* **in line through an impairment stage** (``stage``, an :class:`~.impair.ImpairedLine`): what is
  read goes to the stage, and what the stage says is due is written when it is due — its bytes
  (forwarded as above), its notes (``on_note(t, text)``, ``t`` the fault's time) and its cuts:
  at a cut's start the side ``cut_side`` is unplugged (``unplug(side, link)``: the owner closes
  it; the relay neither reads nor writes it meanwhile) and at its end plugged back
  (``replug(side)`` returns the new link; None or an ``OSError``: tried again every
  :data:`REPLUG_RETRY_S`). The thread wakes when something is due (a paced byte's end), not
  only for input, but not sooner than :data:`PACE_TICK_S` after it last looked;
* **tap** (``forward=False``, ``--tap``): the two receive lines of a Y-cable; only read, never
  a byte written to either.

Each chunk is reported as ``on_bytes(t, direction, data)``: ``direction`` is
:data:`~helmcheck.grammar.wirelog.TO_VEHICLE` for bytes the backseat sent and
:data:`~helmcheck.grammar.wirelog.FROM_VEHICLE` for the vehicle's; ``t`` is read from ``clock``
(one clock for both directions). Without a stage the chunk is what was read, ``t`` read right
after the read, before forwarding; with a stage it is what was delivered, ``t`` read right
before the write. The callback runs after the forwarding write, so slow judging never delays a
forwarded byte; it should be quick (append to a log) because the next read waits for it.
``on_idle(t)``, if given, is called once per turn of the loop (at least every :data:`_IDLE` s).
The judges run in a process of their own (:mod:`helmcheck.monitor.live`); any other thread of
this process (the main loop, a live screen) shares the interpreter lock with this one, so while
a relay runs the interpreter's switch interval is :data:`SWITCH_INTERVAL_S`: such a thread
holds a read byte back at most that long (``benchmarks/monitor_bench.py`` measures what it all
comes to). With ``realtime`` (the default) the thread asks for the lowest real-time priority
(Linux ``SCHED_FIFO`` :data:`RT_PRIORITY`), so that a waking relay is not queued behind
whatever else keeps the CPUs busy; it blocks in ``select`` between chunks, so it takes no CPU it
does not use. Without the permission (root, ``CAP_SYS_NICE``, or an ``rtprio`` limit of at
least :data:`RT_PRIORITY`) it runs at normal priority; :attr:`Relay.priority` says which, once
:meth:`started` returns. Sides coming and going are ``on_event(t, kind, side)``:
``connect``/``disconnect`` (a TCP server link's client), ``closed`` (the link raised
:class:`~helmcheck.line.link.LinkClosed`: a pty or device gone), ``unplugged``/``replugged``
(a stage's cut), ``lost``/``reopened`` (with ``reopen``: a side whose link closed, and the same
side opened again); the relay keeps serving the other side. With ``reopen(side)`` a side whose
link closes is not gone for good: it is set aside like a cut one (nothing read from it, nothing
written to it: what was on its way to it is lost) and ``reopen(side)`` is called every
:data:`REPLUG_RETRY_S` from the relay's thread — a new link plugs it back, None (or an
``OSError``) means not yet, :class:`~helmcheck.line.link.LinkClosed` that it is gone for good
(``closed``). RH-FRM-9: the line is 8N1 and a TCP
byte stream carries the same bytes, so every link is the same byte stream here. The caller
opens and closes links (a replugged one included).
"""

from __future__ import annotations

import os
import select
import sys
import threading
import time
from typing import Callable, Optional

from ..grammar.wirelog import FROM_VEHICLE, TO_VEHICLE
from .impair import BYTES, NOTE, REPLUG, UNPLUG, ImpairedLine
from .link import Link, LinkClosed

__all__ = ["Relay", "SIDES"]

SIDES = ("backseat", "vehicle")
_READS = {"backseat": TO_VEHICLE, "vehicle": FROM_VEHICLE}  # direction of the bytes read from a side
_GOES_TO = {TO_VEHICLE: "vehicle", FROM_VEHICLE: "backseat"}  # the side a direction is written to
_IDLE = 0.05  # the longest select wait: a side without a descriptor, a missed wake-up
_NO_FD_WAIT = 0.005  # the wait when a side has no descriptor (pyserial loop://) and is polled
_MAX_WRITE = 65536  # the most offered to one write_some
#: How often a side that could not be plugged back after a cut is tried again.
REPLUG_RETRY_S = 0.25
#: With a stage, the shortest wait for something due later: what falls due within it is done
#: together at its end (a paced byte is never early, and at most this late, plus the host's
#: scheduling). One wake a byte would cost a third of a CPU at 115200 baud both ways; a USB
#: serial adapter delivers in chunks of a millisecond or more anyway.
PACE_TICK_S = 0.001
#: With a stage, the most read from a side at a time: the stage handles bytes one by one, so a
#: long burst taken at once would hold back what falls due meanwhile (about 4 ms a kilobyte).
STAGE_READ = 256
#: The interpreter's thread switch interval while a relay runs (Python's default is 5 ms): another
#: thread holding the interpreter lock hands it over within this, so a byte read waits on it at
#: most this long before it is forwarded.
SWITCH_INTERVAL_S = 0.0002
#: The real-time priority the relay thread asks for (the lowest: above every normal process,
#: below every real-time one the system has, such as interrupt threads).
RT_PRIORITY = 1


def _ignore(t: float, kind: str, side: str) -> None:  # noqa: ARG001 - the default on_event
    pass


def _no_note(t: float, text: str) -> None:  # noqa: ARG001 - the default on_note
    pass


class Relay(threading.Thread):
    """Reads ``backseat`` and ``vehicle`` (both :class:`~helmcheck.line.link.Link`), forwards
    when ``forward`` (through ``stage`` when given), reports each chunk to
    ``on_bytes(t, direction, data)`` and each side's ``connect``/``disconnect``/``closed``/
    ``unplugged``/``replugged`` to ``on_event(t, kind, side)`` (module docstring).

    :meth:`start` it; :meth:`stop` ends it promptly (a self-pipe wakes the loop). An exception
    that ended the thread (raised by a link or a callback) is in :attr:`error`."""

    def __init__(self, backseat: Link, vehicle: Link, *, forward: bool,
                 on_bytes: Callable[[float, str, bytes], None],
                 on_event: Callable[[float, str, str], None] = _ignore,
                 clock: Callable[[], float] = time.monotonic, name: str = "helmcheck-relay",
                 realtime: bool = True, stage: Optional[ImpairedLine] = None,
                 on_note: Callable[[float, str], None] = _no_note, cut_side: str = "backseat",
                 unplug: Optional[Callable[[str, Link], None]] = None,
                 replug: Optional[Callable[[str], Optional[Link]]] = None,
                 on_idle: Optional[Callable[[float], None]] = None,
                 reopen: Optional[Callable[[str], Optional[Link]]] = None):
        super().__init__(name=name, daemon=True)
        if stage is not None and not forward:
            raise ValueError("an impairment stage needs the relay in line (forward=True)")
        if cut_side not in SIDES:
            raise ValueError(f"cut_side must be one of {SIDES}, not {cut_side!r}")
        self.stage = stage
        self.on_note = on_note
        self.cut_side = cut_side
        self._unplug_cb = unplug
        self._replug_cb = replug
        self.on_idle = on_idle
        self.unplugged: set[str] = set()  #: sides a cut has unplugged (or whose link closed), not yet back
        self.reopen = reopen
        self.lost: set[str] = set()  #: of those, the sides whose link closed (``reopen`` brings them back)
        self._replug_at: dict[str, float] = {}  # side -> when to try plugging it back (again)
        self.realtime = realtime
        #: the thread's scheduling, once running: "real-time" or "normal (…why…)"
        self.priority = ""
        self._running = threading.Event()
        self.links = {"backseat": backseat, "vehicle": vehicle}
        self.forward = forward
        self.on_bytes = on_bytes
        self.on_event = on_event
        self.clock = clock
        self.error: Optional[BaseException] = None
        self.closed: set[str] = set()  #: sides gone for good
        self._pending = {TO_VEHICLE: bytearray(), FROM_VEHICLE: bytearray()}
        self._stats = {k: {TO_VEHICLE: 0, FROM_VEHICLE: 0}
                       for k in ("bytes", "chunks", "max_pending", "undelivered")}
        self._stopping = threading.Event()
        self._pipe_lock = threading.Lock()  # the self-pipe is closed once, never written after
        self._wake_r, self._wake_w = os.pipe()
        os.set_blocking(self._wake_r, False)
        os.set_blocking(self._wake_w, False)

    # ------------------------------------------------------------------ control
    @property
    def stats(self) -> dict:
        """``bytes``, ``chunks``, ``max_pending``, ``pending`` and ``undelivered``, each a dict
        keyed by direction (``">"``, ``"<"``); a snapshot."""
        out = {k: dict(v) for k, v in self._stats.items()}
        out["pending"] = {d: len(p) for d, p in self._pending.items()}
        return out

    def started(self, timeout: float = 5.0) -> str:
        """Wait until the thread runs (its priority set); returns :attr:`priority`."""
        self._running.wait(timeout)
        return self.priority

    def stop(self, timeout: Optional[float] = 1.0) -> bool:
        """Ask the loop to end, wait up to ``timeout`` s; True when the thread has ended."""
        self._stopping.set()
        with self._pipe_lock:
            if self._wake_w >= 0:
                try:
                    os.write(self._wake_w, b"x")
                except OSError:  # full: already woken
                    pass
        if self.ident is None:  # never started: nothing will close the self-pipe
            self._close_pipe()
        elif self.is_alive():
            self.join(timeout)
        return not self.is_alive()

    # ------------------------------------------------------------------ the loop
    def run(self) -> None:
        switch = sys.getswitchinterval()
        sys.setswitchinterval(min(switch, SWITCH_INTERVAL_S))
        self.priority = _raise_priority() if self.realtime else "normal (real-time priority not asked for)"
        self._running.set()
        try:
            while not self._stopping.is_set() and len(self.closed) < len(SIDES):
                self._once()
        except BaseException as e:  # noqa: BLE001 - reported through .error
            self.error = e
        finally:
            sys.setswitchinterval(switch)
            self._close_pipe()

    def _close_pipe(self) -> None:
        with self._pipe_lock:
            for fd in (self._wake_r, self._wake_w):
                if fd >= 0:
                    os.close(fd)
            self._wake_r = self._wake_w = -1

    def _once(self) -> None:
        rfds: dict[int, str] = {}
        wfds: dict[int, str] = {}
        unselectable: list[str] = []
        for side in SIDES:
            if side in self.closed or side in self.unplugged:
                continue
            try:
                fd = self.links[side].fileno()  # re-read each turn: a TCP server's changes
            except OSError:
                unselectable.append(side)
                continue
            rfds[fd] = side
            if self.forward and self._pending[_READS[_other(side)]]:
                wfds[fd] = side
        timeout = _NO_FD_WAIT if unselectable else _IDLE
        if self.stage is not None or self._replug_at:
            now = self.clock()
            due = self.stage.next_due() if self.stage is not None else None
            wake = [t for t in (due, *self._replug_at.values()) if t is not None]
            if wake:
                left = min(wake) - now
                timeout = min(timeout, 0.0 if left <= 0 else max(left, PACE_TICK_S))
        r, w, _ = select.select([self._wake_r, *rfds], list(wfds), [], timeout)
        if self._wake_r in r:
            try:
                os.read(self._wake_r, 64)
            except OSError:
                pass
        if self._stopping.is_set():
            return
        for fd in w:
            self._flush(_READS[_other(wfds[fd])])
        for side in [rfds[fd] for fd in r if fd in rfds] + unselectable:
            if side not in self.closed:
                self._read(side)
        if self.stage is not None:
            self._run_stage()
        elif self._replug_at:
            self._replug_due()
        if self.forward:
            for side in unselectable:  # no descriptor to wait on for writability
                self._flush(_READS[_other(side)])
        if self.on_idle is not None:
            self.on_idle(self.clock())

    def _read(self, side: str) -> None:
        link = self.links[side]
        try:
            events = link.poll() if self.stage is None else link.poll(STAGE_READ)
        except LinkClosed:
            self._closed(side)
            return
        t = self.clock()  # right after the read, before forwarding
        direction = _READS[side]
        for ev in events:
            if ev.kind == "data" and ev.data:
                self._stats["bytes"][direction] += len(ev.data)
                self._stats["chunks"][direction] += 1
                if self.stage is not None:
                    self.stage.push(t, direction, ev.data)
                    continue
                if self.forward:
                    self._send(direction, ev.data)
                self.on_bytes(t, direction, ev.data)
            elif ev.kind in ("connect", "disconnect"):
                if ev.kind == "disconnect":  # what waited for that client is not for the next one
                    self._forget(_READS[_other(side)])
                self.on_event(t, ev.kind, side)

    def _send(self, direction: str, data: bytes) -> None:
        """Forward ``data``: at once when nothing waits before it, else behind what waits."""
        pending = self._pending[direction]
        if not self._reachable(_GOES_TO[direction]):
            self._stats["undelivered"][direction] += len(data)
            return
        if not pending:
            n = self._write(direction, data)
            if n >= len(data) or _GOES_TO[direction] in self.closed:
                return
            data = data[n:]
        pending += data
        self._flush(direction)

    def _reachable(self, side: str) -> bool:
        """False for a side closed for good or unplugged, and a TCP server with no client (its
        link would take the bytes and drop them, like an unplugged line)."""
        return side not in self.closed and side not in self.unplugged and self.links[side].connected

    # ------------------------------------------------------------------ the stage
    def _run_stage(self) -> None:
        """Carry out what the stage says is due now (module docstring)."""
        stage = self.stage
        for a in stage.due(self.clock()):  # type: ignore[union-attr]
            if a.kind == BYTES:
                t = self.clock()
                self._send(a.direction, a.data)
                self.on_bytes(t, a.direction, a.data)
            elif a.kind == NOTE:
                self.on_note(a.t, a.text)
            elif a.kind == UNPLUG:
                self._unplug(self.cut_side)
            elif a.kind == REPLUG:
                self._replug_at[self.cut_side] = self.clock()
        self._replug_due()

    def _replug_due(self) -> None:
        now = self.clock()
        for side, when in list(self._replug_at.items()):
            if when <= now:
                self._replug(side)

    def _unplug(self, side: str) -> None:
        if side in self.closed or side in self.unplugged:
            return
        self.unplugged.add(side)
        self._forget(_READS[_other(side)])
        if self._unplug_cb is not None:
            self._unplug_cb(side, self.links[side])
        self.on_event(self.clock(), "unplugged", side)

    def _replug(self, side: str) -> None:
        if side not in self.unplugged:
            self._replug_at.pop(side, None)
            return
        link = None
        cb = self.reopen if side in self.lost else self._replug_cb
        if cb is not None:
            try:
                link = cb(side)
            except LinkClosed:  # given up on: gone for good
                self._replug_at.pop(side, None)
                self.unplugged.discard(side)
                self.lost.discard(side)
                self._gone(side)
                return
            except OSError:
                link = None
        else:
            link = self.links[side]
        if link is None:
            self._replug_at[side] = self.clock() + REPLUG_RETRY_S
            return
        self._replug_at.pop(side, None)
        self.links[side] = link
        self.unplugged.discard(side)
        kind = "reopened" if side in self.lost else "replugged"
        self.lost.discard(side)
        self.on_event(self.clock(), kind, side)

    def _flush(self, direction: str) -> None:
        pending = self._pending[direction]
        while pending:
            n = self._write(direction, bytes(pending[:_MAX_WRITE]))
            if n <= 0:
                break
            del pending[:n]
        if len(pending) > self._stats["max_pending"][direction]:
            self._stats["max_pending"][direction] = len(pending)

    def _write(self, direction: str, data: bytes) -> int:
        side = _GOES_TO[direction]
        if side in self.closed or side in self.unplugged:
            return 0
        try:
            return self.links[side].write_some(data)
        except (LinkClosed, BrokenPipeError, ConnectionError):
            self._closed(side)
            return 0

    def _closed(self, side: str) -> None:
        """A side's link closed: gone for good, or (with ``reopen``) set aside until it is back."""
        if self.reopen is None or side in self.closed or side in self.unplugged:
            self._gone(side)
            return
        self.unplugged.add(side)
        self.lost.add(side)
        self._forget(_READS[_other(side)])
        self._replug_at[side] = self.clock() + REPLUG_RETRY_S
        self.on_event(self.clock(), "lost", side)

    def _gone(self, side: str) -> None:
        """A side closed for good: report it, forget what waited for it, serve the other."""
        if side in self.closed:
            return
        self.closed.add(side)
        self._forget(_READS[_other(side)])
        self.on_event(self.clock(), "closed", side)

    def _forget(self, direction: str) -> None:
        self._stats["undelivered"][direction] += len(self._pending[direction])
        self._pending[direction].clear()


def _raise_priority() -> str:
    """Give the calling thread :data:`RT_PRIORITY` (module docstring); what it got."""
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(RT_PRIORITY))  # 0: this thread (Linux)
    except AttributeError:
        return "normal (no real-time scheduling on this system)"
    except OSError as e:
        return f"normal (real-time priority refused: {e.strerror or e})"
    return f"real-time (SCHED_FIFO {RT_PRIORITY})"


def _other(side: str) -> str:
    return "vehicle" if side == "backseat" else "backseat"
