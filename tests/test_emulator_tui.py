"""``helmcheck emulate --tui`` on a real 80×24 pseudo-terminal held by the test.

The emulator runs in a subprocess whose standard streams are the slave side of a pty; the test
reads (and, on purpose, stops reading) the master side, like a terminal that is scrolled back
or stopped. Each frame the view writes is a whole screen from the home position, so the last
complete frame is the screen a user sees.
"""

from __future__ import annotations

import fcntl
import os
import re
import signal
import struct
import subprocess
import sys
import termios
import threading
import time

import pytest

from helmcheck.emulator.process import HelmClient
from helmcheck.emulator.tui import FAULT_KEYS, FAULT_WORDS, legend, legend_lines
from helmcheck.line.transport import open_link

ROWS, COLS = 24, 80
_CSI = re.compile(rb"\x1b\[[0-9;?]*[A-Za-z]")


class Terminal:
    """The master side of a pty: collects what the program writes; can stop reading."""

    def __init__(self, rows: int = ROWS, cols: int = COLS):
        self.master, self.slave = os.openpty()
        fcntl.ioctl(self.slave, termios.TIOCSWINSZ, struct.pack("HHHH", rows, cols, 0, 0))
        self.data = bytearray()
        self.reading = threading.Event()
        self.reading.set()
        self.closed = False
        self._lock = threading.Lock()
        self._t = threading.Thread(target=self._pump, daemon=True)
        self._t.start()

    def _pump(self) -> None:
        while not self.closed:
            self.reading.wait()
            try:
                chunk = os.read(self.master, 65536)
            except OSError:
                return
            if not chunk:
                return
            with self._lock:
                self.data += chunk

    def text(self) -> bytes:
        with self._lock:
            return bytes(self.data)

    def screen(self) -> list[str]:
        """The last complete frame, as plain text lines."""
        data = self.text()
        parts = data.split(b"\x1b[H")
        if len(parts) < 3:
            return []
        frame = parts[-2]  # the last one is maybe still being written
        rows = re.split(rb"\x1b\[\d+;1H", frame)[1:]  # each line is placed at its row
        return [_CSI.sub(b"", r).decode("utf-8", "replace") for r in rows]

    def wait_screen(self, predicate, timeout: float = 20.0) -> list[str]:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            lines = self.screen()
            if lines and predicate(lines):
                return lines
            time.sleep(0.05)
        raise AssertionError("screen never matched; last screen:\n" + "\n".join(self.screen()))

    def close(self) -> None:
        self.closed = True
        self.reading.set()
        for fd in (self.slave, self.master):
            try:
                os.close(fd)
            except OSError:
                pass


@pytest.fixture
def tui():
    term = Terminal()
    proc = subprocess.Popen([sys.executable, "-m", "helmcheck", "emulate", "--tui", "--time-scale", "20",
                             "--baud", "0"], stdin=term.slave, stdout=term.slave, stderr=term.slave,
                            start_new_session=True)
    try:
        deadline = time.monotonic() + 30
        port = None
        while time.monotonic() < deadline and port is None:
            m = re.search(rb"port: (\S+)\r?\n", term.text())
            port = m.group(1).decode() if m else None
            time.sleep(0.02)
        assert port, term.text()
        yield term, proc, port
    finally:
        term.reading.set()
        if proc.poll() is None:
            proc.send_signal(signal.SIGTERM)
            try:
                proc.wait(10)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        term.close()


def test_newest_traffic_refusals_and_legend_at_80x24(tui):
    term, proc, port = tui
    client = HelmClient(open_link(port, role="client", baud=19200))
    try:
        for _ in range(30):  # more traffic than the screen has rows
            client.request("OSD,S", 8)
        ack = client.ack("OMS,400,2,20,0,5", 9)  # heading out of range: refused, err 20
        assert (ack.status, ack.err) == (1, 20)
    finally:
        client.link.close()
    lines = term.wait_screen(lambda ls: any("$ACK,9,1" in ln for ln in ls))
    assert len(lines) == ROWS and all(len(ln) <= COLS for ln in lines), lines
    traffic = [ln for ln in lines if re.search(r"\d\.\d{3}\s+[<>!]", ln)]
    assert "$ACK,9,1" in traffic[-1] and "refused (err 20)" in traffic[-1], lines  # the newest, last
    oms = next(ln for ln in traffic if "$OMS,4" in ln)
    assert "refused (err 20)" in oms and " ok " not in oms, oms
    screen = "\n".join(lines)
    assert "1 over-pitch (Sop)" in screen and "= Iridium stop (Sti)" in screen and "q quit" in screen


def test_a_terminal_that_stops_reading_never_stalls_the_emulator(tui):
    term, proc, port = tui
    term.wait_screen(lambda ls: any("controller" in ln for ln in ls))
    term.reading.clear()  # the terminal stops reading: the pty's buffer fills up
    client = HelmClient(open_link(port, role="client", baud=19200))
    try:
        t0 = time.monotonic()
        worst = 0.0
        while time.monotonic() - t0 < 6.0:  # ~48 frames offered while nobody reads
            t = time.monotonic()
            assert client.ack("OSD,S", 8, timeout=2.0).status == 0
            worst = max(worst, time.monotonic() - t)
        assert worst < 1.0, worst  # within the ACK window (RH-ACK-2); a blocked write would never answer
        term.reading.set()  # reading again: the picture comes back, up to date
        client.ack("OMS,400,2,20,0,5", 9)
        term.wait_screen(lambda ls: any("$ACK,9,1" in ln for ln in ls))
    finally:
        client.link.close()
    proc.send_signal(signal.SIGTERM)
    assert proc.wait(10) == 0


def test_legend_names_every_key_in_words_and_packs_whole_entries():
    text = legend()
    for key, code in FAULT_KEYS.items():
        assert f"{key} {FAULT_WORDS[code]} ({code})" in text
    for width in (80, 100, 132):
        lines = legend_lines(width)
        assert all(len(ln) <= width for ln in lines)
        assert "  ".join(lines) == text
