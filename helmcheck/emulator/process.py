"""Start ``helmcheck emulate`` as a subprocess and talk to it: for tests, benchmarks and tools.

:class:`EmulatorProcess` runs ``python -m helmcheck emulate …``, reads the ``port: …`` line the
command prints first, and stops it with SIGTERM. :class:`HelmClient` is a minimal synchronous
backseat over any :class:`~helmcheck.line.transport.Link`: it frames commands
(``$body*hh`` CR LF, RH-FRM-1/2) and collects the replies up to the command's ``$ACK``
(RH-ACK-1, RH-ACK-5).
"""

from __future__ import annotations

import os
import select
import signal
import subprocess
import sys
import tempfile
import time
from typing import Optional, Sequence

from ..grammar import Framer, Line, checksum_hex, decode
from ..grammar import sentences as s
from ..line.transport import Link, open_link

__all__ = ["EmulatorProcess", "HelmClient", "frame", "AckTimeout"]


def frame(body: str) -> bytes:
    """``$body*HH`` CR LF with the body's checksum (RH-FRM-1, RH-FRM-2)."""
    raw = body.encode("latin-1")
    return b"$" + raw + b"*" + checksum_hex(raw).encode() + b"\r\n"


class AckTimeout(TimeoutError):
    """No ``$ACK`` of the wanted type arrived in time."""


class EmulatorProcess:
    """``helmcheck emulate`` in a subprocess; ``port`` is what its first line names."""

    def __init__(self, args: Sequence[str] = (), *, port: str = "pty", time_scale: Optional[float] = None,
                 baud: Optional[int] = None, python: str = sys.executable, startup_timeout: float = 120.0,
                 env: Optional[dict] = None):
        self.argv = [python, "-m", "helmcheck", "emulate", "--port", port]
        if time_scale is not None:
            self.argv += ["--time-scale", str(time_scale)]
        if baud is not None:
            self.argv += ["--baud", str(baud)]
        self.argv += list(args)
        self.startup_timeout = startup_timeout
        self.env = env
        self.proc: Optional[subprocess.Popen] = None
        self.port = ""
        self._stderr = tempfile.TemporaryFile()

    def start(self) -> "EmulatorProcess":
        """Launch and wait for the port line."""
        return self.launch().wait_ready()

    def launch(self) -> "EmulatorProcess":
        """Start the process without waiting (several can load in parallel)."""
        if self.proc is None:
            self.proc = subprocess.Popen(self.argv, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                         stderr=self._stderr, env=self.env)
        return self

    def wait_ready(self) -> "EmulatorProcess":
        """Read the ``port: …`` line (RuntimeError if the process dies or times out first)."""
        if self.port:
            return self
        assert self.proc is not None, "launch() first"
        deadline = time.monotonic() + self.startup_timeout
        buf = b""
        fd = self.proc.stdout.fileno()  # type: ignore[union-attr]
        while b"\n" not in buf:
            left = deadline - time.monotonic()
            if left <= 0 or self.proc.poll() is not None:
                self.stop()
                raise RuntimeError(f"emulator did not start: {self.stderr_text()[-2000:]}")
            r, _, _ = select.select([fd], [], [], min(left, 0.5))
            if r:
                chunk = os.read(fd, 4096)
                if not chunk:
                    continue
                buf += chunk
        first = buf.split(b"\n", 1)[0].decode("utf-8", "replace").strip()
        if not first.startswith("port: "):
            self.stop()
            raise RuntimeError(f"unexpected first line {first!r}")
        self.port = first[len("port: "):]
        return self

    @property
    def pid(self) -> int:
        assert self.proc is not None
        return self.proc.pid

    def rss_kb(self) -> int:
        """Resident set size of the emulator process (``/proc/<pid>/status`` VmRSS), in KiB."""
        with open(f"/proc/{self.pid}/status", encoding="ascii") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1])
        return 0

    def connect(self, baud: int = 19200) -> Link:
        """Open the emulator's port as a client."""
        return open_link(self.port, role="client", baud=baud)

    def stop(self, timeout: float = 10.0) -> Optional[int]:
        """SIGTERM, then wait (SIGKILL after ``timeout``); the exit status."""
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

    def __enter__(self) -> "EmulatorProcess":
        return self.start()

    def __exit__(self, *exc) -> None:
        self.stop()


class HelmClient:
    """A synchronous backseat: send a command, collect replies through its ``$ACK``."""

    def __init__(self, link: Link):
        self.link = link
        self.framer = Framer(4096)
        self.lines: list[bytes] = []

    def send(self, body: str) -> None:
        self.link.write_all(frame(body))

    def send_raw(self, data: bytes) -> None:
        self.link.write_all(data)

    def _fill(self, timeout: float) -> None:
        data = self.link.read(timeout)
        for ev in self.framer.feed(data):
            if isinstance(ev, Line):
                self.lines.append(ev.raw)

    def read_line(self, timeout: float = 2.0) -> Optional[bytes]:
        deadline = time.monotonic() + timeout
        while not self.lines:
            left = deadline - time.monotonic()
            if left <= 0:
                return None
            self._fill(left)
        return self.lines.pop(0)

    def drain(self, quiet: float = 0.05) -> list[bytes]:
        """Read until the line is quiet for ``quiet`` seconds; returns what came."""
        out = list(self.lines)
        self.lines.clear()
        while True:
            line = self.read_line(quiet)
            if line is None:
                return out
            out.append(line)

    def until_ack(self, ack_type: int, timeout: float = 2.0) -> list[s.Sentence]:
        """Replies up to and including the next ``$ACK,<ack_type>``."""
        got: list[s.Sentence] = []
        deadline = time.monotonic() + timeout
        while True:
            line = self.read_line(max(0.0, deadline - time.monotonic()))
            if line is None:
                raise AckTimeout(f"no $ACK,{ack_type} within {timeout} s (got {got})")
            d = decode(line)
            if d.sentence is None:
                raise AssertionError(f"invalid sentence from the vehicle: {line!r}: {d.error}")
            got.append(d.sentence)
            if isinstance(d.sentence, s.ACK) and d.sentence.type == ack_type:
                return got

    def request(self, body: str, ack_type: int, timeout: float = 2.0) -> list[s.Sentence]:
        self.send(body)
        return self.until_ack(ack_type, timeout)

    def ack(self, body: str, ack_type: int, timeout: float = 2.0) -> s.ACK:
        """Send and return just the ``$ACK``."""
        return self.request(body, ack_type, timeout)[-1]  # type: ignore[return-value]

    def osi(self, timeout: float = 2.0) -> s.OSI:
        """``$OSD,S`` and the ``$OSI`` it returns (RH-OSD-1)."""
        for r in self.request("OSD,S", 8, timeout):
            if isinstance(r, s.OSI):
                return r
        raise AssertionError("no $OSI before $ACK,8")
