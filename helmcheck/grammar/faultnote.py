"""The text of a line-fault note: what an impaired line did, as a wire-log note (``!`` record).

A relay that spoils the line on purpose (:mod:`helmcheck.line.impair`, ``helmcheck relay``)
writes every fault it injects to its wire log as a note, at the time the fault touched the line
and with the direction it touched. This module owns that note's text, its writer
(:func:`fault_note`) and its reader (:func:`read_fault_note`), so that whatever reads a log
later (a judge that must not blame an implementation for what the line did) reads the notes
the relay wrote, by the same rule. The wire-log record itself is :mod:`.wirelog`'s. ::

    12.402113 ! line fault > drop: byte 1834 (0x2c ',')
    12.905220 ! line fault < flip: byte 977 bit 3: 0x41 'A' -> 0x49 'I'
    40.000000 ! line fault <> cut: 5 s from 40 s: nothing passes, what is sent is lost

Format: ``line fault DIR KIND: DETAIL`` — ``DIR`` is :data:`TO_VEHICLE` (``>``),
:data:`FROM_VEHICLE` (``<``) or :data:`BOTH` (``<>``, the line as a whole: a cut); ``KIND`` is
one of :data:`KINDS`; ``DETAIL`` is free text for people on one line (byte numbers count from
0 in that direction's stream as the sender sent it; bytes quoted are escaped as the wire log
escapes them, a space as ``\x20``). Pure text: no clock, no I/O.
"""

from __future__ import annotations

import re
from typing import NamedTuple, Optional

from .wirelog import FROM_VEHICLE, TO_VEHICLE

__all__ = ["PREFIX", "BOTH", "KINDS", "FaultNote", "fault_note", "read_fault_note", "byte_text"]

PREFIX = "line fault"  #: every line-fault note begins with it
BOTH = "<>"  #: the direction of a fault of the whole line (both directions at once)
#: What a note may say the line did: ``timing`` (pacing, delays: once, when the line starts),
#: ``reframe`` (a receiver at another baud: once), ``drop``, ``flip``, ``noise`` (each time),
#: ``stall`` and ``cut`` (when one begins and when it ends).
KINDS = ("timing", "reframe", "drop", "flip", "noise", "stall", "cut")
_DIRS = (BOTH, TO_VEHICLE, FROM_VEHICLE)
_RE = re.compile(r"^line fault (<>|>|<) ([a-z]+): (.*)$")


class FaultNote(NamedTuple):
    """A line-fault note read back: its direction, its kind and the detail."""

    direction: str
    kind: str
    detail: str

    @property
    def text(self) -> str:
        return fault_note(self.direction, self.kind, self.detail)


def fault_note(direction: str, kind: str, detail: str) -> str:
    """The note's text (module docstring). ``ValueError`` for a direction or kind not in the format."""
    if direction not in _DIRS:
        raise ValueError(f"a line fault's direction is one of {_DIRS}, not {direction!r}")
    if kind not in KINDS:
        raise ValueError(f"a line fault's kind is one of {KINDS}, not {kind!r}")
    return f"{PREFIX} {direction} {kind}: {detail.replace(chr(10), ' ').replace(chr(13), ' ')}"


def read_fault_note(text: str) -> Optional[FaultNote]:
    """The :class:`FaultNote` a note's text is, or None when it is not a line-fault note."""
    m = _RE.match(text)
    if m is None or m.group(2) not in KINDS:
        return None
    return FaultNote(m.group(1), m.group(2), m.group(3))


def byte_text(b: int) -> str:
    """A byte for a note: ``0x24 '$'`` (printable ASCII shown), ``0x0d``."""
    return f"0x{b:02x} {chr(b)!r}" if 0x20 <= b < 0x7f and b not in (0x27, 0x5c) else f"0x{b:02x}"
