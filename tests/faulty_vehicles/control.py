"""Faulty vehicles for §4, §5, §7 and §8: control and interrupts, missions, safety, time
(RH-INT-*, RH-SRV-*, RH-PRM-*, RH-JW-*, RH-PK-*, RH-OMW-*, RH-MSN-*, RH-SAF-*, RH-TIM-*)."""

from __future__ import annotations

from dataclasses import replace

from helmcheck.emulator.core import EmulatorCore
from helmcheck.grammar import sentences as s
from helmcheck.model.handlers import ack

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
    """RH-INT-3: a $OPK park interrupted by $OMS comes back when the servo ends (that servo's
    own end: a park a stop or another command put away does not come back later)."""

    saved = None

    def receive(self, item, now):
        if self.mode == "mP" and isinstance(item, s.OMS):
            self.saved = self.opk
        elif not isinstance(item, (s.OMS, s.OSD)):
            self.saved = None
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


# ====================================================================== §4 control commands

class OmpRefusedInServo(Model):
    """RH-INT-1: an $OMP while the servo (A) is active is refused (err 21) instead of taking over."""

    def receive(self, item, now):
        if isinstance(item, s.OMP) and self.mode == "A" and self.phase == "none":
            return [ack(10, 21)]
        return super().receive(item, now)


class OmsAcceptedInS(Model):
    """RH-SRV-1: an $OMS with no mission running is acknowledged as accepted (and ignored)."""

    def receive(self, item, now):
        if isinstance(item, s.OMS) and self.mission is None and self.phase == "none":
            return [ack(9)]
        return super().receive(item, now)


class OmsHeadingWraps(EmulatorCore):
    """RH-SRV-2: an $OMS heading of 360 or more is taken modulo 360 instead of refused."""

    def _line(self, raw, now, v):
        if raw.startswith(b"$OMS,") and b"*" in raw:
            f = body(raw).split(b",")
            try:
                heading = float(f[1])
            except (IndexError, ValueError):
                heading = -1.0
            if heading >= 360:
                f[1] = f"{heading % 360:g}".encode()
                raw = reframe(raw, b",".join(f))
        return super()._line(raw, now, v)


class OmsRefreshKeepsTimeout(Model):
    """RH-SRV-3: an $OMS in A replaces the set-points but not the first $OMS's timeout."""

    def receive(self, item, now):
        if isinstance(item, s.OMS) and self.mode == "A" and self.timers.armed("remote"):
            duration = self.timers.duration("remote")
            started = self.timers.deadline("remote") - duration
            out = super().receive(item, now)
            if self.mode == "A":  # accepted: put the first timeout back
                self.timers.arm("remote", started, duration)
            return out
        return super().receive(item, now)


class OmpRefusedInS(Model):
    """RH-PRM-1: $OMP is refused (err 21) when no mission runs."""

    def receive(self, item, now):
        if isinstance(item, s.OMP) and self.mission is None and self.phase == "none":
            return [ack(10, 21)]
        return super().receive(item, now)


class OmpReservedIgnored(EmulatorCore):
    """RH-PRM-2: the $OMP reserved field is not checked (any value is taken as 00)."""

    def _line(self, raw, now, v):
        if raw.startswith(b"$OMP,") and b"*" in raw:
            f = body(raw).split(b",")
            if len(f) == 4 and f[2] != b"00":
                raw = reframe(raw, b",".join((f[0], f[1], b"00", f[3])))
        return super()._line(raw, now, v)


class OmpLowerHexRefused(Model):
    """RH-PRM-2: an $OMP whose fins and motor are written in lower-case hex is refused (err 21),
    though hex case is free on input; in upper case it is accepted."""

    def receive(self, item, now):
        if isinstance(item, s.OMP) and item.actuators != item.actuators.upper() and self.phase != "lockout":
            return [ack(10, 21)]
        return super().receive(item, now)


class OsdRefusedInLockout(Model):
    """RH-SAF-1: $OSD is refused (26) during the lockout like every other command, though it is
    the one command the lockout serves."""

    def receive(self, item, now):
        if isinstance(item, s.OSD) and self.phase == "lockout":
            return [ack(8, 26)]
        return super().receive(item, now)


class OsiFinsSwapped(Model):
    """RH-PRM-3: in M, $OSI field 1 shows the pitch fins before the yaw fins."""

    def osi(self, now=None):
        o = super().osi(now)
        if self.mode == "M":
            a = o.actuators
            return replace(o, actuators=a[4:8] + a[0:4] + a[8:10])
        return o


class OjwOnePastLast(Model):
    """RH-JW-1: an $OJW one past the last waypoint is accepted (as the last one)."""

    def receive(self, item, now):
        if isinstance(item, s.OJW) and self.mission is not None:
            n = item.waypoint - self.profile.waypoint_base
            if n == self.mission.last + 1:
                item = s.OJW(item.waypoint - 1)
        return super().receive(item, now)


class OjwKeepsRemote(Model):
    """RH-JW-2: an $OJW under remote control sets the mission's next waypoint but leaves the
    remote control (A, M, mP, W) in charge."""

    def receive(self, item, now):
        if isinstance(item, s.OJW) and self.remote_active and self.mission is not None:
            n = item.waypoint - self.profile.waypoint_base
            if 0 <= n <= self.mission.last:
                self.mission_wp = n
                return [ack(7)]
        return super().receive(item, now)


class OpkNoDistanceLimit(Model):
    """RH-PK-1: an $OPK farther than 10 miles is accepted (the firmware has no err 40)."""

    def __init__(self, profile, *args, **kw):
        super().__init__(profile.replace(opk_max_distance_m=float("inf")), *args, **kw)


class OpkMinutesAsSeconds(Model):
    """RH-PK-2: the $OPK park time is taken in seconds: it counts down from minutes, not minutes x 60."""

    def receive(self, item, now):
        out = super().receive(item, now)
        if isinstance(item, s.OPK) and self.mode == "mP" and self.opk is item:
            self.opk_seconds = item.minutes
            if self.timers.armed("opk"):
                self.timers.arm("opk", now, self.opk_seconds)
        return out


class OpkNeverEnds(Model):
    """RH-PK-3: when the $OPK park time is up the vehicle keeps station in mP (P0) for good."""

    done = None  #: the $OPK whose time is up

    def _fire(self, event, now):
        if event == "opk_expired":
            self.done = self.opk
            return None
        return super()._fire(event, now)

    def park_remaining(self, now=None):
        if self.mode == "mP" and self.opk is not None and self.opk is self.done:
            return 0.0
        return super().park_remaining(now)


class OmwAcceptedInS(Model):
    """RH-OMW-1: an $OMW with no mission running is acknowledged as accepted (and ignored)."""

    def receive(self, item, now):
        if isinstance(item, s.OMW) and self.mission is None and self.phase == "none":
            return [ack(16)]
        return super().receive(item, now)


class OmwQueueOfOne(Model):
    """RH-OMW-2: the queue holds one waypoint: a second $OMW while in W is refused (err 36)."""

    def receive(self, item, now):
        if isinstance(item, s.OMW) and self.mode == "W" and self.phase == "none":
            return [ack(16, 36)]
        return super().receive(item, now)


class OmwOnlyClr(Model):
    """RH-OMW-3: only the keyword Clr clears the queue; its synonyms CLEAR and STOP are refused (36)."""

    def receive(self, item, now):
        if isinstance(item, s.OMWClear) and item.keyword.lower() != "clr" and self.phase == "none":
            return [ack(16, 36)]
        return super().receive(item, now)


class OmwHoldsAtLast(Model):
    """RH-OMW-4: the last queued waypoint reached, the vehicle holds there in W instead of resuming."""

    def _fire(self, event, now):
        if event == "queue_wp_reached" and not self.queue_more and not self.head_parks:
            return None
        if event == "queue_park_expired" and not self.queue_more:
            return None
        return super()._fire(event, now)


class OmwQueueResumes(Model):
    """RH-OMW-5: a control that interrupted W hands back to the queue when it ends (a stack)."""

    saved = ()

    def receive(self, item, now):
        queue = list(self.queue) if self.mode == "W" else None
        out = super().receive(item, now)
        if queue and self.mode in ("A", "M", "mP"):
            self.saved = queue
        elif self.mode in ("S", "N", "P", "W"):
            self.saved = ()
        return out

    def _release(self, row, now):
        saved, self.saved = self.saved, ()
        super()._release(row, now)
        if saved and self.mode in ("N", "P") and self.phase == "none":
            self.queue = list(saved)
            self.mode = "W"
            self._control_changed()


# ====================================================================== §5 missions

class OmstartRestarts(Model):
    """RH-MSN-2: $OMSTART while a mission runs restarts it instead of being refused (err 30)."""

    def receive(self, item, now):
        if isinstance(item, (s.OMSTART, s.OMSTARTPaper)) and self.mission is not None and self.phase == "none":
            self.receive(s.OMSTOP(0), now)
        return super().receive(item, now)


class OmstopIgnoredInServo(Model):
    """RH-MSN-3: $OMSTOP in servo mode (A) is acknowledged, but the servo goes on until its timeout."""

    def receive(self, item, now):
        if isinstance(item, s.OMSTOP) and self.mode == "A" and self.phase == "none":
            return [ack(1)]
        return super().receive(item, now)


# ====================================================================== §7 safety

class LockoutCommandsQueued(Model):
    """RH-SAF-2: a control command refused during the lockout is carried out when the lockout ends."""

    held = None

    def receive(self, item, now):
        out = super().receive(item, now)
        if self.phase == "lockout" and out and out[-1].err == 26 and isinstance(item, (s.OMP, s.OMS)):
            self.held = item
        return out

    def _fire(self, event, now):
        row = super()._fire(event, now)
        if event == "lockout_end" and self.held is not None:
            held, self.held = self.held, None
            self.receive(held, now)
        return row


class OmpLockedTillSurface(Model):
    """RH-SAF-3: after the lockout $OMP stays refused (26) until the surface, like the other controls."""

    def receive(self, item, now):
        if isinstance(item, s.OMP) and self.phase == "ascent":
            return [ack(10, 26)]
        return super().receive(item, now)


class OxfltIgnored(Model):
    """RH-SAF-5: declares the $OXFLT test extension but ignores it (no violation is raised)."""

    def receive(self, item, now):
        if isinstance(item, s.OXFLT):
            return []
        return super().receive(item, now)


# ====================================================================== §8 time

class TimeoutsFromRampEnd(Model):
    """RH-TIM-1: $OMS/$OMP timeouts start 5 s after the ACK (when the set-points are reached)."""

    def receive(self, item, now):
        out = super().receive(item, now)
        if isinstance(item, (s.OMS, s.OMP)) and out and out[-1].status == 0 and self.timers.armed("remote"):
            self.timers.arm("remote", now + 5.0, self.timers.duration("remote"))
        return out


class ClockRunsFast(EmulatorCore):
    """RH-TIM-2: the vehicle runs 1.3 times faster than the time scale it declares."""

    def __init__(self, profile, missions=None, *, time_scale=None, **kw):
        super().__init__(profile, missions, time_scale=1.3 * (time_scale or profile.time_scale), **kw)


MUTANTS = (
    Mutant("servo-timeout-ignored", "RH-SRV-4", ("RH-SRV-4",), model=ServoTimeoutIgnored, time_scales=TIMED_SCALES),
    Mutant("servo-resumes-S", "RH-INT-2", ("RH-INT-2",), model=ServoResumesS),
    Mutant("opk-kept-after-interrupt", "RH-INT-3", ("RH-INT-3",), model=OpkKeptAfterInterrupt),
    Mutant("lockout-accepts-oms", "RH-SAF-1", ("RH-SAF-1",), model=LockoutAcceptsOms),
    Mutant("lockout-10s", "RH-SAF-1", ("RH-SAF-1",), profile_changes=(("lockout_s", 10.0),)),
    Mutant("omload-accepts-dotdot", "RH-MSN-1", ("RH-MSN-1",), core=OmloadDotDot),
    Mutant("primitive-never-neutral", "RH-PRM-4", ("RH-PRM-4",), model=PrimitiveNeverNeutral, time_scales=TIMED_SCALES),
    Mutant("safety-action-srp-ignored", "RH-SAF-4", ("RH-SAF-4",), model=SafetyActionSrpIgnored),
    Mutant("omp-refused-in-servo", "RH-INT-1", ("RH-INT-1",), model=OmpRefusedInServo),
    Mutant("oms-accepted-in-S", "RH-SRV-1", ("RH-SRV-1",), model=OmsAcceptedInS),
    Mutant("oms-heading-360-wraps", "RH-SRV-2", ("RH-SRV-2",), core=OmsHeadingWraps),
    Mutant("oms-refresh-keeps-timeout", "RH-SRV-3", ("RH-SRV-3",), model=OmsRefreshKeepsTimeout,
           time_scales=TIMED_SCALES),
    Mutant("omp-refused-in-S", "RH-PRM-1", ("RH-PRM-1",), model=OmpRefusedInS),
    Mutant("omp-reserved-ignored", "RH-PRM-2", ("RH-PRM-2",), core=OmpReservedIgnored),
    Mutant("osi-fins-swapped", "RH-PRM-3", ("RH-PRM-3",), model=OsiFinsSwapped),
    Mutant("ojw-one-past-last", "RH-JW-1", ("RH-JW-1",), model=OjwOnePastLast),
    Mutant("ojw-keeps-remote", "RH-JW-2", ("RH-JW-2",), model=OjwKeepsRemote),
    Mutant("opk-no-distance-limit", "RH-PK-1", ("RH-PK-1",), model=OpkNoDistanceLimit),
    Mutant("opk-minutes-as-seconds", "RH-PK-2", ("RH-PK-2",), model=OpkMinutesAsSeconds),
    Mutant("opk-never-ends", "RH-PK-3", ("RH-PK-3",), model=OpkNeverEnds),
    Mutant("omw-accepted-in-S", "RH-OMW-1", ("RH-OMW-1",), model=OmwAcceptedInS),
    Mutant("omw-queue-of-one", "RH-OMW-2", ("RH-OMW-2",), model=OmwQueueOfOne),
    Mutant("omw-only-clr", "RH-OMW-3", ("RH-OMW-3",), model=OmwOnlyClr),
    Mutant("omw-holds-at-last", "RH-OMW-4", ("RH-OMW-4",), model=OmwHoldsAtLast),
    Mutant("omw-queue-resumes", "RH-OMW-5", ("RH-OMW-5",), model=OmwQueueResumes),
    Mutant("omstart-restarts", "RH-MSN-2", ("RH-MSN-2",), model=OmstartRestarts),
    Mutant("omstop-ignored-in-servo", "RH-MSN-3", ("RH-MSN-3",), model=OmstopIgnoredInServo),
    Mutant("lockout-commands-queued", "RH-SAF-2", ("RH-SAF-2",), model=LockoutCommandsQueued),
    Mutant("omp-locked-till-surface", "RH-SAF-3", ("RH-SAF-3",), model=OmpLockedTillSurface),
    Mutant("oxflt-ignored", "RH-SAF-5", ("RH-SAF-5",), model=OxfltIgnored),
    Mutant("timeouts-from-ramp-end", "RH-TIM-1", ("RH-TIM-1",), model=TimeoutsFromRampEnd, time_scales=TIMED_SCALES),
    Mutant("clock-runs-fast", "RH-TIM-2", ("RH-TIM-2",), core=ClockRunsFast, time_scales=TIMED_SCALES),
    Mutant("mission-never-ends", "RH-MSN-4", ("RH-MSN-4",), model=MissionNeverEnds, time_scales=(60.0, 90.0)),
)


class OmpNineHexAccepted(EmulatorCore):
    """RH-PRM-2: an $OMP whose field 1 has nine hex digits is accepted (read as if a last 0 followed)."""

    def _line(self, raw, now, v):
        if raw.startswith(b"$OMP,") and b"*" in raw:
            f = body(raw).split(b",")
            if len(f) == 4 and len(f[1]) == 9 and all(ch in b"0123456789abcdefABCDEF" for ch in f[1]):
                raw = reframe(raw, b",".join((f[0], f[1] + b"0", f[2], f[3])))
        return super()._line(raw, now, v)


MUTANTS += (
    Mutant("omp-nine-hex-accepted", "RH-PRM-2", ("RH-PRM-2",), core=OmpNineHexAccepted),
    # refused where a clause names the behaviour: booked on that clause, not on the case's subject
    Mutant("omp-lower-hex-refused", "RH-PRM-2", ("RH-PRM-2", "RH-PRM-3"), model=OmpLowerHexRefused, only=True),
    Mutant("osd-refused-in-lockout", "RH-SAF-1", ("RH-SAF-1", "RH-OSD-1"), model=OsdRefusedInLockout, only=True,
           also=("RH-OSD-1",)),
)
