"""The shipped copy of the reference profile is the shared specification, byte for byte."""

from __future__ import annotations

from pathlib import Path

import pytest

from helmcheck.clauses import backseat_clauses, catalogue, clause, vehicle_clauses

SHARED = Path(__file__).resolve().parents[2] / "shared" / "spec" / "reference-profile.md"


@pytest.mark.skipif(not SHARED.exists(), reason="shared specification not beside this checkout")
def test_shipped_spec_matches_shared_spec():
    shipped = Path(__file__).resolve().parents[1] / "helmcheck" / "spec" / "reference-profile.md"
    assert shipped.read_bytes() == SHARED.read_bytes(), "run: cp ../shared/spec/reference-profile.md helmcheck/spec/"


def test_catalogue_reads_every_family():
    fams = {c.family for c in catalogue().values()}
    assert {"FRM", "ACK", "OUT", "INT", "SRV", "PRM", "JW", "PK", "OMW", "MSN", "POS", "OSD", "LOG",
            "SET", "DVL", "SAF", "TIM", "RD", "BS"} == fams
    assert clause("RH-BS-5").level == "SHOULD" and clause("RH-SRV-4").level == "MUST"
    assert len(backseat_clauses()) == 8 and all(c.role == "vehicle" for c in vehicle_clauses())
    assert "20 s" in clause("RH-SAF-1").text


def test_unknown_clause_is_named():
    with pytest.raises(KeyError, match="RH-XXX-1"):
        clause("RH-XXX-1")
