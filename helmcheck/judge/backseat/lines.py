"""RH-BS-1, RH-BS-2, RH-BS-7: each line the backseat sends, on its own.

* **RH-BS-1** (MUST) — every sentence is well-formed per §1 with a correct checksum of exactly
  two hex digits. A line the grammar rejects for its framing (``kind == "framing"``: checksum
  missing, malformed or wrong, unknown or lower-case ID — RH-FRM-1/2/4/5) fails; so does every
  run of bytes the framer discards (noise before ``$``, a torn line, an overlong line —
  RH-FRM-6/7). Decision: a line begun with ``$`` but unterminated when the run or the log ends
  is not judged (the recording stopped it, not the backseat); bytes before any ``$`` then are
  noise whatever would have followed, and fail; a well-formed vehicle-side sentence from the
  backseat (``$OSI``, ``$ACK``…) meets RH-BS-1 and nothing else in §9 speaks of it.
* **RH-BS-2** (MUST) — every field within the ranges of §4–6: a line with a syntax or range
  error (the grammar's ``syntax``/``range`` kinds) fails, and a decoded command whose fields the
  model would refuse (:func:`helmcheck.model.validate.field_error`) fails.
* **RH-BS-7** (SHOULD) — upper-case checksum hex and CR LF: a grammar finding on the line
  (lower-case hex, bare LF) is a violation; every other line meets it.

A well-framed line with a right checksum is judged as sent, on any link: a field out of range
under a right checksum is what the backseat wrote (RH-BS-2 at once). On a link that cannot damage
a byte (``line model: clean``) every broken line is the backseat's at once too. Elsewhere a faulty
line between the backseat and the vehicle breaks lines the backseat wrote whole, so a broken
line's violations are held, not booked (``docs/contracts.md``, "A faulty line"; the
repetition rule, :mod:`helmcheck.judge.streaks`, and the damage's form,
:mod:`helmcheck.judge.spoil`): the next line of the same sentence read whole makes them the
line's; the same error on the backseat's next lines of that sentence, as often as its form
needs, makes them the backseat's; a line never sent again leaves them INCONCLUSIVE, naming what
the line may have done. Bytes that frame into nothing are held the same way (the same bytes
before line after line are the backseat's). In a line-fault relay's record (its notes,
:mod:`helmcheck.judge.linefaults`) the line is known: what no note touched is booked at once.
"""

from __future__ import annotations

from ...grammar import sentences as s
from ...grammar.errors import FRAMING
from ...grammar.ranges import check_ranges
from ...model.validate import field_error
from ..ledger import Ledger
from ..spoil import REPEAT, SHORTEST_COMMAND, explain, explain_discard, signature
from ..streaks import OTHER_REPEAT, Streaks
from .common import SentLine, Settings
from .words import discard_words, field_words, finding_words, framing_words

__all__ = ["LineRules"]


class LineRules:
    """RH-BS-1/2/7 per line (module docstring)."""

    def __init__(self, settings: Settings, ledger: Ledger):
        self.s = settings
        self.ledger = ledger
        self.lines = 0
        self.commands = 0
        self._first = set()
        self.streaks = Streaks(ledger)  #: broken lines held until the backseat sends the sentence again
        #: the record carries a line-fault relay's notes, and the note on the line being judged
        self.instrumented = False
        self.fault: str | None = None
        self._junk_before = False

    def _pass(self, cid: str, reason: str, line: SentLine) -> None:
        if cid in self._first:
            self.ledger.passed(cid, case=self.s.case)
        else:
            self._first.add(cid)
            self.ledger.passed(cid, reason, [line.evidence()], self.s.case)

    def _hold(self, line: SentLine, fails: list) -> None:
        """A broken line's violations: held (module docstring), or booked at once."""
        fault, self.fault = self.fault, None
        case = self.s.case
        if not fails:
            return
        if self.instrumented and fault is None:
            for cid, reason in fails:
                self.ledger.failed(cid, reason, [line.evidence()], case)
            return
        raw, d = line.raw, line.decoded
        if (fault is None and d is not None and not d.findings and (d.error is None or d.error.kind != FRAMING)
                and explain(raw, self.s.profile, d, SHORTEST_COMMAND) is None):
            # well framed with a right checksum: judged as sent, on any link (no one line fault
            # makes it; a value out of range under a right checksum is what the backseat wrote)
            for cid, reason in fails:
                self.ledger.failed(cid, reason, [line.evidence()], case)
            return
        junk = d is None and raw[:1] != b"$"
        key = ("bs-junk",) if junk else ("bs", line.sid or "?")
        if fault is not None:
            text, sig, need = f"the line touched it (the relay's note: {fault})", ("note",), REPEAT
        else:
            sig = ("junk", raw[:32]) if junk else (signature(raw, d) if d is not None
                                                   else ("discard", line.discard.clause))
            spoil = None if self.streaks.proven(key, sig) else (
                explain_discard(raw, line.discard.clause, "", self.s.profile) if d is None
                else explain(raw, self.s.profile, d, SHORTEST_COMMAND))
            if spoil is not None:
                text, need = spoil.text, REPEAT
            else:
                text, need = "a broken line (of a form no one fault of a line gives)", OTHER_REPEAT
        self.streaks.hold(key, sig, text, [(cid, reason, [line.evidence()], case) for cid, reason in fails],
                          need=need, known=fault is not None, raw=None if junk else raw)

    def discarded(self, line: SentLine) -> None:
        """RH-BS-1: bytes the framer threw away."""
        d = line.discard
        if line.raw[:1] != b"$":
            self._junk_before = True
        self._hold(line, [("RH-BS-1", discard_words(d.length, d.clause, d.reason))])

    def line(self, line: SentLine) -> None:
        d = line.decoded
        fails: list = []
        self.lines += 1
        junk, self._junk_before = self._junk_before, False
        if d.findings:
            fails.append(("RH-BS-7", finding_words(d.findings[0].message)))
        else:
            self._pass("RH-BS-7", "upper-case checksum hex and CR LF", line)
        err = d.error
        if err is not None:
            if err.kind == FRAMING:
                fails.append(("RH-BS-1", framing_words(err)))
            else:
                self._pass("RH-BS-1", "well framed, with a correct two-digit checksum", line)
                fails.append(("RH-BS-2", field_words(err)))
            self._hold(line, fails)
            return
        self._pass("RH-BS-1", "well framed, with a correct two-digit checksum", line)
        cmd = d.sentence
        if isinstance(cmd, s.Command):
            self.commands += 1
            code = field_error(cmd, self.s.profile)
            if code is not None:
                bad = check_ranges(cmd, self.s.profile)
                fails.append(("RH-BS-2", field_words(bad) if bad is not None else
                              f"${cmd.ID}: a field outside the ranges of §4–6 (a vehicle answers err {code})"))
            else:
                self._pass("RH-BS-2", f"every field of ${cmd.ID} within the ranges of §4–6", line)
        if fails:
            self._hold(line, fails)
            return
        self.fault = None
        if self.streaks:  # the sentence read whole: what was held for it (and junk before it) was the line's
            self.streaks.clean(("bs", line.sid))
            if not junk:
                self.streaks.clean(("bs-junk",))

    def close(self) -> None:
        """The record ended: what is still held is INCONCLUSIVE."""
        self.streaks.conclude("the record ended before the backseat sent it again")
