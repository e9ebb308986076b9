"""Finding the logs of an archive: directories and glob patterns in, the logs to judge out.

This module owns what ``helmcheck check-log DIR|GLOB…`` judges and where each result goes. It
judges nothing and writes nothing.

* Arguments: a directory is walked recursively (symbolic links to directories are not followed,
  so a link loop cannot make the walk endless); a pattern with ``*``, ``?`` or ``[`` that is not an
  existing path is a :func:`glob.glob` pattern (``**`` spans directories); any other path is one
  file. A directory that does not exist or a pattern that matches nothing is a usage error.
* A file is a log when its first :data:`~.records.HEAD_BYTES` are a format
  :func:`~.readers.detect_format` knows — by content, never by name, as ``check-log FILE`` decides.
  Everything else is :class:`Skipped`, with the reason: not a log (no known format), empty, a
  later segment of a session whose first file is judged (``wire.001.log`` beside ``wire.log``,
  :mod:`helmcheck.reports.segments`: judged with it), the report directory when it lies inside
  the archive (listed once, not walked: its files are results and copies).
* A file that cannot be opened or read (no permission, a dangling symbolic link, an I/O error)
  is :class:`Unreadable`: reported in the summary and counted in the exit status, never skipped
  silently.
* Mirroring: every log's results go to ``REPORT_DIR/<its path relative to the archive root>/``
  (the file name kept whole, ``a/b/session.log/``, so ``session.log`` and ``session.txt`` never
  share a directory). The archive root is the deepest directory holding every argument's base
  (a directory argument itself, a pattern's part before its first wildcard, a file's directory).
"""

from __future__ import annotations

import glob
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterable, Optional

from ..failures import PathError, UsageError
from ..reports.segments import session_files
from .readers import detect_format
from .records import HEAD_BYTES

__all__ = ["Archive", "LogFile", "Skipped", "Unreadable", "find_logs", "archive_root", "is_pattern"]

_WILDCARDS = set("*?[")


@dataclass(frozen=True)
class LogFile:
    """A log to judge: where it is, its path below the archive root (``/``-separated), its size
    (all segments) and format."""

    path: Path
    rel: str
    size: int
    format: str


@dataclass(frozen=True)
class Skipped:
    rel: str
    reason: str


@dataclass(frozen=True)
class Unreadable:
    rel: str
    path: Path
    reason: str


@dataclass
class Archive:
    root: Path
    logs: list[LogFile] = field(default_factory=list)
    skipped: list[Skipped] = field(default_factory=list)
    unreadable: list[Unreadable] = field(default_factory=list)


def is_pattern(arg: str) -> bool:
    """A glob pattern (a wildcard, and no existing path of that name)."""
    return bool(_WILDCARDS & set(arg)) and not os.path.lexists(arg)


def _base(arg: str) -> Path:
    """The directory an argument lies in (module docstring)."""
    if is_pattern(arg):
        parts = Path(arg).parts
        fixed = []
        for part in parts:
            if _WILDCARDS & set(part):
                break
            fixed.append(part)
        return Path(*fixed) if fixed else Path(".")
    p = Path(arg)
    return p if p.is_dir() else p.parent


def _walk(directory: Path, prune: Optional[Path] = None) -> Iterable[Path]:
    for top, dirs, files in os.walk(directory, onerror=None, followlinks=False):
        if prune is not None:  # the report directory inside the archive: not walked (its copies are results)
            dirs[:] = [d for d in dirs if Path(os.path.join(top, d)).resolve() != prune]
        dirs.sort()
        for name in sorted(files):
            yield Path(top) / name
        for name in dirs:  # a link to a directory is listed by os.walk as a directory: not followed
            if os.path.islink(os.path.join(top, name)):
                yield Path(top) / name


def _candidates(args: list[str], prune: Optional[Path]) -> list[Path]:
    out: list[Path] = []
    for arg in args:
        if is_pattern(arg):
            found = sorted(glob.glob(arg, recursive=True))
            if not found:
                raise UsageError(f"{arg}: the pattern matches nothing")
            for m in found:
                p = Path(m)
                out.extend(_walk(p, prune) if p.is_dir() and not p.is_symlink() else [p])
        else:
            p = Path(arg)
            if p.is_dir():
                out.extend(_walk(p, prune))
            elif os.path.lexists(p):
                out.append(p)
            else:
                raise PathError(f"cannot read {arg}: No such file or directory")
    return out


def _within(path: Path, directory: Optional[Path]) -> bool:
    if directory is None:
        return False
    try:
        path.resolve().relative_to(directory)
        return True
    except ValueError:
        return False


def archive_root(args: list[str]) -> Path:
    """The deepest directory holding every argument's base (module docstring)."""
    return Path(os.path.commonpath([str(_base(a).resolve()) for a in args]))


def find_logs(args: list[str], report_dir: Optional[Path] = None) -> Archive:
    """The archive the arguments name (module docstring). ``UsageError``/``PathError`` for an
    argument that names nothing."""
    report = report_dir.resolve() if report_dir is not None else None
    candidates = _candidates(args, report)
    root = archive_root(args)
    archive = Archive(root=root)
    if report is not None and _within(report, root) and report != root:
        archive.skipped.append(Skipped(os.path.relpath(report, root).replace(os.sep, "/") + "/",
                                       "the report directory (not walked)"))
    seen: set[Path] = set()
    segments: dict[Path, str] = {}
    heads: list[tuple[Path, str, str]] = []
    for p in candidates:
        key = Path(os.path.abspath(p))
        if key in seen:
            continue
        seen.add(key)
        rel = os.path.relpath(key, root).replace(os.sep, "/")
        if _within(p, report):
            archive.skipped.append(Skipped(rel, "inside the report directory"))
            continue
        try:
            if not p.is_file():
                if not p.exists():
                    raise FileNotFoundError(2, "No such file or directory (a dangling symbolic link)")
                archive.skipped.append(Skipped(rel, "not a regular file"))
                continue
            with open(p, "rb") as f:
                head = f.read(HEAD_BYTES)
        except OSError as e:
            archive.unreadable.append(Unreadable(rel, p, f"cannot read: {e.strerror or e}"))
            continue
        if not head.strip():
            archive.skipped.append(Skipped(rel, "empty" if not head else "blank"))
            continue
        fmt = detect_format(head)
        if fmt is None:
            archive.skipped.append(Skipped(rel, "not a log: no helmcheck wire log, socat -v or socat -x "
                                                "capture in its first lines"))
            continue
        heads.append((p, rel, fmt))
        if fmt == "wirelog":
            for later in session_files(p).files[1:]:
                segments[Path(os.path.abspath(later))] = rel
    for p, rel, fmt in heads:
        first = segments.get(Path(os.path.abspath(p)))
        if first is not None and first != rel:
            archive.skipped.append(Skipped(rel, f"a later segment of the session {first}: judged with it"))
            continue
        try:
            size = sum(s.stat().st_size for s in session_files(p).files)
        except OSError as e:
            archive.unreadable.append(Unreadable(rel, p, f"cannot read: {e.strerror or e}"))
            continue
        archive.logs.append(LogFile(p, rel, size, fmt))
    archive.logs.sort(key=lambda x: x.rel)
    archive.skipped.sort(key=lambda x: x.rel)
    archive.unreadable.sort(key=lambda x: x.rel)
    return archive
