"""The TCP links (RH-FRM-9: a TCP byte stream carries the same bytes as a serial line): the
tester's client (:class:`TcpClientLink`) and the one-client-at-a-time serial server
(:class:`TcpServerLink`).
"""

from __future__ import annotations

import errno
import socket
from typing import Optional

from .link import Link, LinkClosed, LinkEvent


def _nodelay(sock: socket.socket) -> None:
    try:
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    except OSError:
        pass


class TcpClientLink(Link):
    """Connects to a serial server at ``socket://HOST:PORT``."""

    def __init__(self, host: str, port: int, timeout: float = 5.0):
        self.sock = socket.create_connection((host, port), timeout=timeout)
        self.sock.setblocking(False)
        _nodelay(self.sock)
        self.name = f"socket://{host}:{port}"
        self.description = f"tcp client {host}:{port}"
        self._closed = False

    @property
    def connected(self) -> bool:
        return not self._closed

    def fileno(self) -> int:
        return self.sock.fileno()

    def poll(self, max_bytes: int = 65536) -> list[LinkEvent]:
        if self._closed:
            raise LinkClosed(errno.ENOTCONN, f"{self.name}: closed")
        try:
            data = self.sock.recv(max_bytes)
        except (BlockingIOError, InterruptedError):
            return []
        except OSError as e:
            self._closed = True
            raise LinkClosed(errno.ECONNRESET, f"{self.name}: {e}") from None
        if not data:
            self._closed = True
            raise LinkClosed(errno.ECONNRESET, f"{self.name}: closed by peer")
        return [LinkEvent("data", data)]

    def write_some(self, data: bytes) -> int:
        try:
            return self.sock.send(data)
        except (BlockingIOError, InterruptedError):
            return 0
        except OSError as e:
            self._closed = True
            raise LinkClosed(errno.ECONNRESET, f"{self.name}: {e}") from None

    def close(self) -> None:
        self._closed = True
        try:
            self.sock.close()
        except OSError:
            pass


class TcpServerLink(Link):
    """A serial server: listens on HOST:PORT and serves one client at a time.

    While no client is connected :meth:`fileno` is the listening socket and :meth:`poll`
    accepts (a ``connect`` event); while one is, it is the client's socket and further clients
    wait in the listen backlog until it leaves (a ``disconnect`` event). Writes with no client
    are dropped (return the full length, like bytes sent down an unplugged line).
    """

    def __init__(self, host: str = "127.0.0.1", port: int = 0, backlog: int = 4):
        family = socket.AF_INET6 if ":" in host else socket.AF_INET
        self.listener = socket.socket(family, socket.SOCK_STREAM)
        self.listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.listener.bind((host, port))
        self.listener.listen(backlog)
        self.listener.setblocking(False)
        bound = self.listener.getsockname()
        shown = bound[0] if family == socket.AF_INET else f"[{bound[0]}]"
        self.port = bound[1]
        self.name = f"socket://{shown}:{self.port}"
        self.description = f"tcp server {shown}:{self.port}"
        self.client: Optional[socket.socket] = None
        self.peer = ""

    @property
    def connected(self) -> bool:
        return self.client is not None

    def fileno(self) -> int:
        return self.client.fileno() if self.client is not None else self.listener.fileno()

    def poll(self, max_bytes: int = 65536) -> list[LinkEvent]:
        if self.client is None:
            try:
                sock, addr = self.listener.accept()
            except (BlockingIOError, InterruptedError):
                return []
            sock.setblocking(False)
            _nodelay(sock)
            self.client = sock
            self.peer = f"{addr[0]}:{addr[1]}"
            return [LinkEvent("connect", info=self.peer)]
        try:
            data = self.client.recv(max_bytes)
        except (BlockingIOError, InterruptedError):
            return []
        except OSError as e:
            return [self._drop(str(e))]
        if not data:
            return [self._drop("closed by peer")]
        return [LinkEvent("data", data)]

    def _drop(self, why: str) -> LinkEvent:
        peer = self.peer
        try:
            self.client.close()  # type: ignore[union-attr]
        except OSError:
            pass
        self.client = None
        self.peer = ""
        return LinkEvent("disconnect", info=f"{peer} {why}")

    def disconnect(self) -> Optional[LinkEvent]:
        """Drop the present client (if any)."""
        return self._drop("closed by server") if self.client is not None else None

    def write_some(self, data: bytes) -> int:
        if self.client is None:
            return len(data)
        try:
            return self.client.send(data)
        except (BlockingIOError, InterruptedError):
            return 0
        except OSError:
            return len(data)  # the next poll reports the disconnect

    def close(self) -> None:
        try:  # first stop listening: a client that sees its connection end can connect nowhere
            self.listener.close()
        except OSError:
            pass
        if self.client is not None:
            self._drop("closed by server")
