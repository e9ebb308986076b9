"""Self-test by mutation: each faulty vehicle must fail certification on the right clause.

Every mutant in :mod:`tests.faulty_vehicles` is served behind a real pty (the emulator's own I/O
loop in a thread) and certified, at each of its two time scales (``make test``: one of them, the
first and the second in turn down the list; ``make matrix``, ``HELMCHECK_MATRIX=1``: both), with
only the clauses that reach its fault selected, so each run takes a few seconds. The conforming core passes the same
selections at the same time scales (no false alarms). Some mutants say more: that the run fails
the clause that states the rule alone, not a neighbour (``only``), or that a fault in one field
of every report blinds the tester to nothing else (``blinds_nothing``: every other selected
clause judged as on the conforming core, the restore verified, exit 1). Every run directory is also re-judged
offline by the suite's agreement check (``tests/conftest.py``): live and offline must agree.
"""

from __future__ import annotations

import os

import pytest

from helmcheck.clauses import vehicle_clauses
from helmcheck.certify.vehicle.runner import Options, certify
from tests.judging import not_passed
from tests.faulty_vehicles import EMU_PROFILE, MUTANTS, make_core, serve

MATRIX = os.environ.get("HELMCHECK_MATRIX") == "1"
CASES = [(m, k) for i, m in enumerate(MUTANTS) for k in m.time_scales
         if MATRIX or k == m.time_scales[i % len(m.time_scales)]]


def _certify(port, tmp_path, select, k, examples=0):
    opts = Options(port=port, profile=EMU_PROFILE.replace(time_scale=k), time_scale=k,
                   report_dir=tmp_path / "r", select=list(select), examples=examples, progress=False,
                   render=False, seed=1)
    return certify(opts)


@pytest.mark.parametrize("mutant,k", CASES, ids=[f"{m.name}-x{k:g}" for m, k in CASES])
def test_mutant_fails_on_its_clause(mutant, k, tmp_path):
    with serve(lambda start: make_core(mutant, k, start)) as port:
        out = _certify(port, tmp_path, mutant.select, k)
    failed = {c["id"]: c for c in out.results["clauses"] if c["verdict"] == "fail"}
    assert out.verdict == "fail", (out.reason, [(c["id"], c["verdict"], c["reason"]) for c in out.results["clauses"]
                                                if c["verdict"] != "pass"])
    assert out.exit_code == 1
    assert mutant.clause in failed, f"failed {sorted(failed)}: {out.reason}"
    entry = failed[mutant.clause]
    assert entry["reason"] and entry["evidence"], entry
    if mutant.only:  # booked on the clause that states the rule (and those that also name it), no neighbour
        assert set(failed) == {mutant.clause, *mutant.also}, {c: e["reason"] for c, e in failed.items()}
    if mutant.blinds_nothing:  # every other selected clause judged as on the conforming core (the test
        # below: every selected clause passes there), the restore verified, exit 1 (above)
        judged = {c["id"] for c in out.results["clauses"] if c["verdict"] in ("pass", "fail", "inconclusive")}
        assert judged >= set(mutant.select), {c["id"]: c["reason"] for c in out.results["clauses"]
                                              if c["id"] in set(mutant.select) - judged}
        assert not not_passed(out.results, set(mutant.select) - {mutant.clause, *mutant.also})
        assert out.results["restore"]["verified"], out.results["restore"]


SCALES = sorted({k for _, k in CASES})


@pytest.mark.parametrize("k", SCALES)
def test_conforming_core_passes_the_same_selections(k, tmp_path):
    """The unmutated core passes every selection the mutants use, at their time scales."""
    select = sorted({c for m, mk in CASES if mk == k for c in m.select})
    with serve(lambda start: make_core(None, k, start)) as port:
        out = _certify(port, tmp_path, select, k)
    bad = not_passed(out.results)
    assert not bad, bad  # no FAIL, and nothing INCONCLUSIVE but for the host's load (tests/conftest.py)
    judged = {c["id"] for c in out.results["clauses"] if c["verdict"] in ("pass", "inconclusive")}
    assert judged >= set(select), set(select) - judged


def test_every_vehicle_clause_has_a_faulty_vehicle():
    """Mutation coverage: a clause no faulty vehicle fails is a clause the suite cannot show it
    judges."""
    covered = {m.clause for m in MUTANTS}
    missing = [c.id for c in vehicle_clauses() if c.id not in covered]
    assert not missing, f"no faulty vehicle for {', '.join(missing)}"
