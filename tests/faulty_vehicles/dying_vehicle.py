#!/usr/bin/env python3
"""A conforming vehicle (the reference emulator's core) that gives up after a while.

Usage: ``dying_vehicle.py PORT [--after S] [--time-scale K]``. It opens PORT (a pty path or a
device, 8N1 at 115200 baud, or ``socket://HOST:PORT`` to listen on), serves the protocol, and
``S`` seconds after opening it says so on standard error and exits with code 5 at once — a
vehicle simulator that crashes in the middle of a certification (``certify vehicle --exec``).
"""

from __future__ import annotations

import argparse
import os
import sys
import threading
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from helmcheck.emulator.server import Server  # noqa: E402
from helmcheck.line.transport import open_link  # noqa: E402
from tests.faulty_vehicles import make_core  # noqa: E402


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("port")
    p.add_argument("--after", type=float, default=2.0)
    p.add_argument("--time-scale", type=float, default=25.0)
    args = p.parse_args()
    link = open_link(args.port, role="server", baud=115200)
    server = Server(link, make_core(None, args.time_scale, time.monotonic()), install_signals=False)
    threading.Thread(target=server.run, daemon=True).start()
    print(f"dying_vehicle: serving {link.name}", flush=True)
    time.sleep(args.after)
    print(f"dying_vehicle: giving up after {args.after:g} s", file=sys.stderr, flush=True)
    os._exit(5)


if __name__ == "__main__":
    sys.exit(main())
