"""The reference emulator's core driven in virtual time, recorded as a real vehicle's line is.

For tests that need a conforming vehicle in a precise situation (a fix just as it reaches a
waypoint, a violation just after an unseen arrival): :class:`VirtualVehicle` feeds the core a
framed command at the present virtual time ``now`` and ticks it until the answer's bytes are out;
:meth:`VirtualVehicle.write` keeps the wire log without the emulator's own notes (``plant:``,
model notes), so ``check-log`` has to judge it from the wire alone. :func:`certifier_session` puts
the certifier's own session (its link, recorder and vehicle observer) in front of a core over a
:class:`~helmcheck.certify.vehicle.virtual.VirtualLine`, for tests of the certifier's steps.
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import Optional

from helmcheck.emulator.core import EmulatorCore
from helmcheck.emulator.missionfile import DirectoryCatalog, builtin_dir
from helmcheck.grammar import checksum_hex
from helmcheck.grammar.wirelog import WireLogWriter
from helmcheck.profile import Profile


def certifier_session(core: EmulatorCore, k: float):
    """The certifier's session on ``core`` over a line in virtual time at ``k`` (its profile's baud),
    every line judged by a vehicle observer of every vehicle clause."""
    from helmcheck.certify.vehicle import link as tester_link
    from helmcheck.certify.vehicle.session import Session
    from helmcheck.certify.vehicle.virtual import VirtualLine
    from helmcheck.clauses import vehicle_clauses
    from helmcheck.judge import Ledger
    from helmcheck.judge.vehicle import VehicleObserver
    from helmcheck.line.recorder import Recorder

    profile = core.profile
    line = VirtualLine(core, profile.baud)
    observer = VehicleObserver(profile, Ledger([c.id for c in vehicle_clauses()]), time_scale=k, baud=profile.baud)
    link = tester_link.TesterLink(line, profile, Recorder(None, [], [observer]), clock=line.clock)
    return Session(link, profile, k, observer)


def frame(body: str) -> bytes:
    return f"${body}*{checksum_hex(body)}\r\n".encode()


def osi_fields(data: bytes) -> Optional[list]:
    """The fields of the first ``$OSI`` in ``data`` (index 0 is ``OSI``), or None."""
    for line in data.split(b"\r\n"):
        if line.startswith(b"$OSI,"):
            return line[1:line.index(b"*")].decode().split(",")
    return None


class VirtualVehicle:
    """The emulator core at 19200 baud, time scale 1, its clock set by hand (``now``); its model
    ``model_factory`` (a faulty vehicle's) when given; ``settings``: the emulator's freedoms
    (:class:`~helmcheck.emulator.freedoms.EmulatorSettings`)."""

    def __init__(self, profile: Profile, model_factory=None, settings=None):
        self.buf = io.StringIO()
        log = WireLogWriter(self.buf, ("started 2026-11-26T08:00:00.000000Z  port virtual  baud 19200  "
                                       "time_scale 1",))
        self.core = EmulatorCore(profile, DirectoryCatalog([builtin_dir()]), start=0.0, time_scale=1.0,
                                 baud=19200, log=log, settings=settings,
                                 **({"model_factory": model_factory} if model_factory else {}))
        self.now = 0.0

    def send(self, body: str) -> bytes:
        """``$body*hh`` at ``now``; the core's answer, its bytes at the line's pace."""
        out = self.core.feed(frame(body), self.now)
        for _ in range(40):
            wake = self.core.next_wakeup()
            if wake is None or wake > self.now + 0.2:
                break
            out += self.core.tick(wake)
        return out

    def write(self, path: Path) -> Path:
        path.write_text("".join(ln for ln in self.buf.getvalue().splitlines(keepends=True) if " ! " not in ln))
        return path
