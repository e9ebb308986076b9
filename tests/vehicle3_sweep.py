"""The third vehicle's single faults, each certified as a new user would: ``python -m tests.vehicle3_sweep``.

``../shared/third-party/vehicle3/vehicle3.py`` is a vehicle we did not write, with 36 mutants
(``--mutant NAME``), each naming the clause it breaks (``--list-mutants``). Each is started on its
own pty on the fast line (``--time-scale 20 --baud 115200 --latency-max-ms 40``, or the time scale
given) and certified whole with the ICS of its README (:data:`ICS`), no ``--select``. The outcome
of each is classified (:func:`classify`):

* ``own``: FAIL on the clause the mutant names;
* ``refined``: the mutant names a reading (``RH-RD-*``, never booked: :mod:`helmcheck.judge.vehicle.blame`)
  and the run FAILs the clause the traceability table books that reading's rule on
  (:func:`helmcheck.rules.reading_books`);
* ``elsewhere``: FAIL, on other clauses only;
* ``pass``: no FAIL (but a known false verdict, :data:`KNOWN_FALSE`) and nothing INCONCLUSIVE;
  ``other``: anything else (INCONCLUSIVE, a tester error).

Used by ``tests/test_vehicle3_mutants.py`` (the full sweep behind ``HELMCHECK_MATRIX=1``) and by
hand: ``python -m tests.vehicle3_sweep [--jobs 2] [--time-scale 20] [--precision nominal] [NAME …]``
prints one row per mutant and writes ``--out`` (JSON).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from pathlib import Path

from tests.processes import announced_port

ROOT = Path(__file__).resolve().parent.parent
VEHICLE3 = Path(os.environ.get("HELMCHECK_VEHICLE3", ROOT.parent / "shared" / "third-party" / "vehicle3" / "vehicle3.py"))

#: The ICS of vehicle3's README, on the fast line (``baud``, ``time_scale`` appended per run).
ICS = '''protocol = "rh5"
depth_unit = "m"
ack_window_s = 1.0
lockout_s = 20.0
timeout_range = [1, 120]
max_depth_m = 100.0
max_speed_kn = 4.5
osi_fields = 21
osd_letters = "GCSPDTI"
commands = ["OMS","OMP","OJW","OMSTOP","OMLOAD","OMSTART","OPOS","OSD","OLOGL","OLOGD","ORWSET","ODVL","OPK","OMW"]
mission = "conformance.mis"
mission_waypoints = 4
fault_injection = "oxflt"
violation_trigger = "oxflt"
violation_mission = "timelimit.mis"
violation_after_s = 40.0
'''


def mutants() -> dict[str, str]:
    """name → the clause vehicle3 says the mutant breaks (its ``--list-mutants``)."""
    out = subprocess.run([sys.executable, str(VEHICLE3), "--list-mutants"], capture_output=True, text=True,
                         timeout=60, check=True).stdout
    return {m.group(1): m.group(2) for m in re.finditer(r"^(\S+) (RH-[A-Z]+-\d+)", out, re.M)}


@contextmanager
def vehicle3(workdir: Path, k: float, mutant: str = "", baud: int = 115200, latency_ms: int = 40):
    """vehicle3 on its own pty; yields its port."""
    workdir.mkdir(parents=True, exist_ok=True)
    args = [sys.executable, str(VEHICLE3), "--time-scale", f"{k:g}", "--baud", str(baud),
            "--latency-max-ms", str(latency_ms), "--mission-dir", str(workdir / "missions"),
            "--log", str(workdir / "vehicle.log")]
    if mutant:
        args += ["--mutant", mutant]
    with announced_port(args, "vehicle3", within=30.0, stderr=subprocess.DEVNULL) as port:
        yield port


def outcome(workdir: Path, code: int, seconds: float) -> dict:
    """What a run in ``workdir`` ended with: {code, verdicts, reasons, seconds}."""
    try:
        results = json.loads((workdir / "run" / "results.json").read_text())
    except (OSError, ValueError):
        results = {"clauses": []}
    verdicts = {c["id"]: c["verdict"] for c in results.get("clauses", [])}
    return {"code": code, "verdicts": verdicts, "seconds": seconds,
            "reasons": {c["id"]: c.get("reason", "") for c in results.get("clauses", []) if c["verdict"] != "pass"}}


def certify(workdir: Path, k: float, mutant: str = "", precision: str = "", extra: tuple = (),
            python: str = sys.executable, baud: int = 115200) -> dict:
    """Certify one vehicle3 (a mutant, or the correct one): {code, verdicts, reasons, seconds}."""
    prof = workdir / "ics.toml"
    workdir.mkdir(parents=True, exist_ok=True)
    prof.write_text(ICS + f"baud = {baud}\ntime_scale = {k:g}\n")
    out = workdir / "run"
    t0 = time.monotonic()
    with vehicle3(workdir, k, mutant, baud=baud) as port:
        cmd = [python, "-m", "helmcheck", "certify", "vehicle", "--port", port, "--profile", str(prof),
               "--time-scale", f"{k:g}", "--baud", str(baud), "--report-dir", str(out), "--overwrite",
               "--no-progress", *extra]
        if precision:
            cmd += ["--precision", precision]
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=3600, cwd=str(ROOT))
    (workdir / "certify.out").write_text(proc.stdout + proc.stderr)
    (workdir / "exit").write_text(f"{proc.returncode} {time.monotonic() - t0:.1f}\n")
    return outcome(workdir, proc.returncode, round(time.monotonic() - t0, 1))


def refined(clause: str) -> str:
    """The clause a reading's rule is booked on (the traceability table), else the clause itself."""
    try:
        from helmcheck.rules import reading_books
        books = reading_books()
    except ImportError:  # a checkout from before the table: the decisions as issue 42 states them
        books = {"RH-RD-16": "RH-FRM-5", "RH-RD-2": "RH-SAF-1", "RH-RD-13": "RH-SAF-1", "RH-RD-4": "RH-OMW-3",
                 "RH-RD-9": "RH-PK-1"}
    return books.get(clause, clause)


#: False verdicts known on the code a measurement runs on, left out of the classification (clause ->
#: the reason's pattern). None now: V-72's RH-MSN-1 FAIL for err 31 (an SRP name outside the mission
#: directory: 30 or 31, the readings table's srp_bad_path) is fixed.
KNOWN_FALSE: dict = {}


def failed_clauses(outcome: dict) -> set[str]:
    """The clauses the run FAILed, less a known false verdict (:data:`KNOWN_FALSE`)."""
    return {c for c, v in outcome["verdicts"].items() if v == "fail"
            and not (c in KNOWN_FALSE and KNOWN_FALSE[c].search(outcome["reasons"].get(c, "")))}


def classify(clause: str, outcome: dict) -> str:
    """``own``, ``refined``, ``elsewhere``, ``pass`` or ``other`` (module docstring)."""
    failed = failed_clauses(outcome)
    if clause in failed:
        return "own"
    if clause.startswith("RH-RD-") and refined(clause) in failed:
        return "refined"
    if failed:
        return "elsewhere"
    return "pass" if outcome["code"] == 0 or not (set(outcome["verdicts"].values()) - {"pass", "fail", "not-tested"}) \
        else "other"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("names", nargs="*", help="mutants (all when none)")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--time-scale", type=float, default=20.0)
    ap.add_argument("--precision", default="")
    ap.add_argument("--work", type=Path, default=Path("/tmp/vehicle3-sweep"))
    ap.add_argument("--out", type=Path, default=None)
    ap.add_argument("--python", default=sys.executable, help="the Python whose helmcheck certifies")
    ap.add_argument("--reuse", action="store_true", help="a mutant whose run in --work ended is read, not run again")
    ap.add_argument("--correct", action="store_true", help="certify the correct vehicle too (row 'correct')")
    args = ap.parse_args(argv)
    table = mutants()
    names = args.names or list(table)
    if args.correct:
        table["correct"] = "-"
        names = ["correct", *names]

    def one(name):
        done = args.work / name / "exit"
        if args.reuse and done.is_file():
            code, secs = done.read_text().split()
            got = outcome(args.work / name, int(code), float(secs))
        else:
            got = certify(args.work / name, args.time_scale, "" if name == "correct" else name, args.precision,
                          python=args.python)
        got["clause"], got["class"] = table[name], classify(table[name], got)
        failed = sorted(failed_clauses(got))
        print(f"{name:28} {table[name]:10} {got['class']:9} exit {got['code']} {got['seconds']:6.0f}s "
              f"fail: {' '.join(failed)}", flush=True)
        return name, got

    with ThreadPoolExecutor(max_workers=max(1, min(2, args.jobs))) as pool:
        rows = dict(pool.map(one, names))
    counts: dict[str, int] = {}
    for r in rows.values():
        counts[r["class"]] = counts.get(r["class"], 0) + 1
    print("summary:", ", ".join(f"{k} {v}" for k, v in sorted(counts.items())))
    if args.out:
        args.out.write_text(json.dumps(rows, indent=1, sort_keys=True))
    return 0


if __name__ == "__main__":
    sys.exit(main())
