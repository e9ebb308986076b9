"""Both vehicles at once: one callable run on side A and side B, each in its own thread.

The two sides of a diff must see each step at the same vehicle time, so a step is never done on
A and then on B: :meth:`Pair.both` hands it to two worker threads (one per side, always the same
one) and waits for both. Each side's session, link and judge are only ever touched by its own
worker while a step runs, and by the caller between steps. If either side raised, the first
exception is raised again once both have finished (a side is never left mid-step).
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from typing import Callable, TypeVar

from .side import Side

__all__ = ["Pair"]

T = TypeVar("T")


class Pair:
    """Sides A and B, and a worker thread for each (module docstring)."""

    def __init__(self, a: Side, b: Side):
        self.a, self.b = a, b
        self._pools = {a.name: ThreadPoolExecutor(1, thread_name_prefix=f"diff-{a.name}"),
                       b.name: ThreadPoolExecutor(1, thread_name_prefix=f"diff-{b.name}")}

    @property
    def sides(self) -> tuple[Side, Side]:
        return self.a, self.b

    def both(self, fn: Callable[[Side], T]) -> tuple[T, T]:
        """``fn(A)`` and ``fn(B)`` at once; both results, or the first exception."""
        futures = [self._pools[s.name].submit(fn, s) for s in self.sides]
        out, errors = [], []
        for f in futures:
            try:
                out.append(f.result())
            except BaseException as e:  # noqa: BLE001 - raised again below, after both have ended
                out.append(None)
                errors.append(e)
        if errors:
            raise errors[0]
        return out[0], out[1]

    def close(self) -> None:
        for pool in self._pools.values():
            pool.shutdown(wait=True)
