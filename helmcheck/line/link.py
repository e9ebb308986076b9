"""The byte-link interface every link implements (:class:`Link`), what its poll reports
(:class:`LinkEvent`), :class:`LinkClosed`, and non-blocking descriptor reads and writes.

Every link is non-blocking and selectable: :meth:`Link.fileno` is the descriptor to wait on for
input (a TCP server's changes between the listening socket and the client, so re-read it after
every :meth:`Link.poll`). :meth:`Link.poll` reads what is there and returns
:class:`LinkEvent` s (``data``, ``connect``, ``disconnect``); :meth:`Link.write_some` writes
without blocking. For simple synchronous use (a certifier's client side) there are blocking
helpers :meth:`Link.read` and :meth:`Link.write_all`.
"""

from __future__ import annotations

import errno
import os
import select
import time
from dataclasses import dataclass
from typing import Optional


class LinkClosed(OSError):
    """The link is gone for good (device removed, connection reset on a client link)."""


@dataclass(frozen=True, slots=True)
class LinkEvent:
    """What :meth:`Link.poll` saw: ``data`` (bytes arrived), ``connect`` or ``disconnect``."""

    kind: str
    data: bytes = b""
    info: str = ""


class Link:
    """A non-blocking byte link. Subclasses implement ``fileno``, ``poll``, ``write_some``, ``close``."""

    name: str = ""  #: what to tell the other side to open ("/dev/pts/3", "socket://127.0.0.1:4001")
    description: str = ""  #: one-line description for humans and log headers
    baud: int = 0

    @property
    def connected(self) -> bool:
        """True when bytes written now can reach a peer (always for pty and devices)."""
        return True

    def fileno(self) -> int:
        raise NotImplementedError

    def poll(self, max_bytes: int = 65536) -> list[LinkEvent]:
        """Read whatever is available now, without blocking."""
        raise NotImplementedError

    def write_some(self, data: bytes) -> int:
        """Write as much of ``data`` as fits now; returns the count (0 when nothing fits or no peer)."""
        raise NotImplementedError

    def close(self) -> None:
        raise NotImplementedError

    # -------------------------------------------------------------- blocking helpers
    def wait_readable(self, timeout: Optional[float]) -> bool:
        try:
            r, _, _ = select.select([self.fileno()], [], [], timeout)
        except (OSError, ValueError):
            return False
        return bool(r)

    def read(self, timeout: Optional[float] = None, max_bytes: int = 65536) -> bytes:
        """Wait up to ``timeout`` seconds for input; return the data bytes seen (maybe ``b""``)."""
        deadline = None if timeout is None else time.monotonic() + timeout
        while True:
            out = b"".join(e.data for e in self.poll(max_bytes) if e.kind == "data")
            if out:
                return out
            left = None if deadline is None else deadline - time.monotonic()
            if left is not None and left <= 0:
                return b""
            self.wait_readable(left)

    def write_all(self, data: bytes, timeout: Optional[float] = 5.0) -> None:
        """Write every byte or raise :class:`TimeoutError`."""
        deadline = None if timeout is None else time.monotonic() + timeout
        view = memoryview(data)
        while view:
            n = self.write_some(bytes(view))
            view = view[n:]
            if not view:
                return
            left = None if deadline is None else deadline - time.monotonic()
            if left is not None and left <= 0:
                raise TimeoutError(f"{self.name}: could not write {len(view)} bytes")
            try:
                select.select([], [self._write_fd()], [], min(left, 0.05) if left is not None else 0.05)
            except (OSError, ValueError):
                time.sleep(0.001)

    def _write_fd(self) -> int:
        return self.fileno()

    def __enter__(self) -> "Link":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _read_fd(fd: int, max_bytes: int) -> tuple[bytes, bool]:
    """(data, closed) from a non-blocking descriptor."""
    try:
        data = os.read(fd, max_bytes)
    except BlockingIOError:
        return b"", False
    except InterruptedError:
        return b"", False
    except OSError as e:
        if e.errno in (errno.EIO, errno.ECONNRESET, errno.EBADF, errno.ENXIO):
            return b"", True
        raise
    return data, not data


def _write_fd(fd: int, data: bytes) -> int:
    try:
        return os.write(fd, data)
    except (BlockingIOError, InterruptedError):
        return 0
