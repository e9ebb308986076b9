"""``certify vehicle --resume DIR``: an interrupted run goes on from its last completed case, into
the same report, and the record still re-judges to the same verdicts offline.

The emulator runs as a subprocess on a pty; the certification is a real ``helmcheck`` process,
stopped with SIGTERM in the middle of its cases, then resumed by a second process.
"""

from __future__ import annotations

import re
import signal
import subprocess
import sys
from pathlib import Path

from helmcheck.cli import main as cli_main
from helmcheck.emulator.process import EmulatorProcess
from helmcheck.reports.results import load_results
from tests.judging import not_passed
from tests.waiting import wait_for_text

K = 25.0
SELECT = "RH-SRV-*,RH-INT-*,RH-ACK-1"


def _certify(*args: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "helmcheck", "certify", "vehicle", "--no-progress", *args],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL)



def test_an_interrupted_run_resumes_from_its_last_completed_case(tmp_path):
    rdir = tmp_path / "r"
    prof = tmp_path / "emu.toml"
    prof.write_text('fault_injection = "oxflt"\nbaud = 115200\n')
    with EmulatorProcess(time_scale=K, baud=115200) as emu:
        first = _certify("--port", emu.port, "--time-scale", str(K), "--profile", str(prof), "--select", SELECT,
                         "--examples", "0", "--report-dir", str(rdir))
        wait_for_text(rdir / "wire.log", "case V-22 end")  # three cases done, the fourth under way
        first.send_signal(signal.SIGTERM)
        first.communicate(timeout=60)
        assert first.returncode == 2
        part = load_results(rdir)
        assert part["partial"] is True
        done = [c["id"] for c in part["cases"]]
        second = _certify("--port", emu.port, "--resume", str(rdir))
        out, err = second.communicate(timeout=180)
    r = load_results(rdir)
    assert r["partial"] is False
    assert not not_passed(r), r["verdict_reason"]  # PASS, but for what the host's load left unjudged
    assert second.returncode == (0 if r["verdict"] == "pass" else 2), (out, err)
    ids = [c["id"] for c in r["cases"]]
    assert ids[:len(done)] == done and len(ids) == len(set(ids))  # nothing twice, nothing lost
    assert {c["id"] for c in r["clauses"] if c["verdict"] == "pass"} >= {"RH-SRV-1", "RH-INT-1", "RH-ACK-1"}
    wire = (rdir / "wire.log").read_text()
    for cid in done:
        assert len(re.findall(rf"! case {cid} RH-", wire)) == 1, cid  # a completed case is not run again
    assert wire.index("run aborted: interrupted (SIGTERM)") < wire.index("run resumed: ")
    assert wire.count("# helmcheck wire-log") == 1  # one record, appended to
    assert r["settings"]["resumed"] and r["settings"]["resumed"][0]["completed_cases"] == len(done)
    assert "Traceback" not in err.decode()


def test_resume_refuses_a_finished_run_and_changed_options(tmp_path, capsys):
    d = Path(__file__).parent / "fixtures" / "reports" / "pass_run"
    assert cli_main(["certify", "vehicle", "--port", "/dev/null", "--resume", str(d)]) == 64
    assert "finished run" in capsys.readouterr().err
    assert cli_main(["certify", "vehicle", "--port", "/dev/null", "--resume", str(d), "--select", "RH-SRV-1"]) == 64
    assert "drop --select" in capsys.readouterr().err
    assert cli_main(["certify", "vehicle", "--port", "/dev/null", "--resume", str(tmp_path / "none")]) == 64
    assert "--resume" in capsys.readouterr().err
