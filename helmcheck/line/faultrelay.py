"""The line-fault relay: two ports, the line between them spoiled on purpose, every fault logged.

:class:`FaultRelay` owns a running line-fault relay's ports and files: it opens both sides
(``pty`` makes a new pseudo-terminal; a ``socket://`` backseat side listens, a ``socket://``
vehicle side connects; a device is opened at ``baud``), points a stable symbolic link at a pty
side if asked (``link``: as ``/dev/serial/by-id`` names an adapter), runs the
:class:`~.relay.Relay` thread with an :class:`~.impair.ImpairedLine` stage, and writes the
:class:`~.relaylog.RelayLog`. It is what ``helmcheck relay`` runs, and what
:func:`impaired_line` runs for a test (:mod:`.faultline`).

A cut (``cut=T@X``) unplugs the side ``cut_side`` (the backseat's by default: the side a tester
or a backseat opens) and plugs it back T seconds later, as a USB adapter pulled out and pushed
back in: a pty side is closed (whoever has it open reads end-of-file or an error) and its link
removed; then a *new* pty is made and the link points to it. A listening ``socket://`` side
stops listening (the client's connection drops, a new one is refused) and listens again on the
same port; a connecting one disconnects and connects again; a device is closed and opened again
(its far end sees a dead line, not a vanished device). ``on_port(side, name)`` is told each pty
side's name, at the start and after each cut.

Notes of its own (besides the faults the stage notes): the start (ports, impairment, seed), each
side unplugged and back, a side closed, the stop. Decisions: a link path that exists and is not
a symbolic link is refused (``FileExistsError``), never replaced; the links are removed at
:meth:`FaultRelay.stop`.
"""

from __future__ import annotations

import os
import time
from datetime import datetime, timezone
from pathlib import Path
from typing import Callable, Optional

from .. import __version__
from ..grammar.faultnote import FaultNote, read_fault_note
from ..judge.linemodel import NOISY, LineModel, line_note
from .impair import ImpairedLine
from .impair_spec import LineFaults, parse_impairment
from .link import Link
from .port_spec import PortSpec, parse_port_spec
from .pty_link import PtyLink
from .relay import SIDES, Relay
from .relaylog import RelayLog
from .tcp_link import TcpClientLink, TcpServerLink
from .transport import open_link

__all__ = ["FaultRelay", "side_role", "point_link"]


def side_role(side: str, spec: PortSpec) -> str:
    """How a side is opened: a ``socket://`` backseat side listens (the backseat connects as to a
    serial server); everything else is opened as a client (``pty`` makes a new pty either way)."""
    return "server" if side == "backseat" and spec.kind == "socket" else "client"


def point_link(path: Path, target: str) -> None:
    """Make ``path`` a symbolic link to ``target``, atomically (replacing an older link).
    ``FileExistsError`` when ``path`` is something other than a symbolic link."""
    if os.path.lexists(path) and not os.path.islink(path):
        raise FileExistsError(f"{path} exists and is not a symbolic link")
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        os.unlink(tmp)
    except FileNotFoundError:
        pass
    os.symlink(target, tmp)
    os.replace(tmp, path)


def _unlink(path: Path) -> None:
    try:
        if os.path.islink(path):
            os.unlink(path)
    except OSError:
        pass


class FaultRelay:
    """A line-fault relay between ``backseat`` and ``vehicle`` (port specs); see the module docstring.

    ``faults`` is a :class:`~.impair_spec.LineFaults` or an ``--impair`` text; ``seed``
    overrides its seed. :meth:`start` opens everything (``OSError``/``ValueError`` naming what
    failed, nothing left open); :meth:`stop` ends it; a ``with`` block does both."""

    def __init__(self, backseat: str, vehicle: str, faults: LineFaults | str = "", *,
                 link: Optional[str | Path] = None, vehicle_link: Optional[str | Path] = None,
                 baud: int = 19200, wire_log: Optional[str | Path] = None, cut_side: str = "backseat",
                 seed: Optional[int] = None, realtime: bool = True, clock: Callable[[], float] = time.monotonic,
                 on_port: Optional[Callable[[str, str], None]] = None):
        self.faults = parse_impairment(faults) if isinstance(faults, str) else faults
        if seed is not None:
            self.faults = self.faults.with_seed(seed)
        self.specs = {"backseat": parse_port_spec(backseat), "vehicle": parse_port_spec(vehicle)}
        self.links: dict[str, Optional[Path]] = {"backseat": Path(link) if link else None,
                                                  "vehicle": Path(vehicle_link) if vehicle_link else None}
        for side, path in self.links.items():
            if path is not None and self.specs[side].kind != "pty":
                raise ValueError(f"a link names a pty the relay makes; the {side} side is {self.specs[side].text}")
            if path is not None and os.path.lexists(path) and not os.path.islink(path):
                raise FileExistsError(f"{path} exists and is not a symbolic link")
        if cut_side not in SIDES:
            raise ValueError(f"cut_side must be one of {SIDES}, not {cut_side!r}")
        self.baud = baud
        self.wire_log = Path(wire_log) if wire_log else None
        self.cut_side = cut_side
        self.realtime = realtime
        self.clock = clock
        self.on_port = on_port
        self.sides: dict[str, Link] = {}
        self.names: dict[str, str] = {}  #: each side's present port name (a pty's path)
        self.relay: Optional[Relay] = None
        self.stage: Optional[ImpairedLine] = None
        self.log: Optional[RelayLog] = None
        self.t0 = 0.0

    # ------------------------------------------------------------------ ports
    @property
    def port(self) -> str:
        """What the backseat side's user opens: its link if it has one, else its port's name."""
        return self.port_of("backseat")

    @property
    def vehicle_port(self) -> str:
        return self.port_of("vehicle")

    def port_of(self, side: str) -> str:
        path = self.links[side]
        return str(path) if path is not None else self.names.get(side, self.specs[side].text)

    def _open(self, side: str) -> Link:
        spec = self.specs[side]
        if spec.kind == "socket" and side_role(side, spec) == "server":
            return TcpServerLink(spec.host, spec.port)
        if spec.kind == "socket":
            return TcpClientLink("127.0.0.1" if spec.host == "0.0.0.0" else spec.host, spec.port, timeout=2.0)
        if spec.kind == "pty":
            return PtyLink(self.baud)
        return open_link(spec, role="client", baud=self.baud)

    def _plugged(self, side: str, link: Link, announce: bool = True) -> None:
        """A side (re)opened: its name, its link, the owner told."""
        self.sides[side] = link
        self.names[side] = link.name
        if self.specs[side].kind == "pty":
            if self.links[side] is not None:
                point_link(self.links[side], link.name)
            if announce and self.on_port is not None:
                self.on_port(side, link.name)

    # ------------------------------------------------------------------ start, stop
    def start(self) -> "FaultRelay":
        """Open both sides, the links and the log, and start the relay. A side that cannot be
        opened raises ``OSError`` whose ``filename`` is its port and ``strerror`` why."""
        try:
            for side in SIDES:
                try:
                    link = self._open(side)
                except (OSError, ValueError) as e:
                    text = self.specs[side].text
                    why = getattr(e, "strerror", None) or str(e)
                    why = why[len(text) + 2:] if why.startswith(text + ": ") else why
                    raise OSError(getattr(e, "errno", None) or 0, why, text) from None
                if isinstance(link, TcpServerLink):  # port 0: the port it got is the one to listen on again
                    self.specs[side] = parse_port_spec(link.name)
                self._plugged(side, link, announce=False)
            stream = open(self.wire_log, "w", encoding="utf-8") if self.wire_log is not None else None
        except BaseException:
            self._close_sides()
            raise
        for side in SIDES:
            if self.specs[side].kind == "pty" and self.on_port is not None:
                self.on_port(side, self.names[side])
        self.t0 = self.clock()
        started = datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%S.%fZ")
        line_baud = self.faults.to_vehicle.baud or self.baud
        meta = [f"started {started}  port {self.names['backseat']} {self.names['vehicle']}  baud {line_baud}  "
                f"time_scale 1",
                f"helmcheck {__version__} relay: impair {self.faults.text or '(none)'!r} seed {self.faults.seed}",
                f"clock monotonic {self.t0:.6f} (the records' time 0)"]
        self.log = RelayLog(stream, meta, self.t0)
        self.log.note(self.t0, f"relay started: backseat {self._shown('backseat')}, vehicle {self._shown('vehicle')}; "
                               f"impair {self.faults.text or '(none)'!r}, seed {self.faults.seed}; "
                               f"a cut unplugs the {self.cut_side} side")
        self.log.note(self.t0, line_note(LineModel(NOISY, "helmcheck relay damages the line (its notes say how)")))
        self.stage = ImpairedLine(self.faults, self.t0)
        self.relay = Relay(self.sides["backseat"], self.sides["vehicle"], forward=True, on_bytes=self.log.bytes,
                           on_event=self._event, clock=self.clock, name="helmcheck-fault-relay",
                           realtime=self.realtime, stage=self.stage, on_note=self.log.note, cut_side=self.cut_side,
                           unplug=self._unplug, replug=self._replug, on_idle=self.log.idle)
        self.relay.start()
        self.relay.started()
        return self

    def _shown(self, side: str) -> str:
        link = self.links[side]
        return f"{self.names[side]} ({link})" if link is not None else self.names[side]

    def stop(self, why: str = "", timeout: float = 2.0) -> None:
        """End the relay, close both sides, remove the links, close the log (its last note says
        ``why`` when given)."""
        if self.relay is not None:
            self.relay.stop(timeout)
        self._close_sides()
        if self.log is not None:
            self.log.note(self.clock(), f"relay stopped{': ' + why if why else ''}")
            self.log.close()

    def _close_sides(self) -> None:
        for link in self.sides.values():
            link.close()
        for path in self.links.values():
            if path is not None:
                _unlink(path)

    def __enter__(self) -> "FaultRelay":
        return self.start()

    def __exit__(self, *exc) -> None:
        self.stop()

    # ------------------------------------------------------------------ while it runs (the relay's thread)
    def _note(self, text: str) -> None:
        self.log.note(self.clock(), text)  # type: ignore[union-attr]

    def _event(self, t: float, kind: str, side: str) -> None:
        if kind in ("unplugged", "replugged"):
            return  # noted by _unplug/_replug, with the ports' names
        self.log.note(t, f"relay: the {side} side: {kind}")  # type: ignore[union-attr]

    def _unplug(self, side: str, link: Link) -> None:
        link.close()
        path = self.links[side]
        if path is not None:
            _unlink(path)
        self._note(f"relay: the {side} side's port {self._shown(side)} unplugged")

    def _replug(self, side: str) -> Optional[Link]:
        link = self._open(side)
        self._plugged(side, link)
        self._note(f"relay: the {side} side's port is back: {self._shown(side)}")
        return link

    # ------------------------------------------------------------------ what it did
    def notes(self) -> list[tuple[float, str]]:
        """Every note so far: (seconds since the start, text)."""
        return [(t - self.t0, text) for t, text in list(self.log.notes)] if self.log is not None else []

    def fault_notes(self) -> list[tuple[float, FaultNote]]:
        """The line-fault notes so far, read back: (seconds since the start, note)."""
        return [(t, f) for t, f in ((t, read_fault_note(text)) for t, text in self.notes()) if f is not None]

    @property
    def stats(self) -> dict:
        """What the stage did (``faults``) and what the relay moved (``relay``), per direction."""
        out = {"faults": self.stage.stats if self.stage is not None else {},
               "relay": self.relay.stats if self.relay is not None else {}}
        return out

