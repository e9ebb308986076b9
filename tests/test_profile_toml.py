"""The profile emitter (``profile.toml`` in every run directory): ``load_profile(emit(p)) == p``.

A run's profile is re-read by ``helmcheck verify`` to re-judge the wire log, so the round trip must
be exact for the defaults and for any valid profile (hypothesis builds them through the same
validation a file goes through), and the text must be the same bytes every time.
"""

from __future__ import annotations

import tomllib

from hypothesis import given, settings
from hypothesis import strategies as st

from helmcheck.profile import COMMAND_IDS, DEFAULT, OSI_FIELD_RANGE, PROTOCOLS, load_profile, profile_from_dict
from helmcheck.profile_toml import emit_profile


def _roundtrip(tmp_path, profile, name="p.toml"):
    path = tmp_path / name
    path.write_text(emit_profile(profile), encoding="utf-8")
    return load_profile(path).replace(name=profile.name)


def test_defaults_round_trip(tmp_path):
    assert _roundtrip(tmp_path, DEFAULT) == DEFAULT


def test_every_key_is_written_and_the_text_is_deterministic():
    text = emit_profile(DEFAULT)
    data = tomllib.loads(text)
    assert "violation_trigger" not in data  # "" = derived from fault_injection, not a file value
    assert data["bench_safety"] == {"in_water": False, "max_motor_byte": 0x90, "max_speed_kn": 0.5}
    assert data["lockout_s"] == 20.0 and isinstance(data["lockout_s"], float)
    assert emit_profile(DEFAULT.replace(name="elsewhere.toml")) == text


def test_awkward_strings_survive(tmp_path):
    p = DEFAULT.replace(vehicle_name='IVER3 "Ørsted" \\ #1\t\x01\x7f\u00a0\U0001F30A', mission="a'b.mis",
                        omw_clear_keywords=("", "x=y", "[t]"), vehicle_serial="S/N 0042")
    assert _roundtrip(tmp_path, p) == p


_text = st.text(max_size=16)
_pos = st.floats(min_value=1e-6, max_value=60.0, allow_nan=False, allow_infinity=False)
_nonneg = st.floats(min_value=0.0, max_value=10.0, allow_nan=False, allow_infinity=False)


@st.composite
def profile_data(draw):
    """A valid profile file's data (what tomllib would give), covering every key."""
    protocol = draw(st.sampled_from(PROTOCOLS))
    lo, hi = OSI_FIELD_RANGE[protocol]
    t_lo = draw(st.integers(0, 200))
    fault = draw(st.sampled_from(("none", "oxflt")))
    triggers = ["", "none", "operator", "mission-rule"] + (["oxflt"] if fault == "oxflt" else [])
    trigger = draw(st.sampled_from(triggers))
    data = {
        "protocol": protocol,
        "depth_unit": draw(st.sampled_from(("m", "ft"))),
        "ack_window_s": draw(_pos),
        "lockout_s": draw(st.floats(min_value=0.001, max_value=3600.0)),
        "timeout_range": [t_lo, t_lo + draw(st.integers(0, 200))],
        "max_depth_m": draw(st.floats(min_value=0.01, max_value=11000.0)),
        "max_speed_kn": draw(st.floats(min_value=0.0, max_value=50.0)),
        "osi_fields": draw(st.integers(lo, hi)),
        "osd_letters": draw(st.text(alphabet="GCSPYDTI", min_size=1, max_size=8)),
        "commands": draw(st.lists(st.sampled_from(COMMAND_IDS), max_size=14)),
        "mission": draw(_text),
        "mission_waypoints": draw(st.integers(1, 100000)),
        "fault_injection": fault,
        "violation_mission": draw(_text.filter(bool)) if trigger == "mission-rule" else draw(_text),
        "violation_after_s": draw(st.floats(min_value=0.5, max_value=86400.0)),
        "reaction_s": draw(_nonneg),
        "time_scale": draw(st.floats(min_value=0.01, max_value=1000.0)),
        "baud": draw(st.sampled_from((9600, 19200, 38400, 57600, 115200))),
        "bench_safety": {"in_water": draw(st.booleans()), "max_motor_byte": draw(st.integers(0, 255)),
                         "max_speed_kn": draw(st.floats(min_value=0.0, max_value=1e6))},
        "max_line_bytes": draw(st.integers(16, 65536)),
        "lowercase_checksum_in": draw(st.booleans()),
        "waypoint_base": draw(st.sampled_from((0, 1))),
        "omw_clear_keywords": draw(st.lists(_text, max_size=4)),
        "safety_action": draw(st.sampled_from(("park", "srp"))),
        "on_station_m": draw(st.floats(min_value=0.001, max_value=10000.0)),
        "gps_fix_depth_m": draw(st.floats(min_value=0.0, max_value=100.0)),
        "opk_max_distance_m": draw(st.floats(min_value=0.0, max_value=100000.0)),
        "vehicle_name": draw(_text),
        "end_mission": draw(_text),
        "srp_mission": draw(_text),
        "vehicle_serial": draw(_text),
        "uvc_version": draw(_text),
    }
    if trigger:
        data["violation_trigger"] = trigger
    return data


@settings(derandomize=True, max_examples=150, deadline=None)
@given(profile_data())
def test_any_valid_profile_round_trips(data):
    """``load_profile(emit(p)) == p`` modulo ``name``, for profiles built as files are."""
    import tempfile
    from pathlib import Path

    profile = profile_from_dict(data, where="generated")
    text = emit_profile(profile)
    assert emit_profile(profile) == text
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "profile.toml"
        path.write_text(text, encoding="utf-8")
        back = load_profile(path)
    assert back.replace(name="generated") == profile
    assert emit_profile(back) == text
