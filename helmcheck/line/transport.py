"""Serial-line plumbing shared by the emulator and the certifiers: pty, serial device, TCP.

This module owns *opening* a byte link (:func:`open_link`); it knows nothing about sentences.
One spec string names a link everywhere (RH-FRM-9: a TCP byte stream carries the same bytes as a
serial line):

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

The links and their parts live in :mod:`~helmcheck.line.port_spec` (:class:`PortSpec`,
:func:`parse_port_spec`, ``BAUD_RATES``), :mod:`~helmcheck.line.link` (:class:`Link`,
:class:`LinkEvent`, :class:`LinkClosed`), :mod:`~helmcheck.line.pty_link`,
:mod:`~helmcheck.line.serial_link`, :mod:`~helmcheck.line.tcp_link` and
:mod:`~helmcheck.line.pacer` (:class:`LinePacer`); their public names are re-exported here.
"""

from __future__ import annotations

import errno

from .link import Link, LinkClosed, LinkEvent
from .pacer import LinePacer
from .port_spec import BAUD_RATES, PortSpec, parse_port_spec
from .pty_link import PtyLink
from .serial_link import SerialLink
from .tcp_link import TcpClientLink, TcpServerLink

__all__ = ["PortSpec", "parse_port_spec", "LinkEvent", "LinkClosed", "Link", "PtyLink", "SerialLink",
           "TcpClientLink", "TcpServerLink", "open_link", "LinePacer", "BAUD_RATES"]


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
