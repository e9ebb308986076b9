"""Signals that end a run: SIGINT, SIGTERM and SIGHUP all raise :class:`~helmcheck.failures.Interrupted`.

``Interrupted`` is a :class:`KeyboardInterrupt`, so every command that already ends a run
cleanly on Ctrl-C (partial results marked as such, reports rendered, logs closed) does exactly
the same on ``kill`` (SIGTERM) or a closed terminal (SIGHUP). :func:`ending_signals` installs the
handlers for the duration of one command; :mod:`helmcheck.cli` is the only caller.

Decisions:

- A signal the process inherited as ignored (``nohup`` ignores SIGHUP; a shell starting a
  background job ignores SIGINT) stays ignored.
- The first signal raises. A second SIGTERM or SIGHUP while the run is already ending is
  ignored, so the partial results and reports are written; a second Ctrl-C raises again (the
  user insists), as Python does by default.
- Off the main thread (a test calling a command in a worker thread) nothing is installed.
- Within :func:`deferred` an ending signal does not raise at once: it raises when the block
  ends. The recorder writes a record to the wire log and feeds it to the judges inside one such
  block, so an interruption never leaves a record logged but unjudged, or judged halfway (the
  live verdicts would then differ from the log's).
"""

from __future__ import annotations

import signal
import threading
from contextlib import contextmanager
from typing import Iterator

from .failures import Interrupted

__all__ = ["ENDING_SIGNALS", "ending_signals", "deferred"]

ENDING_SIGNALS = tuple(getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, name))


class _Deferral:
    """How deep the :func:`deferred` blocks run, and the signal that came inside one."""

    depth = 0
    pending: str | None = None


class _Handler:
    def __init__(self) -> None:
        self.raised: str | None = None

    def __call__(self, signum: int, frame) -> None:  # noqa: ARG002 - signal handler signature
        name = signal.Signals(signum).name
        if self.raised is not None and signum != signal.SIGINT:
            return
        self.raised = name
        if _Deferral.depth:
            _Deferral.pending = name  # raised when the deferred block ends
            return
        raise Interrupted(name)


@contextmanager
def deferred() -> Iterator[None]:
    """An ending signal that comes within the block raises :class:`Interrupted` when the block
    ends, not inside it (module docstring)."""
    _Deferral.depth += 1
    try:
        yield
    finally:
        _Deferral.depth -= 1
    if _Deferral.depth == 0 and _Deferral.pending is not None:
        name, _Deferral.pending = _Deferral.pending, None
        raise Interrupted(name)


@contextmanager
def ending_signals(*, linger: bool = False) -> Iterator[None]:
    """Within the block, the ending signals raise :class:`Interrupted` (module docstring).

    With ``linger`` (the process's own entry point), once a signal has ended the run SIGTERM
    and SIGHUP stay ignored after the block too, until the process exits: a repeated ``kill``
    cannot cut the last lines short. Without it the earlier handlers are put back."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    handler = _Handler()
    old: dict[int, object] = {}
    for sig in ENDING_SIGNALS:
        current = signal.getsignal(sig)
        if current in (signal.SIG_DFL, signal.default_int_handler):
            old[sig] = signal.signal(sig, handler)
    try:
        yield
    finally:
        for sig, h in old.items():
            if linger and handler.raised is not None and sig != signal.SIGINT:
                h = signal.SIG_IGN
            signal.signal(sig, h)
