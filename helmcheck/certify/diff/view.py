"""What the profile pins of one step, and when two vehicles' views of it differ (sans-IO).

:class:`Seen` is what one vehicle showed in one step of a diff, reduced to what the reference
profile pins: the ``$ACK`` type, status and error code of the line sent (err 26 is the
lockout), and of the ``$OSI`` that ends the step the mode letter, the mission's next waypoint
(field 3), the park countdown (field 10) and the error state (field 8). Nothing else of a
report is compared: number formats, position, attitude, speed, depth, battery, the reserved
fields and the pacing of replies are freedoms a conforming vehicle has (``docs/freedoms.md``).

:func:`differences` lists where two views differ. The park countdown is a timed value: two
countdowns differ only by more than RH-TIM-1's tolerance of the larger one, widened by the
vehicle time between the two reports (since the step began, or twice that since the sequence
began, whichever is more: the countdowns began at each side's own time) and a second of rounding. Whether a difference is a
*divergence* (or a timing race, or a choice the model leaves) is decided by :mod:`.machine`
with each side's own judge; this module only compares.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

from ...model.timers import tolerance

__all__ = ["Seen", "OsiView", "differences", "ack_text", "osi_text", "seen_text"]


@dataclass(frozen=True)
class OsiView:
    """The pinned fields of one ``$OSI``."""

    mode: str
    waypoint: int
    park: int  #: field 10, seconds
    error: str  #: field 8

    @classmethod
    def of(cls, osi) -> "OsiView":
        return cls(osi.mode, int(osi.next_waypoint), int(osi.park_time), osi.error_state)


@dataclass
class Seen:
    """What one side showed in one step (module docstring), and what its judge made of it."""

    line: str = ""  #: the line sent in the step (escaped, no CR LF), or a description (``wait 5 s``)
    ack: Optional[tuple] = None  #: (type, status, err) of the line's ``$ACK``; None: no ACK
    osi: Optional[OsiView] = None  #: the report that ended the step
    v_osi: float = 0.0  #: vehicle seconds from the step's start to that report
    v_seq: float = 0.0  #: vehicle seconds from the sequence's start to that report
    stop: str = ""  #: why the side could not carry the step out (the report then is missing)
    failures: list = field(default_factory=list)  #: (clause, reason) its judge booked in the step
    race: str = ""  #: the line met a model timer within RH-TIM-1's tolerance (which one)
    leeway: str = ""  #: the model allowed more than one state here (why)
    #: (wall deadline, wall tolerance, timer) of model timers whose tolerance spans the report
    pending: list = field(default_factory=list)


def ack_text(ack: Optional[tuple]) -> str:
    return "no $ACK" if ack is None else f"$ACK,{ack[0]},{ack[1]},{ack[2]}"


def osi_text(v: Optional[OsiView]) -> str:
    if v is None:
        return "no $OSI"
    return f"$OSI mode {v.mode}, waypoint {v.waypoint}, P{v.park}, error {v.error}"


def seen_text(s: Seen, ack: bool = True) -> str:
    """One side's view of a step in words (for the result line and ``diff.json``)."""
    if s.stop:
        return f"stopped ({s.stop})"
    parts = [ack_text(s.ack)] if ack else []
    return ", ".join(parts + [osi_text(s.osi)])


def _park_apart(a: Seen, b: Seen) -> bool:
    pa, pb = a.osi.park, b.osi.park
    if (pa == 0) != (pb == 0):
        return True
    # each side's countdown began at its own vehicle time since the sequence began, and the report
    # came at another: two vehicles at different time scales drift apart by the steps' line time
    allowed = tolerance(max(pa, pb)) + max(abs(a.v_osi - b.v_osi), 2 * abs(a.v_seq - b.v_seq)) + 1.0
    return abs(pa - pb) > allowed


def differences(a: Seen, b: Seen, answers: bool = True) -> list[str]:
    """Where two views of the same step differ, in words (empty: they agree).
    ``answers``: compare the ``$ACK`` too (a settled re-poll compares the report only)."""
    if a.stop or b.stop:
        return [] if a.stop and b.stop else [f"A {seen_text(a)}, B {seen_text(b)}"]
    out = []
    if answers and a.ack != b.ack:
        out.append(f"A answered {ack_text(a.ack)}, B {ack_text(b.ack)}")
    if (a.osi is None) != (b.osi is None):
        out.append(f"A reported {osi_text(a.osi)}, B {osi_text(b.osi)}")
    elif a.osi is not None and b.osi is not None:
        va, vb = a.osi, b.osi
        what = [name for name, x, y in (("mode", va.mode, vb.mode), ("waypoint", va.waypoint, vb.waypoint),
                                        ("error", va.error, vb.error)) if x != y]
        if _park_apart(a, b):
            what.append("park time")
        if what:
            out.append(f"{' and '.join(what)}: A {osi_text(va)}, B {osi_text(vb)}")
    return out
