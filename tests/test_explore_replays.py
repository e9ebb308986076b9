"""Replays that reproduce: a failure the exploration alone finds is saved with everything from the
verified reset that led to it, and re-driven on a *fresh* instance of the same faulty vehicle it
fails again, at the step named (``helmcheck/certify/vehicle/replay.py``); on the conforming
vehicle the same file passes.

The two faults are the deep kinds a replay used to lose: a lockout that ends early (RH-SAF-1: the
failure comes 10 s after the ``$OXFLT`` that set it going, and a replay without that ``$OXFLT``
passes) and a ``$OPK`` park that an interrupting control hands back to (RH-INT-3: park, interrupt,
release). Each is certified with one trivial clause selected (RH-POS-1), so that only the
exploration can find it, at a fixed seed.
"""

from __future__ import annotations

import json
import os

import pytest

from helmcheck.cli import main as cli_main
from helmcheck.certify.vehicle.runner import Options, certify
from tests.faulty_vehicles import EMU_PROFILE, MUTANTS, make_core, serve

K = 25.0
#: fault -> (its clause, the fixed seed the exploration runs at)
FAULTS = {"lockout-10s": ("RH-SAF-1", 1), "opk-kept-after-interrupt": ("RH-INT-3", 1)}


def _mutant(name):
    return next(m for m in MUTANTS if m.name == name)


#: ``make matrix``'s (a minute or two each); ``make test`` replays a finding in
#: tests/test_certify_vehicle.py (test_exploration_shrinks_and_replays)
MATRIX_ONLY = {"lockout-10s", "opk-kept-after-interrupt"}
MATRIX = os.environ.get("HELMCHECK_MATRIX") == "1"


@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.skipif(
    n in MATRIX_ONLY and not MATRIX, reason="make matrix's (HELMCHECK_MATRIX=1): a minute or two of make test's budget"))
    for n in sorted(FAULTS)])
def test_an_exploration_finding_replays_on_a_fresh_vehicle(name, tmp_path, capsys):
    """The fault's own clause is among the replays; every replay saved fails again on a fresh
    instance of the faulty vehicle, naming its clause, and passes on the conforming one."""
    mutant = _mutant(name)
    own, seed = FAULTS[name]
    with serve(lambda start: make_core(mutant, K, start)) as port:
        out = certify(Options(port=port, profile=EMU_PROFILE.replace(time_scale=K), time_scale=K,
                              report_dir=tmp_path / "r", select=["RH-POS-1"], progress=False, render=False,
                              seed=seed, explore_budget_s=45.0))
    failed = {c["id"] for c in out.results["clauses"] if c["verdict"] == "fail"}
    replays = out.results["replays"]
    assert own in failed and own in {r["clause"] for r in replays}, (replays, out.results["stats"]["explore"])
    for rep in replays:
        clause = rep["clause"]
        assert clause in failed, (clause, failed)
        path = tmp_path / "r" / rep["file"]
        doc = json.loads(path.read_text())
        assert doc["version"] == 2 and doc["start"] == "verified-reset"
        sent = [st["send"] for st in doc["steps"] if "send" in st]
        assert sent[0].startswith("$OLOGL,"), sent[:3]  # what the sequence sent after its verified reset
        if clause == "RH-SAF-1":
            assert any(x.startswith("$OXFLT,") for x in sent), sent  # the violation that set it going
        capsys.readouterr()
        with serve(lambda start: make_core(mutant, K, start)) as port:  # a fresh instance
            code = cli_main(["replay", str(path), "--port", port])
        text = capsys.readouterr().out
        assert code == 1 and text.startswith("STILL FAILS: at step "), text
        assert clause in text, text
        with serve(lambda start: make_core(None, K, start)) as port:  # the conforming vehicle
            code = cli_main(["replay", str(path), "--port", port])
        text = capsys.readouterr().out
        assert code == 0 and text.startswith("PASSES NOW"), text
