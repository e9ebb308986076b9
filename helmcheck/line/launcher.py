"""Start, watch and stop the implementation under test: ``certify backseat|vehicle --exec CMD``.

This module owns the child process and nothing else (no judging, no port): it builds the
argument vector, starts the child, captures its output into the report directory, tells when
it has ended, stops it at the end of the run, and describes how it ended for ``results.json``.

Decisions:

* The command is split with :func:`shlex.split` and run without a shell. In each argument the
  placeholders ``{port}`` (what the child opens or serves: a pty path, ``socket://HOST:PORT``
  or the device given), ``{host}`` and ``{tcp_port}`` (the two halves of a TCP port; empty
  otherwise) and ``{time_scale}`` (the run's K, RH-TIM-2) are replaced; other braces are left
  alone. A command without ``{port}`` gets the port appended as its last argument — unless the
  child announces its own port (``--port announced``: no port is given to it, ``{port}`` is
  empty, nothing is appended; it prints ``port: URL`` on a line of its standard output,
  :meth:`Launcher.announced`).
* The environment passes through, plus ``HELMCHECK_PORT`` (the port) and
  ``HELMCHECK_TIME_SCALE``. Standard input is ``/dev/null``; the working directory is the
  caller's.
* The child runs in a process group of its own (same session, so it never gets a controlling
  terminal from the pty it opens, and a terminal's Ctrl-C reaches helmcheck only); stopping
  signals the whole group, so grandchildren do not survive: SIGTERM, then SIGKILL to whatever
  is left of the group after the grace period (default 5 s).
* Standard output and error go, through two reader threads, to ``<subject>.stdout.log`` and
  ``<subject>.stderr.log`` in the report directory; the last :data:`TAIL_LINES` lines of both
  are kept for the report in the order they were read (within a stream exact; between the two
  streams only as close as two readers can tell), each cut to :data:`TAIL_WIDTH` characters and
  decoded as UTF-8 with replacement.
* Times are ``time.monotonic()`` seconds; :meth:`Launcher.record` turns the end time into
  seconds since the run's epoch (the certifier's start), the time axis of its report.
"""

from __future__ import annotations

import os
import shlex
import shutil
import signal
import subprocess
import threading
import time
from collections import deque
from pathlib import Path
from typing import IO, Optional

__all__ = ["Launcher", "CommandError", "build_argv", "check_command", "PLACEHOLDERS", "TAIL_LINES",
           "TAIL_WIDTH", "DEFAULT_GRACE_S"]

PLACEHOLDERS = ("port", "host", "tcp_port", "time_scale")
TAIL_LINES = 20  #: lines of output quoted in results.json
TAIL_WIDTH = 500  #: characters kept of each quoted line
DEFAULT_GRACE_S = 5.0  #: SIGTERM → SIGKILL
_CHUNK = 65536


class CommandError(ValueError):
    """A command line that cannot be run; the message is one line."""


def _split(command: str) -> list[str]:
    try:
        argv = shlex.split(command)
    except ValueError as e:
        raise CommandError(f"cannot split {command!r}: {e}") from None
    if not argv:
        raise CommandError("the command is empty")
    return argv


def build_argv(command: str, values: dict[str, str]) -> list[str]:
    """The argument vector of *command* with the placeholders replaced (module docstring).

    *values* maps placeholder names (without braces) to their text; ``port`` is required.
    """
    argv = _split(command)
    port_seen = any("{port}" in a for a in argv)
    out = []
    for arg in argv:
        for name in PLACEHOLDERS:
            arg = arg.replace("{" + name + "}", str(values.get(name, "")))
        out.append(arg)
    if not port_seen and values["port"]:
        out.append(str(values["port"]))
    return out


def check_command(command: str) -> Optional[str]:
    """Why *command* cannot be started (one line), or None: it splits, and its program exists."""
    try:
        argv = build_argv(command, {"port": "PORT"})
    except CommandError as e:
        return str(e)
    prog = argv[0]
    if "/" in prog:
        if not os.path.isfile(prog):
            return f"{prog}: no such file"
        if not os.access(prog, os.X_OK):
            return f"{prog}: not executable"
    elif shutil.which(prog) is None:
        return f"{prog}: command not found on PATH"
    return None


class Launcher:
    """One child process: start, poll, stop, record. See the module docstring."""

    def __init__(self, command: str, *, subject: str, directory: Path | str,
                 grace_s: float = DEFAULT_GRACE_S):
        self.command = command
        self.subject = subject
        self.directory = Path(directory)
        self.grace_s = grace_s
        self.argv: list[str] = []
        self.proc: Optional[subprocess.Popen] = None
        self.pgid: Optional[int] = None
        self.started_at: Optional[float] = None
        self.ended_at: Optional[float] = None
        self.stopping_at: Optional[float] = None  #: when :meth:`stop` began (None: never)
        self._tail: deque[str] = deque(maxlen=TAIL_LINES)
        self._announced: Optional[str] = None  #: the port the child printed (``port: URL``)
        self._lock = threading.Lock()
        self._readers: list[threading.Thread] = []

    # ------------------------------------------------------------------ start
    @property
    def log_names(self) -> tuple[str, str]:
        return f"{self.subject}.stdout.log", f"{self.subject}.stderr.log"

    def start(self, port: str, *, host: str = "", tcp_port: str = "", time_scale: float = 1.0) -> None:
        """Start the child on *port*. ``OSError`` if it cannot be started (no such program …)."""
        values = {"port": port, "host": host, "tcp_port": tcp_port, "time_scale": f"{time_scale:g}"}
        self.argv = build_argv(self.command, values)
        env = dict(os.environ, HELMCHECK_PORT=port, HELMCHECK_TIME_SCALE=values["time_scale"])
        self.directory.mkdir(parents=True, exist_ok=True)
        out_name, err_name = self.log_names
        files = [open(self.directory / out_name, "wb"), open(self.directory / err_name, "wb")]
        try:
            self.proc = subprocess.Popen(self.argv, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                         stderr=subprocess.PIPE, env=env, process_group=0, close_fds=True)
        except BaseException:
            for f in files:
                f.close()
            raise
        self.started_at = time.monotonic()
        self.pgid = self.proc.pid
        for pipe, f, name in ((self.proc.stdout, files[0], "stdout"), (self.proc.stderr, files[1], "stderr")):
            t = threading.Thread(target=self._pump, args=(pipe, f), name=f"{self.subject}-{name}", daemon=True)
            t.start()
            self._readers.append(t)

    def _pump(self, pipe: IO[bytes], sink: IO[bytes]) -> None:
        """Copy one pipe to its log file, keeping the last lines for the tail."""
        partial = b""
        fd = pipe.fileno()
        try:
            while True:
                try:
                    data = os.read(fd, _CHUNK)
                except InterruptedError:
                    continue
                except OSError:
                    break
                if not data:
                    break
                sink.write(data)
                sink.flush()
                lines = (partial + data).split(b"\n")
                partial = lines.pop()
                if len(partial) > 4 * TAIL_WIDTH:  # an endless line: keep its start
                    lines.append(partial)
                    partial = b""
                self._keep(lines)
            if partial:
                self._keep([partial])
        finally:
            sink.close()
            pipe.close()

    def _keep(self, lines: list[bytes]) -> None:
        with self._lock:
            for raw in lines:
                text = raw.decode("utf-8", "replace").rstrip("\r")
                if self._announced is None and text.startswith("port: ") and len(text.split()) == 2:
                    self._announced = text.split()[1]
                self._tail.append(text if len(text) <= TAIL_WIDTH else text[: TAIL_WIDTH - 1] + "…")

    def announced(self) -> Optional[str]:
        """The port the child printed on a line ``port: URL`` of its output (the first such), or None."""
        with self._lock:
            return self._announced

    # ------------------------------------------------------------------ watch
    @property
    def pid(self) -> Optional[int]:
        return self.proc.pid if self.proc is not None else None

    def poll(self) -> Optional[int]:
        """The child's return code once it has ended (negative: killed by that signal), else None."""
        if self.proc is None:
            return None
        rc = self.proc.poll()
        if rc is not None and self.ended_at is None:
            self.ended_at = time.monotonic()
        return rc

    @property
    def ended(self) -> bool:
        return self.poll() is not None

    def wait(self, timeout: float) -> bool:
        """Wait up to *timeout* seconds for the child to end; True if it has."""
        if self.proc is None:
            return False
        try:
            self.proc.wait(timeout=max(0.0, timeout))
        except subprocess.TimeoutExpired:
            return False
        return self.poll() is not None

    def exit_text(self) -> str:
        """``exited with code 3`` / ``was killed by SIGKILL`` / ``is running``."""
        rc = self.poll()
        if rc is None:
            return "is running"
        if rc < 0:
            return f"was killed by {_signal_name(-rc)}"
        return f"exited with code {rc}"

    def output_tail(self) -> list[str]:
        with self._lock:
            return list(self._tail)

    # ------------------------------------------------------------------ stop
    def _group_alive(self) -> bool:
        if self.pgid is None:
            return False
        try:
            os.killpg(self.pgid, 0)
        except ProcessLookupError:
            return False
        except PermissionError:
            return True
        return True

    def _signal_group(self, sig: int) -> None:
        if self.pgid is None:
            return
        try:
            os.killpg(self.pgid, sig)
        except (ProcessLookupError, PermissionError):
            pass

    def stop(self) -> None:
        """End the child and its whole process group: SIGTERM, then SIGKILL after the grace
        period; reap it and let the output readers finish. Safe to call more than once."""
        if self.proc is None:
            return
        self.poll()
        if self.stopping_at is None:
            self.stopping_at = time.monotonic()
        self._signal_group(signal.SIGTERM)
        deadline = time.monotonic() + self.grace_s
        while time.monotonic() < deadline:
            if self.poll() is not None and not self._group_alive():
                break
            time.sleep(0.02)
        else:
            self._signal_group(signal.SIGKILL)
        if self.poll() is None:
            self._signal_group(signal.SIGKILL)
            self.proc.wait()
            self.poll()
        if self._group_alive():  # members that outlived the leader and ignored SIGTERM
            self._signal_group(signal.SIGKILL)
        self._join_readers()

    def _join_readers(self) -> None:
        """Let the output readers reach the end of the pipes (bounded: a process outside the
        group may still hold them)."""
        deadline = time.monotonic() + 2.0
        for t in self._readers:
            t.join(timeout=max(0.0, deadline - time.monotonic()))

    @property
    def ended_by_itself(self) -> bool:
        """True when the child was seen ended before :meth:`stop` began (or without any stop)."""
        if self.stopping_at is None:
            return self.ended
        return self.ended_at is not None and self.ended_at <= self.stopping_at

    # ------------------------------------------------------------------ report
    def record(self, *, epoch: float, ended_early: Optional[bool] = None) -> dict:
        """The ``process`` object of ``results.json`` (schema: :mod:`helmcheck.reports.schema`).

        *ended_early* defaults to :attr:`ended_by_itself`."""
        if ended_early is None:
            ended_early = self.ended_by_itself
        rc = self.poll()
        if rc is not None:
            self._join_readers()
        return {
            "command": shlex.join(self.argv) if self.argv else self.command,
            "pid": self.pid,
            "exit_code": rc if rc is not None and rc >= 0 else None,
            "signal": _signal_name(-rc) if rc is not None and rc < 0 else None,
            "ended_at_s": None if self.ended_at is None else round(max(0.0, self.ended_at - epoch), 3),
            "ended_early": bool(ended_early),
            "output_tail": self.output_tail(),
        }


def _signal_name(num: int) -> str:
    try:
        return signal.Signals(num).name
    except ValueError:
        return f"SIG{num}"
