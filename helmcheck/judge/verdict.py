"""The verdict words: one type, :class:`Verdict`, for every clause and run verdict.

Reference profile, preamble: a MUST not met gives FAIL, a SHOULD not met gives NON-STRICT; a
clause the run could not judge is INCONCLUSIVE (exercised, not decidable) or NOT-TESTED (not
exercised). :class:`Verdict` is a :class:`~enum.StrEnum`: a member *is* its word (``"pass"``,
``"non-strict"``, …), so ``results.json`` holds plain strings and a verdict read back from it
compares equal to the member. The ledger (:mod:`.ledger`) and the verdict rules
(:mod:`helmcheck.reports.verdicts`) take their words from here.
"""

from __future__ import annotations

from enum import StrEnum

__all__ = ["Verdict", "RUN_VERDICTS", "CLAUSE_VERDICTS", "PASS", "NON_STRICT", "FAIL", "INCONCLUSIVE", "NOT_TESTED"]


class Verdict(StrEnum):
    PASS = "pass"
    NON_STRICT = "non-strict"
    FAIL = "fail"
    INCONCLUSIVE = "inconclusive"
    NOT_TESTED = "not-tested"

    @property
    def shout(self) -> str:
        """As the one-line verdicts print it: ``PASS``, ``NON-STRICT``, ``NOT-TESTED``."""
        return self.value.upper()


#: The members as module constants, for hot paths (a module global is read several times faster
#: than an enum class attribute; the values are the same objects).
PASS, NON_STRICT, FAIL, INCONCLUSIVE, NOT_TESTED = (Verdict.PASS, Verdict.NON_STRICT, Verdict.FAIL,
                                                   Verdict.INCONCLUSIVE, Verdict.NOT_TESTED)

#: the verdicts a run can have (a run is never NOT-TESTED)
RUN_VERDICTS = (Verdict.PASS, Verdict.NON_STRICT, Verdict.FAIL, Verdict.INCONCLUSIVE)
#: the verdicts a clause can have
CLAUSE_VERDICTS = RUN_VERDICTS + (Verdict.NOT_TESTED,)
