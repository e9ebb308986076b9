"""Waiting in tests for a running process to write something (a wire log line, a note)."""

from __future__ import annotations

import time
from pathlib import Path


def wait_for_text(path: Path, text: str, timeout: float = 90.0) -> None:
    """Return once ``text`` appears in the file at ``path``; fail the test after ``timeout`` s."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if path.exists() and text in path.read_text(errors="replace"):
            return
        time.sleep(0.05)
    raise AssertionError(f"{text!r} never appeared in {path}")
