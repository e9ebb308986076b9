#!/usr/bin/env python3
"""The example backseat (``backseat.py``) with one defect: its ``$OMS`` timeout is in milliseconds.

A mistake that is easy to make where the rest of a code base counts in milliseconds: the
timeout field of ``$OMS`` is whole seconds, 1 to 120 (RH-SRV-2), and this backseat sends 3000
for three seconds. A conforming vehicle refuses every such ``$OMS`` (``$ACK,9,1,20``), so the
backseat never gets servo control; ``helmcheck certify backseat`` fails it on RH-BS-2 ("every
field is within the ranges of §4–6"), with the offending lines as evidence:

    helmcheck certify backseat --time-scale 10 \\
        --exec 'python3 examples/faulty_backseat.py --port {port} --time-scale {time_scale}'

Everything else is the example backseat's: the same options, the same loop.
"""

from __future__ import annotations

import sys

from backseat import Backseat, main


class MillisecondTimeout(Backseat):
    def servo(self, heading: float) -> None:
        timeout_ms = round(self.timeout / self.k * 1000)  # the defect: RH-SRV-2 wants vehicle seconds
        self.send(f"OMS,{heading:.1f},2.0,20.0,1.0,{timeout_ms}")


if __name__ == "__main__":
    sys.exit(main(backseat=MillisecondTimeout))
