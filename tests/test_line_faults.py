"""The line-fault relay (``helmcheck relay``, :mod:`helmcheck.line.impair`, :func:`impaired_line`).

Two kinds of test: the sans-IO schedule driven with explicit times (properties: what comes out,
when, which notes; the rates against binomial bounds; same seed, same bytes), and the relay
itself on real ptys, timed by the clock (pacing measured, a line held, a stall, a cut that
re-creates the device under its link). RH-FRM-9: 8N1, 10 bits a byte. Longer runs are behind
``HELMCHECK_LINE_SOAK=1``.
"""

from __future__ import annotations

import os
import select
import termios
import time
import tty

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from helmcheck.grammar.faultnote import read_fault_note
from helmcheck.grammar.wirelog import FROM_VEHICLE, TO_VEHICLE, transmit_time
from helmcheck.line.faultline import impaired_line
from helmcheck.line.impair import BYTES, NOTE, ImpairedLine
from helmcheck.line.impair_spec import parse_impairment
from helmcheck.line.pty_link import PtyLink

SOAK = os.environ.get("HELMCHECK_LINE_SOAK") == "1"


# ============================================================================ helpers
def run_schedule(faults, pushes, start: float = 0.0, until: float | None = None):
    """Drive an :class:`ImpairedLine` with ``pushes`` [(t, direction, data)], asking it at every
    push and every time it says something is due; every action, in order."""
    line = ImpairedLine(parse_impairment(faults) if isinstance(faults, str) else faults, start)
    out = []
    pushes = sorted(pushes, key=lambda p: p[0])
    i = 0
    while True:
        nxt = line.next_due()
        push_t = pushes[i][0] if i < len(pushes) else None
        if push_t is not None and (nxt is None or push_t <= nxt):
            out += line.due(push_t)
            line.push(*pushes[i])
            i += 1
            continue
        if nxt is None or (until is not None and nxt > until):
            break
        out += line.due(nxt)
    return line, out


def delivered(actions, direction: str) -> bytes:
    return b"".join(a.data for a in actions if a.kind == BYTES and a.direction == direction)


def byte_times(actions, direction: str) -> list[float]:
    """Each delivered byte's time (a joined action's bytes all at its time)."""
    return [a.t for a in actions if a.kind == BYTES and a.direction == direction for _ in a.data]


def open_peer(path: str) -> int:
    """A port opened as a backseat or a vehicle opens it (raw, non-blocking)."""
    fd = os.open(path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
    tty.setraw(fd, termios.TCSANOW)
    return fd


def read_for(fd: int, n: int, timeout: float) -> list[tuple[float, bytes]]:
    """Chunks read from ``fd`` with their arrival times, until ``n`` bytes or ``timeout``."""
    got: list[tuple[float, bytes]] = []
    total = 0
    deadline = time.monotonic() + timeout
    while total < n:
        left = deadline - time.monotonic()
        if left <= 0:
            break
        if select.select([fd], [], [], left)[0]:
            try:
                data = os.read(fd, 65536)
            except BlockingIOError:
                continue
            except OSError:
                break
            got.append((time.monotonic(), data))
            total += len(data)
    return got


def link_read(link: PtyLink, n: int, timeout: float) -> list[tuple[float, bytes]]:
    got: list[tuple[float, bytes]] = []
    total = 0
    deadline = time.monotonic() + timeout
    while total < n and time.monotonic() < deadline:
        link.wait_readable(max(0.0, deadline - time.monotonic()))
        for ev in link.poll():
            if ev.data:
                got.append((time.monotonic(), ev.data))
                total += len(ev.data)
    return got


SENTENCE = b"$OSI,8080,N,,Normal,123.4,45.12345,-81.123456,0.0,1.2,32.1,0*5C\r\n"
lines = st.lists(st.binary(min_size=0, max_size=40).map(lambda b: b.replace(b"\n", b"") + b"\r\n"),
                 min_size=1, max_size=6)


# ============================================================================ pacing and holding a line (sans-IO)
@settings(max_examples=60)
@given(chunks=st.lists(st.tuples(st.floats(0, 0.05), st.binary(min_size=1, max_size=30)), min_size=1, max_size=12),
       baud=st.sampled_from([4800, 9600, 19200, 115200]))
def test_pacing_delivers_every_byte_in_order_one_byte_time_apart_never_early(chunks, baud):
    """baud=N: each byte takes 10 bit times (8N1, RH-FRM-9), starts when the one before it has
    ended and not before it was sent; nothing is lost, added or reordered."""
    pushes, t = [], 1.0
    for gap, data in chunks:
        t += gap
        pushes.append((t, TO_VEHICLE, data))
    _, out = run_schedule(f"baud={baud}", pushes, start=1.0)
    sent = b"".join(p[2] for p in pushes)
    assert delivered(out, TO_VEHICLE) == sent
    times = byte_times(out, TO_VEHICLE)
    bt = transmit_time(1, baud)
    assert all(b - a >= bt * (1 - 1e-6) for a, b in zip(times, times[1:]))
    sent_at = [p[0] for p in pushes for _ in p[2]]
    assert all(d >= s + bt * (1 - 1e-6) for d, s in zip(times, sent_at))
    # back to back when the sender is ahead of the line: the last byte is due exactly then
    free = 0.0
    for s in sent_at:
        free = max(free, s) + bt
    assert times[-1] == pytest.approx(free, abs=1e-6)


@settings(max_examples=60)
@given(msgs=lines, gaps=st.lists(st.floats(0.0, 1.0), min_size=6, max_size=6))
def test_line_delay_holds_every_line_until_its_last_byte_plus_the_delay_in_order(msgs, gaps):
    """<line-delay=0.6: a line from the vehicle leaves 0.6 s after its last byte came, paced;
    lines keep their order; what goes to the vehicle is only paced."""
    pushes, t = [], 0.0
    for m, g in zip(msgs, gaps):
        t += g
        half = len(m) // 2
        pushes += [(t, FROM_VEHICLE, m[:half]), (t + 0.01, FROM_VEHICLE, m[half:])]
        t += 0.01
    pushes.append((0.5, TO_VEHICLE, b"$OSD,S*27\r\n"))
    _, out = run_schedule("baud=19200,<line-delay=0.6", [p for p in pushes if p[2]])
    assert delivered(out, FROM_VEHICLE) == b"".join(msgs)
    times = byte_times(out, FROM_VEHICLE)
    bt = transmit_time(1, 19200)
    k = 0
    for (t_last, m) in zip([p[0] for p in pushes if p[1] == FROM_VEHICLE][1::2], msgs):
        first = times[k]
        assert first >= t_last + 0.6 + bt * (1 - 1e-6)  # held from its last byte, then its first byte's frame
        k += len(m)
    assert times == sorted(times)
    to = byte_times(out, TO_VEHICLE)
    assert to[0] == pytest.approx(0.5 + bt) and delivered(out, TO_VEHICLE) == b"$OSD,S*27\r\n"
    notes = [read_fault_note(a.text) for a in out if a.kind == NOTE]
    assert {(n.direction, n.kind) for n in notes} == {(TO_VEHICLE, "timing"), (FROM_VEHICLE, "timing")}
    assert "held 0.6 s" in next(n.detail for n in notes if n.direction == FROM_VEHICLE)


def test_a_line_without_lf_is_held_from_when_the_sender_went_quiet():
    """A run with no LF is a line once the sender has been quiet for line-delay (at least 0.1 s)."""
    _, out = run_schedule("<line-delay=0.3", [(1.0, FROM_VEHICLE, b"garbage"), (1.2, FROM_VEHICLE, b"more")])
    assert [(round(a.t, 6), a.data) for a in out if a.kind == BYTES] == [(1.5, b"garbagemore")]


# ============================================================================ pacing and holding a line (real ptys)
@pytest.mark.parametrize("process", [False, True], ids=["thread", "process"])
def test_relay_paces_19200_both_ways_and_holds_each_vehicle_line_0_6_s_measured(process, tmp_path):
    """The first use: a vehicle's pty behind 19200 baud both ways, every line from the vehicle
    held 0.6 s after its last byte. Measured on real ptys: the byte rate is the baud's (never
    faster; within 5 % over a second), and a line arrives 0.6 s and its transmit time after the
    vehicle wrote it."""
    vehicle = PtyLink(19200)  # the vehicle: its pty's master; the relay opens the path, as a tester would
    try:
        with impaired_line(vehicle.name, "baud=19200,<line-delay=0.6", link=tmp_path / "vehicle",
                           wire_log=tmp_path / "relay.log", process=process) as line:
            assert os.path.realpath(line.port).startswith("/dev/pts/")
            fd = open_peer(line.port)
            try:
                bt = transmit_time(1, 19200)
                n = 1920  # a second of line
                data = bytes(0x41 + i % 26 for i in range(n))
                t0 = time.monotonic()
                os.write(fd, data)
                got = link_read(vehicle, n, 5.0)
                assert b"".join(d for _, d in got) == data
                span = got[-1][0] - t0
                assert span >= n * bt * (1 - 1e-3)  # never faster than the line
                assert span <= n * bt * 1.05, span  # and not much slower
                # a line from the vehicle: held 0.6 s after its last byte, then paced
                t1 = time.monotonic()
                vehicle.write_all(SENTENCE)
                back = read_for(fd, len(SENTENCE), 5.0)
                assert b"".join(d for _, d in back) == SENTENCE
                first, last = back[0][0] - t1, back[-1][0] - t1
                assert first >= 0.6 + bt * (1 - 1e-3)
                assert last >= 0.6 + len(SENTENCE) * bt * (1 - 1e-3)
                assert last <= 0.6 + len(SENTENCE) * bt + 0.1, last
            finally:
                os.close(fd)
            kinds = {(f.direction, f.kind) for _, f in line.fault_notes()}
            assert kinds == {(TO_VEHICLE, "timing"), (FROM_VEHICLE, "timing")}
        assert not os.path.lexists(tmp_path / "vehicle")  # the link goes with the relay
        log = (tmp_path / "relay.log").read_text()
        assert "< " + SENTENCE.decode()[:-2] in log  # what the backseat's side got, as one line
    finally:
        vehicle.close()
