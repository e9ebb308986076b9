"""A side of a monitored line whose device vanished: opened again under its name, the gap recorded.

A USB-serial adapter of a tap or of the in-line relay can drop out (a connector moved) and come
back as a new device under its ``/dev/serial/by-id`` name; a TCP serial server can drop the
connection. :class:`SideGaps` is what the monitor's :class:`~helmcheck.line.relay.Relay` calls for
such a side (its ``reopen``): the relay sets the side aside and goes on relaying and recording
the other one — the judges go on judging what they see — while :meth:`SideGaps.reopen` tries the
side's port (:func:`helmcheck.line.reopen.wait_for_port`) every
:data:`~helmcheck.line.relay.REPLUG_RETRY_S`, for ``wait_s`` seconds (``--reconnect-wait``). A
side that comes back is read (and, in line, written) again where it left off; one that does not
is gone for good and the session goes on with one side, as before.

What the judges are told (notes in the session's log, written from the relay's thread in order
with the bytes; their words are the wire log's, :mod:`helmcheck.judge.wire`):

* when a side goes: ``link gap: …`` (evidence), ``run resumed: with one side only: …`` (the
  vehicle's state and what the backseat knew are unknown from here, a command on the line at the
  cut is not judged) and ``held: …``: from here a violation either judge sees is held, because
  a line seen from one side only can show one that is not there (a vehicle answering a poll the
  monitor did not see, a backseat acting on a report it did);
* when it is back: ``unconfirmed: seen while … was gone …`` (the held violations are booked
  INCONCLUSIVE, naming the gap) and ``run resumed: … is back after a gap of …``: from the return
  the judges start afresh, and an interval that spans the gap is never judged;
* a side that does not come back: ``link gap: … did not come back …``; holding goes on to the
  end of the session, where :meth:`SideGaps.close` books what was held INCONCLUSIVE the same way.

Decisions: holding covers the whole gap and both judges (passes are still counted: a line seen
whole that meets its clause meets it); while two sides are gone at once, holding ends when the
last is back. Which ports can come back is :func:`helmcheck.line.reopen.reopenable`'s (a device,
``socket://`` the monitor connects to, a pyserial URL); a ``pty`` the monitor made and the
backseat's listening ``socket://`` side never close (a client that leaves is a ``disconnect``).
"""

from __future__ import annotations

import threading
import time
from collections import deque
from typing import Callable, Optional

from ..line.link import Link, LinkClosed
from ..line.reopen import reopenable, wait_for_port
from ..line.transport import parse_port_spec

__all__ = ["SideGaps"]


class SideGaps:
    """The sides of one monitored session that vanished (module docstring). ``note(t, text)``
    writes a note at ``t`` seconds of the session; ``ports`` and ``roles`` are each side's port
    spec and how it is opened (:func:`helmcheck.monitor.session.side_roles`)."""

    def __init__(self, ports: dict[str, str], roles: dict[str, str], *, baud: int, wait_s: float,
                 note: Callable[[float, str], None], t0: float, clock: Callable[[], float] = time.monotonic):
        self.ports = dict(ports)
        self.roles = dict(roles)
        self.baud = baud
        self.wait_s = wait_s
        self.note = note
        self.t0 = t0
        self.clock = clock
        #: each side's gap under way: its entry in :attr:`gaps`
        self.open: dict[str, dict] = {}
        self.gaps: list[dict] = []  #: every gap: side, port, when lost and back (session seconds), how long
        self.links: list[Link] = []  #: links opened again (the caller closes them at the end)
        self.messages: deque[str] = deque()  #: for the terminal, taken by the main thread
        self._held: list[dict] = []  #: the gaps of the holding under way (since no side was gone)
        self._lock = threading.Lock()

    def can_come_back(self, side: str) -> bool:
        spec = parse_port_spec(self.ports[side])
        return self.wait_s > 0 and reopenable(spec) and not (spec.kind == "socket" and self.roles[side] == "server")

    @property
    def any(self) -> bool:
        """Whether a side of this session can come back at all (else the relay needs no ``reopen``)."""
        return any(self.can_come_back(side) for side in self.ports)

    # ------------------------------------------------------------------ the relay's thread
    def event(self, t: float, kind: str, side: str) -> None:
        """A relay event at session time ``t`` (``lost``, ``reopened``, ``closed``)."""
        if kind == "lost" and self.can_come_back(side):
            self._lost(t, side)
        elif kind == "reopened" and side in self.open:
            self._back(t, side)
        elif kind == "closed" and side in self.open:
            self._given_up(t, side)

    def reopen(self, side: str) -> Optional[Link]:
        """The relay's ``reopen``: the side's port opened again, None while it is not back,
        :class:`LinkClosed` once the wait is over (or for a side that cannot come back)."""
        gap = self.open.get(side)
        if gap is None or not self.can_come_back(side):
            raise LinkClosed(0, f"the {side} side's port {self.ports[side]} cannot come back")
        if self.clock() - self.t0 - gap["lost_at_s"] >= self.wait_s:
            raise LinkClosed(0, f"the {side} side's port {self.ports[side]} did not come back within "
                                f"{self.wait_s:g} s")
        link, _ = wait_for_port(self.ports[side], baud=self.baud, within_s=0.0, role=self.roles[side])
        if link is not None:
            with self._lock:
                self.links.append(link)
        return link

    def _lost(self, t: float, side: str) -> None:
        port = self.ports[side]
        first = not self.open
        gap = {"side": side, "port": port, "lost_at_s": round(t, 6), "back_at_s": None, "gap_s": None}
        self.open[side] = gap
        self.gaps.append(gap)
        self._held = [gap] if first else [*self._held, gap]
        self.note(t, f"link gap: the {side} side's port {port} is gone (its link closed); waiting up to "
                     f"{self.wait_s:g} s for it (--reconnect-wait); what it sends is not seen meanwhile")
        self.note(t, f"run resumed: with one side only: the {side} side's port {port} is gone at {t:.3f} s; "
                     f"what it sends is not seen until it is back")
        if first:
            self.note(t, f"held: the {side} side is gone: what the other side shows alone is judged, a "
                         f"violation held (the gap may explain it)")
        self.messages.append(f"the {side} side's port {port} is gone; waiting up to {self.wait_s:g} s for it "
                             f"(the other side is still relayed and judged)")

    def _back(self, t: float, side: str) -> None:
        gap = self.open.pop(side)
        lost = gap["lost_at_s"]
        gap.update(back_at_s=round(t, 6), gap_s=round(t - lost, 6))
        if not self.open:
            self.note(t, self._unconfirmed())
        self.note(t, f"run resumed: the {side} side's port {gap['port']} is back after a gap of {t - lost:.2f} s "
                     f"({lost:.3f} s to {t:.3f} s); what it sent meanwhile was not seen")
        self.messages.append(f"the {side} side's port {gap['port']} is back after {t - lost:.1f} s")

    def _given_up(self, t: float, side: str) -> None:
        gap = self.open[side]
        gap["gone_for_good"] = True
        self.note(t, f"link gap: the {side} side's port {gap['port']} did not come back within {self.wait_s:g} s; "
                     f"the session goes on with one side")
        self.messages.append(f"the {side} side's port {gap['port']} did not come back within {self.wait_s:g} s; "
                             f"going on with one side")

    def _unconfirmed(self) -> str:
        spans = "; ".join(f"the {g['side']} side's port {g['port']} from {g['lost_at_s']:.3f} s to "
                          + (f"{g['back_at_s']:.3f} s" if g["back_at_s"] is not None else "the session's end")
                          for g in self._held)
        return f"unconfirmed: seen while a side of the line was gone ({spans}): the gap may explain it"

    # ------------------------------------------------------------------ the end
    def close(self, t: float) -> None:
        """The session ends (the relay stopped): what is still held is booked INCONCLUSIVE."""
        if self.open:
            self.note(t, self._unconfirmed())
            self.open.clear()
