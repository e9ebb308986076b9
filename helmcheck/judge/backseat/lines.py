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
"""

from __future__ import annotations

from ...grammar import sentences as s
from ...grammar.errors import FRAMING
from ...model.validate import field_error
from ..ledger import Ledger
from .common import SentLine, Settings

__all__ = ["LineRules"]


class LineRules:
    """RH-BS-1/2/7 per line (module docstring)."""

    def __init__(self, settings: Settings, ledger: Ledger):
        self.s = settings
        self.ledger = ledger
        self.lines = 0
        self.commands = 0
        self._first = set()

    def _pass(self, cid: str, reason: str, line: SentLine) -> None:
        if cid in self._first:
            self.ledger.passed(cid, case=self.s.case)
        else:
            self._first.add(cid)
            self.ledger.passed(cid, reason, [line.evidence()], self.s.case)

    def discarded(self, line: SentLine) -> None:
        """RH-BS-1: bytes the framer threw away."""
        d = line.discard
        self.ledger.failed("RH-BS-1", f"{d.length} byte(s) that are no sentence ({d.clause}: {d.reason})",
                           [line.evidence()], self.s.case)

    def line(self, line: SentLine) -> None:
        d = line.decoded
        led = self.ledger
        case = self.s.case
        self.lines += 1
        if d.findings:
            led.failed("RH-BS-7", str(d.findings[0]), [line.evidence()], case)
        else:
            self._pass("RH-BS-7", "upper-case checksum hex and CR LF", line)
        err = d.error
        if err is not None:
            if err.kind == FRAMING:
                led.failed("RH-BS-1", str(err), [line.evidence()], case)
            else:
                self._pass("RH-BS-1", "well framed, correct checksum", line)
                led.failed("RH-BS-2", str(err), [line.evidence()], case)
            return
        self._pass("RH-BS-1", "well framed, correct checksum", line)
        cmd = d.sentence
        if not isinstance(cmd, s.Command):
            return
        self.commands += 1
        code = field_error(cmd, self.s.profile)
        if code is not None:
            led.failed("RH-BS-2", f"${cmd.ID}: a field is out of range (a vehicle answers err {code})",
                       [line.evidence()], case)
        else:
            self._pass("RH-BS-2", f"${cmd.ID} fields within range", line)
