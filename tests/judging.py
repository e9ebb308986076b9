"""Reading a certification's verdicts in tests: what counts as "no false alarm"."""

from __future__ import annotations


#: Words of the verdict the observer gives when the *host* was too slow to judge an ACK's timing
#: (RH-ACK-2's late-ACK margin). Under a loaded test machine (several workers on two cores) it is
#: the honest verdict, not a defect of the vehicle or the judge. "The observer's own uncertainty"
#: cannot bound a duration is not excused: the tester chooses every duration from the line budget
#: it measured (:mod:`helmcheck.judge.linebudget`), so such a verdict is the tester's defect.
HOST_LOAD_WORDS = ("host load can explain",)


def not_passed(results: dict, clauses=None) -> dict:
    """Clauses (of ``clauses``, default all) neither PASS nor NOT-TESTED, except INCONCLUSIVE
    verdicts whose only reason is the host's load (:data:`HOST_LOAD_WORDS`): ``{id: reason}``."""
    out = {}
    for c in results["clauses"]:
        if clauses is not None and c["id"] not in clauses:
            continue
        if c["verdict"] in ("pass", "not-tested"):
            continue
        if c["verdict"] == "inconclusive" and any(w in c["reason"] for w in HOST_LOAD_WORDS):
            continue
        out[c["id"]] = c["reason"]
    return out
