"""One monitored session, from the open ports to the results directory: :func:`monitor`.

The wiring: the :class:`helmcheck.line.relay.Relay` thread reads both sides with one clock (and, in line,
forwards every byte at once); each chunk it read goes to the :class:`.sessionlog.SessionLog`,
which writes and flushes it as a wire-log record; the :class:`.live.LiveJudge` — check-log's
judges in a process of their own — follows the log as it grows. New findings go to
``on_finding`` from the main thread as they arrive (a person watching, or a script, sees a
violation within a moment of its record); the view (:mod:`.view`) is refreshed from there too.

A side whose device vanishes (an adapter unplugged, a serial server's connection dropped) is
waited for under its name for ``reconnect_wait`` seconds while the other side is still relayed
and judged, and read again when it is back; the gap is in the record for the judges
(:mod:`.gaps`) and in ``results.json`` ``monitor.link_gaps``. The session ends at ``duration`` or
``until``, on Ctrl-C, SIGTERM or SIGHUP (raised as ``KeyboardInterrupt`` by
:mod:`helmcheck.signals`), or when both sides are gone for good. Then the judge
drains, and the results directory is written as ``check-log`` writes it for the same log
(:mod:`helmcheck.checklog.report`: role ``log``, both roles judged), closed as a certificate
(:func:`helmcheck.reports.certificate.finish_run`: ``profile.toml``, digests of every segment,
identity, optional signature) and rendered. ``helmcheck verify`` re-judges it with check-log.
At each rotation of the log a check of the session so far is written beside it, marked in
progress, so a session of hours has results long before it ends.
"""

from __future__ import annotations

import hashlib
import multiprocessing as mp
import time
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import Any, Callable, Optional

from .. import __version__
from ..failures import describe_interrupt
from ..grammar.wirelog import run_header
from ..judge.linemodel import line_note
from ..line.linekind import line_of_sides
from ..line.link import Link
from ..line.reopen import DEFAULT_WAIT_S, gap_event
from ..line.transport import open_link, parse_port_spec
from ..profile import Profile
from ..reports.certificate import RunDeclaration, finish_run
from ..reports.render import render_all
from ..reports.results import exit_code, write_results_atomic
from ..reports.segments import read_session
from .gaps import SideGaps
from .live import Finding, LiveJudge, helper_process
from ..line.relay import Relay
from .sessionlog import ROTATE_BYTES, SessionLog

#: The session's (first) wire-log segment.
LOG_NAME = "wire.log"

__all__ = ["Options", "Result", "monitor", "open_sides", "side_roles"]

MODES = ("tap", "between")


@dataclass
class Options:
    mode: str  #: "tap" (read only) or "between" (in line)
    backseat: str  #: port spec: the backseat's side (tap: the backseat's TX line)
    vehicle: str  #: port spec: the vehicle's side (tap: the vehicle's TX line)
    profile: Profile
    report_dir: Path
    time_scale: float = 1.0
    baud: int = 19200
    duration: Optional[float] = None  #: wall seconds
    until: Optional[float] = None  #: a ``time.time()`` to end at
    rotate_bytes: int = ROTATE_BYTES
    strict: bool = False
    command: str = ""
    certificate: Optional[RunDeclaration] = None
    render: bool = True
    on_finding: Optional[Callable[[Finding], None]] = None
    on_port: Optional[Callable[[str, str], None]] = None  #: (side, name) of a pty the monitor created
    view: Any = None  #: has ``refresh(state)``/``close()`` (``.view``), or None
    links: Optional[tuple[Link, Link]] = None  #: command hook: the two sides, opened by the command
    realtime: bool = True  #: the relay asks for real-time priority (:mod:`helmcheck.line.relay`)
    on_relay: Optional[Callable[[str], None]] = None  #: told the relay's priority once it runs
    #: seconds a side whose device vanished is waited for under its name (``--reconnect-wait``;
    #: 0: gone for good at once), :mod:`.gaps`
    reconnect_wait: float = DEFAULT_WAIT_S
    on_gap: Optional[Callable[[str], None]] = None  #: told (from the main thread) a side is gone, back
    #: ``--line clean|noisy`` (None: clean only when both sides are, :func:`helmcheck.line.linekind.line_of_sides`)
    line: Optional[str] = None


@dataclass
class Result:
    verdict: str
    reason: str
    exit_code: int
    report_dir: Path
    results: dict = field(default_factory=dict)
    findings: int = 0
    ended: str = ""


def side_roles(mode: str, backseat: str) -> tuple[str, str]:
    """How each side is opened: in line, ``socket://`` on the backseat's side listens (the backseat
    connects as to a serial server) and on the vehicle's side connects; a tap only reads, and
    opens every side as a client. (``pty`` makes a new pseudo-terminal either way.)"""
    return ("server" if mode == "between" and parse_port_spec(backseat).kind == "socket" else "client"), "client"


def open_sides(mode: str, backseat: str, vehicle: str, baud: int) -> tuple[Link, Link]:
    """Open the two sides (``OSError``/``ValueError``), in the roles of :func:`side_roles`."""
    b_role, v_role = side_roles(mode, backseat)
    b = open_link(backseat, role=b_role, baud=baud)
    try:
        return b, open_link(vehicle, role=v_role, baud=baud)
    except BaseException:
        b.close()
        raise


def monitor(opts: Options) -> Result:
    """Run one monitored session (module docstring)."""
    if opts.mode not in MODES:
        raise ValueError(f"mode must be one of {MODES}")
    links = opts.links or open_sides(opts.mode, opts.backseat, opts.vehicle, opts.baud)
    b_link, v_link = links
    for side, link in (("backseat", b_link), ("vehicle", v_link)):
        if opts.on_port is not None and parse_port_spec(getattr(opts, side)).kind == "pty":
            opts.on_port(side, link.name)
    d = Path(opts.report_dir)
    d.mkdir(parents=True, exist_ok=True)
    # the judging process first: the session starts once its judge can judge (it follows the log
    # only once told, after the log below replaces any earlier one); nothing is read meanwhile, so
    # no byte is lost, and a finding at the session's first second is not late by its start-up
    profile = opts.profile.replace(time_scale=opts.time_scale, baud=opts.baud)
    live = LiveJudge(d / LOG_NAME, profile, role="both", time_scale=opts.time_scale, baud=opts.baud)
    try:
        live.wait_ready()
        started = datetime.now(timezone.utc)
        meta = [f"started {started.strftime('%Y-%m-%dT%H:%M:%S.%fZ')}  port {b_link.name} {v_link.name}  "
                f"baud {opts.baud}  time_scale {opts.time_scale:g}",
                run_header(__version__, "monitor", opts.profile.name,
                           more=f" --{opts.mode}: backseat {opts.backseat}, vehicle {opts.vehicle}".replace(";", ","))]
        interim = _Interim(d, opts)
        slog = SessionLog(d, meta, rotate_bytes=opts.rotate_bytes, on_rotate=interim.rotated, name=LOG_NAME)
    except BaseException:
        live.stop()
        raise
    live.follow()
    t0 = time.monotonic()
    roles = dict(zip(("backseat", "vehicle"), side_roles(opts.mode, opts.backseat)))
    gaps = SideGaps({"backseat": opts.backseat, "vehicle": opts.vehicle}, roles, baud=opts.baud,
                    wait_s=opts.reconnect_wait, note=slog.note, t0=t0)

    def on_event(t: float, kind: str, side: str) -> None:  # the relay's thread, in order with the bytes
        slog.note(t - t0, f"monitor: the {side} side: {kind}")
        gaps.event(t - t0, kind, side)

    relay = Relay(b_link, v_link, forward=opts.mode == "between",
                  on_bytes=lambda t, direction, data: slog.bytes(t - t0, direction, data),
                  on_event=on_event, clock=time.monotonic, realtime=opts.realtime,
                  reopen=gaps.reopen if gaps.any else None)
    slog.note(0.0, f"monitor started ({opts.mode}): backseat {b_link.name}, vehicle {v_link.name}")
    slog.note(0.0, line_note(line_of_sides([(opts.backseat, roles["backseat"] == "server"),
                                            (opts.vehicle, roles["vehicle"] == "server")], opts.line)))
    relay.start()
    slog.note(time.monotonic() - t0, f"monitor: relay priority {relay.started()}")
    if opts.on_relay is not None:
        opts.on_relay(relay.priority)
    ended = "the session ended"
    try:
        ended = _wait(opts, relay, live, interim, t0, gaps)
    except KeyboardInterrupt as e:  # Ctrl-C, SIGTERM, SIGHUP (helmcheck.signals)
        ended = f"the monitor was {describe_interrupt(e)}"
    except BaseException:
        live.stop()
        raise
    finally:
        relay.stop(2.0)
        for link in (*links, *gaps.links):
            link.close()
        if opts.view is not None:
            opts.view.close()
    gaps.close(time.monotonic() - t0)  # a side still gone: what was held is not confirmed
    slog.note(time.monotonic() - t0, f"monitor ended: {ended}")
    slog.close()
    interim.join()
    sha = hashlib.sha256(read_session([d / n for n in slog.segments])).hexdigest()
    out, late = live.finish(sha)
    for f in late:
        _found(opts, f)
    out.segments = list(slog.segments[1:])
    out.seconds = time.monotonic() - t0
    results = _results(out, opts, ended, relay, live)
    if gaps.gaps:
        results["monitor"]["link_gaps"] = [dict(g) for g in gaps.gaps]
        results["events"] = sorted([*results.get("events", []), *map(gap_event, gaps.gaps)], key=lambda e: e["t"])
    results["monitor"]["reconnect_wait_s"] = float(opts.reconnect_wait)
    finish_run(results, d, opts.profile.replace(time_scale=opts.time_scale, baud=opts.baud), opts.certificate)
    if opts.render:
        render_all(d)
    return Result(results["verdict"], results["verdict_reason"], exit_code(results["verdict"], opts.strict), d,
                  results, live.findings, ended)


def _found(opts: Options, f: Finding) -> None:
    if opts.on_finding is not None:
        opts.on_finding(f)
    if opts.view is not None and hasattr(opts.view, "finding"):
        opts.view.finding(f)


def _wait(opts: Options, relay: Relay, live: LiveJudge, interim: "_Interim", t0: float, gaps: SideGaps) -> str:
    """Until the session ends (module docstring); returns why it ended."""
    while True:
        for f in live.poll():
            _found(opts, f)
        while gaps.messages:
            text = gaps.messages.popleft()
            if opts.on_gap is not None:
                opts.on_gap(text)
        interim.tick()
        now = time.monotonic()
        if opts.duration is not None and now - t0 >= opts.duration:
            return f"--duration {opts.duration:g} s reached"
        if opts.until is not None and time.time() >= opts.until:
            return "--until reached"
        if relay.error is not None:
            return f"the relay stopped: {relay.error}"
        if not relay.is_alive():
            return "both sides are gone"
        if live.error is not None:
            raise RuntimeError(f"judging failed: {live.error}")
        if opts.view is not None:
            opts.view.refresh(live.state(), relay.stats, now - t0)
        time.sleep(0.05)


def _results(out, opts: Options, ended: str, relay: Relay, live: LiveJudge) -> dict:
    from ..checklog.report import build_results

    profile = opts.profile.replace(time_scale=opts.time_scale, baud=opts.baud)
    res = build_results(out, profile, opts.command or f"helmcheck monitor --{opts.mode}", strict=opts.strict)
    res["log"]["copy"] = res["wire_log"]
    res["monitor"] = {"mode": opts.mode, "backseat": opts.backseat, "vehicle": opts.vehicle,
                      "ended": ended, "in_progress": False, "relay": relay.stats, "relay_priority": relay.priority,
                      "findings": live.findings, "segments": len(out.segments) + 1}
    return res


class _Interim:
    """At each rotation, a check of the session so far, written beside it, marked in progress —
    in a process of its own: neither the relay nor the live judges wait for it."""

    def __init__(self, directory: Path, opts: Options):
        self.directory = directory
        self.opts = opts
        self.proc: Optional[Any] = None
        self.wanted: Optional[str] = None

    def rotated(self, segment: str) -> None:
        """The log went on in ``segment`` (called by the relay's thread: it only takes note)."""
        self.wanted = segment

    def tick(self) -> None:
        """Start the check of a rotation noted (from the main thread)."""
        if self.wanted is None or (self.proc is not None and self.proc.is_alive()):
            return  # none wanted, or the last one still at work: a later tick starts a newer one
        segment, self.wanted = self.wanted, None
        o = self.opts
        self.proc = mp.get_context("spawn").Process(
            target=_interim_check, name="helmcheck-monitor-interim", daemon=True,
            args=(str(self.directory), o.profile, o.time_scale, o.strict, o.command, o.mode, segment, o.render))
        self.proc.start()

    def join(self) -> None:
        if self.proc is not None:
            self.proc.join()


def _interim_check(directory: str, profile: Profile, time_scale: float, strict: bool, command: str, mode: str,
                   segment: str, render: bool) -> None:
    from ..checklog.checker import check_log
    from ..checklog.report import build_results

    helper_process()
    d = Path(directory)
    try:
        out = check_log(d / "wire.log", profile=profile, role="both", time_scale=time_scale)
        res = build_results(out, profile, command or "helmcheck monitor", strict=strict)
        res["monitor"] = {"mode": mode, "in_progress": True,
                          "note": f"a check of the session up to {segment}; the session goes on"}
        write_results_atomic(d, res)
        if render:
            render_all(d)
    except Exception:  # noqa: BLE001 - an interim view only: the final results are what counts
        pass
