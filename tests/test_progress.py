"""Progress displays: on a terminal a bar that stays readable at 80 columns; off a terminal,
lines at the pace a log can take; the exploration shown by what its budget allows.

The terminal is a real pty with its window size set (``TIOCSWINSZ``), read back from the master
side; the plain displays write to a pipe-like stream (not a terminal) and get a clock that the
test moves, so "every 10 s" is checked without waiting ten seconds.
"""

from __future__ import annotations

import fcntl
import io
import os
import re
import struct
import termios
import time

import pytest
from hypothesis import given, strategies as st

from helmcheck.certify.backseat.progress import BAR_WIDTH as BS_BAR, PLAIN_EVERY_S as BS_EVERY, Progress as BSProgress
from helmcheck.certify.vehicle.progress import BAR_WIDTH, PLAIN_EVERY_S, Progress, budget_text, explored_text
from helmcheck.monitor.view import STATUS_EVERY_S, StatusLines

BAR_CHARS = "━╸╺"


class Clock:
    def __init__(self):
        self.t = 1000.0

    def __call__(self) -> float:
        return self.t


class _Terminal:
    """A pty of *columns* columns: the slave as a text stream, the master read back."""

    def __init__(self, columns: int):
        self.master, slave = os.openpty()
        fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, columns, 0, 0))
        self.stream = os.fdopen(slave, "w", buffering=1, encoding="utf-8")
        os.set_blocking(self.master, False)

    def lines(self) -> list[str]:
        """The distinct visible lines drawn so far (escape sequences removed)."""
        self.stream.flush()
        time.sleep(0.05)
        data = b""
        try:
            while chunk := os.read(self.master, 65536):
                data += chunk
        except BlockingIOError:
            pass
        frames = re.split(r"\r|\n|\x1b\[2K|\x1b\[1A", data.decode("utf-8", "replace"))
        return [x for x in (re.sub(r"\x1b\[[0-9;?]*[a-zA-Z]", "", f) for f in frames) if x.strip()]

    def close(self):
        self.stream.close()
        os.close(self.master)


def _bar(line: str) -> str:
    m = re.search(f"[{BAR_CHARS}]+", line)
    assert m, line
    return m.group(0)


@pytest.mark.parametrize("columns", [80, 120])
def test_certify_vehicles_bar_keeps_its_width_at_80_columns(columns):
    """At 80 columns the bar is 20 characters (it was 4): the text after it is cut instead."""
    term = _Terminal(columns)
    try:
        p = Progress(stream=term.stream)
        p.start(65)
        p.step("V-25 RH-SRV-1", "pass")
        p.explore(14, 12.0, 30.0, 480.0, 1500.0)
        time.sleep(0.3)
        p.stop()
        drawn = [ln for ln in term.lines() if ln.startswith("certify vehicle")]
    finally:
        term.close()
    assert drawn
    for line in drawn:
        assert len(line.rstrip()) <= columns, line
        assert len(_bar(line)) == BAR_WIDTH, line
    assert any("exploring: 40 % of budget" in ln for ln in drawn), drawn


def test_certify_backseats_bar_keeps_its_width_at_80_columns():
    term = _Terminal(80)
    try:
        p = BSProgress(stream=term.stream)
        p.start(60.0)
        p.update(12.0, "reject", {"RH-BS-2": 3, "RH-BS-4": 1, "RH-BS-5": 0, "RH-BS-7": 12})
        time.sleep(0.3)
        p.stop()
        drawn = [ln for ln in term.lines() if "━" in ln]
    finally:
        term.close()
    assert drawn
    for line in drawn:
        assert len(line.rstrip()) <= 80 and len(_bar(line)) == BS_BAR, line


def test_certify_backseat_off_a_terminal_says_each_scenario_and_every_10_s():
    """Piped: a line when the run starts, one per scenario, and one at least every 10 s — not
    nothing for a minute."""
    out, clock = io.StringIO(), Clock()
    p = BSProgress(stream=out, clock=clock)
    p.start(60.0)
    for second in range(60):
        clock.t += 1.0
        p.update(float(second), "nominal" if second < 24 else "reject", {"RH-BS-8": 1 if second > 40 else 0})
    p.stop()
    lines = out.getvalue().splitlines()
    assert lines[0] == "helmcheck certify backseat: the backseat connected; the judged run takes 60.0 s"
    assert sum("scenario nominal starts" in ln for ln in lines) == 1
    assert sum("scenario reject starts" in ln for ln in lines) == 1
    times = [float(m.group(1)) for ln in lines if (m := re.search(r": (\d+\.\d) of 60\.0 s", ln))]
    assert times[0] == 0.0 and all(b - a <= BS_EVERY for a, b in zip(times, times[1:])), times
    assert len(lines) <= 1 + 60 / BS_EVERY + 2, lines
    assert "offences so far: RH-BS-8 ×1" in lines[-1]


def test_certify_backseat_shows_nothing_when_turned_off():
    out = io.StringIO()
    p = BSProgress(enabled=False, stream=out)
    p.start(60.0)
    p.update(1.0, "nominal", {})
    p.stop()
    assert out.getvalue() == ""


def test_the_exploration_off_a_terminal_is_a_line_at_its_start_then_every_10_s():
    out, clock = io.StringIO(), Clock()
    p = Progress(stream=out, clock=clock)
    p.start(3)
    for n in range(1, 40):
        clock.t += 1.0
        p.explore(n, float(n), 30.0, 20.0 * n, 1500.0, steps=12 * n)
    lines = [ln for ln in out.getvalue().splitlines() if ln.startswith("exploration:")]
    assert len(lines) == 1 + (39 - 1) // int(PLAIN_EVERY_S)
    assert lines[0] == "exploration: 1 sequence and 12 steps run so far, 3 % of the budget (1 of 30 s wall)"


def test_the_exploration_says_what_it_did_when_it_ends():
    """Issue 43: a short exploration (all its examples run long before its budget) must not read
    as skipped: its last line says the sequences and steps it ran, in how long, and its budget."""
    stats = {"examples": 10, "ran": 10, "steps": 214, "failures": 0, "budget_s": 30.0, "budget_vehicle_s": 1500.0,
             "budget_spent": False, "wall_s": 6.846, "vehicle_s": 274.5, "outcome": "pass"}
    out = io.StringIO()
    p = Progress(stream=out)
    p.start(1)
    p.step("exploration", explored_text(stats))
    assert out.getvalue().splitlines()[-1] == (
        "[1/1] exploration 10 sequences and 214 steps in 6.8 s; all 10 examples asked, within its budget of "
        "30 s wall or 1500 s vehicle time")
    spent = dict(stats, ran=120, steps=2400, failures=1, budget_spent=True, wall_s=30.2, examples=400)
    assert explored_text(spent) == ("120 sequences and 2400 steps in 30.2 s; its budget (30 s wall or 1500 s "
                                    "vehicle time, whichever ends first) spent before the 400 examples asked; "
                                    "1 failing sequence")
    assert explored_text({"examples": 0, "ran": 0, "outcome": "not run (no $OMSTOP claimed)"}) == \
        "not run (no $OMSTOP claimed)"


@given(ran=st.integers(0, 10_000), wall=st.floats(0, 100), wall_budget=st.floats(1, 1000),
       veh=st.floats(0, 5000), veh_budget=st.floats(1, 5000))
def test_the_exploration_is_shown_by_its_budget_never_by_the_examples_asked_for(ran, wall, wall_budget, veh,
                                                                                veh_budget):
    """The share shown is the clock further on (capped at 100 %), and no "n/400" promise."""
    used, text = budget_text(ran, wall, wall_budget, veh, veh_budget)
    assert used == pytest.approx(min(1.0, max(wall / wall_budget, veh / veh_budget)))
    assert f"{used * 100:.0f} % of the budget" in text and f"{ran} sequence" in text
    assert "/" not in text


def test_monitor_off_a_terminal_says_it_is_alive_every_10_s():
    out = io.StringIO()
    v = StatusLines("helmcheck monitor", stream=out)
    for tenth in range(0, 355):
        v.refresh({"records": tenth, "mode": "A"}, {"bytes": {">": 10 * tenth, "<": 20 * tenth}}, tenth / 10)
    lines = out.getvalue().splitlines()
    assert len(lines) == int(35.4 // STATUS_EVERY_S)
    assert lines[0].startswith("helmcheck monitor: 10 s, 1000 bytes to the vehicle, 2000 from it, 100 records judged, "
                               "vehicle mode A, 0 finding(s) so far")
