"""How many faulty vehicles the exploration alone finds, on their own clause, and what it reached.

Every faulty vehicle of the suite — the emulator mutants (``tests/faulty_vehicles``) and, where
``../shared/third-party/uvc_sim.py`` is beside the checkout, the single faults of that independent
simulator (``tests/third_party_faults.py``) — and, where ``../shared/third-party/vehicle3`` is,
every single fault of that third vehicle we did not write (its own ``--mutant`` list,
``tests/vehicle3.py``) is certified with one trivial clause selected (``--select RH-POS-1``: its
hand-written case sends one ``$OPOS``), the exploration's default budget and a fixed seed, so that
a finding on any other clause comes from the exploration. The third vehicle runs on the fast line
(115200 baud, replies within 40 ms) at ×20, its timing faults (tolerance + 0.6 s) at the time
scale ``--precision nominal`` names on this line (measured once at the start; ×20 cannot tell
them). The conforming configurations (the emulator, its freedoms, the independent simulator, the
third vehicle) are certified the same way and must get no FAIL.

    .venv/bin/python benchmarks/explore_reach.py [--jobs N] [--seed S] [--families F …] [--only NAME …]
                                                 [--json OUT] [--keep DIR]

Prints one line per vehicle — found on its clause (for a fault of a reading, ``RH-RD-*``: or on the
clause the traceability table books that reading on, :func:`helmcheck.rules.reading_books`) / found
elsewhere / missed, the clauses failed,
and the model coverage the exploration reached on it (transitions, modes, interrupt pairs, timers
run out) — and the figures per family.

The run measures the ``helmcheck`` package as it is when it starts: it copies it to a temporary
directory and imports it from there, in its workers and in the ``helmcheck`` processes it spawns,
so that an edit to the checkout during the half hour does not change the code under measurement
halfway (:func:`_snapshot`).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

SELECT = "RH-POS-1"
#: The families of vehicles: the emulator's mutants, the independent simulator's faults, the third vehicle's.
FAMILIES = ("emulator", "third-party", "vehicle3")
KEEP = os.environ.get("HELMCHECK_REACH_KEEP")  #: --keep: a directory to keep each run's reports in


def _workdir(family: str, name: str):
    """Where one vehicle's runs write: a temporary directory, or ``--keep DIR/family-name``."""
    import contextlib
    if not KEEP:
        return tempfile.TemporaryDirectory()
    d = Path(KEEP) / f"{family}-{name}"
    d.mkdir(parents=True, exist_ok=True)
    return contextlib.nullcontext(str(d))


def _other_choices():
    from helmcheck.emulator.freedoms import EmulatorSettings
    return EmulatorSettings(reply_delay_s=(0.0, 0.15), seed=3, control_tick_s=0.2, timer_factor=1.02,
                            speed_factor=1.25, turn_rate_dps=25.0, ascent_mps=0.6,
                            decimals=(("lat", 7), ("lon", 7), ("speed", 1), ("distance", 0)), idle_distance="last",
                            osi_reserved=("x", "y", "z"), start_battery_pct=80.0)


def _slow_choices():
    from helmcheck.emulator.freedoms import EmulatorSettings
    return EmulatorSettings(reply_delay_s=(0.1, 0.5), seed=5, timer_factor=0.98, speed_factor=0.8,
                            turn_rate_dps=8.0, ascent_mps=0.15, buoyancy_rise_mps=0.05, start_heading=350.0)


#: Conforming emulators with other freedoms than the reference one's: they must get no FAIL.
FREEDOMS = {"conforming-freedoms": _other_choices, "conforming-slow": _slow_choices}


def _replay(path: Path, port: str) -> int:
    """``helmcheck replay`` of one saved replay on a fresh vehicle: its exit status (1: fails again)."""
    import contextlib
    import io

    from helmcheck.cli import main as cli_main
    with contextlib.redirect_stdout(io.StringIO()):
        return cli_main(["replay", str(path), "--port", port])


def _emulator_case(name: str, seed: int, k: float, budget: float | None) -> dict:
    from helmcheck.certify.vehicle.runner import Options, certify
    from tests.faulty_vehicles import EMU_PROFILE, MUTANTS, make_core, serve

    mutant = next((m for m in MUTANTS if m.name == name), None)

    def core(start):
        if name in FREEDOMS:  # a conforming vehicle that takes other freedoms (docs/freedoms.md)
            from helmcheck.emulator.core import EmulatorCore
            from helmcheck.emulator.missionfile import DirectoryCatalog, builtin_dir
            return EmulatorCore(EMU_PROFILE.replace(time_scale=k), DirectoryCatalog([builtin_dir()]), start=start,
                                time_scale=k, baud=115200, settings=FREEDOMS[name]())
        return make_core(mutant, k, start)

    with _workdir("emulator", name) as tmp:
        with serve(core) as port:
            opts = Options(port=port, profile=EMU_PROFILE.replace(time_scale=k), time_scale=k,
                           report_dir=Path(tmp) / "r", select=[SELECT], progress=False, render=False, seed=seed,
                           explore_budget_s=budget)
            out = certify(opts)
        r = _summary(name, mutant.clause if mutant else "", out.results, "emulator")
        codes = []
        for rel in r["replays"]:  # each on a fresh instance of the same vehicle
            with serve(core) as port:
                codes.append(_replay(Path(tmp) / "r" / rel, port))
        r["replayed"] = codes
        return r


def _third_party_case(fault: str, seed: int, k: float, budget: float | None) -> dict:
    import subprocess

    from tests.test_third_party_vehicle import BASE, OXFLT, uvc_sim
    with _workdir("third-party", fault) as tmp:
        t = Path(tmp)
        with uvc_sim(t, k, fault="" if fault == "conforming" else fault) as port:
            prof = t / "profile.toml"
            prof.write_text(BASE + OXFLT + "baud = 115200\n" + f"time_scale = {k:g}\n")
            extra = ["--explore-budget", f"{budget:g}"] if budget else []
            subprocess.run([sys.executable, "-m", "helmcheck", "certify", "vehicle", "--port", port,
                            "--time-scale", f"{k:g}", "--profile", str(prof), "--report-dir", str(t / "run"),
                            "--seed", str(seed), "--no-progress", "--select", SELECT, *extra],
                           capture_output=True, text=True, timeout=900)
            results = json.loads((t / "run" / "results.json").read_text())
        codes = []
        for r in results.get("replays", []):
            with uvc_sim(t, k, fault="" if fault == "conforming" else fault) as port:
                codes.append(subprocess.run([sys.executable, "-m", "helmcheck", "replay", str(t / "run" / r["file"]),
                                             "--port", port], capture_output=True, timeout=600).returncode)
    from tests.test_third_party_vehicle import CAUGHT_ON
    c = CAUGHT_ON.get(fault, "")
    clause = c[0] if isinstance(c, tuple) else c
    out = _summary(fault, clause, results, "third-party")
    out["replayed"] = codes
    return out


def _vehicle3_case(mutant: str, seed: int, k: float, budget: float | None) -> dict:
    """One vehicle of the third vehicle's family: certified, each replay it saved driven again on
    a fresh instance of the same vehicle."""
    import subprocess

    from tests import vehicle3 as V3
    clause = dict((m, c) for m, c, _ in V3.mutants()).get(mutant, "")
    with _workdir("vehicle3", mutant) as tmp:
        t = Path(tmp)
        fault = "" if mutant == "conforming" else mutant
        extra = ["--explore-budget", f"{budget:g}"] if budget else []
        with V3.vehicle3(t / "v", k, fault) as port:
            results = V3.certify(t, port, k, "--seed", str(seed), "--select", SELECT, *extra)
        codes = []
        for r in results.get("replays", []):
            with V3.vehicle3(t / f"v-{len(codes)}", k, fault) as port:
                codes.append(subprocess.run([sys.executable, "-m", "helmcheck", "replay", str(t / "run" / r["file"]),
                                             "--port", port], capture_output=True, timeout=900).returncode)
    out = _summary(mutant, clause, results, "vehicle3")
    out["replayed"] = codes
    out["time_scale"] = k
    return out


def _summary(name: str, clause: str, results: dict, family: str) -> dict:
    from helmcheck.rules import reading_books
    failed = sorted(c["id"] for c in results["clauses"] if c["verdict"] == "fail")
    ex = (results.get("stats") or {}).get("explore") or {}
    # a fault of a reading (RH-RD-*) is on its own clause where the traceability table books that
    # reading's rule (RH-RD-16 -> RH-FRM-5 ...), as the whole certification's sweep counts it
    books = reading_books().get(clause)
    if not clause:
        outcome = "false-fail" if failed else "clean"  # a conforming configuration
    elif clause in failed or books in failed:
        outcome = "own"
    elif failed:
        outcome = "elsewhere"
    else:
        outcome = "missed"
    return {"family": family, "name": name, "clause": clause, "outcome": outcome, "failed": failed,
            "ran": ex.get("ran"), "wall_s": ex.get("wall_s"), "found": ex.get("found", ""),
            "replays": [r.get("file") for r in results.get("replays", [])],
            "model_coverage": {k: f"{v['covered']}/{v['of']}" for k, v in (ex.get("model_coverage") or {}).items()},
            "edges": f"{(results.get('stats') or {}).get('edges', {}).get('reached')}/"
                     f"{(results.get('stats') or {}).get('edges', {}).get('of')}"}


def cases(only: list[str]) -> list[tuple]:
    from tests.faulty_vehicles import MUTANTS
    out = ([("emulator", "conforming")] + [("emulator", n) for n in FREEDOMS]
           + [("emulator", m.name) for m in MUTANTS])
    try:
        from tests.test_third_party_vehicle import CAUGHT_ON, SIM
        if SIM.is_file():
            out += [("third-party", "conforming")] + [("third-party", f) for f in CAUGHT_ON]
    except ImportError:
        pass
    from tests import vehicle3 as V3
    if V3.available():  # its timing faults first: at the nominal time scale they take longest
        names = sorted((m for m, _, _ in V3.mutants()), key=lambda m: m not in V3.TIMING)
        out += [("vehicle3", "conforming")] + [("vehicle3", m) for m in names]
    if only:
        out = [c for c in out if any(o in c[1] for o in only) or c[0] in only]
    return out


def run_one(family: str, name: str, seed: int, budget: float | None, nominal: float | None = None) -> dict:
    t0 = time.monotonic()
    try:
        if family == "emulator":
            r = _emulator_case(name, seed, 25.0, budget)
        elif family == "vehicle3":
            from tests.vehicle3 import TIMING
            r = _vehicle3_case(name, seed, (nominal or 1.0) if name in TIMING else 20.0, budget)
        else:
            r = _third_party_case(name, seed, 20.0, budget)
    except Exception as e:  # noqa: BLE001 - reported per case
        r = {"family": family, "name": name, "clause": "", "outcome": "error", "failed": [],
             "error": f"{type(e).__name__}: {e}"}
    r["case_wall_s"] = round(time.monotonic() - t0, 1)
    return r


def _snapshot() -> Path:
    """A copy of the ``helmcheck`` package as it is now, put first on the import path of this
    process, its workers and every process they spawn (``PYTHONPATH``); it takes effect where
    nothing imported ``helmcheck`` before (the command line, not an in-process call from a test
    session). The tests stay where they are: they find the independent simulator beside the
    checkout."""
    code = Path(tempfile.mkdtemp(prefix="explore-reach-code-"))
    shutil.copytree(ROOT / "helmcheck", code / "helmcheck", ignore=shutil.ignore_patterns("__pycache__"))
    sys.path.insert(0, str(code))
    os.environ["PYTHONPATH"] = os.pathsep.join(p for p in (str(code), os.environ.get("PYTHONPATH", "")) if p)
    return code


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--jobs", type=int, default=4)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--budget", type=float, default=None, help="wall seconds (default: the fast profile's)")
    ap.add_argument("--only", nargs="*", default=[])
    ap.add_argument("--families", nargs="*", default=list(FAMILIES), choices=FAMILIES,
                    help="the families of vehicles to run (default: all there are beside the checkout)")
    ap.add_argument("--json", type=Path)
    ap.add_argument("--keep", type=Path, help="keep each vehicle's report directory under this one")
    a = ap.parse_args(argv)
    if a.keep:
        os.environ["HELMCHECK_REACH_KEEP"] = str(a.keep.resolve())  # the worker processes read it
        global KEEP
        KEEP = os.environ["HELMCHECK_REACH_KEEP"]
    before = os.environ.get("PYTHONPATH"), list(sys.path)
    code = _snapshot()  # before anything imports helmcheck
    try:
        return _run(a, [c for c in cases(a.only) if c[0] in a.families])
    finally:
        if before[0] is None:
            os.environ.pop("PYTHONPATH", None)
        else:
            os.environ["PYTHONPATH"] = before[0]
        sys.path[:] = before[1]
        shutil.rmtree(code, ignore_errors=True)


#: The model coverage columns printed per vehicle.
_REACH = ("rows", "modes", "interrupt_pairs", "timers")


def _reach(r: dict) -> str:
    mc = r.get("model_coverage") or {}
    return " ".join(f"{k.split('_')[0][:5]} {mc[k]}" for k in _REACH if k in mc)


def _nominal(todo) -> float | None:
    """The time scale ``--precision nominal`` names for the third vehicle on this line, when a
    timing fault of it is to be run."""
    from tests import vehicle3 as V3
    if not any(f == "vehicle3" and n in V3.TIMING for f, n in todo):
        return None
    with tempfile.TemporaryDirectory() as tmp:
        k = V3.nominal_scale(Path(tmp))
    print(f"vehicle3: --precision nominal names ×{k:g} on this line (its timing faults run there)"
          if k else "vehicle3: no time scale gives nominal precision on this line (its timing faults run at ×1)",
          flush=True)
    return k


def _mean_reach(rows: list) -> str:
    """The mean share of each :data:`_REACH` dimension the runs reached."""
    out = []
    for k in _REACH:
        got = [tuple(map(int, r["model_coverage"][k].split("/"))) for r in rows
               if k in (r.get("model_coverage") or {})]
        if got:
            out.append(f"{k.replace('_', ' ')} {sum(a for a, _ in got) / len(got):.0f}/{got[0][1]}")
    return ", ".join(out) or "none recorded"


def _run(a, todo) -> int:
    """Certify every vehicle of ``todo``, ``a.jobs`` at a time; print and write the figures."""
    rows: list = []
    t0 = time.monotonic()
    nominal = _nominal(todo)
    with ProcessPoolExecutor(a.jobs) as pool:
        futs = [pool.submit(run_one, f, n, a.seed, a.budget, nominal) for f, n in todo]
        for fut in as_completed(futs):
            r = fut.result()
            rows.append(r)
            print(f"{r['family']:11} {r['name']:34} {r['clause']:10} {r['outcome']:10} "
                  f"{','.join(r['failed'])[:60]:40} {_reach(r)} edges {r.get('edges')} replays {r.get('replayed')} "
                  f"{'x%g ' % r['time_scale'] if r.get('time_scale') not in (None, 20.0) else ''}{r.get('error', '')}",
                  flush=True)
    for fam in FAMILIES:
        faulty = [r for r in rows if r["family"] == fam and r["clause"]]
        if not faulty:
            continue
        own = sum(r["outcome"] == "own" for r in faulty)
        anyf = sum(r["outcome"] in ("own", "elsewhere") for r in faulty)
        bad = [r["name"] + ":" + ",".join(r["failed"]) for r in rows
               if r["family"] == fam and r["outcome"] == "false-fail"]
        replays = [c for r in rows if r["family"] == fam for c in r.get("replayed") or []]
        print(f"{fam}: {own}/{len(faulty)} on their own clause ({100 * own / len(faulty):.0f} %), "
              f"{anyf}/{len(faulty)} found at all; conforming false FAILs: {bad or 'none'}; "
              f"replays failing again on a fresh instance: {replays.count(1)}/{len(replays)}; "
              f"mean model coverage reached: {_mean_reach([r for r in rows if r['family'] == fam])}")
    print(f"wall {time.monotonic() - t0:.0f} s")
    if a.json:
        a.json.write_text(json.dumps(sorted(rows, key=lambda r: (r["family"], r["name"])), indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
