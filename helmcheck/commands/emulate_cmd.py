"""``helmcheck emulate``: the reference vehicle on a pty, a serial device or a TCP serial server.

The emulator answers exactly as the reference model does (:mod:`helmcheck.model`); it adds
plant dynamics, mission files, the settings store and the main log
(:mod:`helmcheck.emulator`). The first line on standard output is
``port: <what to open>`` (flushed), so scripts and backseats can connect; everything else goes
to standard error (or the live view with ``--tui``). SIGINT, SIGTERM and SIGHUP stop it with
exit 0; bad arguments, a malformed profile, a port or file that cannot be opened exit 64 with a
one-line reason; a link that fails while serving, or a log that cannot be written (``--log``,
``--main-log``, ``--settings``: the emulator stops rather than serve with its record lost),
exit 2 with one line naming it.
"""

from __future__ import annotations

import argparse
import math
import sys
from datetime import datetime, timezone
from pathlib import Path

from .. import __version__, exitcodes
from ..failures import UsageError

EPILOG = """\
--baud paces the output at the line rate (10 bits per byte); --baud 0 sends unpaced (pty and
socket only). Built-in missions: conformance.mis (the profile's test mission), short.mis,
srp.mis; --missions DIR adds a directory that overrides them. $OXFLT,<code> (RH-SAF-5) is
honoured unless --no-fault-injection.

the vehicle's own safety rules (RH-SAF-5), for certifying without $OXFLT:
  a mission file line 'max_time_s 120' is the mission's Maximum Operation Time: the vehicle
  raises Stl 120 vehicle seconds after the mission starts (profile violation_trigger =
  "mission-rule"). SIGUSR1 is an operator tripping the leak sensor on the bench: the vehicle
  raises Sle at once (profile violation_trigger = "operator"), e.g. kill -USR1 <pid>.

choices the profile leaves a conforming vehicle (docs/freedoms.md): the [emulator] table of the
--profile file, or --set KEY=VALUE (a TOML value; a.b=V sets key b of table a), e.g.
  helmcheck emulate --set 'reply_delay_s=[0.1, 0.6]' --set control_tick_s=0.25
  helmcheck emulate --set timer_factor=1.03 --set pacing=burst --set decimals.lat=6
A setting outside the profile's bounds is warned about and still obeyed (a non-conforming
vehicle, for testing a tester).

examples:
  helmcheck emulate                                   # pty, prints 'port: /dev/pts/N'
  helmcheck emulate --time-scale 50 --log emulator.log  # 50x faster vehicle clock (RH-TIM-2)
  helmcheck emulate --port socket://127.0.0.1:0       # a serial server on a free TCP port, one client
  helmcheck emulate --port /dev/ttyUSB0 --baud 19200  # a real serial line, 8N1
  helmcheck emulate --tui                             # live view: traffic, fins, mode, timers
  helmcheck emulate --profile examples/emulator.toml --time-scale 20 &   # in the background
  kill %1                                             # … and stopped (SIGTERM: exit 0)

exit status: 0 stopped (Ctrl-C, SIGTERM or SIGHUP), 2 the link failed or a log could not be written,
  64 usage (bad option or profile, a port or file that cannot be opened).
"""


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = sub.add_parser("emulate", help="run the reference vehicle emulator on a serial port",
                       description="Run the reference vehicle on a pty, a serial device or a TCP serial "
                                   "server, answering as the reference model does, until stopped.",
                       epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--port", default="pty", metavar="PORT",
                   help="pty (default), a device path, or socket://HOST:PORT (port 0: any free port)")
    p.add_argument("--baud", type=int, metavar="N",
                   help="line rate for pacing and for a device (default: the profile's, 19200; 0 = unpaced)")
    p.add_argument("--profile", metavar="FILE", help="TOML profile (default: rh5)")
    p.add_argument("--time-scale", type=float, metavar="K",
                   help="vehicle clock runs K times faster than wall time (default: the profile's, 1)")
    p.add_argument("--missions", metavar="DIR", help="extra mission directory (overrides the built-in missions)")
    p.add_argument("--log", metavar="FILE", help="wire log of both directions (helmcheck wire-log 1)")
    p.add_argument("--main-log", metavar="FILE",
                   help="CSV for $OLOGD rows (default: <log stem>.mainlog.csv next to --log)")
    p.add_argument("--settings", metavar="FILE", help="JSON file that keeps $ORWSET settings across runs")
    p.add_argument("--tui", action="store_true", help="live view in the terminal")
    p.add_argument("--fault-injection", action=argparse.BooleanOptionalAction, default=True,
                   help="honour $OXFLT,<code> (RH-SAF-5); default on")
    p.add_argument("--set", dest="settings_set", action="append", default=[], metavar="KEY=VALUE",
                   help="an emulator setting (a freedom the profile leaves a vehicle; docs/freedoms.md); "
                        "overrides the profile file's [emulator] table; repeatable")
    p.set_defaults(func=run)
    return p


def _check_settings_file(path: str) -> None:
    """``--settings``: an existing file must be a settings file this emulator wrote (a JSON
    object); anything else is refused at start rather than silently replaced."""
    import json

    from ..failures import PathError
    from ..outputs import check_writable

    p = check_writable(path, "--settings")
    if not p.exists():
        return
    try:
        data = json.loads(p.read_text(encoding="utf-8"))
    except OSError as e:
        raise PathError(f"--settings: cannot read {p}: {e.strerror or e}") from None
    except ValueError as e:
        raise PathError(f"--settings: {p} is not a settings file (not JSON: {e}); remove it or name "
                        f"another file") from None
    if not isinstance(data, dict):
        raise PathError(f"--settings: {p} is not a settings file (not a JSON object); remove it or name "
                        f"another file")


def run(args: argparse.Namespace) -> int:  # noqa: C901 - argument checks, then one call
    from ..line.transport import BAUD_RATES
    from ..outputs import check_writable, is_regular_or_new, open_output_stream
    from ..profile import load_profile
    from .ports import port_spec

    profile = load_profile(args.profile)  # a ProfileError is exit 64 (helmcheck.cli)
    try:
        choices = _emulator_settings(args)
    except ValueError as e:
        raise UsageError(str(e)) from None
    scale = args.time_scale if args.time_scale is not None else profile.time_scale
    if not (isinstance(scale, float) or isinstance(scale, int)) or not math.isfinite(scale) or scale <= 0:
        raise UsageError(f"--time-scale must be a positive number (got {args.time_scale})")
    baud = args.baud if args.baud is not None else profile.baud
    if baud != 0 and baud not in BAUD_RATES:
        raise UsageError(f"--baud must be 0 or one of {', '.join(map(str, BAUD_RATES))} (got {baud})")
    spec = port_spec(args.port)
    if spec.kind in ("device", "url") and baud == 0:
        raise UsageError("--baud 0 (unpaced) needs --port pty or socket://")
    missions_dir = None
    if args.missions is not None:
        missions_dir = Path(args.missions)
        if not missions_dir.is_dir():
            from ..failures import PathError
            raise PathError(f"--missions: {args.missions} is not a directory")
    profile = profile.replace(time_scale=float(scale), baud=baud if baud else profile.baud,
                              fault_injection="oxflt" if args.fault_injection else "none")
    main_log_path = args.main_log
    if args.log:
        check_writable(args.log, "--log")
        if main_log_path is None and is_regular_or_new(Path(args.log)):
            # next to a log file; a log on a device or pipe has no "next to"
            lp = Path(args.log)
            main_log_path = str(lp.with_name(lp.stem + ".mainlog.csv"))
    if main_log_path:
        check_writable(main_log_path, "--main-log")
    if args.settings:
        _check_settings_file(args.settings)
    from .ports import open_port

    # the port first (before the grammar loads, so a bad one fails fast), then the logs: a port
    # that cannot be opened leaves every file as it was
    link = open_port(spec, role="server", baud=baud if baud else 19200, selectable=True)
    log_file = main_log_file = None
    try:
        if args.log:
            log_file = open_output_stream(args.log, "--log", stop=True, what="wire log")
        if main_log_path:
            main_log_file = open_output_stream(main_log_path, "--main-log", stop=True, what="main log",
                                               newline="")
        return _serve(args, profile, link, baud, missions_dir, log_file, main_log_file, choices)
    except BaseException:
        link.close()
        raise
    finally:
        for f in (log_file, main_log_file):
            if f is not None and not f.closed:
                try:
                    f.close()
                except Exception:  # noqa: BLE001 - the first failure is the one reported
                    pass


def _emulator_settings(args: argparse.Namespace):
    """The ``[emulator]`` table of ``--profile``, then each ``--set`` (a ``ValueError`` names a bad one)."""
    from ..emulator.freedoms import DEFAULT_SETTINGS, parse_assignment, settings_from_dict
    from ..profile import load_emulator_table

    st = settings_from_dict(load_emulator_table(args.profile), where=f"{args.profile}: [emulator]",
                            base=DEFAULT_SETTINGS)
    for text in args.settings_set:
        st = settings_from_dict(parse_assignment(text), where=f"--set {text}", base=st)
    return st


def _serve(args, profile, link, baud, missions_dir, log_file, main_log_file, choices=None) -> int:
    """Serve until stopped. A signal (:mod:`helmcheck.signals`) stops it with exit 0; a link that
    fails during the run is a :class:`~helmcheck.failures.LinkFault` (exit 2); a log that cannot
    be written stops it with :class:`~helmcheck.failures.OutputLost` (exit 2)."""
    import time

    from ..failures import LinkFault, describe_interrupt

    log = server = ui = core = None
    try:
        from ..emulator.core import EmulatorCore, MainLog
        from ..emulator.missionfile import DirectoryCatalog, builtin_dir
        from ..emulator.server import Server
        from ..grammar.wirelog import WireLogWriter, run_header
        dirs = ([missions_dir] if missions_dir is not None else []) + [builtin_dir()]
        catalog = DirectoryCatalog(dirs)
        started = datetime.now(timezone.utc)
        if log_file is not None:
            # monotonic=False: a plant or model event is logged at the wall time it happened,
            # which may come before bytes already logged (the core catches up in vehicle time)
            log = WireLogWriter(log_file, meta=(f"started {started.strftime('%Y-%m-%dT%H:%M:%S.%fZ')}  "
                                                f"port {link.name}  baud {baud}  time_scale {profile.time_scale:g}",
                                                run_header(__version__, "emulate", profile.name,
                                                           [str(Path(d).resolve()) for d in dirs])),
                                monotonic=False)
        core = EmulatorCore(profile, catalog, start=time.monotonic(), baud=baud, log=log, settings=choices,
                            main_log=MainLog(main_log_file) if main_log_file is not None else None,
                            settings_path=Path(args.settings) if args.settings else None,
                            utc0=started.timestamp(),
                            on_error=None if args.tui else lambda text: print(f"helmcheck emulate: {text}",
                                                                              file=sys.stderr))
        if args.tui:
            from ..emulator.tui import LiveView
            ui = LiveView(core, link.name)
        server = Server(link, core, ui=ui, install_signals=False)
        _operator_trips(server)  # before the port is announced: a trip is never fatal
        sys.stdout.write(f"port: {link.name}\n")
        sys.stdout.flush()
        print(f"helmcheck emulate: {link.description}, profile {profile.name}, time scale "
              f"{profile.time_scale:g}, baud {baud or 'unpaced'}, fault injection "
              f"{profile.fault_injection}, missions {', '.join(str(d) for d in dirs)}", file=sys.stderr)
        if choices is not None and not choices.is_default:
            from ..emulator.freedoms import nonconforming
            print(f"helmcheck emulate: settings {' '.join(choices.assignments())}", file=sys.stderr)
            for why in nonconforming(choices, profile):
                print(f"helmcheck emulate: warning: not a conforming vehicle: {why}", file=sys.stderr)
        stopped = "stopped"
        try:
            if ui is not None:
                ui.start()
            status = server.run()
        except KeyboardInterrupt as e:
            status, stopped = 0, f"stopped: {describe_interrupt(e)}"
    finally:
        if ui is not None:
            ui.close()
        link.close()
        if log is not None and core is not None and not log_file.closed:
            log.note(time.monotonic() - core.start, "emulator stopped")
        if log_file is not None:
            log_file.close()
        if main_log_file is not None:
            main_log_file.close()
    if status != 0:
        raise LinkFault(f"link fault on {link.name}: {server.lost or 'the link failed'}")
    print(f"helmcheck emulate: {stopped}", file=sys.stderr)
    return exitcodes.OK


#: The code an operator's trip raises (SIGUSR1): the leak sensor, the one a bench can trip.
OPERATOR_CODE = "Sle"


def _operator_trips(server) -> None:
    """SIGUSR1: an operator tripped the leak sensor (RH-SAF-5, ``violation_trigger = "operator"``)."""
    import signal

    if hasattr(signal, "SIGUSR1"):
        signal.signal(signal.SIGUSR1, lambda *_: server.request_fault(OPERATOR_CODE, "operator: SIGUSR1"))

