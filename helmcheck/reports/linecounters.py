"""The line a run was judged on, in one sentence each for a report: its model and its port's error counters.

:func:`line_model_summary` says whether the link could damage bytes and why (``results.json``
``line_model``, :mod:`helmcheck.judge.linemodel`).

``results.json`` ``cases[].line_counters`` holds, per case, the kernel's per-port error counts
read when the case started and ended (:mod:`helmcheck.certify.vehicle.casecounters`), or why
they could not be read. :func:`counters_summary` says it in one line: "not available (… a
pseudo-terminal has no UART)", "read around 12 cases, no error counted", or the cases whose
counts rose, with the counts. None when no case carries them (an older run, another role).
"""

from __future__ import annotations

from typing import Mapping, Optional

from ..judge.linemodel import LineModel

__all__ = ["counters_summary", "line_model_summary"]


def line_model_summary(results: Mapping) -> Optional[str]:
    """The run's line model in one sentence, or None for a document without one (an older run)."""
    m = results.get("line_model")
    if not isinstance(m, Mapping) or m.get("kind") not in ("clean", "noisy"):
        return None
    return LineModel(str(m["kind"]), str(m.get("why") or "")).describe()


def counters_summary(results: Mapping) -> Optional[str]:
    """The line error counters of a run, in one sentence (module docstring)."""
    entries = [(c.get("id", "?"), c["line_counters"]) for c in results.get("cases") or ()
               if isinstance(c, Mapping) and isinstance(c.get("line_counters"), Mapping)]
    if not entries:
        return None
    read = [(cid, e) for cid, e in entries if e.get("available")]
    if not read:
        reasons = sorted({str(e.get("reason", "")) for _, e in entries if e.get("reason") != "the case did not run"})
        return "not available" + (f" ({'; '.join(reasons)})" if reasons else "")
    rose = [(cid, e["errors"]) for cid, e in read if e.get("errors")]
    if not rose:
        return f"read around {len(read)} case(s); no error counted"
    shown = "; ".join(f"{cid}: " + ", ".join(f"{n} {k.replace('_', ' ')}" for k, n in errs.items())
                      for cid, errs in rose[:5])
    more = f" and {len(rose) - 5} more" if len(rose) > 5 else ""
    return (f"rose in {len(rose)} of {len(read)} case(s) (their clauses INCONCLUSIVE: the line or the host "
            f"lost or garbled bytes): {shown}{more}")
