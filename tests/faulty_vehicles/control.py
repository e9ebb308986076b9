"""Faulty vehicles for §4, §5, §7 and §8: control and interrupts, missions, safety, time
(RH-INT-*, RH-SRV-*, RH-PRM-*, RH-JW-*, RH-PK-*, RH-OMW-*, RH-MSN-*, RH-SAF-*, RH-TIM-*)."""

from __future__ import annotations

from helmcheck.conformance.emulator.core import EmulatorCore
from helmcheck.grammar import sentences as s

from .base import TIMED_SCALES, Model, Mutant, body, reframe

__all__ = ["MUTANTS"]


class ServoTimeoutIgnored(Model):
    """RH-SRV-4: an $OMS never times out."""

    def receive(self, item, now):
        out = super().receive(item, now)
        if isinstance(item, s.OMS) and self.mode == "A":
            self.timers.disarm("remote")
        return out


class ServoResumesS(Model):
    """RH-INT-2: when the servo times out the vehicle stops (S) instead of resuming the mission."""

    def _release(self, row, now):
        was_servo = self.servo is not None
        super()._release(row, now)
        if was_servo:
            self.mode = "S"
            self.mission = None
            self.mission_mode = "N"
            self.timers.disarm("park")


class OpkKeptAfterInterrupt(Model):
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


class LockoutAcceptsOms(Model):
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


class OmloadDotDot(EmulatorCore):
    """RH-MSN-1: $OMLOAD with a '..' component loads the file by its last name."""

    def _line(self, raw, now, v):
        if raw.startswith(b"$OMLOAD,") and b".." in raw and b"*" in raw:
            name, _, rest = body(raw)[len(b"OMLOAD,"):].partition(b",")
            raw = reframe(raw, b"OMLOAD," + name.replace(b"\\", b"/").split(b"/")[-1] + b"," + rest)
        return super()._line(raw, now, v)


class PrimitiveNeverNeutral(Model):
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


class SafetyActionSrpIgnored(Model):
    """RH-SAF-4: with SafetyAction srp and an SRP given at start, it parks at the surface anyway."""

    @property
    def srp_ready(self) -> bool:
        return False


class MissionNeverEnds(Model):
    """RH-MSN-4: the last waypoint reached (and parked), the mission goes on in N; it never ends."""

    def _fire(self, event, now):
        if event in ("wp_reached", "park_expired") and self.mission is not None and not self.more_wps:
            if event == "park_expired" or not self.wp_parks:
                return None
        return super()._fire(event, now)


MUTANTS = (
    Mutant("servo-timeout-ignored", "RH-SRV-4", ("RH-SRV-4",), model=ServoTimeoutIgnored, time_scales=TIMED_SCALES),
    Mutant("servo-resumes-S", "RH-INT-2", ("RH-INT-2",), model=ServoResumesS),
    Mutant("opk-kept-after-interrupt", "RH-INT-3", ("RH-INT-3",), model=OpkKeptAfterInterrupt),
    Mutant("lockout-accepts-oms", "RH-SAF-1", ("RH-SAF-1",), model=LockoutAcceptsOms),
    Mutant("lockout-10s", "RH-SAF-1", ("RH-SAF-1",), profile_changes=(("lockout_s", 10.0),)),
    Mutant("omload-accepts-dotdot", "RH-MSN-1", ("RH-MSN-1",), core=OmloadDotDot),
    Mutant("primitive-never-neutral", "RH-PRM-4", ("RH-PRM-4",), model=PrimitiveNeverNeutral, time_scales=TIMED_SCALES),
    Mutant("safety-action-srp-ignored", "RH-SAF-4", ("RH-SAF-4",), model=SafetyActionSrpIgnored),
    Mutant("mission-never-ends", "RH-MSN-4", ("RH-MSN-4",), model=MissionNeverEnds, time_scales=(60.0, 90.0)),
)
