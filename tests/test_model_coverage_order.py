"""The exploration's model coverage lists what it did not reach in value order: the model's rows
by number (row 2 before row 10, not as text), so a reader finds a row where they look for it."""

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
