"""``helmcheck check-log DIR`` over an archive of 200 realistic logs: 1 worker process vs 2.

Run standalone: ``python benchmarks/fleet_bench.py [--files 200] [--min-lines 2000]
[--max-lines 60000] [--pairs 1] [--keep DIR] [--no-render]``.

The archive: ``--files`` wire logs from :func:`realistic_log.write_session` (a scripted backseat
driving the reference vehicle; every tenth with its handful of faults), of mixed size — the
line counts drawn log-uniformly between ``--min-lines`` and ``--max-lines`` with a fixed seed, so
the same options give the same archive — in ten vehicle folders. ``--keep DIR`` writes it there
and uses it again next time (generating takes longer than checking).

Each measurement is one real ``helmcheck check-log ARCHIVE --report-dir R --jobs N --force``
process (reports rendered unless ``--no-render``; ``--force`` so every log is judged, not found
in the cache): its wall time and its CPU seconds (its own and its worker processes',
``resource.getrusage(RUSAGE_CHILDREN)``). ``--pairs K`` runs K pairs, ``--jobs 1`` and
``--jobs 2`` alternating, and reports the medians. Printed: lines judged per second of wall time
for each, the speed-up (wall 1 / wall 2) and the scaling efficiency (speed-up / 2). The machine's
other load counts in wall time: on a shared machine, read the CPU seconds too.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import random
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent))

from realistic_log import write_session  # noqa: E402


def plan(files: int, lo: int, hi: int) -> list[tuple[str, int, int, bool]]:
    """(relative path, lines, seed, faults) for each log of the archive."""
    rng = random.Random(2026)
    out = []
    for i in range(files):
        lines = int(math.exp(rng.uniform(math.log(lo), math.log(hi))))
        out.append((f"vehicle-{i % 10:02d}/session-{i:03d}.log", lines, i, i % 10 == 9))
    return out


def _write(args: tuple[str, str, int, int, bool]) -> int:
    root, rel, lines, seed, faults = args
    path = Path(root) / rel
    path.parent.mkdir(parents=True, exist_ok=True)
    return write_session(path, lines, seed=seed, faults=faults)


def build(root: Path, files: int, lo: int, hi: int) -> int:
    """The archive under ``root`` (kept if it is there already, per its manifest); total lines."""
    wanted = plan(files, lo, hi)
    manifest = root.parent / (root.name + ".json")  # beside the archive: not a file check-log would skip
    if manifest.is_file():
        done = json.loads(manifest.read_text())
        if done.get("plan") == [list(w) for w in wanted]:
            return done["lines"]
    if root.exists():
        shutil.rmtree(root)
    root.mkdir(parents=True)
    t0 = time.monotonic()
    with ProcessPoolExecutor(max_workers=os.cpu_count() or 1) as pool:
        total = sum(pool.map(_write, [(str(root), rel, n, seed, f) for rel, n, seed, f in wanted]))
    manifest.write_text(json.dumps({"plan": [list(w) for w in wanted], "lines": total}))
    print(f"archive: {files} logs, {total:,} lines, written in {time.monotonic() - t0:.1f} s", flush=True)
    return total


def measure(archive: Path, report: Path, jobs: int, render: bool) -> tuple[float, float, dict]:
    """One ``check-log`` process: wall seconds, CPU seconds (with its workers), its summary."""
    cmd = [sys.executable, "-m", "helmcheck", "check-log", str(archive), "--report-dir", str(report),
           "--jobs", str(jobs), "--force", "--overwrite"] + ([] if render else ["--no-render"])
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    done = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if done.returncode not in (0, 1):
        sys.exit(f"check-log failed ({done.returncode}): {done.stderr.strip()}")
    summary = json.loads((report / "summary.json").read_text())
    return wall, cpu, summary


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--files", type=int, default=200)
    ap.add_argument("--min-lines", type=int, default=2000)
    ap.add_argument("--max-lines", type=int, default=60000)
    ap.add_argument("--pairs", type=int, default=1, help="alternating --jobs 1 / --jobs 2 pairs (medians)")
    ap.add_argument("--keep", type=Path, help="write the archive here and use it again next time")
    ap.add_argument("--no-render", action="store_true", help="results.json only (no HTML/Markdown/JUnit)")
    args = ap.parse_args(argv)
    scratch = Path(tempfile.mkdtemp(prefix="helmcheck-fleet-bench-"))
    try:
        archive = args.keep or scratch / "archive"
        lines = build(archive, args.files, args.min_lines, args.max_lines)
        runs: dict[int, list[tuple[float, float]]] = {1: [], 2: []}
        for k in range(args.pairs):
            for jobs in (1, 2) if k % 2 == 0 else (2, 1):
                wall, cpu, summary = measure(archive, scratch / f"out-{jobs}", jobs, not args.no_render)
                judged = summary["counts"]["judged"]
                if judged != args.files:
                    sys.exit(f"--jobs {jobs}: {judged} of {args.files} logs judged")
                runs[jobs].append((wall, cpu))
                print(f"pair {k + 1}: --jobs {jobs}: {wall:.2f} s wall, {cpu:.2f} s CPU, "
                      f"{lines / wall:,.0f} lines/s; {summary['verdict_line']}", flush=True)
        w1, w2 = (statistics.median(w for w, _ in runs[j]) for j in (1, 2))
        c1, c2 = (statistics.median(c for _, c in runs[j]) for j in (1, 2))
        print(f"archive: {args.files} logs, {lines:,} lines ({args.min_lines:,}-{args.max_lines:,} per log), "
              f"reports {'not ' if args.no_render else ''}rendered; cores: {os.cpu_count()}")
        print(f"--jobs 1: {w1:.2f} s wall ({c1:.2f} s CPU), {lines / w1:,.0f} lines/s")
        print(f"--jobs 2: {w2:.2f} s wall ({c2:.2f} s CPU), {lines / w2:,.0f} lines/s")
        print(f"speed-up {w1 / w2:.2f}x, scaling efficiency {w1 / w2 / 2:.0%} "
              f"(medians of {args.pairs} alternating pair(s))")
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
