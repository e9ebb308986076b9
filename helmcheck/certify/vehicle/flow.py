"""How a case stops early: flow control only, never a verdict.

Verdicts live in the ledger the observer writes (:mod:`helmcheck.judge`). A driver stops a case
when continuing would prove nothing more: the observer has booked a failure inside it (the
first fail is the root cause), the vehicle could not be brought where the case needs it, or the
profile does not claim what the case needs. :class:`CaseStop` carries that decision and its
reason to the case list of the report; what the clauses are is already in the ledger (and, for
the tester's own reasons, in a ``not tested``/``inconclusive`` note the driver wrote).
"""

from __future__ import annotations

from typing import Optional

__all__ = ["CaseStop", "LinkLost", "LinkSilent"]


class CaseStop(Exception):
    """A case ends early: ``outcome`` is ``fail``, ``inconclusive`` or ``not-tested``."""

    def __init__(self, outcome: str, reason: str, clause: Optional[str] = None):
        super().__init__(reason)
        self.outcome, self.reason, self.clause = outcome, reason, clause


class LinkLost(Exception):
    """The device or connection is gone (a link fault: INCONCLUSIVE, never FAIL)."""


class LinkSilent(LinkLost):
    """The vehicle stopped answering anything at all (a link fault, INCONCLUSIVE)."""
