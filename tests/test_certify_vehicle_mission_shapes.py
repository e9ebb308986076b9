"""One judge for any test mission §10 allows: conforming vehicles with differently shaped missions pass.

The judge must not have learnt the built-in emulator's test mission (a park on waypoint 1, about
150 m legs). Each shape below is a mission file written by the test; the emulator serves it as
the profile's test mission (its mission set is a parameter: a :class:`DirectoryCatalog` with the
shape's directory first), and the clauses that depend on the mission's geometry — jumps, parks,
interrupts, the mission's end, the waypoint queue and timeouts — are certified against it. A
conforming vehicle must pass every one; the suite's agreement check (``tests/conftest.py``) then
re-judges each run offline from its wire log.

* ``park-on-waypoint-0`` — the mission park is on waypoint 0, where the vehicle already is when
  the mission starts: it reports ``P`` at once, and again whenever a case restarts the mission.
* ``short-legs`` — legs of about 20 m: several waypoints can be passed between two polls.
* ``long-legs`` — legs of about 300 m, the park on waypoint 2: arrivals are rare and far apart.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from helmcheck.emulator.core import EmulatorCore
from helmcheck.emulator.missionfile import DirectoryCatalog, builtin_dir
from helmcheck.certify.vehicle.runner import Options, certify
from helmcheck.grammar.wirelog import read_records
from tests.faulty_vehicles import EMU_PROFILE, serve
from tests.judging import not_passed

HEADER = "helmcheck-mission 1\n# lat  lon  depth_m  speed_kn  park_s\n"

SHAPES = {
    # the vehicle's home position is 41.52 N, 71.32 W (the emulator's start)
    "park-on-waypoint-0": ("41.520000 -71.320000 2.0 2.0 120\n"
                           "41.521000 -71.320000 2.0 2.0 0\n"
                           "41.521000 -71.319000 2.0 2.0 0\n"
                           "41.520000 -71.319000 0.0 2.0 0\n", 0),
    "short-legs": ("41.520180 -71.320000 1.0 2.0 0\n"
                   "41.520360 -71.320000 1.0 2.0 200\n"
                   "41.520360 -71.319760 1.0 2.0 0\n"
                   "41.520180 -71.319760 0.0 2.0 0\n", 1),
    "long-legs": ("41.522700 -71.320000 5.0 2.0 0\n"
                  "41.525400 -71.320000 5.0 2.0 0\n"
                  "41.525400 -71.316400 5.0 2.0 90\n"
                  "41.522700 -71.316400 0.0 2.0 0\n", 2),
}

#: The clauses whose judging depends on the test mission's shape.
GEOMETRY = ["RH-JW-1", "RH-JW-2", "RH-PK-1", "RH-PK-2", "RH-PK-3", "RH-INT-1", "RH-INT-2", "RH-INT-3",
            "RH-MSN-2", "RH-MSN-3", "RH-MSN-4", "RH-OMW-2", "RH-OMW-4", "RH-OMW-5", "RH-OUT-4"]

#: Time scale per shape: the long legs run faster (RH-TIM-1's 10 s timeouts are not judgeable
#: there, so it is certified on the two shorter shapes only).
RUNS = [("park-on-waypoint-0", 50.0, GEOMETRY + ["RH-TIM-1"]),
        ("short-legs", 50.0, GEOMETRY + ["RH-TIM-1"]),
        ("long-legs", 100.0, GEOMETRY)]


def _mission_dir(tmp_path: Path, shape: str) -> Path:
    d = tmp_path / "missions"
    d.mkdir()
    (d / EMU_PROFILE.mission).write_text(HEADER + SHAPES[shape][0])
    return d


def _park_reports(log: Path) -> set[int]:
    """The waypoints (``$OSI`` field 3) at which the vehicle reported a mission park ``P``."""
    with log.open("rb") as f:
        sent = b"".join(r.data for r in read_records(f) if r.dir == "<")
    out = set()
    for line in sent.split(b"\r\n"):
        f3 = line.split(b"*")[0].split(b",")
        if f3[0] == b"$OSI" and len(f3) > 3 and f3[2] == b"P":
            out.add(int(f3[3]))
    return out


@pytest.mark.parametrize("shape,k,select", RUNS, ids=[r[0] for r in RUNS])
def test_a_conforming_vehicle_passes_with_any_mission_shape(shape, k, select, tmp_path):
    missions = DirectoryCatalog([_mission_dir(tmp_path, shape), builtin_dir()])
    prof = EMU_PROFILE.replace(time_scale=k)
    with serve(lambda start: EmulatorCore(prof, missions, start=start, time_scale=k, baud=prof.baud)) as port:
        out = certify(Options(port=port, profile=prof, time_scale=k, report_dir=tmp_path / "r", select=select,
                              examples=0, progress=False, render=False, seed=1))
    bad = not_passed(out.results)
    assert not bad, bad  # no FAIL, and nothing INCONCLUSIVE but for the host's load
    judged = {c["id"] for c in out.results["clauses"] if c["verdict"] in ("pass", "inconclusive")}
    assert judged >= set(select), sorted(set(select) - judged)
    # the shape was really the one exercised: the mission park was reported on its waypoint
    assert SHAPES[shape][1] in _park_reports(tmp_path / "r" / "wire.log"), _park_reports(tmp_path / "r" / "wire.log")
