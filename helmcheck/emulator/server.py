"""The emulator's I/O loop: one link, one :class:`~.core.EmulatorCore`, no busy polling.

This module owns descriptors, the clock and signals; the core owns everything else. The loop
waits in a selector on the link (and, with a live view, the keyboard) with a timeout that ends
at the core's :meth:`~.core.EmulatorCore.next_wakeup` (or the view's next refresh): it sleeps
until input arrives or something is due, reads the clock once per event, and hands the time
to the core. Writes are non-blocking; bytes the link cannot take yet wait in a bounded buffer
(beyond :data:`MAX_PENDING` they are dropped and noted — a real UART with nobody reading
loses them too).

Link changes: on a TCP serial server a client's disconnect resets the framer and drops unsent
replies (the model's state persists for the next client); a serial device that disappears ends
the loop with exit status 2 (:attr:`Server.lost` says why). SIGINT, SIGTERM and SIGHUP end the
loop cleanly (exit status 0): the handlers only set a flag and wake the selector through
``signal.set_wakeup_fd``. ``helmcheck emulate`` passes ``install_signals=False``: there the
command line's handlers (:mod:`helmcheck.signals`) end the loop by raising ``Interrupted``.
"""

from __future__ import annotations

import selectors
import signal
import socket
import threading
import time
from typing import Any, Callable, Optional

from ..line.transport import Link, LinkClosed
from .core import EmulatorCore

__all__ = ["Server", "MAX_PENDING", "MAX_SLEEP_S"]

MAX_PENDING = 256 * 1024
#: The longest the loop sleeps at once (seconds): a wakeup further off (a waypoint thousands of
#: kilometres away at a slow speed, at time scale 1) is met by waking sooner and looking again —
#: a selector takes no timeout beyond about 24 days.
MAX_SLEEP_S = 3600.0


class Server:
    """Runs ``core`` on ``link`` until :meth:`stop` or a signal. See the module docstring."""

    def __init__(self, link: Link, core: EmulatorCore, *, clock: Callable[[], float] = time.monotonic,
                 ui: Any = None, install_signals: bool = True):
        self.link = link
        self.core = core
        self.clock = clock
        self.ui = ui
        self.install_signals = install_signals and threading.current_thread() is threading.main_thread()
        self._stop = False
        self.exit_status = 0
        self.lost: Optional[str] = None  #: why the link ended the loop (exit status 2)
        self._pending = bytearray()
        self._dropped = 0
        self._requests: list[tuple[str, str]] = []  #: faults asked for by a signal handler
        self._wake_r, self._wake_w = socket.socketpair()
        self._wake_r.setblocking(False)
        self._wake_w.setblocking(False)

    # ------------------------------------------------------------------ control
    def stop(self, status: int = 0) -> None:
        """Ask the loop to end (safe from a signal handler or another thread)."""
        self._stop = True
        self.exit_status = status
        try:
            self._wake_w.send(b"\0")
        except OSError:
            pass

    def inject_fault(self, code: str, source: str = "key") -> None:
        """Raise a safety violation now (from the live view's keys)."""
        self._queue(self.core.inject_fault(code, self.clock(), source))
        self._flush()

    def request_fault(self, code: str, source: str) -> None:
        """Raise a safety violation at the loop's next turn: safe from a signal handler (an
        operator tripping a sensor on the bench, ``helmcheck emulate``'s SIGUSR1)."""
        self._requests.append((code, source))
        try:
            self._wake_w.send(b"\0")
        except OSError:
            pass

    # ------------------------------------------------------------------ the loop
    def run(self) -> int:
        old: dict[int, Any] = {}
        old_wakeup = None
        if self.install_signals:
            for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
                old[sig] = signal.signal(sig, lambda *_: self.stop(0))
            old_wakeup = signal.set_wakeup_fd(self._wake_w.fileno(), warn_on_full_buffer=False)
        sel = selectors.DefaultSelector()
        sel.register(self._wake_r, selectors.EVENT_READ, "wake")
        ui_fd = self.ui.fileno() if self.ui is not None else None
        if ui_fd is not None:
            sel.register(ui_fd, selectors.EVENT_READ, "ui")
        link_fd = -1
        link_mask = 0
        try:
            while not self._stop:
                now = self.clock()
                while self._requests:
                    code, source = self._requests.pop(0)
                    self._queue(self.core.inject_fault(code, now, source))
                self._queue(self.core.tick(now))
                self._flush()
                if self.ui is not None:
                    r = self.ui.next_refresh()
                    if r is not None and r <= now:
                        self.ui.refresh(now)
                fd = self.link.fileno()
                mask = selectors.EVENT_READ | (selectors.EVENT_WRITE if self._pending and self.link.connected else 0)
                if fd != link_fd or mask != link_mask:
                    if link_fd >= 0:
                        try:
                            sel.unregister(link_fd)
                        except (KeyError, ValueError, OSError):
                            pass
                    sel.register(fd, mask, "link")
                    link_fd, link_mask = fd, mask
                timeout = self._timeout(now)
                for key, events in sel.select(timeout):
                    if key.data == "wake":
                        self._drain_wake()
                    elif key.data == "ui":
                        self.ui.on_input(self, self.clock())
                    elif key.data == "link":
                        if events & selectors.EVENT_READ:
                            if not self._read():
                                break
                        if events & selectors.EVENT_WRITE:
                            self._flush()
        finally:
            sel.close()
            if self.install_signals:
                signal.set_wakeup_fd(old_wakeup if old_wakeup is not None else -1)
                for sig, h in old.items():
                    signal.signal(sig, h)
            self._wake_r.close()
            self._wake_w.close()
        return self.exit_status

    def _timeout(self, now: float) -> Optional[float]:
        due = self.core.next_wakeup()
        if self.ui is not None:
            r = self.ui.next_refresh()
            if r is not None:
                due = r if due is None else min(due, r)
        if due is None:
            return None
        return min(max(0.0, due - now), MAX_SLEEP_S)

    def _drain_wake(self) -> None:
        try:
            while self._wake_r.recv(512):
                pass
        except (BlockingIOError, InterruptedError, OSError):
            pass

    def _read(self) -> bool:
        """Handle the link's input; False when the link is gone for good."""
        try:
            events = self.link.poll()
        except LinkClosed as e:
            self.lost = str(e.strerror or e)
            self.core.note(self.clock(), f"link lost: {e}")
            self.core.disconnect(self.clock(), "link lost")
            self.stop(2)
            return False
        for ev in events:
            now = self.clock()
            if ev.kind == "data":
                self._queue(self.core.feed(ev.data, now))
            elif ev.kind == "connect":
                self._pending.clear()
                self.core.connect(now, ev.info)
            elif ev.kind == "disconnect":
                self._pending.clear()
                self.core.disconnect(now, ev.info)
        self._flush()
        return True

    # ------------------------------------------------------------------ output
    def _queue(self, data: bytes) -> None:
        if not data:
            return
        if len(self._pending) + len(data) > MAX_PENDING:
            if not self._dropped:
                self.core.note(self.clock(), "link: output dropped, nobody is reading the port")
            self._dropped += len(data)
            return
        self._pending += data

    def _flush(self) -> None:
        while self._pending:
            try:
                n = self.link.write_some(bytes(self._pending[:65536]))
            except (LinkClosed, OSError):
                self._pending.clear()
                return
            if n <= 0:
                return
            del self._pending[:n]
        self._dropped = 0
