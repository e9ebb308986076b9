"""Opening the port a user named, once, at start: every command treats a bad one alike.

Decision (contracts table, "Failures and exit codes"): a port the user typed that cannot be
opened when the command starts — a device path that does not exist or cannot be opened, a
URL with a scheme nobody handles, a TCP serial server that refuses the connection — is a
:class:`~helmcheck.failures.PathError` (exit 64, ``cannot open PORT: reason``) in ``emulate``,
``certify vehicle``, ``certify backseat`` and ``replay`` alike, and nothing is written. A link
that opened and fails later is a link fault (exit 2, in the run's report). The link opened
here is the one the command uses: a serial device is opened once (opening it again could reset
the device on the other end, a TCP server would see two clients).
"""

from __future__ import annotations

import os
from typing import Callable, Optional

from ..line.transport import Link, PortSpec, open_link, parse_port_spec
from ..failures import PathError, UsageError

__all__ = ["port_spec", "open_port"]


def port_spec(text: str, option: str = "--port") -> PortSpec:
    """Read a port spec; a malformed one is a :class:`UsageError`."""
    try:
        return parse_port_spec(text)
    except ValueError as e:
        raise UsageError(f"{option}: {e}") from None


def open_port(spec: PortSpec, *, role: str, baud: int, selectable: bool = False,
              opener: Optional[Callable[[], Link]] = None) -> Link:
    """Open ``spec`` (or call ``opener``); any failure is a :class:`PathError` naming the port.
    With ``selectable`` the link must have a descriptor to wait on (an I/O loop's link)."""
    if spec.kind == "device" and not os.path.exists(spec.path):
        raise PathError(f"cannot open {spec.text}: no such device or file")
    try:
        link = opener() if opener is not None else open_link(spec, role=role, baud=baud)
    except (OSError, ValueError) as e:
        why = getattr(e, "strerror", None) or str(e)
        prefix = f"{spec.text}: "
        if why.startswith(prefix):
            why = why[len(prefix):]
        raise PathError(f"cannot open {spec.text}: {why}") from None
    try:
        if selectable:
            link.fileno()
    except OSError:
        link.close()
        raise PathError(f"cannot open {spec.text}: not selectable (use pty, a device or socket://)") from None
    return link
