"""Which line model a port gets: :func:`guess_line` (and :func:`line_for`, with a user's ``--line``).

The judges' rule for a faulty line (hold what the line could have done until it is made again)
is for links that can damage bytes. Which links can (:mod:`helmcheck.judge.linemodel`):

==============================================  =======  ===========================================
the port                                        model    why
==============================================  =======  ===========================================
``pty`` (helmcheck's own), ``loop://``          clean    the kernel (or pyserial) copies the bytes
a pseudo-terminal, also behind a symlink        clean    its device is a pty slave (major 136–143)
``socket://`` to this host                      clean    a TCP connection through loopback
``socket://`` served on loopback                clean    only this host can connect
``socket://`` served on another address         noisy    a serial server may be at its far end
a serial device (``/dev/ttyUSB0``)              noisy    a UART: bits flip, bytes are lost
``socket://`` to another host, ``rfc2217://``   noisy    a serial server: a UART at its far end
any other pyserial URL                          noisy    helmcheck cannot see what is behind it
==============================================  =======  ===========================================

A TCP port on this host that bridges to a real UART (``ser2net``) is still a UART at its far end:
``--line noisy`` says so. Reads the file system and the host's addresses; writes nothing.
"""

from __future__ import annotations

import ipaddress
import os
import socket
import stat
from typing import Optional

from ..judge.linemodel import CLEAN, NOISY, LineModel, given
from .port_spec import parse_port_spec

__all__ = ["guess_line", "line_for", "line_of_sides", "is_pty_device"]

#: Linux's Unix98 pty slave majors (``Documentation/admin-guide/devices.txt``: 136–143).
_PTY_MAJORS = range(136, 144)


def is_pty_device(path: str) -> bool:
    """``path`` (or what a symlink at it points to) is a pseudo-terminal's slave device."""
    try:
        st = os.stat(path)
    except OSError:
        return os.path.realpath(path).startswith("/dev/pts/")
    if stat.S_ISCHR(st.st_mode) and os.major(st.st_rdev) in _PTY_MAJORS:
        return True
    return os.path.realpath(path).startswith("/dev/pts/")


def _local_host(host: str) -> bool:
    """``host`` is this machine: a loopback address, or one of its own names or addresses."""
    if host in ("", "0.0.0.0", "::", "localhost"):
        return True
    try:
        infos = socket.getaddrinfo(host, None)
    except OSError:
        return False
    own: set[str] = set()
    try:
        for name in {socket.gethostname(), socket.getfqdn()}:
            own.update(i[4][0] for i in socket.getaddrinfo(name, None))
    except OSError:
        pass
    for info in infos:
        addr = info[4][0]
        try:
            if ipaddress.ip_address(addr.split("%")[0]).is_loopback:
                return True
        except ValueError:
            continue
        if addr in own:
            return True
    return False


def _loopback(host: str) -> bool:
    try:
        return ipaddress.ip_address(host.split("%")[0]).is_loopback
    except ValueError:
        return host == "localhost"


def guess_line(port: str, *, serving: bool = False) -> LineModel:
    """The model of the link ``port`` names (module docstring); ``serving``: helmcheck listens on
    it (``certify backseat --port socket://HOST:PORT``) rather than connects to it."""
    if port == "pty":
        return LineModel(CLEAN, "a pty helmcheck made")
    try:
        spec = parse_port_spec(port)
    except ValueError:
        return LineModel(NOISY, f"{port}: a port helmcheck cannot read")
    if spec.kind == "socket" and serving:
        if _loopback(spec.host):
            return LineModel(CLEAN, f"a TCP port only this host can reach ({port})")
        return LineModel(NOISY, f"a TCP port other hosts can reach; a serial server may be at its far end ({port})")
    if spec.kind == "socket":
        if _local_host(spec.host):
            return LineModel(CLEAN, f"a TCP connection to this host ({port})")
        return LineModel(NOISY, f"a TCP serial server on another host ({port})")
    if spec.kind == "url":
        if port.lower().startswith("loop://"):
            return LineModel(CLEAN, f"pyserial's loop-back ({port})")
        if port.lower().startswith("rfc2217://"):
            return LineModel(NOISY, f"an RFC 2217 serial server ({port})")
        return LineModel(NOISY, f"a pyserial URL whose link helmcheck cannot see ({port})")
    if is_pty_device(spec.path):
        real = os.path.realpath(spec.path)
        shown = spec.path if real == spec.path else f"{spec.path} → {real}"
        return LineModel(CLEAN, f"a pseudo-terminal ({shown})")
    return LineModel(NOISY, f"a serial device ({spec.path})")


def line_for(port: str, choice: Optional[str] = None, *, serving: bool = False) -> LineModel:
    """The model a run uses: the user's ``--line`` when given, else :func:`guess_line`."""
    return given(choice) if choice else guess_line(port, serving=serving)


def line_of_sides(sides: list[tuple[str, bool]], choice: Optional[str] = None) -> LineModel:
    """The model of a session carried over several links (a monitor's two sides; ``(port,
    serving)`` each): noisy when any of them is, and why; the user's ``--line`` when given."""
    if choice:
        return given(choice)
    models = [guess_line(port, serving=serving) for port, serving in sides]
    noisy = [m for m in models if m.can_damage]
    if noisy:
        return LineModel(NOISY, "; ".join(m.why for m in noisy))
    return LineModel(CLEAN, "; ".join(m.why for m in models))
