"""The traceability table's probes that need more than a faulty vehicle on a pty (``tests/faulty_vehicles/rules.py``
has those): V-90's reconnection, over a TCP serial server the tester closes and opens again.

The emulator as a TCP serial server keeps its state across clients (RH-FRM-9); V-90 goes quiet,
closes its connection, connects again under the same name and sends the first command after it
(RH-ACK-1). The wire log names the reopen; the run passes, the restore verified after it.
"""

from __future__ import annotations

from helmcheck.certify.vehicle.runner import Options, certify
from helmcheck.emulator.process import EmulatorProcess
from helmcheck.profile import emulator_profile


def test_V_90_reopens_a_tcp_link_and_the_first_command_after_it_is_answered(tmp_path):
    k = 20.0
    with EmulatorProcess(port="socket://127.0.0.1:0", time_scale=k, baud=0) as emu:
        out = certify(Options(port=emu.port, profile=emulator_profile().replace(time_scale=k), time_scale=k,
                              report_dir=tmp_path / "r", select=["RH-ACK-1"], examples=0, progress=False,
                              render=False, seed=1))
    log = (tmp_path / "r" / "wire.log").read_text()
    assert "link reopened by the tester" in log, log[-3000:]
    after = log.split("link reopened by the tester", 1)[1].splitlines()
    first = next(ln for ln in after if " > $" in ln)
    assert "> $OSD,S*" in first, after[:6]  # the first command after it
    cases = {c["id"]: c for c in out.results["cases"]}
    assert cases["V-90"]["verdict"] == "pass", cases["V-90"]
    verdicts = {c["id"]: c["verdict"] for c in out.results["clauses"]}
    assert verdicts["RH-ACK-1"] == "pass", out.reason
    assert out.results["restore"]["verified"], out.results["restore"]
