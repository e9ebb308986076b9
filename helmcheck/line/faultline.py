"""A vehicle behind an impaired line, for a test: :func:`impaired_line`.

::

    with impaired_line(emulator.port, "baud=19200,<line-delay=0.6", link=tmp / "vehicle") as line:
        certify(port=line.port, ...)          # the tester opens line.port
        faults = line.fault_notes()           # what the line did, when, which way

The vehicle's port (a pty path such as the emulator's, a device, ``socket://HOST:PORT``) is
opened as the relay's vehicle side; the tester-facing side is a new pty, behind ``link`` when
given (a cut re-creates it there), and :attr:`~.faultrelay.FaultRelay.port` is what to open.
The relay runs in a thread of this process (``process=False``, the default: it starts at once)
or in a process of its own (``process=True``: ``helmcheck relay``, so that this process's own
work never holds a byte back; it costs the interpreter's start, about half a second). Either
way the timing is real: bytes are delivered when the schedule says, by the clock.

The object yielded has ``port``, ``t0`` (when the relay started, on the monotonic clock: the
windows of ``stall`` and ``cut`` count from it), ``wire_log`` (the relay's log; a temporary file
when none was asked for), :meth:`notes` (every note so far: seconds since the relay started,
text) and :meth:`fault_notes` (the line-fault notes, read back by
:func:`helmcheck.grammar.faultnote.read_fault_note`). ``realtime`` (the thread asks for
real-time priority where allowed) is the thread's; a process asks for it always.
"""

from __future__ import annotations

import os
import select
import signal
import subprocess
import sys
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator, Optional

from ..grammar.faultnote import FaultNote, read_fault_note
from ..grammar.wirelog import NOTE, read_wire_log
from .faultrelay import FaultRelay
from .impair_spec import LineFaults

__all__ = ["impaired_line", "RelayProcess", "read_notes"]


def read_notes(path: Path | str) -> list[tuple[float, str]]:
    """The notes of a relay's wire log: (seconds since the relay started, text)."""
    try:
        with open(path, "rb") as f:
            return [(r.t, r.note) for r in read_wire_log(f) if r.dir == NOTE]
    except FileNotFoundError:
        return []


def _faults(notes: list[tuple[float, str]]) -> list[tuple[float, FaultNote]]:
    return [(t, f) for t, f in ((t, read_fault_note(text)) for t, text in notes) if f is not None]


class RelayProcess:
    """``helmcheck relay --between pty VEHICLE …`` in a process of its own (module docstring)."""

    def __init__(self, vehicle: str, faults: str, *, link: Optional[Path] = None, wire_log: Optional[Path] = None,
                 seed: Optional[int] = None, baud: int = 19200, cut_side: str = "backseat",
                 startup_timeout: float = 30.0):
        self.wire_log = Path(wire_log) if wire_log else None
        self.link = Path(link) if link else None
        self.argv = [sys.executable, "-m", "helmcheck", "relay", "--between", "pty", vehicle, "--impair", faults,
                     "--baud", str(baud), "--cut-side", cut_side]
        if self.link is not None:
            self.argv += ["--link", str(self.link)]
        if self.wire_log is not None:
            self.argv += ["--wire-log", str(self.wire_log)]
        if seed is not None:
            self.argv += ["--seed", str(seed)]
        self.startup_timeout = startup_timeout
        self.proc: Optional[subprocess.Popen] = None
        self.pty = ""  #: the first pty's path (after a cut the link points to another)
        self._stderr = tempfile.TemporaryFile()

    @property
    def port(self) -> str:
        return str(self.link) if self.link is not None else self.pty

    @property
    def t0(self) -> float:
        """When the relay started, on this machine's monotonic clock (the log's time 0; the
        windows of ``stall`` and ``cut`` count from it), read from its wire log's header."""
        with open(self.wire_log, "rb") as f:  # type: ignore[arg-type]
            for line in f:
                if line.startswith(b"# clock monotonic "):
                    return float(line.split()[3])
                if not line.startswith(b"#"):
                    break
        raise RuntimeError(f"{self.wire_log} does not say when the relay started")

    def start(self) -> "RelayProcess":
        self.proc = subprocess.Popen(self.argv, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                     stderr=self._stderr)
        fd = self.proc.stdout.fileno()  # type: ignore[union-attr]
        deadline = time.monotonic() + self.startup_timeout
        buf = b""
        while b"\n" not in buf:
            left = deadline - time.monotonic()
            if left <= 0 or (self.proc.poll() is not None and not select.select([fd], [], [], 0)[0]):
                self.stop()
                raise RuntimeError(f"the relay did not start: {self.stderr_text()[-2000:]}")
            if select.select([fd], [], [], min(left, 0.2))[0]:
                chunk = os.read(fd, 4096)
                if not chunk and self.proc.poll() is not None:
                    continue
                buf += chunk
        first = buf.split(b"\n", 1)[0].decode("utf-8", "replace").strip()
        if not first.startswith("port: "):
            self.stop()
            raise RuntimeError(f"unexpected first line from the relay: {first!r}")
        self.pty = first[len("port: "):]
        return self

    def stop(self, timeout: float = 5.0) -> Optional[int]:
        p = self.proc
        if p is None:
            return None
        if p.poll() is None:
            p.send_signal(signal.SIGTERM)
            try:
                p.wait(timeout)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
        if p.stdout is not None:
            p.stdout.close()
        return p.returncode

    def stderr_text(self) -> str:
        self._stderr.seek(0)
        return self._stderr.read().decode("utf-8", "replace")

    def notes(self) -> list[tuple[float, str]]:
        return read_notes(self.wire_log) if self.wire_log is not None else []

    def fault_notes(self) -> list[tuple[float, FaultNote]]:
        return _faults(self.notes())


@contextmanager
def impaired_line(vehicle: str, faults: LineFaults | str = "", *, link: Optional[str | Path] = None,
                  wire_log: Optional[str | Path] = None, seed: Optional[int] = None, baud: int = 19200,
                  cut_side: str = "backseat", process: bool = False,
                  realtime: bool = True) -> Iterator["FaultRelay | RelayProcess"]:
    """Put the vehicle at port ``vehicle`` behind a line spoiled by ``faults`` (module docstring)."""
    tmp = None
    if wire_log is None:
        tmp = tempfile.TemporaryDirectory(prefix="helmcheck-relay-")
        wire_log = Path(tmp.name) / "relay.log"
    try:
        if process:
            if isinstance(faults, LineFaults):
                if not faults.text and not faults.clean:
                    raise ValueError("a relay in a process of its own takes the faults as --impair text")
                faults = faults.text
            proc = RelayProcess(vehicle, faults, link=Path(link) if link else None, wire_log=Path(wire_log),
                                seed=seed, baud=baud, cut_side=cut_side).start()
            try:
                yield proc
            finally:
                proc.stop()
        else:
            with FaultRelay("pty", vehicle, faults, link=link, wire_log=wire_log, seed=seed, baud=baud,
                         cut_side=cut_side, realtime=realtime) as relay:
                yield relay
    finally:
        if tmp is not None:
            tmp.cleanup()
