"""SIGTERM and SIGHUP end a live run like Ctrl-C (docs/contracts.md, row "interrupted").

Real processes only: ``helmcheck certify vehicle`` against a real ``helmcheck emulate`` on a
pty, ``helmcheck certify backseat`` with the example backseat connected, and ``helmcheck
emulate`` itself. Each is signalled a couple of seconds into its run; the results must be
final (``partial: true``, a reason that says it was interrupted and by what, never "in
progress"), the reports rendered, and the exit code the table's.
"""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from helmcheck.emulator.process import EmulatorProcess
from helmcheck.reports.results import load_results
from tests.waiting import wait_for_text

HERE = Path(__file__).resolve().parent
GOOD_BACKSEAT = HERE / "backseats" / "good_backseat.py"
K = 20.0
SIGNALS = [pytest.param(signal.SIGTERM, id="SIGTERM"), pytest.param(signal.SIGHUP, id="SIGHUP")]



def _finish(proc: subprocess.Popen, timeout: float = 60.0) -> tuple[str, str]:
    try:
        out, err = proc.communicate(timeout=timeout)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    return out.decode(errors="replace"), err.decode(errors="replace")


def _assert_interrupted_results(rdir: Path, sig: signal.Signals) -> dict:
    r = load_results(rdir)
    assert r["partial"] is True
    assert f"interrupted ({sig.name})".lower() in r["verdict_reason"].lower(), r["verdict_reason"]
    assert "in progress" not in r["verdict_reason"]
    assert r["verdict"] != "pass"
    assert (rdir / "report.html").exists() and (rdir / "junit.xml").exists()
    return r


@pytest.mark.parametrize("sig", SIGNALS)
def test_certify_vehicle_signalled_mid_run_writes_partial_results_and_reports(sig, tmp_path):
    rdir = tmp_path / "r"
    with EmulatorProcess(time_scale=K) as emu:
        proc = subprocess.Popen([sys.executable, "-m", "helmcheck", "certify", "vehicle", "--port", emu.port,
                                 "--time-scale", str(K), "--report-dir", str(rdir), "--no-progress",
                                 "--examples", "0"],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL)
        wait_for_text(rdir / "wire.log", "case ", timeout=60.0)  # the cases have started
        time.sleep(2.0)
        proc.send_signal(sig)
        out, err = _finish(proc)
    assert proc.returncode in (1, 2), err  # 2 unless a MUST had already failed
    assert "Traceback" not in err
    r = _assert_interrupted_results(rdir, sig)
    assert proc.returncode == (1 if r["verdict"] == "fail" else 2)
    assert out.startswith(f"{r['verdict'].upper()} — partial:"), out


@pytest.mark.parametrize("sig", SIGNALS)
def test_certify_backseat_signalled_mid_run_writes_partial_results_and_reports(sig, tmp_path):
    rdir = tmp_path / "r"
    proc = subprocess.Popen([sys.executable, "-m", "helmcheck", "certify", "backseat", "--time-scale", "5",
                             "--duration", "60", "--report-dir", str(rdir), "--connect-timeout", "60"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL)
    backseat = None
    try:
        port = proc.stdout.readline().decode().split(": ", 1)[1].strip()
        backseat = subprocess.Popen([sys.executable, str(GOOD_BACKSEAT), port, "--time-scale", "5"],
                                    stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        wait_for_text(rdir / "wire.log", "scenario nominal starts", timeout=60.0)
        time.sleep(2.0)
        proc.send_signal(sig)
        out, err = _finish(proc)
    finally:
        if backseat is not None:
            try:
                backseat.wait(timeout=10)
            except subprocess.TimeoutExpired:
                backseat.kill()
                backseat.wait()
    assert proc.returncode == 2, err
    assert "Traceback" not in err
    _assert_interrupted_results(rdir, sig)
    assert out.startswith("INCONCLUSIVE — partial:"), out


@pytest.mark.parametrize("sig", SIGNALS)
def test_emulate_signalled_stops_with_0_and_closes_its_log(sig, tmp_path):
    log = tmp_path / "wire.log"
    proc = subprocess.Popen([sys.executable, "-m", "helmcheck", "emulate", "--time-scale", str(K),
                             "--log", str(log)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL)
    assert proc.stdout.readline().decode().startswith("port: ")
    time.sleep(1.0)
    proc.send_signal(sig)
    out, err = _finish(proc)
    assert proc.returncode == 0, err
    assert err.strip().splitlines()[-1] == f"helmcheck emulate: stopped: interrupted ({sig.name})"
    assert log.read_text().rstrip().endswith("emulator stopped")


def test_a_second_sigterm_while_the_run_ends_does_not_lose_the_results(tmp_path):
    """The first SIGTERM ends the run; more of them while results are written are ignored."""
    rdir = tmp_path / "r"
    with EmulatorProcess(time_scale=K) as emu:
        proc = subprocess.Popen([sys.executable, "-m", "helmcheck", "certify", "vehicle", "--port", emu.port,
                                 "--time-scale", str(K), "--report-dir", str(rdir), "--no-progress",
                                 "--examples", "0"],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL)
        wait_for_text(rdir / "wire.log", "case ", timeout=60.0)
        time.sleep(1.0)
        for _ in range(5):
            proc.send_signal(signal.SIGTERM)
            time.sleep(0.02)
        _finish(proc)
    assert proc.returncode in (1, 2)
    _assert_interrupted_results(rdir, signal.SIGTERM)
