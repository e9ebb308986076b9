"""``helmcheck check-log``: check recorded serial logs against the reference model, offline.

The command owns the command line only; the work is :mod:`helmcheck.checklog`.
Exit status, like the certifiers: 0 conformant (every judged clause passes, or non-strict
without ``--strict``), 1 a clause failed, 2 inconclusive (nothing failed, something could not be
judged; or a report that could not be written), 64 usage (bad option, unreadable or
unrecognised log file, bad profile, a report directory that holds an earlier check without
``--overwrite``) with a one-line error naming the file. With several files each is checked on
its own; the exit status is the worst of them. A directory or a pattern among the arguments (or
``--jobs``, ``--cluster``, ``--force``) is a whole archive: :mod:`.checklog_fleet_cmd` does it,
with the exit status over all files that ``docs/contracts.md`` gives.
"""

from __future__ import annotations

import argparse
import math
import os
import shlex
import sys
import time
from pathlib import Path

from .. import exitcodes
from ..failures import UsageError
from .lineopt import add_line_argument
from .messages import report_line

EPILOG = """\
formats (detected): helmcheck wire-log 1 (certify, emulate --log, monitor), socat -v, socat -x,
socat -v -x.

what is judged, unless the options say: a wire log names the run that wrote it in its header,
and is judged as that run judged it — a certify vehicle log as the vehicle's (helmcheck's own
lines there, some malformed on purpose, are not a backseat's), a certify backseat log as the
backseat's, a monitor or emulator log as both sides' — under the profile.toml of the results
directory it sits in (else the profile its header names, else rh5), at its header's time scale,
with the mission directories its header names. A capture that names none of this is judged as
both sides', under rh5; one line says what the header did not say.

The report directory (default reports/check-log-<stem>) gets results.json (role "log"), a copy
of the log, profile.toml, report.html, junit.xml and report.md: a results directory that
'helmcheck verify' re-judges like any run's. Each violation names its log line numbers.

examples:
  helmcheck check-log reports/vehicle/wire.log      # a certification's log, judged as the run judged it
  helmcheck check-log reports/vehicle/wire.log --role both --report-dir reports/both   # helmcheck's lines too
  helmcheck check-log capture.txt --missions missions/ --time-scale 1   # a socat capture of a session
  socat -v /dev/ttyUSB0,raw,b19200 PTY,link=/tmp/vehicle 2> capture.txt   # how to record one
  helmcheck check-log capture.txt --role backseat --report-dir reports/bs

whole archives (a DIR or a quoted GLOB; logs found by content, recursively):
  helmcheck check-log archive/ --report-dir out/            # out/<path of each log>/, out/summary.md
  helmcheck check-log 'archive/2026-*/**/*.log' --jobs 4 --profile iver3.toml --report-dir out-iver3/
  helmcheck check-log archive/ --report-dir out/            # again: only new or changed logs are judged
  helmcheck check-log archive/ --report-dir out/ --force    # judge every log again
  dask scheduler --port 8786                    # a cluster: the scheduler on one machine,
  dask worker tcp://HOST:8786 --nthreads 1      # a worker on each machine (same helmcheck, shared paths)
  helmcheck check-log /shared/archive --report-dir /shared/out --cluster tcp://HOST:8786

Each log gets its own results directory, mirroring the archive's tree, with check-key.json: a
log whose key (helmcheck version, profile hash, log hash, role, time scale, missions, strict)
is unchanged is not judged again. out/summary.json is the source of truth; out/summary.md has
the per-file verdicts, clause x file counts and the matrix (also out/matrix.html). A file that
cannot be read counts as 2, so the run cannot exit 0; Ctrl-C keeps the finished files and writes
the summary marked partial. --cluster needs: pip install 'helmcheck[cluster]'.

exit status: 0 conformant (every judged clause passes; non-strict without --strict), 1 a clause
  failed, 2 inconclusive (nothing failed, something could not be judged; a report that could not
  be written), 64 usage (bad option or profile, an unreadable or unrecognised log, a report
  directory holding an earlier check without --overwrite). Several files or an archive: the
  worst over the files (1 over 2 over 0).
"""


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = sub.add_parser("check-log", help="judge a recorded serial log against the reference model",
                       description="Judge a recorded serial log (a helmcheck wire log or a socat capture) "
                                   "against the reference model, clause by clause, with the judges the "
                                   "certifiers use.",
                       epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("files", nargs="+", metavar="FILE|DIR|GLOB",
                   help="log file(s) to check; a directory or a quoted pattern ('archive/**/*.log') checks a "
                        "whole archive (below)")
    p.add_argument("--profile", metavar="FILE",
                   help="TOML profile (default: the profile.toml of the run directory the log sits in, else the "
                        "profile the log's header names, else rh5)")
    p.add_argument("--report-dir", metavar="DIR",
                   help="results directory (default reports/check-log-<stem>; with several files, "
                        "DIR/<stem> each; for an archive, DIR/<path of each log below the archive> and "
                        "DIR/summary.md, default reports/check-log-<archive directory's name>)")
    p.add_argument("--role", choices=("vehicle", "backseat", "both"), default=None,
                   help="whose behaviour to judge (default: the role the run that wrote the log tested, as its "
                        "header names it: certify vehicle → vehicle, certify backseat → backseat; else both)")
    p.add_argument("--missions", metavar="DIR",
                   help="the vehicle's mission directory (default: those the log's header names; "
                        "mission-dependent answers are otherwise inconclusive)")
    p.add_argument("--time-scale", type=float, metavar="K",
                   help="vehicle clock rate (default: the log header's, else the profile's)")
    p.add_argument("--swap-directions", action="store_true",
                   help="socat's '>' is vehicle→backseat (socat started with the vehicle side first)")
    p.add_argument("--strict", action="store_true", help="a SHOULD not met fails the run")
    add_line_argument(p, "the log's own line model note; a log without one (socat -v) is noisy")
    p.add_argument("--no-render", action="store_true", help="write results.json only")
    p.add_argument("--overwrite", action="store_true",
                   help="replace an earlier check in the report directory (its results, log copy and "
                        "reports are removed first); without it such a directory is refused")
    p.add_argument("--progress", action=argparse.BooleanOptionalAction, default=None,
                   help="progress on stderr (default: for files over 4 MiB, a bar on a terminal, else a line every "
                        "10 s; for an archive, files done, lines/s and ETA: redrawn on a terminal, else a line "
                        "every 10 s, or one per file with --progress)")
    a = p.add_argument_group("archives (a DIR or GLOB argument, or any of these options)")
    a.add_argument("--jobs", type=int, metavar="N",
                   help="judge N files at a time, each in its own process (default: the cores)")
    a.add_argument("--cluster", metavar="tcp://HOST:PORT",
                   help="judge the files on a Dask distributed scheduler instead "
                        "(pip install 'helmcheck[cluster]'; a shared file system)")
    a.add_argument("--force", action="store_true",
                   help="judge every file again, also those whose results are current (cached)")
    p.set_defaults(func=run)
    return p


def _report_dir(f: Path, args: argparse.Namespace, several: bool) -> Path:
    if args.report_dir is None:
        return Path("reports") / f"check-log-{f.stem}"
    return Path(args.report_dir) / f.stem if several else Path(args.report_dir)


def _archive_mode(args: argparse.Namespace) -> bool:
    """An archive check: a directory or a pattern among the arguments, or an archive option."""
    from ..checklog.archive import is_pattern
    return (args.jobs is not None or args.cluster is not None or args.force
            or any(Path(f).is_dir() or is_pattern(f) for f in args.files))


def run(args: argparse.Namespace) -> int:  # noqa: C901 - argument checks, then one loop
    if args.time_scale is not None and not (math.isfinite(args.time_scale) and args.time_scale > 0):
        raise UsageError(f"--time-scale must be positive (got {args.time_scale})")
    if _archive_mode(args):
        from .checklog_fleet_cmd import run_fleet
        return run_fleet(args)
    from ..failures import OutputLost, PathError
    from ..outputs import prepare_report_dir
    from ..profile import load_profile
    from ..reports import results as R
    from ..reports.results import ReportError
    from ..checklog.checker import LogFormatError, check_log, log_meta
    from ..checklog.origin import resolve
    from ..checklog.report import write_report_dir

    if args.profile is not None:
        load_profile(args.profile)  # a ProfileError is exit 64 (helmcheck.cli), before anything is read
    if args.missions is not None and not Path(args.missions).is_dir():
        raise PathError(f"--missions: {args.missions} is not a directory")
    files = [Path(f) for f in args.files]
    for f in files:
        if not f.is_file() or not os.access(f, os.R_OK):
            why = "no such file" if not f.exists() else ("not a regular file" if not f.is_file() else "not readable")
            raise PathError(f"cannot read {f}: {why}")
    several = len(files) > 1
    rdirs = [_report_dir(f, args, several) for f in files]
    if len(set(map(str, rdirs))) < len(rdirs):
        raise UsageError("two FILEs have the same name: their reports would share a directory; "
                         "check them one at a time with --report-dir")
    for rdir in rdirs:  # every directory usable before any is cleared or written
        prepare_report_dir(rdir, args.overwrite, clear=False)
    worst = exitcodes.OK
    command = "helmcheck check-log " + " ".join(shlex.quote(a) for a in sys.argv[2:])
    for f, rdir in zip(files, rdirs):
        try:
            _, meta = log_meta(f)
            how = resolve(f, meta, role=args.role, profile_arg=args.profile, missions_arg=args.missions,
                          time_scale=args.time_scale)
            catalog = None
            if how.missions:
                from ..emulator.missionfile import DirectoryCatalog
                catalog = DirectoryCatalog(how.missions)
            with _progress(f, args.progress) as prog:
                out = check_log(f, profile=how.profile, role=how.role, catalog=catalog,
                                time_scale=how.time_scale, swap=args.swap_directions, progress=prog,
                                line=args.line)
        except LogFormatError as e:
            raise PathError(str(e)) from None
        except OSError as e:
            raise PathError(f"cannot read {f}: {e.strerror or e}") from None
        prepare_report_dir(rdir, args.overwrite)
        args.current_report_dir = str(rdir)
        settings: dict = {"swap_directions": bool(args.swap_directions)}
        if args.line:
            settings["line"] = args.line
        if how.missions:
            settings["missions"] = [str(Path(d).resolve()) for d in how.missions]
        try:
            res = write_report_dir(rdir, out, how.profile, command, strict=args.strict, render=not args.no_render,
                                   settings=settings, origin=how.as_dict())
        except (OSError, ReportError) as e:
            if isinstance(e, OSError):
                raise OutputLost(f"cannot write {e.filename or rdir}: {e.strerror or e}") from None
            raise OutputLost(f"report not written: {e}") from None
        _summary(f, out, res, rdir, how, rendered=not args.no_render)
        worst = max(worst, R.exit_code(res["verdict"], args.strict), key=_rank)
    return worst


def _rank(code: int) -> int:
    return {0: 0, 2: 1, 1: 2}.get(code, 3)


def _summary(f: Path, out, res: dict, rdir: Path, how, rendered: bool = True) -> None:
    counts: dict[str, int] = {}
    for c in res["clauses"]:
        counts[c["verdict"]] = counts.get(c["verdict"], 0) + 1
    print(f"{f}: {res['verdict'].upper()} — {res['verdict_reason']}{_line_hint(res)}")
    print(f"  {how.describe()}")
    if how.lacking:
        print(f"  note: {how.lacking}")
    print(f"  format {out.format}, {out.stats['records']} records, time scale {out.time_scale:g}, "
          f"timestamp step {out.resolution:g} s; clauses: "
          + ", ".join(f"{v} {n}" for v, n in sorted(counts.items())))
    if out.one_direction:
        print(f"  one-direction log ({out.one_direction} side only): the other side's clauses are not tested")
    for c in res["clauses"]:
        if c["verdict"] in ("fail", "non-strict"):
            lines = ", ".join(map(str, c.get("lines", [])[:8]))
            print(f"  {c['id']} {c['verdict']}: lines {lines}")
    print(report_line(rdir, rendered))


#: Words of a reason that gave something to a faulty line (held, or made again and dismissed).
_LINE_WORDS = ("faulty line", "the line may have", "the line, not the implementation")


def _line_hint(res: dict) -> str:
    """What to do when a log that does not say what its link was had errors given to a faulty line
    (INCONCLUSIVE, or made again and not judged): on a pty or TCP the line cannot have made them
    (:mod:`helmcheck.judge.linemodel`)."""
    from ..judge.linemodel import UNKNOWN
    if (res.get("line_model") or {}).get("why") != UNKNOWN.why:
        return ""
    if not any(w in c.get("reason", "") for c in res["clauses"] for w in _LINE_WORDS
               if c["verdict"] in ("inconclusive", "pass", "non-strict")):
        return ""
    return (" This log does not say what its link was, so errors a faulty line could have made were given to "
            "the line: if this capture's link was a pty or TCP, run with --line clean")


#: From this size on a check shows its progress without --progress.
PROGRESS_BYTES = 4 * 1024 * 1024
#: Seconds between two progress lines when standard error is not a terminal.
PLAIN_EVERY_S = 10.0


class _progress:
    """Progress on stderr, by bytes read (files over :data:`PROGRESS_BYTES`, or any with
    ``--progress``; none with ``--no-progress``): a rich bar on a terminal, else a line at most
    every :data:`PLAIN_EVERY_S` seconds."""

    def __init__(self, path: Path, wanted):
        self.path = path
        self.size = path.stat().st_size
        self.on = wanted if wanted is not None else self.size > PROGRESS_BYTES
        self.bar = None
        self._acc = 0
        self._done = 0

    def __enter__(self):
        if not self.on:
            return None
        if not sys.stderr.isatty():
            t0 = time.monotonic()
            said = [t0]

            def line(n: int) -> None:
                self._done += n
                now = time.monotonic()
                if now - said[0] >= PLAIN_EVERY_S:
                    said[0] = now
                    pct = 100.0 * self._done / self.size if self.size else 100.0
                    print(f"helmcheck check-log: {self.path}: {pct:.0f} % ({self._done / 2**20:.0f} of "
                          f"{self.size / 2**20:.0f} MiB) in {now - t0:.0f} s", file=sys.stderr, flush=True)
            return line
        from rich.console import Console
        from rich.progress import BarColumn, DownloadColumn, Progress, TimeRemainingColumn
        from rich.table import Column
        self.bar = Progress("[progress.description]{task.description}",
                            BarColumn(bar_width=20, table_column=Column(min_width=20, no_wrap=True)),
                            DownloadColumn(table_column=Column(no_wrap=True)),
                            TimeRemainingColumn(table_column=Column(no_wrap=True)),
                            console=Console(stderr=True), transient=True)
        self.bar.start()
        self.task = self.bar.add_task("checking", total=self.size)

        def step(n: int) -> None:
            self._acc += n
            if self._acc >= 262144:
                self.bar.update(self.task, advance=self._acc)
                self._acc = 0
        return step

    def __exit__(self, *exc):
        if self.bar is not None:
            self.bar.stop()
        return False
