"""Link plumbing: port specs, pty and TCP in both roles, the line pacer."""

from __future__ import annotations

import os
import time

import pytest

from helmcheck.line.transport import (LinePacer, LinkClosed, PtyLink, SerialLink, TcpClientLink,
                                             TcpServerLink, open_link, parse_port_spec)


@pytest.mark.parametrize("text, kind, host, port", [
    ("pty", "pty", "", 0),
    ("/dev/ttyUSB0", "device", "", 0),
    ("socket://127.0.0.1:4001", "socket", "127.0.0.1", 4001),
    ("socket://:0", "socket", "0.0.0.0", 0),
    ("socket://[::1]:5000", "socket", "::1", 5000),
    ("rfc2217://host:2217", "url", "", 0),
])
def test_parse_port_spec(text, kind, host, port):
    p = parse_port_spec(text)
    assert (p.kind, p.host, p.port) == (kind, host, port)


@pytest.mark.parametrize("text", ["", "ttyS0", "socket://host", "socket://h:99999", "socket://h:x"])
def test_parse_port_spec_rejects(text):
    with pytest.raises(ValueError):
        parse_port_spec(text)


def test_open_link_rejects_bad_role_and_baud():
    with pytest.raises(ValueError):
        open_link("pty", role="both")
    with pytest.raises(ValueError):
        open_link("/dev/ttyS0", baud=1234)
    with pytest.raises(OSError):
        open_link("/dev/does-not-exist-helmcheck")


def test_RH_FRM_9_pty_server_and_pyserial_client_move_bytes_both_ways():
    server = open_link("pty", role="server", baud=19200)
    assert isinstance(server, PtyLink) and server.name.startswith("/dev/")
    client = open_link(server.name, role="client", baud=19200)
    assert isinstance(client, SerialLink)
    try:
        payload = bytes(range(256)) * 4  # raw mode: every byte value passes unchanged
        client.write_all(payload)
        got = b""
        while len(got) < len(payload):
            chunk = server.read(2.0)
            assert chunk, "timed out"
            got += chunk
        assert got == payload
        server.write_all(b"$ACK,8,0,0*5D\r\n")
        assert client.read(2.0) == b"$ACK,8,0,0*5D\r\n"
        assert client.read(0.05) == b""  # an empty tty read is not an end of file
    finally:
        client.close()
    # the server keeps its own slave open: a closed client is not a hang-up
    assert server.poll() == []
    again = open_link(server.name, role="client")
    again.write_all(b"x")
    assert server.read(2.0) == b"x"
    again.close()
    server.close()


def test_RH_FRM_9_tcp_server_one_client_at_a_time():
    server = open_link("socket://127.0.0.1:0", role="server")
    assert isinstance(server, TcpServerLink) and server.port > 0
    listen_fd = server.fileno()
    assert server.write_some(b"lost") == 4  # no client: dropped like an unplugged line
    c1 = open_link(server.name, role="client")
    assert isinstance(c1, TcpClientLink)
    assert server.wait_readable(2.0)
    assert [e.kind for e in server.poll()] == ["connect"]
    assert server.connected and server.fileno() != listen_fd
    c1.write_all(b"hello")
    assert server.read(2.0) == b"hello"
    server.write_all(b"back")
    assert c1.read(2.0) == b"back"
    c2 = TcpClientLink("127.0.0.1", server.port)  # waits in the backlog
    c2.write_all(b"second")
    c1.close()
    assert server.wait_readable(2.0)
    assert [e.kind for e in server.poll()] == ["disconnect"]
    assert server.fileno() == listen_fd
    assert server.wait_readable(2.0)
    assert [e.kind for e in server.poll()] == ["connect"]
    assert server.read(2.0) == b"second"
    server.close()
    with pytest.raises(LinkClosed):
        deadline = time.monotonic() + 2
        while time.monotonic() < deadline:
            c2.read(0.1)
    c2.close()


def test_line_pacer_models_10_bits_per_byte():
    p = LinePacer(9600)
    assert p.transmit_time(960) == pytest.approx(1.0)
    assert p.reserve(96, 0.0) == 0.0
    assert p.free_at == pytest.approx(0.1)
    assert p.reserve(96, 0.05) == pytest.approx(0.1)  # waits for the line
    assert p.reserve(10, 5.0) == 5.0  # an idle line starts at once
    unpaced = LinePacer(0)
    assert unpaced.reserve(10_000, 1.0) == 1.0 and unpaced.free_at == 1.0


def test_pty_write_some_never_blocks():
    server = PtyLink()
    total = 0
    t0 = time.monotonic()
    while time.monotonic() - t0 < 2:
        n = server.write_some(b"x" * 4096)
        if n == 0:
            break
        total += n
    assert n == 0 and total > 0  # nobody reads: the buffer fills, the write does not block
    server.close()
    assert os.path.exists("/dev/ptmx")
