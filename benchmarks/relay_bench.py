"""How well the line-fault relay keeps a baud rate, and what it costs: ``helmcheck relay`` paced.

``helmcheck relay --between pty VEHICLE --impair baud=N`` runs in its own process between two
ptys; a backlog of bytes is written into each side at once, so each direction's line is busy
from its first byte to its last. At the receiving ends every byte's arrival is compared with
where an exact UART at N baud would have it (one byte time after the other, from the earliest
start the arrivals allow): how late the bytes are (p50, p99, max; and after the first tenth,
once the writers are done: they share this process's interpreter with the readers, whose
timestamps they delay) and the rate over the run (1: the baud's, never more). The far ends run
above the relay's real-time priority where allowed. The relay process's CPU
time (``/proc/PID/stat``) over the wall time is its cost. ``--busy`` adds a process that keeps
one CPU busy, as a loaded bench host would.

    python benchmarks/relay_bench.py [--seconds 2] [--busy]
"""

from __future__ import annotations

import argparse
import os
import select
import statistics
import subprocess
import sys
import termios
import threading
import time
import tty
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from helmcheck.grammar.wirelog import transmit_time  # noqa: E402
from helmcheck.line.faultline import RelayProcess  # noqa: E402
from helmcheck.line.pty_link import PtyLink  # noqa: E402


def _cpu(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _above_the_relay() -> None:
    """The far ends run above the relay's real-time priority where allowed (so that what is
    measured is the relay's timing, not the measuring threads')."""
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(2))
    except (AttributeError, OSError):
        pass


def _pump(write_fd: int, data: bytes) -> None:
    _above_the_relay()
    view = memoryview(data)
    while view:
        select.select([], [write_fd], [], 1.0)
        try:
            view = view[os.write(write_fd, view):]
        except BlockingIOError:
            pass


def _arrivals(read_fd: int, n: int, timeout: float, out: list) -> None:
    _above_the_relay()
    got = 0
    deadline = time.monotonic() + timeout
    while got < n and time.monotonic() < deadline:
        if select.select([read_fd], [], [], 0.5)[0]:
            try:
                data = os.read(read_fd, 65536)
            except BlockingIOError:
                continue
            t = time.monotonic()
            out.extend([t] * len(data))
            got += len(data)


def measure(baud: int, seconds: float) -> dict:
    vehicle = PtyLink(baud)
    n = int(seconds * baud / 10)
    data = bytes(0x20 + i % 90 for i in range(n))
    relay = RelayProcess(vehicle.name, f"baud={baud}").start()
    fd = os.open(relay.port, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
    tty.setraw(fd, termios.TCSANOW)
    try:
        time.sleep(0.3)
        cpu0, wall0 = _cpu(relay.proc.pid), time.monotonic()
        to_v, from_v = [], []
        readers = [threading.Thread(target=_arrivals, args=(vehicle.master, n, seconds * 3 + 5, to_v)),
                   threading.Thread(target=_arrivals, args=(fd, n, seconds * 3 + 5, from_v))]
        for r in readers:
            r.start()
        writers = [threading.Thread(target=_pump, args=(fd, data)),
                   threading.Thread(target=_pump, args=(vehicle.master, data))]
        for w in writers:
            w.start()
        for t in writers + readers:
            t.join()
        cpu = _cpu(relay.proc.pid) - cpu0
        wall = time.monotonic() - wall0
    finally:
        os.close(fd)
        relay.stop()
        vehicle.close()
    bt = transmit_time(1, baud)
    out = {"baud": baud, "bytes": n, "cpu_share": cpu / wall}
    for name, times in (("to vehicle", to_v), ("from vehicle", from_v)):
        # an exact UART's schedule, as early as the arrivals allow: every byte is as late as
        # its arrival is after it (0 for the byte the schedule is pinned to)
        start = min(t - k * bt for k, t in enumerate(times))
        every = [t - (start + k * bt) for k, t in enumerate(times)]
        late = sorted(every)
        steady = sorted(every[len(every) // 10:])  # once the writers are done
        out[name] = {"got": len(times), "rate": (len(times) - 1) * bt / (times[-1] - start),
                     "p50_ms": statistics.median(late) * 1e3, "p99_ms": late[int(0.99 * (len(late) - 1))] * 1e3,
                     "max_ms": late[-1] * 1e3, "steady_p99_ms": steady[int(0.99 * (len(steady) - 1))] * 1e3,
                     "steady_max_ms": steady[-1] * 1e3}
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seconds", type=float, default=2.0)
    ap.add_argument("--busy", action="store_true", help="keep one CPU busy meanwhile")
    args = ap.parse_args()
    busy = subprocess.Popen([sys.executable, "-c", "while True: pass"]) if args.busy else None
    try:
        print(f"helmcheck relay, paced, both directions at once, {args.seconds:g} s of line each"
              f"{', one CPU kept busy' if busy else ''}")
        for baud in (19200, 115200):
            m = measure(baud, args.seconds)
            for d in ("to vehicle", "from vehicle"):
                x = m[d]
                print(f"{baud:>6} baud {d:<12}: {x['got']}/{m['bytes']} bytes, rate {x['rate']:.4f} of the baud's; "
                      f"late p50 {x['p50_ms']:.2f} ms, p99 {x['p99_ms']:.2f} ms, max {x['max_ms']:.2f} ms; "
                      f"after the first tenth p99 {x['steady_p99_ms']:.2f} ms, max {x['steady_max_ms']:.2f} ms")
            print(f"{baud:>6} baud relay CPU: {m['cpu_share'] * 100:.1f} % of one CPU")
    finally:
        if busy is not None:
            busy.kill()
            busy.wait()
    return 0


if __name__ == "__main__":
    sys.exit(main())
