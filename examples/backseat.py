#!/usr/bin/env python3
"""An example remote helm backseat: start a mission, steer the vehicle for a while, hand it back.

It needs Python 3.10+ and pyserial only (``python3 -m pip install pyserial``); helmcheck's own
Python has both. Point it at the vehicle's serial line, or at an emulator:

    python3 examples/backseat.py --port /dev/ttyUSB0
    python3 examples/backseat.py --port socket://127.0.0.1:4001 --time-scale 20

The loop, for as long as the port is open (Ctrl-C ends it):

1. While the vehicle reports ``S`` (stopped): once, set up its logging (``$OLOGL``: allowed only
   before a mission starts, RH-BS-3); then start the mission by name (``$OMSTART``).
2. Once a mission runs: take servo control (``$OMS``: heading, depth, pitch, speed, timeout) for
   ``--steer`` seconds, sending the next ``$OMS`` after a third of its timeout, so control never
   lapses (RH-BS-6).
3. Release: send no more ``$OMS``. When the timeout runs out the vehicle hands control back to
   the mission (RH-SRV-4, RH-INT-2). After ``--release`` seconds, steer again (step 2). The
   release lasts well over twice the timeout, so that the next ``$OMS`` takes control anew and
   does not read as a refresh that came too late (RH-BS-6).

Throughout it asks for the vehicle's state (``$OSD,S``, answered by ``$OSI``) every second:
at least every 5 s is the rule (RH-BS-8). And it follows the other rules of the reference
profile's §9:

* every line is ``$BODY*HH`` with the checksum in upper-case hex, two digits, then CR LF
  (RH-BS-1, RH-BS-7);
* after a refused command (``$ACK`` status 1) it sends that kind of command again no sooner
  than 1.5 s later (RH-BS-5);
* on a safety violation (``$OSI`` field 8 not ``N``, or ``$ACK`` error 26) it sends nothing but
  ``$OSD`` for the lockout (20 vehicle seconds) and a margin, then ends the episode with
  ``$OMSTOP`` and starts again (RH-BS-5, RH-SAF-1);
* when the mission ends (the vehicle reports ``S``) it stops steering at once and starts the
  mission again a little later.

Times it keeps are wall seconds. Durations the vehicle counts (the ``$OMS`` timeout, the
lockout) are vehicle seconds: with ``--time-scale K`` (an emulator running K times faster than
real time) they are divided by K.
"""

from __future__ import annotations

import argparse
import sys
import time

import serial  # pyserial

RUNNING = {"N", "P", "mP", "A", "M", "W"}  # $OSI modes in which a mission runs
LOCKOUT_S = 20.0  # the safety lockout, vehicle seconds (RH-SAF-1)
POLL_EVERY = 1.0  # wall seconds between state polls (the rule: at most 5)
BACKOFF_S = 1.5  # wall seconds before a refused kind of command is sent again (the rule: 1)
PAUSE_S = 1.5  # wall seconds between a mission's end and starting it again
STEER_TIMEOUT_WALL = 3.0  # the $OMS timeout we choose, in wall seconds
OMS, OMSTART, OMSTOP = 9, 3, 1  # $ACK types of the commands whose answer we act on


def checksum(body: str) -> str:
    """The NMEA checksum of the text between ``$`` and ``*``: two upper-case hex digits."""
    x = 0
    for byte in body.encode("ascii"):
        x ^= byte
    return f"{x:02X}"


def open_port(url: str, baud: int, wait_s: float = 10.0) -> serial.Serial:
    """Open the port; a network one (``socket://…``) is retried for a few seconds, as the
    serial server may not listen yet."""
    deadline = time.monotonic() + (wait_s if "://" in url else 0.0)
    while True:
        try:
            return serial.serial_for_url(url, baudrate=baud, timeout=0.05)
        except (OSError, serial.SerialException):
            if time.monotonic() > deadline:
                raise
            time.sleep(0.2)


class Backseat:
    """The backseat's state and its one rule per step. Send and receive are plain text lines."""

    def __init__(self, port: serial.Serial, *, mission: str, time_scale: float,
                 steer_s: float, release_s: float):
        self.port = port
        self.mission = mission
        self.k = time_scale
        self.steer_s, self.release_s = steer_s, release_s
        # The $OMS timeout, in vehicle seconds, within the protocol's 1..120 (RH-SRV-2).
        self.timeout = max(1, min(120, round(STEER_TIMEOUT_WALL * time_scale)))
        self.refresh_every = self.timeout / time_scale / 3
        self.lockout_wall = LOCKOUT_S / time_scale + 1.0

        self.rx = b""
        self.mode: str | None = None  # the vehicle's mode as last reported; None: not heard yet
        self.logging_set_up = False
        self.start_sent_at: float | None = None  # an $OMSTART waiting for its $ACK
        self.stopped_at = 0.0  # when the vehicle was last seen to stop
        self.steering_since: float | None = None  # None: released
        self.released_at = 0.0
        self.last_oms = self.last_poll = -1e9
        self.heading = 0.0
        self.refused_until: dict[int, float] = {}  # $ACK type -> wall time it may be sent again
        self.lockout_until: float | None = None  # only $OSD until then
        self.episode_ended_at = -1e9  # our last $OMSTOP after a lockout

    # -- the line ---------------------------------------------------------------------------
    def send(self, body: str) -> None:
        self.port.write(f"${body}*{checksum(body)}\r\n".encode("ascii"))

    def receive(self, now: float) -> None:
        self.rx += self.port.read(self.port.in_waiting or 1)
        while b"\n" in self.rx:
            raw, self.rx = self.rx.split(b"\n", 1)
            line = raw.strip().decode("ascii", "replace")
            if line.startswith("$") and "*" in line:
                fields = line[1:line.index("*")].split(",")
                if fields[0] == "OSI" and len(fields) > 8:
                    self.on_state(mode=fields[2], error_state=fields[8], now=now)
                elif fields[0] == "ACK" and len(fields) >= 4 and fields[1].isdigit():
                    self.on_ack(int(fields[1]), fields[2] == "0", fields[3], now)

    # -- what the vehicle says ---------------------------------------------------------------
    def on_state(self, mode: str, error_state: str, now: float) -> None:
        if error_state != "N" and now - self.episode_ended_at > 1.0:  # not a report from before our $OMSTOP
            self.violation(now)
        if mode == "S" and self.mode in RUNNING:
            self.say("the vehicle stopped: mission over")
            self.stopped_at = now
            self.steering_since = None
        self.mode = mode

    def on_ack(self, type_: int, accepted: bool, error: str, now: float) -> None:
        if type_ == OMSTART:
            self.start_sent_at = None
            if accepted:
                self.mode = "N"
                self.say(f"mission {self.mission} started")
        elif type_ == OMSTOP and accepted:
            self.mode = "S"
        if accepted:
            return
        if error == "26":  # a safety lockout is running
            if now - self.episode_ended_at > 1.0:
                self.violation(now)
        else:
            self.refused_until[type_] = now + BACKOFF_S

    def violation(self, now: float) -> None:
        if self.lockout_until is None:
            self.say(f"safety violation: only $OSD for {self.lockout_wall:.1f} s")
            self.lockout_until = now + self.lockout_wall
            self.steering_since = None

    # -- what to send ------------------------------------------------------------------------
    def may_send(self, type_: int, now: float) -> bool:
        return now >= self.refused_until.get(type_, 0.0)

    def step(self, now: float) -> None:
        if now - self.last_poll >= POLL_EVERY:
            self.last_poll = now
            self.send("OSD,S")
        if self.mode is None:  # no state report yet
            return
        if self.lockout_until is not None:
            if now >= self.lockout_until and self.may_send(OMSTOP, now):
                self.send("OMSTOP,0")  # end the episode; the mission starts again from S
                self.refused_until[OMSTOP] = now + BACKOFF_S
                self.lockout_until = None
                self.episode_ended_at = self.stopped_at = now
                self.mode = "S"
            return
        if self.mode == "S":
            self.when_stopped(now)
        elif self.mode in RUNNING:
            self.when_running(now)

    def when_stopped(self, now: float) -> None:
        if not self.logging_set_up:
            self.logging_set_up = True
            self.send("OLOGL,depth,heading")
            return
        waiting_for_ack = self.start_sent_at is not None and now - self.start_sent_at < BACKOFF_S
        if now - self.stopped_at >= PAUSE_S and not waiting_for_ack and self.may_send(OMSTART, now):
            self.start_sent_at = now
            self.send(f"OMSTART,0,0,0,0,{self.mission},")

    def when_running(self, now: float) -> None:
        if self.steering_since is None:
            if now - self.released_at < self.release_s:
                return  # the mission has the helm
            self.steering_since = now
            self.say(f"steering ($OMS timeout {self.timeout} s)")
        elif now - self.steering_since >= self.steer_s:
            self.steering_since = None
            self.released_at = now
            self.say("released: the mission resumes when the $OMS timeout runs out")
            return
        if now - self.last_oms >= self.refresh_every and self.may_send(OMS, now):
            self.last_oms = now
            self.heading = (self.heading + 2.0) % 360.0
            self.servo(self.heading)

    def servo(self, heading: float) -> None:
        """``$OMS,<heading>,<depth>,<max pitch>,<speed>,<timeout>``: hold 2 m at 1 knot."""
        self.send(f"OMS,{heading:.1f},2.0,20.0,1.0,{self.timeout}")

    def say(self, what: str) -> None:
        print(f"backseat: {what}", flush=True)

    def run(self) -> int:
        self.say(f"on {self.port.name}, time scale {self.k:g}")
        try:
            while True:
                now = time.monotonic()
                self.step(now)
                self.receive(now)
        except (OSError, serial.SerialException):
            self.say("the port closed")
            return 0
        except KeyboardInterrupt:
            return 0


def main(argv: list[str] | None = None, backseat: type[Backseat] = Backseat) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--port", required=True, help="/dev/ttyUSB0, /dev/pts/N, socket://HOST:PORT, …")
    p.add_argument("--baud", type=int, default=19200)
    p.add_argument("--time-scale", type=float, default=1.0, help="the vehicle's clock runs K times faster")
    p.add_argument("--mission", default="conformance.mis", help="the mission to start, by name")
    p.add_argument("--steer", type=float, default=10.0, help="seconds of servo control each time")
    p.add_argument("--release", type=float, default=10.0, help="seconds the mission has the helm between")
    args = p.parse_args(argv)
    try:
        port = open_port(args.port, args.baud)
    except (OSError, serial.SerialException) as e:
        print(f"backseat: cannot open {args.port}: {e}", file=sys.stderr)
        return 2
    b = backseat(port, mission=args.mission, time_scale=args.time_scale,
                 steer_s=args.steer, release_s=args.release)
    return b.run()


if __name__ == "__main__":
    sys.exit(main())
