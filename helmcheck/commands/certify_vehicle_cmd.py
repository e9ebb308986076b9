"""``helmcheck certify vehicle``: arguments, and the one-line verdict at the end.

``add_arguments(parser)`` and ``run(args) -> int`` are what
:mod:`helmcheck.commands.certify_cmd` dispatches to; :data:`EPILOG` is the ``--help`` epilog.
The certification itself is the driver's library entry point,
:func:`helmcheck.certify.vehicle.runner.certify`; this module is its command line.
Exit status: 0 pass (or non-strict without ``--strict``), 1 fail, 2 inconclusive, 64 usage.
``--plan`` (:mod:`helmcheck.certify.vehicle.plan`) estimates the run instead, and opens no
port and writes no file. The port is opened here, once, before anything is written
(:mod:`helmcheck.commands.ports`: one that cannot be opened is exit 64); the report directory is
checked first and cleared with ``--overwrite`` (:mod:`helmcheck.outputs`); the reports are
rendered and ``--wire-log`` copied here after the run, and a file that cannot be written is
exit 2 naming it.
"""
from __future__ import annotations

import argparse
import math
import shlex
import sys
from pathlib import Path

from .. import exitcodes
from ..failures import UsageError
from .lineopt import add_line_argument

__all__ = ["add_arguments", "run", "EPILOG"]

EPILOG = """\
how it works:
  helmcheck plays the backseat. For every vehicle clause of the profile (§1-8) it runs a numbered
  case (steps, description, expectation), each after a verified reset: $OMSTOP,0 until $OSI shows S,
  then the profile's test mission started by name ($OMSTART,0,0,0,0,<mission>,) and N verified.
  Every reply and every $OSI is compared with the reference model, durations within RH-TIM-1's
  max(0.5 s, 5 %) widened by the measured slack. Then hypothesis sends random valid and invalid
  command sequences and shrinks any failure to a replay file (helmcheck replay FILE --port URL).

time scale: before the cases, the vehicle's $GPRMC times are read against wall time for up to 2 s;
  a vehicle whose clock clearly does not run at K (the measured interval beyond 1.5x either way)
  stops the run INCONCLUSIVE, naming both rates. --no-clock-check skips it.

verdicts: pass, non-strict (a SHOULD missed), fail, inconclusive (link fault, noisy timing),
  not-tested (the profile does not claim it). A link fault is never a fail.

safety violations (§7, RH-SAF-5), per the profile's violation_trigger:
  oxflt         $OXFLT,<code> raises one at once (emulators, firmware with the test extension)
  mission-rule  the profile's violation_mission is started and helmcheck waits violation_after_s
                for its own safety rule (e.g. Maximum Operation Time) to trip
  operator      helmcheck tells you on this terminal when to trip a sensor (e.g. the leak sensor)
                and waits for $OSI field 8; without a terminal these clauses are NOT-TESTED
  none          §7 is NOT-TESTED, unless a violation happens by itself (then it is judged)

bench safety: unless the profile says [bench_safety] in_water = true, no $OMP motor byte above
  max_motor_byte and no speed above max_speed_kn is ever sent, whatever a case or hypothesis asks.

--exec CMD starts the vehicle under test (a simulator, a firmware build on the host) on a new
pty ({port} is its path; without {port} the path is appended), or with --port socket://HOST:0
on a free TCP port ({port} is socket://HOST:N, {host} and {tcp_port} its halves), or with
--port announced on the port it makes itself and prints as a line 'port: URL' (a simulator with a
pty of its own; it is given no port); {time_scale} is K. Its output goes to DIR/vehicle.stdout.log and DIR/vehicle.stderr.log; at the end it gets
SIGTERM, then SIGKILL after --exec-grace. A vehicle that exits or dies before the end fails the
run (results.json "process", its last output quoted).

plan: --plan prints every selected case with its estimated vehicle and wall time at time scale K,
  and the total, without opening a port or writing anything (--json: one JSON object). The cases
  are run on the reference vehicle in virtual time, so the estimate includes the protocol's waits
  and the ACK windows sat out for discarded lines; the exploration counts at its wall budget.
  --missions DIR names the vehicle's mission files (default: the emulator's built-in ones).

certificate: a run that judges every vehicle clause is a certificate; --select runs and runs with a
  NOT-TESTED or INCONCLUSIVE clause say "partial: N of 60 claimed clauses judged; not a certificate".
  --sign-key KEY signs the run (helmcheck keygen); helmcheck verify DIR checks it.

the vehicle left as found: before it writes a setting helmcheck reads it (in S), and at the end
  of every run (also after a FAIL, Ctrl-C, SIGTERM or SIGHUP) it stops the vehicle ($OMSTOP until
  S), writes back every setting it changed and reads them again. A restore that cannot be verified
  is exit 2 (1 when the run also failed) and a message naming what to set by hand; the report's
  "Vehicle restored" section lists each setting before and after.

a vanished port: when the vehicle's device goes away mid-run (a USB adapter unplugged: EIO; the
  socket dropped), helmcheck waits up to --reconnect-wait seconds (default 30) for it to come back
  under the same name (/dev/serial/by-id/... names an adapter plugged back), records the gap in the
  wire log (time the judge did not see: a command it cut off is INCONCLUSIVE, never FAIL), stops
  the vehicle and sees it in S again, and runs the case the gap cut from its start. Not back in
  time: the run stops (exit 2; the wire log and a partial report hold everything up to the cut)
  and prints the command that goes on from that case:
    resume: helmcheck certify vehicle --port /dev/serial/by-id/usb-... --resume reports/vehicle

results: DIR/results.json (schema 1), DIR/wire.log, DIR/profile.toml, DIR/signature.json (signed runs),
  DIR/report.html, DIR/junit.xml, DIR/report.md. A DIR that holds an earlier run is refused
  unless --overwrite. SIGINT, SIGTERM and SIGHUP end the run early: results marked partial,
  reports rendered.

examples:
  helmcheck emulate --port pty --time-scale 20 &        # a vehicle to certify; prints port: /dev/pts/N
  helmcheck certify vehicle --port /dev/pts/N --time-scale 20 --profile examples/emulator.toml
  helmcheck certify vehicle --exec 'helmcheck emulate --port {port} --time-scale {time_scale}' \\
      --time-scale 20 --profile examples/emulator.toml --select 'RH-SRV-*' --examples 0 \\
      --report-dir reports/servo                        # start the vehicle too; four clauses, no exploration
  helmcheck certify vehicle --plan --time-scale 1 --profile iver3.toml   # how long a run takes; no port
  helmcheck certify vehicle --port /dev/ttyUSB0 --profile iver3.toml --hypothesis-profile patient
  helmcheck certify vehicle --port socket://10.0.0.5:4001 --profile iver3.toml --select 'RH-SRV-*' \\
      --select RH-ACK-2
  helmcheck certify vehicle --port /dev/ttyUSB0 --resume reports/vehicle   # go on after an interruption
  helmcheck certify vehicle --port /dev/ttyUSB0 --profile iver3.toml --reconnect-wait 120   # a flaky adapter

exit status: 0 pass (or non-strict without --strict), 1 fail, 2 inconclusive, link fault, tester
  error, a vehicle not verified as restored after a run that did not fail, or an output that could
  not be written, 64 usage
  (bad option, profile, port or path).
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--port", metavar="URL",
                   help="what pyserial opens: /dev/ttyUSB0, /dev/pts/N, socket://HOST:PORT, rfc2217://… "
                        "(required unless --exec; with --exec: pty, the default, socket://HOST:0, or "
                        "announced: the vehicle makes its own port and prints 'port: URL')")
    p.add_argument("--profile", metavar="FILE", help="TOML profile (the ICS; default: rh5)")
    p.add_argument("--time-scale", type=float, metavar="K",
                   help="the vehicle's clock runs K times faster than wall time (RH-TIM-2; default: the profile's)")
    p.add_argument("--baud", type=int, metavar="N", help="line rate (default: the profile's baud)")
    p.add_argument("--report-dir", default="reports/vehicle", metavar="DIR",
                   help="where results.json, wire.log and the reports go (default: reports/vehicle)")
    p.add_argument("--select", action="append", metavar="IDS",
                   help="clause IDs or globs to certify (RH-SRV-*, RH-ACK-2); comma-separated or repeated")
    p.add_argument("--examples", type=int, metavar="N",
                   help="at most N generated sequences, within the budget (0: no exploration; default: the "
                        "--hypothesis-profile's, fast 400, patient 8)")
    p.add_argument("--seed", type=int, metavar="N", help="hypothesis seed (reproducible sequences)")
    p.add_argument("--strict", action="store_true", help="a SHOULD not met fails the run")
    p.add_argument("--wire-log", metavar="FILE", help="also copy the wire log to FILE")
    p.add_argument("--hypothesis-profile", choices=("fast", "patient"), default=None,
                   help="the exploration's budget: fast for emulators (30 s wall or 1500 s of vehicle time; "
                        "default when K > 1), patient for hardware (600 s of vehicle time or 900 s wall)")
    p.add_argument("--no-progress", action="store_true", help="no progress display")
    p.add_argument("--exec", dest="exec_cmd", metavar="CMD",
                   help="start the vehicle under test on the port: CMD is split like a shell line, run "
                        "without a shell; {port} is replaced by the port (appended if absent; with --port "
                        "announced none is given), {time_scale} by K")
    p.add_argument("--exec-grace", type=float, default=5.0, metavar="S",
                   help="seconds between SIGTERM and SIGKILL when stopping it (default 5)")
    p.add_argument("--exec-ready", type=float, default=30.0, metavar="S",
                   help="seconds it may take to open (or listen on) the port (default 30)")
    p.add_argument("--resume", metavar="DIR",
                   help="continue the interrupted run in DIR from its last completed case, into the same "
                        "report (its profile, selection, time scale and seed are the run's own)")
    p.add_argument("--reconnect-wait", type=float, default=None, metavar="SECONDS",
                   help="how long a vehicle port that vanished mid-run (an adapter unplugged, a socket "
                        "dropped) is waited for under the same name before the run stops with the --resume "
                        "command to go on (default 30; 0: not waited for)")
    p.add_argument("--precision", choices=("any", "nominal"), default="any",
                   help="nominal: timing must be judged to RH-TIM-1's tolerance + 0.3 s at most; the line "
                        "is measured first, and a vehicle started with --exec is run at the time scale that "
                        "gives it, else the run stops (exit 2) naming that time scale. any (default): judge "
                        "with what the line gives; timing clauses judged coarser say how coarse")
    add_line_argument(p)
    p.add_argument("--no-clock-check", dest="clock_check", action="store_false",
                   help="do not measure the vehicle's clock rate ($GPRMC times) against --time-scale at start "
                        "(for a vehicle whose $GPRMC time is not its own clock)")
    p.add_argument("--overwrite", action="store_true",
                   help="replace an earlier run in --report-dir (its results, wire log, reports and "
                        "replays are removed first); without it such a directory is refused")
    plan = p.add_argument_group("plan (no port opened, nothing written)")
    plan.add_argument("--plan", action="store_true",
                      help="print each selected case with its estimated vehicle and wall time at the time "
                           "scale, and the total, then exit; --port is not needed")
    plan.add_argument("--json", action="store_true",
                      help="with --plan: one JSON object (cases, total_wall_s, total_vehicle_s, assumptions)")
    plan.add_argument("--missions", metavar="DIR",
                      help="with --plan: the vehicle's mission files (default: the emulator's built-in ones)")
    plan.add_argument("--latency", metavar="SECONDS", type=float,
                      help="with --plan: how long the vehicle takes to answer a line (default 0.05; the run "
                           "itself measures it): the durations the cases choose follow from it")


def run(args: argparse.Namespace) -> int:  # noqa: C901 - argument checks, then one call
    from ..failures import OutputLost
    from ..outputs import OutputStream, check_writable, prepare_report_dir
    from ..profile import load_profile
    from ..line.transport import BAUD_RATES
    from ..certify.vehicle.runner import Options, certify
    from .ports import open_port, port_spec

    if args.resume is not None:
        why = _resume_args(args)
        if why:
            raise UsageError(why)
    profile = load_profile(args.profile)  # a ProfileError is exit 64 (helmcheck.cli)
    k = args.time_scale if args.time_scale is not None else profile.time_scale
    if not math.isfinite(k) or k <= 0:
        raise UsageError(f"--time-scale must be a positive number (got {k})")
    if args.baud is not None:
        if args.baud not in BAUD_RATES:
            raise UsageError(f"--baud must be one of {', '.join(map(str, BAUD_RATES))}")
        profile = profile.replace(baud=args.baud)
    profile = profile.replace(time_scale=float(k))
    if args.plan or args.json or args.missions is not None or args.latency is not None:
        return _plan(args, profile, k)
    if args.exec_cmd is not None:
        from ..line.launcher import check_command
        why = check_command(args.exec_cmd)
        if why:
            raise UsageError(f"--exec: {why}")
        for name in ("exec_grace", "exec_ready"):
            value = getattr(args, name)
            if not math.isfinite(value) or value <= 0:
                raise UsageError(f"--{name.replace('_', '-')} must be a positive number of seconds (got {value})")
        if args.port is None:
            args.port = "pty"
    elif args.port is None:
        raise UsageError("--port is required (or --exec CMD to start the vehicle under test)")
    spec = port_spec(args.port)
    if spec.kind == "pty" and args.exec_cmd is None:
        raise UsageError("--port pty creates a new pseudo-terminal; give the vehicle's port (e.g. /dev/pts/N) "
                         "or --exec CMD to start the vehicle on it")
    if spec.kind == "announced" and args.exec_cmd is None:
        raise UsageError("--port announced takes the port the vehicle --exec starts prints ('port: URL'); "
                         "without --exec give the vehicle's port")
    select = _selection(args)
    wait = _reconnect_wait(args)
    from .certificate_opts import DeclarationError, declaration
    try:
        cert = declaration(args, "vehicle")
    except DeclarationError as e:
        raise UsageError(str(e)) from None
    if args.wire_log:
        check_writable(args.wire_log, "--wire-log")
    resume = args.resume is not None
    report_dir = (Path(args.resume) if resume else
                  prepare_report_dir(args.report_dir, args.overwrite, clear=False))
    # the vehicle's port is opened here (a port that cannot be opened is a usage error); with
    # --exec the runner starts the vehicle under test, which opens it
    link = open_port(spec, role="client", baud=profile.baud) if args.exec_cmd is None else None
    try:
        if not resume:
            prepare_report_dir(report_dir, args.overwrite)
        wire: list[OutputStream] = []

        def open_wire_log(path: Path) -> OutputStream:
            try:
                f = open(path, "a" if resume else "w", encoding="utf-8")
            except OSError as e:
                raise OutputLost(f"cannot write wire log {path}: {e.strerror or e}") from None
            wire.append(OutputStream(f, path, stop=False, what="wire log"))
            return wire[-1]

        hp = _hypothesis_profile(args, k)
        command = "helmcheck certify vehicle " + shlex.join(sys.argv[3:] if len(sys.argv) > 3 else [])
        opts = Options(port=args.port, profile=profile, time_scale=float(k), report_dir=report_dir,
                       select=select, examples=args.examples, seed=args.seed, strict=args.strict,
                       wire_log=None, hypothesis_profile=hp, explore=args.examples != 0,
                       progress=not args.no_progress, command=command.strip(), render=False,
                       link=link, log_opener=open_wire_log, exec_cmd=args.exec_cmd,
                       exec_grace_s=args.exec_grace, exec_ready_s=args.exec_ready, certificate=cert,
                       operator=_at_a_terminal(), resume=resume, clock_check=args.clock_check,
                       precision=args.precision, reconnect_wait_s=wait, line=args.line,
                       resume_command=resume_command(args, report_dir))
        out = certify(opts)
        if out.nominal_time_scale is not None and args.exec_cmd is not None:
            # --precision nominal with a vehicle helmcheck starts: run it again at the time scale
            # this line judges timing to nominal precision at (the line was measured at its link check)
            k = out.nominal_time_scale
            print(f"helmcheck certify vehicle: --precision nominal: the line needs --time-scale {k:g}; "
                  f"starting the vehicle again at it", file=sys.stderr)
            wire.clear()
            prepare_report_dir(report_dir, True)
            opts.profile = profile.replace(time_scale=k)
            opts.time_scale = float(k)
            opts.hypothesis_profile = _hypothesis_profile(args, k)
            opts.precision = "any"
            out = certify(opts)
    finally:
        if link is not None:
            link.close()
    from ..reports.scope import exploration_note, headline, precision_note, what_to_change
    from .messages import report_line
    notes = [x for x in (what_to_change(out.results), precision_note(out.results), exploration_note(out.results))
             if x]
    print(f"{headline(out.results)}. {out.reason}{''.join(' ' + x for x in notes)}")
    print(report_line(out.report_dir))
    if out.resume_command:  # the port did not come back: one line that goes on from the cut
        print(f"resume: {out.resume_command}")
    sys.stdout.flush()
    restore = out.results.get("restore")
    if restore is not None and restore.get("attempted") and not restore.get("verified"):
        from ..certify.vehicle.restore import unverified_text
        print(f"helmcheck certify vehicle: {unverified_text(restore)}", file=sys.stderr)
    _finish_outputs(out.report_dir, wire, args.wire_log)
    return out.exit_code


#: Options a resumed run takes from its record, never from the command line.
_RESUME_FIXED = {"profile": "--profile", "time_scale": "--time-scale", "baud": "--baud", "select": "--select",
                 "examples": "--examples", "seed": "--seed", "strict": "--strict",
                 "hypothesis_profile": "--hypothesis-profile", "overwrite": "--overwrite"}


def _resume_args(args: argparse.Namespace) -> str:
    """``--resume DIR``: check DIR holds an interrupted vehicle run and fill ``args`` with its
    profile, time scale, selection and seed; the usage error, or ``""``."""
    from ..reports.results import ReportError, load_results

    given = [flag for key, flag in _RESUME_FIXED.items() if getattr(args, key, None) not in (None, False)]
    if given:
        return f"--resume continues the run as it was recorded; drop {', '.join(given)}"
    if args.report_dir != "reports/vehicle":
        return "--resume DIR is the report directory; drop --report-dir"
    d = Path(args.resume)
    try:
        prior = load_results(d)
    except ReportError as e:
        return f"--resume: {e}"
    if prior.get("role") != "vehicle":
        return f"--resume: {d} holds a {prior.get('role')} run, not a vehicle certification"
    if not prior.get("partial"):
        return f"--resume: {d} holds a finished run; there is nothing to resume"
    if not (d / "profile.toml").is_file() or not (d / "wire.log").is_file():
        return f"--resume: {d} lacks profile.toml or wire.log; it cannot be continued"
    st = prior.get("settings") or {}
    args.profile = str(d / "profile.toml")
    args.time_scale = float(st.get("time_scale", 1.0))
    args.select = st.get("select") or None
    args.examples = st.get("examples")
    args.seed = st.get("seed")
    args.strict = bool(st.get("strict", False))
    args.hypothesis_profile = st.get("hypothesis_profile")
    return ""


def _reconnect_wait(args: argparse.Namespace) -> float:
    """``--reconnect-wait`` in seconds (:data:`helmcheck.line.reopen.DEFAULT_WAIT_S` when not given)."""
    from ..line.reopen import DEFAULT_WAIT_S

    if args.reconnect_wait is None:
        return DEFAULT_WAIT_S
    if not math.isfinite(args.reconnect_wait) or args.reconnect_wait < 0:
        raise UsageError(f"--reconnect-wait must be 0 or a positive number of seconds (got {args.reconnect_wait:g})")
    if args.exec_cmd is not None and args.reconnect_wait > 0:
        raise UsageError("--reconnect-wait: a vehicle started with --exec is not waited for (its port going "
                         "away is its process ending); drop one of them")
    return float(args.reconnect_wait)


#: Options of this invocation a resumed run is given again (each: attribute, flag, takes a value).
_RESUME_AGAIN = (("reconnect_wait", "--reconnect-wait", True), ("precision", "--precision", True), ("line", "--line", True),
                 ("clock_check", "--no-clock-check", False), ("no_progress", "--no-progress", False),
                 ("sign_key", "--sign-key", True), ("operator", "--operator", True),
                 ("site", "--site", True), ("implementation", "--implementation", True))


def resume_command(args: argparse.Namespace, report_dir: Path) -> str:
    """The command that goes on with this run after a port that did not come back: ``--port`` and
    ``--resume DIR``, and this invocation's own options a resumed run takes from its command line
    (the run's profile, selection, time scale and seed are the record's, :data:`_RESUME_FIXED`)."""
    out = ["helmcheck", "certify", "vehicle", "--port", args.port, "--resume", str(report_dir)]
    for attr, flag, valued in _RESUME_AGAIN:
        value = getattr(args, attr, None)
        if attr == "clock_check":
            if value is False:
                out.append(flag)
        elif attr == "precision":
            if value not in (None, "any"):
                out += [flag, value]
        elif valued and value is not None:
            out += [flag, f"{value:g}" if isinstance(value, float) else str(value)]
        elif not valued and value:
            out.append(flag)
    return shlex.join(out)


def _at_a_terminal() -> bool:
    """A person can be told to act (``violation_trigger = "operator"``): standard input and
    standard error are a terminal."""
    try:
        return sys.stdin.isatty() and sys.stderr.isatty()
    except (AttributeError, ValueError):
        return False


def _selection(args: argparse.Namespace):
    """``--select`` as a list of IDs and globs (``None``: every case); checks ``--examples`` too."""
    select = None
    if args.select:
        select = [x.strip() for item in args.select for x in item.split(",") if x.strip()]
        from fnmatch import fnmatchcase
        from ..clauses import vehicle_clauses
        ids = [c.id for c in vehicle_clauses()]
        bad = [p for p in select if not any(fnmatchcase(cid, p) for cid in ids)]
        if bad:
            raise UsageError(f"--select: {', '.join(bad)} match no vehicle clause (e.g. RH-SRV-*, RH-ACK-2)")
    if args.examples is not None and args.examples < 0:
        raise UsageError("--examples must be 0 or more")
    return select


def _hypothesis_profile(args: argparse.Namespace, k: float) -> str:
    return args.hypothesis_profile or ("fast" if k > 1 else "patient")


def _plan(args: argparse.Namespace, profile, k: float) -> int:
    """``--plan``: the estimate (:mod:`helmcheck.certify.vehicle.plan`) on standard output; no port, no file touched."""
    import json

    from ..certify.vehicle.plan import as_json, estimate, render_text
    from ..judge.linebudget import ASSUMED_LATENCY_S

    if not args.plan:
        given = "--json" if args.json else ("--missions" if args.missions is not None else "--latency")
        raise UsageError(f"{given} goes with --plan")
    latency = ASSUMED_LATENCY_S if args.latency is None else args.latency
    if not 0.0 <= latency <= profile.ack_window_s:
        raise UsageError(f"--latency {args.latency:g}: a conforming vehicle answers within the ACK window, "
                         f"0 to {profile.ack_window_s:g} s (RH-ACK-2)")
    select = _selection(args)
    missions = None
    if args.missions is not None:
        missions = Path(args.missions)
        if not missions.is_dir():
            raise UsageError(f"--missions: {args.missions} is not a directory")
    plan = estimate(profile, k, select=select, examples=args.examples,
                    hypothesis_profile=_hypothesis_profile(args, k), missions_dir=missions, latency_s=latency)
    if args.json:
        print(json.dumps(as_json(plan), indent=1))
    else:
        print(render_text(plan))
    return exitcodes.OK


def _finish_outputs(report_dir: Path, wire: list, wire_copy) -> None:
    """Reports rendered, the wire log whole, its copy written — or :class:`OutputLost` (exit 2)."""
    from ..failures import OutputLost
    from ..outputs import copy_output
    from ..reports.render import render_all
    from ..reports.results import ReportError

    for w in wire:
        w.check()
    try:
        render_all(report_dir)
    except ReportError as e:
        raise OutputLost(f"report not written: {e}") from None
    if wire_copy:
        copy_output(report_dir / "wire.log", wire_copy, what="wire log copy")
