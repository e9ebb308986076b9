"""A port that vanished, opened again under the same name once it is back: :func:`wait_for_port`.

A USB-serial adapter pulled out and pushed back comes back as a *new* device under its stable
name (``/dev/serial/by-id/…``: a symbolic link udev removes and makes again); a TCP serial server
that dropped its client accepts a new connection on the same port; the line-fault relay's cut
(``cut=T@X``, :mod:`.faultrelay`) does the same to a pty behind its link. What a run that lost
its link waits for is therefore the *name* it opened: :func:`wait_for_port` tries it every
:data:`RETRY_S` until it opens or the time allowed is over.

Which names can come back (:func:`reopenable`): a device path and a ``socket://`` a client
connects to, and pyserial URLs (``rfc2217://``, whose server drops and accepts like a TCP one).
``pty`` cannot: it names a pseudo-terminal the opener makes, and a new one is another device. Nor
can ``/dev/pts/N``: the number names whichever pseudo-terminal is made next (a terminal window,
say), never the one that closed — a symbolic link to it (what the line-fault relay keeps) can.

Decisions: :data:`DEFAULT_WAIT_S` (30 s) is how long a run waits by default — a connector
re-seated or an adapter plugged back takes a few seconds, and a run waiting longer for a vehicle
that was switched off only delays the report that says so. A device path is looked for before it
is opened (no error to read while its name is gone), and an open that fails right after it
appears (udev still setting its permissions) is tried again like a missing one.
"""

from __future__ import annotations

import os
import time
from typing import Callable, Optional

from .link import Link
from .port_spec import PortSpec, parse_port_spec
from .transport import open_link

__all__ = ["DEFAULT_WAIT_S", "RETRY_S", "reopenable", "wait_for_port", "gap_event"]

#: How long a run waits for a vanished port to come back, unless told otherwise (module docstring).
DEFAULT_WAIT_S = 30.0
#: How often the port is tried while it is gone.
RETRY_S = 0.2


def reopenable(port: str | PortSpec) -> bool:
    """Whether ``port`` names something that can come back under the same name (module docstring)."""
    try:
        spec = port if isinstance(port, PortSpec) else parse_port_spec(port)
    except ValueError:
        return False
    if spec.kind == "device":
        return not spec.path.startswith("/dev/pts/")
    return spec.kind in ("socket", "url") and not spec.text.lower().startswith("loop://")


def wait_for_port(port: str | PortSpec, *, baud: int, within_s: float, role: str = "client",
                  clock: Callable[[], float] = time.monotonic, sleep: Callable[[float], None] = time.sleep,
                  retry_s: float = RETRY_S) -> tuple[Optional[Link], str]:
    """Open ``port`` as soon as it can be, trying every ``retry_s`` for ``within_s`` seconds:
    ``(link, "")``, or ``(None, why)`` with the last reason it could not be opened."""
    spec = port if isinstance(port, PortSpec) else parse_port_spec(port)
    end = clock() + max(0.0, within_s)
    why = "not tried"
    while True:
        if spec.kind == "device" and not os.path.exists(spec.path):
            why = "no such device"
        else:
            try:
                return open_link(spec, role=role, baud=baud), ""
            except (OSError, ValueError) as e:
                why = getattr(e, "strerror", None) or str(e)
        left = end - clock()
        if left <= 0:
            return None, why
        sleep(min(retry_s, left))


def gap_event(gap: dict) -> dict:
    """A run's ``link_gaps`` entry (``lost_at_s``, ``back_at_s``, ``gap_s``, ``port``, and what it
    ``cut`` or which ``side``) as a ``results.json`` event (kind ``note``) for the report's timeline."""
    what = f"the {gap['side']} side's port {gap['port']}" if gap.get("side") else str(gap.get("port"))
    if gap.get("gap_s") is not None:
        text = f"link gap: {what} gone {gap['gap_s']:.1f} s"
    else:
        text = f"link gap: {what} gone, not back"
    if gap.get("cut"):
        text += f" (it cut {gap['cut']})"
    return {"t": max(0.0, round(float(gap["lost_at_s"]), 6)), "kind": "note", "label": text[:120]}
