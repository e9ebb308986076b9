"""A side job in a second process: one role of a long log judged beside the other.

``check-log --role both`` judges two independent roles over the same records: the vehicle
observer and the backseat observer share no state. On a machine with more than one core the
checker hands one role to a :class:`SideJob`: a module-level function and its (picklable)
arguments, run by a fresh Python interpreter on the same ``helmcheck`` package, whose return
value or exception comes back pickled on its standard output.

* The child is a plain ``python -P -c`` process, not a :mod:`multiprocessing` one: it never
  re-imports the caller's main script (a benchmark, a user's own script), and it forks nothing
  from a process that may hold threads. It imports the caller's own ``helmcheck`` (its
  directory first on the path, never the working directory's) and refuses to run another.
* What the function prints goes to the child's standard error: its standard output carries only
  the answer.
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

import helmcheck

__all__ = ["SideJob", "SideJobLost", "cores", "child"]

#: the directory holding helmcheck/ (found as the child finds it, wherever this module lies in the package)
_PACKAGE_ROOT = str(Path(helmcheck.__file__).resolve().parents[1])


class SideJobLost(RuntimeError):
    """The second process ended without handing back a result."""


def cores() -> int:
    """CPU cores this process may run on: its affinity, capped by a cgroup CPU quota."""
    try:
        n = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        n = os.cpu_count() or 1
    try:  # cgroup v2: "max 100000" (no quota) or "<quota> <period>"
        quota, period = Path("/sys/fs/cgroup/cpu.max").read_text().split()[:2]
        if quota != "max":
            n = min(n, max(1, int(quota) // int(period)))
    except (OSError, ValueError):
        pass
    return n


def child() -> None:
    """The second process: read ``(package root, fn, args)`` pickled from stdin, write
    ``(ok, value)`` to stdout."""
    answer_to = sys.stdout.buffer
    sys.stdout = sys.stderr  # whatever fn prints must not mix with the answer
    try:
        root, fn, args = pickle.load(sys.stdin.buffer)
        if str(Path(helmcheck.__file__).resolve().parents[1]) != root:
            raise SideJobLost(f"the second process imported another helmcheck ({helmcheck.__file__}, not "
                              f"the one under {root})")
        answer = (True, fn(*args))
    except Exception as e:  # handed to the caller, which raises it
        answer = (False, e)
    try:
        data = pickle.dumps(answer)
    except Exception as e:  # an exception that does not pickle: its text still travels
        data = pickle.dumps((False, SideJobLost(f"the second process failed: {answer[1]!r} ({e})")))
    answer_to.write(data)
    answer_to.flush()


class SideJob:
    """``fn(*args)`` in a second process (module docstring)."""

    def __init__(self, fn: Callable[..., Any], *args: Any):
        """Start the child. Raises what pickling the job raises, or ``OSError`` when no process
        can be started; in either case no child is left running."""
        job = pickle.dumps((_PACKAGE_ROOT, fn, args))
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join(p for p in (_PACKAGE_ROOT, env.get("PYTHONPATH", "")) if p)
        self._proc = subprocess.Popen(
            [sys.executable, "-P", "-c", "from helmcheck.checklog.sidejob import child; child()"],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env,
            start_new_session=True)
        stdin, self._proc.stdin = self._proc.stdin, None  # written once here; communicate() only reads
        try:
            stdin.write(job)  # type: ignore[union-attr]
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
            try:
                self._proc.wait(5)
            except subprocess.TimeoutExpired:
                pass  # killed; the system reaps it
        for pipe in (self._proc.stdout, self._proc.stderr):
            if pipe is not None:
                pipe.close()
