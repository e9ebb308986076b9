"""Emulator benchmark: ACK round-trip latency over a real pty, and the highest sustained rate,
unpaced and at the baud of a real line.

Starts ``python -m helmcheck emulate --port pty --baud B``, opens the pty like a backseat would
and sends commands on a fixed schedule from one thread, reading in the same select loop; ACKs
are matched to commands in order (RH-ACK-6). Every figure says at which baud it was measured.

*Unpaced* (``--baud 0``): what the emulator's core can do, not what a line carries —

1. latency at ``--rate`` commands/s (default 1000) for ``--seconds``: median, p99, max, lost;
2. the highest rate (doubling from 1000, then bisecting) at which every command got its ACK
   within the ACK window (1 s, RH-ACK-2).

*Paced* at each of ``--bauds`` (default 19200 and 115200): the emulator writes its replies at
the line's rate (8N1, ten bits a byte, RH-FRM-9); the commands reach it over the pty unpaced, so
the measured rate is bounded by the vehicle-to-backseat direction, as on a real line where the
replies are the longer direction —

3. latency at ``--paced-rate`` commands/s (default 10, a backseat polling and steering at
   10 Hz) for ``--paced-seconds``: p50, p99, max, lost;
4. what the line can carry in theory: the bytes each command puts on the line each way (counted
   during run 3) times the byte time, and the command rate that fills the busier direction;
5. the highest rate (doubling from a quarter of that, then bisecting to 5 %) with no lost or
   late ACK and no backlog building up (the median round trip of the run's last fifth no more
   than ``max(50 ms, three command periods)`` above its first fifth's).

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
from helmcheck.grammar.wirelog import transmit_time  # noqa: E402

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
    got = 0  # bytes from the emulator
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
        chunk = os.read(fd, 65536)
        got += len(chunk)
        buf += chunk
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
    fifth = max(1, len(lat) // 5)
    growth = (statistics.median(lat[-fifth:]) - statistics.median(lat[:fifth])) if lat else 0.0
    lat.sort()

    def pct(p: float) -> float:
        return lat[min(len(lat) - 1, int(p * len(lat)))] if lat else float("nan")

    return {"rate": rate, "sent": sent_count, "acked": len(lat), "lost": lost, "late": late,
            "median_ms": statistics.median(lat) * 1e3 if lat else float("nan"),
            "p99_ms": pct(0.99) * 1e3, "max_ms": (lat[-1] * 1e3) if lat else float("nan"),
            "achieved": sent_count / max(seconds, 1e-9), "bytes_in": got,
            "bytes_out": sum(len(MIX[k % len(MIX)][0]) for k in range(sent_count)), "growth_s": growth}


def drain(fd: int, quiet: float = 0.2) -> None:
    while select.select([fd], [], [], quiet)[0]:
        os.read(fd, 65536)


def _open(emu: EmulatorProcess) -> int:
    import termios
    import tty

    fd = os.open(emu.port, os.O_RDWR | os.O_NOCTTY)
    tty.setraw(fd, termios.TCSANOW)
    return fd


def unpaced(args) -> None:
    print("unpaced (--baud 0): what the emulator's core can do, not what a line carries")
    with EmulatorProcess(time_scale=1, baud=0) as emu:
        fd = _open(emu)
        try:
            drain(fd)
            run_rate(fd, 200, 0.5)  # warm-up
            drain(fd)
            r = run_rate(fd, args.rate, args.seconds)
            print(f"  pty {emu.port}, baud 0 (unpaced)")
            print(f"  latency at {r['rate']:.0f} commands/s, unpaced ({r['sent']} sent, {r['acked']} ACKs, "
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
                print(f"  {rate:8.0f}/s, unpaced: sent {res['sent']}, lost {res['lost']}, late {res['late']}, "
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
                    print(f"  {mid:8.0f}/s, unpaced: lost {res['lost']}, late {res['late']}, "
                          f"p99 {res['p99_ms']:.2f} ms -> {'ok' if ok else 'fail'}")
                    lo, hi = (mid, hi) if ok else (lo, mid)
                good = lo
            print(f"  highest sustained rate without a lost or late ACK, unpaced: {good:.0f} commands/s"
                  if good else "  even 1000 commands/s lost ACKs, unpaced")
            if fast:
                print(f"  highest tried rate with p99 < 5 ms, unpaced: {fast:.0f} commands/s")
        finally:
            os.close(fd)


def _sustained(res: dict, rate: float) -> bool:
    return (res["lost"] == 0 and res["late"] == 0 and res["achieved"] >= 0.95 * rate
            and res["growth_s"] <= max(0.05, 3.0 / rate))


def paced(baud: int, args) -> None:
    byte_ms = transmit_time(1, baud) * 1e3
    print(f"paced at {baud} baud (8N1, byte time {byte_ms:.3f} ms; the emulator's replies paced, "
          f"the commands unpaced over the pty)")
    with EmulatorProcess(time_scale=1, baud=baud) as emu:
        fd = _open(emu)
        try:
            drain(fd)
            run_rate(fd, 5, 1.0)  # warm-up
            drain(fd, 0.5)
            r = run_rate(fd, args.paced_rate, args.paced_seconds)
            drain(fd, 0.5)
            print(f"  latency at {r['rate']:.0f} commands/s, {baud} baud ({r['sent']} sent, {r['acked']} ACKs, "
                  f"{r['lost']} lost, {r['late']} late): p50 {r['median_ms']:.1f} ms, p99 {r['p99_ms']:.1f} ms, "
                  f"max {r['max_ms']:.1f} ms")
            per_in = r["bytes_in"] / max(r["sent"], 1)  # vehicle -> backseat, per command
            per_out = r["bytes_out"] / max(r["sent"], 1)  # backseat -> vehicle
            busier = max(per_in, per_out)
            theory = 1.0 / transmit_time(busier, baud)
            print(f"  the line at {baud} baud: {per_in:.1f} bytes a command from the vehicle "
                  f"({transmit_time(per_in, baud) * 1e3:.1f} ms), {per_out:.1f} to it "
                  f"({transmit_time(per_out, baud) * 1e3:.1f} ms); in theory at most {theory:.1f} commands/s")
            rate = max(1.0, theory / 4)
            good = bad = None
            while rate <= theory * 4:
                res = run_rate(fd, rate, args.search_seconds)
                drain(fd, 0.5)
                ok = _sustained(res, rate)
                print(f"  {rate:7.1f}/s, {baud} baud: sent {res['sent']}, lost {res['lost']}, late {res['late']}, "
                      f"p50 {res['median_ms']:.1f} ms, p99 {res['p99_ms']:.1f} ms, "
                      f"backlog growth {res['growth_s'] * 1e3:.0f} ms -> {'ok' if ok else 'fail'}")
                if not ok:
                    bad = rate
                    break
                good = rate
                rate *= 2
            if good is not None and bad is not None:
                lo, hi = good, bad
                while hi - lo > lo * 0.05:
                    mid = (lo + hi) / 2
                    res = run_rate(fd, mid, args.search_seconds)
                    drain(fd, 0.5)
                    ok = _sustained(res, mid)
                    print(f"  {mid:7.1f}/s, {baud} baud: lost {res['lost']}, late {res['late']}, "
                          f"p99 {res['p99_ms']:.1f} ms, backlog growth {res['growth_s'] * 1e3:.0f} ms"
                          f" -> {'ok' if ok else 'fail'}")
                    lo, hi = (mid, hi) if ok else (lo, mid)
                good = lo
            if good is None:
                print(f"  even {max(1.0, theory / 4):.1f} commands/s lost or delayed ACKs at {baud} baud")
            else:
                print(f"  highest sustained rate at {baud} baud (no lost or late ACK, no backlog building up): "
                      f"{good:.1f} commands/s "
                      f"({good / theory:.0%} of the {theory:.1f} the line carries in theory)")
        finally:
            os.close(fd)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rate", type=float, default=1000.0, help="commands per second for the unpaced latency run")
    ap.add_argument("--seconds", type=float, default=3.0, help="duration of each unpaced run")
    ap.add_argument("--max-rate", type=float, default=64000.0, help="stop the unpaced search here")
    ap.add_argument("--bauds", default="19200,115200", help="paced runs at these bauds ('' for none)")
    ap.add_argument("--paced-rate", type=float, default=10.0, help="commands per second for the paced latency runs")
    ap.add_argument("--paced-seconds", type=float, default=20.0, help="duration of each paced latency run")
    ap.add_argument("--search-seconds", type=float, default=5.0, help="duration of each paced rate-search run")
    ap.add_argument("--no-unpaced", action="store_true", help="skip the unpaced figures")
    args = ap.parse_args()
    if not args.no_unpaced:
        unpaced(args)
    for baud in (int(b) for b in args.bauds.split(",") if b.strip()):
        paced(baud, args)
    return 0


if __name__ == "__main__":
    sys.exit(main())
