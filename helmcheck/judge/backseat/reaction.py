"""RH-BS-5 (SHOULD): how a backseat reacts to a rejection and to a safety lockout.

*Resend.* After a command was rejected (``$ACK`` status 1), the same command text (everything
before the checksum) is not sent again sooner than 1 s after its previous sending. Judged from
when the rejection had arrived plus ``reaction_s``; a sending before that is not judged (the
backseat could not know). The interval runs between the first bytes of the two sendings and is
judged by :func:`~.common.spacing` against 1 s less the observer's
:data:`~helmcheck.judge.timing.JITTER_S` (the earlier line may have been seen late). Each
rejection is judged once, at the next sending of its text; a rejected text never sent again
met the clause. An accepted sending clears the text.

*Lockout.* During a safety lockout the backseat sends nothing but ``$OSD``: every line with a
sentence ID other than ``OSD`` whose first byte falls in the judged window of an episode
(:class:`~.knowledge.Lockout`: from the first sign arrived plus ``reaction_s`` until the
lockout ends) is a violation; a damaged ``$OSD`` is still a poll. Decision: ``$OXFLT`` (the
tester's fault-injection extension, RH-SAF-5) is not backseat traffic and is exempt; a run of
bytes with no sentence ID is RH-BS-1's alone. An episode with no violation met the clause.
"""

from __future__ import annotations

from collections import OrderedDict
from typing import Optional

from ..ledger import Ledger
from ..timing import JITTER_S
from .common import INCONCLUSIVE, VIOLATION, SentLine, Settings, spacing
from .knowledge import Episode, Lockout

__all__ = ["Reaction", "RESEND_SPACING_S"]

RESEND_SPACING_S = 1.0  #: RH-BS-5: at most once per second
_MEMORY = 1024  #: command texts remembered (bounded memory)


class Reaction:
    """RH-BS-5 (module docstring)."""

    def __init__(self, settings: Settings, ledger: Ledger, lockout: Lockout):
        self.s = settings
        self.ledger = ledger
        self.lockout = lockout
        self._last: OrderedDict[bytes, float] = OrderedDict()  # text -> first byte of its last sending
        self._rejected: OrderedDict[bytes, tuple[float, str]] = OrderedDict()  # text -> (known, case)
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
        if body not in self._rejected:
            self._rejected[body] = (arrived + self.s.reaction_s, self.s.case)
            if len(self._rejected) > _MEMORY:
                self._met(self._rejected.popitem(last=False)[1][1], None, "a rejected command was not resent")

    def sent(self, line: SentLine) -> None:
        """A line from the backseat (a decoded command or a damaged line with its ID)."""
        self._lockout_rule(line)
        body = line.body
        t = line.t
        prev = self._last.get(body)
        rej = self._rejected.get(body)
        if rej is not None and prev is not None and t >= rej[0]:
            del self._rejected[body]
            measured = t - prev
            v = spacing(measured, RESEND_SPACING_S - JITTER_S, self.s.resolution)
            what = (f"${line.sid} resent {measured:.3f} s after its previous sending, which the "
                    f"vehicle had rejected (at most once per second)")
            if v == VIOLATION:
                self.ledger.failed("RH-BS-5", what, [line.evidence()], self.s.case)
            elif v == INCONCLUSIVE:
                self.ledger.inconclusive("RH-BS-5", what + "; the timestamp step cannot tell",
                                         [line.evidence()], self.s.case)
            else:
                self._met(self.s.case, line, f"${line.sid} resent {measured:.3f} s after a rejection")
        self._last[body] = t
        self._last.move_to_end(body)
        if len(self._last) > _MEMORY:
            self._last.popitem(last=False)

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
        self.ledger.failed("RH-BS-5", f"${sid} sent during the safety lockout ({ep.code}; only $OSD "
                                      f"is allowed)", [line.evidence()], self.s.case)

    def episode_over(self, ep: Optional[Episode]) -> None:
        """An episode ended (or the run did): one observation if the backseat knew of it."""
        if ep is None or ep.known is None or ep.offences:
            return
        if ep.end is not None and ep.end <= ep.known:
            return  # over before the backseat could know
        self._met(ep.case, None, f"only $OSD during the lockout ({ep.code}, {ep.osd} poll(s))")

    def close(self) -> None:
        for _, (_, case) in self._rejected.items():
            self._met(case, None, "a rejected command was not resent")
        self._rejected.clear()

    def _met(self, case: str, line: Optional[SentLine], reason: str) -> None:
        ev = [line.evidence()] if line is not None else []
        if self._passed:
            self.ledger.passed("RH-BS-5", case=case)
        else:
            self._passed = True
            self.ledger.passed("RH-BS-5", reason, ev, case)
