"""Throughput of ``VehicleModel.receive`` over a realistic mixed command stream.

Run standalone: ``python benchmarks/model_bench.py [--seconds N]``. The stream is what a busy
backseat sends during a mission: mostly ``$OSD`` polls (state, compass, GPS), ``$OMS`` servo
refreshes, ``$OPOS``/``$ODVL`` updates, ``$OLOGD`` rows, the odd ``$OMW``/``$OMW,Clr``, ``$OJW``,
``$OMP``, rejected commands and malformed ones, with time moving 20 ms per command so that
timeouts fire. The target is at least 50 000 ``receive`` calls per second.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from helmcheck.grammar.errors import SentenceError  # noqa: E402
from helmcheck.model import testing as t  # noqa: E402
from helmcheck.model.plant import WaypointReached  # noqa: E402
from helmcheck.model.vehicle import VehicleModel  # noqa: E402

TARGET = 50_000


def stream() -> list:
    bad_oms = SentenceError("RH-SRV-2", "heading out of range", None, "range", "OMS", "heading", 9, 20)
    cycle = [
        t.osd("G", "C", "S", "P", "", "", "", ""), t.oms(90, 2, 20, 2, 5), t.opos(cond=40, temp=12),
        t.osd("S"), t.oms(95, 2, 20, 2, 5), t.ologd("1.0", "2.0"), t.osd("S", "C"),
        t.odvl(0.5, 0.1, 5), t.oms(100, 3, 20, 2, 5), t.osd("S"), t.omw(), t.omw(park_s=5),
        t.osd("S", "G"), t.omw_clear("CLEAR"), t.ojw(2), t.osd("S"), t.omp("8080808090", timeout=3),
        t.osd("S", "P"), t.ologl("x"), bad_oms, t.opk(), t.osd("S"),
        t.omw_clear("Clr"), t.osd("S", "D", "T"), t.orwset("Sop"),
    ]
    return cycle


def run(seconds: float) -> float:
    model = VehicleModel(missions=t.catalog())
    model.receive(t.ologl("a", "b"), 0.0)
    model.receive(t.omstart(), 0.0)
    cmds = stream()
    now = 0.0
    calls = 0
    start = time.perf_counter()
    deadline = start + seconds
    receive = model.receive
    while True:
        for c in cmds:
            now += 0.02
            receive(c, now)
        calls += len(cmds)
        if model.mission is None:
            model.receive(t.omstart(), now)
        elif calls % 2500 == 0:
            model.plant(WaypointReached(), now)
            model.advance(now)
        if time.perf_counter() >= deadline:
            break
    elapsed = time.perf_counter() - start
    return calls / elapsed


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=2.0)
    args = ap.parse_args(argv)
    rate = run(args.seconds)
    verdict = "meets" if rate >= TARGET else "BELOW"
    print(f"VehicleModel.receive: {rate:,.0f} calls/s over a mixed command stream "
          f"({verdict} the {TARGET:,}/s target)")
    return 0 if rate >= TARGET else 1


if __name__ == "__main__":
    raise SystemExit(main())
