"""Faulty vehicles for the certifier's self-test: the reference emulator with one fault each.

Each mutant is the emulator's core (:class:`~helmcheck.conformance.emulator.core.EmulatorCore`)
or its model with one behaviour changed, served behind a real pseudo-terminal by the emulator's
own I/O loop in a thread (:func:`serve`). :data:`MUTANTS` lists them with the clause a correct
certifier must fail them on and the ``--select`` that reaches the fault quickly. They live in the
tests, not the product: the product's emulator stays conforming.
"""

from __future__ import annotations

import threading
import time
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Callable

from helmcheck.conformance.emulator.core import EmulatorCore
from helmcheck.conformance.emulator.missionfile import DirectoryCatalog, builtin_dir
from helmcheck.conformance.emulator.server import Server
from helmcheck.conformance.transport import PtyLink
from helmcheck.grammar import checksum_hex
from helmcheck.grammar import sentences as s
from helmcheck.model.vehicle import VehicleModel
from helmcheck.profile import DEFAULT, Profile

__all__ = ["Mutant", "MUTANTS", "serve", "make_core", "EMU_PROFILE"]

#: The profile the emulators run (and the tester is given): $OXFLT declared.
EMU_PROFILE = DEFAULT.replace(fault_injection="oxflt", baud=115200)


def _reframe(line: bytes, body: bytes, lower: bool = False) -> bytes:
    ck = checksum_hex(body)
    return b"$" + body + b"*" + (ck.lower() if lower else ck).encode() + b"\r\n"


def _body(line: bytes) -> bytes:
    return line[1:line.index(b"*")]


# ============================================================================ core mutants

class AcceptsBadChecksum(EmulatorCore):
    """RH-FRM-2: acts on a line whose checksum is wrong."""

    def _line(self, raw, now, v):
        if b"*" in raw and raw.startswith(b"$"):
            raw = _reframe(raw, _body(raw))
        return super()._line(raw, now, v)


class LowercaseOut(EmulatorCore):
    """RH-FRM-3: writes its checksums in lower-case hex."""

    def _send(self, raw, now):
        return super()._send(_reframe(raw, _body(raw), lower=True), now)


class NoAckForOsd(EmulatorCore):
    """RH-ACK-1: sends the data of an $OSD but never its $ACK,8."""

    def _send(self, raw, now):
        if raw.startswith(b"$ACK,8,"):
            return None
        return super()._send(raw, now)


class AckBeforeData(EmulatorCore):
    """RH-ACK-5: answers $OSD with the $ACK first, then the data."""

    def _command(self, item, now, v):
        if isinstance(item, s.OSD):
            sent = []
            real = self._send
            self._send = lambda raw, now: sent.append(raw)  # type: ignore[assignment]
            try:
                super()._command(item, now, v)
            finally:
                del self._send
            acks = [r for r in sent if r.startswith(b"$ACK")]
            for r in acks + [r for r in sent if not r.startswith(b"$ACK")]:
                real(r, now)
            return
        super()._command(item, now, v)


class Mp(EmulatorCore):
    """RH-OUT-1: spells the manual-park mode ``Mp`` in its $OSI."""

    def _send(self, raw, now):
        if raw.startswith(b"$OSI,") and b",mP," in raw:
            raw = _reframe(raw, _body(raw).replace(b",mP,", b",Mp,"))
        return super()._send(raw, now)


# ============================================================================ model mutants

class _Model(VehicleModel):
    pass


class ServoTimeoutIgnored(_Model):
    """RH-SRV-4: an $OMS never times out."""

    def receive(self, item, now):
        out = super().receive(item, now)
        if isinstance(item, s.OMS) and self.mode == "A":
            self.timers.disarm("remote")
        return out


class ServoResumesS(_Model):
    """RH-INT-2: when the servo times out the vehicle stops (S) instead of resuming the mission."""

    def _release(self, row, now):
        was_servo = self.servo is not None
        super()._release(row, now)
        if was_servo:
            self.mode = "S"
            self.mission = None
            self.mission_mode = "N"
            self.timers.disarm("park")


class OpkKeptAfterInterrupt(_Model):
    """RH-INT-3: a $OPK park interrupted by $OMS comes back when the servo ends."""

    saved = None

    def receive(self, item, now):
        if self.mode == "mP" and isinstance(item, s.OMS):
            self.saved = self.opk
        return super().receive(item, now)

    def _release(self, row, now):
        saved = self.saved if self.servo is not None else None
        super()._release(row, now)
        if saved is not None:
            self.saved = None
            self.mode = "mP"
            self.opk = saved
            self.opk_seconds = saved.minutes * 60
            self.timers.arm("opk", now, self.opk_seconds)


class LockoutAcceptsOms(_Model):
    """RH-SAF-1: an $OMS during the lockout is accepted."""

    def receive(self, item, now):
        if isinstance(item, s.OMS) and self.phase == "lockout":
            self.phase = "none"
            try:
                return super().receive(item, now)
            finally:
                if self.timers.armed("lockout"):
                    self.phase = "lockout"
        return super().receive(item, now)


class SettingNotStored(_Model):
    """RH-SET-2: an $ORWSET write is acknowledged but not stored."""

    def receive(self, item, now):
        if isinstance(item, s.ORWSET) and item.access == "W":
            before = self.settings.copy()
            out = super().receive(item, now)
            self.settings = before
            return out
        return super().receive(item, now)


class OmloadDotDot(EmulatorCore):
    """RH-MSN-1: $OMLOAD with a '..' component loads the file by its last name."""

    def _line(self, raw, now, v):
        if raw.startswith(b"$OMLOAD,") and b".." in raw and b"*" in raw:
            name, _, rest = _body(raw)[len(b"OMLOAD,"):].partition(b",")
            raw = _reframe(raw, b"OMLOAD," + name.replace(b"\\", b"/").split(b"/")[-1] + b"," + rest)
        return super()._line(raw, now, v)


class WrongErrNumber(_Model):
    """RH-ACK-3: $OMS with bad fields is rejected with 21 instead of its own 20."""

    def receive(self, item, now):
        return [s.ACK(9, 1, 21) if isinstance(r, s.ACK) and (r.type, r.err) == (9, 20) else r
                for r in super().receive(item, now)]

    def _receive_error(self, err):
        return [s.ACK(9, 1, 21) if isinstance(r, s.ACK) and (r.type, r.err) == (9, 20) else r
                for r in super()._receive_error(err)]


class PrimitiveNeverNeutral(_Model):
    """RH-PRM-4: after an $OMP from S times out, $OSI keeps the last fins and motor."""

    last = None

    def receive(self, item, now):
        if isinstance(item, s.OMP):
            self.last = item.actuators.upper()
        return super().receive(item, now)

    def osi(self, now=None):
        o = super().osi(now)
        if self.mode == "S" and self.last:
            from dataclasses import replace
            return replace(o, actuators=self.last)
        return o


class SafetyActionSrpIgnored(_Model):
    """RH-SAF-4: with SafetyAction srp and an SRP given at start, it parks at the surface anyway."""

    @property
    def srp_ready(self) -> bool:
        return False


class MissionNeverEnds(_Model):
    """RH-MSN-4: the last waypoint reached (and parked), the mission goes on in N; it never ends."""

    def _fire(self, event, now):
        if event in ("wp_reached", "park_expired") and self.mission is not None and not self.more_wps:
            if event == "park_expired" or not self.wp_parks:
                return None
        return super()._fire(event, now)


# ============================================================================ registry

@dataclass(frozen=True)
class Mutant:
    name: str
    clause: str  #: the clause a correct certifier fails it on
    select: tuple  #: clauses to certify (fast)
    core: type = EmulatorCore
    model: type | None = None
    profile_changes: tuple = ()  #: (key, value) pairs for the *vehicle's* profile
    time_scale: float = 25.0  #: k for the emulator and the tester (higher for long missions)


MUTANTS = (
    Mutant("accepts-bad-checksum", "RH-FRM-2", ("RH-FRM-2",), core=AcceptsBadChecksum),
    Mutant("lowercase-checksum-out", "RH-FRM-3", ("RH-FRM-3",), core=LowercaseOut),
    Mutant("rejects-lowercase-checksum-in", "RH-FRM-3", ("RH-FRM-3",),
           profile_changes=(("lowercase_checksum_in", False),)),
    Mutant("no-ack-for-osd", "RH-ACK-1", ("RH-ACK-1",), core=NoAckForOsd),
    Mutant("ack-before-data", "RH-ACK-5", ("RH-ACK-5",), core=AckBeforeData),
    Mutant("spells-mP-as-Mp", "RH-OUT-1", ("RH-OUT-1", "RH-PK-1"), core=Mp),
    Mutant("servo-timeout-ignored", "RH-SRV-4", ("RH-SRV-4",), model=ServoTimeoutIgnored),
    Mutant("servo-resumes-S", "RH-INT-2", ("RH-INT-2",), model=ServoResumesS),
    Mutant("opk-kept-after-interrupt", "RH-INT-3", ("RH-INT-3",), model=OpkKeptAfterInterrupt),
    Mutant("lockout-accepts-oms", "RH-SAF-1", ("RH-SAF-1",), model=LockoutAcceptsOms),
    Mutant("lockout-10s", "RH-SAF-1", ("RH-SAF-1",), profile_changes=(("lockout_s", 10.0),)),
    Mutant("orwset-write-not-stored", "RH-SET-2", ("RH-SET-2",), model=SettingNotStored),
    Mutant("omload-accepts-dotdot", "RH-MSN-1", ("RH-MSN-1",), core=OmloadDotDot),
    Mutant("wrong-err-number", "RH-ACK-3", ("RH-ACK-3",), model=WrongErrNumber),
    Mutant("primitive-never-neutral", "RH-PRM-4", ("RH-PRM-4",), model=PrimitiveNeverNeutral),
    Mutant("safety-action-srp-ignored", "RH-SAF-4", ("RH-SAF-4",), model=SafetyActionSrpIgnored),
    Mutant("mission-never-ends", "RH-MSN-4", ("RH-MSN-4",), model=MissionNeverEnds, time_scale=60.0),
)


def make_core(m: Mutant | None, time_scale: float, start: float) -> EmulatorCore:
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
