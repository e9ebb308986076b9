"""Certificates on recorded results: scope rule, identity, profile and digests, signature file,
and how every rendering leads with the scope, shows passing evidence and keeps negative tests apart.

The results directories are the report fixtures (``tests/fixtures/reports``), copied; the real
certification runs and ``helmcheck verify`` are in ``tests/test_verify.py``.
"""

from __future__ import annotations

import json
import shutil
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from helmcheck.cli import main as cli_main
from helmcheck.clauses import vehicle_clauses
from helmcheck.profile import DEFAULT, load_profile
from helmcheck.reports.certificate import RunDeclaration, finish_run
from helmcheck.reports.identity import Declared, parse_implementation
from helmcheck.reports.manifest import sha256_file
from helmcheck.reports.render import render_all
from helmcheck.reports.results import add_event, finish, load_results, new_results, validate, write_results_atomic
from helmcheck.reports.scope import headline, id_ranges, scope_of
from helmcheck.reports.signing import generate_keypair, load_signing_key

FIXTURES = Path(__file__).parent / "fixtures" / "reports"
VEHICLE_IDS = [c.id for c in vehicle_clauses()]


def copy_run(tmp_path: Path, name: str, as_name: str | None = None) -> Path:
    d = tmp_path / (as_name or name)
    shutil.copytree(FIXTURES / name, d)
    return d


def vehicle_results(verdicts: dict[str, str] | None = None, *, partial: bool = False, default: str = "pass") -> dict:
    r = new_results("vehicle", command="test")
    from helmcheck.reports.results import add_clause
    for cid in VEHICLE_IDS:
        v = (verdicts or {}).get(cid, default)
        add_clause(r, cid, v, f"V-00: {v} by construction" if v != "not-tested" else "no violation trigger declared")
    finish(r, partial=partial)
    return r


# --------------------------------------------------------------------------- the scope rule

def test_a_run_that_judges_every_vehicle_clause_is_a_certificate():
    r = vehicle_results()
    sc = scope_of(r)
    assert sc.certificate and len(sc.claimed) == 60 and not sc.gaps
    assert headline(r) == "PASS — certificate: all 60 claimed clauses judged"


def test_a_not_tested_must_clause_makes_a_pass_not_a_certificate():
    """RH-SAF-1..5 not tested (no violation trigger): the PASS stands, the certificate does not."""
    r = vehicle_results({f"RH-SAF-{i}": "not-tested" for i in range(1, 6)})
    sc = scope_of(r)
    assert r["verdict"] == "pass" and not sc.certificate
    assert headline(r) == "PASS — partial: 55 of 60 claimed clauses judged; not a certificate"
    assert sc.why() == ["RH-SAF-1..5 not tested: no violation trigger declared"]


def test_inconclusive_and_missing_clauses_are_not_judged():
    r = vehicle_results({"RH-TIM-1": "inconclusive"})
    r["clauses"] = [c for c in r["clauses"] if c["id"] != "RH-OSD-2"]
    sc = scope_of(r)
    assert not sc.certificate and len(sc.judged) == 58
    assert [g.verdict for g in sc.gaps] == ["missing", "inconclusive"]
    assert sc.why()[0] == "RH-OSD-2 missing from the results"


def test_a_complete_failing_run_is_a_certificate_of_non_conformance_and_an_interrupted_one_is_not():
    failed = vehicle_results({"RH-SRV-4": "fail"})
    assert failed["verdict"] == "fail" and scope_of(failed).certificate
    stopped = vehicle_results(partial=True)
    assert not scope_of(stopped).certificate
    assert scope_of(stopped).statement == ("partial: the run was interrupted; 60 of 60 claimed clauses judged; "
                                           "not a certificate")


def test_a_backseat_run_claims_the_section_9_clauses(tmp_path):
    r = load_results(FIXTURES / "backseat_run")
    sc = scope_of(r)
    assert sc.claimed == tuple(f"RH-BS-{i}" for i in range(1, 9)) and sc.certificate
    assert headline(r) == "NON-STRICT — certificate: all 8 claimed clauses judged"


def test_id_ranges_compress_consecutive_clauses():
    assert id_ranges(["RH-SAF-1", "RH-SAF-2", "RH-SAF-3", "RH-FRM-9", "RH-FRM-7"]) == "RH-SAF-1..3, RH-FRM-9, RH-FRM-7"
    assert id_ranges([]) == ""


def test_the_schema_checks_the_certificate_flag_against_the_clauses():
    r = vehicle_results({"RH-SAF-1": "not-tested"})
    r["certificate"] = True
    assert any(e.startswith("certificate:") for e in validate(r))
    r["certificate"] = False
    assert validate(r) == []


@pytest.mark.parametrize("key,value,needle", [
    ("digests", {"wire.log": "XYZ"}, "not a SHA-256"),
    ("digests", {"../wire.log": None}, "relative path inside"),
    ("signature", {"file": "signature.json", "algorithm": "RSA", "key_id": "0" * 64}, "signature.algorithm"),
    ("certificate", "yes", "expected a boolean"),
    ("identity", {"implementation": {"role": "vehicle"}, "profile_sha256": "00", "tester": {}}, "profile_sha256"),
])
def test_the_schema_checks_the_shape_of_the_new_keys(key, value, needle):
    r = vehicle_results()
    r[key] = value
    assert any(needle in e for e in validate(r)), validate(r)


def test_negative_test_marks_only_ack_errors():
    r = vehicle_results()
    add_event(r, 1.0, "ack-error", "$ACK,9,1,20 for $OMS", negative_test=True)
    assert validate(r) == [] and r["events"][-1]["negative_test"] is True
    r["events"].append({"t": 2.0, "kind": "command", "label": "$OSD", "negative_test": True})
    assert any("only an ack-error" in e for e in validate(r))
    with pytest.raises(ValueError):
        add_event(r, 1.0, "lockout", "x", negative_test=True)


def test_implementation_name_and_version():
    assert parse_implementation("moos-ivp-helm@2.1.0") == ("moos-ivp-helm", "2.1.0")
    assert parse_implementation("goby") == ("goby", None)
    assert parse_implementation("team@host@1.0") == ("team@host", "1.0")
    for bad in ("", "@1.0", "name@"):
        with pytest.raises(ValueError):
            parse_implementation(bad)


# --------------------------------------------------------------------------- finish_run

@pytest.mark.unverifiable  # a hand-made results fixture, not a run
def test_finish_run_records_profile_digests_identity_scope_and_signature(tmp_path):
    d = copy_run(tmp_path, "pass_run")
    key, _, kid = generate_keypair(tmp_path / "lab")
    given = tmp_path / "given.toml"
    given.write_text('vehicle_serial = "S/N 0042"\nuvc_version = "UVC 5.2.1"\n')
    profile = load_profile(given).replace(time_scale=20.0)
    r = load_results(d)
    finish_run(r, d, profile, RunDeclaration(Declared(operator="J. Doe", site="Bench 2", profile_file=str(given)),
                                             load_signing_key(key)))
    assert load_profile(d / "profile.toml").replace(name=profile.name) == profile
    back = load_results(d)
    assert back == r and validate(back) == []
    assert back["digests"] == {"wire.log": sha256_file(d / "wire.log"), "profile.toml": sha256_file(d / "profile.toml")}
    ident = back["identity"]
    assert ident["implementation"] == {"role": "vehicle", "name": "IVER3-EMU", "serial": "S/N 0042",
                                       "version": "UVC 5.2.1", "name_on_wire": "IVER3-EMU"}
    assert (ident["operator"], ident["site"]) == ("J. Doe", "Bench 2")
    assert ident["profile_sha256"] == sha256_file(d / "profile.toml")
    assert ident["profile_file"] == {"path": str(given), "sha256": sha256_file(given)}
    assert ident["tester"]["revision"]  # git describe here, "unknown" outside a checkout
    assert back["certificate"] is False and back["scope"]["judged"] == 58  # RH-FRM-9, RH-POS-2 not tested
    assert back["signature"] == {"file": "signature.json", "algorithm": "Ed25519", "key_id": kid}
    sig = json.loads((d / "signature.json").read_text())
    assert sig["manifest"]["files"] == {"results.json": sha256_file(d / "results.json"),
                                        "wire.log": sha256_file(d / "wire.log"),
                                        "profile.toml": sha256_file(d / "profile.toml")}
    assert sig["manifest"]["tool"]["version"] == back["tool"]["version"]


@pytest.mark.unverifiable  # a hand-made results fixture, not a run
def test_an_unsigned_run_leaves_no_stale_signature(tmp_path):
    d = copy_run(tmp_path, "pass_run")
    key, _, _ = generate_keypair(tmp_path / "lab")
    finish_run(load_results(d), d, DEFAULT, RunDeclaration(sign_key=load_signing_key(key)))
    assert (d / "signature.json").exists()
    finish_run(load_results(d), d, DEFAULT)
    assert not (d / "signature.json").exists() and load_results(d)["signature"] is None


@pytest.mark.unverifiable  # a hand-made results fixture, not a run
def test_a_backseat_is_named_by_the_command_line_not_by_the_emulated_vehicle(tmp_path):
    d = copy_run(tmp_path, "backseat_run")
    r = finish_run(load_results(d), d, DEFAULT,
                   RunDeclaration(Declared(implementation_name="moos-ivp-helm", implementation_version="2.1.0")))
    assert r["identity"]["implementation"] == {"role": "backseat", "name": "moos-ivp-helm", "version": "2.1.0"}
    render_all(d)
    html = (d / "report.html").read_text()
    assert "moos-ivp-helm" in html.split('id="summary"')[0]


# --------------------------------------------------------------------------- renderings

def _render(d: Path) -> tuple[str, str, ET.Element]:
    render_all(d)
    return ((d / "report.html").read_text(encoding="utf-8"), (d / "report.md").read_text(encoding="utf-8"),
            ET.parse(d / "junit.xml").getroot())


def _props(junit: ET.Element) -> list[tuple[str, str]]:
    return [(p.get("name"), p.get("value")) for p in junit.iter("property")]


def test_every_rendering_leads_with_the_scope_of_a_partial_pass(tmp_path):
    """A --select-like run: 4 judged, 56 not selected — never the green PASS of a certificate."""
    d = copy_run(tmp_path, "pass_run")
    r = load_results(d)
    keep = {"RH-SRV-1", "RH-SRV-2", "RH-SRV-3", "RH-SRV-4"}
    r["clauses"] = [c for c in r["clauses"] if c["id"] in keep or not c["id"].startswith("RH-RD")]
    for c in r["clauses"]:
        if c["id"] not in keep:
            c.update(verdict="not-tested", reason="not selected (--select)", replay=None)
    r["replays"] = []
    finish(r, finished=r["finished"], duration_s=r["duration_s"])
    write_results_atomic(d, r)
    html, md, junit = _render(d)
    line = "PASS — partial: 4 of 60 claimed clauses judged; not a certificate"
    banner = html.split('id="verdict"', 1)[1].split("</div>", 3)
    assert 'class="banner v-pass not-certificate scope-partial"' in html and 'data-certificate="false"' in html
    assert "partial: 4 of 60 claimed clauses judged; not a certificate" in "".join(banner)
    assert "not tested: not selected (--select)" in html.split('id="identity"')[0]
    assert md.splitlines()[0] == f"## helmcheck vehicle report: **{line}**"
    assert _props(junit)[:3] == [("helmcheck.headline", line), ("helmcheck.certificate", "false"),
                                 ("helmcheck.scope", "partial: 4 of 60 claimed clauses judged; not a certificate")]


@pytest.mark.unverifiable  # a hand-made results fixture, not a run
def test_a_certificate_says_so_and_shows_identity_and_signature_on_the_first_screen(tmp_path):
    d = copy_run(tmp_path, "backseat_run")
    key, _, kid = generate_keypair(tmp_path / "lab")
    finish_run(load_results(d), d, DEFAULT, RunDeclaration(Declared(implementation_name="goby", operator="A. N."),
                                                           load_signing_key(key)))
    html, md, junit = _render(d)
    first = html.split("<body>")[1].split('id="matrix"')[0]
    assert "NON-STRICT</span> — certificate: all 8 claimed clauses judged" in first
    assert "scope-partial" not in first and 'data-certificate="true"' in first
    assert kid in first and "Signed" in first and "goby" in first and "A. N." in first
    assert first.index('id="certificate-page"') < first.index('id="verdict"') < first.index('id="identity"')
    assert f"Signed (Ed25519) by key `{kid}`" in md
    assert ("helmcheck.signature_key_id", kid) in _props(junit)
    assert ("identity.backseat", "goby") in _props(junit)


def test_passing_clauses_show_their_evidence_in_every_rendering(tmp_path):
    d = copy_run(tmp_path, "pass_run")
    r = load_results(d)
    line = "$OMS,90,2,20,0.5,10*2F"
    for c in r["clauses"]:
        if c["id"] == "RH-SRV-1":
            c["evidence"] = [{"t": 1.5, "dir": ">", "line": line}, {"t": 1.51, "dir": "<", "line": "$ACK,9,0,0*5C"}]
    write_results_atomic(d, r)
    html, md, junit = _render(d)
    section = html.split('id="evidence-RH-SRV-1"', 1)[1].split("</section>", 1)[0]
    assert line in section and "$ACK,9,0,0*5C" in section
    assert 'href="#evidence-RH-SRV-1"' in html  # the matrix links each passing clause to its evidence
    assert "No wire evidence recorded" in html.split('id="evidence-RH-SRV-2"', 1)[1].split("</section>", 1)[0]
    passed = md.split("### Passed, with evidence", 1)[1]
    row = next(ln for ln in passed.splitlines() if ln.startswith("| RH-SRV-1 |"))
    assert "1.500000 &gt; \\$OMS,90,2,20,0.5,10\\*2F (+1 more)" in row
    case = next(c for c in junit.iter("testcase") if c.get("name").startswith("RH-SRV-1 "))
    assert line in case.find("system-out").text


def test_negative_tests_are_drawn_and_counted_apart_from_ack_errors(tmp_path):
    d = copy_run(tmp_path, "pass_run")
    r = load_results(d)
    r["events"] = []
    add_event(r, 1.0, "ack-error", "$ACK,9,1,20 for $OMS", negative_test=True)
    add_event(r, 2.0, "ack-error", "$ACK,11,1,22 for $OPK", negative_test=True)
    add_event(r, 3.0, "ack-error", "$ACK,10,1,21 for $OMP")
    write_results_atomic(d, r)
    html, md, _ = _render(d)
    assert html.count('class="ev-negative"') == 2 and html.count('class="ev-ack-error"') == 1
    assert "expected refusal (negative test): $ACK,9,1,20 for $OMS" in html
    assert "1 ACK error(s); 2 expected refusal(s)" in html
    assert "Events: 1 ACK error(s); 2 expected refusal(s) (negative tests" in md


# --------------------------------------------------------------------------- compare

def _not_selected(d: Path, keep: set[str]) -> None:
    r = load_results(d)
    for c in r["clauses"]:
        if c["id"] not in keep:
            c.update(verdict="not-tested", reason="not selected (--select)", replay=None)
    finish(r, finished=r["finished"], duration_s=r["duration_s"])
    write_results_atomic(d, r)


def test_compare_counts_lost_coverage_and_fail_on_regression_exits_1(tmp_path, capsys):
    old = copy_run(tmp_path, "pass_run", "old")
    new = copy_run(tmp_path, "pass_run", "new")
    _not_selected(new, {"RH-SRV-1", "RH-SRV-2", "RH-SRV-3", "RH-SRV-4"})
    assert cli_main(["report", str(new), "--compare", str(old)]) == 0
    out = capsys.readouterr().out
    judged_before = sum(c["verdict"] != "not-tested" for c in load_results(old)["clauses"])
    assert f"0 regressed, {judged_before - 4} lost coverage" in out
    assert "lost coverage: RH-FRM-1 PASS -> NOT-TESTED" in out
    assert cli_main(["report", str(new), "--compare", str(old), "--fail-on-regression"]) == 1
    assert "lost coverage since" in capsys.readouterr().err
    assert cli_main(["report", str(old), "--compare", str(old), "--fail-on-regression"]) == 0
    assert cli_main(["report", str(new), "--fail-on-regression"]) == 64


# --------------------------------------------------------------------------- certify options

def test_a_bad_signing_key_is_a_usage_error_before_anything_runs(tmp_path, capsys):
    missing = tmp_path / "missing.key"
    code = cli_main(["certify", "vehicle", "--port", str(tmp_path / "no-such-port"), "--sign-key", str(missing),
                     "--report-dir", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 64 and f"--sign-key: {missing}: cannot read the private key" in err
    assert not (tmp_path / "out").exists() and "Traceback" not in err


@pytest.mark.parametrize("argv,needle", [
    (["--implementation", "@1.0"], "--implementation '@1.0': give NAME or NAME@VERSION"),
    (["--implementation", "goby@"], "nothing after '@'"),
    (["--operator", "a\x07b"], "--operator must be printable text"),
])
def test_bad_backseat_declarations_are_usage_errors(tmp_path, capsys, argv, needle):
    code = cli_main(["certify", "backseat", "--report-dir", str(tmp_path / "out"), *argv])
    err = capsys.readouterr().err
    assert code == 64 and needle in err, err
    assert not (tmp_path / "out").exists()


def test_the_certificate_options_are_offered_to_both_roles(capsys):
    for role, extra in (("vehicle", ""), ("backseat", "--implementation")):
        assert cli_main(["certify", role, "--help"]) == 0
        out = capsys.readouterr().out
        assert "--sign-key" in out and "--operator" in out and "--site" in out and extra in out


@pytest.mark.unverifiable  # a hand-made results fixture, not a run
def test_a_vehicle_name_on_the_wire_that_differs_from_the_profile_is_flagged(tmp_path):
    d = copy_run(tmp_path, "fail_run")  # its $OSI carries a hostile vehicle name
    finish_run(load_results(d), d, DEFAULT)
    html, md, _ = _render(d)
    cell = html.split('id="identity"', 1)[1].split("</table>", 1)[0]
    assert "(differs from the profile&#x27;s vehicle_name)</td>" in cell and 'class="missing"' in cell
    assert "<img" not in cell
    assert "differs from the profile's vehicle\\_name)**" in md


# --------------------------------------------------------------------------- the banner

def _banner_html(html: str) -> str:
    return html.split('id="verdict"', 1)[1].split('id="certificate"', 1)[0]


def _banner_md(md: str) -> str:
    return md.split("| What was tested |", 1)[0]


@pytest.mark.unverifiable  # a hand-made results fixture, not a run
def test_the_banner_leads_with_what_failed_and_its_reason_then_what_was_not_judged(tmp_path):
    """Issue 43: under "FAIL — partial", the failed clauses with their reasons come first, then
    the clauses not judged, in the HTML banner and the Markdown summary alike."""
    d = copy_run(tmp_path, "fail_run")
    finish_run(load_results(d), d, DEFAULT)
    html, md, _ = _render(d)
    for banner, reason, gap in (
            (_banner_html(html), "$ACK,10 came 1.400 s after $OMP", "RH-FRM-9 not tested: Serial settings"),
            (_banner_md(md), "\\$ACK,10 came 1.400 s after \\$OMP", "RH-FRM-9 not tested: Serial settings")):
        failed = banner.index("RH-ACK-2")
        assert banner.index("RH-FRM-4") < failed < banner.index("RH-SRV-4"), banner  # profile order
        assert banner.index(reason) > failed
        assert failed < banner.index("Not judged:") < banner.index(gap), banner
        assert banner.index("RH-TIM-1 inconclusive") > banner.index("Not judged:")
    assert '<a href="#finding-RH-ACK-2"><b>RH-ACK-2</b></a> failed: $ACK,10 came' in html
    assert md.index("- RH-FRM-4 failed: ") < md.index("Not judged:") < md.index("- RH-FRM-9 not tested")


def test_a_passing_certificate_has_no_failure_or_gap_lines_in_its_banner(tmp_path):
    d = tmp_path / "clean"
    write_results_atomic(d, vehicle_results())
    html, md, _ = _render(d)
    assert 'id="failed"' not in html and "Not judged:" not in html and "Not judged:" not in md
    assert " failed: " not in _banner_md(md)


@pytest.mark.unverifiable  # hand-made results, not a run
def test_the_banner_lists_four_failures_then_says_how_many_more(tmp_path):
    d = tmp_path / "many"
    failing = VEHICLE_IDS[:7]
    write_results_atomic(d, vehicle_results({cid: "fail" for cid in failing}))
    html, md, _ = _render(d)
    banner = _banner_md(md)
    assert all(f"- {cid} failed: V-00: fail by construction" in banner for cid in failing[:4])
    assert f"- and 3 more: {id_ranges(failing[4:])}" in banner and f"- {failing[4]} failed" not in banner
    assert html.count("</li>", 0, html.index('id="certificate"')) == 5


def _with_process(d: Path, command: str) -> None:
    r = load_results(d)
    r["process"] = {"command": command, "pid": 4242, "exit_code": None, "signal": "SIGTERM",
                    "ended_at_s": 12.0, "ended_early": False, "output_tail": ["steering"]}
    write_results_atomic(d, r)


@pytest.mark.unverifiable  # a hand-made results fixture, not a run
def test_a_backseat_report_names_the_backseat_by_its_exec_command_never_the_vehicle_helmcheck_played(tmp_path):
    """Issue 43: no --implementation, started with --exec: every place a report names the
    implementation names the command; the $OSI name of the vehicle helmcheck played is nowhere
    among them."""
    d = copy_run(tmp_path, "backseat_run")  # its $OSI (helmcheck's vehicle) says IVER3-EMU
    _with_process(d, "python3 ./my_backseat.py --serial /dev/pts/5")
    finish_run(load_results(d), d, DEFAULT)
    html, md, junit = _render(d)
    command = "python3 ./my_backseat.py --serial /dev/pts/5"
    first = html.split('id="contents"')[0]
    assert f"<h1>helmcheck backseat certificate — {command}</h1>" in first
    assert f"{command} (the command --exec ran; --implementation NAME@VERSION names it)" in first
    implementation = html.split('id="implementation"', 1)[1].split("</details>", 1)[0]
    assert f"backseat: {command}" in implementation and "IVER3-EMU" not in implementation
    assert "IVER3-EMU" not in first
    line = next(ln for ln in md.splitlines() if ln.startswith("Backseat: "))
    assert line.startswith(f"Backseat: `{command}` (the command --exec ran) on /dev/pts/5")
    assert "IVER3-EMU" not in md.split("| PASS |")[0] and "Implementation:" not in md
    assert ("identity.backseat", f"{command} (the command --exec ran; --implementation NAME@VERSION names it)") \
        in _props(junit)


@pytest.mark.unverifiable  # a hand-made results fixture, not a run
def test_a_backseat_named_with_implementation_is_named_so_even_when_started_with_exec(tmp_path):
    d = copy_run(tmp_path, "backseat_run")
    _with_process(d, "./pHelmBridge --port=/dev/pts/5")
    finish_run(load_results(d), d, DEFAULT,
               RunDeclaration(Declared(implementation_name="moos-ivp-helm", implementation_version="2.1.0")))
    html, md, _ = _render(d)
    assert "<h1>helmcheck backseat certificate — moos-ivp-helm@2.1.0</h1>" in html
    assert "Backseat: moos-ivp-helm@2.1.0 on /dev/pts/5" in md
    assert "--exec ran" not in html.split('id="contents"')[0] and "IVER3-EMU" not in md.split("| PASS |")[0]


@pytest.mark.unverifiable  # hand-made results, not a run
def test_the_precision_remark_says_what_it_means_in_the_html_banner_and_the_markdown(tmp_path):
    """Issue 43: one sentence — the timing faults that could pass at this scale, and the time
    scale that judges timing to the profile's tolerance — in every rendering's banner."""
    from helmcheck.judge.linebudget import LineBudget

    r = vehicle_results()
    budget = LineBudget(k=20.0, baud=19200, latency_s=0.02, measured=True)
    r["settings"]["line_budget"] = budget.as_dict()
    for c in r["clauses"]:
        if c["id"] == "RH-SRV-4":
            c["precision"] = {"nominal_s": 0.65, "widened_s": 6.21, "time_scale": 20.0}
    d = tmp_path / "coarse"
    write_results_atomic(d, r)
    html, md, _ = _render(d)
    sentence = (f"Timing faults up to ±6.2 s could pass at ×20 (1 timing clause(s) judged coarser than "
                f"RH-TIM-1's tolerance; RH-SRV-4 within ±6.2 s, nominal ±0.65 s); for timing at the "
                f"profile's tolerance run at ×{budget.nominal_scale():g}.")
    assert f'<p class="precision" id="precision">{sentence.replace(chr(39), "&#x27;")}</p>' in _banner_html(html)
    assert sentence.replace("'", "'") in _banner_md(md).replace("\\", "")
