"""The exploration's model coverage (``helmcheck/certify/vehicle/modelcover.py``): what it did not
reach listed in value order (the model's rows by number, row 2 before row 10, not as text, so a
reader finds a row where they look for it); the cases' reach counted apart; the traceability
table's hook."""

from __future__ import annotations

import re

from helmcheck.certify.vehicle.modelcover import ModelCoverage
from helmcheck.profile import emulator_profile


def test_uncovered_rows_are_in_numeric_order():
    cov = ModelCoverage(emulator_profile())
    cov.rows.update({0, 5, 11})
    summary = cov.summary()
    numbers = [int(re.match(r"row (\d+):", x).group(1)) for x in summary["rows"]["uncovered"]]
    assert numbers == sorted(numbers) and {0, 5, 11}.isdisjoint(numbers)
    assert numbers[:3] == [1, 2, 3] and 10 in numbers and 100 > max(numbers) >= 12
    for name in ("interrupt_pairs", "boundaries", "error_codes"):
        assert summary[name]["uncovered"], name


def test_the_traceability_table_plugs_in_as_a_rules_dimension_the_verdict_line_names():
    """The table of every rule of every clause (not built here) is given the keys the exploration
    reached and names the rules they exercised; the coverage then has a ``rules`` dimension and
    the verdict line lists the rules not reached rather than the transitions."""
    from helmcheck.certify.vehicle.modelcover import register_rules, rules_provider
    from helmcheck.reports.scope import exploration_note
    seen = []

    def table(keys):
        seen.append(keys)
        return (["RH-SRV-4.1"] if "row:65" in keys else []), ["RH-SRV-4.2", "RH-INT-2.3"]

    assert rules_provider() is None
    cov = ModelCoverage(emulator_profile())
    cov.rows.add(65)
    cov.timers.add("remote")
    register_rules(table)
    try:
        summary = cov.summary()
    finally:
        register_rules(None)
    assert {"row:65", "timer:remote"} <= seen[0]
    assert summary["rules"] == {"covered": 1, "of": 3, "percent": 33.3, "uncovered": ["RH-INT-2.3", "RH-SRV-4.2"],
                                "with_cases": 1}
    line = exploration_note({"stats": {"explore": {"model_coverage": summary}}})
    assert line.startswith("The exploration reached 1 of 91 transitions, ")
    assert "1 of 3 rules" in line and "rules not reached: RH-INT-2.3; RH-SRV-4.2" in line
    assert "rules" not in cov.summary()  # unplugged again


def test_the_cases_reach_counts_apart_and_the_aim_skips_it():
    """What the clause cases' lines reached is not the exploration's, but it is not aimed at again."""
    cov = ModelCoverage(emulator_profile())
    cov.reach["cases"].rows.add(21)
    cov.rows.add(24)
    s = cov.summary()["rows"]
    assert (s["covered"], s["with_cases"]) == (1, 2)
    assert "row 21: N/P/mP/W OMS -> A" in s["uncovered"]
    assert not {21, 24} & cov.uncovered()["rows"] and 21 in cov.uncovered(with_cases=False)["rows"]
