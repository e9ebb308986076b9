"""The emulator as a TCP serial server (RH-FRM-9): one client at a time, state kept across clients."""

from __future__ import annotations

import signal
import socket

import pytest

from helmcheck.emulator.process import EmulatorProcess, HelmClient, frame
from helmcheck.line.transport import open_link

#: The module-scoped run below is made once: all of this module's tests go to one worker.
pytestmark = pytest.mark.xdist_group("test_emulator_tcp")


@pytest.fixture(scope="module")
def emulator():
    emu = EmulatorProcess(port="socket://127.0.0.1:0", time_scale=20, baud=0).start()
    yield emu
    emu.stop()


def test_RH_FRM_9_port_line_names_the_bound_socket(emulator):
    assert emulator.port.startswith("socket://127.0.0.1:")
    assert int(emulator.port.rsplit(":", 1)[1]) > 0


def test_RH_FRM_9_reconnect_keeps_state_and_resets_the_framer(emulator):
    link = open_link(emulator.port, role="client")
    c = HelmClient(link)
    assert c.ack("OMSTOP,0", 1).status == 0
    assert (c.ack("OMSTART,0,0,0,0,conformance.mis", 3).status, c.osi().mode) == (0, "N")
    c.send_raw(b"$OMS,90,2,2")  # torn: the client leaves mid-line
    link.close()

    link = open_link(emulator.port, role="client")
    c = HelmClient(link)
    got = c.request("OSD,S", 8)  # the partial line died with the old client
    assert [type(g).__name__ for g in got] == ["OSI", "ACK"]
    o = got[0]
    assert (o.mode, o.mission_name) == ("N", "conformance.mis")  # the vehicle carried on
    assert c.ack("OMS,90,2,20,2,10", 9).status == 0
    assert c.osi().mode == "A"

    # a second client waits in the backlog until the first one leaves
    other = socket.create_connection(("127.0.0.1", int(emulator.port.rsplit(":", 1)[1])))
    other.sendall(frame("OSD,S"))
    other.settimeout(0.3)
    with pytest.raises(socket.timeout):
        other.recv(100)
    link.close()
    other.settimeout(5.0)
    data = b""
    while b"$ACK,8" not in data:
        chunk = other.recv(4096)
        assert chunk
        data += chunk
    assert b"$OSI," in data
    other.close()


def test_sigint_exits_zero_without_traceback(emulator):
    link = open_link(emulator.port, role="client")
    c = HelmClient(link)
    assert c.osi().mode in ("A", "N", "S")
    link.close()
    emulator.proc.send_signal(signal.SIGINT)
    assert emulator.proc.wait(10) == 0
    err = emulator.stderr_text()
    assert "Traceback" not in err and "stopped" in err
