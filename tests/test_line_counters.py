"""A port's error counters (:mod:`helmcheck.line.counters`): where the kernel keeps none (a pty, a
socket, a file) the answer is "not available" with the reason, never zeros claiming a clean
line. (A real UART's counters need a real serial port; none is used here.)"""

from __future__ import annotations

import os
import socket

from helmcheck.line.counters import LineCounters, NotAvailable, read_counters
from helmcheck.line.pty_link import PtyLink


def test_a_pty_has_no_counters_and_says_why_for_both_ends():
    link = PtyLink(19200)
    fd = os.open(link.name, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
    try:
        for port in (link, fd):  # the master through the link, the slave a program opens
            got = read_counters(port)
            assert isinstance(got, NotAvailable) and not got.available
            assert "pseudo-terminal" in got.reason and "TIOCGICOUNT refused" in got.reason
            assert got.as_dict() == {"available": False, "reason": got.reason}
            assert got.since(got) is got and got.errors == 0
    finally:
        os.close(fd)
        link.close()


def test_a_socket_a_file_and_a_closed_descriptor_have_no_counters():
    with socket.socket() as s:
        assert "a socket has no UART" in read_counters(s).reason
    with open(__file__) as f:
        assert "a regular file has no UART" in read_counters(f).reason
    r, w = os.pipe()
    os.close(r)
    os.close(w)
    assert isinstance(read_counters(r), NotAvailable)
    assert "no descriptor" in read_counters(object()).reason


def test_counters_arithmetic():
    a = LineCounters(rx=100, tx=5, frame=1, parity=0, overrun=0, brk=0, buf_overrun=0)
    b = LineCounters(rx=180, tx=9, frame=4, parity=1, overrun=2, brk=0, buf_overrun=1)
    d = b.since(a)
    assert d == LineCounters(80, 4, 3, 1, 2, 0, 1) and d.errors == 7 and d.available
    assert d.as_dict()["available"] is True and d.as_dict()["frame"] == 3
