#!/usr/bin/env python3
"""A backseat configured like a widely used real-time backseat driver: it polls fast and ignores answers.

Usage: ``realtime_backseat.py PORT [--time-scale K] [--baud N] [--start-missions]``. Its habits
are those of a real-time driver seen in the field, each legal on its own:

* it polls ``$OSD,G,C,S,P,,,,`` (four letters, empty trailing fields) ten times a second — about
  240 bytes a second of its own, within RH-BS-4 on 19200 baud, but about 3.2 kB a second of
  replies asked of a line that drains 1.92 kB;
* it starts the mission by name, ``$OMSTART,0,0,0,0,conformance.mis,`` (an empty SRP field), once,
  when the vehicle first reports ``S``;
* it drives ``$OMS,90.0,3.0,45.0,1.9,5`` (one decimal) every second while the last ``$OSI`` shows a
  mode other than ``S`` or ``P`` ("accepting commands"), whatever the ``$ACK`` said: it never reads
  an ``$ACK``, and it does not react to a lockout (``$OSI`` field 8) — during one it keeps sending
  ``$OMS`` (RH-BS-5, a SHOULD: NON-STRICT);
* its ``$OMS`` timeout is 5 vehicle seconds, told the time scale (``--time-scale K``: ``5 × K``,
  at most 120), refreshed every wall second.

With ``--start-missions`` it starts the mission again itself, 5 s after the vehicle began to
report ``S``, and drives from its own idea that a mission runs: it sends ``$OMS`` every second
from its first start on, also while the vehicle reports no mission (RH-BS-3, a MUST: FAIL). It
runs until the port goes away.
"""

from __future__ import annotations

import argparse
import sys
import time

import serial  # pyserial

POLL = "OSD,G,C,S,P,,,,"
POLL_EVERY = 0.1
OMS_EVERY = 1.0
RESTART_EVERY = 5.0


def frame(body: str) -> bytes:
    x = 0
    for c in body.encode("ascii"):
        x ^= c
    return f"${body}*{x:02X}\r\n".encode("ascii")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("port")
    p.add_argument("--time-scale", type=float, default=1.0)
    p.add_argument("--baud", type=int, default=19200)
    p.add_argument("--start-missions", action="store_true")
    args = p.parse_args(argv)
    ser = serial.serial_for_url(args.port, baudrate=args.baud, timeout=0.005)
    timeout = max(1, min(120, round(5 * args.time_scale)))
    oms = frame(f"OMS,90.0,3.0,45.0,1.9,{timeout}")
    start = frame("OMSTART,0,0,0,0,conformance.mis,")
    mode = None
    started = False
    s_since = None  #: when the vehicle began to report S
    t0 = time.monotonic()
    next_poll, next_oms = t0, t0 + OMS_EVERY
    buf = b""
    print(f"realtime_backseat: driving {args.port}, $OMS timeout {timeout}", flush=True)
    try:
        while True:
            now = time.monotonic()
            if now >= next_poll:
                ser.write(frame(POLL))
                next_poll += POLL_EVERY
                if next_poll < now:  # fell behind (a loaded machine): keep the rate, not the backlog
                    next_poll = now + POLL_EVERY
            if mode == "S" and s_since is None:
                s_since = now
            elif mode != "S":
                s_since = None
            if mode == "S" and (not started or (args.start_missions and now - s_since >= RESTART_EVERY)):
                ser.write(start)
                started, s_since = True, now
            if now >= next_oms:
                next_oms += OMS_EVERY
                if next_oms < now:
                    next_oms = now + OMS_EVERY
                accepting = mode is not None and mode not in ("S", "P")
                if accepting or (args.start_missions and started):
                    ser.write(oms)
            data = ser.read(ser.in_waiting or 1)
            if data:
                buf += data
                while b"\n" in buf:
                    line, buf = buf.split(b"\n", 1)
                    if line.startswith(b"$OSI,"):
                        fields = line.split(b",")
                        if len(fields) > 2:
                            mode = fields[2].decode("ascii", "replace")
            sleep = min(next_poll, next_oms) - time.monotonic()
            if sleep > 0.002 and not ser.in_waiting:
                time.sleep(min(sleep, 0.01))
    except (OSError, serial.SerialException):
        return 0


if __name__ == "__main__":
    sys.exit(main())
