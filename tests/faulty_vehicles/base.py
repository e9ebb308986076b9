"""The faulty-vehicle toolkit: a profile, the :class:`Mutant` record, a core factory and a server.

A mutant is the emulator's core (:class:`~helmcheck.emulator.core.EmulatorCore`) or
its model (:class:`~helmcheck.model.vehicle.VehicleModel`) with one behaviour changed, served
behind a real pseudo-terminal by the emulator's own I/O loop in a thread (:func:`serve`). The
mutants themselves live in one module per family of clauses (:mod:`.wire`, :mod:`.control`);
:mod:`tests.faulty_vehicles` gathers them in :data:`~tests.faulty_vehicles.MUTANTS`.
"""

from __future__ import annotations

import threading
import time
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Callable

from helmcheck.emulator.core import EmulatorCore
from helmcheck.emulator.missionfile import DirectoryCatalog, builtin_dir
from helmcheck.emulator.server import Server
from helmcheck.line.transport import PtyLink
from helmcheck.grammar import checksum_hex
from helmcheck.model.vehicle import VehicleModel
from helmcheck.profile import Profile, emulator_profile

__all__ = ["Mutant", "serve", "make_core", "EMU_PROFILE", "reframe", "body", "Model", "TIME_SCALES", "TIMED_SCALES"]

#: The profile the emulators run (and the tester is given): the built-in emulator's own ($OXFLT
#: declared, its end and SRP missions named), at 115200 baud.
EMU_PROFILE = emulator_profile().replace(baud=115200)
#: Every mutant is certified at two time scales (the judges must not depend on one).
TIME_SCALES = (25.0, 50.0)
#: For mutants whose selection holds a 10 s timer (RH-SRV-4, RH-PRM-4): at k = 50 the observer's
#: own slack (k x tens of milliseconds) nears half the duration, so a conforming timer would be
#: honestly NOT-TESTED, not PASS (RH-TIM-1's last sentence); these are certified slower.
TIMED_SCALES = (10.0, 25.0)


def reframe(line: bytes, body: bytes, lower: bool = False) -> bytes:
    """``$body*HH`` CR LF with ``body``'s checksum (upper-case hex unless ``lower``)."""
    ck = checksum_hex(body)
    return b"$" + body + b"*" + (ck.lower() if lower else ck).encode() + b"\r\n"


def body(line: bytes) -> bytes:
    """What is between ``$`` and ``*``."""
    return line[1:line.index(b"*")]


class Model(VehicleModel):
    """Base of the model mutants."""


@dataclass(frozen=True)
class Mutant:
    name: str
    clause: str  #: the clause a correct certifier fails it on
    select: tuple  #: clauses to certify (fast)
    core: type = EmulatorCore
    model: type | None = None
    profile_changes: tuple = ()  #: (key, value) pairs for the *vehicle's* profile
    time_scales: tuple = TIME_SCALES  #: k for the emulator and the tester (higher for long missions)
    #: the run fails its clause (and :attr:`also`, the other clauses that name the fault) alone
    only: bool = False
    also: tuple = ()
    #: every selected clause is judged, as on the conforming core, and the restore is verified: the
    #: fault (a bad field of every report) blinds the tester to nothing else
    blinds_nothing: bool = False



def make_core(m: "Mutant | None", time_scale: float, start: float) -> EmulatorCore:
    profile: Profile = EMU_PROFILE.replace(time_scale=time_scale, **dict(m.profile_changes if m else ()))
    catalog = DirectoryCatalog([builtin_dir()])
    cls = m.core if m else EmulatorCore
    model = m.model if m is not None and m.model is not None else VehicleModel
    return cls(profile, catalog, start=start, time_scale=time_scale, baud=115200, model_factory=model)


@contextmanager
def serve(core_factory: Callable[[float], EmulatorCore]):
    """Serve a core behind a new pty in a thread; yields the pty's path (what a client opens)."""
    link = PtyLink(baud=115200)
    core = core_factory(time.monotonic())
    server = Server(link, core, install_signals=False)
    th = threading.Thread(target=server.run, name="faulty-vehicle", daemon=True)
    th.start()
    try:
        yield link.name
    finally:
        server.stop()
        th.join(5)
        link.close()
