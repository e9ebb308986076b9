"""Did you mean …: the known words closest to a mistyped one.

A usage error about an unknown word (a subcommand, a profile key) names the closest known ones
instead of listing them all: :func:`close_matches` finds them (by :mod:`difflib`'s ratio: the
closest and those nearly as close; else a known word that starts with or contains the given
one), :func:`did_you_mean` says it.
"""

from __future__ import annotations

import difflib
from typing import Iterable

__all__ = ["close_matches", "did_you_mean", "CUTOFF", "BAND"]

#: How alike (:class:`difflib.SequenceMatcher` ratio) a known word must be to be named …
CUTOFF = 0.75
#: … and how much less alike than the closest one it may be.
BAND = 0.1


def _squash(word: str) -> str:
    return word.lower().replace("-", "").replace("_", "").replace(".", "")


def close_matches(word: str, known: Iterable[str], n: int = 3) -> list[str]:
    """Up to *n* of *known* closest to *word*, closest first (``[]``: none is close). Case,
    ``-``, ``_`` and ``.`` are not counted: ``checklog`` is ``check-log``."""
    known = list(known)
    squashed = {_squash(k): k for k in known}
    w = _squash(word)
    if not w:
        return []
    if w in squashed:
        return [squashed[w]]
    ratios = sorted(((difflib.SequenceMatcher(None, w, s).ratio(), s) for s in squashed), reverse=True)
    best = ratios[0][0] if ratios else 0.0
    # the closest, and those nearly as close (a tie is named, a distant runner-up is not)
    found = [squashed[s] for r, s in ratios[:n] if r >= CUTOFF and r >= best - BAND]
    if not found:  # a prefix or a part of a longer word (``name`` of ``vehicle_name``)
        found = [k for s, k in squashed.items() if len(w) >= 3 and (s.startswith(w) or w in s)][:n]
    return found


def did_you_mean(word: str, known: Iterable[str], n: int = 3) -> str:
    """``" (did you mean 'x'?)"`` or ``" (did you mean 'x' or 'y'?)"``; ``""`` when nothing is close."""
    close = close_matches(word, known, n)
    if not close:
        return ""
    return " (did you mean " + " or ".join(f"'{c}'" for c in close) + "?)"
