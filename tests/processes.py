"""Processes helmcheck started for a test run, found through ``/proc``; and the programs a test
starts itself that announce their port (:func:`announced_port`, :func:`stop`).

Every process helmcheck starts with ``--exec`` carries ``HELMCHECK_PORT`` in its environment
(and so do its own children). The test session sets :data:`MARKER` in its own environment, which
every process it starts inherits, so the two together pick out exactly the processes this test
session caused helmcheck to start — even those orphaned and re-parented away from the test
process — and nothing of other test runs on the same machine.
"""

from __future__ import annotations

import contextlib
import os
import re
import select
import signal
import subprocess
import uuid
from pathlib import Path
from typing import Iterator

__all__ = ["MARKER", "install_marker", "survivors", "descendants", "kill", "announced_port", "stop"]

MARKER = "HELMCHECK_TEST_RUN"


def install_marker() -> str:
    """Set (once) this session's marker in the environment; returns its value. Each pytest-xdist
    worker has its own (a worker's survivors are its own tests' processes, not another worker's
    that are still running)."""
    suffix = "-" + os.environ.get("PYTEST_XDIST_WORKER", "main")
    current = os.environ.get(MARKER, "")
    if not current.endswith(suffix):
        os.environ[MARKER] = uuid.uuid4().hex + suffix
    return os.environ[MARKER]


def _environ(pid: str) -> dict[str, str]:
    try:
        raw = Path(f"/proc/{pid}/environ").read_bytes()
    except OSError:
        return {}
    out = {}
    for item in raw.split(b"\0"):
        key, sep, value = item.partition(b"=")
        if sep:
            out[key.decode(errors="replace")] = value.decode(errors="replace")
    return out


def _cmdline(pid: str) -> str:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace").strip()
    except OSError:
        return "?"


def _state(pid: str) -> str:
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return "?"
    return stat.rsplit(")", 1)[1].split()[0]


def survivors(marker: str | None = None) -> list[tuple[int, str]]:
    """(pid, command line) of every live process (zombies aside) that helmcheck started for
    this session (``HELMCHECK_PORT`` and the session marker in its environment)."""
    marker = marker or os.environ.get(MARKER)
    out = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit() or int(entry) == os.getpid():
            continue
        env = _environ(entry)
        if "HELMCHECK_PORT" in env and env.get(MARKER) == marker and _state(entry) not in ("Z", "X", "?"):
            out.append((int(entry), _cmdline(entry)))
    return out


def descendants(root: int | None = None) -> list[tuple[int, str]]:
    """(pid, command line) of the live descendants of *root* (default: this process)."""
    root = root or os.getpid()
    parent: dict[int, int] = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            stat = Path(f"/proc/{entry}/stat").read_text()
        except OSError:
            continue
        fields = stat.rsplit(")", 1)[1].split()
        if fields[0] not in ("Z", "X"):
            parent[int(entry)] = int(fields[1])
    found, frontier = [], {root}
    while frontier:
        children = {pid for pid, ppid in parent.items() if ppid in frontier}
        found += sorted(children)
        frontier = children
    return [(pid, _cmdline(str(pid))) for pid in found]


def kill(procs: list[tuple[int, str]]) -> None:
    for pid, _ in procs:
        try:
            os.kill(pid, signal.SIGKILL)
        except OSError:
            pass


def stop(proc: subprocess.Popen, within: float = 10.0) -> None:
    """Stop a program started in a session of its own (``start_new_session``): SIGTERM to its
    process group, SIGKILL if it is still there after ``within`` seconds."""
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGTERM)
        try:
            proc.wait(within)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()


@contextlib.contextmanager
def announced_port(cmd: list[str], name: str, *, within: float = 20.0,
                   stderr=subprocess.STDOUT) -> Iterator[str]:
    """Start ``cmd`` (a vehicle we did not write, a simulator) in a session of its own; it prints
    ``port: PATH`` first. Yields the port, and stops the program at the end (:func:`stop`).
    Raises :class:`RuntimeError` naming ``name`` when no port came within ``within`` seconds."""
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=stderr, start_new_session=True)
    try:
        ready, _, _ = select.select([proc.stdout], [], [], within)
        line = proc.stdout.readline().decode(errors="replace") if ready else ""
        m = re.match(r"port: (\S+)", line)
        if not m:
            raise RuntimeError(f"{name} did not print its port: {line!r}")
        yield m.group(1)
    finally:
        stop(proc)
