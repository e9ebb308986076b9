"""``helmcheck check-log`` on a 1,000,000-line two-direction wire log: time and peak memory.

Run standalone: ``python benchmarks/check_log_bench.py [--lines N] [--keep FILE] [--tracemalloc]``.
The log is what a busy, conforming session looks like: a mission started, then a loop of
``$OSD,G,C,S`` polls (answered ``$GPRMC``, ``$C``, ``$OSI``, ``$ACK,8``) and ``$OMS`` servo
refreshes (``$ACK,9``) every 0.25 s, with the odd ``$OPOS``. It is written line by line (never held
in memory), then checked (role both, no report rendering). Targets: under 15 s and a peak
resident size under 200 MB (``resource.getrusage`` maxrss of this process and of the second
process that judges the backseat role of a long log; ``--tracemalloc`` also reports the Python
heap peak, at some cost in speed). The CPU seconds of both processes are printed too: on one core
the check takes about their sum (``--one-process`` measures that directly).
"""

from __future__ import annotations

import argparse
import resource
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from helmcheck.checklog.checker import check_log  # noqa: E402
from helmcheck.grammar import checksum_hex  # noqa: E402
from helmcheck.profile import DEFAULT  # noqa: E402

TARGET_S = 15.0
TARGET_MB = 200.0


def S(body: str) -> str:
    return f"${body}*{checksum_hex(body)}"


def osi(mode: str, act: str) -> str:
    return S(f"OSI,{act},{mode},0,41.52000000,-71.32000000,2.00,157.59,N,38.00,P0,-14.5000,"
             f"conformance.mis,4.5893,97.6,2.00,95.0,False,IVER3-EMU,0.0,False,False")


def generate(path: Path, lines: int) -> int:
    """Write a conforming session of about ``lines`` lines; returns the number written."""
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


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lines", type=int, default=1_000_000)
    ap.add_argument("--keep", metavar="FILE", help="write the log here and keep it")
    ap.add_argument("--tracemalloc", action="store_true", help="also measure the Python heap peak")
    ap.add_argument("--one-process", action="store_true", help="judge both roles in this process")
    args = ap.parse_args(argv)
    tmpdir = None
    if args.keep:
        path = Path(args.keep)
    else:
        tmpdir = tempfile.TemporaryDirectory(prefix="helmcheck-bench-")
        path = Path(tmpdir.name) / "bench.log"
    t0 = time.perf_counter()
    n = generate(path, args.lines)
    gen_s = time.perf_counter() - t0
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
    bad = {c["id"]: c["verdict"] for c in out.clauses if c["verdict"] not in ("pass", "not-tested")}
    print(f"log: {n} lines, {size_mb:.1f} MB, generated in {gen_s:.1f} s")
    print(f"check-log: {check_s:.2f} s ({n / check_s:,.0f} lines/s), peak RSS {rss_mb:.0f} MB"
          + (f" (second process {child_mb:.0f} MB)" if cpu_child else "")
          + (f", Python heap peak {heap:.1f} MB" if heap is not None else ""))
    print(f"CPU: {cpu_self:.2f} s in this process"
          + (f" + {cpu_child:.2f} s in the second process (backseat role)" if cpu_child else " (one process)"))
    print(f"verdicts not pass: {bad or 'none'}; records {out.stats['records']}")
    # tracemalloc slows every allocation several times over: then only memory is held to target
    ok = (args.tracemalloc or check_s < TARGET_S) and max(rss_mb, child_mb) < TARGET_MB and not bad
    print(f"targets: < {TARGET_S:g} s, < {TARGET_MB:g} MB, a clean verdict: {'met' if ok else 'NOT met'}")
    if tmpdir is not None:
        tmpdir.cleanup()
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
