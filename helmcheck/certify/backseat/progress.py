"""The progress display of ``certify backseat``: scenario, elapsed time and offences so far.

A rich progress bar on standard error when it is a terminal (and the caller asked for it);
nothing otherwise. The runner calls :meth:`Progress.start` once the backseat has connected,
:meth:`Progress.update` as the run goes (at most five redraws a second) and :meth:`Progress.stop`.
"""

from __future__ import annotations

import time


class Progress:
    def __init__(self, enabled: bool = True) -> None:
        self.enabled = enabled
        self.task = None
        self._last = 0.0
        if not enabled:
            return
        from rich.console import Console
        from rich.progress import BarColumn, Progress as Bar, TextColumn, TimeRemainingColumn

        self.console = Console(stderr=True)
        self.bar = Bar(TextColumn("{task.description}"), BarColumn(), TextColumn("{task.fields[extra]}"),
                       TimeRemainingColumn(), console=self.console, transient=False,
                       disable=not self.console.is_terminal)

    def start(self, total: float) -> None:
        if not self.enabled:
            return
        self.bar.start()
        self.task = self.bar.add_task("connected", total=total, extra="")

    def update(self, elapsed: float, scenario: str, counts: dict) -> None:
        if self.task is None:
            return
        now = time.monotonic()
        if now - self._last < 0.2:
            return
        self._last = now
        bad = ", ".join(f"{c} ×{n}" for c, n in counts.items() if n)
        self.bar.update(self.task, completed=elapsed, description=f"{scenario:<11}",
                        extra=bad or "no offence so far")

    def stop(self) -> None:
        if self.task is not None:
            self.bar.stop()
