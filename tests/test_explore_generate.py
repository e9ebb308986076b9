"""What the exploration draws (``helmcheck/certify/vehicle/generate.py``): a line that must be
refused is refused for one reason, so that a vehicle that gets that one reason wrong is told apart
from one that refuses the line for another (RH-PRM-2: the bytes, the reserved field and the
timeout of ``$OMP`` are each drawn off alone)."""

from __future__ import annotations

import re

from hypothesis import given
from hypothesis import strategies as st

from helmcheck.certify.vehicle.generate import commands, one_field_off, timeouts
from tests.faulty_vehicles import EMU_PROFILE

P = EMU_PROFILE
TOS = timeouts(13, P.timeout_range)  # the shortest timeable timeout on a line at x20
HEX10 = re.compile(r"[0-9A-Fa-f]{10}")


def _omp_fields_off(body: str) -> list[str]:
    """Which of ``$OMP``'s fields a conforming vehicle refuses (RH-PRM-2)."""
    f = body.split(",")
    if len(f) != 4:
        return ["field count"]
    off = []
    if not HEX10.fullmatch(f[1]):
        off.append("bytes")
    if f[2] != "00":
        off.append("reserved")
    lo, hi = P.timeout_range
    if not (f[3].isdigit() and lo <= int(f[3]) <= hi):
        off.append("timeout")
    return off


@given(st.one_of(commands(P, TOS, "motion"), one_field_off(P, TOS)))
def test_RH_PRM_2_an_omp_drawn_is_off_in_one_field_at_most(body):
    if body.startswith("OMP,"):
        assert len(_omp_fields_off(body)) <= 1, body
