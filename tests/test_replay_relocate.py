"""A replay asks, relative to the vehicle, what it asked when recorded (``certify/vehicle/relocate.py``).

The exploration's positions are drawn relative to where the vehicle is, and the vehicle moves over
a run; a replay carries the position its steps began at (``origin``) and a re-drive moves every
position it sends by the difference to where the vehicle begins it. Unit properties of the move
(positions moved and moved back are the same bytes; edges, other sentences and lines mutated in
their framing stay byte for byte), and the case that made it necessary: an ``$OPOS`` 1.1 km north
of a vehicle that applies it with a GPS fix (RH-POS-2), recorded where the vehicle was before the
fault moved it there — re-driven on the same vehicle without the move it asks for the vehicle's
own position and shows nothing. And a vehicle further than 10 m from where the steps began is
driven back there first (``replay._return``), when it claims ``$OMW``.
"""

from __future__ import annotations

import json

import pytest
from hypothesis import given, strategies as st

from helmcheck.certify.vehicle.relocate import shift_line
from helmcheck.cli import main as cli_main
from helmcheck.emulator.freedoms import EmulatorSettings
from helmcheck.grammar import checksum_hex
from tests.faulty_vehicles import EMU_PROFILE, MUTANTS, make_core, serve

K = 25.0


def line(body: str) -> bytes:
    return f"${body}*{checksum_hex(body)}\r\n".encode()


lat6 = st.integers(-89_000_000, 89_000_000).map(lambda n: f"{n / 1e6:.6f}")
lon6 = st.integers(-179_000_000, 179_000_000).map(lambda n: f"{n / 1e6:.6f}")
delta = st.integers(-500_000, 500_000).map(lambda n: n / 1e6)


@given(lat=lat6, lon=lon6, dlat=delta, dlon=delta,
       fmt=st.sampled_from(["OPOS,{},{},0,35,12", "OPK,{},{},1,0.5", "OMW,{},{},2,,15,0.5,0,",
                            "OMW,CLEAR,{},{},2,,15,0.5,0,"]))
def test_moved_and_moved_back_is_the_same_line(lat, lon, dlat, dlon, fmt):
    raw = line(fmt.format(lat, lon))
    moved = shift_line(raw, dlat, dlon)
    f = moved.decode().split(",")
    at = 2 if "CLEAR" in fmt else 1
    assert abs(float(f[at]) - (float(lat) + dlat)) < 1e-6 and abs(float(f[at + 1]) - (float(lon) + dlon)) < 1e-6
    body = moved[1:moved.index(b"*")].decode()
    assert moved.endswith(f"*{checksum_hex(body)}\r\n".encode())  # a line the vehicle reads as written
    assert shift_line(moved, -dlat, -dlon) == raw


@pytest.mark.parametrize("raw", [
    line("OPOS,91,181,0,35,12"), line("OPK,-91,-181,1,0.5"),                 # range edges: not positions
    line("OSD,S"), line("OMS,90,2,20,0.5,10"), line("OJW,2"),               # no position
    b"$OPOS,41.520000,-71.320000,0,35,12*00\r\n",                           # a wrong checksum
    line("OPOS,41.520000,-71.320000,0,35,12").lower(),                      # mutated in its framing
    b"$OPOS,41.520000,-71.320000,0,35,12\r\n",                              # no checksum
])
def test_lines_that_are_not_positions_read_as_written_stay_byte_for_byte(raw):
    assert shift_line(raw, 0.25, -0.5) == raw


def test_lines_written_back_to_back_each_move():
    raw = line("OSD,S") + line("OPOS,41.520000,-71.320000,0,35,12") + line("OPK,91,-71.320000,1,0.5")
    out = shift_line(raw, 0.01, 0.0)
    assert out.split(b"\r\n")[0] + b"\r\n" == line("OSD,S")
    assert line("OPOS,41.530000,-71.320000,0,35,12") in out
    assert line("OPK,91,-71.320000,1,0.5") in out  # the latitude is an edge; the longitude stays inside


def _replay(tmp_path, origin):
    """An ``$OPOS`` at the vehicle's start position, recorded where the vehicle was 1.1 km south;
    for a vehicle that does not claim ``$OMW`` (a re-drive cannot drive it back to where the steps
    began: only the move of the positions makes the steps ask what they asked)."""
    home = EmulatorSettings()
    profile = EMU_PROFILE.replace(time_scale=K).as_dict()
    profile["commands"] = [c for c in profile["commands"] if c != "OMW"]
    body = f"OPOS,{home.start_lat:.6f},{home.start_lon:.6f},0,35,12"
    doc = {"format": "helmcheck-replay", "version": 2, "clause": "RH-POS-2", "reason": "by hand",
           "time_scale": K, "profile": profile, "start": "verified-reset",
           "lazy_silence": True,
           "steps": [{"send": "$OSD,S*27\\r\\n", "t": 0.0}, {"send": line(body).decode().replace("\r\n", "\\r\\n"),
                                                                "t": 0.05},
                     {"send": "$OSD,S*27\\r\\n", "t": 0.1}]}
    if origin:
        doc["origin"] = [round(home.start_lat - 0.01, 6), home.start_lon]
    path = tmp_path / f"replay-{bool(origin)}.json"
    path.write_text(json.dumps(doc))
    return path


@pytest.mark.parametrize("origin", [True, False])
def test_an_opos_applied_with_a_fix_fails_again_only_where_it_is_asked_relative_to_the_vehicle(
        tmp_path, capsys, origin):
    mutant = next(m for m in MUTANTS if m.name == "opos-ignores-gps-fix")
    path = _replay(tmp_path, origin)
    capsys.readouterr()
    with serve(lambda start: make_core(mutant, K, start)) as port:
        code = cli_main(["replay", str(path), "--port", port])
    text = capsys.readouterr().out
    if origin:  # moved 1.1 km north of the vehicle: applied, and seen
        assert code == 1 and "RH-POS-2" in text, text
    else:  # the vehicle's own position: nothing to see
        assert code == 0, text
    with serve(lambda start: make_core(None, K, start)) as port:  # the conforming vehicle
        assert cli_main(["replay", str(path), "--port", port]) == 0, capsys.readouterr().out


def test_a_vehicle_far_from_where_the_steps_began_is_driven_back_first(tmp_path, capsys):
    """30 m from the replay's origin, the re-drive drives the vehicle back ($OMSTART, $OMW past the
    origin by the on-station distance) before the steps: the first report of the steps is about on
    the origin (within 1.5 m: the emulator runs in this process, and a busy host keeps it a few
    hundredths of a second from its reports), not up to the on-station distance short of it."""
    from helmcheck.model.geo import distance_m
    home = EmulatorSettings()
    origin = [round(home.start_lat + 30.0 / 111320.0, 6), home.start_lon]
    doc = {"format": "helmcheck-replay", "version": 2, "clause": "RH-OUT-4", "reason": "by hand", "time_scale": K,
           "profile": EMU_PROFILE.replace(time_scale=K).as_dict(), "start": "verified-reset", "lazy_silence": True,
           "origin": origin, "steps": [{"send": "$OSD,S*27\\r\\n", "t": 0.0}]}
    path = tmp_path / "far.json"
    path.write_text(json.dumps(doc))
    log = tmp_path / "wire.log"
    with serve(lambda start: make_core(None, K, start)) as port:
        assert cli_main(["replay", str(path), "--port", port, "--wire-log", str(log)]) == 0, capsys.readouterr().out
    text = log.read_text()
    assert "driven back there first" in text, text[-2000:]
    last = [ln for ln in text.splitlines() if "< $OSI," in ln][-1].split(",")
    assert distance_m(float(last[4]), float(last[5]), *origin) <= 1.5, last


def test_after_the_last_step_a_redrive_follows_a_queue_to_its_end():
    """``replay._arrive``: a vehicle still following its ``$OMW`` queue after the last step is polled
    until the queue is done (a vehicle a few metres from where the recording began takes longer to
    get where the recorded failure showed); one that follows nothing is not waited for."""
    from helmcheck.certify.vehicle.replay import _arrive
    from helmcheck.certify.vehicle.session import frame
    from tests.test_certify_vehicle_surface_start import session
    ses = session()
    ses.reset(mission=True)
    lat, lon = map(float, ses.here())
    assert ses.exchange(frame(f"OMW,{lat + 10.0 / 111320.0:.6f},{lon:.6f},0,,15,0.5,0,")).accepted
    assert ses.poll().mode == "W"
    t0 = ses.now()
    _arrive(ses)
    assert ses.obs.last_osi.mode != "W" and ses.now() > t0
    t1 = ses.now()
    _arrive(ses)
    assert ses.now() - t1 < 0.2
    assert not ses.failures(), ses.failures()
