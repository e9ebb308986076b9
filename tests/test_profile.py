"""Profile files (§10): every [D] a key, unknown keys and bad values refused with a clear error."""

from __future__ import annotations

import pytest

from helmcheck.profile import DEFAULT, ProfileError, load_profile


def _write(tmp_path, text):
    p = tmp_path / "p.toml"
    p.write_text(text)
    return p


def test_defaults_are_rh5():
    assert (DEFAULT.protocol, DEFAULT.osi_fields, DEFAULT.lockout_s, DEFAULT.depth_unit) == ("rh5", 21, 20.0, "m")


def test_the_section_10_example_loads(tmp_path):
    from importlib import resources
    text = resources.files("helmcheck.spec").joinpath("reference-profile.md").read_text()
    example = text.split("```toml", 1)[1].split("```", 1)[0]
    p = load_profile(_write(tmp_path, example))
    assert p.bench_safety.max_motor_byte == 0x90 and p.commands[0] == "OMS"


@pytest.mark.parametrize("text,needle", [
    ("protocl = 'rh5'", "unknown key 'protocl'"),
    ("protocol = 'rh9'", "key 'protocol'"),
    ("lockout_s = -1", "key 'lockout_s'"),
    ("timeout_range = [5, 1]", "key 'timeout_range'"),
    ("commands = ['OMS', 'OFOO']", "unknown command 'OFOO'"),
    ("[bench_safety]\nmax_motor_byte = 300", "max_motor_byte"),
    ("[bench_safety]\nspeed = 1", "unknown key 'bench_safety.speed'"),
    ("baud = 12345", "key 'baud'"),
    ("osi_fields = 17", "expects" if False else "osi_fields"),
    ("protocol = = 'rh5'", "not valid TOML"),
])
def test_bad_profiles_name_file_and_key(tmp_path, text, needle):
    path = _write(tmp_path, text)
    with pytest.raises(ProfileError) as e:
        load_profile(path)
    assert str(path) in str(e.value) and needle in str(e.value)


def test_missing_profile_file_is_a_clear_error(tmp_path):
    with pytest.raises(ProfileError, match="cannot read profile"):
        load_profile(tmp_path / "nope.toml")


def test_rh4_defaults_to_feet_and_shorter_osi(tmp_path):
    p = load_profile(_write(tmp_path, "protocol = 'rh4'"))
    assert p.depth_unit == "ft" and p.osi_fields == 17
    assert abs(p.max_depth - 328.08) < 0.01


def test_end_and_srp_missions_are_string_keys(tmp_path):
    """RH-MSN-4 ``end_mission`` and RH-SAF-4 ``srp_mission``: none by default (a real vehicle is not
    assumed to hold the emulator's missions), any name or empty (none) in a file, and refused when
    not a string."""
    assert (DEFAULT.end_mission, DEFAULT.srp_mission) == ("", "")
    p = load_profile(_write(tmp_path, "end_mission = 'sub/end.mis'\nsrp_mission = ''"))
    assert (p.end_mission, p.srp_mission) == ("sub/end.mis", "")
    for key in ("end_mission", "srp_mission"):
        with pytest.raises(ProfileError, match=f"key '{key}': must be a string"):
            load_profile(_write(tmp_path, f"{key} = 3"))


def test_the_emulator_profile_names_what_the_emulator_ships():
    """``helmcheck/profiles/emulator.toml``: the ``$OXFLT`` extension and the missions the emulator
    ships, every one of them present in its built-in catalogue."""
    from helmcheck.emulator.missionfile import builtin_dir
    from helmcheck.profile import emulator_profile

    emu = emulator_profile()
    assert (emu.fault_injection, emu.trigger) == ("oxflt", "oxflt")
    assert (emu.end_mission, emu.srp_mission) == ("short.mis", "srp.mis")
    for name in (emu.mission, emu.end_mission, emu.srp_mission):
        assert (builtin_dir() / name).is_file(), name
    assert emu.replace(name="x") == DEFAULT.replace(name="x", fault_injection="oxflt", violation_trigger="oxflt",
                                                    end_mission="short.mis", srp_mission="srp.mis")


def test_empty_end_or_srp_mission_makes_its_case_not_tested():
    """No srp_mission: its case is NOT-TESTED before it runs. No end_mission: RH-MSN-4's case runs the
    test mission in rh5 (the vehicle's remaining time, ``$OSI`` field 13, says whether its end can be
    waited for; NOT-TESTED in the case otherwise), and is NOT-TESTED before it runs where the ``$OSI``
    shows no remaining time (rh4, rh3)."""
    from helmcheck.certify.vehicle.catalogue import CASES, unmet_need
    from helmcheck.profile import emulator_profile
    end = next(c for c in CASES if c.subject == "RH-MSN-4")
    srp = next(c for c in CASES if c.subject == "RH-SAF-4" and "srp_mission" in c.needs)
    emu = emulator_profile()
    assert unmet_need(end, emu) is None and unmet_need(srp, emu) is None
    assert unmet_need(end, emu.replace(end_mission="")) is None
    assert "end_mission" in unmet_need(end, emu.replace(end_mission="", protocol="rh4", depth_unit="ft",
                                                        osi_fields=17))
    assert "srp_mission" in unmet_need(srp, emu.replace(srp_mission=""))
    assert unmet_need(end, DEFAULT) is None and "srp_mission" in unmet_need(srp, DEFAULT.replace(
        fault_injection="oxflt"))


# ---------------------------------------------------------------------------- non-finite numbers

def _float_keys() -> list[str]:
    import dataclasses

    from helmcheck.profile import BenchSafety, Profile

    keys = [f.name for f in dataclasses.fields(Profile) if isinstance(f.default, float)]
    keys += [f"bench_safety.{f.name}" for f in dataclasses.fields(BenchSafety) if isinstance(f.default, float)]
    return keys


@pytest.mark.parametrize("value", ["nan", "inf", "-inf", "+inf"])
@pytest.mark.parametrize("key", _float_keys())
def test_every_number_key_refuses_nan_and_infinity_naming_file_and_key(key, value, tmp_path):
    """TOML has nan and inf literals; a duration of nan or inf seconds would hang or never time
    out (ack_window_s = nan, lockout_s = inf). Every float key refuses them."""
    from helmcheck.profile import ProfileError, load_profile

    p = tmp_path / "p.toml"
    table, _, name = key.rpartition(".")
    p.write_text((f"[{table}]\n" if table else "") + f"{name} = {value}\n")
    with pytest.raises(ProfileError) as e:
        load_profile(p)
    msg = str(e.value)
    assert str(p) in msg and repr(key) in msg and "finite" in msg and "\n" not in msg


def test_a_profile_round_trips_through_as_dict():
    """What a run stores (results.json, replay files) loads back as the same profile."""
    from helmcheck.profile import DEFAULT, profile_from_dict

    stored = {k: v for k, v in DEFAULT.as_dict().items() if k != "name"}
    assert profile_from_dict(stored).replace(name=DEFAULT.name) == DEFAULT
