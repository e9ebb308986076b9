"""Atomic file writes for everything helmcheck puts on disk.

A file is written to a temporary name in the same directory, flushed to disk, then moved over
the target with ``os.replace`` (atomic on POSIX and Windows). A reader sees the old file or the
new one, never half of one, and no temporary file is left behind, even when writing fails.

Decisions: a target that exists and is not a regular file — a device such as ``/dev/stdout``
or a named pipe — is written straight into, as a stream (renaming over a device node would
replace the device); a directory is refused. Every ``OSError`` raised here carries the
target's path as its ``filename`` (not the temporary name), so a message can name the file.
"""

from __future__ import annotations

import os
import stat
import tempfile
from pathlib import Path

__all__ = ["write_bytes_atomic", "write_text_atomic", "copy_file_atomic"]


def write_bytes_atomic(path: Path | str, data: bytes, mode: int = 0o644) -> Path:
    """Replace *path* with *data* atomically; returns the path. ``OSError`` on failure."""
    return _write_atomic(path, lambda fh: fh.write(data), mode)


def copy_file_atomic(src: Path | str, dst: Path | str, mode: int = 0o644) -> Path:
    """Replace *dst* with a copy of *src*, streamed (any size), atomically."""
    import shutil

    with open(src, "rb") as r:
        return _write_atomic(dst, lambda fh: shutil.copyfileobj(r, fh, 1 << 20), mode)


def _named(e: OSError, path: Path) -> OSError:
    return OSError(e.errno, e.strerror or str(e), str(path))


def _is_stream_target(path: Path) -> bool:
    try:
        st = os.stat(path)
    except OSError:
        return False
    if stat.S_ISDIR(st.st_mode):
        raise IsADirectoryError(21, "Is a directory", str(path))
    return not stat.S_ISREG(st.st_mode)


def _write_atomic(path: Path | str, fill, mode: int) -> Path:
    path = Path(path)
    if _is_stream_target(path):
        try:
            with open(path, "wb") as fh:
                fill(fh)
                fh.flush()
        except OSError as e:
            raise _named(e, path) from None
        return path
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    except OSError as e:
        raise _named(e, path) from None
    try:
        with os.fdopen(fd, "wb") as fh:
            fill(fh)
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, mode)
        os.replace(tmp, path)
    except BaseException as e:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        if isinstance(e, OSError) and e.filename != str(path):
            raise _named(e, path) from None
        raise
    _fsync_dir(path.parent)
    return path


def write_text_atomic(path: Path | str, text: str, mode: int = 0o644) -> Path:
    """:func:`write_bytes_atomic` for UTF-8 text."""
    return write_bytes_atomic(path, text.encode("utf-8"), mode)


def _fsync_dir(directory: Path) -> None:
    """Make the rename itself durable where the platform allows it."""
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)
