"""RH-SAF-2 when the report of the carried-out command lands just before the lockout's end is due.

A vehicle that carries out, when the lockout ends, a command it refused (26) during it breaks
RH-SAF-2. Its lockout may end a little before the judge's nominal end (RH-TIM-1's tolerance: the
start of a lockout raised by ``$OXFLT`` is known only to within the line, and a conforming clock
may run a little fast); a report sent in that gap shows the carried-out command while the mirror
still counts the lockout. That report must still be booked on RH-SAF-2, not on the lockout's own
RH-SAF-1 or the generic RH-OUT-4: a certification once failed so under load. The session is the
emulator's core with a faulty model (the command held and carried out), driven in virtual time,
then the first report in ``M`` moved to ``shift`` seconds before its own time (still after the
report before it), as that vehicle's slightly early lockout end would have sent it.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from helmcheck.checklog.checker import check_log
from tests.faulty_vehicles import EMU_PROFILE
from tests.faulty_vehicles.control import LockoutCommandsQueued
from tests.virtual_vehicle import VirtualVehicle, osi_fields

PROFILE = EMU_PROFILE.replace(time_scale=1.0)


def session(path: Path) -> Path:
    """``$OXFLT,Sop``, an ``$OMP`` refused in the lockout, then ``$OSD,S`` every 0.5 s until ``M``."""
    vv = VirtualVehicle(PROFILE, model_factory=LockoutCommandsQueued)
    vv.now = 1.0
    vv.send("OSD,S")
    vv.now += 0.5
    vv.send("OXFLT,Sop")
    vv.now += 0.5
    assert b"$ACK,10,1,26" in vv.send("OMP,8080808080,00,60")
    while vv.now < 40:
        vv.now += 0.5
        f = osi_fields(vv.send("OSD,S"))
        if f is not None and f[2] == "M":
            break
    vv.now += 0.5
    vv.send("OSD,S")
    return vv.write(path)


def moved_earlier(path: Path, shift: float) -> Path:
    """The log with the first report in ``M`` (its ``$OSD,S`` and its ``$ACK``) ``shift`` s earlier."""
    lines = path.read_text().splitlines(keepends=True)
    i = next(i for i, ln in enumerate(lines) if ",M," in ln and "$OSI," in ln)
    j = i - 1  # its $OSD,S
    assert "> $OSD,S" in lines[j]
    prev = max(float(ln.split()[0]) for ln in lines[:j] if not ln.startswith("#") and "$OSI," in ln)
    out = []
    for k, ln in enumerate(lines):
        if j <= k <= i + 1 and not ln.startswith("#"):
            t, rest = ln.split(" ", 1)
            nt = float(t) - shift
            assert nt > prev, "the move must keep the report after the one before it"
            ln = f"{nt:.6f} {rest}"
        out.append(ln)
    dst = path.with_name(f"moved-{shift:g}.log")
    dst.write_text("".join(out))
    return dst


@pytest.mark.parametrize("shift", [0.0, 0.1, 0.25, 0.4])
def test_a_refused_command_carried_out_is_rh_saf_2_even_reported_early(tmp_path, shift):
    log = moved_earlier(session(tmp_path / "wire.log"), shift)
    out = check_log(log, profile=PROFILE, role="vehicle")
    failed = {c["id"]: c["reason"] for c in out.clauses if c["verdict"] == "fail"}
    assert "RH-SAF-2" in failed, failed


def test_the_conforming_core_passes_the_same_session(tmp_path):
    """The same session on the unmutated core (the $OMP stays refused): no FAIL."""
    from helmcheck.model import VehicleModel
    vv_log = tmp_path / "wire.log"
    vv = VirtualVehicle(PROFILE, model_factory=VehicleModel)
    vv.now = 1.0
    vv.send("OXFLT,Sop")
    vv.now += 0.5
    assert b"$ACK,10,1,26" in vv.send("OMP,8080808080,00,60")
    while vv.now < 30:
        vv.now += 0.5
        vv.send("OSD,S")
    vv.write(vv_log)
    out = check_log(vv_log, profile=PROFILE, role="vehicle")
    failed = {c["id"]: c["reason"] for c in out.clauses if c["verdict"] == "fail"}
    assert not failed, failed
