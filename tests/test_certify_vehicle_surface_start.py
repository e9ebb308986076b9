"""A sequence or a re-drive starts at the surface (``Session.outwait_surface``).

A reset (``$OMSTOP,0`` → ``S``) stops a vehicle where it is: after a dive, still under water, where
it has no GPS fix and applies an ``$OPOS`` position that it ignores at the surface (RH-POS-2). A
re-drive that begins there asks something else than the sequence it re-drives (a finding of
``$OPOS`` applied with a fix does not fail again). So the exploration's start and the re-drive
wait, after the reset, until the vehicle reports a depth within ``gps_fix_depth_m``. The vehicle is
the emulator's core in virtual time, behind the certifier's own link and observer.
"""

from __future__ import annotations

from helmcheck.certify.vehicle.session import frame
from helmcheck.emulator.core import EmulatorCore
from helmcheck.emulator.missionfile import DirectoryCatalog, builtin_dir
from helmcheck.judge.vehicle.closure import osi_depth_m
from helmcheck.profile import emulator_profile
from tests.virtual_vehicle import certifier_session

K = 20.0


def session():
    profile = emulator_profile().replace(time_scale=K)
    return certifier_session(EmulatorCore(profile, DirectoryCatalog([builtin_dir()]), start=0.0, time_scale=K,
                                       baud=profile.baud), K)


def dived(ses) -> float:
    """Start the mission, dive with ``$OMS`` to 6 m and wait there; the depth reached."""
    ses.reset(mission=True)
    ses.exchange(frame("OMS,90,6,20,0.5,60"))
    ses.wait(40.0)
    return osi_depth_m(ses.poll(), ses.profile.depth_unit)


def test_a_reset_after_a_dive_leaves_the_vehicle_under_water_and_outwait_surface_brings_it_up():
    ses = session()
    assert dived(ses) > 2.0
    ses.reset(mission=False)
    under = osi_depth_m(ses.obs.last_osi, ses.profile.depth_unit)
    assert under > ses.profile.gps_fix_depth_m  # what a sequence began from before
    t0 = ses.now()
    ses.outwait_surface()
    assert osi_depth_m(ses.obs.last_osi, ses.profile.depth_unit) <= ses.profile.gps_fix_depth_m
    assert ses.now() > t0
    assert not ses.failures(), ses.failures()


def test_at_the_surface_it_does_not_wait():
    ses = session()
    ses.reset(mission=False)
    t0 = ses.now()
    ses.outwait_surface()
    assert ses.now() - t0 < 0.5
