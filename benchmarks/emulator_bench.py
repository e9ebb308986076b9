"""Emulator benchmark: ACK round-trip latency over a real pty, and the highest sustained rate.

Starts ``python -m helmcheck emulate --port pty`` (unpaced unless ``--baud``), opens the pty
like a backseat would and sends commands on a fixed schedule from one thread, reading in the
same select loop; ACKs are matched to commands in order (RH-ACK-6). Figures printed:

1. latency at ``--rate`` commands/s (default 1000) for ``--seconds``: median, p99, max, lost;
2. the highest rate (doubling from 1000, then bisecting) at which every command got its ACK
   within the ACK window (1 s, RH-ACK-2) with no backlog building up.

The command mix: ``$OSD,S`` (an ``$OSI`` then the ACK), ``$OSD,C``, ``$OPOS`` and
``$ORWSET,Sle,R``. Run: ``.venv/bin/python benchmarks/emulator_bench.py``.
"""

from __future__ import annotations

import argparse
import os
import select
import statistics
import sys
import time
from collections import deque
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from helmcheck.emulator.process import EmulatorProcess, frame  # noqa: E402

MIX = [(frame("OSD,S"), b"$ACK,8,"), (frame("OPOS,41.52,-71.32,1.5,42,15"), b"$ACK,6,"),
       (frame("OSD,C"), b"$ACK,8,"), (frame("ORWSET,Sle,R"), b"$ACK,12,")]


def run_rate(fd: int, rate: float, seconds: float, window: float = 1.0) -> dict:
    """Send at ``rate`` for ``seconds``; match ACKs; returns latencies (s) and counts."""
    n = int(rate * seconds)
    period = 1.0 / rate
    sent: deque = deque()  # (send time, ack prefix)
    lat: list[float] = []
    buf = b""
    i = 0
    late = 0
    dropped = 0
    t0 = time.perf_counter()
    deadline = t0 + seconds + window + 0.5
    while (i < n or sent) and time.perf_counter() < deadline:
        now = time.perf_counter()
        due = t0 + i * period
        while i < n and due <= now:  # catch up the schedule if the client was slow
            cmd, ack = MIX[i % len(MIX)]
            os.write(fd, cmd)
            sent.append((time.perf_counter(), ack))
            i += 1
            due = t0 + i * period
        timeout = max(0.0, due - time.perf_counter()) if i < n else 0.05
        r, _, _ = select.select([fd], [], [], timeout)
        if not r:
            continue
        buf += os.read(fd, 65536)
        t = time.perf_counter()
        while b"\n" in buf:
            line, buf = buf.split(b"\n", 1)
            if line.startswith(b"$ACK,"):
                ts, want = sent.popleft()
                while not line.startswith(want) and sent:  # an ACK went missing
                    dropped += 1
                    ts, want = sent.popleft()
                d = t - ts
                lat.append(d)
                if d > window:
                    late += 1
    lost = len(sent) + dropped
    sent_count = i
    lat.sort()

    def pct(p: float) -> float:
        return lat[min(len(lat) - 1, int(p * len(lat)))] if lat else float("nan")

    return {"rate": rate, "sent": sent_count, "acked": len(lat), "lost": lost, "late": late,
            "median_ms": statistics.median(lat) * 1e3 if lat else float("nan"),
            "p99_ms": pct(0.99) * 1e3, "max_ms": (lat[-1] * 1e3) if lat else float("nan"),
            "achieved": sent_count / max(seconds, 1e-9)}


def drain(fd: int, quiet: float = 0.2) -> None:
    while select.select([fd], [], [], quiet)[0]:
        os.read(fd, 65536)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rate", type=float, default=1000.0, help="commands per second for the latency run")
    ap.add_argument("--seconds", type=float, default=3.0, help="duration of each run")
    ap.add_argument("--baud", type=int, default=0, help="emulator output pacing (0 = unpaced)")
    ap.add_argument("--max-rate", type=float, default=64000.0, help="stop the search here")
    args = ap.parse_args()

    with EmulatorProcess(time_scale=1, baud=args.baud) as emu:
        import termios
        import tty

        fd = os.open(emu.port, os.O_RDWR | os.O_NOCTTY)
        tty.setraw(fd, termios.TCSANOW)
        try:
            drain(fd)
            run_rate(fd, 200, 0.5)  # warm-up
            drain(fd)
            r = run_rate(fd, args.rate, args.seconds)
            print(f"pty {emu.port}, baud {args.baud or 'unpaced'}")
            print(f"latency at {r['rate']:.0f} commands/s ({r['sent']} sent, {r['acked']} ACKs, "
                  f"{r['lost']} lost): median {r['median_ms']:.3f} ms, p99 {r['p99_ms']:.3f} ms, "
                  f"max {r['max_ms']:.3f} ms  [target p99 < 5 ms: {'met' if r['p99_ms'] < 5 else 'NOT met'}]")
            drain(fd)
            good, bad = None, None
            fast = None  # highest rate with p99 under 5 ms
            rate = 1000.0
            while rate <= args.max_rate:
                res = run_rate(fd, rate, args.seconds)
                drain(fd, 0.5)
                ok = res["lost"] == 0 and res["late"] == 0 and res["achieved"] >= 0.95 * rate
                print(f"  {rate:8.0f}/s: sent {res['sent']}, lost {res['lost']}, late {res['late']}, "
                      f"median {res['median_ms']:.2f} ms, p99 {res['p99_ms']:.2f} ms -> {'ok' if ok else 'fail'}")
                if not ok:
                    bad = rate
                    break
                good = rate
                if res["p99_ms"] < 5:
                    fast = rate
                rate *= 2
            if good is not None and bad is not None:
                lo, hi = good, bad
                while hi - lo > max(250.0, lo * 0.1):
                    mid = (lo + hi) / 2
                    res = run_rate(fd, mid, args.seconds)
                    drain(fd, 0.5)
                    ok = res["lost"] == 0 and res["late"] == 0 and res["achieved"] >= 0.95 * mid
                    print(f"  {mid:8.0f}/s: lost {res['lost']}, late {res['late']}, p99 {res['p99_ms']:.2f} ms"
                          f" -> {'ok' if ok else 'fail'}")
                    lo, hi = (mid, hi) if ok else (lo, mid)
                good = lo
            print(f"highest sustained rate without a lost or late ACK: {good:.0f} commands/s"
                  if good else "even 1000 commands/s lost ACKs")
            if fast:
                print(f"highest tried rate with p99 < 5 ms: {fast:.0f} commands/s")
        finally:
            os.close(fd)
    return 0


if __name__ == "__main__":
    sys.exit(main())
