"""``helmcheck verify``: a report anyone can check against its evidence (issue: certificates).

Real runs, real files: the emulator (``helmcheck emulate`` on a pty, time scale 25) certified by
``helmcheck certify vehicle --sign-key``, a ``--select 'RH-SRV-*'`` run of it, and a backseat
certified by ``helmcheck certify backseat --implementation … --sign-key`` with the example
backseat. Each tamper test works on a copy of a run directory and checks that ``verify`` exits 1
and names what differs; the untouched runs must verify (exit 0).
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from helmcheck.cli import main as cli_main
from helmcheck.emulator.process import EmulatorProcess
from helmcheck.profile import load_profile
from helmcheck.profile_toml import emit_profile
from helmcheck.reports.manifest import sha256_file
from helmcheck.reports.results import finish, load_results, write_results_atomic

K = 25.0
GOOD_BACKSEAT = Path(__file__).resolve().parent / "backseats" / "good_backseat.py"


pytestmark = pytest.mark.xdist_group("full-emulator-run")


@pytest.fixture(scope="module")
def runs(full_emulator_run):
    """The shared signed full emulator certification (``tests/conftest.py``), a ``--select`` run
    of the emulator, and a signed backseat run, side by side under one root."""
    root, code, _alive = full_emulator_run
    codes = {"full": code}
    with EmulatorProcess(time_scale=K, baud=115200) as emu:
        codes["select"] = cli_main(["certify", "vehicle", "--port", emu.port, "--time-scale", str(K),
                                    "--profile", str(root / "emu.toml"), "--examples", "0", "--seed", "2",
                                    "--no-progress", "--report-dir", str(root / "select"), "--select", "RH-SRV-*"])
    codes["backseat"] = _certify_backseat(root / "backseat", root / "lab.key")
    return root, codes


def _certify_backseat(out: Path, key: Path) -> int:
    proc = subprocess.Popen([sys.executable, "-m", "helmcheck", "certify", "backseat", "--time-scale", "5",
                             "--duration", "20", "--report-dir", str(out), "--connect-timeout", "20",
                             "--implementation", "good-backseat@1.0", "--sign-key", str(key)],
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, stdin=subprocess.DEVNULL)
    port = proc.stdout.readline().decode().split("port:", 1)[1].strip()
    bs = subprocess.Popen([sys.executable, str(GOOD_BACKSEAT), port, "--time-scale", "5"],
                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, stdin=subprocess.DEVNULL)
    proc.communicate(timeout=120)
    bs.wait(timeout=30)
    return proc.returncode


def copy(runs, name: str, tmp_path: Path) -> Path:
    root, _ = runs
    d = tmp_path / name
    shutil.copytree(root / name, d)
    return d


def verify(capsys, *argv: str) -> tuple[int, list[str]]:
    code = cli_main(["verify", *argv])
    captured = capsys.readouterr()
    return code, captured.out.splitlines() + captured.err.splitlines()


def mismatches(lines: list[str], subject: str) -> list[str]:
    return [ln for ln in lines if ln.startswith(f"MISMATCH {subject}:")]


# --------------------------------------------------------------------------- what a run records

def test_a_full_emulator_run_is_a_signed_certificate(runs):
    root, codes = runs
    assert codes["full"] == 0
    r = load_results(root / "full")
    assert r["verdict"] == "pass" and r["certificate"] is True
    assert r["scope"] == {"claimed": 60, "judged": 60, "statement": "certificate: all 60 claimed clauses judged",
                          "gaps": []}
    impl = r["identity"]["implementation"]
    assert impl == {"role": "vehicle", "name": "IVER3-EMU", "serial": "EMU-0001", "version": "emulator 0.1.0",
                    "name_on_wire": "IVER3-EMU"}
    assert (r["identity"]["operator"], r["identity"]["site"]) == ("J. Doe", "Bench 2")
    assert r["digests"]["wire.log"] == sha256_file(root / "full" / "wire.log")
    assert load_profile(root / "full" / "profile.toml").lockout_s == r["profile"]["lockout_s"]
    assert (root / "full" / "signature.json").is_file() and r["signature"]["algorithm"] == "Ed25519"
    negative = [e for e in r["events"] if e.get("negative_test")]
    assert negative and all(e["kind"] == "ack-error" for e in negative)


def test_a_select_run_is_not_a_certificate(runs):
    root, codes = runs
    assert codes["select"] == 0  # exit codes unchanged
    r = load_results(root / "select")
    assert r["verdict"] == "pass" and r["certificate"] is False
    assert r["scope"]["statement"] == "partial: 4 of 60 claimed clauses judged; not a certificate"
    md = (root / "select" / "report.md").read_text()
    assert md.splitlines()[0].endswith("**PASS — partial: 4 of 60 claimed clauses judged; not a certificate**")


def test_a_backseat_run_names_the_backseat(runs):
    root, codes = runs
    r = load_results(root / "backseat")
    assert codes["backseat"] == 0 and r["certificate"] is True
    assert r["identity"]["implementation"] == {"role": "backseat", "name": "good-backseat", "version": "1.0"}


# --------------------------------------------------------------------------- untouched runs verify

@pytest.mark.parametrize("name,key", [("full", "lab.pub"), ("select", None), ("backseat", "lab.pub")])
def test_an_untouched_run_verifies(runs, capsys, name, key):
    root, _ = runs
    argv = [str(root / name)] + (["--public-key", str(root / key)] if key else [])
    code, lines = verify(capsys, *argv)
    assert code == 0, "\n".join(lines)
    assert lines[-1].startswith("VERIFIED: ")


# --------------------------------------------------------------------------- tampering is named

@pytest.mark.unverifiable
def test_a_consistent_edit_of_results_json_is_caught(runs, tmp_path, capsys):
    """RH-SRV-4 turned to FAIL with the verdict and its reason adjusted: a valid document, caught
    by re-judging (unsigned copy) and by the signature (signed copy)."""
    for signed in (False, True):
        d = copy(runs, "full", tmp_path / ("signed" if signed else "unsigned"))
        r = load_results(d)
        for c in r["clauses"]:
            if c["id"] == "RH-SRV-4":
                c.update(verdict="fail", reason="V-28: servo control released 2 s late")
        finish(r, finished=r["finished"], duration_s=r["duration_s"])
        if not signed:
            (d / "signature.json").unlink()
            r["signature"] = None
        write_results_atomic(d, r)  # schema-valid: the verdict follows from the clauses
        code, lines = verify(capsys, str(d))
        assert code == 1
        assert any("results.json says FAIL, the wire log gives PASS" in ln
                   for ln in mismatches(lines, "clause RH-SRV-4")), lines
        if signed:
            assert mismatches(lines, "results.json") and "is not the signed" in mismatches(lines, "results.json")[0]


@pytest.mark.unverifiable
def test_one_byte_of_the_wire_log_is_caught(runs, tmp_path, capsys):
    d = copy(runs, "full", tmp_path)
    data = bytearray((d / "wire.log").read_bytes())
    at = data.index(b"$ACK,9,0,0") + len("$ACK,9,0,")
    data[at] = ord("7")  # an accepted $OMS now reads as refused with err 7
    (d / "wire.log").write_bytes(bytes(data))
    code, lines = verify(capsys, str(d), "--public-key", str(runs[0] / "lab.pub"))
    assert code == 1
    wire = mismatches(lines, "wire.log")
    assert any("differs from the" in ln and "recorded in results.json" in ln for ln in wire), lines
    assert any("is not the signed" in ln for ln in wire), lines


@pytest.mark.unverifiable
def test_a_swapped_profile_is_caught(runs, tmp_path, capsys):
    d = copy(runs, "full", tmp_path)
    swapped = load_profile(d / "profile.toml").replace(lockout_s=10.0)
    (d / "profile.toml").write_text(emit_profile(swapped))
    code, lines = verify(capsys, str(d))
    assert code == 1
    prof = mismatches(lines, "profile.toml")
    assert any("recorded in results.json" in ln for ln in prof), lines
    assert any("key lockout_s is 10.0, but results.json records 20.0" in ln for ln in prof), lines
    assert any("is not the signed" in ln for ln in prof), lines


def test_a_wrong_public_key_is_caught(runs, capsys):
    """Another key than the signer's: one line naming the key problem, and nothing suggesting the
    files were changed (they were not: the signature holds with the key that made it)."""
    root, _ = runs
    code, lines = verify(capsys, str(root / "full"), "--public-key", str(root / "other.pub"))
    assert code == 1
    assert [ln for ln in lines if ln.startswith("MISMATCH ")] == mismatches(lines, "signature")
    sig = mismatches(lines, "signature")
    assert len(sig) == 1, lines
    assert "not with the given key" in sig[0] and "other.pub" in sig[0] and "signed by another key" in sig[0]
    assert not any("changed" in ln for ln in lines), lines


def test_an_unsigned_run_fails_against_a_public_key(runs, capsys):
    root, _ = runs
    code, lines = verify(capsys, str(root / "select"), "--public-key", str(root / "lab.pub"))
    assert code == 1
    assert any("the run is not signed" in ln for ln in mismatches(lines, "signature")), lines


@pytest.mark.unverifiable
def test_a_removed_signature_is_caught(runs, tmp_path, capsys):
    d = copy(runs, "full", tmp_path)
    (d / "signature.json").unlink()
    code, lines = verify(capsys, str(d))
    assert code == 1 and mismatches(lines, "signature.json"), lines


@pytest.mark.unverifiable
def test_a_forged_signature_file_is_caught(runs, tmp_path, capsys):
    """Re-signing the manifest of an edited run with another key: the given key does not match."""
    d = copy(runs, "full", tmp_path)
    sig = json.loads((d / "signature.json").read_text())
    sig["manifest"]["tool"]["version"] = "9.9.9"
    (d / "signature.json").write_text(json.dumps(sig))
    code, lines = verify(capsys, str(d))
    assert code == 1
    assert any("does not verify" in ln for ln in mismatches(lines, "signature")), lines


@pytest.mark.unverifiable
def test_a_run_without_recorded_evidence_cannot_be_verified(tmp_path, capsys):
    d = tmp_path / "old"
    shutil.copytree(Path(__file__).parent / "fixtures" / "reports" / "pass_run", d)
    code, lines = verify(capsys, str(d))
    assert code == 1
    assert mismatches(lines, "results.json") and mismatches(lines, "profile.toml"), lines


# --------------------------------------------------------------------------- usage

def test_usage_errors_exit_64(tmp_path, capsys):
    code, lines = verify(capsys, str(tmp_path / "nowhere"))
    assert code == 64 and any("no such results directory" in ln for ln in lines)
    code, lines = verify(capsys, str(tmp_path))
    assert code == 64 and any("results.json: no such file" in ln for ln in lines)
    bad = tmp_path / "bad.pub"
    bad.write_text("not a key")
    code, lines = verify(capsys, str(tmp_path), "--public-key", str(bad))
    assert code == 64 and any(str(bad) in ln and "not a PEM public key" in ln for ln in lines)
    assert not any("Traceback" in ln for ln in lines)
    assert cli_main(["verify"]) == 64
