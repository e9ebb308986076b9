"""``helmcheck check-log`` on a 1,000,000-line two-direction wire log: time, CPU, peak memory, and
the judge's cost against the parse of the same file.

Run standalone: ``python benchmarks/check_log_bench.py [--lines N] [--seed S] [--best-case]
[--one-process] [--keep FILE] [--tracemalloc] [--no-parse] [--log FILE]``.

The input, by default, is realistic: a session of the reference vehicle driven by a scripted
backseat (``realistic_log.py``: missions started and stopped, servo episodes, parks, on-the-fly
waypoints, positions, log data, a lockout now and then), in which every state line differs as a
real vehicle's do — positions, times, attitude, battery, modes. It is generated once and kept
in the system temp directory (keyed by its arguments and the sources it depends on).
``--best-case`` checks instead the log this benchmark used first: a loop of 11 distinct lines
(``$OSD,G,C,S`` polls answered ``$GPRMC``, ``$C``, ``$OSI``, ``$ACK,8``, ``$OMS`` refreshes, the
odd ``$OPOS``) in which only the timestamps change — the observers' caches of lines seen before
answer nearly everything, so it is the best case, not a session.

The check is ``check_log`` (role both, no report rendering) in this process; the backseat role
of a log of 4 MiB or more runs in a second process on a machine with more than one core
(``--one-process``: both here, the one-core figure). Printed: wall time; CPU seconds (user +
system) of each process and per 100,000 lines, with the role each judged; peak resident size of
each (``resource.getrusage`` maxrss; ``--tracemalloc`` also the Python heap peak, at a cost in
speed); then ``helmcheck parse`` of the same file as a process of its own (output discarded),
its wall and CPU, and the ratio judge/parse (wall; and CPU, all processes of the check against
the parse's). Targets: under 10 s wall on two cores, under 15 s in one process, peak RSS under
200 MB, judge/parse at most 1.5; a clean verdict (no FAIL, no INCONCLUSIVE).
"""

from __future__ import annotations

import argparse
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from helmcheck.checklog.checker import check_log  # noqa: E402
from helmcheck.grammar import checksum_hex  # noqa: E402
from helmcheck.profile import DEFAULT  # noqa: E402
from realistic_log import cached_session  # noqa: E402

TARGET_S = 10.0  #: two cores
TARGET_ONE_S = 15.0  #: one process
TARGET_MB = 200.0
TARGET_RATIO = 1.5


def S(body: str) -> str:
    return f"${body}*{checksum_hex(body)}"


def osi(mode: str, act: str) -> str:
    return S(f"OSI,{act},{mode},0,41.52000000,-71.32000000,2.00,157.59,N,38.00,P0,-14.5000,"
             f"conformance.mis,4.5893,97.6,2.00,95.0,False,IVER3-EMU,0.0,False,False")


def generate(path: Path, lines: int) -> int:
    """The best case: a loop of 11 distinct lines, about ``lines`` of them; the number written."""
    gprmc = S("GPRMC,200825.62,A,4131.2000,N,07119.2000,W,2.0,75.5,211126,14.5,W,A")
    comp = S("C90.0P0.00R0.00T20.0D2.00")
    osd = S("OSD,G,C,S")
    oms = S("OMS,180,3,20,2,10")
    opos = S("OPOS,41.52,-71.32,1.0,40.0,12.0")
    a8, a9, a6, a3 = S("ACK,8,0,0"), S("ACK,9,0,0"), S("ACK,6,0,0"), S("ACK,3,0,0")
    osi_a = osi("A", "B0B0A0A0B8")
    n = 0
    t = 0.0
    with open(path, "w", encoding="ascii", buffering=1 << 20) as f:
        w = f.write
        w("# helmcheck wire-log 1\n# benchmark session  baud 115200  time_scale 1\n")
        w(f"{t:.6f} > {S('OMSTART,0,0,0,0,conformance.mis')}\n{t + 0.002:.6f} < {a3}\n")
        n += 2
        k = 0
        while n < lines:
            t += 0.25
            w(f"{t:.6f} > {oms}\n{t + 0.002:.6f} < {a9}\n"
              f"{t + 0.010:.6f} > {osd}\n{t + 0.012:.6f} < {gprmc}\n{t + 0.014:.6f} < {comp}\n"
              f"{t + 0.020:.6f} < {osi_a}\n{t + 0.022:.6f} < {a8}\n")
            n += 7
            k += 1
            if k % 20 == 0:
                w(f"{t + 0.1:.6f} > {opos}\n{t + 0.102:.6f} < {a6}\n")
                n += 2
    return n


def _cpu() -> tuple[float, float]:
    """CPU seconds (user + system) of this process and of its finished children."""
    me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return me.ru_utime + me.ru_stime, kids.ru_utime + kids.ru_stime


def parse_time(path: Path) -> tuple[float, float]:
    """``helmcheck parse FILE`` as a process of its own: (wall s, CPU s)."""
    cpu0 = _cpu()[1]
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "helmcheck", "parse", str(path)], stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL, cwd=Path(__file__).resolve().parents[1])
    return time.perf_counter() - t0, _cpu()[1] - cpu0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lines", type=int, default=1_000_000)
    ap.add_argument("--seed", type=int, default=0, help="the realistic session's seed")
    ap.add_argument("--best-case", action="store_true", help="the repeated-line log, not a realistic one")
    ap.add_argument("--keep", metavar="FILE", help="best case: write the log here and keep it")
    ap.add_argument("--tracemalloc", action="store_true", help="also measure the Python heap peak")
    ap.add_argument("--one-process", action="store_true", help="judge both roles in this process")
    ap.add_argument("--no-parse", action="store_true", help="skip the helmcheck parse comparison")
    ap.add_argument("--log", metavar="FILE", type=Path, help="check this log instead (e.g. a session "
                    "realistic_log.py wrote, to compare two versions of the code on the same bytes)")
    args = ap.parse_args(argv)
    tmpdir = None
    t0 = time.perf_counter()
    if args.log is not None:
        path, made, kind = args.log, "given", "given log"
    elif args.best_case:
        if args.keep:
            path = Path(args.keep)
        else:
            tmpdir = tempfile.TemporaryDirectory(prefix="helmcheck-bench-")
            path = Path(tmpdir.name) / "bench.log"
        generate(path, args.lines)
        made = "generated"
        kind = "best case: 11 distinct lines repeated"
    else:
        path, fresh = cached_session(args.lines, args.seed)
        made = "generated" if fresh else "cached"
        kind = f"realistic session, seed {args.seed}"
    gen_s = time.perf_counter() - t0
    with open(path, "rb") as f:
        n = sum(1 for _ in f)
    size_mb = path.stat().st_size / 1e6
    if args.tracemalloc:
        import tracemalloc
        tracemalloc.start()
    cpu0 = _cpu()
    t0 = time.perf_counter()
    out = check_log(path, profile=DEFAULT, role="both", parallel=False if args.one_process else None)
    check_s = time.perf_counter() - t0
    cpu_self, cpu_child = (a - b for a, b in zip(_cpu(), cpu0))
    heap = None
    if args.tracemalloc:
        import tracemalloc
        heap = tracemalloc.get_traced_memory()[1] / 1e6
        tracemalloc.stop()
    rss_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    child_mb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024.0
    two = cpu_child > 0
    per = 1e5 / n
    bad = {c["id"]: c["verdict"] for c in out.clauses if c["verdict"] in ("fail", "inconclusive")}
    print(f"log: {n} lines, {size_mb:.1f} MB ({kind}), {made} in {gen_s:.1f} s")
    print(f"check-log: {check_s:.2f} s wall ({n / check_s:,.0f} lines/s), "
          + ("two processes" if two else "one process")
          + f"; peak RSS {rss_mb:.0f} MB" + (f", second process {child_mb:.0f} MB" if two else "")
          + (f", Python heap peak {heap:.1f} MB" if heap is not None else ""))
    if two:
        print(f"CPU: {cpu_self:.2f} s in this process (reading, vehicle role, results; "
              f"{cpu_self * per:.2f} s per 100k lines) + {cpu_child:.2f} s in the second "
              f"(backseat role; {cpu_child * per:.2f} s per 100k lines) = {cpu_self + cpu_child:.2f} s")
    else:
        print(f"CPU: {cpu_self:.2f} s, both roles in this process ({cpu_self * per:.2f} s per 100k lines)")
    print(f"verdicts not pass: "
          f"{ {c['id']: c['verdict'] for c in out.clauses if c['verdict'] not in ('pass', 'not-tested')} or 'none'}"
          f"; records {out.stats['records']}")
    ratio = None
    if not args.no_parse:
        pw, pc = parse_time(path)
        ratio = check_s / pw
        print(f"helmcheck parse (a process, output discarded): {pw:.2f} s wall, {pc:.2f} s CPU "
              f"({pc * per:.2f} s per 100k lines); judge/parse {ratio:.2f} wall, "
              f"{(cpu_self + cpu_child) / pc:.2f} CPU")
    limit = TARGET_S if two else TARGET_ONE_S
    # tracemalloc slows every allocation several times over: then only memory is held to target
    ok = ((args.tracemalloc or check_s < limit) and max(rss_mb, child_mb) < TARGET_MB and not bad
          and (ratio is None or ratio <= TARGET_RATIO))
    print(f"targets: < {limit:g} s ({'two processes' if two else 'one process'}), < {TARGET_MB:g} MB, "
          f"judge/parse <= {TARGET_RATIO:g}, no FAIL or INCONCLUSIVE: {'met' if ok else 'NOT met'}")
    if tmpdir is not None:
        tmpdir.cleanup()
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
