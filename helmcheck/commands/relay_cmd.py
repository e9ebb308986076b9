"""``helmcheck relay``: sit between two ports and spoil the line on purpose, every fault logged.

The command owns the command line only; the relay is :class:`helmcheck.line.faultrelay.FaultRelay`
and what it does to the bytes :mod:`helmcheck.line.impair` (read from ``--impair`` by
:mod:`helmcheck.line.impair_spec`, whose table of items the help shows).

Why a command of its own and not ``monitor --between … --impair``: the monitor promises that
it never alters, delays, drops or injects a byte, and it judges what it forwards as what both
ends saw; a relay that spoils the line breaks both (what the backseat sent is not what the
vehicle got), so its judging would blame an implementation for the line's faults. ``relay``
judges nothing: it gives each side a bad line and writes down exactly what it did, and any
judge (``certify``, ``monitor``) runs at one end of it, unchanged.

Standard output: ``port: PATH`` for a backseat side that is ``pty`` (first, flushed), ``vehicle
port: PATH`` for a vehicle side that is ``pty``, and the same again with the new path after
each cut. Exit status: 0 when it ran until told to stop (``--duration``, Ctrl-C, SIGTERM) or
both sides closed; 2 when a side failed during the run or the wire log could not be written;
64 usage (a bad ``--impair`` item, named; a port that cannot be opened; a ``--link`` path that
is not a symbolic link).
"""

from __future__ import annotations

import argparse
import math
import sys
import time

from ..failures import LinkFault, OutputLost, PathError, UsageError, describe_interrupt

DESCRIPTION = ("Relay every byte between two ports through a line that fails the way real ones do — paced at a "
               "baud rate, bits flipped, bytes lost, noise, late lines, a stall, a cable pulled out and pushed "
               "back in, a wrong baud rate — deterministically from a seed, every fault a note in the wire log.")


def _epilog() -> str:
    from ..line.impair_spec import items_table

    return f"""\
the line (--impair 'ITEM,ITEM,…'; '>ITEM' to the vehicle only, '<ITEM' from it only):
{items_table()}

the ports: BACKSEAT_PORT is the side a backseat (or a tester in its place) opens: 'pty' makes a
new pseudo-terminal (its path printed as 'port: /dev/pts/N'; --link gives it a stable name that
a cut re-creates), socket://HOST:PORT listens for it. VEHICLE_PORT is the vehicle's: a device,
a pty path (an emulator's), socket://HOST:PORT (a serial server), or 'pty'.

why not 'monitor --impair': the monitor promises never to alter a byte and judges what it
forwards as what both ends saw. A relay that spoils the line cannot promise either, so it
judges nothing: run the judge (certify, monitor) at one end of it, and read the relay's wire
log for what the line did ('line fault …' notes: time, direction, what).

examples:
  helmcheck relay --between pty /dev/ttyUSB0 --link /tmp/hc-vehicle \\
      --impair 'flip=1e-5,drop=1e-4,cut=5s@60' --wire-log relay.log     # a bad line to a real vehicle
  helmcheck relay --between pty /dev/pts/5 --impair 'baud=19200,<line-delay=0.6'   # a slow vehicle
  helmcheck relay --between socket://0.0.0.0:4001 /dev/ttyUSB0 --impair 'baud=115200,rx-baud=19200'

exit status: 0 stopped as asked (--duration, Ctrl-C, SIGTERM) or both sides closed;
2 a side failed during the run, or the wire log could not be written; 64 usage (a bad --impair
item, named; a port that cannot be opened; a --link path that is not a symbolic link).
"""


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = sub.add_parser("relay", help="relay between two ports through a line with faults (for testing on a bad line)",
                       description=DESCRIPTION, epilog=_epilog(), formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--between", nargs=2, metavar=("BACKSEAT_PORT", "VEHICLE_PORT"), required=True,
                   help="the two sides (see 'the ports' below)")
    p.add_argument("--impair", default="", metavar="SPEC", help="what the line does (see 'the line' below); "
                                                                "empty: a clean line")
    p.add_argument("--seed", type=int, metavar="N", help="the seed of every random draw (overrides seed= in --impair)")
    p.add_argument("--link", metavar="PATH", help="a symbolic link to the backseat side's pty, re-made after a cut")
    p.add_argument("--vehicle-link", metavar="PATH", help="the same for a vehicle side that is 'pty'")
    p.add_argument("--cut-side", choices=("backseat", "vehicle"), default="backseat",
                   help="the side a cut unplugs (default: backseat, the side a tester opens)")
    p.add_argument("--baud", type=int, default=19200, metavar="N",
                   help="the rate a serial device is opened at (default 19200); the line's pacing is --impair's baud=")
    p.add_argument("--wire-log", metavar="FILE", help="write what each side was given and every fault here")
    p.add_argument("--duration", type=float, metavar="S", help="stop after S seconds")
    p.add_argument("--no-realtime", action="store_true", help="do not ask for real-time priority for the relay thread")
    p.set_defaults(func=run)
    return p


def run(args: argparse.Namespace) -> int:
    from ..line.faultrelay import FaultRelay
    from ..line.impair_spec import ImpairError, parse_impairment
    from ..line.port_spec import BAUD_RATES
    from .ports import port_spec

    try:
        faults = parse_impairment(args.impair, seed=args.seed)
    except ImpairError as e:
        raise UsageError(f"--impair: {e}") from None
    if args.duration is not None and not (math.isfinite(args.duration) and args.duration > 0):
        raise UsageError(f"--duration must be a positive number of seconds (got {args.duration})")
    if args.baud not in BAUD_RATES:
        raise UsageError(f"--baud must be one of {', '.join(map(str, BAUD_RATES))} (got {args.baud})")
    b_port, v_port = args.between
    for port, link in ((b_port, args.link), (v_port, args.vehicle_link)):
        spec = port_spec(port, "--between")
        if link and spec.kind != "pty":
            raise UsageError(f"--link/--vehicle-link name a pty the relay makes; {port} is not 'pty'")
        if spec.kind == "device":
            import os
            if not os.path.exists(spec.path):
                raise PathError(f"cannot open {spec.text}: no such device or file")

    def on_port(side: str, name: str) -> None:
        print(f"{'port' if side == 'backseat' else 'vehicle port'}: {name}", flush=True)

    try:
        relay = FaultRelay(b_port, v_port, faults, link=args.link, vehicle_link=args.vehicle_link, baud=args.baud,
                           wire_log=args.wire_log, cut_side=args.cut_side, realtime=not args.no_realtime,
                           on_port=on_port)
    except FileExistsError as e:
        raise PathError(f"--link: {e}") from None
    except ValueError as e:
        raise UsageError(str(e)) from None
    try:
        relay.start()
    except FileExistsError as e:
        raise PathError(f"--link: {e}") from None
    except OSError as e:
        if e.filename is None:
            raise
        raise PathError(f"cannot open {e.filename}: {e.strerror or e}") from None
    print(f"helmcheck relay: backseat {relay.port_of('backseat')}, vehicle {relay.port_of('vehicle')}; impair "
          f"{faults.text or '(none)'!r}, seed {faults.seed}"
          + (f"; wire log {args.wire_log}" if args.wire_log else "")
          + "; a tester on its ports judges a line that can damage bytes with --line noisy "
            "(a pty looks clean)", file=sys.stderr, flush=True)
    ended = "the relay ended"
    try:
        ended = _wait(relay, args.duration)
    except KeyboardInterrupt as e:
        ended = describe_interrupt(e)
    finally:
        relay.stop(ended)
    print(f"helmcheck relay: stopped: {ended}", file=sys.stderr)
    stats = relay.stats["faults"]
    for d, name in ((">", "to the vehicle"), ("<", "from the vehicle")):
        s = stats.get(d, {})
        print(f"helmcheck relay: {name}: {s.get('in', 0)} bytes in, {s.get('out', 0)} out; dropped "
              f"{s.get('dropped', 0)}, bits flipped {s.get('flipped_bits', 0)}, noise bursts "
              f"{s.get('noise_bursts', 0)}, held by stalls {s.get('stalled', 0)}, lost in cuts {s.get('cut', 0)}",
              file=sys.stderr)
    if relay.log is not None and relay.log.write_error:
        raise OutputLost(f"cannot write {args.wire_log}: {relay.log.write_error}")
    if ended.startswith("link fault"):
        raise LinkFault(ended)
    return 0


def _wait(relay, duration) -> str:
    t0 = time.monotonic()
    while True:
        r = relay.relay
        if r.error is not None:
            return f"link fault: the relay stopped: {r.error}"
        if r.closed and r.closed != set(r.links):
            return f"link fault: the {' and '.join(sorted(r.closed))} side closed"
        if not r.is_alive():
            return "both sides closed"
        if duration is not None and time.monotonic() - t0 >= duration:
            return f"--duration {duration:g} s reached"
        time.sleep(0.05)
