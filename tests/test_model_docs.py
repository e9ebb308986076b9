"""Generated model docs are current; every vehicle clause of §2–8 is named by a model test."""

from __future__ import annotations

from pathlib import Path

from helmcheck.clauses import catalogue
from helmcheck.model import docs
from helmcheck.model.coverage import MODEL_FAMILIES, clause_coverage, vehicle_clause_ids
from helmcheck.model.transitions import TABLE

TESTS = Path(__file__).resolve().parent


def test_generated_docs_are_up_to_date():
    stale = docs.stale()
    assert not stale, f"run `python -m helmcheck.model.docs`; stale: {stale}"


def test_docs_name_every_row_and_state():
    md = docs.render_markdown()
    dot = docs.render_dot()
    assert all(f"| {r.id} |" in md for r in TABLE)
    assert dot.startswith("// generated") and "cluster_safety" in dot and '"mP"' in dot


def test_docs_check_command(tmp_path):
    assert docs.main(["--dir", str(tmp_path), "--check"]) == 1
    assert docs.main(["--dir", str(tmp_path)]) == 0
    assert docs.main(["--dir", str(tmp_path), "--check"]) == 0


def test_table_cites_only_known_clauses():
    known = catalogue()
    for r in TABLE:
        for c in r.clauses:
            assert c in known, (r.id, c)


def test_every_vehicle_clause_of_sections_2_to_8_has_a_model_test():
    ids = vehicle_clause_ids()
    assert "RH-SRV-4" in ids and "RH-FRM-1" not in ids and "RH-RD-1" not in ids
    assert {i.split("-")[1] for i in ids} == set(MODEL_FAMILIES)
    files = sorted(TESTS.glob("test_model*.py"))
    found = clause_coverage(files, ids)
    missing = [cid for cid, where in found.items() if not where]
    assert not missing, "clauses without a model test: " + ", ".join(missing)
