"""``helmcheck certify backseat``: play the vehicle on a serial line and judge a backseat.

The command opens the port (``--port pty`` prints ``port: /dev/pts/N`` as its first line on
standard output, flushed, for the backseat to open; a device path is opened 8N1 at the
profile's baud; ``socket://HOST:PORT`` serves one client), plays the reference vehicle, stages
the scenarios of :mod:`helmcheck.certify.backseat.scenarios` with the driver's
:class:`~helmcheck.certify.backseat.runner.Runner` and judges every byte the backseat sends
(:class:`helmcheck.judge.backseat.BackseatObserver`, the judge ``check-log`` uses too).
At the end (also after Ctrl-C, SIGTERM or SIGHUP — :mod:`helmcheck.signals` raises them as
``KeyboardInterrupt`` —, a backseat that never connected or one that went away) it writes
``results.json``, ``wire.log`` and every report format into ``--report-dir``, prints one verdict
line on standard output and exits 0 (pass; non-strict without ``--strict``), 1 (fail), 2
(inconclusive; or a report, wire log or ``--wire-log`` copy that could not be written) or 64
(usage: bad option or profile, a port that cannot be opened, a report directory holding an
earlier run without ``--overwrite``). Progress goes to standard error.

With ``--exec CMD`` helmcheck starts the backseat itself once the port is open and stops it at
the end (:mod:`helmcheck.certify.backseat.process`); a backseat that exits or dies before
the end fails the run.
"""

from __future__ import annotations

import argparse
import math
import shlex
import sys
import time
from datetime import datetime, timezone
from pathlib import Path
from typing import Any, Callable, Optional

from ..certify.backseat.scenarios import SCENARIOS
from ..failures import UsageError, describe_interrupt

__all__ = ["add_arguments", "run", "EPILOG"]

EPILOG = """\
scenarios (default: all, in this order, over --duration):
  nominal      the vehicle answers as the reference model does
  reject       every command but $OSD is refused with its "incorrect values" $ACK
  lockout      a safety violation: 20 s (vehicle time) of err 26 for all but $OSD
  mission-end  the running mission ends on the vehicle ($OSI reports S)
  silence      the vehicle neither reads nor answers for a while

judged (reference profile §9): RH-BS-1 framing and checksum, RH-BS-2 field ranges,
RH-BS-3 preconditions, RH-BS-4 line budget (baud/10 bytes in any second), RH-BS-5 reaction
to rejections and lockouts, RH-BS-6 servo refresh, RH-BS-7 upper-case hex and CR LF,
RH-BS-8 $OSD polling every 5 s. A SHOULD missed is NON-STRICT (exit 0; 1 with --strict).

examples:
  helmcheck certify backseat                          # pty: prints 'port: /dev/pts/N'
  helmcheck certify backseat --duration 30 --time-scale 10 --report-dir out/
  helmcheck certify backseat --port socket://127.0.0.1:4001 --scenario lockout
  helmcheck certify backseat --port /dev/ttyUSB0 --profile site.toml --strict
  helmcheck certify backseat --time-scale 10 --exec 'python3 my_backseat.py --port {port} --k {time_scale}'

--exec CMD starts the backseat under test on the port once it is open: CMD is split like a
shell line and run without a shell; {port} becomes the pty path (or socket://HOST:PORT; {host}
and {tcp_port} its halves), {time_scale} the time scale; without {port} the port is appended.
Environment: yours, plus HELMCHECK_PORT and HELMCHECK_TIME_SCALE. Its output goes to
DIR/backseat.stdout.log and DIR/backseat.stderr.log. At the end it gets SIGTERM (its whole
process group), then SIGKILL after --exec-grace seconds. A backseat that exits or is killed
before the end fails the run: results.json "process" has its exit and last output, the clauses
whose scenarios had not finished are NOT-TESTED.

  helmcheck certify backseat --implementation moos-ivp-helm@2.1.0 --sign-key lab.key --operator "J. Doe"

certificate: --implementation names the backseat in every report; --sign-key signs the run
  (helmcheck keygen); helmcheck verify DIR --public-key lab.pub checks it against its evidence.

exit status: 0 conformant, 1 non-conformant, 2 inconclusive, 64 usage.
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--port", default="pty", metavar="PORT",
                   help="pty (default; prints 'port: /dev/pts/N' first), a device path, or socket://HOST:PORT")
    p.add_argument("--profile", metavar="FILE", help="TOML profile (default: rh5)")
    p.add_argument("--duration", type=float, default=60.0, metavar="S",
                   help="seconds of judged run after the backseat's first byte, split across the scenarios (default 60)")
    p.add_argument("--time-scale", type=float, metavar="K",
                   help="the vehicle clock runs K times faster (RH-TIM-2; tell the backseat the same K; default: the profile's)")
    p.add_argument("--scenario", action="append", choices=SCENARIOS, metavar="NAME",
                   help=f"run only these scenarios, in order (repeatable): {', '.join(SCENARIOS)}")
    p.add_argument("--report-dir", metavar="DIR",
                   help="where results.json, wire.log and the reports go (default: reports/backseat-<UTC time>)")
    p.add_argument("--strict", action="store_true", help="a SHOULD not met fails the run")
    p.add_argument("--wire-log", metavar="FILE", help="also keep a copy of the wire log here")
    p.add_argument("--connect-timeout", type=float, default=30.0, metavar="S",
                   help="seconds to wait for the backseat's first byte (default 30)")
    p.add_argument("--baud", type=int, metavar="N", help="line rate (default: the profile's)")
    p.add_argument("--exec", dest="exec_cmd", metavar="CMD",
                   help="start the backseat under test on the port ({port} is replaced, or the port appended)")
    p.add_argument("--exec-grace", type=float, default=5.0, metavar="S",
                   help="seconds between SIGTERM and SIGKILL when stopping it (default 5)")
    p.add_argument("--overwrite", action="store_true",
                   help="replace an earlier run in --report-dir (its results, wire log and reports are "
                        "removed first); without it such a directory is refused")


def _positive(x: Optional[float]) -> bool:
    return x is not None and math.isfinite(x) and x > 0


class _Progress:
    """Rich progress on standard error: scenario, elapsed time and offences so far."""

    def __init__(self) -> None:
        from rich.console import Console
        from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

        self.console = Console(stderr=True)
        self.bar = Progress(TextColumn("{task.description}"), BarColumn(), TextColumn("{task.fields[extra]}"),
                            TimeRemainingColumn(), console=self.console, transient=False,
                            disable=not self.console.is_terminal)
        self.task = None
        self._last = 0.0

    def start(self, total: float) -> None:
        self.bar.start()
        self.task = self.bar.add_task("connected", total=total, extra="")

    def update(self, elapsed: float, scenario: str, counts: dict) -> None:
        if self.task is None:
            return
        now = time.monotonic()
        if now - self._last < 0.2:
            return
        self._last = now
        bad = ", ".join(f"{c} ×{n}" for c, n in counts.items() if n)
        self.bar.update(self.task, completed=elapsed, description=f"{scenario:<11}",
                        extra=bad or "no offence so far")

    def stop(self) -> None:
        if self.task is not None:
            self.bar.stop()


def run(args: argparse.Namespace, *, on_port: Optional[Callable[[str], None]] = None) -> int:  # noqa: C901
    """Carry out ``certify backseat``; returns the exit status. ``on_port(name)`` is called
    once the port is open (after the ``port:`` line), for callers that start the backseat."""
    from ..judge.timing import JITTER_S
    from ..profile import ProfileError, load_profile
    from ..certify.backseat.scenarios import make_plan
    from ..line.transport import BAUD_RATES, parse_port_spec

    try:
        profile = load_profile(args.profile)
    except ProfileError as e:
        raise UsageError(str(e)) from None
    scale = args.time_scale if args.time_scale is not None else profile.time_scale
    if not _positive(scale):
        raise UsageError(f"--time-scale must be a positive number (got {args.time_scale})")
    if not _positive(args.duration):
        raise UsageError(f"--duration must be a positive number of seconds (got {args.duration})")
    if not _positive(args.connect_timeout):
        raise UsageError(f"--connect-timeout must be a positive number of seconds (got {args.connect_timeout})")
    exec_cmd = getattr(args, "exec_cmd", None)
    if exec_cmd is not None:
        from ..line.launcher import check_command
        why = check_command(exec_cmd)
        if why:
            raise UsageError(f"--exec: {why}")
        if not _positive(args.exec_grace):
            raise UsageError(f"--exec-grace must be a positive number of seconds (got {args.exec_grace})")
    baud = args.baud if args.baud is not None else profile.baud
    if baud not in BAUD_RATES:
        raise UsageError(f"--baud must be one of {', '.join(map(str, BAUD_RATES))} (got {baud})")
    try:
        spec = parse_port_spec(args.port)
    except ValueError as e:
        raise UsageError(f"--port: {e}") from None
    profile = profile.replace(time_scale=float(scale), baud=baud)
    from .certificate_opts import DeclarationError, declaration
    try:
        cert = declaration(args, "backseat")
    except DeclarationError as e:
        raise UsageError(str(e)) from None
    names = args.scenario or list(SCENARIOS)
    plan = make_plan(names, args.duration, time_scale=scale, lockout_s=profile.lockout_s)
    started_dt = datetime.now(timezone.utc)
    stamp = started_dt.strftime("%Y%m%dT%H%M%SZ")
    report_dir = Path(args.report_dir) if args.report_dir else Path("reports") / f"backseat-{stamp}"
    # Command-line hooks (helmcheck.outputs, helmcheck.commands.ports): every path and the port
    # checked before anything is written; the port opened once, here (exit 64 if it cannot be).
    link, log_file = _open_outputs_and_port(args, spec, profile, report_dir)
    settings: dict[str, Any] = {"time_scale": float(scale), "strict": bool(args.strict),
                                "duration_s": float(args.duration), "planned_s": round(plan.total, 3),
                                "scenarios": list(dict.fromkeys(names)), "baud": baud,
                                "connect_timeout_s": float(args.connect_timeout),
                                "reaction_s": float(profile.reaction_s), "jitter_s": JITTER_S}
    command = "helmcheck certify backseat " + shlex.join(sys.argv[3:] if sys.argv[1:3] == ["certify", "backseat"]
                                                         else ["--port", args.port])
    started = started_dt.isoformat(timespec="seconds").replace("+00:00", "Z")
    return _certify(args, profile, spec, plan, report_dir, log_file, settings, command, started, started_dt,
                    on_port, cert, link)


def _open_outputs_and_port(args, spec, profile, report_dir: Path):
    """(link, wire-log stream): paths checked, port opened, report directory prepared."""
    from ..certify.backseat.link import HangupPty
    from ..outputs import check_writable, open_output_stream, prepare_report_dir
    from .ports import open_port

    if args.wire_log:
        check_writable(args.wire_log, "--wire-log")
    prepare_report_dir(report_dir, args.overwrite, clear=False)
    link = open_port(spec, role="server", baud=profile.baud,
                     opener=(lambda: HangupPty(profile.baud)) if spec.kind == "pty" else None)
    try:
        prepare_report_dir(report_dir, args.overwrite)
        args.report_dir = str(report_dir)  # where a tester error's traceback goes
        return link, open_output_stream(report_dir / "wire.log", "--report-dir", stop=False, what="wire log")
    except BaseException:
        link.close()
        raise


def _certify(args, profile, spec, plan, report_dir: Path, log_file, settings, command: str,
             started: str, started_dt: datetime, on_port=None, cert=None, link=None) -> int:
    strict = bool(args.strict)
    outcome = None
    reason = ""
    progress = None
    child = process = None  # --exec: the backseat under test (.process)
    try:
        if link is not None:
            try:
                sys.stdout.write(f"port: {link.name}\n")
                sys.stdout.flush()
            except OSError:
                pass
            from ..emulator.missionfile import DirectoryCatalog, builtin_dir  # after the port line
            from ..certify.backseat.runner import Runner
            meta = [f"started {started_dt.strftime('%Y-%m-%dT%H:%M:%S.%fZ')}  port {link.name}  "
                    f"baud {profile.baud}  time_scale {profile.time_scale:g}"]
            print(f"helmcheck certify backseat: {link.description}, profile {profile.name}, time scale "
                  f"{profile.time_scale:g}, baud {profile.baud}, scenarios {', '.join(s.name for s in plan.slots)} "
                  f"over {plan.total:.1f} s; waiting up to {args.connect_timeout:g} s for the backseat",
                  file=sys.stderr)
            if plan.note:
                print(f"helmcheck certify backseat: {plan.note}", file=sys.stderr)
            progress = _Progress()
            if on_port is not None:
                on_port(link.name)
            runner = Runner(link, profile, plan, time_scale=profile.time_scale,
                            missions=DirectoryCatalog([builtin_dir()]), log=log_file, meta=meta,
                            connect_timeout=args.connect_timeout, progress=progress)
            if getattr(args, "exec_cmd", None):
                from ..certify.backseat.process import start_backseat
                try:
                    runner.child = child = start_backseat(args.exec_cmd, link.name, report_dir,
                                                          time_scale=profile.time_scale, grace_s=args.exec_grace)
                except OSError as e:
                    runner.stop(f"stopped: the backseat under test could not be started ({e.strerror or e})")
            try:
                outcome = runner.run()
            except KeyboardInterrupt as e:  # Ctrl-C, SIGTERM, SIGHUP (helmcheck.signals)
                outcome = runner.outcome
                outcome.status = "interrupted"
                outcome.reason = (f"the run was {describe_interrupt(e)} after "
                                  f"{outcome.ended_at - (outcome.connected_at or 0.0):.1f} s")
            finally:
                progress.stop()
                process = runner.outcome.process  # stopped and recorded before the record closed
    finally:
        if child is not None and process is None:
            child.stop()  # the run never started (or broke): leave nothing behind
        if link is not None:
            link.close()
        try:
            log_file.close()
        except OSError:
            pass
    from ..failures import OutputLost
    from ..outputs import copy_output
    from ..reports.certificate import finish_run
    from ..reports.render import render_all
    from ..reports.results import ReportError, exit_code
    from ..reports.scope import headline
    from ..certify.backseat.report import build_results

    results = build_results(outcome, profile=profile, settings=settings, command=command,
                            port=link.name if link is not None else args.port, started=started,
                            reason=reason)
    try:
        # results.json with the certificate (profile.toml, digests, identity, scope, signature), then the reports
        finish_run(results, report_dir, profile, cert)
        render_all(report_dir)
    except (ReportError, OSError) as e:
        raise OutputLost(f"report not written: {e}") from None
    verdict = results["verdict"]
    print(f"{headline(results)}. {results['verdict_reason']}")  # the headline says when the run was cut short
    print(f"helmcheck certify backseat: report in {report_dir}", file=sys.stderr)
    sys.stdout.flush()
    if hasattr(log_file, "check"):
        log_file.check()  # the wire log lost on the way is exit 2, after the verdict line
    if args.wire_log:
        copy_output(report_dir / "wire.log", args.wire_log, what="wire log copy")
    return exit_code(verdict, strict)
