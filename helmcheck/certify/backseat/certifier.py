"""The library entry of ``certify backseat``: :func:`certify` (:class:`Options`) → :class:`Outcome`.

One certification: the plan made (:func:`plan_for`: each scenario as long as what it must show
needs at the run's time scale and baud; a ``duration`` shorter than that is named on standard
error before anything runs, and the plan's lengths kept), the port opened (a pty by default; the
caller may hand over a link it opened), the backseat under test started there when ``exec_cmd`` says so
(:mod:`.process`), the reference vehicle played and the scenarios staged by :class:`.runner.Runner`
while every byte the backseat sends is judged (:class:`helmcheck.judge.backseat.BackseatObserver`),
then ``results.json`` assembled from the ledger and the run facts (:mod:`.report`), the
certificate recorded (:func:`helmcheck.reports.certificate.finish_run`) and every report
rendered into ``report_dir``. Ctrl-C, SIGTERM and SIGHUP (raised as ``KeyboardInterrupt`` by
:mod:`helmcheck.signals`) end the run as a partial one; a backseat that never connects or goes
away is recorded, never raised. The command line (:mod:`helmcheck.commands.certify_backseat_cmd`)
and the pytest plugin both call this; neither parses the other's arguments.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import IO, Any, Callable, Optional

from ... import __version__
from ...failures import OutputLost, describe_interrupt
from ...grammar.wirelog import run_header
from ...judge.linemodel import line_note
from ...judge.timing import JITTER_S
from ...line.linekind import line_for
from ...line.reopen import DEFAULT_WAIT_S, reopenable
from ...line.transport import BAUD_RATES, Link, open_link, parse_port_spec
from ...profile import Profile
from ...reports.certificate import RunDeclaration, finish_run
from ...reports.render import render_all
from ...reports.results import ReportError, exit_code
from ..outcome import Outcome
from .report import build_results
from .scenarios import SCENARIOS, make_plan

__all__ = ["Options", "Outcome", "certify", "problems", "plan_for", "OVERRUN_DEFAULT"]

#: What the vehicle helmcheck plays does with requests that ask for more replies than its line
#: carries (docs/choices.md, "The vehicle's line"): a request whose replies could not start within
#: the ACK window goes unanswered. ``queue`` (every reply waits its turn) is the other reading.
OVERRUN_DEFAULT = "drop"


@dataclass
class Options:
    """What one backseat certification does. ``profile`` carries the time scale and baud unless
    ``time_scale``/``baud`` say otherwise."""

    profile: Profile
    report_dir: Path
    port: str = "pty"  #: ``pty`` (a new one), a device path, or ``socket://HOST:PORT`` (served)
    time_scale: Optional[float] = None
    baud: Optional[int] = None
    #: seconds of judged run after the backseat's first byte (None: what the plan needs, :func:`plan_for`)
    duration: Optional[float] = None
    scenarios: Optional[list[str]] = None  #: default: all of :data:`.scenarios.SCENARIOS`, in order
    strict: bool = False  #: a SHOULD not met fails the run
    connect_timeout: float = 30.0  #: seconds to wait for the backseat's first byte
    #: seconds helmcheck's own device (a serial adapter) that vanished mid-run is waited for under
    #: the same name (:mod:`.runner`, link life); 0: not waited for
    reconnect_wait: float = DEFAULT_WAIT_S
    exec_cmd: Optional[str] = None  #: start the backseat under test on the port (:mod:`.process`)
    exec_grace_s: float = 5.0  #: SIGTERM → SIGKILL when stopping it
    certificate: Optional[RunDeclaration] = None  #: identity and signing key
    command: str = ""  #: the command line recorded in ``results.json``
    progress: bool = True  #: progress on standard error (a bar on a terminal, else plain lines)
    render: bool = True  #: write report.html, junit.xml, report.md
    on_port: Optional[Callable[[str], None]] = None  #: called with the port's name once it is open
    # Command-line hooks (helmcheck.commands.certify_backseat_cmd): the link the command opened
    # (a port that cannot be opened is a usage error there) and the wire log stream it opened.
    link: Optional[Link] = None
    log: Optional[IO[str]] = None
    settings: dict[str, Any] = field(default_factory=dict)  #: recorded too (``settings`` in results.json)
    #: ``--line clean|noisy`` (None: guessed from the port, :func:`helmcheck.line.linekind.line_for`)
    line: Optional[str] = None
    #: requests asking for more replies than the line carries: ``drop`` or ``queue`` (:data:`OVERRUN_DEFAULT`)
    overrun: str = OVERRUN_DEFAULT


def _positive(x: Optional[float]) -> bool:
    return x is not None and math.isfinite(x) and x > 0


def problems(opts: Options, spell: Callable[[str], str] = lambda name: f"--{name}") -> list[str]:
    """What is wrong with *opts* before anything is opened (empty: nothing); one line each, naming
    the option as *spell* spells it (default: the command line's ``--name``)."""
    out = []
    scale = opts.time_scale if opts.time_scale is not None else opts.profile.time_scale
    if not _positive(scale):
        out.append(f"{spell('time-scale')} must be a positive number (got {scale})")
    if opts.duration is not None and not _positive(opts.duration):
        out.append(f"{spell('duration')} must be a positive number of seconds (got {opts.duration})")
    if opts.overrun not in ("drop", "queue"):
        out.append(f"{spell('overrun')} must be drop or queue (got {opts.overrun})")
    if not _positive(opts.connect_timeout):
        out.append(f"{spell('connect-timeout')} must be a positive number of seconds (got {opts.connect_timeout})")
    if not (math.isfinite(opts.reconnect_wait) and opts.reconnect_wait >= 0):
        out.append(f"{spell('reconnect-wait')} must be 0 or a positive number of seconds (got {opts.reconnect_wait})")
    if opts.exec_cmd is not None:
        from ...line.launcher import check_command
        why = check_command(opts.exec_cmd)
        if why:
            out.append(f"{spell('exec')}: {why}")
        if not _positive(opts.exec_grace_s):
            out.append(f"{spell('exec-grace')} must be a positive number of seconds (got {opts.exec_grace_s})")
    baud = opts.baud if opts.baud is not None else opts.profile.baud
    if baud not in BAUD_RATES:
        out.append(f"{spell('baud')} must be one of {', '.join(map(str, BAUD_RATES))} (got {baud})")
    unknown = [s for s in opts.scenarios or () if s not in SCENARIOS]
    if unknown:
        out.append(f"{spell('scenario')}: unknown {', '.join(unknown)} (choose from {', '.join(SCENARIOS)})")
    try:
        parse_port_spec(opts.port)
    except ValueError as e:
        out.append(f"{spell('port')}: {e}")
    return out


def plan_for(opts: Options):
    """The run's plan (:func:`.scenarios.make_plan`) for *opts*: its scenarios at its time scale and
    baud, the profile's lockout, ACK window, reaction time and longest timeout, and the ascent from
    the test mission's deepest waypoint (the vehicle helmcheck plays flies its built-in missions)."""
    from ...emulator.freedoms import DEFAULT_SETTINGS
    from ...emulator.missionfile import DirectoryCatalog, builtin_dir
    from ...model.missions import Mission

    scale = float(opts.time_scale if opts.time_scale is not None else opts.profile.time_scale)
    baud = opts.baud if opts.baud is not None else opts.profile.baud
    p = opts.profile
    found = DirectoryCatalog([builtin_dir()]).lookup(p.mission)
    depth = 0.0
    if isinstance(found, Mission) and isinstance(found.waypoints, tuple):
        depth = max((max(0.0, w.depth) for w in found.waypoints), default=0.0)
    return make_plan(list(opts.scenarios or SCENARIOS), opts.duration, time_scale=scale, lockout_s=p.lockout_s,
                     baud=baud, ack_window_s=p.ack_window_s, reaction_s=p.reaction_s,
                     timeout_max_s=float(p.timeout_range[1]), ascent_depth_m=depth,
                     ascent_mps=DEFAULT_SETTINGS.ascent_mps)


def certify(opts: Options) -> Outcome:
    """Run one backseat certification (module docstring). ``ValueError`` for options that
    :func:`problems` rejects; ``OSError`` when the port cannot be opened; :class:`OutputLost`
    when the results cannot be written."""
    wrong = problems(opts)
    if wrong:
        raise ValueError("; ".join(wrong))
    scale = float(opts.time_scale if opts.time_scale is not None else opts.profile.time_scale)
    baud = opts.baud if opts.baud is not None else opts.profile.baud
    profile = opts.profile.replace(time_scale=scale, baud=baud)
    names = list(opts.scenarios or SCENARIOS)
    plan = plan_for(opts)
    if plan.short:  # named before anything runs, whatever the progress display
        print(f"helmcheck certify backseat: {plan.note}", file=sys.stderr)
        for line in plan.describe()[1:]:
            print(f"helmcheck certify backseat: {line.strip()}", file=sys.stderr)
        sys.stderr.flush()
    report_dir = Path(opts.report_dir)
    report_dir.mkdir(parents=True, exist_ok=True)
    started_dt = datetime.now(timezone.utc)
    settings: dict[str, Any] = {"time_scale": scale, "strict": bool(opts.strict),
                                "duration_s": float(opts.duration if opts.duration is not None else plan.needed),
                                "planned_s": round(plan.total, 3), "plan_needs_s": round(plan.needed, 3),
                                "overrun": opts.overrun,
                                "scenarios": list(dict.fromkeys(names)), "baud": baud,
                                "connect_timeout_s": float(opts.connect_timeout),
                                "reconnect_wait_s": float(opts.reconnect_wait),
                                "reaction_s": float(profile.reaction_s), "jitter_s": JITTER_S, **opts.settings}
    link = opts.link if opts.link is not None else _open(opts.port, baud)
    log = opts.log if opts.log is not None else open(report_dir / "wire.log", "w", encoding="utf-8")
    outcome = _run(opts, profile, plan, report_dir, link, log, started_dt)
    results = build_results(outcome, profile=profile, settings=settings,
                            command=opts.command or f"certify backseat --port {opts.port}", port=link.name,
                            started=started_dt.isoformat(timespec="seconds").replace("+00:00", "Z"))
    try:
        # results.json with the certificate (profile.toml, digests, identity, scope, signature), then the reports
        finish_run(results, report_dir, profile, opts.certificate)
        if opts.render:
            render_all(report_dir)
    except (ReportError, OSError) as e:
        raise OutputLost(f"report not written: {e}") from None
    return Outcome(results["verdict"], results["verdict_reason"], exit_code(results["verdict"], opts.strict),
                   report_dir, results)


def _open(port: str, baud: int) -> Link:
    from .link import HangupPty

    spec = parse_port_spec(port)
    return HangupPty(baud) if spec.kind == "pty" else open_link(spec, role="server", baud=baud)


def _run(opts: Options, profile: Profile, plan, report_dir: Path, link: Link, log: IO[str], started_dt: datetime):
    """The run itself, from the open port to the closed record: the runner's outcome."""
    from ...emulator.missionfile import DirectoryCatalog, builtin_dir
    from .progress import Progress
    from .runner import Runner

    child = process = runner = None  # exec_cmd: the backseat under test (.process)
    progress = Progress(enabled=opts.progress)
    try:
        meta = [f"started {started_dt.strftime('%Y-%m-%dT%H:%M:%S.%fZ')}  port {link.name}  "
                f"baud {profile.baud}  time_scale {profile.time_scale:g}",
                run_header(__version__, "certify backseat", profile.name)]
        if opts.progress:
            print(f"helmcheck certify backseat: {link.description}, profile {profile.name}, time scale "
                  f"{profile.time_scale:g}, baud {profile.baud}, scenarios {', '.join(s.name for s in plan.slots)} "
                  f"over {plan.total:.1f} s; waiting up to {opts.connect_timeout:g} s for the backseat",
                  file=sys.stderr)
            if plan.note and not plan.short:
                print(f"helmcheck certify backseat: {plan.note}", file=sys.stderr)
        spec = parse_port_spec(opts.port)
        runner = Runner(link, profile, plan, time_scale=profile.time_scale,
                        missions=DirectoryCatalog([builtin_dir()]), log=log, meta=meta,
                        connect_timeout=opts.connect_timeout, progress=progress,
                        # helmcheck's own device can come back; a pty it made or a client it
                        # serves that goes away is the backseat leaving (.runner, link life)
                        port=opts.port if spec.kind != "socket" and reopenable(spec) else None,
                        reconnect_wait=opts.reconnect_wait, overrun=opts.overrun)
        runner.recorder.note(0.0, line_note(line_for(opts.port, opts.line, serving=True)))
        runner.recorder.note(0.0, f"plan: {plan.describe()[0]}; the vehicle's line: overrun = {opts.overrun}")
        if plan.note:
            runner.recorder.note(0.0, f"plan: {plan.note}")
        if opts.on_port is not None:  # the port is announced once the vehicle is ready to read it
            opts.on_port(link.name)
        if opts.exec_cmd:
            from .process import start_backseat
            try:
                runner.child = child = start_backseat(opts.exec_cmd, link.name, report_dir,
                                                      time_scale=profile.time_scale, grace_s=opts.exec_grace_s)
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
        return outcome
    finally:
        if child is not None and process is None:
            child.stop()  # the run never started (or broke): leave nothing behind
        if runner is not None and runner.link is not link:
            runner.link.close()  # the port opened again after a gap
        link.close()
        try:
            log.close()
        except OSError:
            pass
