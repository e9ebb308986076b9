"""One log of an archive, judged into its results directory or found judged already: the per-file task.

This module owns the task every way of running an archive check runs — in this process
(``--jobs 1``), in a pool of processes (``--jobs N``, :mod:`.fleet`) or on a Dask distributed
worker (``--cluster``, :mod:`.cluster`) — so the results are the same bytes whichever ran it:
:func:`judge_file` takes a :class:`FileTask` and the run's :class:`Options` (plain, picklable
data) and returns a plain ``dict`` (JSON-able) saying what happened. The judging is
:func:`~.checker.check_log` and the writing :func:`~.report.write_report_dir`, as for
``check-log FILE``.

**Each log's own run.** What the archive's options do not say is each log's own, as for
``check-log FILE`` (:mod:`.origin`): the role its header's run tested, the profile of the run
directory it sits in (or the one its header names), the mission directories its header names;
without any, the archive's defaults.

**The cache.** Each results directory gets ``check-key.json`` beside ``results.json``: the
helmcheck version and revision, the SHA-256 of the profile the log is judged under (canonical
JSON), the SHA-256 of the log (every segment, as the checker hashes it), and every option that
changes a verdict or the files written (the role judged, time scale, the mission directories'
content hash, swapped directions, strict, rendered reports). A log whose directory holds the same key and a readable
``results.json`` is not judged again (``cached``); ``force`` judges it anyway. The key is written
last, after the results and reports, so a check cut short leaves no key and is judged next time.

What a task records in ``results.json`` does not depend on how it was run: the ``command`` is the
``helmcheck check-log FILE …`` that judges this one file alone, the same for every ``--jobs`` and
``--cluster``. Only the clock differs from one run to the next (``started``, ``finished``,
``duration_s``, ``log.check_seconds`` and their renderings).
"""

from __future__ import annotations

import hashlib
import json
import os
import shlex
import traceback
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Optional

import helmcheck

from ..profile import Profile
from ..reports.segments import session_files

__all__ = ["FileTask", "Options", "judge_file", "profile_sha256", "tree_sha256", "KEY_NAME", "KEY_FORMAT"]

KEY_NAME = "check-key.json"
KEY_FORMAT = "helmcheck-check-key-1"
_BLOCK = 1 << 20


@dataclass(frozen=True)
class Options:
    """What every file of one archive check is judged with (module docstring)."""

    profile: Profile
    profile_sha256: str
    role: Optional[str] = None  #: ``None``: each log's own (the role its header's run tested, else both)
    missions: Optional[str] = None
    missions_sha256: Optional[str] = None
    time_scale: Optional[float] = None
    swap: bool = False
    strict: bool = False
    render: bool = True
    force: bool = False
    line: Optional[str] = None  #: ``--line clean|noisy`` (None: each log's own note, else noisy)
    profile_arg: Optional[str] = None  #: --profile as given (for the recorded command)
    version: str = helmcheck.__version__  #: the helmcheck that planned the run
    revision: str = "unknown"

    def key_options(self) -> dict[str, Any]:
        return {"role": self.role, "time_scale": self.time_scale, "missions_sha256": self.missions_sha256,
                "swap_directions": self.swap, "strict": self.strict, "render": self.render, "line": self.line}

    def command(self, path: str) -> str:
        """``helmcheck check-log`` of this one file with these options."""
        words = ["helmcheck", "check-log", path] + (["--role", self.role] if self.role is not None else [])
        if self.profile_arg is not None:
            words += ["--profile", self.profile_arg]
        if self.missions is not None:
            words += ["--missions", self.missions]
        if self.time_scale is not None:
            words += ["--time-scale", f"{self.time_scale:g}"]
        words += ["--swap-directions"] * self.swap + ["--strict"] * self.strict + ["--no-render"] * (not self.render)
        words += ["--line", self.line] if self.line else []
        return " ".join(shlex.quote(w) for w in words)


@dataclass(frozen=True)
class FileTask:
    path: str  #: the log, as the archive was named on the command line
    rel: str  #: its path below the archive root
    out_dir: str  #: its results directory


def profile_sha256(profile: Profile) -> str:
    """SHA-256 of the resolved profile as canonical JSON (sorted keys, no spaces)."""
    text = json.dumps(profile.as_dict(), sort_keys=True, separators=(",", ":"), default=str)
    return hashlib.sha256(text.encode()).hexdigest()


def tree_sha256(directory: Path) -> str:
    """SHA-256 over a directory's files: each relative path and its bytes, in sorted order."""
    h = hashlib.sha256()
    for top, dirs, files in sorted(os.walk(directory)):
        dirs.sort()
        for name in sorted(files):
            p = Path(top) / name
            h.update(os.path.relpath(p, directory).encode() + b"\0")
            h.update(hashlib.sha256(p.read_bytes()).digest())
    return h.hexdigest()


def _log_sha256(path: Path) -> str:
    """The checker's hash of a log: every segment's bytes, one after another."""
    h = hashlib.sha256()
    for seg in session_files(path).files:
        with open(seg, "rb") as f:
            while block := f.read(_BLOCK):
                h.update(block)
    return h.hexdigest()


@dataclass(frozen=True)
class _Judging:
    """How one log of the archive is judged: the archive's options where given, else the log's
    own (:func:`helmcheck.checklog.origin.resolve`, as ``check-log FILE`` does)."""

    profile: Profile
    profile_sha256: str
    role: Optional[str]
    missions: Optional[list]
    missions_sha256: Optional[str]
    origin: Optional[dict] = None


def _judging(path: Path, opts: Options) -> _Judging:
    from .checker import log_meta
    from .origin import resolve

    if opts.profile_arg is not None and opts.role is not None and opts.missions is not None:
        return _Judging(opts.profile, opts.profile_sha256, opts.role, [Path(opts.missions)], opts.missions_sha256)
    _, meta = log_meta(path)
    how = resolve(path, meta, role=opts.role, profile_arg=opts.profile_arg, missions_arg=opts.missions,
                  time_scale=opts.time_scale)
    profile = opts.profile if opts.profile_arg is not None else how.profile
    msha = opts.missions_sha256
    if how.missions and opts.missions is None:
        msha = hashlib.sha256("".join(tree_sha256(d) for d in how.missions).encode()).hexdigest()
    return _Judging(profile, profile_sha256(profile), how.role, how.missions, msha, how.as_dict())


def _key(opts: Options, how: _Judging, log_sha: str) -> bytes:
    options = {**opts.key_options(), "role": how.role, "missions_sha256": how.missions_sha256}
    doc = {"format": KEY_FORMAT, "helmcheck": {"version": opts.version, "revision": opts.revision},
           "profile_sha256": how.profile_sha256, "log_sha256": log_sha, "options": options}
    return (json.dumps(doc, indent=2, sort_keys=True) + "\n").encode()


def _entry(task: FileTask, status: str, **kw: Any) -> dict[str, Any]:
    return {"path": task.rel, "status": status, **kw}


def _from_results(task: FileTask, status: str, res: dict[str, Any], seconds: float = 0.0) -> dict[str, Any]:
    log = res.get("log", {})
    stats = log.get("stats", {})
    return _entry(task, status, verdict=res["verdict"], reason=res.get("verdict_reason", ""),
                  format=log.get("format"), records=int(stats.get("records", 0)),
                  bytes=int(stats.get("bytes_to_vehicle", 0)) + int(stats.get("bytes_from_vehicle", 0)),
                  seconds=round(seconds, 3), clauses={c["id"]: c["verdict"] for c in res.get("clauses", ())})


def _cached(task: FileTask, opts: Options, how: _Judging, out: Path) -> Optional[dict[str, Any]]:
    """The entry of a log judged already with this key, else None."""
    from ..reports.results import ReportError, load_results
    try:
        stored = (out / KEY_NAME).read_bytes()
    except OSError:
        return None
    if stored != _key(opts, how, _log_sha256(Path(task.path))):
        return None
    try:
        res = load_results(out)
    except ReportError:
        return None
    if opts.render and not (out / "report.html").is_file():
        return None
    return _from_results(task, "cached", res)


def judge_file(task: FileTask, opts: Options) -> dict[str, Any]:
    """Judge one log of the archive, or find it judged (module docstring). Never raises for the
    file's sake: a log that cannot be read is ``unreadable``, a report that cannot be written or
    a tester bug is ``error`` (with ``tester-error.txt`` in its directory)."""
    from ..failures import PathError
    from ..outputs import prepare_report_dir
    from ..reports.atomic import write_bytes_atomic
    from ..reports.results import ReportError
    from .checker import LogFormatError, check_log
    from .report import write_report_dir

    if opts.version != helmcheck.__version__:
        return _entry(task, "error", message=f"this worker runs helmcheck {helmcheck.__version__}, the check "
                                             f"was started with {opts.version}")
    out = Path(task.out_dir)
    path = Path(task.path)
    try:
        how = _judging(path, opts)
        if not opts.force:
            hit = _cached(task, opts, how, out)
            if hit is not None:
                return hit
        catalog = None
        if how.missions:
            from ..emulator.missionfile import DirectoryCatalog
            catalog = DirectoryCatalog(list(how.missions))
        outcome = check_log(path, profile=how.profile, role=how.role, catalog=catalog,
                            time_scale=opts.time_scale, swap=opts.swap, parallel=False, line=opts.line)
    except (OSError, LogFormatError) as e:
        why = f"cannot read: {e.strerror or e}" if isinstance(e, OSError) else str(e)
        return _entry(task, "unreadable", message=why)
    except Exception as e:  # noqa: BLE001 - a tester bug in one file must not end the archive's check
        return _tester_error(task, out, e)
    try:
        (out / KEY_NAME).unlink(missing_ok=True)
        prepare_report_dir(out, overwrite=True)
        settings: dict[str, Any] = {"swap_directions": opts.swap}
        if opts.line:
            settings["line"] = opts.line
        if how.missions:
            settings["missions"] = [str(Path(d).resolve()) for d in how.missions]
        res = write_report_dir(out, outcome, how.profile, opts.command(task.path), strict=opts.strict,
                               render=opts.render, settings=settings, origin=how.origin)
        write_bytes_atomic(out / KEY_NAME, _key(opts, how, outcome.sha256))
    except (OSError, ReportError, PathError) as e:
        what = f"cannot write {getattr(e, 'filename', None) or out}: {getattr(e, 'strerror', None) or e}"
        return _entry(task, "error", message=what)
    except Exception as e:  # noqa: BLE001
        return _tester_error(task, out, e)
    return _from_results(task, "judged", res, outcome.seconds)


def _tester_error(task: FileTask, out: Path, e: Exception) -> dict[str, Any]:
    from ..failures import TRACEBACK_NAME
    from ..reports.atomic import write_text_atomic
    where = ""
    try:
        out.mkdir(parents=True, exist_ok=True)
        where = str(write_text_atomic(out / TRACEBACK_NAME, "".join(traceback.format_exception(e))))
    except OSError:
        pass
    return _entry(task, "error", message=f"tester error: {type(e).__name__}: {e}"
                                         + (f" — traceback in {where}" if where else ""))
