"""The third vehicle, ``vehicle3.py``: a vehicle we did not write, certified with the ICS its README gives.

``../shared/third-party/vehicle3/`` holds an independent rh5 vehicle written from the reference
profile alone: a 10 Hz control loop, seeded reply latency (30–400 ms by default), output paced at
the baud, its own mission format with the park on waypoint 2, a mission whose own time-limit rule
trips (``timelimit.mis``, 40 s after its start), no YSI sonde; and 36 single-fault mutants
(``--mutant NAME``), each naming the clause it breaks. Its README lists its choices and the
ambiguities it met; where the profile leaves room, every reading is accepted (the readings table,
``helmcheck/model/readings.py``), and nothing here or in helmcheck special-cases it. It makes its
own pty and prints ``port: …``, so it is started with ``--port announced --exec``.

* ``make test``: the correct vehicle on a fast line (115200 baud, replies 30–40 ms), ×20, under
  ``$OXFLT`` — PASS with a certificate, nothing FAIL or INCONCLUSIVE, ``helmcheck verify``
  agreeing —, and under its own mission rule the lockout clauses, each PASS; and a representative
  set of its mutants, each certified on the clause its README names: FAIL there.
* ``make matrix`` (``HELMCHECK_MATRIX=1``): the whole certificate under its mission rule, and the
  correct vehicle on its own default line (19200 baud, replies 30–400 ms) under ``$OXFLT``: a
  certificate. Every mutant certified whole is
  ``tests/test_vehicle3_mutants.py``'s.

Where ``../shared`` is not beside the checkout, these tests skip and say so.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
V3 = ROOT.parent / "shared" / "third-party" / "vehicle3" / "vehicle3.py"
MATRIX = os.environ.get("HELMCHECK_MATRIX") == "1"

pytestmark = pytest.mark.skipif(not V3.is_file(), reason=f"the third vehicle is not there: {V3} (it is kept in "
                                                         "../shared/third-party beside the checkout)")

#: Its README's ICS: every rh5 default but osd_letters and the trigger keys.
ICS = ('protocol = "rh5"\nosd_letters = "GCSPDTI"\nmission = "conformance.mis"\nmission_waypoints = 4\n'
       'fault_injection = "oxflt"\n')
OXFLT = 'violation_trigger = "oxflt"\n'
RULE = 'violation_trigger = "mission-rule"\nviolation_mission = "timelimit.mis"\nviolation_after_s = 40.0\n'
FAST = ("--baud", "115200", "--latency-max-ms", "40")


def certify(tmp: Path, ics: str, baud: int, vehicle_args: tuple = (), *extra: str, k: float = 20.0):
    """``certify vehicle --port announced --exec 'vehicle3.py …'``: (exit code, results, output)."""
    prof = tmp / "ics.toml"
    prof.write_text(ics + f"time_scale = {k:g}\nbaud = {baud}\n")
    out = tmp / "run"
    cmd = " ".join([sys.executable, str(V3), "--time-scale", "{time_scale}", "--mission-dir", str(tmp / "missions"),
                    *vehicle_args])
    proc = subprocess.run([sys.executable, "-m", "helmcheck", "certify", "vehicle", "--port", "announced",
                           "--exec", cmd, "--time-scale", f"{k:g}", "--profile", str(prof), "--report-dir",
                           str(out), "--seed", "3", "--no-progress", *(extra or ("--examples", "5"))],
                          capture_output=True, text=True, timeout=900, cwd=ROOT)
    results = json.loads((out / "results.json").read_text())
    return proc.returncode, results, proc.stdout + proc.stderr


def not_passed(results: dict) -> dict:
    return {c["id"]: f"{c['verdict']}: {c['reason']}" for c in results["clauses"] if c["verdict"] != "pass"}


def verified(tmp: Path) -> bool:
    return subprocess.run([sys.executable, "-m", "helmcheck", "verify", str(tmp / "run")], capture_output=True,
                          text=True, timeout=300, cwd=ROOT).returncode == 0


# ============================================================================ the correct vehicle

@pytest.mark.parametrize("trigger", ["oxflt", pytest.param("mission-rule", marks=pytest.mark.skipif(
    not MATRIX, reason="make matrix's (HELMCHECK_MATRIX=1): make test certifies the lockout clauses under its "
                       "mission rule (test_its_mission_rule_trips_the_lockout_while_it_dives)"))])
def test_the_correct_vehicle_certifies_on_a_fast_line(tmp_path, trigger):
    """×20, 115200 baud, replies within 40 ms: every claimed clause PASS, a certificate — the SRP
    name outside the directory refused with 31 (RH-RD-6: 30 or 31), RH-MSN-4 on its own test
    mission (no end_mission in its ICS: the vehicle reports it short), its time-limit rule tripping
    while the servo dive of V-60 is under way."""
    code, results, text = certify(tmp_path, ICS + (OXFLT if trigger == "oxflt" else RULE), 115200, FAST,
                                  "--examples", "0" if trigger == "mission-rule" else "5")
    assert not_passed(results) == {}, text
    assert code == 0 and results["certificate"] is True, text
    assert results["line_model"]["kind"] == "clean", results["line_model"]
    assert verified(tmp_path)
    msn = next(c for c in results["clauses"] if c["id"] == "RH-MSN-2")
    assert "srp_bad_path = 31" in msn["reason"], msn["reason"]


def test_its_mission_rule_trips_the_lockout_while_it_dives(tmp_path):
    """Its own time-limit rule as the trigger (RH-SAF-5, no ``$OXFLT`` sent), ×20, fast line: the
    lockout clauses — its rule trips while V-60's servo dive is under way — each PASS, and
    ``helmcheck verify`` agrees (the whole certification under this trigger: make matrix)."""
    code, results, text = certify(tmp_path, ICS + RULE, 115200, FAST, "--examples", "0", "--select", "RH-SAF-*")
    saf = {c["id"]: c for c in results["clauses"] if c["id"].startswith("RH-SAF-")}
    assert {c: e["verdict"] for c, e in saf.items() if c != "RH-SAF-5"} == \
        {"RH-SAF-1": "pass", "RH-SAF-2": "pass", "RH-SAF-3": "pass", "RH-SAF-4": "pass"}, not_passed(results)
    assert code == 0, text
    assert "$OXFLT" not in (tmp_path / "run" / "wire.log").read_text().replace("not tested", "")
    assert verified(tmp_path)


@pytest.mark.skipif(not MATRIX, reason="make matrix (HELMCHECK_MATRIX=1): its own default line, about 5 minutes")
def test_matrix_the_correct_vehicle_certifies_on_its_own_default_line(tmp_path):
    """19200 baud, replies 30–400 ms (its defaults), ×20, ``$OXFLT``: a certificate; timing judged as
    coarsely as the line allows (said so in the verdict), nothing INCONCLUSIVE from the tester's own
    choice of a range edge's timeout."""
    code, results, text = certify(tmp_path, ICS + OXFLT, 19200)
    assert not_passed(results) == {}, text
    assert code == 0 and results["certificate"] is True, text


# ============================================================================ its mutants

def mutants() -> dict:
    """NAME -> the clause its README names (``--list-mutants``)."""
    if not V3.is_file():
        return {}
    out = subprocess.run([sys.executable, str(V3), "--list-mutants"], capture_output=True, text=True, timeout=30)
    return {ln.split()[0]: ln.split()[1] for ln in out.stdout.splitlines() if ln.strip()}


#: A mutant whose clause is a reading (§8b) is certified on the clauses that reading refines.
SELECT = {"RH-RD-16": "RH-FRM-5", "RH-RD-2": "RH-SAF-1", "RH-RD-4": "RH-OMW-3", "RH-RD-9": "RH-PK-1",
          "RH-RD-13": "RH-SAF-*"}
#: A mutant whose fault only a case of another clause meets: its clause and that one (an ``mP``
#: shows only in a park by ``$OPK``, RH-PK-2's case).
ALSO = {"mode-Mp": "RH-PK-2"}
#: make test's representative set: a framing, an ACK order, a file rule, a report fault (the rest,
#: certified whole: tests/test_vehicle3_mutants.py in make matrix).
REPRESENTATIVE = ("cksum-lowercase", "ack-out-of-order", "omload-dotdot", "mode-Mp")
ALL = mutants()


@pytest.mark.parametrize("name", [n for n in ALL if n in REPRESENTATIVE] or ["none"])
def test_each_mutant_fails(tmp_path, name):
    """Certified on the clause its README names (the clause a reading refines for a §8b one), on the
    fast line: FAIL, exit 1 — never PASS, never only INCONCLUSIVE."""
    if name == "none":
        pytest.skip("vehicle3 --list-mutants listed none")
    clause = ALL[name]
    select = ",".join(filter(None, (SELECT.get(clause, clause), ALSO.get(name))))
    code, results, text = certify(tmp_path, ICS + OXFLT, 115200, (*FAST, "--mutant", name), "--select", select,
                                  "--examples", "0")
    failed = [c["id"] for c in results["clauses"] if c["verdict"] == "fail"]
    assert failed and code == 1, (name, clause, text)
