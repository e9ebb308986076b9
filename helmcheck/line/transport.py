"""Serial-line plumbing shared by the emulator and the certifiers: pty, serial device, TCP.

This module owns *opening* a byte link and moving bytes over it; it knows nothing about
sentences. One spec string names a link everywhere (RH-FRM-9: a TCP byte stream carries the
same bytes as a serial line):

==========================  ==============================  ==================================
spec                        role ``"server"`` (vehicle)     role ``"client"`` (tester)
==========================  ==============================  ==================================
``pty``                     a new pseudo-terminal in raw mode; its slave path is ``link.name``
                            (the same in both roles: whoever says ``pty`` creates it)
``/dev/ttyX``, ``/dev/pts/N``  the device via pyserial, 8N1 at ``baud``
``socket://HOST:PORT``      listen, serve one client at a   connect to ``HOST:PORT``
                            time (port 0: pick a free one)
other pyserial URLs         pyserial ``serial_for_url`` (``rfc2217://``, ``loop://``, ``spy://`` …)
==========================  ==============================  ==================================

Every link is non-blocking and selectable: :meth:`Link.fileno` is the descriptor to wait on for
input (a TCP server's changes between the listening socket and the client, so re-read it after
every :meth:`Link.poll`). :meth:`Link.poll` reads what is there and returns
:class:`LinkEvent` s (``data``, ``connect``, ``disconnect``); :meth:`Link.write_some` writes
without blocking. For simple synchronous use (a certifier's client side) there are blocking
helpers :meth:`Link.read` and :meth:`Link.write_all`.

:class:`LinePacer` is the sans-IO model of the line's capacity: 10 bits per byte (8N1,
:func:`helmcheck.grammar.wirelog.transmit_time`) at the baud rate, so a sender can pace its output
as a real UART would (RH-ACK-2's "serial transmit time", RH-BS-4's line budget). Pacing is wall
time; it never scales with a time scale (RH-TIM-2).

Decisions: a pty link keeps its own slave descriptor open, so the master never sees a hang-up
when a client closes the port (no busy loop on EIO, raw settings kept); bytes written while no
client has the port open wait in the pty's buffer (a few KB) until one does. A client should
flush its input on opening (pyserial ``reset_input_buffer``).
"""

from __future__ import annotations

import errno
import os
import re
import select
import socket
import termios
import time
import tty
from dataclasses import dataclass
from typing import Optional

from ..grammar.wirelog import transmit_time

__all__ = ["PortSpec", "parse_port_spec", "LinkEvent", "LinkClosed", "Link", "PtyLink", "SerialLink",
           "TcpClientLink", "TcpServerLink", "open_link", "LinePacer", "BAUD_RATES"]

#: Baud rates a serial device may be opened at (RH-FRM-9 plus 38400).
BAUD_RATES = (9600, 19200, 38400, 57600, 115200)
_TERMIOS_BAUD = {9600: termios.B9600, 19200: termios.B19200, 38400: termios.B38400,
                 57600: termios.B57600, 115200: termios.B115200}
_SOCKET_RE = re.compile(r"^socket://(\[[^\]]+\]|[^:/\[\]]*):(\d{1,5})/?$")
_URL_RE = re.compile(r"^[a-z][a-z0-9+.-]*://", re.I)


class LinkClosed(OSError):
    """The link is gone for good (device removed, connection reset on a client link)."""


@dataclass(frozen=True)
class PortSpec:
    """A parsed ``--port`` value. ``kind`` is ``pty``, ``socket``, ``device`` or ``url``."""

    kind: str
    text: str
    host: str = ""
    port: int = 0
    path: str = ""


def parse_port_spec(text: str) -> PortSpec:
    """Read a port spec; raises :class:`ValueError` with a one-line reason."""
    if not text:
        raise ValueError("empty port")
    if text == "pty":
        return PortSpec("pty", text)
    if text.lower().startswith("socket://"):
        m = _SOCKET_RE.match(text)
        if m is None:
            raise ValueError(f"bad socket port {text!r}: want socket://HOST:PORT")
        host = m.group(1).strip("[]") or "0.0.0.0"
        port = int(m.group(2))
        if port > 65535:
            raise ValueError(f"bad socket port {text!r}: port number above 65535")
        return PortSpec("socket", text, host=host, port=port)
    if _URL_RE.match(text):
        return PortSpec("url", text)
    if not text.startswith("/"):
        raise ValueError(f"bad port {text!r}: want pty, a device path (/dev/ttyX) or socket://HOST:PORT")
    return PortSpec("device", text, path=text)


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


class SerialLink(Link):
    """A serial device or pyserial URL, opened 8N1 at ``baud`` (RH-FRM-9)."""

    def __init__(self, spec: str, baud: int = 19200):
        import serial  # pyserial; imported here so pty/TCP users do not pay for it

        self.baud = baud
        self.name = spec
        self.description = f"serial {spec} {baud} 8N1"
        kwargs = dict(baudrate=baud, bytesize=serial.EIGHTBITS, parity=serial.PARITY_NONE,
                      stopbits=serial.STOPBITS_ONE, timeout=0, write_timeout=0)
        if _URL_RE.match(spec):
            self.ser = serial.serial_for_url(spec, **kwargs)
        else:
            self.ser = serial.Serial(spec, **kwargs)
        self._empty = 0
        try:
            self._fd: Optional[int] = self.ser.fileno()
        except Exception:  # noqa: BLE001 - URL handlers without a descriptor (loop://)
            self._fd = None

    def fileno(self) -> int:
        if self._fd is None:
            raise OSError(errno.ENOTSUP, f"{self.name}: not selectable")
        return self._fd

    def wait_readable(self, timeout: Optional[float]) -> bool:
        if self._fd is None:  # no descriptor: poll gently
            time.sleep(min(timeout if timeout is not None else 0.01, 0.01))
            return True
        return super().wait_readable(timeout)

    def poll(self, max_bytes: int = 65536) -> list[LinkEvent]:
        import serial

        try:
            if self._fd is not None:
                # A tty read with VMIN=0 returns b"" when nothing is there: that is not an
                # end of file. A device that goes away raises EIO/ENXIO instead.
                try:
                    data = os.read(self._fd, max_bytes)
                except (BlockingIOError, InterruptedError):
                    data = b""
                except OSError as e:
                    raise LinkClosed(errno.EIO, f"{self.name}: {e.strerror or e}") from None
            else:
                data = self.ser.read(min(self.ser.in_waiting, max_bytes))
        except serial.SerialException as e:
            raise LinkClosed(errno.EIO, f"{self.name}: {e}") from None
        if data:
            self._empty = 0
            return [LinkEvent("data", data)]
        if self._fd is not None and select.select([self._fd], [], [], 0)[0]:
            self._empty += 1  # readable yet nothing to read: a hung-up line
            if self._empty > 1000:
                raise LinkClosed(errno.EIO, f"{self.name}: line hung up")
        return []

    def write_some(self, data: bytes) -> int:
        import serial

        if self._fd is not None:
            return _write_fd(self._fd, data)
        try:
            return self.ser.write(data) or 0
        except serial.SerialTimeoutException:
            return 0

    def close(self) -> None:
        try:
            self.ser.close()
        except Exception:  # noqa: BLE001
            pass


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
        if self.client is not None:
            self._drop("closed by server")
        try:
            self.listener.close()
        except OSError:
            pass


def open_link(spec: str | PortSpec, role: str = "client", baud: int = 19200) -> Link:
    """Open the link a port spec names, in ``role`` ``"client"`` or ``"server"``.

    Raises :class:`ValueError` for a bad spec and :class:`OSError` when it cannot be opened.
    """
    if role not in ("client", "server"):
        raise ValueError(f"role must be 'client' or 'server', not {role!r}")
    p = spec if isinstance(spec, PortSpec) else parse_port_spec(spec)
    if p.kind == "pty":
        return PtyLink(baud)
    if p.kind == "socket":
        if role == "server":
            return TcpServerLink(p.host, p.port)
        return TcpClientLink("127.0.0.1" if p.host == "0.0.0.0" else p.host, p.port)
    if baud not in BAUD_RATES:
        raise ValueError(f"baud {baud} is not one of {', '.join(map(str, BAUD_RATES))}")
    try:
        return SerialLink(p.text, baud)
    except OSError:
        raise
    except Exception as e:  # pyserial raises SerialException (an IOError) or ValueError
        raise OSError(errno.EIO, f"{p.text}: {e}") from None


class LinePacer:
    """Sans-IO model of a UART's capacity: a byte takes the 8N1 :func:`transmit_time` at ``baud``.

    ``reserve(n, now)`` books ``n`` bytes onto the line and returns when they may start; the
    line is then busy until :attr:`free_at`. ``baud = 0`` means unpaced (everything at once)."""

    __slots__ = ("baud", "free_at", "_per_byte")

    def __init__(self, baud: int):
        self.baud = baud
        self.free_at = 0.0
        self._per_byte = transmit_time(1, baud)

    def transmit_time(self, n: int) -> float:
        return n * self._per_byte

    def start_time(self, now: float) -> float:
        """When the next byte booked now may start."""
        return now if self.free_at <= now else self.free_at

    def reserve(self, n: int, now: float) -> float:
        start = self.start_time(now)
        self.free_at = start + n * self._per_byte
        return start

    def reset(self, now: float) -> None:
        self.free_at = now
