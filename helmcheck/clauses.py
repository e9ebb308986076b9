"""The clause catalogue: every clause ID of the reference profile, read from the profile itself.

The normative contract is ``helmcheck/spec/reference-profile.md`` (a byte-for-byte copy of the
project's shared specification; ``tests/test_clauses.py`` fails if the two drift apart). This
module parses it once and gives each clause its ID, section, level (MUST or SHOULD), whether it
speaks to the vehicle or the backseat, and its requirement text. Reports, test-coverage checks and
certifiers all read clause texts from here, so no requirement text is ever copied by hand.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources

__all__ = ["Clause", "catalogue", "clause", "vehicle_clauses", "backseat_clauses", "SPEC_NAME"]

SPEC_NAME = "reference-profile.md"

_SECTION = re.compile(r"^##\s+(\d+b?)\.\s+(.*)$")
_ITEM = re.compile(r"^- \*\*(RH-[A-Z]+-\d+)\*\*\s*(.*)$")


@dataclass(frozen=True, slots=True)
class Clause:
    """One numbered clause of the reference profile."""

    id: str
    section: str  #: "1" … "9", or "8b"
    section_title: str
    text: str  #: the requirement as written (Markdown, one paragraph)
    level: str  #: "MUST" or "SHOULD"

    @property
    def family(self) -> str:
        """``RH-SRV-4`` → ``SRV``."""
        return self.id.split("-")[1]

    @property
    def role(self) -> str:
        """Who the clause binds: ``backseat`` (§9), ``reading`` (§8b) or ``vehicle``.

        §1 framing and §8 time bind both sides; they are listed as vehicle clauses, and the
        backseat certifier judges the backseat's framing under RH-BS-1/RH-BS-7.
        """
        if self.family == "BS":
            return "backseat"
        if self.family == "RD":
            return "reading"
        return "vehicle"


def _parse(text: str) -> dict[str, Clause]:
    clauses: dict[str, Clause] = {}
    section, title = "", ""
    current: list[str] | None = None
    cid = ""

    def flush() -> None:
        if current is not None:
            body = " ".join(s.strip() for s in current).strip()
            level = "SHOULD" if "(SHOULD)" in body else "MUST"
            clauses[cid] = Clause(cid, section, title, body, level)

    for line in text.splitlines():
        m = _SECTION.match(line)
        if m:
            flush()
            current = None
            section, title = m.group(1), m.group(2).strip()
            continue
        m = _ITEM.match(line)
        if m:
            flush()
            cid = m.group(1)
            current = [m.group(2)]
            continue
        if current is not None:
            if line.startswith("  ") and line.strip():
                current.append(line)
            else:
                flush()
                current = None
    flush()
    return clauses


@lru_cache(maxsize=1)
def catalogue() -> dict[str, Clause]:
    """All clauses, keyed by ID, in the order the profile lists them."""
    text = resources.files("helmcheck.spec").joinpath(SPEC_NAME).read_text(encoding="utf-8")
    return _parse(text)


def clause(cid: str) -> Clause:
    """The clause with this ID; ``KeyError`` naming the ID if the profile has none."""
    try:
        return catalogue()[cid]
    except KeyError:
        raise KeyError(f"no clause {cid!r} in {SPEC_NAME}") from None


def vehicle_clauses() -> list[Clause]:
    """Clauses a vehicle is certified against (§1–8, not the §8b readings)."""
    return [c for c in catalogue().values() if c.role == "vehicle"]


def backseat_clauses() -> list[Clause]:
    """Clauses a backseat is certified against (§9)."""
    return [c for c in catalogue().values() if c.role == "backseat"]
