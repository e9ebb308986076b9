"""The port's error counters around each case of a vehicle certification.

A real serial port's UART counts what went wrong on the line it receives — frames without a stop
bit, parity errors, bytes it or its driver lost (:mod:`helmcheck.line.counters`, ``TIOCGICOUNT``).
:class:`CaseCounters` reads them when a case starts and when it ends. A jump in the error counts
means the line or the host lost or garbled bytes during the case, which no judge can see in the
bytes that did arrive: every clause of the case is marked INCONCLUSIVE by a tester note naming the
counts (``inconclusive RH-X: V-12: the port's error counters rose during the case: …``), so an
offline check of the wire log reaches the same verdict. Each case's ``results.json`` entry gets
``line_counters``: the readings and the rise, or ``"available": false`` with the reason (a pty, a
socket, a pyserial URL have no UART to ask).
"""

from __future__ import annotations

from typing import Optional

from ...judge.wire import tester_note
from ...line.counters import ERROR_FIELDS, read_counters

__all__ = ["CaseCounters", "counters_entry"]


def counters_entry(before, after) -> dict:
    """A case's ``line_counters`` entry from the readings at its start and its end."""
    if not before.available:
        return before.as_dict()
    if not after.available:
        return after.as_dict()
    rise = after.since(before)
    errors = {f: getattr(rise, f) for f in ERROR_FIELDS if getattr(rise, f)}
    return {"available": True, "start": before._asdict(), "end": after._asdict(), "errors": errors,
            "rx": rise.rx, "tx": rise.tx}


class CaseCounters:
    """Reads the port's counters around one case and says what a rise means (module docstring)."""

    def __init__(self, link):
        self.link = link  #: the run's :class:`~.link.TesterLink`
        self.before = None

    def _read(self):
        return read_counters(self.link.link)

    def start(self) -> None:
        self.before = self._read()

    def end(self, case_id: str, clauses) -> Optional[dict]:
        """The case's entry; a rise in the error counts is noted INCONCLUSIVE on ``clauses``."""
        if self.before is None:
            return None
        entry = counters_entry(self.before, self._read())
        self.before = None
        errors = entry.get("errors")
        if errors:
            counts = ", ".join(f"{n} {f.replace('_', ' ')}" for f, n in errors.items())
            self.link.note(tester_note("inconclusive", list(clauses) or ["RH-FRM-9"],
                                       f"{case_id}: the port's error counters rose during the case ({counts}): "
                                       f"the line or the host lost or garbled bytes, so what the case saw may "
                                       f"not be what the vehicle sent"))
        return entry
