"""Reading a certification's verdicts in tests: what counts as "no false alarm"."""

from __future__ import annotations


#: Words of the two verdicts the observer gives when the *host* was too slow to judge a duration
#: (RH-TIM-1's last sentence; RH-ACK-2's late-ACK margin). Under a loaded test machine (several
#: workers on two cores) they are the honest verdict, not a defect of the vehicle or the judge.
HOST_LOAD_WORDS = ("the observer's own uncertainty", "host load can explain")


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
