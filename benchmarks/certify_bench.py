"""Cost of certifying a vehicle: a full run of the emulator, and the time to detect each fault.

Run standalone: ``python benchmarks/certify_bench.py [--time-scale K] [--repeat N] [--quick]``.

1. A full certification (every case plus the ``fast`` exploration) of the built-in emulator
   started as a subprocess on a pty at time scale 20 (``$OXFLT`` declared, 115200 baud). It
   prints the wall time and the share spent in waits the protocol forces: timeouts, lockouts,
   park times and mission travel (scaled by k), and the ACK windows the tester must sit out to
   judge a silent discard. Overhead is the rest. Targets: the run under 90 s, overhead under 25 %.
2. For each faulty vehicle of ``tests/faulty_vehicles`` (served in-process behind a pty), the
   median wall time over ``--repeat`` runs of a certification restricted to its clause, until
   the verdict FAIL on that clause.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from helmcheck.emulator.process import EmulatorProcess  # noqa: E402
from helmcheck.certify.vehicle.runner import Options, certify  # noqa: E402
from helmcheck.profile import emulator_profile  # noqa: E402


def full_run(k: float, examples) -> dict:
    profile = emulator_profile().replace(baud=115200, time_scale=k)
    with tempfile.TemporaryDirectory() as d, EmulatorProcess(time_scale=k, baud=115200) as emu:
        t0 = time.monotonic()
        out = certify(Options(port=emu.port, profile=profile, time_scale=k, report_dir=Path(d),
                              examples=examples, seed=1, progress=False))
        wall = time.monotonic() - t0
    st = out.results.get("stats", {})
    forced = float(st.get("forced_wait_s", 0.0))
    counts: dict = {}
    for c in out.results["clauses"]:
        counts[c["verdict"]] = counts.get(c["verdict"], 0) + 1
    return {"verdict": out.verdict, "wall": wall, "forced": forced, "counts": counts,
            "explore": st.get("explore", {}), "cases": len(out.results.get("cases", []))}


def detection(k: float, repeat: int) -> list[tuple[str, str, float, bool]]:
    from tests.faulty_vehicles import EMU_PROFILE, MUTANTS, make_core, serve

    rows = []
    for m in MUTANTS:
        times, ok = [], True
        for _ in range(repeat):
            with tempfile.TemporaryDirectory() as d, serve(lambda start, m=m: make_core(m, k, start)) as port:
                t0 = time.monotonic()
                out = certify(Options(port=port, profile=EMU_PROFILE.replace(time_scale=k), time_scale=k,
                                      report_dir=Path(d), select=list(m.select), examples=0, progress=False,
                                      render=False))
                times.append(time.monotonic() - t0)
                ok &= any(c["id"] == m.clause and c["verdict"] == "fail" for c in out.results["clauses"])
        rows.append((m.name, m.clause, statistics.median(times), ok))
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--time-scale", type=float, default=20.0)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--examples", type=int, default=None, help="exploration examples (default: fast profile)")
    ap.add_argument("--quick", action="store_true", help="fault detection only, one run each")
    a = ap.parse_args(argv)
    rc = 0
    if not a.quick:
        r = full_run(a.time_scale, a.examples)
        over = 1.0 - r["forced"] / r["wall"] if r["wall"] else 0.0
        print(f"full certification of the emulator at k={a.time_scale:g}: {r['verdict'].upper()} in "
              f"{r['wall']:.1f} s ({r['cases']} cases; clauses {r['counts']})")
        print(f"  protocol-forced waits {r['forced']:.1f} s ({100 * r['forced'] / r['wall']:.0f} %), "
              f"overhead {100 * over:.0f} % (targets: < 90 s, overhead < 25 %)")
        if r["explore"]:
            e = r["explore"]
            print(f"  exploration: {e.get('ran')} sequences in {e.get('wall_s')} s, outcome {e.get('outcome')}")
        rc |= r["verdict"] != "pass"
    rows = detection(a.time_scale, 1 if a.quick else a.repeat)
    print(f"time to detect each shipped fault (median of {1 if a.quick else a.repeat}, k={a.time_scale:g}):")
    for name, cid, med, ok in rows:
        print(f"  {name:32s} {cid:9s} {med:6.2f} s {'detected' if ok else 'MISSED'}")
        rc |= not ok
    print(f"  median over faults: {statistics.median(r[2] for r in rows):.2f} s")
    return int(rc)


if __name__ == "__main__":
    sys.exit(main())
