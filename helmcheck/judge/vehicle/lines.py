"""One line at a time: what a backseat line is to a vehicle, and whether a vehicle line is valid.

:func:`classify` reads a line (or a discarded run) the backseat sent the way a conforming vehicle
does (RH-FRM-4..7, RH-RD-16) and says what it owes: an ``$ACK`` of a type (a command — tagged with
the clause of a form the vehicle must still read: a zero-padded checksum RH-FRM-2, lower-case hex
RH-FRM-3, a bare LF RH-FRM-7, a line of exactly the limit RH-FRM-6 — or a
malformed command answered with its "incorrect values" error, RH-ACK-3), nothing (a line it must
discard silently, with the clause that says so), or nothing because it is the ``$OXFLT`` test
extension (RH-SAF-5). A command the profile does not claim is an unknown ID (RH-FRM-5).

:class:`OutputJudge` judges every line the vehicle sends on its own (RH-FRM-1/2/3/6/8,
RH-OUT-1/2/3) into the ledger; a ``$C`` that does not follow its form fails RH-FRM-8, and a line
that is a sentence with a parity bit in bit 7 of every byte fails RH-FRM-9 (not 8N1). A broken
line's failures go to its :attr:`~OutputJudge.holder` first: a faulty line may have broken it,
so the vehicle observer holds them until the line is read again (the repetition rule,
:mod:`helmcheck.judge.streaks`; the form of the damage, :mod:`helmcheck.judge.spoil`). Bytes
from the vehicle that frame into no sentence are RH-FRM-1's the same way: line noise unless the
same bytes come before reply after reply (:data:`PREFIX_REPEAT` in a row: a modem or vehicle
prefix).

A sentence with bad fields (:attr:`~helmcheck.grammar.Decoded.partial`: framed, checksummed, split
into its fields, but with a field the grammar cannot read or a value out of its range) fails each
bad field's clause — the one the grammar or the range rule names: RH-OUT-1 for a field's form,
RH-OUT-3 for a physical range — and an ``$OSI`` among them is still a report: the rest of its
fields are read (:data:`STATE_FIELDS` must be among them, or it shows no state), for every other
clause, the tester's polls and the restore. The failures so booked are kept in
:attr:`OutputJudge.read_anyway`: a fault of the line's form, not of what the vehicle does, which
does not stop a case about another clause (:meth:`~helmcheck.certify.vehicle.session.Session.check`).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Optional

from ...grammar import Decoded, decode
from ...grammar import sentences as s
from ...grammar.wirelog import escape
from ...grammar.errors import SentenceError
from ...profile import Profile
from ..ledger import Evidence, Ledger
from ..wire import LINE_CACHE

__all__ = ["Kind", "classify", "OutputJudge", "ID_ACK_TYPE", "PREFIX_REPEAT", "STATE_FIELDS"]

#: Sentence ID → the ACK type a vehicle answers it with (for a line it must not answer).
ID_ACK_TYPE = {cls.ID: cls.ACK_TYPE for cls in (s.OMS, s.OMP, s.OJW, s.OMSTOP, s.OMLOAD, s.OMSTART,
                                                 s.OPOS, s.OSD, s.OLOGL, s.OLOGD, s.ORWSET, s.ODVL,
                                                 s.OPK, s.OMW)}
#: Replies in a row preceded by the same discarded bytes before that is called a prefix (RH-FRM-1).
PREFIX_REPEAT = 3
_ID = re.compile(rb"\$([A-Za-z]+)[,*\r\n]")
#: Vehicle-output decode errors → the clause a vehicle breaks by sending it.
_OUT_CLAUSE = {"RH-FRM-4": "RH-FRM-2", "RH-FRM-5": "RH-FRM-1", "RH-FRM-7": "RH-FRM-1", "RH-ACK-3": "RH-FRM-1"}
#: The ``$OSI`` fields a report's state is (RH-OUT-4): one of them unread, the report shows none.
STATE_FIELDS = frozenset({"mode", "next_waypoint", "park_time", "error_state"})
#: Backseat-line decode errors → the clause that says the vehicle discards such a line.
_DISCARD_CLAUSE = {"RH-FRM-2": "RH-FRM-4"}


@dataclass(frozen=True, slots=True)
class Kind:
    """What a backseat line is to a conforming vehicle."""

    kind: str  #: command | error | discard | oxflt
    item: object = None  #: the Command, or the SentenceError a vehicle answers
    ack_type: Optional[int] = None  #: the ACK owed (None: nothing may answer)
    clause: str = ""  #: discard: the clause that says it is discarded
    would_be: Optional[int] = None  #: discard: the ACK type its ID would have
    variant: str = ""  #: a command in a form a vehicle must still read (RH-FRM-3 hex, RH-FRM-7)


def _id_type(raw: bytes) -> Optional[int]:
    m = _ID.search(raw)
    return ID_ACK_TYPE.get(m.group(1).decode().upper()) if m else None


def classify(d: Optional[Decoded], raw: bytes, profile: Profile, discard_clause: str = "") -> Kind:
    """What ``raw`` (decoded as ``d``; ``None`` for a framer discard) is to a vehicle."""
    if d is None:
        return Kind("discard", clause=discard_clause or "RH-FRM-7", would_be=_id_type(raw))
    sent = d.sentence
    variant = ""
    for f in d.findings:
        if f.clause in ("RH-FRM-3", "RH-FRM-7"):
            variant = f.clause
    if len(raw) >= profile.max_line_bytes:
        variant = "RH-FRM-6"  # a line of exactly the limit must still be read
    elif not variant and raw[raw.rfind(b"*") + 1:][:1] == b"0":
        variant = "RH-FRM-2"  # a checksum under 0x10 written zero-padded must still be read
    if isinstance(sent, s.OXFLT):
        if profile.fault_injection == "oxflt":
            return Kind("oxflt", sent)
        return Kind("discard", clause="RH-FRM-5")
    if isinstance(sent, s.Command):
        if sent.ID not in profile.commands:
            return Kind("discard", clause="RH-FRM-5", would_be=sent.ACK_TYPE)
        return Kind("command", sent, sent.ACK_TYPE, variant=variant)
    if sent is not None:  # a vehicle sentence sent by the backseat: an unknown command ID
        return Kind("discard", clause="RH-FRM-5")
    err: SentenceError = d.error  # type: ignore[assignment]
    if err.answered and err.sentence_id in profile.commands:
        return Kind("error", err, err.ack_type, variant=variant)
    clause = err.clause if err.clause.startswith("RH-FRM") else "RH-FRM-5"
    # RH-FRM-2 only says what the checksum is; discarding a line whose checksum is wrong is
    # RH-FRM-4's rule ("missing, malformed … or wrong: no $ACK, no state change")
    return Kind("discard", clause=_DISCARD_CLAUSE.get(clause, clause), would_be=_id_type(raw))


#: The passes of a valid vehicle sentence, by (class, no findings, $OSI field count): they
#: depend on nothing else, and a session's lines differ only in their values.
_PASSES: dict = {}


def _passes(sent: s.Sentence, d: Decoded) -> tuple:
    passes = [("RH-FRM-1", "vehicle sentences are $ID,fields*hh CR LF"),
              ("RH-FRM-2", "vehicle checksums are right")]
    if not d.findings:
        passes.append(("RH-FRM-3", "vehicle checksums are upper-case hex"))
    if not isinstance(sent, s.ACK):
        passes.append(("RH-OUT-3", "numeric fields within their physical ranges"))
        if isinstance(sent, s.OSI):
            passes.append(("RH-OUT-1", f"$OSI with {sent.field_count} fields"))
        else:
            passes.append(("RH-OUT-2", f"${sent.ID} in its format"))
            if isinstance(sent, s.Compass):
                passes.append(("RH-FRM-8", "$C has no commas"))
    return tuple(passes)


class OutputJudge:
    """Per-line judgement of the vehicle's output (module docstring)."""

    def __init__(self, ledger: Ledger, profile: Profile):
        self.ledger = ledger
        self.profile = profile
        self.noise_before: Optional[bytes] = None  #: a discarded run just before the next line
        #: the run discarded just before the line last judged (None: the line came clean after a line)
        self.before_line: Optional[bytes] = None
        self.discards = 0
        #: a line's bytes → (its sentence, its passes), for lines judged without any fault
        self._clean: dict = {}
        #: (clause, reason) of the failures booked for bad fields of sentences still read (module
        #: docstring; the latest :data:`~helmcheck.judge.wire.LINE_CACHE` of them)
        self.read_anyway: set = set()
        #: takes a broken line's failures for the repetition rule (a faulty line may have broken
        #: it: :mod:`helmcheck.judge.streaks`): ``holder(raw, decoded, fails, evidence, case,
        #: discard_clause)`` returns True when it took them; None: book them at once
        self.holder = None

    def _book(self, raw: bytes, d: Optional[Decoded], fails: list, ev: Evidence, case: str,
              discard: str = "") -> None:
        """The failures of one broken run: to the holder, or into the ledger."""
        if not fails:
            return
        if self.holder is not None and self.holder(raw, d, fails, ev, case, discard):
            return
        for clause, reason in fails:
            if clause == "RH-FRM-1" and d is None:  # no holder: bytes that frame into nothing
                self.ledger.inconclusive(clause, reason, [ev], case)
            else:
                self.ledger.failed(clause, reason, [ev], case)

    def discard(self, raw: bytes, length: int, clause: str, ev: Evidence, case: str) -> None:
        """Bytes from the vehicle that frame into no sentence."""
        self.discards += 1
        if clause == "RH-FRM-6":
            self.ledger.failed("RH-FRM-6", f"the vehicle sent a line of {length} bytes, over the "
                                           f"{self.profile.max_line_bytes}-byte limit", [ev], case)
            return
        if raw[:1] != b"$":
            self.noise_before = raw
        self._book(raw, None, [("RH-FRM-1", f"bytes from the vehicle that frame into no sentence: "
                                            f"{escape(raw[:40])!r}")], ev, case, clause)

    def line(self, d: Decoded, ev: Evidence, case: str) -> Optional[s.Sentence]:
        """Judge one vehicle line; returns the sentence when it is valid."""
        led = self.ledger
        self.before_line, self.noise_before = self.noise_before, None
        known = self._clean.get(d.raw)
        if known is not None:  # a line seen before without fault: the same passes again
            led.passed_all(known[1], [ev], case)
            return known[0]
        if self._parity(d, ev, case):
            return None
        fails: list = []
        if d.terminator != "\r\n":
            fails.append(("RH-FRM-1", "the vehicle ended a sentence without CR LF"))
        for f in d.findings:
            if f.clause == "RH-FRM-3":
                fails.append(("RH-FRM-3", f"the vehicle emitted lower-case checksum hex: {f.message}"))
        sent = d.sentence
        if sent is None:
            if d.partial is not None and not isinstance(d.partial, s.Command):
                got = self._partial(d, ev, case, fails)
                self._book(d.raw, d, fails, ev, case)
                return got
            err = d.error
            clause, why = self._clause(d, err)
            fails.append((clause, f"the vehicle sent an invalid {d.sentence_id or 'line'}: {why}"))
            self._book(d.raw, d, fails, ev, case)
            return None
        if isinstance(sent, s.Command):
            fails.append(("RH-FRM-1", f"the vehicle sent a command sentence ${sent.ID}"))
            self._book(d.raw, d, fails, ev, case)
            return None
        cls = type(sent)
        key = (cls, not d.findings, sent.field_count if cls is s.OSI else 0)
        passes = _PASSES.get(key)
        if passes is None:
            passes = _PASSES[key] = _passes(sent, d)
        led.passed_all(passes, [ev], case)
        if fails:
            self._book(d.raw, d, fails, ev, case)
        elif d.terminator == "\r\n" and not d.findings and d.raw.isascii():  # judged by its bytes alone
            if len(self._clean) >= LINE_CACHE:
                self._clean.clear()
            self._clean[d.raw] = (sent, passes)
        return sent

    @staticmethod
    def _clause(d: Decoded, err: Optional[SentenceError]) -> tuple[str, str]:
        """The clause a vehicle breaks by sending a line the grammar read as ``err``, and why."""
        clause = _OUT_CLAUSE.get(err.clause, err.clause) if err is not None else "RH-FRM-1"
        why = str(err)
        if d.sentence_id == "C" and clause == "RH-OUT-2":
            clause = "RH-FRM-8"  # the $C form is RH-FRM-8's: no commas, letters in order
            why = f"{err.message} (the form is $C<hdg>P<pitch>R<roll>T<temp>D<depth>, no commas)"
        return clause, why

    def _partial(self, d: Decoded, ev: Evidence, case: str, fails: list) -> Optional[s.Reply]:
        """A reply with bad fields (module docstring): each fails its own clause (into ``fails``);
        an ``$OSI`` whose state fields were read is returned, the bad fields ``None`` in it."""
        sent = d.partial
        read = isinstance(sent, s.OSI) and not d.unread & STATE_FIELDS
        failed = set()
        for err in d.field_errors:
            clause, why = self._clause(d, err)
            reason = f"the vehicle sent ${d.sentence_id} with a bad field: {why}"
            if read:
                if len(self.read_anyway) >= LINE_CACHE:
                    self.read_anyway.clear()
                self.read_anyway.add((clause, reason))
            failed.add(clause)
            fails.append((clause, reason))
        # what the line does show: its frame, and the rules no field of it breaks
        self.ledger.passed_all(tuple((c, "the other fields in their form and range" if c.startswith("RH-OUT") else r)
                                     for c, r in _passes(sent, d) if c not in failed), [ev], case)
        return sent if read else None

    def _parity(self, d: Decoded, ev: Evidence, case: str) -> bool:
        """RH-FRM-9: a line whose bytes carry a parity bit in bit 7 (7E1 or 7O1 read as 8N1): every
        byte has the same parity over all eight bits, and with bit 7 cleared the line is a valid
        sentence. Line noise does not do that; a UART set to 7 data bits with parity does."""
        raw = d.raw
        if raw.isascii():
            return False
        low = bytes(b & 0x7F for b in raw)
        ones = {bin(b).count("1") % 2 for b in raw}
        if len(ones) != 1 or not decode(low, self.profile).valid:
            return False
        kind = "odd" if ones == {1} else "even"
        self.ledger.failed("RH-FRM-9", f"bit 7 of every byte is the {kind} parity of the other seven: the "
                                       f"vehicle sends 7{kind[0].upper()}1, not 8N1 (bit 7 cleared, the line "
                                       f"reads {escape(low.rstrip(bytes((13, 10))))[:80]})", [ev], case)
        return True
