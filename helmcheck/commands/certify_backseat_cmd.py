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
line and ``report: DIR/report.html`` on standard output and exits 0 (pass; non-strict without ``--strict``), 1 (fail), 2
(inconclusive; or a report, wire log or ``--wire-log`` copy that could not be written) or 64
(usage: bad option or profile, a port that cannot be opened, a report directory holding an
earlier run without ``--overwrite``). Progress goes to standard error.

With ``--exec CMD`` helmcheck starts the backseat itself once the port is open and stops it at
the end (:mod:`helmcheck.certify.backseat.process`); a backseat that exits or dies before
the end fails the run. ``--plan`` prints each scenario's length at the time scale and baud, and
why (:func:`~helmcheck.certify.backseat.certifier.plan_for`), and exits 0 without opening a port;
the default ``--duration`` is that plan's. ``--overrun drop|queue`` chooses what the vehicle does
with requests that ask for more replies than its line carries.

This module turns the arguments into :class:`helmcheck.certify.backseat.certifier.Options`,
checks every path and opens the port before anything runs, and calls
:func:`~helmcheck.certify.backseat.certifier.certify` (the pytest plugin calls it too).
"""

from __future__ import annotations

import argparse
import shlex
import sys
from datetime import datetime, timezone
from pathlib import Path
from typing import Callable, Optional

from ..certify.backseat.scenarios import SCENARIOS
from ..failures import UsageError
from .lineopt import add_line_argument

__all__ = ["add_arguments", "run", "EPILOG"]

EPILOG = """\
scenarios (default: all, in this order; --plan prints how long each lasts and why):
  nominal      the vehicle answers as the reference model does
  reject       every command but $OSD is refused with its "incorrect values" $ACK
  lockout      a safety violation: 20 s (vehicle time) of err 26 for all but $OSD, then the ascent
  mission-end  the running mission ends on the vehicle ($OSI reports S)
  silence      the vehicle neither reads nor answers for a while

how long: each scenario lasts what it must show needs at the time scale and on the line (a
20 s lockout lasts 20 s of wall time at x1, 2 s at x10; a report reaches the backseat after the
ACK window and its transmit time at the baud), and is held open until its moment has reached
the backseat (the lockout's start and end, the mission's end, a staged refusal, a silence
outlasting the backseat's own timeout), by at most a stated limit; a moment that never reached
it leaves that scenario's observations unclaimed, and the run is not a certificate. The default
--duration is the plan's; a shorter one is named before the run starts and the plan is kept.

the vehicle's line: its replies leave at the baud (10 bits a byte). Requests that ask for more
replies than that (ten $OSD,G,C,S,P a second on 19200 baud) overrun it: with --overrun drop
(default) a request whose replies could not start within the ACK window goes unanswered; with
--overrun queue every reply waits its turn, later and later. Either way the verdict names the
overrun (a remark beside RH-BS-4, which bounds only what the backseat sends).

judged (reference profile §9): RH-BS-1 framing and checksum, RH-BS-2 field ranges,
RH-BS-3 preconditions, RH-BS-4 line budget (baud/10 bytes in any second), RH-BS-5 reaction
to rejections and lockouts, RH-BS-6 servo refresh, RH-BS-7 upper-case hex and CR LF,
RH-BS-8 $OSD polling every 5 s. A SHOULD missed is NON-STRICT (exit 0; 1 with --strict).

--exec CMD starts the backseat under test on the port once it is open: CMD is split like a
shell line and run without a shell; {port} becomes the pty path (or socket://HOST:PORT; {host}
and {tcp_port} its halves), {time_scale} the time scale; without {port} the port is appended.
Environment: yours, plus HELMCHECK_PORT and HELMCHECK_TIME_SCALE. Its output goes to
DIR/backseat.stdout.log and DIR/backseat.stderr.log. At the end it gets SIGTERM (its whole
process group), then SIGKILL after --exec-grace seconds. A backseat that exits or is killed
before the end fails the run: results.json "process" has its exit and last output, the clauses
whose scenarios had not finished are NOT-TESTED.

a vanished port: when helmcheck's own device (--port /dev/..., a USB adapter) goes away mid-run,
helmcheck waits up to --reconnect-wait seconds (default 30) for it to come back under the same
name (/dev/serial/by-id/...), records the gap (time the judge did not see: the next poll is due
from the return, nothing the backseat may have learnt meanwhile is held against it) and runs the
scenario it cut again from its start. Not back in time: INCONCLUSIVE (exit 2), the report holding
everything up to the cut. A backseat that closes a pty helmcheck made, or leaves its TCP port,
is the backseat going away: not waited for.

certificate: --implementation names the backseat in every report; --sign-key signs the run
  (helmcheck keygen); helmcheck verify DIR --public-key lab.pub checks it against its evidence.

examples:
  helmcheck certify backseat                          # pty: prints 'port: /dev/pts/N', waits for a backseat
  helmcheck certify backseat --plan --time-scale 1    # how long each scenario lasts at x1, and why
  helmcheck certify backseat --time-scale 10 \\
      --exec 'python3 examples/backseat.py --port {port} --time-scale {time_scale}'
  helmcheck certify backseat --port socket://127.0.0.1:0 --scenario lockout   # a TCP server; prints its port
  helmcheck certify backseat --port /dev/ttyUSB0 --profile iver3.toml --strict
  helmcheck keygen --out lab                          # a signing key pair, once
  helmcheck certify backseat --implementation moos-ivp-helm@2.1.0 --sign-key lab.key --operator "J. Doe"

exit status: 0 conformant (or non-strict without --strict), 1 non-conformant, 2 inconclusive (the
  backseat never connected, went away, or an output could not be written), 64 usage (bad option
  or profile, a port that cannot be opened, a report directory holding an earlier run).
"""


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--port", default="pty", metavar="PORT",
                   help="pty (default; prints 'port: /dev/pts/N' first), a device path, or socket://HOST:PORT")
    p.add_argument("--profile", metavar="FILE", help="TOML profile (default: rh5)")
    p.add_argument("--duration", type=float, default=None, metavar="S",
                   help="seconds of judged run after the backseat's first byte (default: what the scenarios need "
                        "at this time scale and baud, --plan; longer shares the surplus, shorter is named and "
                        "the plan kept)")
    p.add_argument("--plan", action="store_true",
                   help="print each scenario's length at this time scale and baud, and why, then exit")
    p.add_argument("--overrun", choices=("drop", "queue"), default="drop",
                   help="requests asking for more replies than the line carries: drop (default; a request whose "
                        "replies could not start within the ACK window goes unanswered) or queue (every reply "
                        "waits its turn)")
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
    p.add_argument("--reconnect-wait", type=float, default=None, metavar="SECONDS",
                   help="how long helmcheck's own device (a serial adapter: --port /dev/...) that vanished "
                        "mid-run is waited for under the same name; the scenario it cut then runs again "
                        "(default 30; 0: not waited for)")
    p.add_argument("--baud", type=int, metavar="N", help="line rate (default: the profile's)")
    p.add_argument("--exec", dest="exec_cmd", metavar="CMD",
                   help="start the backseat under test on the port ({port} is replaced, or the port appended)")
    p.add_argument("--exec-grace", type=float, default=5.0, metavar="S",
                   help="seconds between SIGTERM and SIGKILL when stopping it (default 5)")
    add_line_argument(p, "guessed from the port: clean for helmcheck's pty and TCP served on loopback")
    p.add_argument("--no-progress", action="store_true",
                   help="no progress on standard error (by default: a bar on a terminal, else a line per "
                        "scenario and at least every 10 s)")
    p.add_argument("--overwrite", action="store_true",
                   help="replace an earlier run in --report-dir (its results, wire log and reports are "
                        "removed first); without it such a directory is refused")


def run(args: argparse.Namespace, *, on_port: Optional[Callable[[str], None]] = None) -> int:
    """Carry out ``certify backseat``; returns the exit status. ``on_port(name)`` is called
    once the port is open (after the ``port:`` line), for callers that start the backseat."""
    from ..certify.backseat.certifier import Options, certify, problems
    from ..line.reopen import DEFAULT_WAIT_S
    from ..profile import ProfileError, load_profile
    from ..reports.scope import headline
    from .certificate_opts import DeclarationError, declaration
    from .ports import port_spec

    try:
        profile = load_profile(args.profile)
    except ProfileError as e:
        raise UsageError(str(e)) from None
    opts = Options(profile=profile, report_dir=Path("."), port=args.port, time_scale=args.time_scale,
                   baud=args.baud, duration=args.duration, scenarios=args.scenario, strict=bool(args.strict),
                   connect_timeout=args.connect_timeout, exec_cmd=getattr(args, "exec_cmd", None),
                   reconnect_wait=(DEFAULT_WAIT_S if getattr(args, "reconnect_wait", None) is None
                                   else args.reconnect_wait),
                   exec_grace_s=args.exec_grace, progress=not getattr(args, "no_progress", False),
                   line=getattr(args, "line", None), overrun=getattr(args, "overrun", "drop"))
    wrong = problems(opts)
    if wrong:
        raise UsageError(wrong[0])
    if getattr(args, "plan", False):
        from ..certify.backseat.certifier import plan_for
        for line in plan_for(opts).describe():
            print(line)
        return 0
    try:
        opts.certificate = declaration(args, "backseat")
    except DeclarationError as e:
        raise UsageError(str(e)) from None
    stamp = datetime.now(timezone.utc).strftime("%Y%m%dT%H%M%SZ")
    opts.report_dir = Path(args.report_dir) if args.report_dir else Path("reports") / f"backseat-{stamp}"
    opts.command = "helmcheck certify backseat " + shlex.join(
        sys.argv[3:] if sys.argv[1:3] == ["certify", "backseat"] else ["--port", args.port])
    # Every path and the port checked before anything is written; the port opened once, here
    # (exit 64 if it cannot be: helmcheck.outputs, helmcheck.commands.ports).
    opts.link, opts.log = _open_outputs_and_port(args, port_spec(args.port), opts.baud or profile.baud,
                                                 opts.report_dir)

    def announce(name: str) -> None:
        try:
            sys.stdout.write(f"port: {name}\n")
            sys.stdout.flush()
        except OSError:
            pass
        if on_port is not None:
            on_port(name)

    opts.on_port = announce
    out = certify(opts)
    from .messages import report_line
    print(f"{headline(out.results)}. {out.reason}")  # the headline says when the run was cut short
    print(report_line(out.report_dir))
    sys.stdout.flush()
    if hasattr(opts.log, "check"):
        opts.log.check()  # the wire log lost on the way is exit 2, after the verdict line
    if args.wire_log:
        from ..outputs import copy_output
        copy_output(out.report_dir / "wire.log", args.wire_log, what="wire log copy")
    return out.exit_code


def _open_outputs_and_port(args, spec, baud: int, report_dir: Path):
    """(link, wire-log stream): paths checked, port opened, report directory prepared."""
    from ..certify.backseat.link import HangupPty
    from ..outputs import check_writable, open_output_stream, prepare_report_dir
    from .ports import open_port

    if args.wire_log:
        check_writable(args.wire_log, "--wire-log")
    prepare_report_dir(report_dir, args.overwrite, clear=False)
    link = open_port(spec, role="server", baud=baud,
                     opener=(lambda: HangupPty(baud)) if spec.kind == "pty" else None)
    try:
        prepare_report_dir(report_dir, args.overwrite)
        args.report_dir = str(report_dir)  # where a tester error's traceback goes
        return link, open_output_stream(report_dir / "wire.log", "--report-dir", stop=False, what="wire log")
    except BaseException:
        link.close()
        raise
