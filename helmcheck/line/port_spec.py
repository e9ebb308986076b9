"""Port specs: parsing a ``--port`` value (``pty``, a device path, ``socket://HOST:PORT``, another
pyserial URL) into a :class:`PortSpec`, and the baud rates a serial device may be opened at.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

#: Baud rates a serial device may be opened at (RH-FRM-9 plus 38400).
BAUD_RATES = (9600, 19200, 38400, 57600, 115200)
_SOCKET_RE = re.compile(r"^socket://(\[[^\]]+\]|[^:/\[\]]*):(\d{1,5})/?$")
_URL_RE = re.compile(r"^[a-z][a-z0-9+.-]*://", re.I)


@dataclass(frozen=True)
class PortSpec:
    """A parsed ``--port`` value. ``kind`` is ``pty``, ``socket``, ``device``, ``url`` or
    ``announced`` (with ``--exec``: the started implementation prints its own port)."""

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
    if text == "announced":  # with --exec: the implementation prints "port: URL" (launcher)
        return PortSpec("announced", text)
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
