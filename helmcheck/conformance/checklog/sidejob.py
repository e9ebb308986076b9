"""A side job in a second process: one role of a long log judged beside the other.

``check-log --role both`` judges two independent roles over the same records: the vehicle
observer and the backseat observer share no state. On a machine with more than one core the
checker hands one role to a :class:`SideJob`: a module-level function and its (picklable)
arguments, run by a fresh Python interpreter on the same ``helmcheck`` package, whose return
value or exception comes back pickled on its standard output.

* The child is a plain ``python -c`` process, not a :mod:`multiprocessing` one: it never
  re-imports the caller's main script (a benchmark, a user's own script), and it forks nothing
  from a process that may hold threads.
* It runs in a session of its own, so Ctrl-C at a terminal reaches only the caller (which writes
  its partial report); :meth:`SideJob.stop` ends the child whenever the caller leaves early.
* A child that dies without an answer raises :class:`SideJobLost` (with what it wrote on its
  standard error), so the caller can do the work itself instead: nothing is lost but time.
"""

from __future__ import annotations

import os
import pickle
import subprocess
import sys
from pathlib import Path
from typing import Any, Callable

__all__ = ["SideJob", "SideJobLost", "cores", "child"]

_PACKAGE_ROOT = str(Path(__file__).resolve().parents[3])  # the directory holding helmcheck/


class SideJobLost(RuntimeError):
    """The second process ended without handing back a result."""


def cores() -> int:
    """CPU cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


def child() -> None:
    """The second process: read ``(fn, args)`` pickled from stdin, write ``(ok, value)`` to stdout."""
    fn, args = pickle.load(sys.stdin.buffer)
    try:
        answer = (True, fn(*args))
    except Exception as e:  # handed to the caller, which raises it
        answer = (False, e)
    try:
        data = pickle.dumps(answer)
    except Exception as e:  # an exception that does not pickle: its text still travels
        data = pickle.dumps((False, SideJobLost(f"the second process failed: {answer[1]!r} ({e})")))
    sys.stdout.buffer.write(data)
    sys.stdout.buffer.flush()


class SideJob:
    """``fn(*args)`` in a second process (module docstring)."""

    def __init__(self, fn: Callable[..., Any], *args: Any):
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join(p for p in (_PACKAGE_ROOT, env.get("PYTHONPATH", "")) if p)
        self._proc = subprocess.Popen(
            [sys.executable, "-c", "from helmcheck.conformance.checklog.sidejob import child; child()"],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env,
            start_new_session=True)
        stdin, self._proc.stdin = self._proc.stdin, None  # written once here; communicate() only reads
        try:
            stdin.write(pickle.dumps((fn, args)))  # type: ignore[union-attr]
            stdin.close()  # type: ignore[union-attr]
        except OSError:
            pass  # it died at once: result() says so

    def result(self) -> Any:
        """Wait for the answer: the function's return value, or its exception raised here."""
        out, err = self._proc.communicate()
        try:
            ok, value = pickle.loads(out)
        except Exception:
            tail = err.decode("utf-8", "replace").strip().splitlines()[-1:] or ["no message"]
            raise SideJobLost(f"the second process ended without a result (exit code "
                              f"{self._proc.returncode}: {tail[0]})") from None
        if ok:
            return value
        raise value

    def stop(self) -> None:
        """End the child if it still runs."""
        if self._proc.poll() is None:
            self._proc.kill()
            self._proc.wait(5)
        for pipe in (self._proc.stdout, self._proc.stderr):
            if pipe is not None:
                pipe.close()
