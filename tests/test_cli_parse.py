"""``helmcheck parse``: per-line verdicts, JSON output, wire logs, exit codes 0/1/64."""

from __future__ import annotations

import json
import subprocess
import sys


def run(*args, stdin=b""):
    p = subprocess.run([sys.executable, "-m", "helmcheck", "parse", *args], input=stdin,
                       capture_output=True, timeout=60)
    return p.returncode, p.stdout.decode(), p.stderr.decode()


def test_valid_stdin_exits_0():
    rc, out, _ = run("-", stdin=b"$OMSTOP,0*06\r\n$ACK,8,0,0*5D\r\n")
    assert rc == 0 and out == ""


def test_invalid_line_prints_file_line_clause_and_exits_1(tmp_path):
    f = tmp_path / "cap.txt"
    f.write_bytes(b"$OMSTOP,0*06\r\n$ACK,8,0,0*5C\r\n")
    rc, out, _ = run(str(f))
    assert rc == 1
    assert out.strip() == f"{f}:2: RH-FRM-2: checksum 5C does not match computed 5D at column 12"


def test_json_one_object_per_line_with_wire_log_records(tmp_path):
    f = tmp_path / "wire.log"
    f.write_text("# helmcheck wire-log 1\n0.000000 > $OMSTOP,0*06\n0.100000 < $ACK,1,0,0*54\n"
                 "0.2 ! a note\n0.300000 >~ junk\\x00\n")
    rc, out, _ = run("--json", str(f))
    objs = [json.loads(x) for x in out.splitlines()]
    assert rc == 1 and len(objs) == 3
    assert objs[0]["type"] == "OMSTOP" and objs[0]["valid"] and objs[0]["direction"] == ">"
    assert objs[1]["fields"] == {"type": 1, "status": 0, "err": 0, "extra": []}
    assert not objs[2]["valid"] and objs[2]["errors"][0]["clause"] == "RH-FRM-7"


def test_usage_errors_exit_64(tmp_path):
    assert run("--nope")[0] == 64
    assert run(str(tmp_path / "missing.txt"))[0] == 64
    bad = tmp_path / "p.toml"
    bad.write_text("nonsense = 1")
    rc, _, err = run("--profile", str(bad), "-")
    assert rc == 64 and "unknown key 'nonsense'" in err
