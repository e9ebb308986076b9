"""``helmcheck certify vehicle``: the built-in emulator passes; link faults are INCONCLUSIVE.

The full certification runs the emulator as a subprocess on a pty (``helmcheck emulate``) at
time scale 40. The link-fault vehicles are served in-process behind real ptys.
"""

from __future__ import annotations

import json
import os
import re
import threading
import time
from decimal import Decimal
from pathlib import Path

import pytest

from helmcheck.cli import main as cli_main
from helmcheck.line.transport import PtyLink
from helmcheck.certify.vehicle import runner as runner_mod
from helmcheck.certify.vehicle.runner import Options, certify
from helmcheck.certify.vehicle.safety import BenchGuard
from helmcheck.grammar.wirelog import read_records
from helmcheck.profile import DEFAULT
from helmcheck.reports.results import load_results
from tests.faulty_vehicles import EMU_PROFILE, MUTANTS, make_core, serve

K = 40.0


def _opts(port, tmp_path, **kw):
    base = dict(port=port, profile=EMU_PROFILE.replace(time_scale=K), time_scale=K,
                report_dir=tmp_path / "r", examples=0, progress=False, render=False, seed=1)
    base.update(kw)
    return Options(**base)


def _sent_lines(path: Path):
    with open(path, "rb") as f:
        return [r.data for r in read_records(f) if r.dir == ">"]


def _assert_bench_safe(path: Path, max_motor=0x90, max_speed=Decimal("0.5")):
    for raw in _sent_lines(path):
        for chunk in raw.decode("latin-1").split("$")[1:]:
            fields = chunk.split("*")[0].rstrip("\r\n").split(",")
            sid = fields[0].upper()
            if sid == "OMP" and len(fields) > 1 and re.fullmatch(r"[0-9A-Fa-f]{10}.*", fields[1]):
                assert int(fields[1][8:10], 16) <= max_motor, raw
            idx = {"OMS": 4, "OPK": 4, "OMW": 6}.get(sid)
            if not idx:
                continue
            # every alignment a vehicle could act on: as sent, or with leading empty fields or a
            # clear keyword passed over, wherever the position (or heading) fields are numbers
            num = re.compile(r"-?\d+(\.\d+)?")
            need = 1 if sid == "OMS" else 2
            for shift in range(3):
                if shift and (shift >= len(fields) or fields[shift].strip().upper() not in ("", "CLR", "CLEAR", "STOP")):
                    break
                f = fields[shift:]
                if len(f) <= idx or not all(num.fullmatch(x.strip()) for x in f[1:need + 1]):
                    continue
                if num.fullmatch(f[idx].strip()):
                    assert Decimal(f[idx]) <= max_speed, raw


# ---------------------------------------------------------------------------- the emulator

@pytest.mark.xdist_group("full-emulator-run")
def test_builtin_emulator_certifies(full_emulator_run):
    """Every vehicle clause PASS (RH-MSN-4 on the profile's end_mission, RH-SAF-4 in both SafetyAction
    branches); all report formats written; the emulator still running afterwards. The run is the
    suite's shared full certification (``tests/conftest.py``)."""
    root, code, alive = full_emulator_run
    out = root / "full"
    assert alive
    r = load_results(out)
    bad = {c["id"]: c["reason"] for c in r["clauses"] if c["verdict"] not in ("pass", "not-tested")}
    assert not bad, bad
    assert code == 0 and r["verdict"] == "pass" and r["partial"] is False
    assert r["role"] == "vehicle"
    for c in r["clauses"]:
        assert c["reason"], c
    nt = {c["id"] for c in r["clauses"] if c["verdict"] == "not-tested"}
    assert not nt, nt
    verdicts = {c["id"]: c["verdict"] for c in r["clauses"]}
    assert verdicts["RH-MSN-4"] == "pass" and verdicts["RH-SAF-4"] == "pass"
    cases = {c["id"]: c["verdict"] for c in r["cases"]}
    assert cases["V-47"] == "pass" and cases["V-61"] == "pass" and cases["V-63"] == "pass", cases
    for name in ("results.json", "wire.log", "report.html", "junit.xml", "report.md"):
        assert (out / name).stat().st_size > 0, name
    assert r["settings"]["bench_safety"]["enforced"] is True
    assert r["restore"]["verified"] is True and r["restore"]["left"]["mode"] == "S", r["restore"]
    assert {"S", "N", "A", "M", "mP", "W", "P"} <= set(r["coverage"]["modes"])
    assert r["coverage"]["interrupt_pairs"] and r["timeline"] and r["events"]
    assert len(r["cases"]) >= 60
    _assert_bench_safe(out / "wire.log")


# ---------------------------------------------------------------------------- link faults

class _FakeVehicle:
    """A pty whose far end is silent, sends garbage, or closes after a while."""

    def __init__(self, behaviour: str, close_after: float = 0.0):
        self.link = PtyLink(baud=115200)
        self.behaviour = behaviour
        self.close_after = close_after
        self.stop = False
        self.th = threading.Thread(target=self._run, daemon=True)
        self.th.start()

    def _run(self):
        while not self.stop:
            if not self.link.wait_readable(0.05):
                continue
            try:
                data = b"".join(e.data for e in self.link.poll())
            except OSError:
                return
            if data and self.behaviour == "garbage":
                self.link.write_some(os.urandom(40).replace(b"$", b"#") + b"\r\n")

    def close(self):
        self.stop = True
        self.th.join(2)
        self.link.close()


@pytest.mark.parametrize("behaviour,words", [("silent", "no bytes at all"), ("garbage", "none of them a valid")])
def test_dead_or_garbled_link_is_inconclusive(tmp_path, behaviour, words):
    v = _FakeVehicle(behaviour)
    try:
        out = certify(_opts(v.link.name, tmp_path, render=True))
    finally:
        v.close()
    assert out.verdict == "inconclusive" and out.exit_code == 2
    r = load_results(tmp_path / "r")
    assert any(words in c["reason"] for c in r["clauses"]), [c["reason"] for c in r["clauses"]][:3]
    assert not any(c["verdict"] == "fail" for c in r["clauses"])
    assert (tmp_path / "r" / "report.html").exists() and (tmp_path / "r" / "wire.log").exists()


def test_pty_closing_mid_run_is_inconclusive(tmp_path):
    """The vehicle's pty closes ~2 s into the run: INCONCLUSIVE with the reason, report written."""
    box = {}

    def run(port):
        box["out"] = certify(_opts(port, tmp_path, render=True))

    with serve(lambda start: make_core(None, K, start)) as port:
        th = threading.Thread(target=run, args=(port,))
        th.start()
        time.sleep(2.0)
    th.join(60)
    out = box["out"]
    assert out.verdict == "inconclusive" and out.exit_code == 2, out.reason
    r = load_results(tmp_path / "r")
    reasons = " ".join(c["reason"] for c in r["clauses"] if c["verdict"] == "inconclusive")
    assert "link" in reasons
    assert not any(c["verdict"] == "fail" for c in r["clauses"])
    assert (tmp_path / "r" / "report.html").exists()


def test_ctrl_c_leaves_a_partial_report(tmp_path, monkeypatch):
    real = runner_mod.run_case
    calls = {"n": 0}

    def interrupting(session, case):
        calls["n"] += 1
        if calls["n"] == 3:
            raise KeyboardInterrupt
        return real(session, case)

    monkeypatch.setattr(runner_mod, "run_case", interrupting)
    with serve(lambda start: make_core(None, K, start)) as port:
        out = certify(_opts(port, tmp_path, render=True))
    r = load_results(tmp_path / "r")
    assert r["partial"] is True and r["verdict"] == "inconclusive" and out.exit_code == 2
    assert len(r["cases"]) == 2
    assert (tmp_path / "r" / "report.md").exists()


# ---------------------------------------------------------------------------- bench safety

def test_bench_guard_reads_every_line():
    g = BenchGuard(DEFAULT)
    assert g.problem(b"$OMP,80808080FF,00,10*00\r\n")
    assert g.problem(b"$omp,80808080a0,00,10\r\n")
    assert g.problem(b"$OMS,90,2,20,3.0,10*11\r\n")
    assert g.problem(b"$OPK,41.5,-71.3,1,0.6*11\r\n")
    assert g.problem(b"$OMW,41.5,-71.3,2,,15,1,0,*11\r\n")
    assert g.problem(b"$OMW,CLEAR,41.5,-71.3,2,,15,1,0,*11\r\n")
    assert g.problem(b"noise$OSD,S*27\r\n$OMS,1,2,3,9,5*00\r\n")
    # a shifted line is checked in every alignment a vehicle could execute (issue: one judge)
    assert g.problem(b"$OMW,,41.5,-71.3,2,,15,3.0,0,*11\r\n")  # read from its second field: 3 kn
    assert g.problem(b"$OMW,,,41.5,-71.3,2,,15,3.0,0,*11\r\n")
    assert g.problem(b"$OPK,,41.5,-71.3,1,0.9*11\r\n")
    assert g.problem(b"$OMS,,90,2,20,3.0,10*11\r\n")
    assert not g.problem(b"$OMW,,41.5,-71.3,2,,15,0.4,0,*11\r\n")  # 15 is the pitch when shifted
    assert not g.problem(b"$OMW,41.5,-71.3,2,,15,0.5,30,*11\r\n")
    for short in (b"$OMW*00\r\n", b"$OMW,,*00\r\n", b"$OMS\r\n", b"$OPK,*00\r\n", b"$OMW,Clr*00\r\n"):
        assert not g.problem(short)  # nothing to execute, and no exception
    assert not g.problem(b"$OMP,8080808090,00,10*00\r\n")
    assert not g.problem(b"$OMS,90,2,20,0.5,10*00\r\n")
    assert not BenchGuard(DEFAULT.replace(bench_safety=type(DEFAULT.bench_safety)(in_water=True))).problem(
        b"$OMP,80808080FF,00,10*00\r\n")


# ---------------------------------------------------------------------------- exploration + replay

def test_exploration_shrinks_and_replays(tmp_path, capsys):
    mutant = next(m for m in MUTANTS if m.name == "wrong-err-number")
    with serve(lambda start: make_core(mutant, K, start)) as port:
        out = certify(_opts(port, tmp_path, select=["RH-ACK-3"], examples=20, explore_budget_s=15.0, seed=4))
        r = out.results
        assert out.verdict == "fail", out.reason
        assert r["replays"], (r["clauses"], r["stats"])
        assert r["stats"]["explore"]["confirmed"] == "2/2"
        rep = tmp_path / "r" / r["replays"][0]["file"]
        doc = json.loads(rep.read_text())
        assert doc["format"] == "helmcheck-replay" and doc["steps"]
        assert all(sum(k in s for k in ("send", "wait", "expect")) == 1 for s in doc["steps"])
        code = cli_main(["replay", str(rep), "--port", port, "--time-scale", str(K)])
        assert code == 1, capsys.readouterr().out
        assert "STILL FAILS" in capsys.readouterr().out
    with serve(lambda start: make_core(None, K, start)) as port:
        code = cli_main(["replay", str(rep), "--port", port, "--time-scale", str(K)])
        assert code == 0, capsys.readouterr().out


def test_exploration_counts_only_the_sequences_that_ran(tmp_path):
    """A spent wall budget ends exploration: the report counts the sequences that really ran
    (each one's reset is on the wire), never the examples hypothesis asked for afterwards. (3 s: on
    a busy host a 1 s budget was seen spent before the first sequence's reset was answered.)"""
    with serve(lambda start: make_core(None, K, start)) as port:
        out = certify(_opts(port, tmp_path, select=["RH-ACK-1"], examples=500, explore_budget_s=3.0, seed=3))
    ex = out.results["stats"]["explore"]
    assert ex["budget_spent"] is True, ex
    assert 0 < ex["ran"] < 500, ex
    notes = [r.note for r in read_records(open(tmp_path / "r" / "wire.log", "rb")) if r.dir == "!"]
    assert any(f"exploration: {ex['ran']} sequence(s) ran; the 3 s wall budget was spent" in n for n in notes), notes
    stops = sum(1 for raw in _sent_lines(tmp_path / "r" / "wire.log") if raw.startswith(b"$OMSTOP,0*"))
    assert stops >= ex["ran"], (stops, ex)  # every counted sequence began with its reset


# ---------------------------------------------------------------------------- command line

@pytest.mark.parametrize("argv", [
    ["certify", "vehicle"],
    ["certify", "vehicle", "--port", "pty"],
    ["certify", "vehicle", "--port", "/dev/null", "--select", "RH-NOPE-*"],
    ["certify", "vehicle", "--port", "/dev/null", "--time-scale", "0"],
    ["replay", "/nonexistent.json", "--port", "/dev/null"],
])
def test_usage_errors_exit_64(argv, capsys):
    with pytest.raises(SystemExit) as e:
        raise SystemExit(cli_main(argv))
    assert e.value.code == 64


def test_unopenable_port_is_a_usage_error_and_writes_nothing(tmp_path, capsys):
    """A port the user typed that cannot be opened at start is exit 64 (docs/contracts.md)."""
    code = cli_main(["certify", "vehicle", "--port", "/dev/helmcheck-no-such-tty", "--report-dir",
                     str(tmp_path / "r"), "--examples", "0", "--no-progress"])
    assert code == 64
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "cannot open /dev/helmcheck-no-such-tty" in err[0]
    assert not (tmp_path / "r").exists()


# ---------------------------------------------------------------------------- RH-MSN-4 bounds

def test_RH_MSN_4_an_end_mission_too_long_for_the_cap_is_inconclusive(tmp_path):
    """The vehicle reports hours left (the long test mission named as end_mission): not a FAIL."""
    with serve(lambda start: make_core(None, K, start)) as port:
        out = certify(_opts(port, tmp_path, select=["RH-MSN-4"],
                            profile=EMU_PROFILE.replace(time_scale=K, end_mission=EMU_PROFILE.mission)))
    c = next(c for c in out.results["clauses"] if c["id"] == "RH-MSN-4")
    assert c["verdict"] == "inconclusive" and "past the cap" in c["reason"], c
