"""Observations a faulty line may have spoilt, held until they are made again: the repetition rule.

A judge that meets an error the line could have caused (a broken sentence, a lost or late
answer, an incomplete reply: :mod:`.spoil` names its form) does not book it at once. It
*holds* it here, under the observation's key (the command, re-sent; the sentence, asked for
again), with the findings it would book. What happens next decides:

* **made again, clean** (:meth:`Streaks.clean`) — the same command answered in full and on time,
  the same sentence read whole: the held observations were the line's. None is booked against
  the implementation; each is counted on its clauses as spoilt and made again
  (:meth:`~.ledger.Ledger.spoiled`, shown in the verdict's reason);
* **the same error again** — a fault of the line does not repeat itself; an implementation's
  does. When the last observations of a key all show the same error (:func:`.spoil.signature`),
  as many of them as the error's form needs, they are booked as the violations they are: an
  error of a form one line fault gives (:data:`.spoil.REPEAT` in a row: the original and
  :data:`.spoil.RERUNS` re-runs) or of any other form (:data:`OTHER_REPEAT`: the line would have
  to do two faults in one line, twice). The error is then *proven* for that key: met again, it is
  booked at once;
* **the same broken bytes again** — a faulty line does not break a line the same way twice
  (the same bit of the same byte flipped, the same byte lost): the same broken line, byte for
  byte, seen :data:`SAME_REPEAT` times for a key (:data:`SAME_REPEAT_SHORT` for a line shorter
  than :data:`SHORT_LINE`, which a structural fault — its CR lost — can hit more often), made
  again clean in between or not, is the implementation's: an error that comes only now and then
  is found by it;
* **never made again** (:meth:`Streaks.conclude`: the case ends, the record ends, the key is
  pushed out) — INCONCLUSIVE, naming what the line may have done.

An observation a relay's note says the line touched (``known``) is the line's for certain: it
is never booked as a violation, only dismissed or INCONCLUSIVE. Memory is bounded
(:data:`MAX_KEYS` keys, :data:`MAX_HELD` observations a key). Pure: no clock, no I/O.
"""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass, field
from typing import Hashable, Optional

from .ledger import Ledger
from .spoil import REPEAT

__all__ = ["Held", "Streaks", "OTHER_REPEAT", "SAME_REPEAT", "SAME_REPEAT_SHORT", "SHORT_LINE", "MAX_KEYS",
           "MAX_HELD"]

#: In a row, the same error of a form no single line fault gives is the implementation's.
OTHER_REPEAT = 2
#: The same broken bytes, this many times for a key (not necessarily in a row), are the
#: implementation's; for a line shorter than :data:`SHORT_LINE` bytes, :data:`SAME_REPEAT_SHORT`.
SAME_REPEAT = 2
SAME_REPEAT_SHORT = 3
SHORT_LINE = 20
MAX_KEYS = 64
MAX_HELD = 16
_BREAK = object()  # the sig of a break in a run (:meth:`Streaks.interrupt`): holds nothing


@dataclass(slots=True)
class Held:
    """One held observation: what it would book, why the line may be to blame, and its place."""

    key: Hashable
    sig: Hashable
    need: int  #: observations in a row with this error that make it the implementation's
    text: str  #: what the line may have done (a reason names it)
    findings: list = field(default_factory=list)  #: (clause, reason, evidence, case)
    owners: tuple = ()  #: the commands (their bytes) it answered, whose re-run makes it again
    seq: int = 0  #: the order it was held in
    known: bool = False  #: a relay's note says the line touched it
    raw: Optional[bytes] = None  #: the broken bytes, when it is a broken line


class Streaks:
    """Held observations per key (module docstring)."""

    def __init__(self, ledger: Ledger):
        self.ledger = ledger
        self._held: OrderedDict[Hashable, list[Held]] = OrderedDict()
        self._proven: dict[Hashable, set] = {}
        self._same: OrderedDict[Hashable, OrderedDict] = OrderedDict()  #: key -> broken bytes -> times seen
        self._seq = 0
        self.dismissed = 0  #: observations made again clean
        self.failed = 0  #: observations booked as violations by repetition
        self.unresolved = 0  #: observations concluded INCONCLUSIVE

    def __bool__(self) -> bool:
        return bool(self._held)

    def _seen_again(self, key: Hashable, raw: bytes) -> bool:
        """Count ``raw`` for ``key``; True when it has now been seen as often as makes it the
        implementation's (module docstring)."""
        seen = self._same.get(key)
        if seen is None:
            seen = self._same[key] = OrderedDict()
            if len(self._same) > MAX_KEYS:
                self._same.popitem(last=False)
        n = seen[raw] = seen.get(raw, 0) + 1
        seen.move_to_end(raw)
        if len(seen) > 32:
            seen.popitem(last=False)
        return n >= (SAME_REPEAT_SHORT if len(raw) < SHORT_LINE else SAME_REPEAT)

    def is_open(self, key: Hashable) -> bool:
        return key in self._held

    def awaits(self, owner: Hashable) -> bool:
        """Something is held that a re-run of the command ``owner`` would make again: the command's
        own observation, or a reply held for it."""
        if ("cmd", owner) in self._held:
            return True
        return any(owner in h.owners for items in self._held.values() for h in items)

    def proven(self, key: Hashable, sig: Hashable) -> bool:
        """The error ``sig`` was shown to be the implementation's for ``key`` (booked at once now)."""
        return sig in self._proven.get(key, ())

    def hold(self, key: Hashable, sig: Hashable, text: str, findings: list, *, need: int = REPEAT,
             owners: tuple = (), known: bool = False, raw: Optional[bytes] = None) -> Optional[Held]:
        """Hold an observation (``raw``: the broken bytes, when it is a broken line); returns it,
        or None when it was booked (repeated, or proven)."""
        if not findings:
            return None
        self._seq += 1
        h = Held(key, sig, need, text, list(findings), owners, self._seq, known, raw)
        if not known and self.proven(key, sig):
            self._book_fail([h], f"the same error as before on this {_what(key)}")
            return None
        if not known and raw is not None and self._seen_again(key, raw):
            self._proven.setdefault(key, set()).add(sig)
            items = self._held.get(key, [])
            same = [x for x in items if x.raw == raw and not x.known]
            if same:
                rest = [x for x in items if x not in same]
                if any(x.findings for x in rest):
                    self._held[key] = rest
                else:
                    self._held.pop(key, None)
            self._book_fail(same + [h], "the same broken line, byte for byte, as before: a faulty line does not "
                                        "break a line the same way twice")
            return None
        items = self._held.get(key)
        if items is None:
            items = self._held[key] = []
            if len(self._held) > MAX_KEYS:
                _, old = self._held.popitem(last=False)
                self._unresolved(old, "not made again before the judge had to let it go")
        else:
            self._held.move_to_end(key)
        items.append(h)
        if len(items) > MAX_HELD:
            self._unresolved([items.pop(0)], "not made again before the judge had to let it go")
        run = 0
        for x in reversed(items):
            if x.known or x.sig != sig:
                break
            run += 1
        if not known and run >= need:
            same = items[len(items) - run:]
            del items[len(items) - run:]
            if not items:
                del self._held[key]
            self._proven.setdefault(key, set()).add(sig)
            self._book_fail(same, f"the same error on {run} observations in a row, which a faulty line does not "
                                  "do")
            return None
        return h

    def interrupt(self, key: Hashable) -> None:
        """Something clean came between (an answer on time): what is held under ``key`` stays held,
        but what comes next does not continue its run."""
        items = self._held.get(key)
        if items and items[-1].sig is not _BREAK:
            items.append(Held(key, _BREAK, 0, ""))

    def release(self, h: Held) -> list:
        """Take a held observation back (it turned out to be another error: a lost answer that came
        late after all); returns its findings ([] when it was already settled)."""
        items = self._held.get(h.key)
        if not items or h not in items:
            return []
        items.remove(h)
        if not items:
            del self._held[h.key]
        return h.findings

    def made_again(self, text: str, findings: list) -> None:
        """An observation held too late to wait: it was already made again, clean (a later sending
        of the same command was answered in full before this one's answer was given up on)."""
        self._dismiss([Held(None, None, 0, text, list(findings))])

    def clean(self, key: Hashable) -> int:
        """The observation ``key`` was made again, clean: what was held for it was the line's."""
        items = self._held.pop(key, None)
        if not items:
            return 0
        self._dismiss(items)
        return len(items)

    def clean_owned(self, owner: Hashable, before: int) -> int:
        """The command ``owner`` was answered again in full: the replies held for its earlier
        sendings (held before ``before``) were made again."""
        n = 0
        for key in list(self._held):
            items = self._held[key]
            mine = [h for h in items if owner in h.owners and h.seq < before]
            if not mine:
                continue
            rest = [h for h in items if h not in mine]
            if any(h.findings for h in rest):
                self._held[key] = rest
            else:
                del self._held[key]
            self._dismiss(mine)
            n += len(mine)
        return n

    def mark(self) -> int:
        """The order the next held observation will have (see :meth:`clean_owned`)."""
        return self._seq + 1

    def conclude(self, why: str = "not made again") -> None:
        """Every observation still held is INCONCLUSIVE (the case or the record ended)."""
        held, self._held = self._held, OrderedDict()
        for items in held.values():
            self._unresolved(items, why)

    # ------------------------------------------------------------------ booking
    def _dismiss(self, items: list[Held]) -> None:
        for h in items:
            if not h.findings:
                continue
            self.dismissed += 1
            for cid, _reason, evidence, case in h.findings:
                self.ledger.spoiled(cid, f"{h.text}", evidence, case)

    def _unresolved(self, items: list[Held], why: str) -> None:
        for h in items:
            if not h.findings:
                continue
            self.unresolved += 1
            for cid, reason, evidence, case in h.findings:
                self.ledger.inconclusive(cid, f"{reason} — not judged: {h.text}; the line, not the implementation, "
                                              f"may have done it ({why})", evidence, case)

    def _book_fail(self, items: list[Held], why: str) -> None:
        for h in items:
            self.failed += 1
            for cid, reason, evidence, case in h.findings:
                self.ledger.failed(cid, f"{reason} ({why})", evidence, case)


def _what(key: Hashable) -> str:
    if isinstance(key, tuple) and key and key[0] == "cmd":
        return "command"
    return "sentence"
