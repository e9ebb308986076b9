"""RH-BS-5 (SHOULD): how a backseat reacts to a rejection and to a safety lockout.

*Resend.* After a command was rejected (``$ACK`` status other than 0), the same command text
(everything before the checksum) is not sent more than once per second. A rejection opens a
*series* for its text, which lasts until a sending of that text is accepted; a further rejection
while the text stands rejected opens nothing new. Every sending of the text after the rejected
one belongs to the series, those already on the line when the rejection arrived included (they
are judged as soon as it arrives). At most what can have been in flight may be excused, and that
is one copy: the first sending after the rejected one, if its first byte came before the
rejection could be known (arrived plus ``reaction_s``). Every other sending of the series (the
first one too, when it came later) is judged against the sending of the same text just before
it: the interval between their first bytes, by :func:`~.common.spacing` against 1 s less the
observer's :data:`~helmcheck.judge.timing.JITTER_S` (the earlier line may have been seen late),
so a coarse timestamp step gives INCONCLUSIVE, never a violation it cannot show; so does a
first sending within the timestamp step of that known time (it may have been the excused one).
A burst of copies is therefore one violation per copy after the excused one. A series with no
judged sending (its text never sent again once the rejection was known) met the clause.

*Lockout.* During a safety lockout the backseat sends nothing but ``$OSD``: every line with a
sentence ID other than ``OSD`` whose first byte falls in the judged window of an episode
(:class:`~.knowledge.Lockout`: from the first sign arrived plus ``reaction_s`` until the
lockout ends) is a violation; a damaged ``$OSD`` is still a poll. Decision: ``$OXFLT`` (the
tester's fault-injection extension, RH-SAF-5) is not backseat traffic and is exempt; a run of
bytes with no sentence ID is RH-BS-1's alone. An episode with no violation met the clause.
"""

from __future__ import annotations

from collections import OrderedDict, deque
from typing import Optional

from ..ledger import Ledger
from ..timing import JITTER_S
from .common import PASS, VIOLATION, SentLine, Settings, spacing
from .knowledge import Episode, Lockout

__all__ = ["Reaction", "RESEND_SPACING_S"]

RESEND_SPACING_S = 1.0  #: RH-BS-5: at most once per second
_MEMORY = 1024  #: command texts remembered (bounded memory)
_RECENT = 8  #: sendings remembered per text, for those on the line when a rejection arrives


class _Series:
    """The sendings of one rejected text (module docstring)."""

    __slots__ = ("known", "case", "last", "copies", "judged")

    def __init__(self, known: float, case: str, last: float):
        self.known = known  #: the rejection arrived plus ``reaction_s``
        self.case = case
        self.last = last  #: first byte of the text's latest sending
        self.copies = 0  #: sendings since the rejected one
        self.judged = 0  #: of which judged (all but an excused one)


class Reaction:
    """RH-BS-5 (module docstring)."""

    def __init__(self, settings: Settings, ledger: Ledger, lockout: Lockout):
        self.s = settings
        self.ledger = ledger
        self.lockout = lockout
        self._recent: OrderedDict[bytes, deque[SentLine]] = OrderedDict()  # text -> its latest sendings
        self._rejected: OrderedDict[bytes, _Series] = OrderedDict()
        self.rejections = 0
        self._passed = False

    # ------------------------------------------------------------------ resend
    def answered(self, line: SentLine, status: int, arrived: float) -> None:
        """The ``$ACK`` of ``line`` arrived at ``arrived``."""
        body = line.body
        if status == 0:
            self._rejected.pop(body, None)
            return
        self.rejections += 1
        if body in self._rejected:
            return  # the text already stands rejected: one series, one excused copy
        ser = self._rejected[body] = _Series(arrived + self.s.reaction_s, self.s.case, line.t)
        if len(self._rejected) > _MEMORY:
            self._end(self._rejected.popitem(last=False)[1])
        # sendings of the text after the rejected one, already on the line
        recent = list(self._recent.get(body, ()))
        i = next((j for j in range(len(recent) - 1, -1, -1) if recent[j] is line), None)
        later = recent[i + 1:] if i is not None else [c for c in recent if c.t > line.t]
        for c in later:
            self._resend(ser, c)

    def sent(self, line: SentLine) -> None:
        """A line from the backseat (a decoded command or a damaged line with its ID)."""
        self._lockout_rule(line)
        body = line.body
        ser = self._rejected.get(body)
        if ser is not None:
            self._resend(ser, line)
        recent = self._recent.get(body)
        if recent is None:
            recent = self._recent[body] = deque(maxlen=_RECENT)
            if len(self._recent) > _MEMORY:
                self._recent.popitem(last=False)
        else:
            self._recent.move_to_end(body)
        recent.append(line)

    def _resend(self, ser: _Series, line: SentLine) -> None:
        """One more sending of a rejected text: the one excused copy, or judged."""
        r = self.s.resolution
        measured = line.t - ser.last
        ser.last = line.t
        ser.copies += 1
        in_flight = ser.copies == 1 and line.t - r < ser.known  # possibly before it was known
        if in_flight and line.t + r < ser.known:
            return  # sent before the backseat could know: the one excused copy
        ser.judged += 1
        v = spacing(measured, RESEND_SPACING_S - JITTER_S, r)
        what = (f"${line.sid} sent again {measured:.3f} s after its previous sending, once the vehicle had "
                f"refused it")
        if v == VIOLATION and not in_flight:
            self.ledger.failed("RH-BS-5", f"{what}: RH-BS-5 allows a refused command again at most once a "
                                          f"second", [line.evidence()], self.s.case)
        elif v != PASS:
            why = ("it may have been sent before the refusal could be known" if v == VIOLATION
                   else "the timestamp step cannot tell")
            self.ledger.inconclusive("RH-BS-5", f"{what} (at most once a second); {why}", [line.evidence()],
                                     self.s.case)
        else:
            self._met(self.s.case, line, f"{what}: at most once a second, as the clause asks")

    def _end(self, ser: _Series) -> None:
        if not ser.judged:
            self._met(ser.case, None, "a refused command was not sent again once the refusal was known")

    # ------------------------------------------------------------------ lockout
    def _lockout_rule(self, line: SentLine) -> None:
        sid = line.sid
        if not sid or sid == "OXFLT":
            return
        ep = self.lockout.window(line.t)
        if ep is None:
            return
        if sid == "OSD":
            ep.osd += 1
            return
        ep.offences += 1
        into = line.t - (ep.known - self.s.reaction_s)
        self.ledger.failed("RH-BS-5", f"${sid} sent {into:.2f} s after the first sign of the {ep.code} lockout "
                                      f"had reached the backseat (it is given {self.s.reaction_s:g} s to act on "
                                      f"it): RH-BS-5 allows nothing but $OSD during a lockout",
                           [line.evidence()], self.s.case)

    def episode_over(self, ep: Optional[Episode]) -> None:
        """An episode ended (or the run did): one observation if the backseat knew of it."""
        if ep is None or ep.known is None or ep.offences:
            return
        if ep.end is not None and ep.end <= ep.known:
            return  # over before the backseat could know
        span = f" in the {ep.end - ep.known:.1f} s it knew of it" if ep.end is not None else ""
        self._met(ep.case, None, f"nothing but $OSD ({ep.osd} poll(s)) during the {ep.code} lockout{span}")

    def forget(self) -> None:
        """After a gap in the record (``run resumed``): the rejections the backseat knew of may
        have been answered since, unseen; a resend is judged only after a rejection seen anew."""
        for ser in self._rejected.values():
            self._end(ser)
        self._rejected.clear()
        self._recent.clear()

    def close(self) -> None:
        for ser in self._rejected.values():
            self._end(ser)
        self._rejected.clear()

    def _met(self, case: str, line: Optional[SentLine], reason: str) -> None:
        ev = [line.evidence()] if line is not None else []
        if self._passed:
            self.ledger.passed("RH-BS-5", case=case)
        else:
            self._passed = True
            self.ledger.passed("RH-BS-5", reason, ev, case)
