"""The exploration's rules (``helmcheck/certify/vehicle/explore.py``), against faulty vehicles
served behind real ptys:

* a failure the exploration found is re-driven after shrinking, from a verified reset, until two
  re-runs count (a re-drive that went another way than recorded and passed does not): 2 of 2 is
  FAIL, 0 or 1 of 2 is INCONCLUSIVE with the count as the reason (docs/exploration.md);
* what hypothesis ends with on a vehicle's failure — also a flaky one, which hypothesis reports as
  ``FlakyFailure`` — is a finding; anything else (a bug in helmcheck) is a tester error, which
  ends the run with exit 2 and its traceback in ``tester-error.txt`` beside ``results.json``.

The exploration's violations are on the wire, so the record itself says whether they were
confirmed: a ``held:`` note before the exploration, then ``confirmed:`` or ``unconfirmed:`` after
the re-runs (``helmcheck/judge/wire.py``); the vehicle judge books the held violations at that
note, live and offline alike (``helmcheck verify`` agrees).

The fault is one only the exploration meets: an ``$OMS`` refused in ``S`` gets err 21 instead of
20 when its timeout is not the one RH-ACK-4's own case (V-13) sends — the first ``$OMS`` of the
run (the line budget's timeout) — so the case passes and only the exploration's ``$OMS`` lines,
whose timeouts are drawn, show it. RH-ACK-4 is the one clause selected, so
that its verdict is the exploration's.
"""

from __future__ import annotations

import os

import re
from pathlib import Path
from typing import Optional

import pytest
from hypothesis.errors import FlakyFailure, FlakyStrategyDefinition

from helmcheck.cli import main as cli_main
from helmcheck.emulator.core import EmulatorCore
from helmcheck.certify.vehicle import explore as explore_mod
from helmcheck.certify.vehicle import machine as machine_mod
from helmcheck.certify.vehicle import replay as replay_mod
from helmcheck.certify.vehicle.runner import Options, certify
from helmcheck.grammar import sentences as s
from helmcheck.reports.results import load_results
from tests.faulty_vehicles import EMU_PROFILE, make_core, serve
from tests.faulty_vehicles.base import Mutant, reframe

K = 20.0
SEED = 2
CLAUSE = "RH-ACK-4"


class RefusesWith21(EmulatorCore):
    """RH-ACK-4: an ``$OMS`` refused in ``S`` is answered ``$ACK,9,1,21`` (not 20) when its
    timeout is not the first ``$OMS``'s (the case's). ``faults`` is how many more times it
    misbehaves (``None``: always)."""

    faults: Optional[int] = None

    def __init__(self, *a, **kw):
        super().__init__(*a, **kw)
        self.wrong = False
        self.misbehaved = 0
        self.first_timeout = None

    def _command(self, item, now, v):
        if isinstance(item, s.OMS) and self.first_timeout is None:
            self.first_timeout = item.timeout
        self.wrong = isinstance(item, s.OMS) and item.timeout != self.first_timeout and self.faults != 0
        try:
            return super()._command(item, now, v)
        finally:
            self.wrong = False

    def _send(self, raw, now):
        if self.wrong and raw.startswith(b"$ACK,9,1,20*"):
            raw = reframe(raw, b"ACK,9,1,21")
            self.misbehaved += 1
            if self.faults is not None:
                self.faults -= 1
        return super()._send(raw, now)


class OnlyOnce(RefusesWith21):
    """Misbehaves on the first such ``$OMS`` only: neither re-run reproduces it (0 of 2)."""

    faults = 1


def _certify(port: str, report_dir: Path):
    return certify(Options(port=port, profile=EMU_PROFILE.replace(time_scale=K), time_scale=K,
                           report_dir=report_dir, select=[CLAUSE], examples=20, explore_budget_s=8.0,
                           progress=False, render=False, seed=SEED))


def _serve(core: type, cores: list):
    def factory(start):
        cores.append(make_core(Mutant(core.__name__, CLAUSE, (CLAUSE,), core=core), K, start))
        return cores[-1]
    return serve(factory)


def _clause(results: dict, cid: str) -> dict:
    return next(c for c in results["clauses"] if c["id"] == cid)


# ---------------------------------------------------------------------------- 2 of 2 = FAIL

def test_a_fault_only_exploration_finds_fails_when_both_reruns_reproduce_it(tmp_path):
    cores: list = []
    with _serve(RefusesWith21, cores) as port:
        out = _certify(port, tmp_path / "r")
    r = out.results
    ex = r["stats"]["explore"]
    assert cores[0].misbehaved >= 3, ex  # found, then reproduced twice
    assert ex["confirmed"] == "2/2", ex
    case = next(c for c in r["cases"] if CLAUSE in c["clauses"])
    assert case["verdict"] == "pass", case  # the clause's own case does not meet the fault
    entry = _clause(r, CLAUSE)
    assert entry["verdict"] == "fail", entry
    assert "explore" in entry["reason"] and "$ACK,9,1,21" in entry["reason"], entry
    assert out.verdict == "fail" and out.exit_code == 1, out.reason
    assert r["replays"] and r["replays"][0]["clause"] == CLAUSE, r["replays"]
    assert not (tmp_path / "r" / "tester-error.txt").exists()


# ---------------------------------------------------------------------------- else INCONCLUSIVE

@pytest.mark.parametrize("reproduced", [0, pytest.param(1, marks=pytest.mark.skipif(
    os.environ.get("HELMCHECK_MATRIX") != "1", reason="make matrix's (HELMCHECK_MATRIX=1): make test's budget (one re-run "
                                                      "of two reproducing it: the same verdict as none)"))])
def test_a_failure_the_reruns_do_not_both_reproduce_is_inconclusive(reproduced, tmp_path, monkeypatch):
    """0 of 2: the vehicle misbehaves once only. 1 of 2: it misbehaves until the second re-run
    begins (the test stops the fault there), so the first re-run reproduces it and the second
    does not."""
    cores: list = []
    if reproduced == 1:
        real = replay_mod.redrive
        reruns: list = []

        def second_rerun_meets_a_mended_vehicle(doc, session):
            reruns.append(doc)
            if len(reruns) == 2:
                cores[0].faults = 0
            return real(doc, session)

        monkeypatch.setattr(replay_mod, "redrive", second_rerun_meets_a_mended_vehicle)
    with _serve(RefusesWith21 if reproduced else OnlyOnce, cores) as port:
        out = _certify(port, tmp_path / "r")
    r = out.results
    ex = r["stats"]["explore"]
    assert ex["confirmed"] == f"{reproduced}/2", ex
    entry = _clause(r, CLAUSE)
    assert entry["verdict"] == "inconclusive", (entry, ex)
    assert f"reproduced {reproduced} of 2 re-runs after shrinking" in entry["reason"], entry
    assert out.verdict == "inconclusive" and out.exit_code == 2, out.reason
    assert not r["partial"], r["verdict_reason"]  # a finding about the vehicle, not a tester error
    assert "tester error" not in r["verdict_reason"].lower(), r["verdict_reason"]
    assert not (tmp_path / "r" / "tester-error.txt").exists()
    assert all(c["verdict"] not in ("fail", "non-strict") for c in r["clauses"]), \
        [(c["id"], c["reason"]) for c in r["clauses"] if c["verdict"] in ("fail", "non-strict")]


# ---------------------------------------------------------------------------- what counts as a re-run

def test_a_rerun_that_went_another_way_and_passed_is_not_counted(tmp_path, monkeypatch):
    """The first re-drive finds the vehicle mended and the recording's first expectation
    otherwise than the model's now (as when a timer raced a line differently): the steps did not
    lead where they led, so its pass says nothing and is not counted; the vehicle misbehaves again
    on the next two, which count: 2 of 2, FAIL. (Counting the first made it 1 of 2.)"""
    cores: list = []
    real = replay_mod.redrive
    reruns: list = []

    def first_rerun_goes_another_way(doc, session):
        if CLAUSE in session.ignore:  # the confirmation of another clause found (it ignores this one)
            return real(doc, session)
        reruns.append(doc)
        if len(reruns) == 1:
            cores[-1].faults = 0
            steps = [dict(st) for st in doc["steps"]]
            first = next(st for st in steps if "expect" in st)
            first["expect"] = "something the model does not expect now"
            doc = dict(doc, steps=steps)
        else:
            cores[-1].faults = None
        got = real(doc, session)
        if len(reruns) == 1:
            assert got.verdict == "pass" and not got.faithful and "went another way" in got.reason, got
        return got

    monkeypatch.setattr(replay_mod, "redrive", first_rerun_goes_another_way)
    with _serve(RefusesWith21, cores) as port:
        out = _certify(port, tmp_path / "r")
    r = out.results
    ex = r["stats"]["explore"]
    assert len(reruns) == 3, ex
    assert ex["confirmed"] == "2/2", ex
    finding = next(f for f in ex["findings"] if f["clause"] == CLAUSE)
    assert finding["reruns"][0].startswith("pass (not counted): "), finding["reruns"]
    assert all(x.startswith("fail: ") for x in finding["reruns"][1:]), finding["reruns"]
    assert _clause(r, CLAUSE)["verdict"] == "fail", _clause(r, CLAUSE)
    assert out.verdict == "fail" and out.exit_code == 1, out.reason


def _redrive(verdict: str, clause=None, faithful=True, reason="at step 3 of 5 ($OMS,…): …", ran=True):
    return replay_mod.Redrive(verdict, reason, clause, faithful, ran)


@pytest.mark.parametrize("got, counted", [
    (_redrive("fail", CLAUSE), True),
    (_redrive("fail", CLAUSE, faithful=False), True),  # went another way, and failed on it all the same
    (_redrive("fail", "RH-SRV-2"), False),  # the recorded way, but another clause failed first
    (_redrive("pass"), False),
    (_redrive("pass", faithful=False), None),
    (_redrive("inconclusive"), None),
    (_redrive("fail", CLAUSE, faithful=False, reason=f"{replay_mod.IN_RESET}: {CLAUSE}: …", ran=False), None),
])
def test_which_redrives_count_as_reruns(got, counted):
    assert explore_mod.counts(got, (CLAUSE, "RH-ACK-3")) is counted


# ---------------------------------------------------------------------------- finding or tester error

def test_a_vehicle_failure_hypothesis_cannot_replay_is_a_finding_not_a_tester_error(tmp_path):
    """The vehicle misbehaves once: hypothesis's replay passes and it ends with ``FlakyFailure``
    (holding the failure and a ``FlakyStrategyDefinition``: the replay ran on where the failing
    example had stopped). That is the vehicle's doing, judged like any finding."""
    cores: list = []
    with _serve(OnlyOnce, cores) as port:
        out = _certify(port, tmp_path / "r")
    r = out.results
    ex = r["stats"]["explore"]
    assert cores[0].misbehaved == 1, ex
    assert ex["outcome"] == "FlakyFailure" and ex["confirmed"] == "0/2", ex
    assert not r["partial"] and "tester error" not in r["verdict_reason"].lower(), r["verdict_reason"]
    assert not (tmp_path / "r" / "tester-error.txt").exists()
    assert _clause(r, CLAUSE)["verdict"] in ("fail", "inconclusive"), _clause(r, CLAUSE)  # judged


def test_what_counts_as_a_finding():
    found = explore_mod.VehicleFailure("RH-ACK-4: …")
    replayed = FlakyStrategyDefinition("the second run drew more data than the first run")
    bug = RuntimeError("a bug in helmcheck")
    assert explore_mod._vehicle_finding(found, 1)
    assert explore_mod._vehicle_finding(FlakyFailure("inconsistent", [found, replayed]), 1)
    assert explore_mod._vehicle_finding(FlakyFailure("inconsistent", [found]), 1)
    assert not explore_mod._vehicle_finding(FlakyFailure("inconsistent", [found, bug]), 1)
    assert not explore_mod._vehicle_finding(replayed, 0)  # no failure to explain it: helmcheck's
    assert not explore_mod._vehicle_finding(bug, 1)
    assert not explore_mod._vehicle_finding(AssertionError("an assert in helmcheck itself"), 1)



def _boom(*_a, **_k):
    raise RuntimeError("boom from a tester bug in the exploration")


def test_a_tester_error_inside_the_exploration_ends_the_run_2_with_its_traceback(tmp_path, capsys,
                                                                                 monkeypatch):
    monkeypatch.setattr(machine_mod, "context", _boom)  # every example's start calls it
    rdir = tmp_path / "r"
    with serve(lambda start: make_core(None, K, start)) as port:
        code = cli_main(["certify", "vehicle", "--port", port, "--time-scale", str(K), "--report-dir", str(rdir),
                         "--select", "RH-POS-1", "--examples", "5", "--seed", str(SEED), "--no-progress"])
    cap = capsys.readouterr()
    assert code == 2, (cap.out, cap.err)
    lines = [ln for ln in cap.err.splitlines() if ln.strip()]
    assert len(lines) == 1 and "Traceback" not in cap.err, cap.err
    m = re.fullmatch(r"helmcheck certify vehicle: tester error: RuntimeError: boom from a tester bug in the "
                     r"exploration — traceback in (\S+); please report it", lines[0])
    assert m, lines[0]
    assert Path(m.group(1)) == rdir / "tester-error.txt"
    text = (rdir / "tester-error.txt").read_text()
    assert "Traceback" in text and "_boom" in text and "machine.py" in text, text
    r = load_results(rdir)
    assert r["partial"] and r["verdict"] == "inconclusive", (r["verdict"], r["verdict_reason"])
    assert "tester error" in r["verdict_reason"].lower() and "tester-error.txt" in r["verdict_reason"], \
        r["verdict_reason"]
    assert r["stats"]["explore"]["outcome"] == "tester error", r["stats"]["explore"]
