"""The files a command promises to write: checked at start, written whole, or a loud failure.

This module owns the command line's side of output files (the writing itself is
:mod:`helmcheck.reports.atomic`):

- :func:`check_writable` — at start, a file the user named can be created: its directory
  exists and it is not a directory (else :class:`~helmcheck.failures.PathError`, exit 64).
- :func:`prepare_report_dir` — a report directory that holds an earlier run (``results.json``)
  is refused unless ``--overwrite``; with it, the earlier run's files are removed first, so
  nothing stale is left beside the new results (:data:`RUN_FILES`).
- :func:`copy_output` — a copy (``--wire-log``) written atomically, or streamed into a device
  or pipe; any error is :class:`~helmcheck.failures.OutputLost` naming the file (exit 2).
- :class:`OutputStream` — a log written as it happens (``emulate --log``, a run's
  ``wire.log``). A write error either stops the command at once (``stop=True``: the emulator
  must not keep serving with its log lost) or is remembered and reported when the run ends
  (``stop=False``: a certification goes on judging and still writes its results;
  :meth:`OutputStream.check` then raises).
"""

from __future__ import annotations

import os
import shutil
import stat
from pathlib import Path
from typing import IO, Optional

from .failures import OutputLost, PathError, UsageError

__all__ = ["RUN_FILES", "RUN_DIRS", "check_writable", "prepare_report_dir", "copy_output", "OutputStream",
           "open_output_stream", "is_regular_or_new"]

#: Files of a run in a report directory, removed by ``--overwrite`` before a new run.
RUN_FILES = ("results.json", "wire.log", "report.html", "junit.xml", "report.md", "tester-error.txt")
#: Directories of a run, removed likewise (replay files of an earlier exploration).
RUN_DIRS = ("replays",)
#: Copies of a checked capture that ``check-log`` keeps under their own name.
RUN_GLOBS = ("capture-*.log",)


def _why(e: OSError) -> str:
    return e.strerror or str(e)


def is_regular_or_new(path: Path) -> bool:
    """True when ``path`` does not exist yet or is a regular file (a copy can replace it)."""
    try:
        return stat.S_ISREG(os.stat(path).st_mode)
    except FileNotFoundError:
        return True
    except OSError:
        return False


def check_writable(path: str | Path, option: str) -> Path:
    """At start: the file ``path`` (given with ``option``) can be written. A device or pipe is
    accepted as it is (written as a stream); a directory, or a file in a directory that does
    not exist, is a :class:`PathError`."""
    p = Path(path)
    if not str(path):
        raise UsageError(f"{option}: empty path")
    if p.is_dir():
        raise PathError(f"{option}: cannot write {p}: it is a directory")
    parent = p.parent if str(p.parent) else Path(".")
    if not parent.is_dir():
        raise PathError(f"{option}: cannot write {p}: directory {parent} does not exist")
    if not os.access(parent, os.W_OK) and not p.exists():
        raise PathError(f"{option}: cannot write {p}: directory {parent} is not writable")
    return p


def prepare_report_dir(directory: str | Path, overwrite: bool, option: str = "--report-dir", *,
                       clear: bool = True) -> Path:
    """Create ``directory`` for a new run (module docstring); returns it.

    A ``results.json`` there means an earlier run: refused (``PathError``, exit 64) with what to
    do, unless ``overwrite``, which removes :data:`RUN_FILES`, :data:`RUN_DIRS` and the capture
    copies first (not with ``clear=False``: a check before anything else is opened). Other
    files are left alone (the exploration's example database ``.hypothesis`` among them). A
    directory that cannot be created is a ``PathError`` too.
    """
    d = Path(directory)
    if not str(directory):
        raise UsageError(f"{option}: empty path")
    if d.exists() and not d.is_dir():
        raise PathError(f"{option}: cannot use {d}: it exists and is not a directory")
    if clear:
        try:
            d.mkdir(parents=True, exist_ok=True)
        except OSError as e:
            raise PathError(f"{option}: cannot create {d}: {_why(e)}") from None
    else:  # a check only: create nothing yet
        base = d
        while not base.exists():
            if base.is_symlink() or base.parent == base:
                break
            base = base.parent
        if not base.is_dir():
            raise PathError(f"{option}: cannot create {d}: {base} is not a directory")
        d_ok = base
        if not os.access(d_ok, os.W_OK | os.X_OK):
            raise PathError(f"{option}: cannot write to {d_ok}: permission denied")
        if not d.exists():
            return d
    if not os.access(d, os.W_OK | os.X_OK):
        raise PathError(f"{option}: cannot write to {d}: permission denied")
    earlier = d / "results.json"
    if not (earlier.exists() or earlier.is_symlink()):
        return d
    if not overwrite:
        raise PathError(f"{option}: {d} holds an earlier run ({earlier}); pass --overwrite to replace it "
                        f"(its results, wire log, reports and replays are removed first) or choose "
                        f"another {option}")
    if not clear:
        return d
    doomed = [d / name for name in RUN_FILES]
    for pattern in RUN_GLOBS:
        doomed += sorted(d.glob(pattern))
    try:
        for f in doomed:
            if f.is_symlink() or f.is_file():
                f.unlink()
            elif f.is_dir():
                shutil.rmtree(f)
        for name in RUN_DIRS:
            sub = d / name
            if sub.is_symlink():
                sub.unlink()
            elif sub.is_dir():
                shutil.rmtree(sub)
    except OSError as e:
        raise PathError(f"--overwrite: cannot remove the earlier run's {e.filename or d}: {_why(e)}") from None
    return d


def copy_output(src: str | Path, dst: str | Path, what: str = "copy") -> Path:
    """Copy ``src`` to ``dst``: atomically for a regular file, streamed into a device or pipe.
    :class:`OutputLost` naming ``dst`` if it cannot be written whole."""
    from .reports.atomic import copy_file_atomic

    dst = Path(dst)
    try:
        return copy_file_atomic(src, dst)
    except OSError as e:
        source = f" (reading {src})" if e.filename == str(src) else ""
        raise OutputLost(f"cannot write {what} {dst}: {_why(e)}{source}") from None


class OutputStream:
    """A text log that is never lost in silence (module docstring)."""

    def __init__(self, stream: IO[str], path: str | Path, *, stop: bool, what: str = "log"):
        self._f: Optional[IO[str]] = stream
        self.path = Path(path)
        self.stop = stop
        self.what = what
        self.error: Optional[str] = None

    def _failed(self, e: OSError) -> None:
        self.error = _why(e)
        f, self._f = self._f, None
        if f is not None:
            try:
                f.close()
            except OSError:
                pass
        if self.stop:
            raise self.failure() from None

    def failure(self) -> OutputLost:
        return OutputLost(f"cannot write {self.what} {self.path}: {self.error}")

    def write(self, text: str) -> int:
        if self._f is not None:
            try:
                return self._f.write(text)
            except OSError as e:
                self._failed(e)
        return len(text)

    def flush(self) -> None:
        if self._f is not None:
            try:
                self._f.flush()
            except OSError as e:
                self._failed(e)

    def close(self) -> None:
        if self._f is not None:
            f = self._f
            try:
                f.flush()
                f.close()
                self._f = None
            except OSError as e:
                self._failed(e)

    @property
    def closed(self) -> bool:
        return self._f is None

    def check(self) -> None:
        """Raise :class:`OutputLost` if a write failed (for ``stop=False`` streams)."""
        if self.error is not None:
            raise self.failure()


def open_output_stream(path: str | Path, option: str, *, stop: bool, what: str = "log",
                       newline: Optional[str] = None) -> OutputStream:
    """Open ``path`` for writing as an :class:`OutputStream`; a path that cannot be opened is a
    :class:`PathError` naming ``option`` (exit 64: nothing has run yet)."""
    try:
        f = open(path, "w", encoding="utf-8", newline=newline)
    except OSError as e:
        raise PathError(f"{option}: cannot write {path}: {_why(e)}") from None
    return OutputStream(f, path, stop=stop, what=what)
