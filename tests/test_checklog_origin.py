"""``check-log`` reads the log's own header, and its results verify like any run's.

A wire log names the run that wrote it (``# helmcheck 0.1.0 certify vehicle; profile …``,
:func:`helmcheck.grammar.wirelog.run_header`). With no option, ``check-log`` judges it in the role
that run tested — a ``certify vehicle`` log as the vehicle's: helmcheck's own lines there, some
malformed on purpose, are never judged as a backseat's (RH-BS-1/2/3) — under the profile of the
run directory it sits in, at the header's time scale (:mod:`helmcheck.checklog.origin`).

The acceptance test certifies the real emulator (a subprocess on a pty, a few clauses at time
scale 40: a few seconds), checks the run's wire log with no option at all and compares every
clause verdict with the live run's; then ``helmcheck verify`` re-judges the check's results
directory (VERIFIED) and a tampered copy (MISMATCH, exit 1, one line per difference).
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from hypothesis import given, strategies as st

from helmcheck.checklog.checker import log_meta
from helmcheck.checklog.origin import RUN_ROLES, read_origin, resolve
from helmcheck.cli import main as cli_main
from helmcheck.emulator.process import EmulatorProcess
from helmcheck.grammar.wirelog import HEADER, MISSIONS_SEP, RUNS, read_run_header, run_header
from helmcheck.profile import EMULATOR_PROFILE

ROOT = Path(__file__).resolve().parent.parent
EMU_PROFILE = ROOT / "helmcheck" / EMULATOR_PROFILE
K = 40.0
#: A few clauses, each a short case, and RH-ACK-2, whose case sends lines a backseat must not.
SELECT = ("RH-ACK-2", "RH-SRV-*", "RH-FRM-3")


def _clauses(d: Path) -> dict[str, str]:
    return {c["id"]: c["verdict"] for c in json.loads((d / "results.json").read_text())["clauses"]}


@pytest.fixture(scope="module")
def certified(tmp_path_factory):
    """A real, short certification of the emulator: the run directory and its exit status."""
    root = tmp_path_factory.mktemp("origin")
    with EmulatorProcess(time_scale=K, baud=115200) as emu:
        args = ["certify", "vehicle", "--port", emu.port, "--time-scale", f"{K:g}", "--baud", "115200",
                "--profile", str(EMU_PROFILE), "--examples", "0", "--no-progress", "--report-dir",
                str(root / "run")]
        for s in SELECT:
            args += ["--select", s]
        code = cli_main(args)
    return root / "run", code


pytestmark = pytest.mark.xdist_group("test_checklog_origin")


def test_check_log_with_no_options_gives_a_vehicle_certification_its_own_verdicts(certified, tmp_path,
                                                                                   monkeypatch, capsys):
    """Acceptance: ``check-log wire.log`` with no option judges a ``certify vehicle`` log as the
    vehicle's, under the run's profile.toml: every clause verdict is the live run's, and no
    RH-BS clause is judged (helmcheck's deliberately malformed lines are not a backseat's)."""
    run, live_code = certified
    assert live_code == 0
    work = tmp_path / "work"
    shutil.copytree(run, work / "run")
    monkeypatch.chdir(work)
    capsys.readouterr()
    code = cli_main(["check-log", "run/wire.log"])
    out = capsys.readouterr().out
    assert code == live_code, out
    checked = work / "reports" / "check-log-wire"
    live, offline = _clauses(run), _clauses(checked)
    assert not [c for c in offline if c.startswith("RH-BS-")], out
    assert offline == live, {c: (live.get(c), offline.get(c)) for c in set(live) | set(offline)
                             if live.get(c) != offline.get(c)}
    res = json.loads((checked / "results.json").read_text())
    assert res["log"]["role"] == "vehicle" and res["settings"]["role"] == "vehicle"
    assert res["log"]["origin"]["run"] == "certify vehicle"
    assert "judged as: vehicle (a certify vehicle run, as its header says); profile run/profile.toml (the run's)" in out
    assert "note:" not in out  # the header said everything
    assert "report: reports/check-log-wire/report.html" in out.splitlines()


def test_role_still_overrides_the_header(certified, tmp_path, capsys):
    """``--role both`` on a certification's log judges helmcheck's own lines as a backseat's:
    what the header's default avoids, still there when asked for."""
    run, _ = certified
    code = cli_main(["check-log", str(run / "wire.log"), "--role", "both", "--report-dir", str(tmp_path / "both"),
                     "--no-render"])
    out = capsys.readouterr().out
    res = json.loads((tmp_path / "both" / "results.json").read_text())
    assert res["log"]["role"] == "both" and "judged as: both (--role)" in out
    assert any(c["id"].startswith("RH-BS-") for c in res["clauses"])
    assert code in (0, 1)


@pytest.mark.unverifiable
def test_a_check_log_results_directory_verifies_and_a_tampered_one_does_not(certified, tmp_path, capsys):
    """``helmcheck verify`` re-judges a log check like any run: VERIFIED; one verdict changed in
    results.json: MISMATCH naming it, exit 1; the identity and digests are recorded."""
    run, _ = certified
    d = tmp_path / "checked"
    assert cli_main(["check-log", str(run / "wire.log"), "--report-dir", str(d)]) == 0
    res = json.loads((d / "results.json").read_text())
    assert set(res["digests"]) == {"wire.log", "profile.toml"}
    assert res["identity"]["implementation"]["name_on_wire"] == "IVER3-EMU"
    assert res["identity"]["tester"]["name"] == "helmcheck"
    capsys.readouterr()
    assert cli_main(["verify", str(d)]) == 0
    assert capsys.readouterr().out.startswith("VERIFIED: ")

    bad = tmp_path / "tampered"
    shutil.copytree(d, bad)
    doc = json.loads((bad / "results.json").read_text())
    victim = next(c for c in doc["clauses"] if c["verdict"] == "pass")
    victim["verdict"] = "fail"
    doc["verdict"] = "fail"
    (bad / "results.json").write_text(json.dumps(doc))
    assert cli_main(["verify", str(bad)]) == 1
    lines = capsys.readouterr().out.splitlines()
    assert f"MISMATCH clause {victim['id']}: results.json says FAIL, the wire log gives PASS" in "\n".join(lines)
    assert [ln for ln in lines if ln.startswith("MISMATCH ")] == [ln for ln in lines[:-1]]
    assert lines[-1].startswith("NOT VERIFIED: 2 difference(s)")


def test_the_report_of_a_log_check_names_its_identity(certified, tmp_path):
    """The report says what it says of any run: no "not recorded" identity for a log checked a
    moment ago."""
    run, _ = certified
    d = tmp_path / "checked"
    assert cli_main(["check-log", str(run / "wire.log"), "--report-dir", str(d)]) == 0
    html = (d / "report.html").read_text()
    assert "not recorded" not in html and "made before" not in html


def _old_log(path: Path, header: list[str]) -> Path:
    path.write_text("\n".join([HEADER, *(f"# {h}" for h in header),
                               "0.000000 > $OSD,S*27", "0.010000 < $ACK,8,0,0*5D"]) + "\n")
    return path


def test_a_header_that_names_no_run_is_said_in_one_line_and_the_defaults_are_used(tmp_path, capsys):
    """An older log (its header names no run and no profile): both roles, rh5, one note line."""
    log = _old_log(tmp_path / "old.log", ["started 2026-01-01T00:00:00Z  port /dev/pts/3  baud 19200  time_scale 20"])
    cli_main(["check-log", str(log), "--report-dir", str(tmp_path / "c"), "--no-render"])
    out = capsys.readouterr().out.splitlines()
    notes = [ln for ln in out if ln.lstrip().startswith("note:")]
    assert len(notes) == 1, out
    assert "does not say which run wrote it or the profile" in notes[0] and "the defaults are used" in notes[0]
    assert "judged as: both (the default: the log names no run); profile rh5 (the default)" in "\n".join(out)
    res = json.loads((tmp_path / "c" / "results.json").read_text())
    assert res["log"]["role"] == "both" and res["settings"]["time_scale"] == 20


def test_a_backseat_certification_log_is_judged_as_the_backseat(tmp_path):
    """The header of a ``certify backseat`` log gives the backseat role, and a profile it names
    that is not here falls back to rh5 with a note."""
    log = _old_log(tmp_path / "bs.log", ["started 2026-01-01T00:00:00Z  port /dev/pts/3  baud 19200  time_scale 5",
                                         run_header("0.1.0", "certify backseat", "/nowhere/site.toml")])
    how = resolve(log, log_meta(log)[1])
    assert how.role == "backseat" and how.profile.name == "rh5"
    assert "a profile that can be read here (/nowhere/site.toml)" in how.lacking


def test_an_emulator_log_is_judged_with_the_missions_its_header_names(tmp_path):
    """``emulate --log`` names its mission directories; check-log uses those that exist."""
    missions = ROOT / "helmcheck" / "emulator" / "missions"
    log = _old_log(tmp_path / "emu.log", ["started 2026-01-01T00:00:00Z  port /dev/pts/3  baud 19200  time_scale 5",
                                          run_header("0.1.0", "emulate", "rh5", [str(missions), "/gone"])])
    how = resolve(log, log_meta(log)[1])
    assert how.role == "both" and how.missions == [missions]
    assert "/gone are not" in how.lacking
    assert resolve(log, log_meta(log)[1], missions_arg=str(tmp_path)).missions == [tmp_path]


_WORD = st.text(st.characters(min_codepoint=33, max_codepoint=126, blacklist_characters=";:"), min_size=1,
                max_size=20)


@given(version=_WORD, run=st.sampled_from(RUNS), profile=_WORD, missions=st.lists(_WORD, max_size=3))
def test_a_run_header_reads_back_as_written(version, run, profile, missions):
    """Whatever a recorder writes with :func:`run_header` reads back the same, and names a role."""
    h = read_run_header(run_header(version, run, profile, missions))
    assert h is not None
    assert (h.version, h.run, h.profile, list(h.missions)) == (version, run, profile, missions)
    assert RUN_ROLES[h.run] in ("vehicle", "backseat", "both")
    assert MISSIONS_SEP == ":"


def test_every_recorder_names_its_run(certified):
    """The run's own wire log carries the header the origin is read from."""
    run, _ = certified
    origin = read_origin(log_meta(run / "wire.log")[1])
    assert (origin.run, origin.role, origin.time_scale) == ("certify vehicle", "vehicle", K)
    assert origin.profile == str(EMU_PROFILE)
