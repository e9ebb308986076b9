"""``helmcheck check-log DIR|GLOB…``: a whole archive of logs, one results directory per log, one summary.

The command line of an archive check (``check-log`` with a directory or a pattern, or with
``--jobs``, ``--cluster`` or ``--force``); :mod:`.checklog_cmd` owns the options and hands over
here. The work is :mod:`helmcheck.checklog`: :mod:`~helmcheck.checklog.archive` finds the logs,
:mod:`~helmcheck.checklog.fleet` runs :mod:`~helmcheck.checklog.fleettask` once per log (here, in
``--jobs`` processes, or on ``--cluster``), :mod:`~helmcheck.checklog.summary` writes the summary
and decides the exit status. This module checks the options, shows progress across files on
standard error (:class:`Progress`) and prints the one-line verdict at the end.

Exit status (``docs/contracts.md``): the worst over the files, ranked 0 < 2 < 1; a file that
cannot be read or judged counts as 2; interrupted: at least 2, the summary ``partial``; 64 for a
usage error before anything is judged (bad option, no log found, an argument that names nothing,
a report directory holding something else, ``--cluster`` without the extra or with a bad address
or an unreachable scheduler).
"""

from __future__ import annotations

import argparse
import os
import shlex
import sys
import time
from pathlib import Path
from typing import Any, Optional

from ..failures import OutputLost, PathError, UsageError, describe_interrupt

__all__ = ["run_fleet", "Progress"]


#: Seconds between two progress lines when standard error is not a terminal (without --progress).
PLAIN_EVERY_S = 10.0


class Progress:
    """Files done of the total, lines judged per second and the time left, on standard error:
    one line redrawn in place on a terminal; otherwise a line at most every
    :data:`PLAIN_EVERY_S` seconds (and for the last file), or one per finished file with
    ``--progress``; nothing with ``--no-progress``. The rate counts the files judged now (not
    cached ones); the time left is the bytes not yet done at the bytes-per-second of the files
    judged so far."""

    def __init__(self, total_files: int, total_bytes: int, wanted: Optional[bool]):
        self.tty = sys.stderr.isatty()
        self.on = wanted is not False
        self.every = 0.0 if (wanted or self.tty) else PLAIN_EVERY_S
        self.total_files, self.total_bytes = total_files, total_bytes
        self.files = self.lines = self.bytes_done = self.bytes_judged = 0
        self.t0 = time.monotonic()
        self._said: Optional[float] = None

    def done(self, entry: dict[str, Any], size: int) -> None:
        self.files += 1
        self.bytes_done += size
        if entry["status"] == "judged":
            self.lines += entry.get("records", 0)
            self.bytes_judged += size
        if not self.on:
            return
        elapsed = max(time.monotonic() - self.t0, 1e-6)
        rate = self.lines / elapsed
        left = self.total_bytes - self.bytes_done
        eta = "—" if not self.bytes_judged else _duration(left / (self.bytes_judged / elapsed))
        text = (f"files {self.files}/{self.total_files} · {rate:,.0f} lines/s · ETA {eta} · "
                f"{entry['path']}: {entry.get('verdict', entry['status'])}")
        if self.tty:
            print("\r\x1b[2K" + text[:max(20, _width() - 1)], end="", file=sys.stderr, flush=True)
            return
        now = time.monotonic()
        if self._said is None or now - self._said >= self.every or self.files == self.total_files:
            self._said = now
            print(text, file=sys.stderr, flush=True)

    def close(self) -> None:
        if self.on and self.tty:
            print("\r\x1b[2K", end="", file=sys.stderr, flush=True)


def _width() -> int:
    try:
        return os.get_terminal_size(sys.stderr.fileno()).columns
    except (OSError, ValueError, AttributeError):
        return 80


def _duration(s: float) -> str:
    s = int(round(s))
    return f"{s // 3600} h {s % 3600 // 60:02d} min" if s >= 3600 else (f"{s // 60} min {s % 60:02d} s" if s >= 60
                                                                        else f"{s} s")


def _report_root(args: argparse.Namespace, archive_root: Path) -> Path:
    if args.report_dir is not None:
        return Path(args.report_dir)
    return Path("reports") / f"check-log-{archive_root.name or 'archive'}"


def _check_report_dir(d: Path, overwrite: bool) -> None:
    """The report directory is new, empty, or an earlier archive check's (its summary.json):
    anything else is refused unless ``--overwrite``."""
    if d.exists() and not d.is_dir():
        raise PathError(f"--report-dir: cannot use {d}: it exists and is not a directory")
    if not d.is_dir() or overwrite or (d / "summary.json").is_file():
        return
    if (d / "results.json").exists():
        raise PathError(f"--report-dir: {d} holds the check of one log ({d / 'results.json'}); choose another "
                        f"--report-dir for an archive, or pass --overwrite to write into it anyway")
    if any(d.iterdir()):
        raise PathError(f"--report-dir: {d} is not empty and holds no earlier archive check (summary.json); "
                        f"choose another --report-dir or pass --overwrite to write into it anyway")


def _options(args: argparse.Namespace):
    from ..checklog.fleettask import Options, profile_sha256, tree_sha256
    from ..profile import load_profile
    from ..reports.identity import source_revision

    profile = load_profile(args.profile)  # a ProfileError is exit 64 (helmcheck.cli)
    if args.profile is None:  # as check-log FILE: $OXFLT is taken as honoured
        profile = profile.replace(fault_injection="oxflt")
    missions = missions_sha = None
    if args.missions is not None:
        if not Path(args.missions).is_dir():
            raise PathError(f"--missions: {args.missions} is not a directory")
        missions = str(Path(args.missions).resolve())
        try:
            missions_sha = tree_sha256(Path(missions))
        except OSError as e:
            raise PathError(f"--missions: cannot read {e.filename or missions}: {e.strerror or e}") from None
    return Options(profile=profile, profile_sha256=profile_sha256(profile), role=args.role, missions=missions,
                   missions_sha256=missions_sha, time_scale=args.time_scale, swap=args.swap_directions,
                   strict=args.strict, render=not args.no_render, force=args.force, line=args.line,
                   profile_arg=None if args.profile is None else str(Path(args.profile).resolve()),
                   revision=source_revision())


def run_fleet(args: argparse.Namespace) -> int:
    """The archive check (module docstring); returns the exit status."""
    from ..checklog.archive import archive_root, find_logs
    from ..checklog.cluster import check_address, require_distributed
    from ..checklog.fleet import Stopped, run_tasks
    from ..checklog.fleettask import FileTask
    from ..checklog.sidejob import cores
    from ..checklog.summary import build_summary, write_summary

    jobs = args.jobs if args.jobs is not None else cores()
    if jobs < 1:
        raise UsageError(f"--jobs must be at least 1 (got {jobs})")
    if args.cluster is not None:
        if args.jobs is not None:
            raise UsageError("--jobs and --cluster exclude each other: the cluster's workers are the jobs")
        check_address(args.cluster)
        require_distributed()
    opts = _options(args)
    started = time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())
    report_dir = _report_root(args, archive_root(args.files))
    archive = find_logs(args.files, report_dir)
    if not archive.logs and not archive.unreadable:
        why = f" ({len(archive.skipped)} file(s) skipped: not logs)" if archive.skipped else ""
        raise PathError(f"no log found in {' '.join(args.files)}{why}")
    _check_report_dir(report_dir, args.overwrite)
    try:
        report_dir.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise PathError(f"--report-dir: cannot create {report_dir}: {e.strerror or e}") from None
    args.current_report_dir = str(report_dir)
    tasks = [FileTask(str(log.path), log.rel, str(report_dir / log.rel)) for log in archive.logs]
    sizes = {log.rel: log.size for log in archive.logs}
    progress = Progress(len(tasks), sum(sizes.values()), args.progress)
    partial = None
    try:
        entries = run_tasks(tasks, opts, jobs=jobs, cluster=args.cluster, sizes=[log.size for log in archive.logs],
                            on_done=lambda e: progress.done(e, sizes.get(e["path"], 0)))
    except Stopped as stop:
        entries, partial = stop.entries, describe_interrupt(stop.cause)
    finally:
        progress.close()
    command = "helmcheck check-log " + " ".join(shlex.quote(a) for a in sys.argv[2:])
    settings = {"version": opts.version, "revision": opts.revision, "role": opts.role,
                "profile": opts.profile_arg, "profile_sha256": opts.profile_sha256, "missions": opts.missions,
                "time_scale": opts.time_scale, "swap_directions": opts.swap, "strict": opts.strict,
                "render": opts.render, "force": opts.force,
                "engine": f"cluster {args.cluster}" if args.cluster else f"{jobs} process(es)"}
    doc = build_summary(archive, entries, report_dir=report_dir, options=settings, command=command,
                        started=started, strict=opts.strict, partial_reason=partial,
                        planned=[t.rel for t in tasks])
    try:
        summary_md = write_summary(report_dir, doc)
    except OSError as e:
        raise OutputLost(f"cannot write {e.filename or report_dir}: {e.strerror or e}") from None
    for f in doc["files"]:
        if f["status"] in ("unreadable", "error"):
            print(f"{f['path']}: {f['status']}: {f.get('message', '')}")
    print(f"report: {summary_md} (also {report_dir / 'summary.json'}, {report_dir / 'matrix.html'})")
    print(doc["verdict_line"])
    if partial is not None:
        print(f"helmcheck check-log: {partial}: the summary is partial; files finished keep their results",
              file=sys.stderr)
    return doc["exit_code"]
