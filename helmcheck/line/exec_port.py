"""The tester's end of a port that a started vehicle opens (``certify vehicle --exec``).

helmcheck plays the backseat, so the vehicle under test is the side that opens or serves the
port. :func:`open_for_child` opens helmcheck's end, starts the child on the other end through a
:class:`~helmcheck.line.launcher.Launcher`, and returns once the child is there:

* ``pty`` — :class:`ChildPty`, a new pseudo-terminal whose own slave descriptor is let go at
  once. Its master then reads EIO until the child has opened the slave path (``{port}``), which
  is how the child's arrival is seen; and again once the child has closed it or died, which the
  certifier sees as the link going away (a plain :class:`~.transport.PtyLink` would see only
  silence). Bytes the child writes before it is asked anything are kept, not lost.
* ``socket://HOST:PORT`` — the child listens, helmcheck connects. Port 0 means a free port is
  chosen (bound and released just before the child starts). Connection attempts are repeated
  every 0.1 s until one succeeds.
* ``announced`` — the child makes its own port (a simulator that opens a pty of its own) and prints
  ``port: URL`` on a line of its standard output; it is given no port, and helmcheck opens the one
  it printed (:meth:`~.launcher.Launcher.announced`);
* a device path or another pyserial URL — the child is told the port as given (it is the
  caller's business what the child does with it) and helmcheck opens the port itself at once.

Waiting ends when the child is there, when it has ended (:class:`ChildEnded`) or after
``ready_s`` seconds (:class:`ChildNotReady`). No judging happens here.
"""

from __future__ import annotations

import errno
import os
import socket
import time

from .launcher import Launcher
from .transport import Link, LinkEvent, PtyLink, TcpClientLink, open_link, parse_port_spec

__all__ = ["ChildPty", "ChildEnded", "ChildNotReady", "open_for_child", "free_tcp_port"]

_STEP_S = 0.02


class ChildNotReady(Exception):
    """The started child did not open (or listen on) its port in time; the message says so."""


class ChildEnded(ChildNotReady):
    """The started child ended before it opened (or listened on) its port."""


class ChildPty(PtyLink):
    """A pty for a child to open; see the module docstring."""

    def __init__(self, baud: int = 19200):
        super().__init__(baud)
        os.close(self._slave)
        self._slave = -1
        self._pending = b""
        self.opened = False

    def peer_opened(self) -> bool:
        """Has the far end opened the slave path? (Never blocks.)"""
        if self.opened:
            return True
        try:
            data = os.read(self.master, 65536)
        except (BlockingIOError, InterruptedError):
            self.opened = True
            return True
        except OSError as e:
            if e.errno == errno.EIO:
                return False
            raise
        if data:
            self._pending += data
            self.opened = True
        return self.opened

    def poll(self, max_bytes: int = 65536) -> list[LinkEvent]:
        if self._pending:
            data, self._pending = self._pending[:max_bytes], self._pending[max_bytes:]
            return [LinkEvent("data", data)]
        return super().poll(max_bytes)


def free_tcp_port(host: str) -> int:
    """A TCP port on *host* that nothing listens on right now."""
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    with socket.socket(family, socket.SOCK_STREAM) as s:
        s.bind((host, 0))
        return s.getsockname()[1]


def _ended(launcher: Launcher, what: str) -> ChildEnded:
    return ChildEnded(f"the {launcher.subject} under test {launcher.exit_text()} before it {what}")


def open_for_child(port: str, launcher: Launcher, *, baud: int, time_scale: float,
                   ready_s: float = 30.0) -> Link:
    """Open helmcheck's end of *port*, start the child on the other end and wait for it.

    Raises ``ValueError`` for a bad port spec, ``OSError`` when the child or the port cannot be
    started or opened, :class:`ChildEnded` or :class:`ChildNotReady` (module docstring).
    """
    spec = parse_port_spec(port)
    deadline = time.monotonic() + ready_s
    if spec.kind == "pty":
        link = ChildPty(baud)
        try:
            launcher.start(link.name, time_scale=time_scale)
            while not link.peer_opened():
                if launcher.ended:
                    raise _ended(launcher, f"opened {link.name}")
                if time.monotonic() >= deadline:
                    raise ChildNotReady(f"the {launcher.subject} under test did not open {link.name} "
                                        f"within {ready_s:g} s")
                time.sleep(_STEP_S)
        except BaseException:
            link.close()
            raise
        link.description = f"pty {link.name} (opened by the {launcher.subject} under test)"
        return link
    if spec.kind == "socket":
        host = "127.0.0.1" if spec.host in ("", "0.0.0.0") else spec.host
        number = spec.port or free_tcp_port(host)
        shown = f"[{host}]" if ":" in host else host
        url = f"socket://{shown}:{number}"
        launcher.start(url, host=host, tcp_port=str(number), time_scale=time_scale)
        while True:
            try:
                return TcpClientLink(host, number, timeout=1.0)
            except OSError:
                pass
            if launcher.ended:
                raise _ended(launcher, f"listened on {url}")
            if time.monotonic() >= deadline:
                raise ChildNotReady(f"the {launcher.subject} under test did not listen on {url} "
                                    f"within {ready_s:g} s")
            time.sleep(0.1)
    if spec.kind == "announced":
        launcher.start("", time_scale=time_scale)
        while (said := launcher.announced()) is None:
            if launcher.ended:
                raise _ended(launcher, "printed its port (a line 'port: URL')")
            if time.monotonic() >= deadline:
                raise ChildNotReady(f"the {launcher.subject} under test did not print its port (a line "
                                    f"'port: URL' on its standard output) within {ready_s:g} s")
            time.sleep(_STEP_S)
        link = open_link(parse_port_spec(said), role="client", baud=baud)
        link.description = f"{said} (announced by the {launcher.subject} under test)"
        return link
    launcher.start(spec.text, time_scale=time_scale)
    return open_link(spec, role="client", baud=baud)
