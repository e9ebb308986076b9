"""The monitor's relay over real ptys (and a TCP server side): in line it forwards every byte
unchanged and in order both ways and reports each chunk; as a tap it writes nothing; a stalled
reader loses nothing; a side that goes away is reported and the other keeps working; stop() is
prompt. RH-FRM-9: 8N1, a TCP byte stream carries the same bytes.
"""

from __future__ import annotations

import os
import select
import socket
import termios
import threading
import time
import tty

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from helmcheck.grammar.wirelog import FROM_VEHICLE, TO_VEHICLE
from helmcheck.line.pty_link import PtyLink
from helmcheck.line.serial_link import SerialLink
from helmcheck.line.tcp_link import TcpServerLink
from helmcheck.line.relay import Relay


def open_peer(path: str) -> int:
    """The far end of a pty link, opened the way a backseat or a vehicle opens its port."""
    fd = os.open(path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
    tty.setraw(fd, termios.TCSANOW)
    return fd


class Seen:
    """What the relay reported: chunks per direction, events, and every callback's time."""

    def __init__(self):
        self.chunks = {TO_VEHICLE: [], FROM_VEHICLE: []}
        self.events: list[tuple[str, str]] = []
        self.times: list[float] = []

    def on_bytes(self, t: float, direction: str, data: bytes) -> None:
        self.times.append(t)
        self.chunks[direction].append(data)

    def on_event(self, t: float, kind: str, side: str) -> None:
        self.times.append(t)
        self.events.append((kind, side))

    def joined(self, direction: str) -> bytes:
        return b"".join(self.chunks[direction])


def read_exactly(fd: int, n: int, timeout: float = 5.0) -> bytes:
    got = bytearray()
    deadline = time.monotonic() + timeout
    while len(got) < n:
        left = deadline - time.monotonic()
        if left <= 0:
            break
        if select.select([fd], [], [], left)[0]:
            try:
                got += os.read(fd, 65536)
            except BlockingIOError:
                pass
    return bytes(got)


def quiet(fd: int, wait: float = 0.3) -> bool:
    """True when nothing arrives on ``fd`` within ``wait`` seconds."""
    return not select.select([fd], [], [], wait)[0]


def wait_until(pred, timeout: float = 3.0) -> bool:
    deadline = time.monotonic() + timeout
    while not pred():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.005)
    return True


def pump(outgoing: dict[int, bytes], expect: dict[int, int], sizes: list[int], timeout: float = 10.0) -> dict:
    """Write each ``outgoing`` stream in pieces (sizes taken in turn) from all ends at once and
    read every end until it has its ``expect`` ed count; returns what each end read."""
    sent = {fd: 0 for fd in outgoing}
    got = {fd: bytearray() for fd in expect}
    k = 0
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        want_w = [fd for fd, data in outgoing.items() if sent[fd] < len(data)]
        want_r = [fd for fd in expect if len(got[fd]) < expect[fd]]
        if not want_w and not want_r:
            break
        r, w, _ = select.select(want_r, want_w, [], 0.05)
        for fd in w:
            size = sizes[k % len(sizes)]
            k += 1
            try:
                sent[fd] += os.write(fd, outgoing[fd][sent[fd]:sent[fd] + size])
            except BlockingIOError:
                pass
        for fd in r:
            try:
                got[fd] += os.read(fd, 65536)
            except BlockingIOError:
                pass
    return {fd: bytes(b) for fd, b in got.items()}


class InLine:
    """Two pty links, their far ends opened, and a started relay between them."""

    def __init__(self, forward: bool = True, on_bytes=None):
        self.seen = Seen()
        self.backseat, self.vehicle = PtyLink(115200), PtyLink(115200)
        self.bs_peer, self.veh_peer = open_peer(self.backseat.name), open_peer(self.vehicle.name)
        self.relay = Relay(self.backseat, self.vehicle, forward=forward, on_bytes=on_bytes or self.seen.on_bytes,
                           on_event=self.seen.on_event)
        self.relay.start()

    def close(self) -> None:
        assert self.relay.stop(2.0)
        for fd in (self.bs_peer, self.veh_peer):
            os.close(fd)
        self.backseat.close()
        self.vehicle.close()

    def __enter__(self) -> "InLine":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


# ---------------------------------------------------------------------- byte streams
_PIECES = [b"$", b"\r", b"\n", b"\r\n", b"\n\r", b"$$", b"*", b"$OSD,G,C,S,P,,,,*5F\r\n", b"$OSD,G,C",
           b",S,P,,,,*5F\r\n", b"$ACK,8,0,0*5D\r\n", b"$OSI,8080808080,N,0,30.35313633,-89.6279528",
           b"\x00", b"\xff", b"\x11\x13", b"\x03\x04\x1a\x7f"]
_chunk = st.one_of(
    st.binary(max_size=80),  # any byte 0x00–0xFF
    st.sampled_from(_PIECES),  # torn lines, a lone '$', CR and LF in odd places
    st.builds(lambda b, n: bytes([b]) * n, st.integers(0, 255), st.integers(100, 6000)),  # long runs
)
_stream = st.lists(_chunk, max_size=25).map(b"".join)


@settings(max_examples=25, deadline=None)
@given(to_vehicle=_stream, from_vehicle=_stream, sizes=st.lists(st.integers(1, 5000), min_size=1, max_size=6))
def test_RH_FRM_9_in_line_every_byte_arrives_unchanged_and_in_order(to_vehicle, from_vehicle, sizes):
    with InLine() as line:
        got = pump({line.bs_peer: to_vehicle, line.veh_peer: from_vehicle},
                   {line.veh_peer: len(to_vehicle), line.bs_peer: len(from_vehicle)}, sizes)
        assert got[line.veh_peer] == to_vehicle
        assert got[line.bs_peer] == from_vehicle
        assert quiet(line.veh_peer, 0.02) and quiet(line.bs_peer, 0.02)  # nothing injected
        assert wait_until(lambda: line.relay.stats["bytes"] == {TO_VEHICLE: len(to_vehicle),
                                                                FROM_VEHICLE: len(from_vehicle)})
    assert line.seen.joined(TO_VEHICLE) == to_vehicle
    assert line.seen.joined(FROM_VEHICLE) == from_vehicle
    assert line.seen.times == sorted(line.seen.times)  # one clock for both directions
    assert line.relay.error is None and line.seen.events == []


def test_tap_writes_nothing_to_either_side():
    with InLine(forward=False) as tap:
        os.write(tap.bs_peer, b"$OSD,G,C,S,P,,,,*5F\r\n")
        os.write(tap.veh_peer, b"$ACK,8,0,0*5D\r\n\x00\xff")
        assert wait_until(lambda: tap.relay.stats["bytes"] == {TO_VEHICLE: 21, FROM_VEHICLE: 17})
        assert quiet(tap.veh_peer) and quiet(tap.bs_peer)  # nothing reached the opposite ends
        stats = tap.relay.stats
    assert tap.seen.joined(TO_VEHICLE) == b"$OSD,G,C,S,P,,,,*5F\r\n"
    assert tap.seen.joined(FROM_VEHICLE) == b"$ACK,8,0,0*5D\r\n\x00\xff"
    assert stats["max_pending"] == {TO_VEHICLE: 0, FROM_VEHICLE: 0}


def test_a_stalled_reader_loses_and_reorders_nothing_and_the_other_way_keeps_flowing():
    big = b"".join(b"$OSD,G,C,S,P,,,,*5F\r\n%06d\x00\xff$\r" % i for i in range(7000))  # ~200 KB
    with InLine() as line:
        sent = 0
        deadline = time.monotonic() + 10
        while sent < len(big) and time.monotonic() < deadline:  # the vehicle's end reads nothing yet
            if select.select([], [line.bs_peer], [], 0.05)[1]:
                try:
                    sent += os.write(line.bs_peer, big[sent:sent + 8192])
                except BlockingIOError:
                    pass
        assert sent == len(big)
        assert wait_until(lambda: line.relay.stats["bytes"][TO_VEHICLE] == len(big))
        assert line.relay.stats["pending"][TO_VEHICLE] > 0  # the far end's buffer is full: held, in order
        os.write(line.veh_peer, b"$ACK,8,0,0*5D\r\n")  # the other direction is not held up
        assert read_exactly(line.bs_peer, 15, 2.0) == b"$ACK,8,0,0*5D\r\n"
        assert read_exactly(line.veh_peer, len(big), 10.0) == big
        assert quiet(line.veh_peer, 0.05)
        stats = line.relay.stats
    assert stats["pending"] == {TO_VEHICLE: 0, FROM_VEHICLE: 0}
    assert stats["max_pending"][TO_VEHICLE] > 0 and stats["undelivered"][TO_VEHICLE] == 0
    assert line.seen.joined(TO_VEHICLE) == big


def test_slow_judging_does_not_delay_forwarding():
    release = threading.Event()

    def slow(t, direction, data):  # noqa: ARG001
        release.wait(5)

    with InLine(on_bytes=slow) as line:
        os.write(line.bs_peer, b"$OSD,G,C,S,P,,,,*5F\r\n")
        assert read_exactly(line.veh_peer, 21, 2.0) == b"$OSD,G,C,S,P,,,,*5F\r\n"  # judge still busy
        release.set()


def test_a_client_that_leaves_is_reported_and_the_line_keeps_working():
    seen = Seen()
    backseat, vehicle = TcpServerLink(), PtyLink(115200)
    veh_peer = open_peer(vehicle.name)
    relay = Relay(backseat, vehicle, forward=True, on_bytes=seen.on_bytes, on_event=seen.on_event)
    relay.start()
    try:
        c1 = socket.create_connection(("127.0.0.1", backseat.port), timeout=5)
        assert wait_until(lambda: ("connect", "backseat") in seen.events)
        c1.sendall(b"$OSD,G,C,S,P,,,,*5F\r\n")
        assert read_exactly(veh_peer, 21) == b"$OSD,G,C,S,P,,,,*5F\r\n"
        os.write(veh_peer, b"$ACK,8,0,0*5D\r\n")
        assert c1.recv(100) == b"$ACK,8,0,0*5D\r\n"
        c1.close()
        assert wait_until(lambda: ("disconnect", "backseat") in seen.events)
        os.write(veh_peer, b"$OSI,lonely\r\n")  # still read and reported with no backseat
        assert wait_until(lambda: seen.joined(FROM_VEHICLE).endswith(b"$OSI,lonely\r\n"))
        assert wait_until(lambda: relay.stats["undelivered"][FROM_VEHICLE] == 13)  # nobody to take them
        c2 = socket.create_connection(("127.0.0.1", backseat.port), timeout=5)  # a new client
        assert wait_until(lambda: seen.events.count(("connect", "backseat")) == 2)
        c2.sendall(b"$OMSTOP,0*2D\r\n")
        assert read_exactly(veh_peer, 14) == b"$OMSTOP,0*2D\r\n"
        os.write(veh_peer, b"$ACK,11,0,0*6C\r\n")
        assert c2.recv(100) == b"$ACK,11,0,0*6C\r\n"
        c2.close()
        assert relay.is_alive() and relay.error is None
    finally:
        assert relay.stop(2.0)
        os.close(veh_peer)
        backseat.close()
        vehicle.close()
    assert seen.events == [("connect", "backseat"), ("disconnect", "backseat"), ("connect", "backseat"),
                           ("disconnect", "backseat")][:len(seen.events)]


@pytest.mark.parametrize("forward", [True, False], ids=["in-line", "tap"])
def test_a_device_that_goes_away_is_reported_and_the_other_side_keeps_working(forward):
    """Each side is a serial device (pyserial on a pty's slave); the vehicle's device goes away
    (its pty master closes: reads fail with EIO) — reported as ``closed``, the backseat served."""
    seen = Seen()
    bs_master, bs_slave = os.openpty()
    veh_master, veh_slave = os.openpty()
    for fd in (bs_slave, veh_slave):
        tty.setraw(fd, termios.TCSANOW)
    backseat, vehicle = SerialLink(os.ttyname(bs_slave), 115200), SerialLink(os.ttyname(veh_slave), 115200)
    relay = Relay(backseat, vehicle, forward=forward, on_bytes=seen.on_bytes, on_event=seen.on_event)
    relay.start()
    try:
        os.write(veh_master, b"$ACK,8,0,0*5D\r\n")
        assert wait_until(lambda: seen.joined(FROM_VEHICLE) == b"$ACK,8,0,0*5D\r\n")
        os.close(veh_master)
        os.close(veh_slave)
        assert wait_until(lambda: ("closed", "vehicle") in seen.events)
        os.write(bs_master, b"$OSD,G,C,S,P,,,,*5F\r\n")
        assert wait_until(lambda: seen.joined(TO_VEHICLE) == b"$OSD,G,C,S,P,,,,*5F\r\n")
        if forward:
            assert read_exactly(bs_master, 15, 2.0) == b"$ACK,8,0,0*5D\r\n"
            assert wait_until(lambda: relay.stats["undelivered"][TO_VEHICLE] == 21)
        else:
            assert quiet(bs_master)
        assert relay.is_alive() and relay.error is None and seen.events == [("closed", "vehicle")]
    finally:
        assert relay.stop(2.0)
        backseat.close()
        vehicle.close()
        os.close(bs_master)
        os.close(bs_slave)


def test_stop_is_prompt():
    with InLine() as line:
        time.sleep(0.2)  # idle in its select
        t0 = time.monotonic()
        assert line.relay.stop(0.5)
        assert time.monotonic() - t0 < 0.5
        assert not line.relay.is_alive() and line.relay.error is None
    a, b = PtyLink(), PtyLink()
    never = Relay(a, b, forward=True, on_bytes=lambda *args: None)
    assert never.stop(0.1)  # never started: nothing to wait for
    a.close()
    b.close()


def test_a_callback_that_raises_ends_the_relay_with_its_error():
    def broken(t, direction, data):  # noqa: ARG001
        raise RuntimeError("judge crashed")

    with InLine(on_bytes=broken) as line:
        os.write(line.bs_peer, b"x")
        assert wait_until(lambda: not line.relay.is_alive())
        assert isinstance(line.relay.error, RuntimeError)
        assert read_exactly(line.veh_peer, 1, 2.0) == b"x"  # forwarded before the callback ran


@pytest.mark.parametrize("realtime", [True, False])
def test_relay_priority_is_what_it_says(realtime):
    """The relay's thread runs at the priority it reports (real-time where permitted, asked for
    by default; normal with ``realtime=False``), and the bytes are forwarded either way."""
    policies: list[int] = []
    b, v = PtyLink(115200), PtyLink(115200)

    def on_bytes(t, direction, data):
        policies.append(os.sched_getscheduler(0))  # the callback runs in the relay's thread

    relay = Relay(b, v, forward=True, on_bytes=on_bytes, realtime=realtime)
    relay.start()
    bs, veh = open_peer(b.name), open_peer(v.name)
    try:
        said = relay.started()
        os.write(bs, b"$OSD,G*00\r\n")
        assert read_exactly(veh, 11) == b"$OSD,G*00\r\n"
        assert wait_until(lambda: policies)
    finally:
        relay.stop()
        os.close(bs)
        os.close(veh)
        b.close()
        v.close()
    assert os.sched_getscheduler(0) == os.SCHED_OTHER  # only the relay's thread, not the process
    if said.startswith("real-time"):
        assert realtime and set(policies) == {os.SCHED_FIFO}
    else:
        assert said.startswith("normal (") and set(policies) == {os.SCHED_OTHER}
        assert realtime or "not asked" in said
