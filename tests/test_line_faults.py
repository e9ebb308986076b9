"""The line-fault relay (``helmcheck relay``, :mod:`helmcheck.line.impair`, :func:`impaired_line`).

Two kinds of test: the sans-IO schedule driven with explicit times (properties: what comes out,
when, which notes; the rates against binomial bounds; same seed, same bytes), and the relay
itself on real ptys, timed by the clock (pacing measured, a line held, a stall, a cut that
re-creates the device under its link). RH-FRM-9: 8N1, 10 bits a byte. Longer runs are behind
``HELMCHECK_LINE_SOAK=1``.
"""

from __future__ import annotations

import math
import os
import random
import select
import signal
import socket
import subprocess
import sys
import termios
import threading
import time
import tty
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from helmcheck.grammar.faultnote import read_fault_note
from helmcheck.grammar.wirelog import FROM_VEHICLE, TO_VEHICLE, transmit_time
from helmcheck.line.faultline import impaired_line
from helmcheck.line.faultrelay import FaultRelay
from helmcheck.line.impair import BYTES, NOTE, ImpairedLine
from helmcheck.line.impair_spec import ITEMS, ImpairError, Window, parse_impairment
from helmcheck.line.pty_link import PtyLink
from helmcheck.line.uart import reframe

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


def write_all(fd: int, data: bytes, chunk: int = 4096) -> None:
    """Write every byte to a non-blocking descriptor, ``chunk`` bytes at a time at most."""
    view = memoryview(data)
    while view:
        select.select([], [fd], [], 1.0)
        try:
            view = view[os.write(fd, view[:chunk]):]
        except BlockingIOError:
            pass


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


# ============================================================================ the line's faults (sans-IO)
def binomial_bounds(n: int, p: float, alpha: float = 1e-6) -> tuple[int, int]:
    """The smallest and largest counts a Binomial(n, p) takes but with probability ``alpha`` on
    each side (exact, from the log-pmf): a count outside is a wrong rate, not bad luck."""
    lq, l1q = math.log(p), math.log1p(-p)

    def logpmf(k: int) -> float:
        return math.lgamma(n + 1) - math.lgamma(k + 1) - math.lgamma(n - k + 1) + k * lq + (n - k) * l1q

    mean, sd = n * p, math.sqrt(n * p * (1 - p))
    ks = range(max(0, int(mean - 12 * sd) - 5), min(n, int(mean + 12 * sd) + 5) + 1)
    pmf = [math.exp(logpmf(k)) for k in ks]
    acc, lo = 0.0, ks[0]
    for k, q in zip(ks, pmf):
        if acc + q > alpha:
            lo = k
            break
        acc += q
    acc, hi = 0.0, ks[-1]
    for k, q in zip(reversed(ks), reversed(pmf)):
        if acc + q > alpha:
            hi = k
            break
        acc += q
    return lo, hi


def explain(sent: bytes, notes: list[str]) -> bytes:
    """What the far side must get when the notes say all the line did (drops, flips, noise bursts
    of at most 32 bytes, quoted in full): the test that every fault is a note."""
    from helmcheck.grammar.wirelog import unescape

    drops, flips, noise = set(), {}, {}
    for text in notes:
        f = read_fault_note(text)
        if f is None or f.kind not in ("drop", "flip", "noise"):
            continue
        if f.kind == "drop":
            drops.add(int(f.detail.split()[1]))
        elif f.kind == "flip":
            words = f.detail.split()
            flips[int(words[1])] = int(f.detail.split("-> ")[1].split()[0], 16)
        else:
            head, _, quoted = f.detail.partition(": ")
            noise[int(head.split()[-1])] = unescape(quoted)
    out = bytearray()
    for i, b in enumerate(sent):
        out += noise.get(i, b"")
        if i not in drops:
            out.append(flips.get(i, b))
    return bytes(out)


def notes_of(actions, direction=None) -> list[str]:
    return [a.text for a in actions if a.kind == NOTE and (direction is None or a.direction == direction)]


RATE_N = 2_000_000 if SOAK else 120_000


@pytest.mark.parametrize("seed", [1, 2])
def test_drop_flip_and_noise_rates_are_within_binomial_bounds_and_every_fault_is_a_note(seed):
    """drop=P per byte, flip=P per data bit, noise=P per byte: on a long run each count lies
    within the exact binomial bounds (1e-6 each side); and the notes alone explain every byte
    the far side got (the bytes sent, less the noted drops, with the noted flips and bursts)."""
    p = 2e-3
    rng = random.Random(seed)
    sent = bytes(rng.getrandbits(8) for _ in range(RATE_N))
    line, out = run_schedule(f"drop={p},flip={p},noise={p},noise-len=1-6,seed={seed}",
                             [(0.0, TO_VEHICLE, sent[:RATE_N // 2]), (0.5, TO_VEHICLE, sent[RATE_N // 2:])])
    s = line.stats[TO_VEHICLE]
    lo, hi = binomial_bounds(RATE_N, p)
    assert lo <= s["dropped"] <= hi, (s, lo, hi)
    assert lo <= s["noise_bursts"] <= hi, (s, lo, hi)
    blo, bhi = binomial_bounds(8 * RATE_N, p)
    assert blo <= s["flipped_bits"] <= bhi, (s, blo, bhi)
    notes = notes_of(out, TO_VEHICLE)
    got = delivered(out, TO_VEHICLE)
    assert got == explain(sent, notes)
    assert len(got) == RATE_N - s["dropped"] + s["noise_bytes"]
    kinds = [read_fault_note(n).kind for n in notes]
    assert kinds.count("drop") == s["dropped"] and kinds.count("noise") == s["noise_bursts"]
    assert sum(len(read_fault_note(n).detail.split(":")[0].split()[-1].split(",")) for n in notes
               if read_fault_note(n).kind == "flip") == s["flipped_bits"]
    assert delivered(out, FROM_VEHICLE) == b""


def test_a_rate_of_zero_touches_nothing_and_one_touches_everything():
    sent = bytes(range(256)) * 4
    _, out = run_schedule("drop=0,flip=0,noise=0", [(0.0, TO_VEHICLE, sent)])
    assert delivered(out, TO_VEHICLE) == sent and not notes_of(out, TO_VEHICLE)
    _, out = run_schedule("flip=1", [(0.0, TO_VEHICLE, sent)])
    assert delivered(out, TO_VEHICLE) == bytes(b ^ 0xFF for b in sent)
    _, out = run_schedule(">drop=1", [(0.0, TO_VEHICLE, sent), (0.0, FROM_VEHICLE, sent)])
    assert delivered(out, TO_VEHICLE) == b"" and delivered(out, FROM_VEHICLE) == sent
    assert len(notes_of(out, TO_VEHICLE)) == len(sent)


@settings(max_examples=25)
@given(data=st.data(), seed=st.integers(0, 2 ** 32), paced=st.booleans())
def test_same_seed_same_bytes_whatever_the_chunks_and_their_times(data, seed, paced):
    """The faults hit the same bytes however the sender chunked them and whenever it sent them:
    two runs of the same bytes with the same seed give the same bytes out, and the same notes
    but for their times."""
    rng = random.Random(seed)
    sent = bytes(rng.getrandbits(8) for _ in range(2000))
    spec = ("baud=115200," if paced else "") + f"drop=5e-3,flip=1e-3,noise=5e-3,seed={seed % 1000}"

    def chunked(cuts: list[int], gaps: list[float]):
        pos = sorted(set([0, len(sent), *cuts]))
        t, pushes = 0.0, []
        for (a, b), g in zip(zip(pos, pos[1:]), gaps + [0.0] * len(pos)):
            pushes.append((t, FROM_VEHICLE, sent[a:b]))
            t += g
        return pushes

    one = data.draw(st.lists(st.integers(1, 1999), max_size=20))
    gaps = data.draw(st.lists(st.floats(0, 0.2), max_size=20))
    _, a = run_schedule(spec, chunked(one, gaps))
    _, b = run_schedule(spec, [(0.0, FROM_VEHICLE, sent)])
    assert delivered(a, FROM_VEHICLE) == delivered(b, FROM_VEHICLE)
    strip = [n.split(": ", 1)[1] for n in notes_of(a)]
    assert strip == [n.split(": ", 1)[1] for n in notes_of(b)]
    _, c = run_schedule(spec.replace(f"seed={seed % 1000}", f"seed={seed % 1000 + 1}"), [(0.0, FROM_VEHICLE, sent)])
    assert delivered(c, FROM_VEHICLE) != delivered(b, FROM_VEHICLE)  # another seed, other faults


# ============================================================================ stall and cut (sans-IO)
@settings(max_examples=50)
@given(pushes=st.lists(st.tuples(st.floats(0, 4), st.binary(min_size=1, max_size=20)), min_size=1, max_size=15),
       at=st.floats(0.5, 2), length=st.floats(0.1, 1.5), baud=st.sampled_from([0, 9600, 115200]))
def test_a_stall_lets_nothing_through_its_window_then_delivers_everything(pushes, at, length, baud):
    """stall=T@X: no byte is on the line from X to X+T (a paced byte's frame neither ends nor
    starts in it); every byte is delivered, in order; the notes say when it began and ended
    and how many bytes it held."""
    spec = (f"baud={baud}," if baud else "") + f"stall={length}s@{at}"
    timed = [(t, TO_VEHICLE, d) for t, d in pushes]
    line, out = run_schedule(spec, timed)
    sent = b"".join(d for _, _, d in sorted(timed, key=lambda p: p[0]))
    assert delivered(out, TO_VEHICLE) == sent
    bt = transmit_time(1, baud)
    for d in byte_times(out, TO_VEHICLE):
        start = d - bt
        assert not (start < at + length - 1e-9 and d > at + 1e-9) if baud else not (at <= d < at + length)
    stall = [read_fault_note(n) for n in notes_of(out, TO_VEHICLE) if read_fault_note(n).kind == "stall"]
    assert len(stall) == 2 and stall[0].detail.endswith("nothing passes")
    assert f"{line.stats[TO_VEHICLE]['stalled']} bytes held" in stall[1].detail
    held = [t for t, _, d in timed for _ in d]
    assert line.stats[TO_VEHICLE]["stalled"] >= sum(1 for t in held if at <= t < at + length)


def test_a_cut_loses_what_is_sent_in_it_both_ways_unplugs_and_plugs_back():
    """cut=T@X: what is on the line from X to X+T is lost both ways (counted in the closing
    note); the port is unplugged at X and plugged back at X+T; before and after, bytes pass."""
    pushes = [(0.5, TO_VEHICLE, b"before\r\n"), (1.2, TO_VEHICLE, b"lost>\r\n"), (1.3, FROM_VEHICLE, b"lost<<\r\n"),
              (2.5, FROM_VEHICLE, b"after\r\n")]
    line, out = run_schedule("baud=19200,cut=1s@1", pushes)
    assert delivered(out, TO_VEHICLE) == b"before\r\n" and delivered(out, FROM_VEHICLE) == b"after\r\n"
    kinds = [(round(a.t, 6), a.kind) for a in out if a.kind in ("unplug", "replug")]
    assert kinds == [(1.0, "unplug"), (2.0, "replug")]
    cut = [read_fault_note(n) for n in notes_of(out) if read_fault_note(n).kind == "cut"]
    assert [c.direction for c in cut] == ["<>", "<>"]
    assert cut[1].detail == "over after 1 s: lost 7 bytes >, 8 bytes <"
    assert line.stats[TO_VEHICLE]["cut"] == 7 and line.stats[FROM_VEHICLE]["cut"] == 8


# ============================================================================ a receiver at another baud
def test_uart_hand_worked_frames_at_twice_the_rate():
    """9600 read at 19200, worked by hand: 0xFF's start bit spans two receiver bits, so bit 0
    reads 0 and bits 1-7 read the sender's bits 0-3 twice: 0xFE, framed. 0x00's nine low
    sender bits fill a whole receiver frame (0x00, no stop bit: a framing error) and begin the
    next, which ends on the sender's stop bit: 0x80."""
    assert [(r.byte, r.framed) for r in reframe(b"\xff", 9600, 19200)] == [(0xFE, True)]
    assert [(r.byte, r.framed) for r in reframe(b"\x00", 9600, 19200)] == [(0x00, False), (0x80, True)]


@settings(max_examples=80)
@given(data=st.binary(min_size=1, max_size=60), gaps=st.lists(st.integers(0, 30), max_size=60),
       baud=st.sampled_from([300, 4800, 19200, 115200, 1_000_000]))
def test_uart_at_the_same_rate_reads_every_byte_as_sent(data, gaps, baud):
    got = reframe(data, baud, baud, gaps)
    assert bytes(r.byte for r in got) == data and all(r.framed for r in got)


def test_rx_baud_delivers_what_a_receiver_at_that_rate_reads():
    """baud=115200,rx-baud=19200: the far side gets the re-sampled bit stream (uart.reframe of
    the same bytes), when the receiver has read each byte; one note says every byte is re-framed."""
    line, out = run_schedule("baud=115200,rx-baud=19200", [(1.0, FROM_VEHICLE, SENTENCE * 3)])
    want = reframe(SENTENCE * 3, 115200, 19200)
    assert delivered(out, FROM_VEHICLE) == bytes(r.byte for r in want)
    assert line.stats[FROM_VEHICLE]["framing_errors"] == sum(not r.framed for r in want) > 0
    notes = [read_fault_note(n) for n in notes_of(out, FROM_VEHICLE)]
    assert [n.kind for n in notes] == ["timing", "reframe"]
    assert delivered(out, FROM_VEHICLE) != SENTENCE * 3


# ============================================================================ the --impair text
@pytest.mark.parametrize("text, says", [
    ("flp=1e-4", "'flp=1e-4': unknown key 'flp'"),
    ("flip=2", "'flip=2': a rate is a probability from 0 to 1"),
    ("drop", "'drop': not KEY=VALUE"),
    ("cut=5s", "'cut=5s': want T@X"),
    ("cut=0s@4", "'cut=0s@4': the length '0s' is not above zero"),
    (">cut=5s@60", "'>cut=5s@60': cut is the whole line's"),
    ("baud=19200,baud=9600", "'baud=9600': baud given twice for both directions"),
    ("rx-baud=19200", "'rx-baud=19200' for >: needs baud=N too"),
    ("line-delay=soon", "'line-delay=soon': 'soon' is not a time"),
    ("delay=nan", "'delay=nan'"),
    ("flip=1e-4,,drop=1e-4", "an empty item"),
    ("noise-len=9-3", "'noise-len=9-3': want 1 <= A <= B <= 4096"),
    ("baud=0", "'baud=0': a baud rate is a whole number from 1"),
])
def test_a_bad_impair_item_is_named_on_one_line(text, says):
    with pytest.raises(ImpairError) as e:
        parse_impairment(text)
    assert str(e.value).startswith(says) and "\n" not in str(e.value)


def test_impair_text_per_direction_and_windows():
    f = parse_impairment("baud=19200,<line-delay=600ms,flip=1e-5,>flip=1e-3,stall=2s@10,<stall=1@20,cut=5s@60,"
                         "cut=1s@90,seed=7")
    assert f.to_vehicle.baud == f.from_vehicle.baud == 19200
    assert f.from_vehicle.line_delay == 0.6 and f.to_vehicle.line_delay == 0
    assert f.to_vehicle.flip == 1e-3 and f.from_vehicle.flip == 1e-5  # the prefixed one wins, whatever the order
    assert f.to_vehicle.stalls == (Window(10, 2),) and f.from_vehicle.stalls == (Window(10, 2), Window(20, 1))
    assert f.cuts == (Window(60, 5), Window(90, 1)) and f.seed == 7
    assert parse_impairment("").clean and parse_impairment("seed=3", seed=9).seed == 9


# ============================================================================ the relay on real ports
def test_relay_stall_holds_everything_then_delivers_it_after_t():
    """stall=0.6s@0.4 on real ptys: a line sent before the stall arrives at once; one sent in it
    arrives only once the stall is over, whole."""
    vehicle = PtyLink(19200)
    try:
        with FaultRelay("pty", vehicle.name, "baud=115200,stall=0.6s@0.4", realtime=False) as relay:
            fd = open_peer(relay.port)
            try:
                t0 = relay.t0
                os.write(fd, b"$OSD,S*27\r\n")
                early = link_read(vehicle, 11, 1.0)
                assert b"".join(d for _, d in early) == b"$OSD,S*27\r\n" and early[-1][0] - t0 < 0.3
                time.sleep(max(0.0, t0 + 0.5 - time.monotonic()))
                os.write(fd, SENTENCE)
                held = link_read(vehicle, len(SENTENCE), 3.0)
                assert b"".join(d for _, d in held) == SENTENCE
                assert held[0][0] - t0 >= 1.0  # nothing before the stall's end
                assert held[-1][0] - t0 <= 1.0 + len(SENTENCE) * transmit_time(1, 115200) + 0.1
            finally:
                os.close(fd)
            notes = [f for _, f in relay.fault_notes() if f.kind == "stall"]
            assert [n.direction for n in notes] == [TO_VEHICLE, FROM_VEHICLE, TO_VEHICLE, FROM_VEHICLE]
            assert f"{len(SENTENCE)} bytes held" in notes[2].detail and "0 bytes held" in notes[3].detail
    finally:
        vehicle.close()


def _dead(fd: int) -> bool:
    """The device behind ``fd`` is gone: reading it ends (EIO or end of file) at once."""
    if not select.select([fd], [], [], 1.0)[0]:
        return False
    try:
        return os.read(fd, 100) == b""
    except OSError:
        return True


def test_relay_cut_closes_the_pty_and_makes_a_new_one_under_the_same_link(tmp_path):
    """cut=0.6s@0.4: the tester's pty is closed (its open descriptor reads EIO) and the link is
    gone while the line is cut; bytes the vehicle sends meanwhile are lost; then the same link
    names a new pty, which carries bytes both ways; the notes say all of it."""
    vehicle = PtyLink(19200)
    link = tmp_path / "vehicle"
    try:
        with impaired_line(vehicle.name, "cut=0.6s@0.4", link=link, wire_log=tmp_path / "relay.log") as relay:
            fd = open_peer(str(link))
            os.write(fd, b"$OSD,S*27\r\n")
            assert b"".join(d for _, d in link_read(vehicle, 11, 1.0)) == b"$OSD,S*27\r\n"
            first = os.readlink(link)
            time.sleep(max(0.0, relay.t0 + 0.55 - time.monotonic()))
            assert _dead(fd)  # unplugged: the descriptor the tester had is dead
            assert not os.path.lexists(link)  # and its name is gone, as /dev/serial/by-id's is
            vehicle.write_all(b"$ACK,8,0,0*5D\r\n")  # into the cut: lost
            os.close(fd)
            deadline = time.monotonic() + 3.0
            while not os.path.lexists(link) and time.monotonic() < deadline:
                time.sleep(0.01)
            assert os.path.lexists(link) and time.monotonic() - relay.t0 >= 1.0
            fd = open_peer(str(link))  # plugged back: a new device under the same name
            try:
                vehicle.write_all(SENTENCE)
                assert b"".join(d for _, d in read_for(fd, len(SENTENCE), 2.0)) == SENTENCE  # not the lost ACK
                os.write(fd, b"$OMSTOP,0*06\r\n")
                assert b"".join(d for _, d in link_read(vehicle, 14, 2.0)) == b"$OMSTOP,0*06\r\n"
            finally:
                os.close(fd)
            notes = [text for _, text in relay.notes()]
            cut = [f for f in map(read_fault_note, notes) if f is not None and f.kind == "cut"]
            assert cut[0].detail.startswith("0.6 s from 0.4 s")
            assert cut[1].detail == "over after 0.6 s: lost 0 bytes >, 15 bytes <"
            assert any(n.startswith(f"relay: the backseat side's port {first} ({link}) unplugged") for n in notes)
            assert any(n.startswith("relay: the backseat side's port is back: /dev/pts/") for n in notes)
    finally:
        vehicle.close()


def test_relay_cut_of_a_socket_side_drops_the_connection_and_listens_again_on_the_same_port():
    vehicle = PtyLink(19200)
    try:
        with FaultRelay("socket://127.0.0.1:0", vehicle.name, "cut=0.5s@0.3", realtime=False) as relay:
            host, port = relay.port.rsplit("//", 1)[1].rsplit(":", 1)
            client = socket.create_connection((host, int(port)), timeout=2.0)
            client.sendall(b"$OSD,S*27\r\n")
            assert b"".join(d for _, d in link_read(vehicle, 11, 1.0)) == b"$OSD,S*27\r\n"
            client.settimeout(2.0)
            assert client.recv(100) == b""  # the cut: the connection drops
            client.close()
            with pytest.raises(OSError):  # nobody listens while the line is cut
                socket.create_connection((host, int(port)), timeout=1.0).close()
            time.sleep(max(0.0, relay.t0 + 0.85 - time.monotonic()))
            client = socket.create_connection((host, int(port)), timeout=2.0)
            try:
                time.sleep(0.1)  # the relay accepts it
                vehicle.write_all(b"$ACK,8,0,0*5D\r\n")
                client.settimeout(2.0)
                got = b""
                while len(got) < 15:
                    got += client.recv(100)
                assert got == b"$ACK,8,0,0*5D\r\n"
            finally:
                client.close()
    finally:
        vehicle.close()


def test_relay_same_seed_same_bytes_as_the_schedule_on_real_ptys():
    """Through the real relay, bytes written in chunks of any size give exactly the bytes the
    schedule gives for them in one piece (drops, flips and noise by the byte count and the seed)."""
    spec = "drop=2e-3,flip=1e-3,noise=2e-3,noise-len=1-4,seed=11"
    rng = random.Random(5)
    sent = bytes(rng.getrandbits(8) for _ in range(20000))
    _, want = run_schedule(spec, [(0.0, TO_VEHICLE, sent)])
    outs = []
    for chunking in (7, 1500):
        vehicle = PtyLink(19200)
        try:
            with FaultRelay("pty", vehicle.name, spec, realtime=False) as relay:
                fd = open_peer(relay.port)
                try:
                    write_all(fd, sent, chunking)
                    n = len(delivered(want, TO_VEHICLE))
                    outs.append(b"".join(d for _, d in link_read(vehicle, n, 5.0)))
                finally:
                    os.close(fd)
        finally:
            vehicle.close()
    assert outs[0] == outs[1] == delivered(want, TO_VEHICLE)


# ============================================================================ the command line
def test_cli_relay_prints_the_port_first_and_again_after_a_cut_under_its_link(tmp_path):
    """helmcheck relay --between pty VEHICLE --link L: 'port: /dev/pts/N' first, 'port: …'
    again after the cut, the link at the new pty; SIGTERM ends it with 0 and removes the link."""
    vehicle = PtyLink(19200)
    link = tmp_path / "hc-vehicle"
    proc = subprocess.Popen([sys.executable, "-m", "helmcheck", "relay", "--between", "pty", vehicle.name,
                             "--link", str(link), "--impair", "cut=0.4s@0.6", "--wire-log", str(tmp_path / "w.log")],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL, text=True)
    try:
        first = proc.stdout.readline().strip()
        assert first.startswith("port: /dev/pts/") and os.readlink(link) == first[6:]
        again = proc.stdout.readline().strip()  # after the cut
        assert again.startswith("port: /dev/pts/") and os.readlink(link) == again[6:]
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(10) == 0
        assert not os.path.lexists(link)
        log = (tmp_path / "w.log").read_text()
        assert "! line fault <> cut: 0.4 s from 0.6 s" in log and "! relay stopped" in log
        from helmcheck.grammar.wirelog import read_records

        assert len(list(read_records((tmp_path / "w.log").read_bytes().splitlines()))) >= 6  # a wire log as any other
        assert "stopped" in proc.stderr.read()
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        vehicle.close()


@pytest.mark.parametrize("argv, says", [
    (["--impair", "flip=1e-4,cutt=5s@60"], "--impair: 'cutt=5s@60': unknown key 'cutt'"),
    (["--impair", "drop=-1"], "--impair: 'drop=-1'"),
    (["--seed", "x"], "argument --seed: invalid int value"),
])
def test_cli_relay_bad_input_is_one_line_and_64(argv, says, capsys):
    from helmcheck.cli import main

    code = main(["relay", "--between", "pty", "pty", *argv])
    err = capsys.readouterr().err
    assert code == 64 and len([ln for ln in err.splitlines() if ln.strip()]) == 1 and says in err, err


def test_cli_relay_refuses_a_link_path_that_is_not_a_link(tmp_path, capsys):
    from helmcheck.cli import main

    f = tmp_path / "taken"
    f.write_text("mine")
    assert main(["relay", "--between", "pty", "pty", "--link", str(f), "--duration", "0.1"]) == 64
    assert "is not a symbolic link" in capsys.readouterr().err and f.read_text() == "mine"


def test_cli_relay_help_teaches():
    out = subprocess.run([sys.executable, "-m", "helmcheck", "relay", "--help"], capture_output=True, text=True).stdout
    for words in ("usage: helmcheck relay", "examples:", "exit status:", "why not 'monitor --impair'", "rx-baud=N",
                  "cut=T@X", "line fault"):
        assert words in out, words


def test_the_schedule_and_its_parts_are_sans_io():
    """The schedule, its settings, the UART model, the baud diagnosis and the note format import
    no clock, port, thread or event loop: they can be driven with any times, as here."""
    import ast
    from pathlib import Path

    import helmcheck

    root = Path(helmcheck.__file__).parent
    forbidden = {"time", "serial", "threading", "asyncio", "socket", "os", "subprocess", "select", "fcntl", "termios"}
    for rel in ("line/impair.py", "line/impair_spec.py", "line/uart.py", "line/baudguess.py", "grammar/faultnote.py"):
        for node in ast.walk(ast.parse((root / rel).read_text())):
            names = []
            if isinstance(node, ast.Import):
                names = [a.name.split(".")[0] for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module.split(".")[0]]
            assert not forbidden & set(names), (rel, names)


# ============================================================================ real vehicles behind the relay
SIM = Path(__file__).resolve().parents[2] / "shared" / "third-party" / "uvc_sim.py"


def test_the_emulator_behind_a_slow_line_answers_as_late_as_the_line_makes_it(tmp_path):
    """The reference emulator's pty behind baud=19200 and every vehicle line held 0.6 s: its
    ACK to an $OSD,S comes at least 0.6 s after the poll went out, and the answers are whole."""
    from helmcheck.emulator.process import EmulatorProcess, HelmClient
    from helmcheck.grammar import sentences as s
    from helmcheck.line.transport import open_link

    with EmulatorProcess() as emu, impaired_line(emu.port, "baud=19200,<line-delay=0.6",
                                                 link=tmp_path / "vehicle") as line:
        link = open_link(line.port, role="client", baud=19200)
        try:
            client = HelmClient(link)
            t0 = time.monotonic()
            replies = client.request("OSD,S", 8, timeout=5.0)
            took = time.monotonic() - t0
            assert isinstance(replies[-1], s.ACK) and any(isinstance(r, s.OSI) for r in replies)
            assert took >= 0.6 + transmit_time(len(b"$OSD,S*27\r\n$ACK,8,0,0*5D\r\n"), 19200)
            assert took < 3.0
        finally:
            link.close()


@pytest.mark.skipif(not SIM.is_file(), reason=f"the independent simulator is not there: {SIM}")
def test_an_independent_simulator_behind_a_cut_answers_again_under_the_same_link(tmp_path):
    """uvc_sim.py (written apart from helmcheck) behind cut=0.6s@0.8: the tester's port, opened
    by its link, answers; dies with the cut; and, opened again by the same link, answers again."""
    from helmcheck.emulator.process import HelmClient
    from helmcheck.line.transport import open_link

    proc = subprocess.Popen([sys.executable, str(SIM)], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                            stdin=subprocess.DEVNULL, start_new_session=True)
    try:
        assert select.select([proc.stdout], [], [], 20.0)[0]
        port = proc.stdout.readline().decode().strip().removeprefix("port: ")
        with impaired_line(port, "cut=0.6s@0.8", link=tmp_path / "vehicle") as line:
            link = open_link(line.port, role="client", baud=19200)
            client = HelmClient(link)
            assert client.ack("OSD,S", 8, timeout=3.0).type == 8
            time.sleep(max(0.0, line.t0 + 1.0 - time.monotonic()))
            with pytest.raises(OSError):  # unplugged: the port the tester has is gone (EIO)
                client.ack("OSD,S", 8, timeout=0.3)
            link.close()
            time.sleep(max(0.0, line.t0 + 1.45 - time.monotonic()))
            link = open_link(line.port, role="client", baud=19200)
            try:
                assert HelmClient(link).ack("OSD,S", 8, timeout=3.0).type == 8
            finally:
                link.close()
    finally:
        os.killpg(proc.pid, signal.SIGTERM)
        proc.wait(10)


def test_the_docs_page_is_the_one_the_code_makes():
    from helmcheck.line import faultdocs

    assert not faultdocs.stale(), "docs/line-faults.md is stale: run 'helmcheck docs'"
    text = faultdocs.render_markdown()
    for item in ITEMS:
        assert f"`{item.key}={item.value}`" in text
    assert "! line fault <> cut: over after 1 s: lost" in text  # a real run's notes, not typed in


# ============================================================================ soak (HELMCHECK_LINE_SOAK=1)
@pytest.mark.skipif(not SOAK, reason="a long run on a real relay: HELMCHECK_LINE_SOAK=1")
def test_soak_a_real_relay_in_its_own_process_gives_the_schedule_s_bytes_and_rates(tmp_path):
    """Two megabytes through ``helmcheck relay`` in a process of its own: the bytes out are the
    schedule's for the same bytes, byte for byte, and the faults its notes count are within the
    binomial bounds."""
    p = 1e-3
    spec = f"drop={p},flip={p},noise={p},noise-len=1-6,seed=21"
    rng = random.Random(21)
    n = 2_000_000
    sent = bytes(rng.getrandbits(8) for _ in range(n))
    _, want = run_schedule(spec, [(0.0, TO_VEHICLE, sent)])
    vehicle = PtyLink(19200)
    try:
        with impaired_line(vehicle.name, spec, wire_log=tmp_path / "relay.log", process=True) as line:
            fd = open_peer(line.port)
            try:
                got: list = []
                reader = threading.Thread(target=lambda: got.extend(link_read(vehicle, len(delivered(want, TO_VEHICLE)),
                                                                              120.0)))
                reader.start()
                write_all(fd, sent)
                reader.join()
            finally:
                os.close(fd)
            time.sleep(0.3)
            kinds = [f.kind for _, f in line.fault_notes()]
        assert b"".join(d for _, d in got) == delivered(want, TO_VEHICLE)
        lo, hi = binomial_bounds(n, p)
        assert lo <= kinds.count("drop") <= hi and lo <= kinds.count("noise") <= hi
    finally:
        vehicle.close()


@pytest.mark.skipif(not SOAK, reason="a long run on a real relay: HELMCHECK_LINE_SOAK=1")
@pytest.mark.parametrize("baud", [9600, 19200, 115200])
def test_soak_pacing_over_ten_seconds_holds_the_rate(baud):
    vehicle = PtyLink(baud)
    try:
        with impaired_line(vehicle.name, f"baud={baud}", process=True) as line:
            fd = open_peer(line.port)
            try:
                bt = transmit_time(1, baud)
                n = int(10 / bt)
                data = bytes(0x41 + i % 26 for i in range(n))

                writer = threading.Thread(target=write_all, args=(fd, data, 512))
                t0 = time.monotonic()
                writer.start()
                got = link_read(vehicle, n, 30.0)
                writer.join()
            finally:
                os.close(fd)
        assert sum(len(d) for _, d in got) == n
        span = got[-1][0] - t0
        assert n * bt * (1 - 1e-3) <= span <= n * bt * 1.01, span
    finally:
        vehicle.close()


def test_cli_relay_a_side_that_fails_during_the_run_is_a_link_fault_2(tmp_path):
    vehicle = PtyLink(19200)
    proc = subprocess.Popen([sys.executable, "-m", "helmcheck", "relay", "--between", "pty", vehicle.name,
                             "--wire-log", str(tmp_path / "w.log")],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL, text=True)
    try:
        assert proc.stdout.readline().startswith("port: /dev/pts/")
        vehicle.close()  # the vehicle's device goes away for good
        assert proc.wait(10) == 2
        err = proc.stderr.read()
        assert "helmcheck relay: link fault: the vehicle side closed" in err and "Traceback" not in err
        assert "! relay: the vehicle side: closed" in (tmp_path / "w.log").read_text()
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def test_cli_relay_a_wire_log_that_cannot_be_written_is_2(capsys):
    from helmcheck.cli import main

    assert main(["relay", "--between", "pty", "pty", "--wire-log", "/dev/full", "--duration", "0.2"]) == 2
    assert "cannot write /dev/full: No space left on device" in capsys.readouterr().err


def test_relay_cut_of_the_vehicle_side_closes_and_reopens_its_device():
    """--cut-side vehicle, the vehicle's side a device path: the relay closes it for the cut and
    opens it again after (the far end sees a dead line, not a vanished device); bytes pass after."""
    vehicle = PtyLink(19200)
    try:
        with FaultRelay("pty", vehicle.name, "cut=0.4s@0.3", cut_side="vehicle", realtime=False) as relay:
            fd = open_peer(relay.port)
            try:
                time.sleep(max(0.0, relay.t0 + 0.8 - time.monotonic()))
                os.write(fd, b"$OSD,S*27\r\n")
                assert b"".join(d for _, d in link_read(vehicle, 11, 2.0)) == b"$OSD,S*27\r\n"
                vehicle.write_all(b"$ACK,8,0,0*5D\r\n")
                assert b"".join(d for _, d in read_for(fd, 15, 2.0)) == b"$ACK,8,0,0*5D\r\n"
            finally:
                os.close(fd)
            notes = [text for _, text in relay.notes()]
            assert any(n.startswith(f"relay: the vehicle side's port {vehicle.name} unplugged") for n in notes)
            assert any(n == f"relay: the vehicle side's port is back: {vehicle.name}" for n in notes)
    finally:
        vehicle.close()
