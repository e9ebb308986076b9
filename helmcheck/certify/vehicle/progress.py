"""The progress display: a rich progress bar on a terminal, plain lines otherwise (stderr).

On a terminal the bar keeps its width (:data:`BAR_WIDTH`) however narrow the terminal: the
text after it (the last case and its verdict, the exploration's budget) is cut with an ellipsis
instead (at 80 columns the bar is 20 characters). Off a terminal (piped, in CI) each case is a
line, and the exploration a line at its start and then at most one every :data:`PLAIN_EVERY_S`.

The exploration is shown by what its budget allows, not by the examples asked for (the wall
budget usually ends it long before): the sequences and steps run so far and the share of the
budget used — the wall clock's or the vehicle clock's, whichever is further on; on the bar, the
exploration's step fills as its budget is used. When it ends, its line says what it did
(:func:`explored_text`: sequences and steps run, the time it took, the budget it had and whether
the budget or the examples asked for ended it), so a short exploration never reads as skipped.
"""

from __future__ import annotations

import sys
import time
from typing import IO, Callable, Optional

__all__ = ["Progress", "BAR_WIDTH", "PLAIN_EVERY_S", "budget_text", "explored_text"]

#: Characters of the bar on a terminal, whatever the terminal's width.
BAR_WIDTH = 20
#: Seconds between two plain exploration lines.
PLAIN_EVERY_S = 10.0


def _n(count: int, what: str) -> str:
    return f"{count} {what}{'s' if count != 1 else ''}"


def budget_text(ran: int, wall_s: float, wall_budget_s: float, vehicle_s: float, vehicle_budget_s: float,
                short: bool = False, steps: Optional[int] = None) -> tuple[float, str]:
    """The share of an exploration's budget used (0..1, whichever clock is further on) and its
    text: ``exploration: 14 sequences and 210 steps run so far, 45 % of the budget (14 of 30 s
    wall)``."""
    wall = wall_s / wall_budget_s if wall_budget_s > 0 else 0.0
    veh = vehicle_s / vehicle_budget_s if vehicle_budget_s > 0 else 0.0
    used = min(1.0, max(wall, veh))
    done = _n(ran, "sequence") + ("" if steps is None else f" and {_n(steps, 'step')}")
    if short:
        return used, f"exploring: {used * 100:.0f} % of budget, {done}"
    clock = (f"{wall_s:.0f} of {wall_budget_s:g} s wall" if wall >= veh
             else f"{vehicle_s:.0f} of {vehicle_budget_s:g} s vehicle time")
    return used, f"exploration: {done} run so far, {used * 100:.0f} % of the budget ({clock})"


def explored_text(stats: Optional[dict]) -> str:
    """What an exploration did, for its progress line when it ends (``stats``: the run's
    ``stats.explore``): ``10 sequences and 214 steps in 6.8 s; all 10 examples asked, within its
    budget of 30 s wall or 1500 s vehicle time`` — or that it was not run, and why."""
    if not isinstance(stats, dict) or not stats.get("examples"):
        why = stats.get("outcome") if isinstance(stats, dict) else None
        return why or "not run"
    done = _n(int(stats.get("ran") or 0), "sequence")
    if stats.get("steps") is not None:
        done += f" and {_n(int(stats['steps']), 'step')}"
    if stats.get("wall_s") is not None:
        done += f" in {float(stats['wall_s']):.1f} s"
    budget = f"{float(stats.get('budget_s') or 0):g} s wall or {float(stats.get('budget_vehicle_s') or 0):g} s vehicle time"
    if stats.get("budget_spent"):
        end = f"its budget ({budget}, whichever ends first) spent before the {stats['examples']} examples asked"
    else:
        end = f"all {stats['examples']} examples asked, within its budget of {budget}"
    found = int(stats.get("failures") or 0)
    return f"{done}; {end}" + (f"; {_n(found, 'failing sequence')}" if found else "")


class Progress:
    """``start(total)``, ``step(label, verdict)``, ``explore(ran, wall_s, wall_budget_s, vehicle_s,
    vehicle_budget_s)``, ``note(text)``, ``alert(text)``, ``stop()``. The verdict shown for a case is
    its subject clause's verdict as the ledger has it — the word the report will use."""

    def __init__(self, stream: Optional[IO[str]] = None, enabled: bool = True,
                 clock: Callable[[], float] = time.monotonic):
        self.stream = stream or sys.stderr
        self.clock = clock  #: when plain exploration lines are due
        self.enabled = enabled
        self.rich = None
        self.task = None
        self.n = 0
        self.total = 0
        self._plain_at: Optional[float] = None  #: when the last plain exploration line was printed

    def start(self, total: int, title: str = "certify vehicle") -> None:
        self.total = total
        if not self.enabled:
            return
        if getattr(self.stream, "isatty", lambda: False)():
            try:
                from rich.console import Console
                from rich.progress import BarColumn, MofNCompleteColumn, Progress as RP, TextColumn, TimeElapsedColumn
                from rich.table import Column

                fixed = Column(no_wrap=True)
                self.rich = RP(TextColumn("[bold]{task.description}", table_column=fixed),
                               BarColumn(bar_width=BAR_WIDTH, table_column=Column(min_width=BAR_WIDTH, no_wrap=True)),
                               MofNCompleteColumn(table_column=Column(no_wrap=True)),
                               TimeElapsedColumn(table_column=Column(no_wrap=True)),
                               TextColumn("{task.fields[last]}",
                                          table_column=Column(ratio=1, no_wrap=True, overflow="ellipsis")),
                               console=Console(file=self.stream), transient=True, expand=True)
                self.rich.start()
                self.task = self.rich.add_task(title, total=total, last="")
                return
            except Exception:  # noqa: BLE001 - fall back to plain lines
                self.rich = None
        print(f"{title}: {total} steps", file=self.stream, flush=True)

    def step(self, label: str, verdict: str) -> None:
        self.n += 1
        if not self.enabled:
            return
        if self.rich is not None:
            self.rich.update(self.task, completed=self.n, last=f"{label} {verdict}")
            return
        print(f"[{self.n}/{self.total}] {label} {verdict}", file=self.stream, flush=True)

    def explore(self, ran: int, wall_s: float, wall_budget_s: float, vehicle_s: float = 0.0,
                vehicle_budget_s: float = 0.0, steps: Optional[int] = None) -> None:
        """Exploration progress: the sequences and steps run and the share of its budget used
        (module docstring)."""
        if not self.enabled:
            return
        short = self.rich is not None
        used, text = budget_text(ran, wall_s, wall_budget_s, vehicle_s, vehicle_budget_s, short=short, steps=steps)
        if self.rich is not None:
            self.rich.update(self.task, completed=self.n + used, last=text)
            return
        now = self.clock()
        if self._plain_at is None or now - self._plain_at >= PLAIN_EVERY_S:
            self._plain_at = now
            print(text, file=self.stream, flush=True)

    def note(self, text: str) -> None:
        if not self.enabled:
            return
        if self.rich is not None:
            self.rich.console.print(text)
        else:
            print(text, file=self.stream, flush=True)

    def alert(self, text: str) -> None:
        """Something a person must act on: shown even with the progress display off, with the
        terminal's bell."""
        bell = "\a" if getattr(self.stream, "isatty", lambda: False)() else ""
        if self.rich is not None:
            self.rich.console.print(f"[bold]>>> {text}[/bold]", markup=True, highlight=False)
            if bell:
                self.stream.write(bell)
                self.stream.flush()
        else:
            print(f">>> {text}{bell}", file=self.stream, flush=True)

    def stop(self) -> None:
        if self.rich is not None:
            self.rich.stop()
            self.rich = None
