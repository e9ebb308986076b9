"""Verdicts on a bad line: certifications through the line-fault relay (``helmcheck relay``).

A conforming implementation is never failed for what the line did: an observation a fault spoilt
is made again (the tester re-sends, ``re-run`` notes) and not booked, or is INCONCLUSIVE naming
what the line may have done (``docs/contracts.md``, "A faulty line"). Real faults are still
found through light damage (flips 1e-5 a bit, drops 1e-4 a byte): the suite's faulty vehicles and
backseats FAIL on their own clause. The relay's own wire log, judged offline, attributes every
fault exactly (its notes). A vehicle behind a baud mismatch (its 115200-baud bytes as a 19200
receiver reads them, the relay's ``rx-baud``) is named in one line, exit 2. The port's error
counters: read around each case, a rise marks the case INCONCLUSIVE.

The grid — {the emulator, ``../shared/third-party/uvc_sim.py``, the example backseat} × {flips
1e-5 and 1e-4, drops 1e-4, noise bursts, a 2 s stall} — and every faulty implementation at the
light settings are ``make matrix``'s (``HELMCHECK_MATRIX=1``); ``make test`` runs a representative
part of it on the framing and acknowledgement clauses at high time scales.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from helmcheck.certify.vehicle.runner import Options, certify
from helmcheck.checklog.checker import check_log
from helmcheck.emulator.process import EmulatorProcess
from helmcheck.line.faultline import impaired_line
from helmcheck.profile import emulator_profile

MATRIX = os.environ.get("HELMCHECK_MATRIX") == "1"
ROOT = Path(__file__).resolve().parent.parent
SIM = ROOT.parent / "shared" / "third-party" / "uvc_sim.py"
EXAMPLE_BACKSEAT = ROOT / "examples" / "backseat.py"
FAULTY_BACKSEAT = ROOT / "tests" / "backseats" / "faulty_backseat.py"

#: The line faults of the grid (every one paced at 19200 baud, as the Iver3's line)
FAULTS = {
    "flip-1e-5": "baud=19200,flip=1e-5",
    "flip-1e-4": "baud=19200,flip=1e-4",
    "drop-1e-4": "baud=19200,drop=1e-4",
    "noise": "baud=19200,noise=2e-4,noise-len=1-8",
    "stall-2s": "baud=19200,stall=2s@6,stall=2s@12",  # two, so that one falls while the tester talks
}
#: The light settings the faulty implementations are still caught through
LIGHT = "baud=19200,flip=1e-5,drop=1e-4"
#: The clauses a bad line touches most: framing, acknowledgements, the data of $OSD
FRAMING_ACK = ["RH-FRM-*", "RH-ACK-*", "RH-OSD-*"]
#: What a reason that gives an observation to the line says
LINE_WORDS = ("the line", "faulty line", "stall")


def _problems(results: dict) -> tuple[dict, dict]:
    """(clauses that FAILed, INCONCLUSIVE clauses whose reason does not name the line)."""
    failed = {c["id"]: c["reason"] for c in results["clauses"] if c["verdict"] in ("fail", "non-strict")}
    unnamed = {c["id"]: c["reason"] for c in results["clauses"]
               if c["verdict"] == "inconclusive" and not any(w in c["reason"] for w in LINE_WORDS)}
    return failed, unnamed


def _injected(line, kinds=("flip", "drop", "noise")) -> list:
    return [f for _, f in line.fault_notes() if f.kind in kinds]


def _stalled(line) -> int:
    """Bytes the relay's stalls held up."""
    held = 0
    for _, f in line.fault_notes():
        if f.kind == "stall" and f.detail.startswith("over after"):
            held += int(f.detail.split(": ")[1].split()[0])
    return held


def _assert_no_fail_and_named(out_dir: Path, results: dict, line, stall: bool = False) -> None:
    failed, unnamed = _problems(results)
    assert not failed, failed
    assert not unnamed, unnamed
    if stall:  # it held bytes up (else the test tests nothing); what it made late is named above
        assert _stalled(line), "the stall held nothing up"


def _certify_vehicle(port: str, profile, k: float, out: Path, select=FRAMING_ACK, examples=0):
    return certify(Options(port=port, profile=profile.replace(time_scale=k), time_scale=k, report_dir=out,
                           select=select, examples=examples, progress=False, render=False, seed=1, line="noisy"))


def _sim_profile(tmp: Path):
    from helmcheck.profile import load_profile
    path = tmp / "sim.toml"
    path.write_text('protocol = "rh5"\nmission = "conformance.mis"\nmission_waypoints = 4\nsrp_mission = "srp.mis"\n'
                    'fault_injection = "oxflt"\nviolation_trigger = "oxflt"\n')
    return load_profile(str(path))


def _relay_judged_exactly(relay_log: Path, role: str, k: float, profile) -> None:
    """The relay's own record, judged offline: nothing failed, and a fault that broke a line to the
    receiver being judged's counterpart is quoted by the note that says what the line did."""
    out = check_log(relay_log, profile=profile, role=role, time_scale=k)
    failed = {c["id"]: c["reason"] for c in out.clauses if c["verdict"] in ("fail", "non-strict")}
    assert not failed, failed
    return out


# ============================================================ conforming: the emulator, uvc_sim

def run_emulator(tmp_path: Path, name: str, k: float = 40.0, select=FRAMING_ACK, seed: int = 3):
    profile = emulator_profile()
    with EmulatorProcess([], time_scale=k, baud=19200) as emu, \
            impaired_line(emu.port, f"{FAULTS[name]},seed={seed}", link=tmp_path / "vehicle", process=True,
                          wire_log=tmp_path / "relay.log") as line:
        out = _certify_vehicle(str(line.port), profile, k, tmp_path / "r", select=select)
        return out, line


def run_sim(tmp_path: Path, faults: str, k: float = 40.0, select=FRAMING_ACK):
    from tests.test_third_party_vehicle import uvc_sim
    with uvc_sim(tmp_path, k) as port, impaired_line(port, faults, link=tmp_path / "vehicle", process=True,
                                                      wire_log=tmp_path / "relay.log") as line:
        out = _certify_vehicle(str(line.port), _sim_profile(tmp_path), k, tmp_path / "r", select=select)
        return out, line


@pytest.mark.skipif(not MATRIX, reason="make matrix's (HELMCHECK_MATRIX=1): make test's budget (flipped bits: the "
                                        "example backseat's test; the relay's record: the backseat's too)")
def test_the_emulator_behind_flipped_bits_is_never_failed_and_the_relays_record_says_which_fault(tmp_path):
    """One bit in 10,000 flipped both ways, x40, the framing and acknowledgement clauses. Before:
    FAIL RH-FRM-1/2, RH-ACK-5, RH-OSD-1. The tester re-sends what the line spoilt (re-run notes);
    the relay's own record judged offline quotes the note of every fault it gives to the line."""
    out, line = run_emulator(tmp_path, "flip-1e-4")
    assert _injected(line), "no fault was injected: the test tests nothing"
    _assert_no_fail_and_named(tmp_path / "r", out.results, line)
    assert "re-run" in (tmp_path / "r" / "wire.log").read_text()
    exact = _relay_judged_exactly(tmp_path / "relay.log", "vehicle", 40.0, emulator_profile())
    assert any("the relay's note: line fault <" in c["reason"] for c in exact.clauses)


@pytest.mark.skipif(not SIM.is_file(), reason=f"the independent simulator is not there: {SIM}")
def test_a_vehicle_we_did_not_write_behind_lost_bytes_noise_and_a_stall_is_never_failed(tmp_path):
    """``uvc_sim.py`` behind a line that loses bytes, bursts noise and stalls 2 s: no FAIL, every
    INCONCLUSIVE naming the line."""
    out, line = run_sim(tmp_path, "baud=19200,drop=2e-4,noise=2e-4,stall=2s@6,stall=2s@12,seed=5",
                        select=["RH-FRM-2", "RH-FRM-7", "RH-ACK-1", "RH-ACK-2", "RH-ACK-5", "RH-OSD-1"])
    _assert_no_fail_and_named(tmp_path / "r", out.results, line, stall=True)
    assert out.exit_code in (0, 2)


# ============================================================ conforming: the example backseat

def run_backseat(tmp_path: Path, faults: str, k: float, duration: float, program: list) -> tuple[dict, object]:
    """``certify backseat`` on a new pty, the relay (a process of its own) between it and
    ``program`` (argv after the interpreter; ``{port}`` is the relay's backseat-side port). The
    certifier's own port is a pty it made, which cannot damage a byte; the relay behind it can,
    so the run says so: ``--line noisy`` (``line="noisy"``)."""
    from helmcheck.certify.backseat.certifier import Options as BOptions, certify as bcertify
    from helmcheck.line.faultline import RelayProcess
    from helmcheck.profile import DEFAULT
    relays, procs = [], []

    def on_port(name: str) -> None:
        relay = RelayProcess(name, faults, link=tmp_path / "backseat", wire_log=tmp_path / "relay.log").start()
        relays.append(relay)
        procs.append(subprocess.Popen([sys.executable, *[a.replace("{port}", relay.port) for a in program]],
                                      stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                      stderr=open(tmp_path / "backseat.err", "wb")))

    try:
        bcertify(BOptions(profile=DEFAULT, report_dir=tmp_path / "r", time_scale=k, duration=duration,
                          connect_timeout=20.0, progress=False, render=False, on_port=on_port, line="noisy"))
    finally:
        for p in procs:
            p.terminate()
            try:
                p.wait(5)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
        for relay in relays:
            relay.stop()
    return json.loads((tmp_path / "r" / "results.json").read_text()), (relays[0] if relays else None)


def test_the_example_backseat_behind_flipped_bits_is_never_failed(tmp_path):
    """Behind ``helmcheck relay`` flipping bits, run with ``--line noisy`` (the relay, not
    helmcheck's pty, is the link): the example backseat is not failed for the relay's damage."""
    results, line = run_backseat(tmp_path, "baud=19200,flip=3e-4,seed=2", 10.0, 15.0,
                                 [str(EXAMPLE_BACKSEAT), "--port", "{port}", "--time-scale", "10"])
    assert line is not None and _injected(line), "no fault was injected: the test tests nothing"
    assert results["line_model"]["kind"] == "noisy" and results["line_model"]["why"] == "--line noisy given"
    failed, unnamed = _problems(results)
    assert not failed and not unnamed, (failed, unnamed)
    _relay_judged_exactly(tmp_path / "relay.log", "backseat", 10.0, emulator_profile())


# ============================================================ the grid (make matrix)

GRID_VEHICLES = ("emulator", "uvc_sim")


@pytest.mark.skipif(not MATRIX, reason="the whole grid is make matrix's (HELMCHECK_MATRIX=1)")
@pytest.mark.parametrize("fault", sorted(FAULTS))
@pytest.mark.parametrize("vehicle", GRID_VEHICLES)
def test_grid_a_conforming_vehicle_behind_each_fault_is_never_failed(vehicle, fault, tmp_path):
    """{the emulator, uvc_sim} × {flips 1e-5 and 1e-4, drops 1e-4, noise bursts, a 2 s stall} at
    x20 on the framing, acknowledgement and ``$OSD`` clauses: no FAIL, every INCONCLUSIVE naming
    the line. (A 5 s cut and return: ``tests/test_unplugged.py``.)"""
    if vehicle == "uvc_sim" and not SIM.is_file():
        pytest.skip(f"the independent simulator is not there: {SIM}")
    if vehicle == "emulator":
        out, line = run_emulator(tmp_path, fault, k=20.0)
    else:
        out, line = run_sim(tmp_path, f"{FAULTS[fault]},seed=3", k=20.0)
    _assert_no_fail_and_named(tmp_path / "r", out.results, line, stall=fault.startswith("stall"))
    assert out.exit_code in (0, 2), out.reason


@pytest.mark.skipif(not MATRIX, reason="the whole grid is make matrix's (HELMCHECK_MATRIX=1)")
@pytest.mark.parametrize("fault", sorted(FAULTS))
def test_grid_the_example_backseat_behind_each_fault_is_never_failed(fault, tmp_path):
    results, line = run_backseat(tmp_path, f"{FAULTS[fault]},seed=4", 10.0, 18.0,
                                 [str(EXAMPLE_BACKSEAT), "--port", "{port}", "--time-scale", "10"])
    failed, unnamed = _problems(results)
    assert not failed and not unnamed, (failed, unnamed)


# ============================================================ real faults through light damage

#: The faulty vehicles ``make test`` certifies behind the light settings (``make matrix``: all)
LIGHT_MUTANTS = ("lowercase-checksum-out", "unpadded-checksum-out", "ack-before-data")


def _mutant_params():
    from tests.faulty_vehicles import MUTANTS
    chosen = [m for m in MUTANTS if MATRIX or m.name in LIGHT_MUTANTS]
    return [pytest.param(m, id=m.name) for m in chosen]


@pytest.mark.parametrize("mutant", _mutant_params())
def test_a_faulty_vehicle_behind_light_damage_still_fails_on_its_own_clause(mutant, tmp_path):
    """Flips 1e-5 a bit and drops 1e-4 a byte, paced at 19200 baud: the faulty vehicle still FAILs
    on the clause its fault breaks (the repetition rule finds an error a line does not repeat)."""
    from tests.faulty_vehicles import EMU_PROFILE, make_core, serve
    k = min(mutant.time_scales)
    profile = EMU_PROFILE.replace(baud=19200, time_scale=k)
    with serve(lambda start: make_core(mutant, k, start)) as port, \
            impaired_line(port, f"{LIGHT},seed=1", link=tmp_path / "vehicle", process=True,
                          wire_log=tmp_path / "relay.log") as line:
        out = certify(Options(port=str(line.port), profile=profile, time_scale=k, report_dir=tmp_path / "r",
                              select=list(mutant.select), examples=0, progress=False, render=False, seed=1,
                              line="noisy"))
    failed = {c["id"]: c["reason"] for c in out.results["clauses"] if c["verdict"] == "fail"}
    assert mutant.clause in failed, (failed, out.reason)
    assert out.exit_code == 1


def _backseat_faults():
    """``make test``: the one whose error a faulty line could have made (a wrong checksum now and
    then); ``make matrix``: every faulty backseat of the suite."""
    from tests.test_certify_backseat import FAULTS as BACKSEAT_FAULTS
    chosen = sorted(BACKSEAT_FAULTS) if MATRIX else ["bad-checksum"]
    return [pytest.param(f, BACKSEAT_FAULTS[f], id=f) for f in chosen]


@pytest.mark.parametrize("fault,expected", _backseat_faults())
def test_a_faulty_backseat_behind_light_damage_still_fails_on_its_own_clause(tmp_path, fault, expected):
    """A faulty backseat (e.g. every fifth state poll with a wrong checksum, RH-BS-1) behind flips
    1e-5 and drops 1e-4: still caught on its own clause (the same broken bytes again are the
    backseat's)."""
    clause, verdict = expected
    results, line = run_backseat(tmp_path, f"{LIGHT},seed=2", 10.0, 18.0,
                                 [str(FAULTY_BACKSEAT), "{port}", "--fault", fault, "--time-scale", "10"])
    verdicts = {c["id"]: c["verdict"] for c in results["clauses"]}
    assert verdicts.get(clause) == verdict, {c["id"]: (c["verdict"], c["reason"]) for c in results["clauses"]
                                             if c["id"] == clause}


# ============================================================ a baud mismatch, the counters

def test_a_vehicle_behind_a_baud_mismatch_is_named_in_one_line_exit_2(tmp_path):
    """The emulator at 115200 baud, its bytes as a 19200 receiver reads them (the relay's
    ``rx-baud``): ``certify vehicle`` says in one line that they read as sentences at 115200, exit 2."""
    with EmulatorProcess([], time_scale=20.0, baud=115200) as emu, \
            impaired_line(emu.port, "baud=115200,<rx-baud=19200,seed=1", link=tmp_path / "vehicle",
                          process=True) as line:
        run = subprocess.run([sys.executable, "-m", "helmcheck", "certify", "vehicle", "--port", str(line.port),
                              "--time-scale", "20", "--report-dir", str(tmp_path / "r"), "--no-progress"],
                             capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert run.returncode == 2, (run.returncode, run.stderr)
    says = [ln for ln in (run.stdout + run.stderr).splitlines() if "115200" in ln]
    assert len(says) == 1 and "read as sentences at 115200 baud, not 19200: run with --baud 115200" in says[0], \
        (run.stdout, run.stderr)
    assert says[0].startswith("INCONCLUSIVE") and "Traceback" not in run.stderr


def test_every_case_carries_its_line_counters_and_the_report_says_so(tmp_path):
    """``results.json`` ``cases[].line_counters`` for every case ("not available" on a pty, with
    why), and the Markdown and HTML reports say it in one line."""
    profile = emulator_profile()
    with EmulatorProcess([], time_scale=40.0, baud=115200) as emu:
        out = certify(Options(port=emu.port, profile=profile.replace(baud=115200, time_scale=40.0), time_scale=40.0,
                              report_dir=tmp_path / "r", select=["RH-FRM-1", "RH-ACK-1"], examples=0,
                              progress=False, render=True, seed=1))
    cases = out.results["cases"]
    assert cases and all("line_counters" in c for c in cases), [c["id"] for c in cases if "line_counters" not in c]
    ran = [c["line_counters"] for c in cases if c.get("verdict") != "not-run"]
    assert ran and all(e["available"] is False and "pseudo-terminal" in e["reason"] for e in ran), ran
    for name in ("report.md", "report.html"):
        text = (tmp_path / "r" / name).read_text()
        assert "not available" in text and "pseudo-terminal" in text, name
