"""The pseudo-terminal link (:class:`PtyLink`): a new pty in raw mode, 8N1, whose slave path the
far end opens.

Decisions: a pty link keeps its own slave descriptor open, so the master never sees a hang-up
when a client closes the port (no busy loop on EIO, raw settings kept); bytes written while no
client has the port open wait in the pty's buffer (a few KB) until one does. A client should
flush its input on opening (pyserial ``reset_input_buffer``).
"""

from __future__ import annotations

import errno
import os
import termios
import tty

from .link import Link, LinkClosed, LinkEvent, _read_fd, _write_fd

_TERMIOS_BAUD = {9600: termios.B9600, 19200: termios.B19200, 38400: termios.B38400,
                 57600: termios.B57600, 115200: termios.B115200}


class PtyLink(Link):
    """A new pseudo-terminal in raw mode; the far end opens :attr:`name` (RH-FRM-9: 8N1)."""

    def __init__(self, baud: int = 19200):
        self.master, self._slave = os.openpty()
        self.name = os.ttyname(self._slave)
        self.baud = baud
        tty.setraw(self._slave, termios.TCSANOW)
        attrs = termios.tcgetattr(self._slave)
        attrs[2] = (attrs[2] & ~(termios.CSIZE | termios.PARENB | termios.CSTOPB)) | termios.CS8 | termios.CLOCAL | termios.CREAD
        speed = _TERMIOS_BAUD.get(baud)
        if speed is not None:
            attrs[4] = attrs[5] = speed
        termios.tcsetattr(self._slave, termios.TCSANOW, attrs)
        os.set_blocking(self.master, False)
        self.description = f"pty {self.name}"

    def fileno(self) -> int:
        return self.master

    def poll(self, max_bytes: int = 65536) -> list[LinkEvent]:
        data, closed = _read_fd(self.master, max_bytes)
        if closed:
            raise LinkClosed(errno.EIO, f"{self.name}: pty closed")
        return [LinkEvent("data", data)] if data else []

    def write_some(self, data: bytes) -> int:
        return _write_fd(self.master, data)

    def close(self) -> None:
        for fd in (self._slave, self.master):
            try:
                os.close(fd)
            except OSError:
                pass
        self._slave = self.master = -1
