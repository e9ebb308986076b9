"""One backseat line as the vehicle observer classified it, and how it is quoted in reasons.

:class:`Sent` is what :class:`~helmcheck.judge.vehicle.observer.VehicleObserver` keeps per line
it saw go to the vehicle (its kind, its case, the ACK and data that answered it); a live driver
waits on it. The helpers format lines and replies for verdict reasons.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from typing import Optional

from ...grammar import sentences as s
from ...grammar.wirelog import escape
from ..ledger import Evidence
from .lines import Kind

__all__ = ["Sent", "class_of_id", "text_of", "brief", "names"]


@dataclass(slots=True)
class Sent:
    """One backseat line as the observer classified it, and what became of it."""

    seq: int
    t: float  #: wall time of the record holding its last byte
    raw: bytes
    ev: Evidence
    kind: Kind
    case: str = ""
    case_clauses: tuple = ()
    vbytes0: int = 0  #: vehicle bytes seen before it (for the transmit time of the replies)
    state: str = "pending"  #: pending | answered | missing | silent | answered-discard
    ack: Optional[s.ACK] = None
    t_ack: Optional[float] = None
    data: list = field(default_factory=list)  #: (sentence or None, class name, Evidence)
    expected: list = field(default_factory=list)
    osi: Optional[s.OSI] = None
    negative: bool = False  #: a conforming vehicle refuses it: the tester's own negative test
    overtaken: bool = False  #: the ACK of a later command came first
    waited: float = 0.0  #: how long the observer waited before calling its ACK missing
    branched: bool = False  #: a later command was answered first: taken into the mirror unanswered
    late_booked: bool = False  #: RH-ACK-2 booked: no ACK by the give-up deadline
    missing_booked: bool = False  #: RH-ACK-1 booked: no ACK at all
    #: sent before the vehicle had answered anything in this record (the link check's first probe
    #: of a vehicle still starting up): its ACK's delay is not judged (RH-ACK-2)
    first_contact: bool = False
    #: a faulty line may have spoilt what answered it (:mod:`helmcheck.judge.streaks`): what it may
    #: have done, for the tester to make the observation again ("" when nothing was spoilt)
    spoil: str = ""
    spoils: list = field(default_factory=list)  #: (what the line may have done, a relay's note) per run
    holding: bool = False  #: its violations are held, not booked (they go to :attr:`held`)
    held: list = field(default_factory=list)  #: (clause, reason, evidence, case) held
    held_item: object = None  #: the :class:`~helmcheck.judge.streaks.Held` its findings went to
    mark: int = 0  #: the streaks' order when it was sent
    late_text: str = ""  #: why its late ``$ACK`` may be the line's (a stall)
    #: the readings of the profile's open questions its answer showed the vehicle takes
    #: (:mod:`helmcheck.model.readings`; ``key = value``)
    reading: tuple = ()

    @property
    def ident(self) -> tuple:
        """What makes a sending the same observation as another: its bytes, and the form a vehicle
        must still read it in (after a torn line, RH-FRM-7, is not the same as on its own)."""
        return (self.raw, self.kind.variant)

    @property
    def done(self) -> bool:
        return self.state != "pending"

    @property
    def accepted(self) -> bool:
        return self.ack is not None and self.ack.status == 0


def class_of_id(sid: Optional[str]) -> str:
    """The data class an ``$OSD`` letter asks for (``C`` → ``Compass``)."""
    return {"C": "Compass"}.get(sid or "", sid or "?")


def text_of(p: Sent) -> str:
    """A backseat line as evidence text (escaped, at most 80 characters)."""
    return _text(p.raw)


@lru_cache(maxsize=4096)
def _text(raw: bytes) -> str:
    return escape(raw.rstrip(b"\r\n"))[:80]  # sessions repeat their lines: each is escaped once


def brief(replies: list) -> str:
    """Replies as ``$ACK,t,s,e, $OSI`` for a reason."""
    out = []
    for r in replies:
        if isinstance(r, s.ACK):
            out.append(f"$ACK,{r.type},{r.status},{r.err}")
        else:
            out.append("$" + (r if isinstance(r, str) else type(r).__name__))
    return ", ".join(out) or "nothing"


def names(xs: list) -> str:
    """Sentence names as ``$OSI,$Compass``."""
    return ",".join("$" + x for x in xs) or "none"
