"""Self-test by mutation: each faulty vehicle must fail certification on the right clause.

Every mutant in :mod:`tests.faulty_vehicles` is served behind a real pty (the emulator's own I/O
loop in a thread) at its time scale (25, or 60 where a whole mission must run) and certified with
only the clauses that reach its fault selected, so each run takes a few seconds.
"""

from __future__ import annotations

import pytest

from helmcheck.conformance.vehicle.runner import Options, certify
from tests.faulty_vehicles import EMU_PROFILE, MUTANTS, make_core, serve

def _certify(port, tmp_path, select, k, examples=0):
    opts = Options(port=port, profile=EMU_PROFILE.replace(time_scale=k), time_scale=k,
                   report_dir=tmp_path / "r", select=list(select), examples=examples, progress=False,
                   render=False, seed=1)
    return certify(opts)


@pytest.mark.parametrize("mutant", MUTANTS, ids=[m.name for m in MUTANTS])
def test_mutant_fails_on_its_clause(mutant, tmp_path):
    k = mutant.time_scale
    with serve(lambda start: make_core(mutant, k, start)) as port:
        out = _certify(port, tmp_path, mutant.select, k)
    failed = {c["id"]: c for c in out.results["clauses"] if c["verdict"] == "fail"}
    assert out.verdict == "fail", out.reason
    assert out.exit_code == 1
    assert mutant.clause in failed, f"failed {sorted(failed)}: {out.reason}"
    entry = failed[mutant.clause]
    assert entry["reason"] and entry["evidence"], entry


@pytest.mark.parametrize("k", sorted({m.time_scale for m in MUTANTS}))
def test_conforming_core_passes_the_same_selections(k, tmp_path):
    """The unmutated core passes every selection the mutants use, at their time scale (no false alarms)."""
    select = sorted({c for m in MUTANTS if m.time_scale == k for c in m.select})
    with serve(lambda start: make_core(None, k, start)) as port:
        out = _certify(port, tmp_path, select, k)
    bad = {c["id"]: c["reason"] for c in out.results["clauses"] if c["verdict"] not in ("pass", "not-tested")}
    assert not bad, bad
    assert out.verdict == "pass"
    assert {c["id"] for c in out.results["clauses"] if c["verdict"] == "pass"} >= set(select)
