"""``certify backseat --exec`` and ``certify vehicle --exec`` end to end: helmcheck starts the
implementation under test itself, captures its output, stops it, and judges its exit.

Every run is the real command line (``python -m helmcheck certify …``) in a subprocess, all at
once, at time scale 5 (backseats: the example backseat of ``tests/backseats``) or 25 (vehicles:
the emulator, and ``tests/faulty_vehicles/dying_vehicle.py`` which crashes on purpose), so the
module takes about 25 s. After every run no process helmcheck started may be left (``/proc``).
"""

from __future__ import annotations

import shlex
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

from helmcheck.reports.results import load_results
from tests.processes import survivors

HERE = Path(__file__).resolve().parent
GOOD = HERE / "backseats" / "good_backseat.py"
DYING = HERE / "faulty_vehicles" / "dying_vehicle.py"
PY = shlex.quote(sys.executable)
BACKSEAT = f"{PY} {shlex.quote(str(GOOD))} {{port}} --time-scale {{time_scale}}"
EMULATE = f"{PY} -m helmcheck emulate --port {{port}} --time-scale {{time_scale}} --baud 115200"
BS = ("--time-scale", "5", "--connect-timeout", "20")
VH = ("--time-scale", "25", "--baud", "115200", "--examples", "0", "--no-progress")

#: name -> helmcheck arguments (the report directory is added)
JOBS = {
    "bs-good": ("certify", "backseat", *BS, "--duration", "20", "--exec", BACKSEAT),
    "bs-crash": ("certify", "backseat", *BS, "--duration", "20", "--exec", BACKSEAT + " --crash-after 2"),
    "bs-tcp": ("certify", "backseat", *BS, "--duration", "4", "--scenario", "nominal",
               "--port", "socket://127.0.0.1:0", "--exec", BACKSEAT),
    "bs-exit0": ("certify", "backseat", *BS, "--duration", "20",
                 "--exec", f"{PY} -c \"print('no backseat today')\""),
    "vh-good": ("certify", "vehicle", *VH, "--select", "RH-FRM-*", "--exec", EMULATE),
    "vh-tcp": ("certify", "vehicle", *VH, "--select", "RH-ACK-1,RH-OUT-1", "--port", "socket://127.0.0.1:0",
               "--exec", f"{PY} -m helmcheck emulate --port {{port}} --time-scale {{time_scale}} --baud 0"),
    "vh-dies": ("certify", "vehicle", *VH, "--select", "RH-SRV-*,RH-INT-*,RH-PRM-*",
                "--exec", f"{PY} {shlex.quote(str(DYING))} --after 1.5 --time-scale {{time_scale}}"),
    "vh-never-opens": ("certify", "vehicle", *VH, "--exec", f"{PY} -c 'import time; time.sleep(60)'",
                       "--exec-ready", "1.5", "--exec-grace", "1"),
}


def _run(root: Path, name: str, argv: tuple[str, ...]) -> dict:
    report = root / name
    proc = subprocess.run([sys.executable, "-m", "helmcheck", *argv, "--report-dir", str(report)],
                          stdin=subprocess.DEVNULL, capture_output=True, text=True, timeout=180)
    left = survivors()
    return {"rc": proc.returncode, "out": proc.stdout, "err": proc.stderr, "dir": report,
            "results": load_results(report), "left": left}


#: The module-scoped run below is made once: all of this module's tests go to one worker.
pytestmark = pytest.mark.xdist_group("test_certify_exec")


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("exec")
    with ThreadPoolExecutor(max_workers=len(JOBS)) as pool:
        futures = {name: pool.submit(_run, root, name, argv) for name, argv in JOBS.items()}
        out = {name: f.result() for name, f in futures.items()}
    assert not survivors(), "a process started by helmcheck outlived its run"
    return out


def _clauses(run: dict) -> dict[str, dict]:
    return {c["id"]: c for c in run["results"]["clauses"]}


def _no_traceback(run: dict) -> None:
    assert "Traceback" not in run["err"], run["err"]


def test_backseat_started_with_exec_passes_and_is_stopped_at_the_end(runs):
    run = runs["bs-good"]
    r = run["results"]
    assert r["verdict"] == "pass" and run["rc"] == 0 and not r["partial"], (r["verdict_reason"], run["err"])
    p = r["process"]
    assert p["ended_early"] is False and p["signal"] == "SIGTERM" and p["exit_code"] is None
    assert shlex.split(p["command"])[2].startswith("/dev/pts/")  # {port} became the pty path
    assert p["output_tail"][0].startswith("good_backseat: driving /dev/pts/")
    assert p["ended_at_s"] >= r["run"]["ended_at"]
    assert (run["dir"] / "backseat.stdout.log").read_text().startswith("good_backseat: driving")
    assert (run["dir"] / "backseat.stderr.log").exists()
    assert "Process under test" in (run["dir"] / "report.html").read_text()
    assert run["out"].startswith("port: /dev/pts/")
    _no_traceback(run)


def test_backseat_that_exits_after_2_s_fails_with_its_exit_quoted(runs):
    """The exit is a finding about the backseat (FAIL), never a link-fault INCONCLUSIVE."""
    run = runs["bs-crash"]
    r = run["results"]
    p = r["process"]
    assert p["exit_code"] == 3 and p["signal"] is None and p["ended_early"] is True
    assert 1.5 < p["ended_at_s"] < 10
    assert p["output_tail"][-1] == "good_backseat: crashing on purpose after 2 s"
    assert r["verdict"] == "fail" and run["rc"] == 1
    assert "exited with code 3" in r["verdict_reason"] and "crashing on purpose" in r["verdict_reason"]
    assert "inconclusive" not in {c["verdict"] for c in r["clauses"]}
    cut = [c for c in r["clauses"] if c["verdict"] == "not-tested"]
    assert cut and all(c["reason"].startswith("the backseat exited with code 3") for c in cut)
    assert all(c["verdict"] == "not-tested" for c in r["clauses"])  # even nominal had not finished
    md = (run["dir"] / "report.md").read_text()
    assert "crashing on purpose" in md and "**FAIL**" in md
    assert run["out"].splitlines()[-2].startswith("FAIL")
    assert run["out"].splitlines()[-1] == f"report: {run['dir'] / 'report.html'}"
    _no_traceback(run)


def test_backseat_on_a_tcp_port_gets_the_socket_url(runs):
    run = runs["bs-tcp"]
    r = run["results"]
    assert r["verdict"] == "pass" and run["rc"] == 0, (r["verdict_reason"], run["err"])
    assert shlex.split(r["process"]["command"])[2].startswith("socket://127.0.0.1:")
    assert r["process"]["ended_early"] is False


def test_backseat_that_exits_with_code_0_before_connecting_fails_too(runs):
    run = runs["bs-exit0"]
    r = run["results"]
    p = r["process"]
    assert p["exit_code"] == 0 and p["ended_early"] is True and p["output_tail"] == ["no backseat today"]
    assert r["verdict"] == "fail" and run["rc"] == 1
    assert "exited with code 0" in r["verdict_reason"] and "no backseat today" in r["verdict_reason"]
    assert r["run"]["status"] == "exited" and r["run"]["ended_at"] < 10  # not the 20 s connect timeout
    _no_traceback(run)


def test_vehicle_started_with_exec_passes(runs):
    run = runs["vh-good"]
    r = run["results"]
    assert r["verdict"] == "pass" and run["rc"] == 0, (r["verdict_reason"], run["err"])
    assert {c["id"] for c in r["clauses"] if c["verdict"] == "pass"} >= {"RH-FRM-2", "RH-FRM-4"}
    p = r["process"]
    assert p["ended_early"] is False and p["exit_code"] == 0  # the emulator stops cleanly on SIGTERM
    assert "port: /dev/pts/" in (run["dir"] / "vehicle.stdout.log").read_text()
    assert any(ln.startswith("helmcheck emulate: stopped") for ln in p["output_tail"])
    _no_traceback(run)


def test_vehicle_on_a_tcp_port_is_connected_to_once_it_listens(runs):
    run = runs["vh-tcp"]
    r = run["results"]
    assert r["verdict"] == "pass" and run["rc"] == 0, (r["verdict_reason"], run["err"])
    assert "socket://127.0.0.1:" in r["process"]["command"]
    assert _clauses(run)["RH-ACK-1"]["verdict"] == "pass"


def test_vehicle_that_dies_mid_run_fails_and_unrun_clauses_are_not_tested(runs):
    run = runs["vh-dies"]
    r = run["results"]
    p = r["process"]
    assert p["exit_code"] == 5 and p["ended_early"] is True
    assert p["output_tail"][-1] == "dying_vehicle: giving up after 1.5 s"
    assert r["verdict"] == "fail" and run["rc"] == 1
    assert "The vehicle under test exited with code 5" in r["verdict_reason"]
    selected = {cid: c for cid, c in _clauses(run).items() if cid.split("-")[1] in ("SRV", "INT", "PRM")}
    assert {c["verdict"] for c in selected.values()} <= {"pass", "not-tested"}  # never a link fault
    cut = [c for c in selected.values() if c["verdict"] == "not-tested"]
    assert cut and all(c["reason"].startswith(("the vehicle under test exited with code 5", "V-"))
                       and "exited with code 5" in c["reason"] for c in cut)
    _no_traceback(run)


def test_vehicle_that_never_opens_its_port_is_inconclusive_and_stopped(runs):
    run = runs["vh-never-opens"]
    r = run["results"]
    assert r["verdict"] == "inconclusive" and run["rc"] == 2
    assert "did not open /dev/pts/" in r["verdict_reason"] or any(
        "did not open /dev/pts/" in c["reason"] for c in r["clauses"])
    p = r["process"]
    assert p["ended_early"] is False and p["signal"] == "SIGTERM"
    _no_traceback(run)


@pytest.mark.parametrize("argv, message", [
    (("certify", "backseat", "--exec", "no-such-backseat-xyz {port}"), "--exec: no-such-backseat-xyz: command not found"),
    (("certify", "backseat", "--exec", "'unclosed"), "--exec: cannot split"),
    (("certify", "vehicle", "--exec", ""), "--exec: the command is empty"),
    (("certify", "vehicle"), "--port is required (or --exec CMD"),
    (("certify", "vehicle", "--port", "pty"), "or --exec CMD to start the vehicle on it"),
    (("certify", "vehicle", "--exec", "true", "--exec-grace", "0"), "--exec-grace must be a positive"),
])
def test_bad_exec_arguments_are_usage_errors(argv, message, tmp_path):
    proc = subprocess.run([sys.executable, "-m", "helmcheck", *argv, "--report-dir", str(tmp_path / "r")],
                          stdin=subprocess.DEVNULL, capture_output=True, text=True, timeout=60)
    assert proc.returncode == 64, proc.stderr
    assert message in proc.stderr and "Traceback" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize("role", ["vehicle", "backseat"])
def test_sigterm_to_helmcheck_stops_the_started_implementation_too(role, tmp_path):
    """A cancelled CI job: helmcheck gets SIGTERM mid-run, writes a partial report, exits 2, and
    the implementation it started is gone with it."""
    import signal
    import time

    report = tmp_path / "r"
    if role == "vehicle":
        argv = ["certify", "vehicle", *VH, "--exec", EMULATE]
        ready = report / "vehicle.stdout.log"
    else:
        argv = ["certify", "backseat", *BS, "--duration", "60", "--exec", BACKSEAT]
        ready = report / "backseat.stdout.log"
    proc = subprocess.Popen([sys.executable, "-m", "helmcheck", *argv, "--report-dir", str(report)],
                            stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and not (ready.exists() and ready.read_text().strip()):
            time.sleep(0.1)
        time.sleep(1.0)
        assert survivors(), "the implementation should be running"
        proc.send_signal(signal.SIGTERM)
        out, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 2, err
    r = load_results(report)
    assert r["partial"] and r["verdict"] == "inconclusive"
    assert r["process"]["ended_early"] is False
    assert not survivors()
    assert "Traceback" not in err
