"""Parse throughput: helmcheck.grammar on a generated mixed capture, and pynmea2 on $GPRMC.

Run: python benchmarks/parse_bench.py [--lines N] [--rounds R] [--whole-process-only]
(default 1,000,000 lines and 5 rounds). Prints lines per second for the fast path (fully typed
objects, ranges checked), for the Lark reference path on a sample, and for pynmea2 and helmcheck
on the same $GPRMC lines in process; then the whole processes, on two inputs of 200,000 $GPRMC
lines each — *repeated* (the mixed capture's, 24 distinct lines) and *varied* (a moving
receiver's, every line different) — ``helmcheck parse FILE`` against ``python -c`` pynmea2 loops
that read the same file, one printing one line per sentence and one printing what ``helmcheck
parse`` prints (start-up, reading and output included; same interpreter; paired: each round
runs every command once in turn, so load on the machine hits all alike; median of R rounds).
"""

from __future__ import annotations

import argparse
import math
import os
import random
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from helmcheck.grammar import decode, format, parse  # noqa: E402
from helmcheck.grammar import sentences as S  # noqa: E402

D = S.Dec


def mixed_lines(n: int, seed: int = 7) -> list[bytes]:
    """A capture shaped like a busy backseat link: OSD polls and their replies, servo, ACKs."""
    rng = random.Random(seed)
    pool: list[bytes] = []
    for i in range(2000):
        h = D(f"{rng.uniform(0, 359.9):.1f}")
        pool += [
            format(S.OSD(("G", "C", "S", "P", "", "", "", ""))),
            format(S.GPRMC(f"{i % 24:02d}3519", "A", "4807.038", "N", "01131.000", "E", "022.4",
                           "084.4", "230394", "003.1", "W")),
            format(S.Compass(h, D("-3.89"), D("-2.63"), D("20.3"), D("3.2"))),
            format(S.OSI("8080808080", "N", i % 4, D("30.35313633"), D("-89.62795283"), D("3.12"),
                         D("37.97"), "N", D("15.404"), 0, D("-1.5404"), "conformance.mis", D("0.0792"),
                         h, D("0.3"), "66.5", "False", "IVER3-3089", ("3.0", "True", "False"))),
            format(S.OPI(D("66.5"), D("400"), D("-35.2"), D("15.1"), D("-2.3"), D("120"), "D", 0)),
            format(S.ACK(8, 0, 0)),
            format(S.OMS(h, D("10.0"), D("20.0"), D("3.0"), 5)),
            format(S.ACK(9, 0, 0)),
        ]
    return [pool[rng.randrange(len(pool))] for _ in range(n)]


def rate(fn, lines) -> float:
    t = time.perf_counter()
    for line in lines:
        fn(line)
    return len(lines) / (time.perf_counter() - t)


def _nmea(body: str) -> bytes:
    """``$body*HH`` CR LF, the checksum computed here (not by the code under test)."""
    x = 0
    for c in body.encode("ascii"):
        x ^= c
    return f"${body}*{x:02X}\r\n".encode("ascii")


def _ddmm(value: float, deg_digits: int) -> str:
    """``ddmm.mmmm`` / ``dddmm.mmmm`` of a non-negative angle, rounded once (no ``60.0000``)."""
    t = round(value * 600000)  # ten-thousandths of a minute
    deg, frac = divmod(t, 600000)
    return f"{deg:0{deg_digits}d}{frac // 10000:02d}.{frac % 10000:04d}"


def varied_gprmc(n: int, seed: int = 11) -> list[bytes]:
    """``n`` $GPRMC lines as a moving receiver writes them, once a second: every line differs
    (time with hundredths, position, speed, course; the date rolls at midnight)."""
    rng = random.Random(seed)
    t = 13 * 3600 + 35 * 60 + 19
    day, lat, lon, cog, sog = 23, 48.1173, 11.5167, 84.4, 5.0
    out = []
    for _ in range(n):
        t += 1
        if t >= 86400:
            t, day = t - 86400, day % 28 + 1
        cog = (cog + rng.uniform(-3, 3)) % 360
        sog = min(30.0, max(0.1, sog + rng.uniform(-0.3, 0.3)))
        step = sog / 3600 / 60  # degrees of arc in one second at sog knots
        lat += step * math.cos(math.radians(cog))
        lon += step * math.sin(math.radians(cog)) / math.cos(math.radians(lat))
        out.append(_nmea(
            f"GPRMC,{t // 3600:02d}{t // 60 % 60:02d}{t % 60:02d}.{rng.randrange(100):02d},A,"
            f"{_ddmm(abs(lat), 2)},{'N' if lat >= 0 else 'S'},{_ddmm(abs(lon), 3)},{'E' if lon >= 0 else 'W'},"
            f"{sog:.1f},{cog:.1f},{day:02d}0394,003.1,W,A"))
    return out


#: The pynmea2 sides of the whole-process comparison. Both read the file, parse every line with
#: the checksum checked and count the lines. The first prints one line per sentence (its type);
#: the second prints what ``helmcheck parse`` prints: a ``FILE:LINE: error`` line for a line it
#: refuses, nothing for one it accepts, and the count on standard error at the end.
PYNMEA2_LOOP = """
import sys, pynmea2
with open(sys.argv[1]) as f:
    for line in f:
        m = pynmea2.parse(line, check=True)
        print(m.sentence_type)
"""
PYNMEA2_CHECK = """
import sys, pynmea2
name = sys.argv[1]
n = bad = 0
with open(name) as f:
    for n, line in enumerate(f, 1):
        try:
            pynmea2.parse(line, check=True)
        except pynmea2.ParseError as e:
            bad += 1
            print(f"{name}:{n}: {e}")
print(f"{n} lines checked, {bad} invalid", file=sys.stderr)
sys.exit(1 if bad else 0)
"""


def _run(argv: list[str]) -> tuple[float, float]:
    """Wall seconds and CPU seconds (user + system) of one whole process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    subprocess.run(argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, stdin=subprocess.DEVNULL,
                   check=True)
    wall = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def _checked_by_helmcheck(path: str) -> str:
    r = subprocess.run([sys.executable, "-m", "helmcheck", "parse", path], capture_output=True, text=True)
    if r.returncode != 0 or r.stdout:
        raise SystemExit(f"helmcheck parse refused lines of the benchmark input: {r.stdout[:300]}{r.stderr[:300]}")
    return r.stderr.strip()


def whole_process(inputs: dict[str, list[bytes]], rounds: int) -> None:
    """``helmcheck parse FILE`` (and ``--json``) against the pynmea2 loops, as whole processes,
    each input in turn: every round runs every command once, in turn (paired, alternating), and
    each figure is the median over the rounds; a speed is the median of the rounds' ratios
    (pynmea2's time over helmcheck's in the same round; above 1: helmcheck is faster), by wall
    time and by CPU time (user + system, which load on the machine disturbs less)."""
    root = str(Path(__file__).resolve().parent.parent)
    os.environ["PYTHONPATH"] = root + os.pathsep + os.environ.get("PYTHONPATH", "")
    # pip compiles an installed package's modules to bytecode (pynmea2's are); a checkout's are
    # compiled on first import, unless PYTHONDONTWRITEBYTECODE forbids it. Compile them here so
    # both sides start from bytecode, as installed packages do.
    subprocess.run([sys.executable, "-m", "compileall", "-q", os.path.join(root, "helmcheck")],
                   stdout=subprocess.DEVNULL, check=True)
    print(f"whole process ({sys.executable}, Python {sys.version.split()[0]}, both packages' modules "
          f"from bytecode); each command run once a round, in turn, {rounds} rounds; median wall time:")
    print("  helmcheck parse FILE: prints nothing for a valid line, FILE:LINE: CLAUSE: message for an "
          "invalid one, the count on stderr")
    print("  pynmea2 loop: pynmea2.parse(line, check=True), prints the sentence type, one line per sentence")
    print("  pynmea2 check loop: pynmea2.parse(line, check=True), prints what helmcheck parse prints")
    print("  helmcheck parse --json FILE: one JSON object per line (typed fields)")
    for label, lines in inputs.items():
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "gprmc.txt")
            with open(path, "wb") as f:
                f.writelines(lines)
            summary = _checked_by_helmcheck(path)
            cmds = {"helmcheck parse": [sys.executable, "-m", "helmcheck", "parse", path],
                    "pynmea2 loop": [sys.executable, "-c", PYNMEA2_LOOP, path],
                    "pynmea2 check loop": [sys.executable, "-c", PYNMEA2_CHECK, path],
                    "helmcheck parse --json": [sys.executable, "-m", "helmcheck", "parse", "--json", path]}
            runs: dict[str, list[tuple[float, float]]] = {k: [] for k in cmds}
            for _ in range(rounds):
                for name, argv in cmds.items():
                    runs[name].append(_run(argv))
        print(f"{label}: {len(lines):,} lines, {len(set(lines)):,} distinct ({summary})")
        for name, rs in runs.items():
            print(f"  {name:<24} wall {statistics.median(w for w, _ in rs):5.2f} s, "
                  f"CPU {statistics.median(c for _, c in rs):5.2f} s  (wall of each run "
                  + ", ".join(f"{w:.2f}" for w, _ in rs) + ")")
        mine = runs["helmcheck parse"]
        for other in ("pynmea2 loop", "pynmea2 check loop"):
            wall = statistics.median(o[0] / h[0] for o, h in zip(runs[other], mine))
            cpu = statistics.median(o[1] / h[1] for o, h in zip(runs[other], mine))
            print(f"  speed of helmcheck parse against the {other}: {wall:.2f}x by wall time, {cpu:.2f}x by CPU "
                  f"time (median of the {rounds} rounds' ratios, {other}'s over helmcheck's; target at least 1.00x)")


def bar_gprmc(lines: list[bytes]) -> list[bytes]:
    """The bar's 200,000 $GPRMC lines: those of the mixed capture (24 distinct lines repeated)."""
    rmc = [x for x in lines if x.startswith(b"$GPRMC")][:200_000]
    if len(rmc) < 200_000:
        rmc = [x for x in mixed_lines(1_700_000) if x.startswith(b"$GPRMC")][:200_000]
    return rmc


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--lines", type=int, default=1_000_000)
    ap.add_argument("--rounds", type=int, default=5, help="alternating whole-process runs (default 5)")
    ap.add_argument("--whole-process-only", action="store_true", help="skip the in-process figures")
    args = ap.parse_args()
    if args.whole_process_only:
        whole_process({"repeated": bar_gprmc([]), "varied": varied_gprmc(200_000)}, args.rounds)
        return
    lines = mixed_lines(args.lines)
    bad = sum(1 for x in lines[:20000] if not decode(x).valid)
    assert bad == 0, f"{bad} generated lines are invalid"
    print(f"mixed capture: {len(lines):,} lines, {sum(map(len, lines)) / 1e6:.1f} MB")
    r = rate(parse, lines)
    print(f"helmcheck fast path (typed, ranges checked): {r:,.0f} lines/s")
    sample = lines[:20000]
    r_lark = rate(lambda x: decode(x, engine="lark"), sample)
    print(f"helmcheck Lark reference path (sample of {len(sample):,}): {r_lark:,.0f} lines/s")
    rmc = [x for x in lines if x.startswith(b"$GPRMC")][:200_000]
    rmc_text = [x.decode().strip() for x in rmc]
    try:
        import pynmea2
    except ImportError:
        print(f"$GPRMC x{len(rmc):,}: helmcheck {rate(parse, rmc):,.0f} lines/s; pynmea2 not installed")
        return
    # alternate the two, three rounds each, and keep each one's best: load on the machine then
    # hits both alike
    r_h = r_p = 0.0
    for _ in range(3):
        r_h = max(r_h, rate(parse, rmc))
        r_p = max(r_p, rate(lambda x: pynmea2.parse(x, check=True), rmc_text))
    print(f"$GPRMC x{len(rmc):,} (best of 3 alternating rounds): helmcheck {r_h:,.0f} lines/s "
          f"(typed, ranges checked); pynmea2 parse(check=True) {r_p:,.0f} lines/s; ratio {r_h / r_p:.2f}")
    whole_process({"repeated": bar_gprmc(lines), "varied": varied_gprmc(200_000)}, args.rounds)


if __name__ == "__main__":
    main()
