"""``helmcheck diff``: two vehicle implementations driven side by side; their first divergence.

Arguments are checked and both ports opened here, before anything is written (a port that
cannot be opened is exit 64, :mod:`helmcheck.commands.ports`); the diff itself is the library
entry point :func:`helmcheck.certify.diff.driver.diff`. Exit status: 0 no divergence within the
budget, 1 a divergence found, 2 inconclusive (link fault, clock not at the time scale, nothing
ran, interrupted) or a tester error, 64 usage.
"""

from __future__ import annotations

import argparse
import math
import shlex
import shutil
import sys
from pathlib import Path

from .. import exitcodes
from ..failures import UsageError
from .lineopt import add_line_argument
from .messages import report_line_for

__all__ = ["add_parser", "run", "EPILOG"]

EPILOG = """\
what is compared:
  the same generated command sequences (valid commands, remote-control commands, mutated lines,
  waits, $OXFLT when both profiles declare it) go to A and B at once, each sequence after the
  verified reset on both. After each step both are polled and compared on what the reference
  profile pins: the $ACK type, status and error code (err 26: the lockout), and the $OSI mode,
  next waypoint, park countdown and error state (field 8). Number formats, positions, attitude,
  speeds, report pacing and the other freedoms of docs/freedoms.md are not compared.

  A transition seen at slightly different times is no divergence when both sides are within
  RH-TIM-1's tolerance of the model's deadline (both are polled again past it); a difference the
  model allows (its judge holds more than one state a conforming vehicle may be in, or an unseen
  plant event: speeds and ascent rates are freedoms) ends the comparison of that sequence. A
  difference is always a divergence when a side's own judge (the one certify vehicle uses)
  failed it in that sequence: the result names that side and the clause.

results: DIR/diff.json (result, the divergence, both sides' findings), DIR/A/wire.log and
  DIR/B/wire.log, and for a divergence one replay per side, DIR/replays/A-*.json and B-*.json,
  which 'helmcheck replay DIR/replays/B-RH-SRV-2.json --port URL' re-drives on one vehicle.

examples:
  helmcheck diff --port /dev/pts/5 --port /dev/pts/7 --time-scale 20 --budget 120
  helmcheck diff --exec 'helmcheck emulate --port {port} --time-scale {time_scale}' \\
      --exec 'helmcheck emulate --port {port} --time-scale {time_scale} --set pacing=burst' \\
      --time-scale 20 --budget 10 --seed 1            # two vehicles helmcheck starts itself
  helmcheck diff --port /dev/ttyUSB0 --profile iver3.toml --time-scale 1 \\
      --exec 'helmcheck emulate --port {port} --time-scale {time_scale}' \\
      --profile-b examples/emulator.toml --time-scale-b 20   # a vehicle against the emulator

exit status: 0 no divergence within the budget, 1 a divergence, 2 inconclusive (link fault,
  a clock not at its time scale, nothing ran) or tester error, 64 usage.
"""


class _SideArg(argparse.Action):
    """``--port`` and ``--exec`` in the order given: the first is A, the second B."""

    def __call__(self, parser, namespace, values, option_string=None):
        sides = list(getattr(namespace, "sides", None) or [])
        sides.append((self.dest, values))
        namespace.sides = sides


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = sub.add_parser("diff", help="drive two vehicles with the same sequences; report their first divergence",
                       description="Drive two vehicle implementations with the same generated command "
                                   "sequences and report the first divergence of what the profile pins, "
                                   "shrunk, with a replay file for each side.",
                       epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.set_defaults(sides=[])
    p.add_argument("--port", dest="port", action=_SideArg, metavar="URL",
                   help="a vehicle's port (what pyserial opens); give two vehicles in all, --port or --exec")
    p.add_argument("--exec", dest="exec", action=_SideArg, metavar="CMD",
                   help="start a vehicle on a new pty: CMD split like a shell line, {port} replaced by its "
                        "path (appended if absent), {time_scale} by K")
    p.add_argument("--profile", metavar="FILE", help="TOML profile of both vehicles (default: rh5 defaults)")
    p.add_argument("--profile-b", metavar="FILE", help="B's profile when it differs from A's")
    p.add_argument("--time-scale", type=float, metavar="K", help="the vehicles' time scale (default: the profile's)")
    p.add_argument("--time-scale-b", type=float, metavar="K", help="B's time scale when it differs from A's")
    p.add_argument("--seed", type=int, metavar="N", help="hypothesis seed (reproducible sequences)")
    p.add_argument("--examples", type=int, default=50, metavar="N", help="sequences at most (default 50)")
    p.add_argument("--steps", type=int, default=10, metavar="N", help="steps per sequence after its reset (default 10)")
    p.add_argument("--budget", type=float, default=60.0, metavar="SECONDS",
                   help="wall-clock budget of the search and its shrinking (default 60)")
    p.add_argument("--report-dir", default="reports/diff", metavar="DIR",
                   help="where diff.json, the wire logs and the replays go (default reports/diff; an earlier "
                        "diff there is replaced)")
    p.add_argument("--no-progress", action="store_true", help="no progress lines on standard error")
    add_line_argument(p)
    p.set_defaults(func=run)
    return p


def _positive(value, option: str) -> None:
    if value is not None and (not math.isfinite(value) or value <= 0):
        raise UsageError(f"{option} must be a positive number (got {value:g})")


def _check(args: argparse.Namespace) -> None:
    if len(args.sides) != 2:
        raise UsageError(f"give exactly two vehicles, as --port URL or --exec CMD (got {len(args.sides)})")
    _positive(args.time_scale, "--time-scale")
    _positive(args.time_scale_b, "--time-scale-b")
    _positive(args.budget, "--budget")
    if args.examples < 1:
        raise UsageError("--examples must be 1 or more")
    if args.steps < 1:
        raise UsageError("--steps must be 1 or more")


def _specs(args: argparse.Namespace) -> list:
    """The two sides, profiles loaded and ports checked (nothing opened yet)."""
    from ..certify.diff.side import SideSpec
    from ..line.launcher import check_command
    from ..profile import load_profile
    from .ports import port_spec

    pa = load_profile(args.profile)  # a ProfileError is exit 64 (helmcheck.cli)
    pb = load_profile(args.profile_b) if args.profile_b else pa
    ka = args.time_scale if args.time_scale is not None else pa.time_scale
    kb = args.time_scale_b if args.time_scale_b is not None else (args.time_scale or pb.time_scale)
    specs = []
    for name, (kind, value), p, k in zip("AB", args.sides, (pa, pb), (ka, kb)):
        _positive(k, "the time scale")
        p = p.replace(time_scale=float(k))
        if kind == "exec":
            why = check_command(value)
            if why:
                raise UsageError(f"--exec ({name}): {why}")
            specs.append(SideSpec(name, "pty", p, float(k), exec_cmd=value, line=args.line))
        else:
            spec = port_spec(value)
            if spec.kind == "pty":
                raise UsageError("--port pty creates a new pseudo-terminal; give the vehicle's port (e.g. "
                                 "/dev/pts/N) or --exec CMD to start it on one")
            specs.append(SideSpec(name, value, p, float(k), line=args.line))
    return specs


def _clear(report_dir: Path) -> None:
    """An earlier diff in the directory is replaced: its own files only."""
    for name in ("A", "B", "replays"):
        shutil.rmtree(report_dir / name, ignore_errors=True)
    (report_dir / "diff.json").unlink(missing_ok=True)


def run(args: argparse.Namespace) -> int:
    from ..certify.diff.driver import DiffOptions, diff
    from ..failures import OutputLost
    from ..outputs import OutputStream, prepare_report_dir
    from .ports import open_port, port_spec

    _check(args)
    specs = _specs(args)
    report_dir = prepare_report_dir(args.report_dir, False, clear=False)
    opened = []
    try:
        for s in specs:  # opened here, once: one that cannot be opened is exit 64, nothing written
            if s.exec_cmd is None:
                s.link = open_port(port_spec(s.port), role="client", baud=s.profile.baud)
                opened.append(s.link)
        prepare_report_dir(report_dir, True)
        _clear(report_dir)
        wire: list[OutputStream] = []

        def open_wire_log(path: Path) -> OutputStream:
            try:
                path.parent.mkdir(parents=True, exist_ok=True)
                f = open(path, "w", encoding="utf-8")
            except OSError as e:
                raise OutputLost(f"cannot write wire log {path}: {e.strerror or e}") from None
            wire.append(OutputStream(f, path, stop=False, what="wire log"))
            return wire[-1]

        command = "helmcheck diff " + shlex.join(sys.argv[2:] if len(sys.argv) > 2 else [])
        opts = DiffOptions(sides=specs, report_dir=report_dir, examples=args.examples, steps=args.steps,
                           budget_s=args.budget, seed=args.seed, progress=not args.no_progress,
                           command=command.strip(), log_opener=open_wire_log)
        args.current_report_dir = str(report_dir)  # a tester error's traceback goes there
        out = diff(opts)
    finally:
        for link in opened:
            link.close()
    print(out.line)
    print(report_line_for(out.report_dir / "diff.json"))  # like every command: where to look next
    sys.stdout.flush()
    for w in wire:
        w.check()  # a wire log lost on the way: exit 2, after the result line
    return out.exit_code if out.exit_code in (0, 1, 2) else exitcodes.INCONCLUSIVE
