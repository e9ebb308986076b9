"""The live view: a terminal picture of the emulated vehicle, after the UVC remote-helm debug window.

The seed paper (§VI, figure 4) describes the UVC's debug window: every incoming sentence with
how the UVC parsed it, and to the right the control surfaces, the motor, the controller state
and the *Timeout* label counting down the active command's life. :class:`LiveView` shows the
same from an :class:`~.core.EmulatorCore`: scrolling incoming and outgoing sentences with their
parse verdicts, fins and motor bytes, mode, next waypoint, the active command's timeout, the
lockout countdown, park time, position, depth and battery. Keys inject safety violations
(RH-SAF-1; one per code, listed at the bottom) and ``q`` quits.

It is optional and separate from the core: the I/O loop (:mod:`.server`) calls
:meth:`LiveView.refresh` at :meth:`LiveView.next_refresh` and :meth:`LiveView.on_input` when a
key arrives. :meth:`LiveView.render` builds the picture without a terminal (tests use it).
"""

from __future__ import annotations

import os
import sys
import termios
import tty
from typing import Any, Optional

from rich.console import Console, Group
from rich.layout import Layout
from rich.live import Live
from rich.panel import Panel
from rich.table import Table
from rich.text import Text

from ...profile import SAFETY_CODES
from .core import EmulatorCore

__all__ = ["LiveView", "FAULT_KEYS", "MODE_NAMES"]

#: Key -> safety code, in the profile's order (§7).
FAULT_KEYS = dict(zip("1234567890-=", SAFETY_CODES))
MODE_NAMES = {"S": "stopped", "N": "normal (mission)", "P": "mission park", "mP": "manual park ($OPK)",
              "A": "servo ($OMS)", "M": "primitive ($OMP)", "W": "on-the-fly waypoints ($OMW)"}
_FINS = ("yaw top", "yaw bottom", "pitch left", "pitch right", "motor")


def _clock(seconds: float) -> str:
    seconds = max(0.0, seconds)
    h, rem = divmod(int(seconds), 3600)
    m, s = divmod(rem, 60)
    return f"{h:02d}:{m:02d}:{s:02d}"


def _verdict_style(verdict: str) -> str:
    if verdict.startswith("ok"):
        return "green"
    if verdict.startswith("error ACK"):
        return "yellow"
    if verdict.startswith(("discard", "ignored")):
        return "red"
    return ""


class LiveView:
    """Rich live view of one core. See the module docstring."""

    def __init__(self, core: EmulatorCore, port: str, *, rate_hz: float = 8.0,
                 console: Optional[Console] = None, rows: int = 30):
        self.core = core
        self.port = port
        self.period = 1.0 / rate_hz
        self.rows = rows
        self.console = console or Console()
        self._live: Optional[Live] = None
        self._next: Optional[float] = None
        self._fd: Optional[int] = None
        self._saved: Any = None
        self.message = ""

    # ------------------------------------------------------------------ lifecycle
    def start(self) -> None:
        if sys.stdin.isatty():
            self._fd = sys.stdin.fileno()
            self._saved = termios.tcgetattr(self._fd)
            tty.setcbreak(self._fd)
        self._live = Live(self.render(), console=self.console, screen=True, auto_refresh=False)
        self._live.start()
        self._next = 0.0

    def close(self) -> None:
        if self._live is not None:
            self._live.stop()
            self._live = None
        if self._fd is not None and self._saved is not None:
            termios.tcsetattr(self._fd, termios.TCSADRAIN, self._saved)
            self._fd = None

    # ------------------------------------------------------------------ loop hooks
    def fileno(self) -> Optional[int]:
        """The keyboard descriptor (standard input in cbreak mode), if there is one."""
        return self._fd if self._fd is not None else (sys.stdin.fileno() if sys.stdin.isatty() else None)

    def next_refresh(self) -> Optional[float]:
        return self._next

    def refresh(self, now: float) -> None:
        self._next = now + self.period
        if self._live is not None:
            self._live.update(self.render(), refresh=True)

    def on_input(self, server: Any, now: float) -> None:
        try:
            keys = os.read(self.fileno(), 64).decode("latin-1")  # type: ignore[arg-type]
        except OSError:
            return
        for k in keys:
            if k in FAULT_KEYS:
                code = FAULT_KEYS[k]
                server.inject_fault(code, f"key {k}")
                self.message = f"injected {code}"
            elif k in "qQ":
                server.stop(0)
        self._next = now

    # ------------------------------------------------------------------ picture
    def render(self) -> Layout:
        v = self.core.view()
        layout = Layout()
        layout.split_column(Layout(self._header(v), name="head", size=3),
                            Layout(name="body"),
                            Layout(self._footer(), name="foot", size=3))
        layout["body"].split_row(Layout(self._traffic(), name="traffic", ratio=3),
                                 Layout(self._state(v), name="state", ratio=1, minimum_size=36))
        return layout

    def _header(self, v: dict) -> Panel:
        t = Text.assemble(("helmcheck emulator", "bold"), f"   port {self.port}   vehicle time ",
                          (_clock(v["v"]), "bold cyan"), f"  (x{v['time_scale']:g})   profile ",
                          self.core.profile.name)
        return Panel(t, style="blue")

    def _footer(self) -> Panel:
        keys = "  ".join(f"{k} {c}" for k, c in FAULT_KEYS.items())
        t = Text.assemble(("keys: ", "bold"), keys, "   q quit   ", (self.message, "bold red"))
        return Panel(t)

    def _traffic(self) -> Panel:
        table = Table(expand=True, show_edge=False, pad_edge=False, box=None)
        table.add_column("t", justify="right", width=9, no_wrap=True)
        table.add_column("", width=1, no_wrap=True)
        table.add_column("sentence", ratio=3, overflow="ellipsis", no_wrap=True)
        table.add_column("verdict", ratio=2, overflow="ellipsis", no_wrap=True)
        entries = list(self.core.history)[-self.rows:]
        for e in entries:
            style = {"<": "cyan", "!": "magenta"}.get(e.direction, "")
            table.add_row(f"{e.t:.3f}", e.direction, Text(e.text, style=style),
                          Text(e.verdict, style=_verdict_style(e.verdict)))
        return Panel(table, title="serial traffic (> in, < out, ! note)")

    def _state(self, v: dict) -> Panel:
        g = Table.grid(padding=(0, 1))
        g.add_column(style="bold", no_wrap=True)
        g.add_column(no_wrap=True)
        mode = v["mode"]
        g.add_row("Mode", Text(f"{mode}  {MODE_NAMES.get(mode, '')}", style="bold green"))
        phase = v["phase"]
        g.add_row("Safety", Text(f"{v['error_state']}  {phase}",
                                 style="bold red" if v["error_state"] != "N" else ""))
        g.add_row("Mission", v["mission"] or "-")
        g.add_row("Next WP", str(v["next_wp"]))
        g.add_row("Distance", f"{v['distance']:.1f} m")
        remote = v["remote_left"]
        g.add_row("Timeout", Text(f"{remote:6.1f} s" if remote is not None else "-",
                                  style="bold yellow" if remote is not None else ""))
        lock = v["lockout_left"]
        g.add_row("Lockout", Text(f"{lock:6.1f} s" if lock is not None else "-",
                                  style="bold red" if lock is not None else ""))
        park = v["park_left"]
        g.add_row("Park", f"{park:6.1f} s" if park is not None else "-")
        g.add_row("Queue", str(v["queue"]))
        g.add_row("", "")
        act = v["actuators"] or "8080808080"
        for i, name in enumerate(_FINS):
            byte = int(act[2 * i:2 * i + 2], 16) if len(act) >= 2 * i + 2 else 0x80
            bar = _bar(byte)
            g.add_row(name.capitalize(), Text(f"{byte:02X} {bar}"))
        g.add_row("", "")
        g.add_row("Lat/Lon", f"{v['lat']:.6f} {v['lon']:.6f}")
        g.add_row("Depth", f"{v['depth']:.2f} m")
        g.add_row("Heading", f"{v['heading']:.1f}° mag")
        g.add_row("Speed", f"{v['speed']:.2f} kn")
        g.add_row("Battery", f"{v['battery']:.1f} %")
        last = v["last_command"]
        last_text = type(last).__name__ if last is not None else "-"
        stats = v["stats"]
        g.add_row("Last cmd", last_text)
        g.add_row("Lines", f"{stats['lines_in']} in, {stats['sentences_out']} out, "
                           f"{stats['discarded']} discarded")
        return Panel(Group(g), title="controller")


def _bar(byte: int, width: int = 10) -> str:
    """A centred bar: 0x80 in the middle, 0x00 full left, 0xFF full right."""
    pos = round((byte / 255.0) * (width - 1))
    mid = (width - 1) // 2
    cells = ["·"] * width
    lo, hi = sorted((mid, pos))
    for i in range(lo, hi + 1):
        cells[i] = "█"
    cells[mid] = "|" if pos == mid else cells[mid]
    return "".join(cells)
