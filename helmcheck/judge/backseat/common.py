"""What every backseat rule shares: the observer's settings, one sent line, the verdict of a measured gap.

* :class:`Settings` — the profile values and observer facts every rule reads (time scale,
  baud, timestamp resolution, ``reaction_s``, ``lockout_s``) and the scenario in progress
  (findings carry it as their case).
* :class:`SentLine` — one complete framing event from the backseat (a line, or a discarded run
  of noise, a torn or an overlong line) with the time its *first* byte was seen (the record
  that held it) and that record's wire-log line number: every behaviour rule times a command
  by its first byte.
* :func:`spacing` / :func:`gap` — the one way a measured wall-time interval is judged against a
  limit when timestamps have a finite resolution ``r``: the true interval is within ``r`` of the
  measured one, so only a certain violation is a violation, a possible one is INCONCLUSIVE
  (RH-TIM-1's last sentence), and the rest meets the limit. Live, ``r`` is 1 µs (the wire log's
  step); offline it is the step the log's timestamps show, so a log read back gives the live
  verdict.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Optional

from ...grammar import Decoded, Discard
from ...grammar import sentences as s
from ...grammar.wirelog import TO_VEHICLE, TO_VEHICLE_RUN, escape, is_line
from ...model.vehicle import VehicleModel
from ...profile import Profile
from ..ledger import Evidence

__all__ = ["Settings", "SentLine", "spacing", "gap", "PASS", "INCONCLUSIVE", "VIOLATION", "BS_CLAUSES"]

BS_CLAUSES = tuple(f"RH-BS-{i}" for i in range(1, 9))
PASS, INCONCLUSIVE, VIOLATION = "pass", "inconclusive", "violation"
_ID = re.compile(rb"\$([A-Z]+)[,*]")
_UNSET = object()


@dataclass
class Settings:
    """What the rules read; ``case`` is the scenario in progress (``scenario X starts``)."""

    profile: Profile
    time_scale: float
    baud: int
    resolution: float
    reaction_s: float
    lockout_s: float
    case: str = ""
    clean: bool = False  #: the record states a link that cannot damage bytes (``line model: clean``)


@dataclass(slots=True)
class SentLine:
    """One complete framing event from the backseat (see the module docstring)."""

    raw: bytes
    t: float  #: when its first byte was seen (the record holding it)
    lineno: int  #: that record's wire-log line (0 when not known)
    decoded: Optional[Decoded] = None  #: ``None`` for a discarded run
    discard: Optional[Discard] = None
    ack_type: Optional[int] = None  #: the ``$ACK`` type a vehicle answers it with, if any
    deferred: Optional[list] = None  #: RH-BS-3 checks waiting for this line's ``$ACK``
    _event: object = _UNSET

    @property
    def command(self) -> Optional[s.Command]:
        d = self.decoded
        return d.sentence if d is not None and isinstance(d.sentence, s.Command) else None

    @property
    def event(self) -> Optional[str]:
        """The transition-table event of the command (``None`` for anything else)."""
        if self._event is _UNSET:
            cmd = self.command
            self._event = VehicleModel.event_of(cmd) if cmd is not None else None
        return self._event

    @property
    def sid(self) -> str:
        """The sentence ID, also of a damaged line when the frame shows one ('' if none)."""
        d = self.decoded
        if d is None:
            return ""
        if d.sentence is not None:
            return d.sentence.ID
        if d.error is not None and d.error.sentence_id:
            return d.error.sentence_id
        m = _ID.match(self.raw)
        return m.group(1).decode() if m else ""

    @property
    def body(self) -> bytes:
        """The text a resend repeats: everything before the checksum (RH-BS-5)."""
        return self.raw.split(b"*", 1)[0].rstrip(b"\r\n")

    def evidence(self) -> Evidence:
        raw = self.raw
        if is_line(raw):
            return Evidence(self.t, TO_VEHICLE, escape(raw[:-2][:300]), self.lineno)
        return Evidence(self.t, TO_VEHICLE_RUN, escape(raw[:300]), self.lineno)


def spacing(measured: float, limit: float, r: float) -> str:
    """An interval that must be *at least* ``limit``: certainly shorter → violation."""
    if measured + r < limit:
        return VIOLATION
    if measured - r < limit:
        return INCONCLUSIVE
    return PASS


def gap(measured: float, limit: float, r: float) -> str:
    """An interval that must be *at most* ``limit``: certainly longer → violation."""
    if measured - r > limit:
        return VIOLATION
    if measured + r > limit:
        return INCONCLUSIVE
    return PASS
