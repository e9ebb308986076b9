"""The process launcher of ``--exec`` (:mod:`helmcheck.line.launcher`), with real processes.

Argument building (placeholders, the port appended when ``{port}`` is absent, shlex, no shell),
command checks, output capture and its tail, exit codes and signals, and stopping: SIGTERM to the
whole process group, SIGKILL after the grace period, nothing left behind (checked in ``/proc``).
"""

from __future__ import annotations

import os
import shlex
import sys
import time

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from helmcheck.line.launcher import TAIL_LINES, CommandError, Launcher, build_argv, check_command
from tests.processes import descendants, survivors

PY = shlex.quote(sys.executable)


def _launch(tmp_path, code: str, *, grace_s: float = 2.0, port: str = "/dev/pts/999", subject: str = "backseat"):
    child = Launcher(f"{PY} -c {shlex.quote(code)} {{port}}", subject=subject, directory=tmp_path,
                     grace_s=grace_s)
    child.start(port, time_scale=4)
    return child


# --------------------------------------------------------------------------- argv

def test_placeholders_are_replaced_and_other_braces_kept():
    argv = build_argv("sim --serial={port} --k {time_scale} --json '{\"a\": 1}' {unknown}",
                      {"port": "/dev/pts/7", "time_scale": "20"})
    assert argv == ["sim", "--serial=/dev/pts/7", "--k", "20", "--json", '{"a": 1}', "{unknown}"]


def test_port_is_appended_when_the_command_does_not_name_it():
    assert build_argv("sim -v", {"port": "socket://127.0.0.1:4001"}) == ["sim", "-v", "socket://127.0.0.1:4001"]
    assert build_argv("nc {host} {tcp_port}", {"port": "socket://h:1", "host": "h", "tcp_port": "1"}) \
        == ["nc", "h", "1", "socket://h:1"]


@settings(derandomize=True, max_examples=60)
@given(st.lists(st.text(st.characters(blacklist_categories=("Cs", "Cc")), min_size=1), min_size=1, max_size=5))
def test_any_argument_list_survives_the_round_trip(args):
    """Whatever the arguments (spaces, quotes, dollar signs), no shell touches them."""
    args = [a.replace("{", "(") for a in args]
    assert build_argv(shlex.join(args), {"port": "P"}) == args + ["P"]


@pytest.mark.parametrize("command, message", [
    ("", "the command is empty"),
    ("sim 'unclosed", "cannot split"),
    ("no-such-program-xyz --port {port}", "no-such-program-xyz: command not found on PATH"),
    ("/nonexistent/sim", "/nonexistent/sim: no such file"),
])
def test_bad_commands_are_refused_with_one_line(command, message):
    why = check_command(command)
    assert why is not None and message in why and "\n" not in why
    if command in ("", "sim 'unclosed"):
        with pytest.raises(CommandError):
            build_argv(command, {"port": "P"})


def test_a_file_that_is_not_executable_is_refused(tmp_path):
    f = tmp_path / "sim"
    f.write_text("#!/bin/sh\n")
    assert check_command(str(f)) == f"{f}: not executable"
    f.chmod(0o755)
    assert check_command(f"{f} --port {{port}}") is None


# --------------------------------------------------------------------------- running

def test_environment_output_and_exit_code_are_recorded(tmp_path):
    code = ("import os, sys\n"
            "print('port', sys.argv[1], os.environ['HELMCHECK_PORT'], os.environ['HELMCHECK_TIME_SCALE'], flush=True)\n"
            "for i in range(30):\n"
            "    print(f'out {i}', flush=True); print(f'err {i}', file=sys.stderr, flush=True)\n"
            "sys.exit(3)\n")
    child = _launch(tmp_path, code)
    assert child.wait(10)
    t0 = child.started_at
    rec = child.record(epoch=t0)  # waits for the output readers of an ended child
    assert rec["exit_code"] == 3 and rec["signal"] is None and rec["ended_early"] is True
    assert rec["pid"] == child.pid and "-c" in rec["command"] and rec["command"].endswith("/dev/pts/999")
    assert 0 <= rec["ended_at_s"] < 10
    out = (tmp_path / "backseat.stdout.log").read_text().splitlines()
    err = (tmp_path / "backseat.stderr.log").read_text().splitlines()
    assert out[0] == "port /dev/pts/999 /dev/pts/999 4"
    assert out[1:] == [f"out {i}" for i in range(30)] and err == [f"err {i}" for i in range(30)]
    tail = rec["output_tail"]
    assert len(tail) == TAIL_LINES
    # Two pipes read by two threads: the interleaving is the order the lines were read in, so
    # all that is certain is that each stream's lines in the tail are that stream's last lines.
    for stream, lines in (("out", out[1:]), ("err", err)):
        mine = [line for line in tail if line.startswith(stream + " ")]
        assert mine == lines[len(lines) - len(mine):]
    assert "out 29" in tail or "err 29" in tail
    assert child.exit_text() == "exited with code 3"


def test_killed_by_a_signal_names_it(tmp_path):
    child = _launch(tmp_path, "import os, signal; os.kill(os.getpid(), signal.SIGKILL)")
    assert child.wait(10)
    rec = child.record(epoch=child.started_at)
    assert rec["exit_code"] is None and rec["signal"] == "SIGKILL" and rec["output_tail"] == []
    assert child.exit_text() == "was killed by SIGKILL"


def test_a_child_stopped_at_the_end_did_not_end_early(tmp_path):
    child = _launch(tmp_path, "import time; print('ready', flush=True); time.sleep(60)")
    time.sleep(0.3)
    assert not child.ended
    child.stop()
    rec = child.record(epoch=child.started_at)
    assert rec["ended_early"] is False and rec["signal"] == "SIGTERM"
    assert rec["output_tail"] == ["ready"]


def test_stop_kills_the_whole_group_even_when_it_ignores_sigterm(tmp_path):
    """The child and a grandchild both ignore SIGTERM: SIGKILL after the grace period ends both."""
    code = ("import signal, subprocess, sys, time\n"
            "signal.signal(signal.SIGTERM, signal.SIG_IGN)\n"
            "g = subprocess.Popen([sys.executable, '-c', 'import signal, time; "
            "signal.signal(signal.SIGTERM, signal.SIG_IGN); print(\"grandchild\", flush=True); time.sleep(60)'])\n"
            "time.sleep(60)\n")
    child = _launch(tmp_path, code, grace_s=0.5)
    deadline = time.monotonic() + 10
    while "grandchild" not in child.output_tail() and time.monotonic() < deadline:
        time.sleep(0.05)
    mine = [pid for pid, _ in descendants()]
    assert child.pid in mine and len(survivors()) >= 2
    t0 = time.monotonic()
    child.stop()
    assert 0.4 < time.monotonic() - t0 < 5
    assert child.record(epoch=t0)["signal"] == "SIGKILL"
    assert not [p for p in survivors() if p[0] in mine]
    assert child.pid not in [pid for pid, _ in descendants()]


def test_grandchildren_left_by_a_child_that_exited_are_stopped_too(tmp_path):
    code = ("import subprocess, sys\n"
            "subprocess.Popen([sys.executable, '-c', 'import time; time.sleep(60)'])\n"
            "print('parent leaves', flush=True)\n")
    child = _launch(tmp_path, code, grace_s=1.0)
    assert child.wait(10)
    assert survivors(), "the grandchild should be running"
    child.stop()
    assert child.record(epoch=0.0)["ended_early"] is True
    assert not [p for p in survivors() if str(tmp_path) in p[1] or "time.sleep(60)" in p[1]]


def test_a_program_that_cannot_start_raises_oserror(tmp_path):
    child = Launcher("/nonexistent/backseat", subject="backseat", directory=tmp_path)
    with pytest.raises(OSError):
        child.start("/dev/pts/1")
    child.stop()  # nothing to stop: no error
    assert not os.path.exists(tmp_path / "missing")
