"""The contracts table "Failures and exit codes" (docs/contracts.md), one test per row.

Every failure is one line on stderr (``helmcheck COMMAND: …``) and the documented exit code,
never a traceback. Commands run in-process through :func:`helmcheck.cli.main` unless the row
needs a process of its own (a signal, a file-size limit, a device that vanishes); the runs
that take a whole session (signals on live runs) are in ``test_cli_signals.py``.
"""

from __future__ import annotations

import json
import os
import re
import resource
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from helmcheck.cli import main
from helmcheck.line.transport import PtyLink
from helmcheck.reports.results import load_results
from tests.faulty_vehicles import make_core, serve

ROOT = Path(__file__).resolve().parents[1]
LOGS = ROOT / "tests" / "fixtures" / "logs"
PASS_RUN = ROOT / "tests" / "fixtures" / "reports" / "pass_run"
TABLE_CODES = {0, 1, 2, 64}


def cli(argv: list[str], capsys) -> tuple[int, str, str]:
    code = main([str(a) for a in argv])
    cap = capsys.readouterr()
    return code, cap.out, cap.err


def one_line(err: str, prog: str) -> str:
    """stderr is exactly one line, from ``prog``, with no traceback; returns it."""
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1, err
    assert lines[0].startswith(prog + ": "), err
    assert "Traceback" not in err
    return lines[0]


def replay_file(tmp_path: Path, steps=()) -> Path:
    f = tmp_path / "replay.json"
    f.write_text(json.dumps({"format": "helmcheck-replay", "clause": "RH-ACK-1", "time_scale": 20,
                             "steps": list(steps)}))
    return f


def subprocess_cli(*args: str, timeout: float = 120, **kw) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "helmcheck", *args], capture_output=True, text=True,
                          timeout=timeout, stdin=subprocess.DEVNULL, **kw)


# ---------------------------------------------------------------------------- row: usage (64)

USAGE = {
    "parse": ["parse", "--bogus"],
    "emulate": ["emulate", "--baud", "fast"],
    "certify vehicle": ["certify", "vehicle"],
    "certify backseat": ["certify", "backseat", "--duration", "0"],
    "replay": ["replay"],
    "diff": ["diff", "--port", "/dev/null"],
    "check-log": ["check-log"],
    "monitor": ["monitor", "--tap", "pty"],
    "relay": ["relay", "--between", "pty", "pty", "--impair", "flip=often"],
    "report": ["report", "--format", "pdf", "x"],
    "docs": ["docs", "--bogus"],
}


@pytest.mark.parametrize("command", USAGE)
def test_row_usage_is_64_with_one_line(command, capsys):
    code, out, err = cli(USAGE[command], capsys)
    assert code == 64
    one_line(err, f"helmcheck {command}")


def test_row_usage_no_command_or_role_is_one_line(capsys):
    assert cli([], capsys)[0] == 64
    code, _, err = cli(["certify"], capsys)
    assert code == 64 and "choose a role" in one_line(err, "helmcheck certify")


# ---------------------------------------------------------------------------- row: unreadable or unwritable path (64)

def _path_cases(tmp: Path) -> dict:
    blocker = tmp / "a-file"
    blocker.write_text("x")
    bad_results = tmp / "bad-results"
    bad_results.mkdir()
    (bad_results / "results.json").write_text("{not json")
    return {
        "parse": (["parse", tmp / "missing.txt"], "missing.txt"),
        "emulate": (["emulate", "--log", tmp / "no-dir" / "wire.log"], "no-dir"),
        "certify vehicle": (["certify", "vehicle", "--port", "/dev/null", "--report-dir", blocker / "r"],
                            "a-file"),
        "certify backseat": (["certify", "backseat", "--report-dir", blocker / "r"], "a-file"),
        "replay": (["replay", tmp / "missing.json", "--port", "/dev/null"], "missing.json"),
        "check-log": (["check-log", LOGS / "make_logs.py", "--report-dir", tmp / "r"], "make_logs.py"),
        "report": (["report", bad_results], "results.json"),
    }


@pytest.mark.parametrize("command", ["parse", "emulate", "certify vehicle", "certify backseat", "replay",
                                     "check-log", "report"])
def test_row_unreadable_or_unwritable_path_is_64_naming_it(command, tmp_path, capsys):
    argv, name = _path_cases(tmp_path)[command]
    code, out, err = cli(argv, capsys)
    assert code == 64, err
    assert name in one_line(err, f"helmcheck {command}")
    assert not (tmp_path / "r").exists()


PORT_COMMANDS = {
    "emulate": lambda port, tmp: ["emulate", "--port", port],
    "certify vehicle": lambda port, tmp: ["certify", "vehicle", "--port", port, "--report-dir", tmp / "r"],
    "certify backseat": lambda port, tmp: ["certify", "backseat", "--port", port, "--report-dir", tmp / "r"],
    "replay": lambda port, tmp: ["replay", replay_file(tmp), "--port", port],
    "diff": lambda port, tmp: ["diff", "--port", port, "--port", port, "--report-dir", tmp / "r"],
    "monitor": lambda port, tmp: ["monitor", "--between", "pty", port, "--report-dir", tmp / "r"],
    "relay": lambda port, tmp: ["relay", "--between", "pty", port, "--wire-log", tmp / "r"],
}


@pytest.mark.parametrize("port", ["/dev/helmcheck-no-such-device", "nosuchscheme://somewhere"])
@pytest.mark.parametrize("command", PORT_COMMANDS)
def test_row_path_a_port_that_cannot_be_opened_is_64_in_every_command(command, port, tmp_path, capsys):
    """A missing device and an unknown URL scheme are the same class everywhere: 64, nothing written."""
    code, out, err = cli(PORT_COMMANDS[command](port, tmp_path), capsys)
    assert code == 64
    assert f"cannot open {port}: " in one_line(err, f"helmcheck {command}")
    assert not (tmp_path / "r").exists()


def test_row_path_an_earlier_run_is_refused_without_overwrite_and_cleared_with_it(tmp_path, capsys):
    rdir = tmp_path / "r"
    log = LOGS / "nominal.log"
    assert cli(["check-log", log, "--report-dir", rdir], capsys)[0] == 0
    stale = [rdir / "replays" / "RH-SRV-4-1.json", rdir / "capture-socat.log"]
    stale[0].parent.mkdir()
    for f in stale:
        f.write_text("from an earlier run")
    (rdir / "notes.txt").write_text("mine")
    before = (rdir / "results.json").read_bytes()
    code, _, err = cli(["check-log", log, "--report-dir", rdir], capsys)
    assert code == 64 and "--overwrite" in one_line(err, "helmcheck check-log")
    assert (rdir / "results.json").read_bytes() == before and all(f.exists() for f in stale)
    assert cli(["check-log", log, "--report-dir", rdir, "--overwrite"], capsys)[0] == 0
    assert not any(f.exists() for f in stale) and not (rdir / "replays").exists()
    assert (rdir / "notes.txt").read_text() == "mine" and (rdir / "report.html").exists()
    # the certifiers refuse it before opening any port
    for argv in (["certify", "vehicle", "--port", "/dev/helmcheck-no-such-device"], ["certify", "backseat"]):
        code, _, err = cli([*argv, "--report-dir", rdir], capsys)
        assert code == 64 and "holds an earlier run" in err and "--overwrite" in err


# ---------------------------------------------------------------------------- row: bad profile value (64)

PROFILE_COMMANDS = {
    "parse": lambda prof, tmp: ["parse", "--profile", prof, LOGS / "nominal.log"],
    "emulate": lambda prof, tmp: ["emulate", "--profile", prof],
    "certify vehicle": lambda prof, tmp: ["certify", "vehicle", "--port", "/dev/null", "--profile", prof,
                                          "--report-dir", tmp / "r"],
    "certify backseat": lambda prof, tmp: ["certify", "backseat", "--profile", prof, "--report-dir", tmp / "r"],
    "replay": lambda prof, tmp: ["replay", replay_file(tmp), "--port", "/dev/null", "--profile", prof],
    "check-log": lambda prof, tmp: ["check-log", LOGS / "nominal.log", "--profile", prof, "--report-dir", tmp / "r"],
    "monitor": lambda prof, tmp: ["monitor", "--tap", "pty", "pty", "--profile", prof, "--report-dir", tmp / "r"],
}


@pytest.mark.parametrize("line", ["ack_window_s = nan", "lockout_s = inf", "time_scale = -inf"])
@pytest.mark.parametrize("command", PROFILE_COMMANDS)
def test_row_profile_non_finite_numbers_are_64_naming_file_and_key(command, line, tmp_path, capsys):
    prof = tmp_path / "p.toml"
    prof.write_text(line + "\n")
    code, out, err = cli(PROFILE_COMMANDS[command](prof, tmp_path), capsys)
    assert code == 64
    msg = one_line(err, f"helmcheck {command}")
    assert str(prof) in msg and line.split()[0] in msg and "finite" in msg
    assert not (tmp_path / "r").exists()


# ---------------------------------------------------------------------------- row: link fault (2)

def test_row_link_fault_certify_vehicle_on_a_silent_line_is_2_with_a_report(tmp_path, capsys):
    link = PtyLink(baud=19200)  # a port that opens and carries nothing
    try:
        code, out, err = cli(["certify", "vehicle", "--port", link.name, "--report-dir", tmp_path / "r",
                              "--examples", "0", "--no-progress"], capsys)
    finally:
        link.close()
    assert code == 2 and out.startswith("INCONCLUSIVE"), (out, err)
    r = load_results(tmp_path / "r")
    assert r["verdict"] == "inconclusive" and (tmp_path / "r" / "report.html").exists()


def _closing_server() -> tuple[socket.socket, threading.Thread]:
    """A TCP serial server that accepts one client, reads a little, and hangs up."""
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(1)

    def serve_once():
        conn, _ = srv.accept()
        conn.settimeout(2.0)
        try:
            conn.recv(64)
        except OSError:
            pass
        conn.close()

    th = threading.Thread(target=serve_once, daemon=True)
    th.start()
    return srv, th


def test_row_link_fault_replay_when_the_vehicle_hangs_up_is_2(tmp_path, capsys):
    srv, th = _closing_server()
    try:
        rep = replay_file(tmp_path, [{"send": "$OSD,S*27\\r\\n"}, {"wait": 1.0}, {"send": "$OSD,S*27\\r\\n"}])
        code, out, err = cli(["replay", rep, "--port", f"socket://127.0.0.1:{srv.getsockname()[1]}"], capsys)
    finally:
        srv.close()
    assert code == 2 and out.startswith("INCONCLUSIVE: link fault"), (out, err)


def test_row_link_fault_emulate_on_a_device_that_vanishes_is_2(tmp_path):
    master, slave = os.openpty()
    device = os.ttyname(slave)
    proc = subprocess.Popen([sys.executable, "-m", "helmcheck", "emulate", "--port", device],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL)
    try:
        assert proc.stdout.readline().decode().startswith(f"port: {device}")
        os.close(slave)
        os.close(master)  # the device goes away under the running emulator
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 2
    assert "link fault" in one_line(err.decode().split("\n", 1)[1], "helmcheck emulate")


def test_row_link_fault_certify_backseat_peer_gone_is_2_with_a_partial_report(tmp_path):
    proc = subprocess.Popen([sys.executable, "-m", "helmcheck", "certify", "backseat", "--port",
                             "socket://127.0.0.1:0", "--report-dir", str(tmp_path / "r"), "--duration", "30"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL)
    try:
        port = proc.stdout.readline().decode().split("socket://", 1)[1].strip()
        host, num = port.rsplit(":", 1)
        with socket.create_connection((host, int(num))) as s:
            s.sendall(b"$OSD,S*27\r\n")
            time.sleep(1.0)
        out, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 2, err
    assert out.decode().startswith("INCONCLUSIVE — partial:")
    assert load_results(tmp_path / "r")["partial"] and (tmp_path / "r" / "report.html").exists()


# ---------------------------------------------------------------------------- row: tester error (2)

def _boom(*_a, **_k):
    raise RuntimeError("boom from a tester bug")


TESTER_BUG = {  # (argv, the function a bug is planted in)
    "parse": (["parse", LOGS / "nominal.log"], "helmcheck.profile.load_profile"),
    "emulate": (["emulate"], "helmcheck.profile.load_profile"),
    "certify vehicle": (["certify", "vehicle", "--port", "/dev/null"], "helmcheck.profile.load_profile"),
    "certify backseat": (["certify", "backseat"], "helmcheck.profile.load_profile"),
    "replay": (["replay", "REPLAY", "--port", "/dev/null"], "helmcheck.certify.vehicle.replay.load_replay"),
    "check-log": (["check-log", LOGS / "nominal.log"], "helmcheck.checklog.checker.check_log"),
    "monitor": (["monitor", "--tap", "pty", "pty"], "helmcheck.profile.load_profile"),
    "report": (["report", PASS_RUN], "helmcheck.reports.rundir.load_run"),
    "docs": (["docs", "--check"], "helmcheck.grammar.docs.render_markdown"),
}


@pytest.mark.parametrize("command", TESTER_BUG)
def test_row_tester_error_is_2_with_the_traceback_in_a_file(command, tmp_path, capsys, monkeypatch):
    argv, target = TESTER_BUG[command]
    argv = [replay_file(tmp_path) if a == "REPLAY" else a for a in argv]
    module, name = target.rsplit(".", 1)
    monkeypatch.setattr(sys.modules[module] if module in sys.modules else __import__(module, fromlist=[name]),
                        name, _boom)
    monkeypatch.chdir(tmp_path)
    code, out, err = cli(argv, capsys)
    assert code == 2
    msg = one_line(err, f"helmcheck {command}")
    m = re.search(r"tester error: RuntimeError: boom from a tester bug — traceback in (\S+); please report it",
                  msg)
    assert m, msg
    saved = Path(m.group(1))
    try:
        text = saved.read_text()
        assert "Traceback" in text and "boom from a tester bug" in text and "_boom" in text
    finally:
        saved.unlink()


def test_row_tester_error_mid_run_leaves_partial_results_and_the_traceback_beside_them(tmp_path, capsys,
                                                                                        monkeypatch):
    from helmcheck.certify.vehicle import runner as runner_mod

    monkeypatch.setattr(runner_mod, "run_case", _boom)
    with serve(lambda start: make_core(None, 20.0, start)) as port:
        prof = tmp_path / "emu.toml"
        prof.write_text('fault_injection = "oxflt"\n')
        code, out, err = cli(["certify", "vehicle", "--port", port, "--time-scale", "20", "--profile", prof,
                              "--report-dir", tmp_path / "r", "--examples", "0", "--no-progress",
                              "--select", "RH-ACK-1"], capsys)
    assert code == 2
    assert f"traceback in {tmp_path / 'r' / 'tester-error.txt'}" in one_line(err, "helmcheck certify vehicle")
    r = load_results(tmp_path / "r")
    assert r["partial"] and r["verdict"] != "pass" and "tester error" in r["verdict_reason"].lower()


# ---------------------------------------------------------------------------- row: interrupted (2; emulate 0)

def test_row_interrupted_parse_is_2_with_one_line(capsys, monkeypatch):
    r, w = os.pipe()  # standard input that never ends
    stdin = os.fdopen(r, "rb", buffering=0)

    class In:
        buffer = stdin

    monkeypatch.setattr(sys, "stdin", In)
    timer = threading.Timer(1.0, os.kill, (os.getpid(), signal.SIGTERM))
    timer.start()
    try:
        os.write(w, b"$OMSTOP,0*06\r\n")
        code, out, err = cli(["parse", "-"], capsys)
    finally:
        timer.cancel()
        os.close(w)
        stdin.close()
    assert code == 2
    assert "interrupted (SIGTERM)" in one_line(err, "helmcheck parse")
    assert signal.getsignal(signal.SIGTERM) == signal.SIG_DFL  # handlers are put back


# ---------------------------------------------------------------------------- row: output not written (2)

def test_row_output_parse_to_a_full_device_is_2_naming_standard_output(tmp_path):
    with open("/dev/full", "w") as full:
        p = subprocess.run([sys.executable, "-m", "helmcheck", "parse", "--json", str(LOGS / "nominal.log")],
                           stdout=full, stderr=subprocess.PIPE, text=True, timeout=60)
    assert p.returncode == 2
    assert "cannot write standard output: No space left on device" in one_line(p.stderr, "helmcheck parse")


@pytest.mark.parametrize("content, json_mode, want", [
    (b"$OMSTOP,0*06\r\n" * 50000, True, 0),  # parse --json … | head -1: quiet, exit 0
    (b"$OMSTOP,0*07\r\n" * 50000, False, 1),  # invalid lines were reported before the cut
], ids=["json", "invalid-lines"])
def test_row_output_a_reader_that_goes_away_ends_parse_quietly(tmp_path, content, json_mode, want):
    f = tmp_path / "cap.txt"
    f.write_bytes(content)
    proc = subprocess.Popen([sys.executable, "-m", "helmcheck", "parse", *(["--json"] if json_mode else []), str(f)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    first = proc.stdout.readline()
    proc.stdout.close()  # like head -1
    err = proc.stderr.read().decode()
    assert proc.wait(60) == want, err
    assert first and "Traceback" not in err and "Broken pipe" not in err
    if not json_mode:
        assert "standard output closed" in err


def test_row_output_emulate_log_on_a_full_device_is_2(capsys):
    code, out, err = cli(["emulate", "--log", "/dev/full"], capsys)
    assert code == 2
    assert "cannot write wire log /dev/full: No space left on device" in one_line(err, "helmcheck emulate")


def _file_size_limit(limit: int):
    def pre():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    return pre


def test_row_output_emulate_settings_that_cannot_be_saved_stop_it_with_2(tmp_path):
    from helmcheck.emulator.process import HelmClient
    from helmcheck.line.transport import open_link

    settings_file = tmp_path / "settings.json"
    proc = subprocess.Popen([sys.executable, "-m", "helmcheck", "emulate", "--settings", str(settings_file)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL,
                            preexec_fn=_file_size_limit(64))  # the settings file is larger
    try:
        port = proc.stdout.readline().decode().split(": ", 1)[1].strip()
        client = HelmClient(open_link(port, role="client", baud=19200))
        client.send("ORWSET,Sop,W,1,45")
        _, err = proc.communicate(timeout=60)
        client.link.close()
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 2
    assert f"cannot write settings {settings_file}: File too large" in err.decode()
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]


def test_row_output_certify_vehicle_wire_log_copy_on_a_full_device_is_2(tmp_path, capsys):
    prof = tmp_path / "emu.toml"
    prof.write_text('fault_injection = "oxflt"\n')
    with serve(lambda start: make_core(None, 20.0, start)) as port:
        code, out, err = cli(["certify", "vehicle", "--port", port, "--time-scale", "20", "--profile", prof,
                              "--report-dir", tmp_path / "r", "--examples", "0", "--no-progress",
                              "--select", "RH-ACK-1", "--wire-log", "/dev/full"], capsys)
    assert out.startswith("PASS"), out  # the verdict line first …
    assert code == 2  # … but a promised file was not written
    assert "cannot write wire log copy /dev/full: No space left on device" in one_line(
        err, "helmcheck certify vehicle")
    assert (tmp_path / "r" / "report.html").exists()


def test_row_output_certify_backseat_wire_log_copy_on_a_full_device_is_2(tmp_path, capsys):
    code, out, err = cli(["certify", "backseat", "--connect-timeout", "0.3", "--report-dir", tmp_path / "r",
                          "--wire-log", "/dev/full"], capsys)
    assert code == 2
    lines = [ln for ln in err.splitlines() if "cannot write" in ln]
    assert lines == ["helmcheck certify backseat: cannot write wire log copy /dev/full: No space left on device"]


def test_row_output_check_log_copy_on_a_full_disk_is_2_and_leaves_no_temporary_file(tmp_path):
    log = LOGS / "nominal.log"
    p = subprocess_cli("check-log", str(log), "--report-dir", str(tmp_path / "r"),
                       preexec_fn=_file_size_limit(log.stat().st_size // 2))
    assert p.returncode == 2, p.stderr
    line = one_line(p.stderr, "helmcheck check-log")
    assert f"cannot write {tmp_path / 'r' / 'wire.log'}: File too large" in line
    assert not [f for f in (tmp_path / "r").iterdir() if f.name.endswith(".tmp")]


def test_row_output_report_that_cannot_be_written_is_2(tmp_path, capsys):
    d = tmp_path / "run"
    shutil.copytree(PASS_RUN, d)
    (d / "report.html").mkdir()  # a directory where the report goes (even root cannot replace it)
    code, out, err = cli(["report", d], capsys)
    assert code == 2 and "report.html" in one_line(err, "helmcheck report")


# ---------------------------------------------------------------------------- the whole table, fuzzed

COMMANDS = ["parse", "emulate", "certify vehicle", "certify backseat", "replay", "check-log", "report", "docs"]
OPTIONS = {
    "parse": ["--json", "--profile"],
    "emulate": ["--port", "--baud", "--profile", "--time-scale", "--missions", "--log", "--main-log", "--settings",
                "--no-fault-injection"],
    "certify vehicle": ["--port", "--profile", "--time-scale", "--baud", "--report-dir", "--select", "--examples",
                        "--seed", "--strict", "--wire-log", "--overwrite", "--no-progress", "--json", "--missions"],
    "certify backseat": ["--port", "--profile", "--duration", "--time-scale", "--scenario", "--report-dir",
                         "--strict", "--wire-log", "--connect-timeout", "--baud", "--overwrite"],
    "replay": ["--port", "--profile", "--time-scale", "--wire-log"],
    "check-log": ["--profile", "--report-dir", "--role", "--missions", "--time-scale", "--swap-directions",
                  "--strict", "--no-render", "--overwrite"],
    "report": ["--format", "--compare"],
    "docs": ["--check"],
}
#: Ports that must be refused at once: missing devices, unknown schemes, malformed specs.
bad_ports = st.one_of(
    st.from_regex(r"/nonexistent-[a-z0-9]{1,8}(/[a-z]{1,4})?", fullmatch=True),
    st.from_regex(r"[a-z]{2,6}zz://[a-z0-9.:]{0,12}", fullmatch=True),
    st.text(st.characters(codec="ascii", exclude_characters="/\x00"), max_size=12).filter(
        lambda s: s != "pty" and "://" not in s),
    st.just("socket://localhost"),
)
junk = st.one_of(st.text(max_size=16).filter(lambda s: "\x00" not in s), st.sampled_from(
    ["0", "-1", "nan", "inf", "1e400", "19200", "RH-*", "both", "html,md", "", "-", "--"]))
file_bodies = st.one_of(
    st.binary(max_size=300),
    st.sampled_from([b"ack_window_s = nan\n", b"lockout_s = inf\n", b"[bench_safety]\nin_water = 3\n",
                     b"# helmcheck wire-log 1\n0.000000 > $OSD,S*27\n0.1 < $ACK,8,0,0*5D\n",
                     b'{"schema": 1}', b'{"format": "helmcheck-replay", "steps": [{"send": 1}]}',
                     b'{"format": "helmcheck-replay", "steps": [], "profile": []}',
                     b"0.5 >~ \\x00\\xff junk\n", b"$OMSTOP,0*06\r\n"]),
)


@st.composite
def argvs(draw, tmp: Path):
    command = draw(st.sampled_from(COMMANDS))
    files = []
    for i in range(draw(st.integers(0, 2))):
        f = tmp / f"in{i}.txt"
        f.write_bytes(draw(file_bodies))
        files.append(str(f))
    rdir = tmp / "results"
    if draw(st.booleans()):
        rdir.mkdir(exist_ok=True)
        (rdir / "results.json").write_bytes(draw(file_bodies))
    nominal = tmp / "nominal.log"  # a copy: an output option may name any file of the pool
    shutil.copyfile(LOGS / "nominal.log", nominal)
    pool = files + [str(rdir), str(tmp / "missing"), str(nominal)]
    argv = command.split()
    existing = files + [str(nominal)] + ([str(rdir)] if rdir.is_dir() else [])
    if command in ("parse", "check-log", "report", "replay") and draw(st.integers(0, 3)):
        argv.append(draw(st.sampled_from(existing)))  # mostly a file that exists: the command runs
    for _ in range(draw(st.sampled_from([0, 0, 1, 1, 2, 3, 4]))):
        opt = draw(st.sampled_from(OPTIONS[command] + ["--bogus"]))
        argv.append(opt)
        if opt in ("--port",):
            argv.append(draw(bad_ports))
        elif opt in ("--profile", "--log", "--main-log", "--settings", "--missions", "--wire-log", "--report-dir",
                     "--compare"):
            argv.append(draw(st.sampled_from(pool)))
        elif opt not in ("--json", "--strict", "--overwrite", "--no-progress", "--no-render",
                         "--swap-directions", "--check", "--no-fault-injection", "--bogus"):
            argv.append(draw(junk))
    if command in ("emulate", "certify vehicle", "certify backseat", "replay") and "--port" not in argv:
        argv += ["--port", draw(bad_ports)]  # never a real port: a pty or a socket would be served
    if command == "docs" and "--check" not in argv:
        argv.append("--check")  # never rewrite the checked-in docs
    if draw(st.integers(0, 3)) == 0:
        argv += draw(st.lists(st.sampled_from(pool), max_size=2))
    return argv


class _Hung(BaseException):
    """A call that did not return in time (not an Exception: the command line must not catch it)."""


@settings(max_examples=150, deadline=None, suppress_health_check=list(HealthCheck))
@given(data=st.data())
def test_random_argv_and_files_never_give_a_traceback_or_a_code_outside_the_table(data, tmp_path_factory, capsys):
    tmp = tmp_path_factory.mktemp("fuzz")
    argv = data.draw(argvs(tmp), label="argv")
    old = signal.signal(signal.SIGALRM, lambda *_: (_ for _ in ()).throw(_Hung(" ".join(argv))))
    cwd = os.getcwd()
    os.chdir(tmp)  # check-log's default report directory lands here
    signal.setitimer(signal.ITIMER_REAL, 10.0)
    try:
        code = main(argv)
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
        os.chdir(cwd)
    cap = capsys.readouterr()
    event(f"{' '.join(argv[:2]) if argv[0] == 'certify' else argv[0]} -> {code}")
    assert code in TABLE_CODES, (argv, code, cap.err)
    assert "Traceback" not in cap.err and "tester error" not in cap.err, (argv, cap.err)
    if code == 64:
        assert len([ln for ln in cap.err.splitlines() if ln.strip()]) == 1, (argv, cap.err)
