"""A long monitored session: memory stays flat (not in ``make test``, nor in ``make bench``).

``python benchmarks/monitor_soak.py [--minutes 120] [--time-scale 20]`` starts the reference
emulator on a pty, ``helmcheck monitor --between pty <emulator>`` in line, and the example
backseat (``tests/backseats/good_backseat.py``) on the monitor's backseat port, all at the time
scale given, for the wall minutes given (default: two hours). Every minute it prints the
monitor's resident set size (``/proc/PID/status`` VmRSS: the relay's process and its helpers,
the live judges among them), the wire log's size and segments, and
at the end the first and last figures and their ratio (acceptance: the last within 10 % of the
first), then the session's verdict line. The log rotates every ``--rotate-mb`` (default 8) so a
session of hours is many segments.
"""

from __future__ import annotations

import argparse
import os
import re
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def rss_kib(pid: int) -> int:
    """Resident KiB of ``pid``; 0 for a process that has ended (gone, or a zombie: an interim
    check that finished between the listing and the reading)."""
    try:
        text = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return 0
    m = re.search(r"VmRSS:\s+(\d+)", text)
    return int(m.group(1)) if m else 0


def children(pid: int) -> list[int]:
    out = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            out.append(int(stat.parent.name))
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--minutes", type=float, default=120.0)
    ap.add_argument("--time-scale", type=float, default=20.0)
    ap.add_argument("--rotate-mb", type=float, default=8.0)
    a = ap.parse_args(argv)
    work = Path(tempfile.mkdtemp(prefix="helmcheck-soak-"))
    k = f"{a.time_scale:g}"
    emu = subprocess.Popen([sys.executable, "-m", "helmcheck", "emulate", "--port", "pty", "--time-scale", k],
                           stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, cwd=ROOT, start_new_session=True)
    port = emu.stdout.readline().decode().split()[-1]  # type: ignore[union-attr]
    mon = subprocess.Popen([sys.executable, "-m", "helmcheck", "monitor", "--between", "pty", port, "--time-scale", k,
                            "--no-tui", "--report-dir", str(work / "session"), "--rotate-mb", f"{a.rotate_mb:g}",
                            "--duration", f"{a.minutes * 60:g}"],
                           stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, cwd=ROOT, start_new_session=True)
    line = mon.stdout.readline().decode()  # type: ignore[union-attr]
    bs_port = line.split()[-1]
    bs = subprocess.Popen([sys.executable, str(ROOT / "tests" / "backseats" / "good_backseat.py"), bs_port,
                           "--time-scale", k], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                          start_new_session=True)
    print(f"monitor soak: {a.minutes:g} min at time scale {k}, session in {work / 'session'}", flush=True)
    samples = []
    t0 = time.monotonic()
    try:
        while mon.poll() is None:
            time.sleep(min(60.0, max(0.1, t0 + 60 * (len(samples) + 1) - time.monotonic())))
            if mon.poll() is not None:
                break
            logs = sorted((work / "session").glob("wire*.log"))
            size = sum(p.stat().st_size for p in logs)
            kids = children(mon.pid)  # the live judges, and an interim check while one runs
            samples.append(rss_kib(mon.pid) + sum(rss_kib(c) for c in kids))
            print(f"minute {len(samples):4d}: monitor RSS {samples[-1] / 1024:7.1f} MiB "
                  f"(relay {rss_kib(mon.pid) / 1024:.1f}, {len(kids)} helper(s)), wire log "
                  f"{size / 1e6:8.2f} MB in {len(logs)} segment(s)", flush=True)
        verdict = mon.stdout.read().decode().strip().splitlines()  # type: ignore[union-attr]
    finally:
        for p in (bs, mon, emu):
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGTERM)
                p.wait(30)
    if samples:
        first, last = samples[0], samples[-1]
        print(f"RSS first {first / 1024:.1f} MiB, last {last / 1024:.1f} MiB, last/first {last / first:.3f} "
              f"({'within' if last <= 1.1 * first else 'NOT within'} 10 %)")
    print("\n".join(verdict[-1:]))
    return 0 if samples and samples[-1] <= 1.1 * samples[0] else 1


if __name__ == "__main__":
    sys.exit(main())
