"""``helmcheck emulate`` argument handling: bad arguments and profiles exit 64 with one line."""

from __future__ import annotations

import subprocess
import sys

import pytest


def run(*args: str, timeout: float = 60.0) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "helmcheck", "emulate", *args], capture_output=True,
                          text=True, timeout=timeout, stdin=subprocess.DEVNULL)


@pytest.mark.parametrize("args, words", [
    (["--time-scale", "0"], "--time-scale"),
    (["--time-scale", "-2"], "--time-scale"),
    (["--time-scale", "nan"], "--time-scale"),
    (["--baud", "1234"], "--baud"),
    (["--port", "ttyS0"], "--port"),
    (["--port", "socket://localhost"], "--port"),
    (["--port", "/dev/ttyUSB0", "--baud", "0"], "--baud 0"),
    (["--missions", "/nonexistent/dir"], "--missions"),
    (["--log", "/nonexistent/dir/wire.log"], "cannot write"),
])
def test_bad_arguments_exit_64_with_one_line(args, words):
    r = run(*args)
    assert r.returncode == 64, r.stderr
    assert r.stdout == ""
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and words in lines[0] and "Traceback" not in r.stderr


def test_malformed_profile_names_file_and_key(tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text('lockout_s = "long"\n')
    r = run("--profile", str(p))
    assert r.returncode == 64
    assert str(p) in r.stderr and "lockout_s" in r.stderr and len(r.stderr.strip().splitlines()) == 1
    p.write_text("no_such_key = 1\n")
    r = run("--profile", str(p))
    assert r.returncode == 64 and "no_such_key" in r.stderr


def test_argparse_usage_errors_exit_64():
    r = run("--baud", "fast")
    assert r.returncode == 64 and "Traceback" not in r.stderr


def test_missing_device_exits_64():
    r = run("--port", "/dev/does-not-exist-helmcheck")
    assert r.returncode == 64 and "cannot open" in r.stderr and "Traceback" not in r.stderr
