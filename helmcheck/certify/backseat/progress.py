"""The progress display of ``certify backseat``: scenario, elapsed time and offences so far.

On a terminal (standard error), a rich progress bar that keeps its width (:data:`BAR_WIDTH`)
however narrow the terminal, the text after it (the offences so far) cut with an ellipsis
instead; off a terminal (piped, in CI), plain lines: one when the judged run starts, one when
each scenario starts, and one at least every :data:`PLAIN_EVERY_S` seconds between. Nothing when
the caller turned it off. The runner calls :meth:`Progress.start` once the backseat has
connected, :meth:`Progress.update` as the run goes (the bar is redrawn at most five times a
second) and :meth:`Progress.stop`.
"""

from __future__ import annotations

import sys
import time
from typing import IO, Callable, Optional

__all__ = ["Progress", "BAR_WIDTH", "PLAIN_EVERY_S"]

#: Characters of the bar on a terminal, whatever the terminal's width.
BAR_WIDTH = 20
#: Seconds between two plain lines within one scenario.
PLAIN_EVERY_S = 10.0
_PREFIX = "helmcheck certify backseat:"


class Progress:
    def __init__(self, enabled: bool = True, stream: Optional[IO[str]] = None,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.enabled = enabled
        self.clock = clock  #: when lines are due (plain) and redraws (bar)
        self.stream = stream if stream is not None else sys.stderr
        self.task = None
        self.bar = None
        self.total = 0.0
        self._last = 0.0
        self._scenario: Optional[str] = None
        self._said_at = 0.0
        if not enabled or not getattr(self.stream, "isatty", lambda: False)():
            return
        from rich.console import Console
        from rich.progress import BarColumn, Progress as Bar, TextColumn, TimeRemainingColumn
        from rich.table import Column

        self.console = Console(file=self.stream)
        self.bar = Bar(TextColumn("{task.description}", table_column=Column(no_wrap=True)),
                       BarColumn(bar_width=BAR_WIDTH, table_column=Column(min_width=BAR_WIDTH, no_wrap=True)),
                       TimeRemainingColumn(table_column=Column(no_wrap=True)),
                       TextColumn("{task.fields[extra]}", table_column=Column(ratio=1, no_wrap=True,
                                                                              overflow="ellipsis")),
                       console=self.console, transient=False, expand=True)

    def start(self, total: float) -> None:
        if not self.enabled:
            return
        self.total = total
        if self.bar is not None:
            self.bar.start()
            self.task = self.bar.add_task("connected", total=total, extra="")
            return
        self.task = True
        self._said_at = self.clock()
        self._say(f"the backseat connected; the judged run takes {total:.1f} s")

    def update(self, elapsed: float, scenario: str, counts: dict, total: Optional[float] = None) -> None:
        """``total``: the run's length as it stands now (a scenario held open for its moment
        lengthens it)."""
        if self.task is None:
            return
        if total is not None and total > self.total:
            self.total = total
            if self.bar is not None:
                self.bar.update(self.task, total=total)
        now = self.clock()
        bad = ", ".join(f"{c} ×{n}" for c, n in counts.items() if n)
        if self.bar is None:
            if scenario != self._scenario or now - self._said_at >= PLAIN_EVERY_S:
                what = f"scenario {scenario} starts" if scenario != self._scenario else f"scenario {scenario}"
                self._scenario, self._said_at = scenario, now
                self._say(f"{elapsed:.1f} of {self.total:.1f} s, {what}; "
                          f"{'offences so far: ' + bad if bad else 'no offence so far'}")
            return
        if now - self._last < 0.2:
            return
        self._last = now
        self.bar.update(self.task, completed=elapsed, description=f"{scenario:<11}",
                        extra=bad or "no offence so far")

    def note(self, text: str) -> None:
        """Something that happened to the run (a port gone, back): shown even between updates."""
        if not self.enabled:
            return
        if self.bar is not None and self.task is not None:
            self.bar.console.print(f"{_PREFIX} {text}", markup=False, highlight=False)
        else:
            self._say(text)

    def _say(self, text: str) -> None:
        try:
            print(f"{_PREFIX} {text}", file=self.stream, flush=True)
        except (OSError, ValueError):
            pass

    def stop(self) -> None:
        if self.bar is not None and self.task is not None:
            self.bar.stop()
        self.task = None
