"""Standard output and error that never raise: a reader that went away is noted, not a traceback.

:class:`GuardedStream` wraps ``sys.stdout`` or ``sys.stderr`` for the duration of one command
(:mod:`helmcheck.cli` installs it). When a write or flush fails it swallows the error,
points the descriptor at ``/dev/null`` (so nothing fails again, not even the interpreter's
last flush) and remembers why:

- :attr:`GuardedStream.gone`: the reader went away — ``EPIPE`` (``helmcheck parse … | head``),
  or ``EIO``/``ENXIO`` on a terminal that was closed (SIGHUP). This is not a failure: the
  command ends quietly (``parse`` stops reading at once; see the contracts table).
- :attr:`GuardedStream.error`: any other write error (a full disk behind ``> out.txt``). The
  command line turns it into exit 2 with one line naming standard output.

:attr:`GuardedStream.lost` is true in both cases; a command that produces its result on
standard output (``parse``) checks it to stop early.
"""

from __future__ import annotations

import errno
import os
from typing import Any, Optional, TextIO

__all__ = ["GuardedStream", "READER_GONE", "TERMINAL_GONE"]

#: errno values that mean "nobody reads this stream any more" (EIO and ENXIO only on a terminal).
READER_GONE = frozenset({errno.EPIPE, errno.ECONNRESET})
TERMINAL_GONE = frozenset({errno.EIO, errno.ENXIO})


class GuardedStream:
    """A text stream proxy that records write failures instead of raising (module docstring)."""

    def __init__(self, stream: TextIO, label: str):
        self._s = stream
        self.label = label
        self.gone: Optional[str] = None
        self.error: Optional[OSError] = None
        try:
            self._tty = bool(stream.isatty())
        except (OSError, ValueError, AttributeError):
            self._tty = False

    @property
    def lost(self) -> bool:
        return self.gone is not None or self.error is not None

    @property
    def wrapped(self) -> TextIO:
        return self._s

    def _failed(self, e: OSError) -> None:
        if e.errno in READER_GONE or (self._tty and e.errno in TERMINAL_GONE):
            self.gone = os.strerror(e.errno) if e.errno else str(e)
        elif self.error is None:
            self.error = e
        try:
            fd = self._s.fileno()
        except (OSError, ValueError, AttributeError):
            return
        try:
            null = os.open(os.devnull, os.O_WRONLY)
            try:
                os.dup2(null, fd)
            finally:
                os.close(null)
        except OSError:
            pass

    def write(self, text: str) -> int:
        if not self.lost:
            try:
                return self._s.write(text)
            except OSError as e:
                self._failed(e)
        return len(text)

    def writelines(self, lines) -> None:
        for line in lines:
            self.write(line)

    def flush(self) -> None:
        if self.lost:
            try:
                self._s.flush()  # into /dev/null now: empties the buffer
            except (OSError, ValueError):
                pass
            return
        try:
            self._s.flush()
        except OSError as e:
            self._failed(e)
            try:
                self._s.flush()
            except (OSError, ValueError):
                pass
        except ValueError:
            pass

    def __getattr__(self, name: str) -> Any:
        return getattr(self._s, name)
