"""The progress display: a rich progress bar on a terminal, plain lines otherwise (stderr)."""

from __future__ import annotations

import sys
from typing import IO, Optional

__all__ = ["Progress"]


class Progress:
    """``start(total)``, ``step(label, verdict)``, ``explore(ran, total, left_s)``, ``note(text)``,
    ``alert(text)``, ``stop()``. The verdict shown for a case is its subject clause's verdict as the ledger has it —
    the word the report will use."""

    def __init__(self, stream: Optional[IO[str]] = None, enabled: bool = True):
        self.stream = stream or sys.stderr
        self.enabled = enabled
        self.rich = None
        self.task = None
        self.n = 0
        self.total = 0

    def start(self, total: int, title: str = "certify vehicle") -> None:
        self.total = total
        if not self.enabled:
            return
        if getattr(self.stream, "isatty", lambda: False)():
            try:
                from rich.console import Console
                from rich.progress import BarColumn, MofNCompleteColumn, Progress as RP, TextColumn, TimeElapsedColumn

                self.rich = RP(TextColumn("[bold]{task.description}"), BarColumn(), MofNCompleteColumn(),
                               TimeElapsedColumn(), TextColumn("{task.fields[last]}"),
                               console=Console(file=self.stream), transient=True)
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
            self.rich.update(self.task, advance=1, last=f"{label} {verdict}")
            return
        print(f"[{self.n}/{self.total}] {label} {verdict}", file=self.stream, flush=True)

    def explore(self, ran: int, total: int, left_s: float) -> None:
        """Exploration progress: sequences run of the examples asked for, and budget left."""
        if not self.enabled:
            return
        text = f"exploration: sequence {ran}/{total}, {left_s:.0f} s of budget left"
        if self.rich is not None:
            self.rich.update(self.task, last=text)
        else:
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
