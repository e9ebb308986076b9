"""What a person watching a monitored session sees: one line per finding, or a live screen.

* :func:`finding_line` — one finding as one line (``  12.345 s  FAIL  RH-BS-4  backseat: …``),
  printed the moment the judge makes it (plain output: a pipe, a log file, a CI job);
* :class:`LiveScreen` — on a terminal: the session clock, bytes and records each way, the
  vehicle's mode as the judge believes it, the clauses seen so far by verdict, the newest
  finding and the judge's backlog, redrawn a few times a second (rich). It only reads snapshots:
  neither the relay nor the judge ever waits for it;
* :class:`StatusLines` — off a terminal (or ``--no-tui``): the same snapshot as one line on
  standard error every :data:`STATUS_EVERY_S` seconds, so a long session piped to a file or
  run in CI shows it is alive between findings.
"""

from __future__ import annotations

import sys
from typing import IO, Optional

from .live import Finding

__all__ = ["finding_line", "LiveScreen", "StatusLines", "STATUS_EVERY_S"]

#: Seconds between two status lines off a terminal.
STATUS_EVERY_S = 10.0


def finding_line(f: Finding) -> str:
    word = "FAIL" if f.first else "fail"
    return f"{f.t:10.3f} s  {word:<4}  {f.clause:<9} {f.role}: {f.reason}  (wire.log line {f.lineno})"


class LiveScreen:
    """A rich live display on standard error (module docstring)."""

    def __init__(self, title: str, stream: IO[str] = sys.stderr):
        from rich.console import Console
        from rich.live import Live

        self.title = title
        self.console = Console(file=stream)
        self.live = Live(console=self.console, refresh_per_second=4, transient=False)
        self.newest: Optional[Finding] = None
        self.live.start()

    def finding(self, f: Finding) -> None:
        self.newest = f

    def refresh(self, state: dict, stats: dict, elapsed: float) -> None:
        from rich.table import Table
        from rich.text import Text

        t = Table.grid(padding=(0, 2))
        t.add_row(Text(self.title, style="bold"), Text(f"{elapsed:8.1f} s"))
        b = stats.get("bytes", {})
        t.add_row("backseat → vehicle", f"{b.get('>', 0)} bytes")
        t.add_row("vehicle → backseat", f"{b.get('<', 0)} bytes")
        t.add_row("records judged", f"{state.get('records', 0)} (backlog {state.get('backlog', 0)})")
        t.add_row("vehicle mode", state.get("mode") or "not seen yet")
        by: dict[str, list[str]] = {}
        for cid, v in sorted(state.get("clauses", {}).items()):
            by.setdefault(v, []).append(cid)
        for v, style in (("fail", "bold red"), ("inconclusive", "yellow"), ("pass", "green")):
            if by.get(v):
                t.add_row(Text(v.upper(), style=style), " ".join(by[v]))
        if self.newest is not None:
            t.add_row(Text("newest finding", style="bold red"), finding_line(self.newest))
        self.live.update(t)

    def close(self) -> None:
        self.live.stop()


class StatusLines:
    """A status line on *stream* at most every :data:`STATUS_EVERY_S` seconds (module docstring)."""

    def __init__(self, title: str, stream: Optional[IO[str]] = None, every: float = STATUS_EVERY_S):
        self.title = title
        self.stream = stream if stream is not None else sys.stderr
        self.every = every
        self.findings = 0
        self._next = every

    def finding(self, f: Finding) -> None:
        self.findings += 1

    def refresh(self, state: dict, stats: dict, elapsed: float) -> None:
        if elapsed < self._next:
            return
        self._next = elapsed + self.every
        b = stats.get("bytes", {})
        try:
            print(f"{self.title}: {elapsed:.0f} s, {b.get('>', 0)} bytes to the vehicle, {b.get('<', 0)} from it, "
                  f"{state.get('records', 0)} records judged, vehicle mode {state.get('mode') or 'not seen yet'}, "
                  f"{self.findings} finding(s) so far", file=self.stream, flush=True)
        except (OSError, ValueError):
            pass

    def close(self) -> None:
        pass
