"""``helmcheck profile init``: a commented profile generated from the ``Profile`` dataclass.

The template must hold every key of :class:`~helmcheck.profile.Profile` (a new field without it
fails here), load as it is, start from safe values, and mark what a real vehicle must fill in.
"""

from __future__ import annotations

import dataclasses
import re
import tomllib

import pytest

from helmcheck.cli import main as cli_main
from helmcheck.profile import DEFAULT, BenchSafety, Profile, emulator_profile, load_profile, profile_keys
from helmcheck.profile_template import GROUPS, render

#: Keys a real vehicle's file must be given a value for (FILL IN).
MUST_FILL = ("vehicle_name", "vehicle_serial", "uvc_version", "baud", "mission", "mission_waypoints",
             "end_mission", "srp_mission")


def _fill_marked(text: str) -> set[str]:
    """Keys whose comment block carries a FILL IN mark."""
    marked, pending = set(), False
    for line in text.splitlines():
        if line.startswith("# FILL IN:"):
            pending = True
        m = re.match(r"^([a-z_]+) = ", line)
        if m:
            if pending:
                marked.add(m.group(1))
            pending = False
        elif not line.startswith("#"):
            pending = False
    return marked


def test_every_profile_field_is_in_the_template_with_its_documentation():
    data = tomllib.loads(render())
    fields = {f.name for f in dataclasses.fields(Profile)} - {"name"}
    assert set(data) == fields, set(data) ^ fields
    assert set(data["bench_safety"]) == {f.name for f in dataclasses.fields(BenchSafety)}
    groups = {g for g, _ in GROUPS}
    for f in [*profile_keys(), *dataclasses.fields(BenchSafety)]:
        assert f.metadata.get("doc"), f"{f.name}: no documentation (helmcheck.profile._key)"
        assert f.metadata.get("group") in groups, f"{f.name}: group {f.metadata.get('group')!r} not in GROUPS"
    text = render()
    for f in profile_keys():
        if f.name != "bench_safety":
            doc = f.metadata["doc"]
            assert doc[1:30] in text.replace("\n# ", " "), f.name  # its comment is there


def test_the_template_loads_as_it_is_and_is_safe(tmp_path):
    path = tmp_path / "iver3.toml"
    path.write_text(render())
    p = load_profile(path)
    assert p.trigger == "none" and p.violation_trigger == "none" and p.fault_injection == "none"
    assert (p.end_mission, p.srp_mission, p.violation_mission) == ("", "", "")
    assert p.bench_safety == BenchSafety() and p.bench_safety.in_water is False
    assert p.time_scale == 1.0 and (p.vehicle_name, p.vehicle_serial, p.uvc_version) == ("", "", "")
    # everything else is the rh5 default
    assert p.replace(name="x", vehicle_name=DEFAULT.vehicle_name, violation_trigger="") == DEFAULT.replace(name="x")
    assert "max_motor_byte = 0x90" in render()


def test_what_a_real_vehicle_must_fill_in_is_marked():
    text = render()
    marked = _fill_marked(text)
    assert set(MUST_FILL) <= marked, set(MUST_FILL) - marked
    assert {f.name for f in profile_keys() if f.metadata.get("fill")} == marked
    assert "violation_trigger" not in marked and "protocol" not in marked
    prefilled = render({"vehicle_name": "IVER3-042", "bench_safety.max_speed_kn": 0.3})
    assert "vehicle_name" not in _fill_marked(prefilled) and 'vehicle_name = "IVER3-042"' in prefilled
    assert "max_speed_kn = 0.3" in prefilled


def test_comment_lines_fit_the_width():
    assert max(len(ln) for ln in render().splitlines() if ln.startswith("#")) <= 100


# ---------------------------------------------------------------------------- the command

def test_init_writes_a_file_with_the_identity_prefilled(tmp_path, capsys):
    path = tmp_path / "iver3.toml"
    code = cli_main(["profile", "init", str(path), "--name", "IVER3-042", "--serial", "3042", "--uvc-version",
                     "5.2.1", "--mission", "survey.mis", "--baud", "57600", "--set", "end_mission=end.mis",
                     "--set", 'commands=["OMS", "OSD", "OMSTOP"]', "--set", "bench_safety.max_motor_byte=0x88"])
    assert code == 0
    assert f"wrote {path}" in capsys.readouterr().err
    p = load_profile(path)
    assert (p.vehicle_name, p.vehicle_serial, p.uvc_version, p.mission, p.baud) == (
        "IVER3-042", "3042", "5.2.1", "survey.mis", 57600)
    assert p.end_mission == "end.mis" and p.commands == ("OMS", "OSD", "OMSTOP")
    assert p.bench_safety.max_motor_byte == 0x88
    assert not {"vehicle_name", "vehicle_serial", "uvc_version", "mission", "baud", "end_mission", "commands"} & \
        _fill_marked(path.read_text())


@pytest.mark.parametrize("argv", [["profile", "init"], ["profile", "init", "-"]])
def test_init_without_a_path_or_with_dash_writes_standard_output(argv, capsys):
    assert cli_main(argv) == 0
    out = capsys.readouterr().out
    assert out == render()
    assert tomllib.loads(out)["violation_trigger"] == "none"


def test_an_existing_file_is_refused_without_overwrite(tmp_path, capsys):
    path = tmp_path / "p.toml"
    path.write_text("# mine\n")
    assert cli_main(["profile", "init", str(path)]) == 64
    err = capsys.readouterr().err
    assert f"{path} exists; --overwrite replaces it" in err and "Traceback" not in err
    assert path.read_text() == "# mine\n"
    assert cli_main(["profile", "init", str(path), "--overwrite"]) == 0
    assert load_profile(path).trigger == "none"


@pytest.mark.parametrize("argv,needle", [
    (["--set", "baud=1234"], "key 'baud': must be one of"),
    (["--baud", "1234"], "key 'baud': must be one of"),
    (["--set", "protocl=rh5"], "unknown key 'protocl'"),
    (["--set", "lockout_s"], "expected KEY=VALUE"),
    (["--set", "mission_waypoints=many"], "is not a TOML value"),
    (["--set", "violation_trigger=oxflt"], "'oxflt' needs fault_injection"),
    (["--set", "bench_safety.max_motor_byte=300"], "max_motor_byte"),
    (["--frobnicate"], "unrecognized arguments"),
])
def test_bad_prefills_are_usage_errors_naming_the_key(argv, needle, tmp_path, capsys):
    path = tmp_path / "p.toml"
    assert cli_main(["profile", "init", str(path), *argv]) == 64
    err = capsys.readouterr().err
    assert needle in err and "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert not path.exists()


def test_an_unwritable_path_and_a_missing_action_are_usage_errors(tmp_path, capsys):
    assert cli_main(["profile", "init", str(tmp_path / "no" / "p.toml")]) == 64
    assert "does not exist" in capsys.readouterr().err
    assert cli_main(["profile", "init", str(tmp_path)]) == 64
    assert "is a directory" in capsys.readouterr().err
    assert cli_main(["profile"]) == 64
    assert "choose an action: init" in capsys.readouterr().err


def test_help_teaches(capsys):
    assert cli_main(["profile", "init", "--help"]) == 0
    out = capsys.readouterr().out
    for needle in ("FILL IN", 'violation_trigger = "none"', "--overwrite", "--set KEY=VALUE", "certify vehicle",
                   "exit status"):
        assert needle in out, needle


def test_init_emulator_is_the_emulators_profile_with_every_key(tmp_path, capsys):
    path = tmp_path / "emu.toml"
    assert cli_main(["profile", "init", "--emulator", str(path)]) == 0
    text = path.read_text()
    assert "FILL IN" not in text
    assert load_profile(path).replace(name="x") == emulator_profile().replace(name="x")


def test_the_documentation_s_key_table_names_every_key():
    """The site's table of keys (docs/reference/profile-keys.md, generated by ``helmcheck docs``
    from the same field documentation as this template) has a row for every key."""
    from pathlib import Path

    page = Path(__file__).resolve().parents[1] / "docs" / "reference" / "profile-keys.md"
    rows = "\n".join(ln for ln in page.read_text(encoding="utf-8").splitlines() if ln.startswith("| [`"))
    keys = [f.name for f in profile_keys() if f.name != "bench_safety"]
    keys += [f"bench_safety.{f.name}" for f in dataclasses.fields(BenchSafety)]
    missing = [k for k in keys if f"[`{k}`]" not in rows]
    assert not missing, f"docs/reference/profile-keys.md: no row for {missing} (run 'helmcheck docs')"
