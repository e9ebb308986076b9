"""The live view: a terminal picture of the emulated vehicle, after the UVC remote-helm debug window.

The seed paper (§VI, figure 4) describes the UVC's debug window: every incoming sentence with
how the UVC parsed it, and to the right the control surfaces, the motor, the controller state
and the *Timeout* label counting down the active command's life. :class:`LiveView` shows the
same from an :class:`~.core.EmulatorCore`: scrolling incoming and outgoing sentences with their
verdicts, fins and motor bytes, mode, next waypoint, the active command's timeout, the lockout
countdown, park time, position, depth and battery. Keys inject safety violations (RH-SAF-1; one
per code, named in words at the bottom: ``1 over-pitch (Sop)``) and ``q`` quits.

It is optional and separate from the core: the I/O loop (:mod:`.server`) calls
:meth:`LiveView.refresh` at :meth:`LiveView.next_refresh` and :meth:`LiveView.on_input` when a
key arrives. :meth:`LiveView.render` builds the picture without a terminal (tests use it).

Decisions:

- The newest traffic is always on screen: the picture is laid out for the terminal's present
  size (at least 80×24), the traffic panel gets every row the header, the key legend and the
  panel frame leave, and it shows the last that many lines.
- A command is shown with what became of it: ``ok OMS`` only when the vehicle accepted it;
  one the vehicle refused (``$ACK`` status 1, RH-ACK-1) reads ``refused (err N)``, and so does
  the ``$ACK`` itself (an accepting one reads ``accepted``).
- The view never blocks the emulator. :meth:`LiveView.refresh` only takes a snapshot; a painter
  thread renders it and writes the frame to the terminal. While the terminal does not read
  (a stopped terminal, a full pty buffer) the painter waits on its write and newer snapshots
  replace the one waiting, so frames are dropped (:attr:`LiveView.dropped`) and the emulator
  keeps serving. Each frame is a whole screen drawn from the home position on the alternate
  screen, so a dropped frame leaves nothing half drawn.
"""

from __future__ import annotations

import io
import os
import sys
import termios
import threading
import tty
from dataclasses import dataclass
from typing import Any, Callable, Optional

from rich.console import Console, Group
from rich.layout import Layout
from rich.panel import Panel
from rich.table import Table
from rich.text import Text

from ..profile import SAFETY_CODES
from .core import EmulatorCore

__all__ = ["LiveView", "FAULT_KEYS", "FAULT_WORDS", "MODE_NAMES", "legend", "legend_lines", "Snapshot"]

#: Key -> safety code, in the profile's order (§7).
FAULT_KEYS = dict(zip("1234567890-=", SAFETY_CODES))
#: Safety code -> what it means, in words (reference profile §7).
FAULT_WORDS = {"Sop": "over-pitch", "Stl": "time limit", "Sle": "leak", "Sfp": "no forward progress",
               "Sed": "max depth", "Sup": "no upward progress", "Stf": "tow float", "Srp": "SRP",
               "Snd": "depth unchanged", "Snc": "compass stopped", "Spw": "low power",
               "Sti": "Iridium stop"}
MODE_NAMES = {"S": "stopped", "N": "normal (mission)", "P": "mission park", "mP": "manual park ($OPK)",
              "A": "servo ($OMS)", "M": "primitive ($OMP)", "W": "on-the-fly waypoints ($OMW)"}
_FINS = ("yaw top", "yaw bottom", "pitch left", "pitch right", "motor")
MIN_SIZE = (80, 24)
_ENTER = b"\x1b[?1049h\x1b[?25l\x1b[2J"  # alternate screen, cursor hidden, cleared
_LEAVE = b"\x1b[?25h\x1b[?1049l"  # cursor shown, main screen back
_HOME = b"\x1b[H"
_CLEAR = b"\x1b[2J"


def legend() -> str:
    """The key legend in words: ``1 over-pitch (Sop)  2 time limit (Stl) …  q quit``."""
    return "  ".join(_legend_items())


def _legend_items() -> list[str]:
    return ["keys:"] + [f"{k} {FAULT_WORDS.get(c, c)} ({c})" for k, c in FAULT_KEYS.items()] + ["q quit"]


def legend_lines(width: int, message: str = "") -> list[str]:
    """The legend packed into lines of ``width``, never splitting one key's entry."""
    lines: list[str] = []
    for item in _legend_items() + ([message] if message else []):
        if lines and len(lines[-1]) + 2 + len(item) <= width:
            lines[-1] += "  " + item
        else:
            lines.append(item[:width])
    return lines


def _clock(seconds: float) -> str:
    seconds = max(0.0, seconds)
    h, rem = divmod(int(seconds), 3600)
    m, s = divmod(rem, 60)
    return f"{h:02d}:{m:02d}:{s:02d}"


def _verdict_style(verdict: str) -> str:
    if verdict.startswith(("ok", "accepted")):
        return "green"
    if verdict.startswith(("refused", "error ACK")):
        return "yellow"
    if verdict.startswith(("discard", "ignored")):
        return "red"
    return ""


@dataclass(frozen=True)
class Snapshot:
    """What one frame shows, taken on the emulator's thread (cheap: no rendering)."""

    view: dict
    history: tuple
    message: str
    size: tuple[int, int]


class _Painter(threading.Thread):
    """Renders snapshots and writes frames to the terminal on its own thread (module docstring)."""

    def __init__(self, fd: int, render: Callable[[Snapshot], bytes]):
        super().__init__(name="live-view", daemon=True)
        self.fd = fd
        self.render = render
        self._cond = threading.Condition()
        self._pending: Optional[Snapshot] = None
        self._stopping = False
        self._size: Optional[tuple[int, int]] = None
        self.frames = 0
        self.dropped = 0
        self.broken: Optional[str] = None

    def offer(self, snap: Snapshot) -> None:
        with self._cond:
            if self._pending is not None:
                self.dropped += 1
            self._pending = snap
            self._cond.notify()

    def stop(self, timeout: float) -> None:
        with self._cond:
            self._stopping = True
            self._cond.notify()
        self.join(timeout)

    def _write(self, data: bytes) -> None:
        view = memoryview(data)
        while view and self.broken is None:
            try:
                n = os.write(self.fd, view)
            except InterruptedError:
                continue
            except OSError as e:  # the terminal went away
                self.broken = e.strerror or str(e)
                return
            view = view[n:]

    def run(self) -> None:
        self._write(_ENTER)
        while self.broken is None:
            with self._cond:
                while self._pending is None and not self._stopping:
                    self._cond.wait()
                snap, self._pending = self._pending, None
                if snap is None:
                    break
            frame = self.render(snap)
            if self._size != snap.size:
                frame = _CLEAR + frame
                self._size = snap.size
            self._write(_HOME + frame)
            self.frames += 1
        self._write(_LEAVE)


class LiveView:
    """Rich live view of one core. See the module docstring."""

    def __init__(self, core: EmulatorCore, port: str, *, rate_hz: float = 8.0,
                 console: Optional[Console] = None, out_fd: Optional[int] = None):
        self.core = core
        self.port = port
        self.period = 1.0 / rate_hz
        self.console = console or Console(file=io.StringIO(), width=MIN_SIZE[0], height=MIN_SIZE[1])
        self.out_fd = out_fd
        self._painter: Optional[_Painter] = None
        self._next: Optional[float] = None
        self._fd: Optional[int] = None
        self._saved: Any = None
        self._colors: Optional[str] = None
        self.message = ""

    # ------------------------------------------------------------------ lifecycle
    def start(self) -> None:
        if sys.stdin.isatty():
            self._fd = sys.stdin.fileno()
            self._saved = termios.tcgetattr(self._fd)
            tty.setcbreak(self._fd)
        if self.out_fd is None:
            self.out_fd = sys.__stdout__.fileno()
        self._colors = Console(file=io.StringIO(), force_terminal=True).color_system
        self._painter = _Painter(self.out_fd, self._frame)
        self._painter.start()
        self._next = 0.0

    def close(self) -> None:
        if self._painter is not None:
            self._painter.stop(timeout=1.0)  # a terminal that does not read is left as it is
            self._painter = None
        if self._fd is not None and self._saved is not None:
            try:
                termios.tcsetattr(self._fd, termios.TCSADRAIN, self._saved)
            except termios.error:
                pass
            self._fd = None

    @property
    def dropped(self) -> int:
        """Frames dropped because the terminal was not reading."""
        return self._painter.dropped if self._painter is not None else 0

    # ------------------------------------------------------------------ loop hooks
    def fileno(self) -> Optional[int]:
        """The keyboard descriptor (standard input in cbreak mode), if there is one."""
        return self._fd if self._fd is not None else (sys.stdin.fileno() if sys.stdin.isatty() else None)

    def next_refresh(self) -> Optional[float]:
        return self._next

    def refresh(self, now: float) -> None:
        self._next = now + self.period
        if self._painter is not None:
            self._painter.offer(self.snapshot())

    def on_input(self, server: Any, now: float) -> None:
        try:
            keys = os.read(self.fileno(), 64).decode("latin-1")  # type: ignore[arg-type]
        except OSError:
            return
        for k in keys:
            if k in FAULT_KEYS:
                code = FAULT_KEYS[k]
                server.inject_fault(code, f"key {k}")
                self.message = f"injected {code} ({FAULT_WORDS.get(code, code)})"
            elif k in "qQ":
                server.stop(0)
        self._next = now

    # ------------------------------------------------------------------ picture
    def _terminal_size(self) -> tuple[int, int]:
        if self.out_fd is not None:
            try:
                ts = os.get_terminal_size(self.out_fd)
                return ts.columns, ts.lines
            except OSError:
                pass
        return self.console.size.width, self.console.size.height

    def snapshot(self) -> Snapshot:
        w, h = self._terminal_size()
        size = (max(w, MIN_SIZE[0]), max(h, MIN_SIZE[1])) if w and h else MIN_SIZE
        history = tuple(self.core.history)[-max(size[1], 24):]
        return Snapshot(self.core.view(), history, self.message, size)

    def _frame(self, snap: Snapshot) -> bytes:
        w, h = snap.size
        console = Console(file=io.StringIO(), force_terminal=True, color_system=self._colors,
                          width=w, height=h, legacy_windows=False)
        with console.capture() as cap:
            console.print(self.render(snap), end="")
        lines = cap.get().split("\n")[:h]
        # each line placed by an explicit cursor position: right whatever the tty's output
        # processing (ONLCR or raw), and nothing ever scrolls
        return "".join(f"\x1b[{i};1H{line}" for i, line in enumerate(lines, 1)).encode("utf-8", "replace")

    def render(self, snap: Optional[Snapshot] = None) -> Layout:
        """The whole picture for ``snap`` (default: now, at the console's size)."""
        if snap is None:
            snap = Snapshot(self.core.view(), tuple(self.core.history), self.message,
                            (self.console.size.width, self.console.size.height))
        v = snap.view
        w, h = snap.size
        foot = self._footer(snap.message, w)
        foot_rows = len(foot.plain.split("\n"))
        body_rows = max(3, h - 1 - foot_rows)
        layout = Layout()
        layout.split_column(Layout(self._header(v), name="head", size=1),
                            Layout(name="body", size=body_rows),
                            Layout(foot, name="foot", size=foot_rows))
        traffic_rows = max(1, body_rows - 3)  # panel frame (2) and the table's header row
        layout["body"].split_row(Layout(self._traffic(snap.history, traffic_rows, w), name="traffic", ratio=3),
                                 Layout(self._state(v, body_rows - 2), name="state", ratio=1, minimum_size=34))
        return layout

    def _header(self, v: dict) -> Text:
        return Text.assemble(("helmcheck emulator", "bold reverse"), f"  port {self.port}  vehicle time ",
                             (_clock(v["v"]), "bold cyan"), f" (x{v['time_scale']:g})  profile ",
                             self.core.profile.name, no_wrap=True, overflow="ellipsis")

    def _footer(self, message: str, width: int) -> Text:
        t = Text("\n".join(legend_lines(width, message)), no_wrap=True, overflow="crop")
        t.highlight_regex(r"^keys:", "bold")
        if message:
            t.highlight_words([message], "bold red")
        return t

    def _traffic(self, history: tuple, rows: int, width: int) -> Panel:
        table = Table(expand=True, show_edge=False, pad_edge=False, box=None)
        table.add_column("t", justify="right", width=8, no_wrap=True)
        table.add_column("", width=1, no_wrap=True)
        table.add_column("sentence", ratio=1, overflow="ellipsis", no_wrap=True)
        table.add_column("verdict", width=max(17, (width - max(34, width // 4)) * 2 // 5),
                         overflow="ellipsis", no_wrap=True)
        for e in history[-rows:]:
            style = {"<": "cyan", "!": "magenta"}.get(e.direction, "")
            table.add_row(f"{e.t:.3f}", e.direction, Text(e.text, style=style),
                          Text(e.verdict, style=_verdict_style(e.verdict)))
        return Panel(table, title="serial traffic (> in, < out, ! note), newest last")

    def _state(self, v: dict, rows: int = 40) -> Panel:
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
        roomy = rows >= 26
        if roomy:
            g.add_row("", "")
        act = v["actuators"] or "8080808080"
        for i, name in enumerate(_FINS):
            byte = int(act[2 * i:2 * i + 2], 16) if len(act) >= 2 * i + 2 else 0x80
            bar = _bar(byte)
            g.add_row(name.capitalize(), Text(f"{byte:02X} {bar}"))
        if roomy:
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
