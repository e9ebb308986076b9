"""Measuring what the line costs, as the run goes: the tester's side of the line budget.

:class:`LineMeter` keeps the reply latency of every command the session exchanged — the time from
the command's last byte to the instant the vehicle answered it (the ACK's arrival less the
transmit time of everything the vehicle sent in reply, RH-RD-15) — the largest ``$OSI`` seen, and
the host's scheduling jitter measured by :func:`host_jitter`. :meth:`LineMeter.budget` turns them
into a :class:`~helmcheck.judge.linebudget.LineBudget` at the run's time scale; the session asks
for it before each case and each exploration sequence, so a vehicle that answers more slowly
later in a run gets longer durations from then on. The link check (:meth:`LineMeter.link_check`)
probes the line a few times before the first case and writes the ``line budget:`` note the judges
read; a later note is written whenever the budget moved enough to change a choice.
"""

from __future__ import annotations

import statistics
import time
from collections import deque
from typing import Optional

from ...grammar.wirelog import transmit_time
from ...judge.linebudget import OSI_BYTES, LineBudget, planning_latency, planning_spread
from ...judge.timing import JITTER_S

__all__ = ["LineMeter", "host_jitter", "LINK_PROBES"]

#: ``$OSD,S`` round trips the link check measures before the first case.
LINK_PROBES = 8
#: Latency samples kept (the newest): enough to see a slow spell, few enough to forget a fast start.
KEPT = 400


def host_jitter(samples: int = 40, step: float = 0.002) -> float:
    """Wall seconds the host oversleeps a short sleep, at the 95th percentile of ``samples``
    (how late a recorder woken by arriving bytes may stamp them)."""
    over = []
    for _ in range(samples):
        t0 = time.monotonic()
        time.sleep(step)
        over.append(max(0.0, time.monotonic() - t0 - step))
    over.sort()
    return over[min(len(over) - 1, int(0.95 * len(over)))]


class LineMeter:
    """See the module docstring."""

    def __init__(self, k: float, baud: int, window_s: float):
        self.k = k
        self.baud = baud
        self.window_s = window_s
        self.latencies: deque[float] = deque(maxlen=KEPT)
        self.osi_bytes = 0
        self.jitter = JITTER_S
        self.measured = False
        self._noted: Optional[LineBudget] = None

    def sample(self, t_sent: float, command_bytes: int, t_ack: float, reply_bytes: int) -> None:
        """One answered command: its reply latency (module docstring)."""
        lat = (t_ack - t_sent) - transmit_time(command_bytes + reply_bytes, self.baud)
        self.latencies.append(max(0.0, lat))

    def saw_osi(self, nbytes: int) -> None:
        self.osi_bytes = max(self.osi_bytes, nbytes)

    def measure_host(self) -> None:
        self.jitter = max(JITTER_S, round(host_jitter() * 1.5 + 0.0005, 4))

    def budget(self) -> LineBudget:
        lats = list(self.latencies)
        p50 = statistics.median(lats) if lats else None
        p99 = sorted(lats)[min(len(lats) - 1, int(0.99 * len(lats)))] if lats else None
        return LineBudget(k=self.k, baud=self.baud, latency_s=planning_latency(lats, self.window_s),
                          spread_s=planning_spread(lats, self.window_s),
                          jitter_s=self.jitter, osi_bytes=self.osi_bytes or OSI_BYTES, latency_p50=p50,
                          latency_p99=p99, samples=len(lats), measured=self.measured)

    def changed(self) -> Optional[LineBudget]:
        """The budget when it moved enough since the last note to change a tester's choice (the
        planning latency up by a fifth and 10 ms, or the jitter up), else ``None``."""
        b = self.budget()
        old = self._noted
        if old is not None and b.latency_s <= old.latency_s * 1.2 + 0.01 and b.jitter_s <= old.jitter_s:
            return None
        self._noted = b
        return b
