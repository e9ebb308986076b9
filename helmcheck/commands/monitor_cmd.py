"""``helmcheck monitor``: judge a live session between a real backseat and a real vehicle.

The command owns the command line only; the work is :mod:`helmcheck.monitor`. Exit status, like
check-log's for the session's log: 0 conformant (nothing failed; non-strict without
``--strict``), 1 a clause failed, 2 inconclusive (or a report that could not be written), 64
usage (bad option or profile, a port that cannot be opened, a report directory that holds an
earlier run without ``--overwrite``).
"""

from __future__ import annotations

import argparse
import math
import shlex
import sys
import time
from datetime import datetime, timedelta
from pathlib import Path

from ..failures import UsageError
from .lineopt import add_line_argument

EPILOG = """\
two ways onto the line:
  --tap BACKSEAT_TX VEHICLE_TX
      passive, the safe default: the two receive lines of a serial Y-cable (two USB serial
      adapters, or any two pyserial URLs). helmcheck only reads: it never writes a byte, and the
      backseat and the vehicle talk to each other exactly as without it.
  --between BACKSEAT_PORT VEHICLE_PORT
      in line: helmcheck is ON THE VEHICLE'S COMMAND PATH. It opens both ports and forwards
      every byte unchanged, in both directions, in arrival order, at once (no line buffering),
      and judges a copy; it never alters, delays on purpose, drops or injects a byte, and if
      judging falls behind, judging waits, not forwarding. If helmcheck stops, the line is cut.
  A port is a device (/dev/ttyUSB0), socket://HOST:PORT (in line, the backseat's side listens for
  the backseat to connect, the vehicle's side connects to a serial server), rfc2217://…, or
  'pty' for a new pseudo-terminal that a simulator on this machine opens (its path is printed).

what you get: every finding as a line the moment it is made (or, on a terminal, a live screen
with both directions, the vehicle's mode, the clauses so far and the newest finding); the
session's wire.log written record by record and flushed (a monitor killed with SIGKILL leaves a
log that 'helmcheck check-log' judges up to its last record), rotated by size into wire.001.log,
wire.002.log, … (judged as one session); at the end (and a check of the session so far at every
rotation) results.json and the reports, exactly as check-log gives them for that log, signable
with --sign-key and checked by 'helmcheck verify'.

a side that vanishes (an adapter unplugged, a serial server's connection dropped): the other side
is still relayed and judged, and the gone one is opened again under the same name
(/dev/serial/by-id/...) when it is back, for up to --reconnect-wait seconds (default 30). The gap
is in the wire log: a violation seen while a side was gone is INCONCLUSIVE (the gap may explain
it), and nothing across the gap is judged; results.json "monitor.link_gaps" lists the gaps.

end: --duration S, --until HH:MM[:SS] (local time) or an ISO date-time, Ctrl-C or SIGTERM.

examples:
  helmcheck monitor --tap /dev/ttyUSB0 /dev/ttyUSB1 --profile iver3.toml --report-dir sea-trial/
  helmcheck monitor --between /dev/ttyUSB0 /dev/ttyUSB1 --duration 3600
  helmcheck emulate --port socket://127.0.0.1:5555 --time-scale 20 &   # a simulated vehicle on TCP
  helmcheck monitor --between pty socket://127.0.0.1:5555 --time-scale 20 --duration 30   # prints the
                                                    # backseat's pty: point the backseat at it

exit status: 0 conformant (non-strict without --strict), 1 a clause failed, 2 inconclusive (or a
  report that could not be written), 64 usage (bad option or profile, a port that cannot be
  opened, a report directory holding an earlier run without --overwrite).
"""


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    from .certificate_opts import add_arguments as add_certificate_arguments

    p = sub.add_parser("monitor", help="judge a live backseat-vehicle session (tap or in line)",
                       description="Judge a live session between a backseat and a vehicle, both roles at once, "
                                   "with the judges check-log uses.",
                       epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    way = p.add_mutually_exclusive_group(required=True)
    way.add_argument("--tap", nargs=2, metavar=("BACKSEAT_TX", "VEHICLE_TX"),
                     help="read the two receive lines of a Y-cable (never writes)")
    way.add_argument("--between", nargs=2, metavar=("BACKSEAT_PORT", "VEHICLE_PORT"),
                     help="sit in line and forward every byte (on the vehicle's command path)")
    p.add_argument("--profile", metavar="FILE", help="TOML profile (default: rh5)")
    p.add_argument("--time-scale", type=float, metavar="K", help="for simulators faster than real time (default: the profile's)")
    p.add_argument("--baud", type=int, metavar="N", help="line rate (default: the profile's)")
    p.add_argument("--report-dir", metavar="DIR", help="where wire.log, results.json and the reports go "
                                                       "(default: reports/monitor-<UTC time>)")
    p.add_argument("--duration", type=float, metavar="S", help="end after S seconds")
    p.add_argument("--until", metavar="TIME", help="end at HH:MM[:SS] (local time, today or tomorrow) or an ISO date-time")
    p.add_argument("--reconnect-wait", type=float, default=None, metavar="SECONDS",
                   help="how long a side whose device vanished is waited for under the same name, the "
                        "other side still relayed and judged (default 30; 0: not waited for)")
    p.add_argument("--rotate-mb", type=float, default=64.0, metavar="MB",
                   help="start a new wire-log segment every MB megabytes (default 64)")
    p.add_argument("--strict", action="store_true", help="a SHOULD not met fails the session")
    add_line_argument(p, "clean when both sides are (ptys, TCP to this host), else noisy")
    p.add_argument("--no-tui", action="store_true",
                   help="plain lines even on a terminal: each finding, and a status line every 10 s")
    p.add_argument("--no-realtime", action="store_true",
                   help="do not ask for real-time priority for the relay (by default it does, where permitted)")
    p.add_argument("--vehicle", metavar="NAME", help="the vehicle's name in the report (default: the profile's)")
    p.add_argument("--overwrite", action="store_true", help="replace an earlier run in --report-dir")
    add_certificate_arguments(p, "backseat")
    p.set_defaults(func=run)
    return p


def _until(text: str) -> float:
    """``--until`` as a ``time.time()`` (UsageError for a bad one)."""
    now = datetime.now()
    for fmt in ("%H:%M", "%H:%M:%S"):
        try:
            t = datetime.strptime(text, fmt).time()
        except ValueError:
            continue
        when = datetime.combine(now.date(), t)
        if when <= now:  # that time today is past: tomorrow's
            when += timedelta(days=1)
        return when.timestamp()
    try:
        when = datetime.fromisoformat(text)
    except ValueError:
        raise UsageError(f"--until: {text!r} is not HH:MM[:SS] or an ISO date-time") from None
    return when.timestamp() if when.tzinfo else when.astimezone().timestamp()


def run(args: argparse.Namespace) -> int:
    from ..line.transport import BAUD_RATES
    from ..monitor.session import Options, monitor
    from ..monitor.view import LiveScreen, StatusLines, finding_line
    from ..outputs import prepare_report_dir
    from ..profile import load_profile
    from ..reports.scope import headline
    from .certificate_opts import DeclarationError, declaration
    from .ports import port_spec

    profile = load_profile(args.profile)  # a ProfileError is exit 64 (helmcheck.cli)
    if args.vehicle is not None:
        profile = profile.replace(vehicle_name=args.vehicle)
    scale = args.time_scale if args.time_scale is not None else profile.time_scale
    if not (scale and math.isfinite(scale) and scale > 0):
        raise UsageError(f"--time-scale must be a positive number (got {scale})")
    baud = args.baud if args.baud is not None else profile.baud
    if baud not in BAUD_RATES:
        raise UsageError(f"--baud must be one of {', '.join(map(str, BAUD_RATES))} (got {baud})")
    if args.duration is not None and not (math.isfinite(args.duration) and args.duration > 0):
        raise UsageError(f"--duration must be a positive number of seconds (got {args.duration})")
    if not (math.isfinite(args.rotate_mb) and args.rotate_mb > 0):
        raise UsageError(f"--rotate-mb must be a positive number (got {args.rotate_mb})")
    until = _until(args.until) if args.until else None
    from ..line.reopen import DEFAULT_WAIT_S
    wait = DEFAULT_WAIT_S if args.reconnect_wait is None else args.reconnect_wait
    if not (math.isfinite(wait) and wait >= 0):
        raise UsageError(f"--reconnect-wait must be 0 or a positive number of seconds (got {wait:g})")
    mode, (b_port, v_port) = ("tap", args.tap) if args.tap else ("between", args.between)
    for port in (b_port, v_port):
        port_spec(port, f"--{mode}")
    try:
        cert = declaration(args, "backseat")
    except DeclarationError as e:
        raise UsageError(str(e)) from None
    stamp = time.strftime("%Y%m%dT%H%M%SZ", time.gmtime())
    report_dir = Path(args.report_dir) if args.report_dir else Path("reports") / f"monitor-{stamp}"
    prepare_report_dir(report_dir, args.overwrite, clear=False)  # checked before a port is opened
    links = _open(mode, b_port, v_port, baud)
    try:
        prepare_report_dir(report_dir, args.overwrite)
    except BaseException:
        for link in links:
            link.close()
        raise
    args.report_dir = str(report_dir)  # where a tester error's traceback goes
    tui = sys.stderr.isatty() and not args.no_tui
    screen = LiveScreen(f"helmcheck monitor --{mode}") if tui else StatusLines("helmcheck monitor")

    def on_finding(f) -> None:  # a live screen gets its findings from the session (it is the view)
        if not tui and f.first:
            print(finding_line(f), flush=True)

    def on_port(side: str, name: str) -> None:
        print(f"{side} port: {name}", flush=True)

    def on_gap(text: str) -> None:
        print(f"helmcheck monitor: {text}", file=sys.stderr, flush=True)

    def on_relay(priority: str) -> None:
        hint = "" if priority.startswith("real-time") or args.no_realtime else \
            " — for the lowest added latency allow it real-time priority (README: At sea)"
        print(f"helmcheck monitor: relay priority {priority}{hint}", file=sys.stderr, flush=True)

    print(f"helmcheck monitor: {mode} — backseat {links[0].name}, vehicle {links[1].name}, baud {baud}, "
          f"time scale {scale:g}; {'forwarding every byte' if mode == 'between' else 'reading only'}; "
          f"wire log in {report_dir / 'wire.log'}", file=sys.stderr, flush=True)
    command = "helmcheck " + shlex.join(sys.argv[1:]) if sys.argv[1:2] == ["monitor"] else "helmcheck monitor"
    out = monitor(Options(mode=mode, backseat=b_port, vehicle=v_port, profile=profile, report_dir=report_dir,
                          time_scale=float(scale), baud=baud, duration=args.duration, until=until,
                          rotate_bytes=int(args.rotate_mb * 1024 * 1024), strict=bool(args.strict),
                          command=command, certificate=cert, on_finding=on_finding, on_port=on_port,
                          view=screen, links=links, realtime=not args.no_realtime, on_relay=on_relay,
                          reconnect_wait=float(wait), on_gap=on_gap, line=args.line))
    from .messages import report_line
    print(f"{headline(out.results)}. {out.reason} ({out.ended}; {out.findings} finding(s))")
    print(report_line(out.report_dir), flush=True)
    return out.exit_code


def _open(mode: str, b_port: str, v_port: str, baud: int):
    """Both sides, opened once, here: a port that cannot be opened is exit 64 naming it, and
    nothing is left open (the roles are :func:`helmcheck.monitor.session.open_sides`')."""
    from ..monitor.session import side_roles
    from .ports import open_port, port_spec

    b_role, v_role = side_roles(mode, b_port)
    b = open_port(port_spec(b_port), role=b_role, baud=baud, selectable=True)
    try:
        return b, open_port(port_spec(v_port), role=v_role, baud=baud, selectable=True)
    except BaseException:
        b.close()
        raise
