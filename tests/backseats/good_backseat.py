#!/usr/bin/env python3
"""A small, well-behaved remote helm backseat (pyserial only), for ``certify backseat``.

It is an example of what §9 of the reference profile asks of a backseat, and the base of the
faulty variants in ``faulty_backseat.py``:

* every sentence is ``$body*HH`` CR LF with an upper-case, zero-padded checksum (RH-BS-1, -7);
* it polls ``$OSD,G,C,S,P,,,,`` once a second (RH-BS-8) and reads ``$OSI`` and ``$ACK``;
* before starting it sets up logging and reads a setting (``$OLOGL``, ``$ORWSET``: only while
  stopped, RH-BS-3), then starts the mission by name and, while the vehicle reports a running
  mission, drives ``$OMS`` refreshed at a third of the timeout it chose (RH-BS-6);
* after a rejection it waits 1.5 s before sending that kind of command again (RH-BS-5);
* when the vehicle shows a safety lockout (a code in ``$OSI`` field 8, or err 26) it sends only
  ``$OSD`` for the lockout time plus a margin, then ends the episode with ``$OMSTOP`` and
  starts again (RH-BS-5, RH-SAF-1..3);
* when the mission ends (``$OSI`` reports ``S``) it stops driving, and starts again after 1 s.

Usage: ``good_backseat.py PORT [--time-scale K] [--mission NAME] [--baud N]
[--crash-after S]``. It runs until the port goes away; ``--crash-after`` makes it say so on
standard error and exit with code 3 at once. Times it keeps are wall time; the vehicle's
durations (servo timeout, lockout) are divided by the time scale it is told (RH-TIM-2).
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import serial  # pyserial

RUNNING = {"N", "P", "mP", "Mp", "A", "W"}
LOCKOUT_S = 20.0


def checksum(body: str) -> int:
    x = 0
    for c in body.encode("ascii"):
        x ^= c
    return x


class Backseat:
    """The well-behaved backseat. Faulty variants override one method each."""

    poll_body = "OSD,G,C,S,P,,,,"
    poll_every = 1.0
    backoff_s = 1.5

    def __init__(self, port: str, *, time_scale: float = 1.0, mission: str = "conformance.mis",
                 baud: int = 19200, crash_after: float | None = None):
        self.ser = serial.serial_for_url(port, baudrate=baud, timeout=0.02)  # a device or socket://
        try:
            self.ser.reset_input_buffer()
        except (OSError, serial.SerialException):
            pass
        self.k = time_scale
        self.mission = mission
        self.crash_after = crash_after
        self.servo_timeout = max(1, min(120, round(2.0 * self.k)))  # ~2 s of wall time
        self.refresh_every = max(0.3, min(1.0, self.servo_timeout / self.k / 3))
        self.lockout_wall = LOCKOUT_S / self.k
        self.buf = b""
        self.mode: str | None = None
        self.error_state = "N"
        self.last_poll = -1e9
        self.last_oms = -1e9
        self.heading = 0.0
        self.backoff: dict[int, float] = {}
        self.setup_done = False
        self.start_pending = False
        self.last_start = -1e9
        self.hold_until = 0.0  # lockout: only $OSD until then
        self.in_lockout = False
        self.stopped_at: float | None = None
        self.episode_end = -1e9
        self.t0 = time.monotonic()

    # ------------------------------------------------------------------ wire
    def frame(self, body: str) -> bytes:
        return f"${body}*{checksum(body):02X}\r\n".encode("ascii")

    def send(self, body: str) -> None:
        self.ser.write(self.frame(body))

    def read(self) -> None:
        data = self.ser.read(self.ser.in_waiting or 1)
        if not data:
            return
        self.buf += data
        while b"\n" in self.buf:
            line, self.buf = self.buf.split(b"\n", 1)
            self.handle(line.strip().decode("ascii", "replace"))

    def handle(self, line: str) -> None:
        if not line.startswith("$") or "*" not in line:
            return
        body = line[1:line.index("*")]
        fields = body.split(",")
        now = time.monotonic()
        if fields[0] == "OSI" and len(fields) > 8:
            self.on_state(fields[2], fields[8], now)
        elif fields[0] == "ACK" and len(fields) >= 4:
            self.on_ack(int(fields[1]), int(fields[2]), int(fields[3]), now)

    # ------------------------------------------------------------------ what the vehicle said
    def on_state(self, mode: str, error_state: str, now: float) -> None:
        was_running = self.mode in RUNNING
        self.mode = mode
        self.error_state = error_state
        if error_state != "N" and now - self.episode_end > 1.0:  # not a reply from before $OMSTOP
            self.lockout_seen(now)
        if mode == "S" and was_running and self.stopped_at is None:
            self.stopped_at = now

    def on_ack(self, type_: int, status: int, err: int, now: float) -> None:
        if type_ == 3:
            self.start_pending = False
            if status == 0:
                self.mode = "N"
        if type_ == 1 and status == 0:  # our $OMSTOP took effect: whatever $OSI was in flight
            self.mode = "S"
        if status == 0:
            return
        if err == 26:
            if now - self.episode_end > 1.0:
                self.lockout_seen(now)
        else:
            self.rejected(type_, now)

    def rejected(self, type_: int, now: float) -> None:
        """RH-BS-5: do not send that kind of command again for a while."""
        self.backoff[type_] = now + self.backoff_s

    def lockout_seen(self, now: float) -> None:
        """RH-BS-5: only $OSD for the lockout time (plus a margin), then end the episode."""
        if not self.in_lockout:
            self.in_lockout = True
            self.hold_until = now + self.lockout_wall + 1.0

    def may(self, type_: int, now: float) -> bool:
        return now >= self.backoff.get(type_, 0.0)

    # ------------------------------------------------------------------ what to send
    def step(self, now: float) -> None:
        if now - self.last_poll >= self.poll_every:
            self.last_poll = now
            self.poll()
        if self.mode is None:
            return
        if self.in_lockout:
            if now < self.hold_until:
                return
            if self.may(1, now):
                self.send("OMSTOP,0")
                self.backoff[1] = now + self.backoff_s
                self.in_lockout = False
                self.episode_end = now
                self.error_state = "N"
                self.mode = "S"
                self.stopped_at = now
            return
        if self.mode == "S":
            self.when_stopped(now)
        elif self.mode in RUNNING:
            self.stopped_at = None
            self.when_running(now)

    def poll(self) -> None:
        self.send(self.poll_body)

    def when_stopped(self, now: float) -> None:
        if not self.setup_done:
            self.setup_done = True
            self.send("OLOGL,depth,heading")
            self.send("ORWSET,SafetyAction,R")
            return
        if self.stopped_at is not None and now - self.stopped_at < 1.0:
            return
        if not self.start_pending and now - self.last_start >= 1.5 and self.may(3, now):
            self.start_pending = True
            self.last_start = now
            self.send(f"OMSTART,0,0,0,0,{self.mission},")

    def when_running(self, now: float) -> None:
        if now - self.last_oms >= self.refresh_every and self.may(9, now):
            self.send_oms(now)

    def send_oms(self, now: float) -> None:
        self.last_oms = now
        self.heading = (self.heading + 1.0) % 360.0
        self.send(f"OMS,{self.heading:.1f},2.0,20.0,1.0,{self.servo_timeout}")

    # ------------------------------------------------------------------ main loop
    def run(self) -> int:
        print(f"good_backseat: driving {self.ser.port} at time scale {self.k:g}", flush=True)
        try:
            while True:
                now = time.monotonic()
                if self.crash_after is not None and now - self.t0 >= self.crash_after:
                    print(f"good_backseat: crashing on purpose after {self.crash_after:g} s", file=sys.stderr)
                    os._exit(3)  # a crash: no goodbye, no flush
                self.step(now)
                self.read()
        except (OSError, serial.SerialException):
            return 0  # the port went away: the certifier is done


def main(cls=Backseat, argv=None, **extra) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("port")
    p.add_argument("--time-scale", type=float, default=1.0)
    p.add_argument("--mission", default="conformance.mis")
    p.add_argument("--baud", type=int, default=19200)
    p.add_argument("--crash-after", type=float)
    for name, kw in extra.items():
        p.add_argument(name, **kw)
    args = p.parse_args(argv)
    b = cls(args.port, time_scale=args.time_scale, mission=args.mission, baud=args.baud,
            crash_after=args.crash_after)
    b.args = args
    return b.run()


if __name__ == "__main__":
    sys.exit(main())
