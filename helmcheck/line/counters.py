"""A serial port's error counters, as the kernel keeps them: :func:`read_counters`.

A UART driver counts what went wrong on the line it receives: frames without a stop bit
(``frame``: noise, a wrong baud rate), parity errors, bytes the UART itself lost because nobody
read it in time (``overrun``), bytes the driver's buffer lost (``buf_overrun``), breaks, and the
bytes received and sent (``rx``, ``tx``). Linux gives them for a real serial port through the
``TIOCGICOUNT`` ioctl (``struct serial_icounter_struct``). A jump in these between the start and
the end of a test is a fault of the line or the host, not of the implementation at the other end.

This module owns reading them, and saying when they cannot be read: a pseudo-terminal, a socket
or a pyserial URL has no UART, so the ioctl is refused (``ENOTTY``, ``EINVAL``) and the answer is
:class:`NotAvailable` with the reason, never zeros that would claim a clean line. Nothing here
opens or closes a port; the caller hands in an open descriptor or link.
"""

from __future__ import annotations

import errno
import fcntl
import os
import stat
import struct
import sys
import termios
from typing import NamedTuple, Union

__all__ = ["LineCounters", "NotAvailable", "read_counters", "FIELDS", "ERROR_FIELDS"]

#: Linux's ``TIOCGICOUNT`` (``asm-generic/ioctls.h``); Python's termios has it on Linux.
TIOCGICOUNT = getattr(termios, "TIOCGICOUNT", 0x545D)
#: ``struct serial_icounter_struct``: cts, dsr, rng, dcd, rx, tx, frame, overrun, parity, brk,
#: buf_overrun, and 9 reserved ints.
_STRUCT = struct.Struct("20i")
FIELDS = ("rx", "tx", "frame", "parity", "overrun", "brk", "buf_overrun")
ERROR_FIELDS = ("frame", "parity", "overrun", "brk", "buf_overrun")
_INDEX = {"rx": 4, "tx": 5, "frame": 6, "overrun": 7, "parity": 8, "brk": 9, "buf_overrun": 10}
#: errnos that mean "this descriptor is not a serial port with counters"
_UNSUPPORTED = {errno.ENOTTY, errno.EINVAL, errno.ENOSYS, errno.EOPNOTSUPP}


class LineCounters(NamedTuple):
    """The kernel's counters for one port at one moment (module docstring)."""

    rx: int
    tx: int
    frame: int
    parity: int
    overrun: int
    brk: int
    buf_overrun: int

    available = True

    @property
    def errors(self) -> int:
        """Frame, parity, overrun, break and buffer-overrun counts together."""
        return sum(getattr(self, f) for f in ERROR_FIELDS)

    def since(self, earlier: "LineCounters") -> "LineCounters":
        """What was counted between ``earlier`` and this reading."""
        return LineCounters(*(a - b for a, b in zip(self, earlier)))

    def as_dict(self) -> dict:
        return {"available": True, **self._asdict()}


class NotAvailable(NamedTuple):
    """The port has no counters to read; ``reason`` says why (one line)."""

    reason: str

    available = False
    errors = 0

    def since(self, earlier) -> "NotAvailable":  # noqa: ARG002 - the same interface as LineCounters
        return self

    def as_dict(self) -> dict:
        return {"available": False, "reason": self.reason}


Counters = Union[LineCounters, NotAvailable]


def _what(fd: int) -> str:
    """A few words on what ``fd`` is, for the reason."""
    try:
        name = os.ttyname(fd)
    except OSError:
        name = ""
    if name.startswith("/dev/pts/") or name == "/dev/ptmx":
        return f"{name} is a pseudo-terminal (no UART)"
    try:
        mode = os.fstat(fd).st_mode
    except OSError as e:
        return f"descriptor {fd}: {e.strerror or e}"
    if stat.S_ISSOCK(mode):
        return "a socket has no UART"
    if stat.S_ISREG(mode):
        return "a regular file has no UART"
    if name:
        return f"{name}: its driver keeps no counters"
    return "not a serial port with counters"


def read_counters(port) -> Counters:
    """The counters of ``port`` (an open descriptor, or anything with ``fileno()``: a
    :class:`~helmcheck.line.link.Link`), or :class:`NotAvailable` with the reason."""
    if sys.platform != "linux":
        return NotAvailable(f"TIOCGICOUNT is Linux's; this is {sys.platform}")
    try:
        fd = port if isinstance(port, int) else port.fileno()
    except (OSError, AttributeError) as e:
        return NotAvailable(f"no descriptor to ask: {getattr(e, 'strerror', None) or e}")
    try:
        raw = fcntl.ioctl(fd, TIOCGICOUNT, bytes(_STRUCT.size))
    except OSError as e:
        if e.errno in _UNSUPPORTED:
            return NotAvailable(f"{_what(fd)}: TIOCGICOUNT refused ({errno.errorcode.get(e.errno, e.errno)})")
        return NotAvailable(f"TIOCGICOUNT failed: {e.strerror or e}")
    values = _STRUCT.unpack(raw)
    return LineCounters(**{f: values[i] for f, i in _INDEX.items()})
