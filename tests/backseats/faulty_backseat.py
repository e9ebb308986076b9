#!/usr/bin/env python3
"""Faulty backseats: the well-behaved one (``good_backseat.py``) with exactly one fault each.

Usage: ``faulty_backseat.py PORT --fault NAME [--time-scale K] …``. Each fault is a real bug
seen in, or easy to make in, client code (public-evidence §3), and breaks one §9 clause:

==================  =========  ================================================================
fault               clause     what it does
==================  =========  ================================================================
bad-checksum        RH-BS-1    every fifth state poll carries a wrong checksum
unpadded-checksum   RH-BS-1    checksums written ``%X`` (no zero padding); an extra poll
                               ``$OSD,,,S,,,,,`` every 3 s then ends ``*B``
lowercase-hex       RH-BS-7    checksums in lower-case hex (``%02x``)
bare-lf             RH-BS-7    lines end with LF alone
short-omp           RH-BS-2    every 3 s an ``$OMP`` built with ``%x``: a byte below 0x10
                               loses a digit (nine hex digits)
rwset-after-start   RH-BS-3    reads a setting with ``$ORWSET`` once the mission runs
oms-while-stopped   RH-BS-3    sends ``$OMS`` while the vehicle reports ``S``
hasty-oms           RH-BS-3    sends one ``$OMS`` 0.5 s after the vehicle reported ``S``
flood               RH-BS-4    once, 300 empty ``$OSD`` requests in one write (2700 bytes)
lockout-ignore      RH-BS-5    keeps driving ``$OMS`` through a safety lockout
fast-resend         RH-BS-5    resends a rejected command every 0.3 s
resend-burst        RH-BS-5    answers its first refused ``$OMS`` with four copies of it
                               within 0.1 s
late-refresh        RH-BS-6    refreshes ``$OMS`` only after 1.6 × its timeout
late-refresh-120    RH-BS-6    chooses the longest timeout, 120 s, and refreshes ``$OMS`` only after
                               1.2 × it (at ×10: every 14.4 s; a scenario must outlast its cycle)
no-poll             RH-BS-8    polls ``$OSD`` every 7 s
==================  =========  ================================================================

And faults seen once in a whole session (each is the backseat's at once on a link that cannot
damage a byte — helmcheck's pty — and a well-framed line with a right checksum is judged as sent
on any link):

==================  =========  ================================================================
once-bad-checksum   RH-BS-1    its fifth state poll, and no other line, has a wrong checksum
once-timeout-121    RH-BS-2    its third ``$OMS`` has timeout 121 (§4: integer [1,120] s)
once-heading-360    RH-BS-2    its third ``$OMS`` has heading ``360.0`` (§4: [0,360))
once-opk-minutes-0  RH-BS-2    once the mission runs, one ``$OPK`` with minutes ``0`` (§4: [1, 1440])
omw-dollar-sum      RH-BS-1    every 3 s while a mission runs, ``$OMW,Clr`` with its checksum
                               taken over the ``$`` too
==================  =========  ================================================================
"""

from __future__ import annotations

import sys
import time

from good_backseat import Backseat, checksum, main


class BadChecksum(Backseat):
    n = 0

    def poll(self) -> None:
        self.n += 1
        if self.n % 5 == 0:
            body = self.poll_body
            self.ser.write(f"${body}*{checksum(body) ^ 0x01:02X}\r\n".encode())
        else:
            super().poll()


class UnpaddedChecksum(Backseat):
    last_extra = 0.0

    def frame(self, body: str) -> bytes:
        return f"${body}*{checksum(body):X}\r\n".encode("ascii")

    def step(self, now: float) -> None:
        if now - self.last_extra >= 3.0:
            self.last_extra = now
            self.send("OSD,,,S,,,,,")  # checksum 0x0B: written "*B"
        super().step(now)


class LowercaseHex(Backseat):
    def frame(self, body: str) -> bytes:
        return f"${body}*{checksum(body):02x}\r\n".encode("ascii")


class BareLf(Backseat):
    def frame(self, body: str) -> bytes:
        return f"${body}*{checksum(body):02X}\n".encode("ascii")


class ShortOmp(Backseat):
    last_omp = 0.0

    def step(self, now: float) -> None:
        super().step(now)
        if now - self.last_omp >= 3.0 and not self.in_lockout:
            self.last_omp = now
            fins = (0x80, 0x80, 0x08, 0x80, 0x80)
            self.send("OMP,%x%x%x%x%x,00,5" % fins)  # 0x08 -> "8": nine digits


class RwsetAfterStart(Backseat):
    asked_at: float | None = None

    def when_running(self, now: float) -> None:
        super().when_running(now)
        if self.asked_at is None:
            self.asked_at = now
        elif self.asked_at > 0 and now - self.asked_at > 1.0:
            self.asked_at = -1.0
            self.send("ORWSET,SafetyAction,R")


class OmsWhileStopped(Backseat):
    s_since: float | None = None

    def when_running(self, now: float) -> None:
        self.s_since = None
        super().when_running(now)

    def when_stopped(self, now: float) -> None:
        if self.s_since is None:
            self.s_since = now
        if not self.setup_done or now - self.s_since >= 3.0:
            super().when_stopped(now)  # starts the mission, but late
        elif now - self.s_since >= 1.0 and now - self.last_oms >= 1.5:
            self.send_oms(now)  # drives although the vehicle reports S


class HastyOms(Backseat):
    """Each time the vehicle reports ``S``, one ``$OMS`` half a second later (a backseat that
    acts on a stale idea of the mission), then carries on as the good one."""

    s_since: float | None = None
    sent_hasty = False

    def when_running(self, now: float) -> None:
        self.s_since = None
        self.sent_hasty = False
        super().when_running(now)

    def when_stopped(self, now: float) -> None:
        if self.s_since is None:
            self.s_since = now
        if not self.sent_hasty and now - self.s_since >= 0.5:
            self.sent_hasty = True
            self.send_oms(now)
            return
        if self.sent_hasty and now - self.s_since >= 1.5:
            super().when_stopped(now)


class Flood(Backseat):
    flooded = False

    def when_running(self, now: float) -> None:
        super().when_running(now)
        if not self.flooded and now - self.t0 > 2.0:
            self.flooded = True
            self.ser.write(self.frame("OSD") * 300)


class LockoutIgnore(Backseat):
    def lockout_seen(self, now: float) -> None:
        pass  # carries on as if nothing happened


class FastResend(Backseat):
    burst_done = False

    def rejected(self, type_: int, now: float) -> None:
        if type_ == 9 and not self.burst_done:  # resend the refused $OMS every 0.3 s, once
            self.burst_done = True
            body = f"OMS,{self.heading:.1f},2.0,20.0,1.0,{self.servo_timeout}"
            for _ in range(6):
                time.sleep(0.3)
                self.send(body)
        super().rejected(type_, now)


class ResendBurst(Backseat):
    """Answers its first refused ``$OMS`` at once with four copies of it, 0.025 s apart (a retry
    loop without a back-off): only the first may have been sent before the rejection was known."""

    burst_done = False

    def rejected(self, type_: int, now: float) -> None:
        if type_ == 9 and not self.burst_done:
            self.burst_done = True
            body = f"OMS,{self.heading:.1f},2.0,20.0,1.0,{self.servo_timeout}"
            for i in range(4):
                if i:
                    time.sleep(0.025)
                self.send(body)
        super().rejected(type_, now)


class LateRefresh(Backseat):
    def __init__(self, *a, **kw):
        super().__init__(*a, **kw)
        self.refresh_every = 1.6 * self.servo_timeout / self.k


class LateRefresh120(Backseat):
    def __init__(self, *a, **kw):
        super().__init__(*a, **kw)
        self.servo_timeout = 120
        self.refresh_every = 1.2 * self.servo_timeout / self.k


class NoPoll(Backseat):
    poll_every = 7.0


class OnceBadChecksum(Backseat):
    n = 0

    def poll(self) -> None:
        self.n += 1
        if self.n == 5:
            body = self.poll_body
            self.ser.write(f"${body}*{checksum(body) ^ 0x01:02X}\r\n".encode())
        else:
            super().poll()


class _OnceOms(Backseat):
    """The third ``$OMS`` it sends carries one field out of its range (``bad``)."""

    n = 0
    bad = ""

    def send_oms(self, now: float) -> None:
        self.n += 1
        if self.n != 3:
            super().send_oms(now)
            return
        self.last_oms = now
        self.send(self.bad.format(timeout=self.servo_timeout, heading=self.heading))


class OnceTimeout121(_OnceOms):
    bad = "OMS,{heading:.1f},2.0,20.0,1.0,121"


class OnceHeading360(_OnceOms):
    bad = "OMS,360.0,2.0,20.0,1.0,{timeout}"


class OnceOpkMinutes0(Backseat):
    sent_opk = False

    def when_running(self, now: float) -> None:
        super().when_running(now)
        if not self.sent_opk and now - self.t0 > 2.0:
            self.sent_opk = True
            self.send("OPK,41.52,-71.32,0,1.0")


class OmwDollarSum(Backseat):
    last_omw = 0.0

    def when_running(self, now: float) -> None:
        super().when_running(now)
        if now - self.last_omw >= 3.0:
            self.last_omw = now
            body = "OMW,Clr"
            self.ser.write(f"${body}*{checksum('$' + body):02X}\r\n".encode())


FAULTS = {
    "bad-checksum": BadChecksum, "unpadded-checksum": UnpaddedChecksum, "lowercase-hex": LowercaseHex,
    "bare-lf": BareLf, "short-omp": ShortOmp, "rwset-after-start": RwsetAfterStart,
    "oms-while-stopped": OmsWhileStopped, "hasty-oms": HastyOms, "flood": Flood, "lockout-ignore": LockoutIgnore,
    "fast-resend": FastResend, "resend-burst": ResendBurst, "late-refresh": LateRefresh,
    "no-poll": NoPoll, "late-refresh-120": LateRefresh120,
    "once-bad-checksum": OnceBadChecksum, "once-timeout-121": OnceTimeout121,
    "once-heading-360": OnceHeading360, "once-opk-minutes-0": OnceOpkMinutes0, "omw-dollar-sum": OmwDollarSum,
}

if __name__ == "__main__":
    argv = sys.argv[1:]
    fault = None
    if "--fault" in argv:
        i = argv.index("--fault")
        fault = argv[i + 1]
        del argv[i:i + 2]
    if fault not in FAULTS:
        sys.exit(f"--fault must be one of {', '.join(FAULTS)}")
    sys.exit(main(FAULTS[fault], argv))
