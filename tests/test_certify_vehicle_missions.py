"""``end_mission`` and ``srp_mission`` default to none: a vehicle that does not name them gets
NOT-TESTED with the reason for what needs them (RH-MSN-4, the srp branch of RH-SAF-4), never
INCONCLUSIVE. Certified against the emulator (which does ship such missions: the profile, not the
vehicle, decides)."""

from __future__ import annotations

from helmcheck.certify.vehicle.runner import Options, certify
from helmcheck.profile import DEFAULT
from tests.faulty_vehicles import EMU_PROFILE, make_core, serve

K = 40.0


def test_a_profile_without_end_or_srp_mission_makes_their_cases_not_tested(tmp_path):
    profile = EMU_PROFILE.replace(time_scale=K, end_mission=DEFAULT.end_mission, srp_mission=DEFAULT.srp_mission)
    assert (profile.end_mission, profile.srp_mission) == ("", "")
    with serve(lambda start: make_core(None, K, start)) as port:
        out = certify(Options(port=port, profile=profile, time_scale=K, report_dir=tmp_path / "r",
                              select=["RH-MSN-4", "RH-SAF-4"], examples=0, progress=False, render=False, seed=1))
    clauses = {c["id"]: c for c in out.results["clauses"]}
    cases = {c["id"]: c for c in out.results["cases"]}
    assert not [c for c in clauses.values() if c["verdict"] == "inconclusive"], clauses
    assert not [c for c in cases.values() if c["verdict"] == "inconclusive"], cases
    msn4 = clauses["RH-MSN-4"]
    assert msn4["verdict"] == "not-tested" and "names no end_mission" in msn4["reason"], msn4
    assert cases["V-47"]["verdict"] == "not-tested" and "end_mission" in cases["V-47"]["reason"]
    assert cases["V-63"]["verdict"] == "not-tested" and "names no srp_mission" in cases["V-63"]["reason"]
    assert cases["V-61"]["verdict"] == "pass"  # the park branch of RH-SAF-4 needs no mission
    assert clauses["RH-SAF-4"]["verdict"] == "pass"
    assert out.verdict == "pass" and out.exit_code == 0
