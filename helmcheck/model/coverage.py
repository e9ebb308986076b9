"""Which clauses a body of tests names: the helper behind the model's clause-coverage test.

A test names a clause by writing its ID with ``_`` for ``-`` (``test_RH_SRV_4_…``) or as is
(``"RH-SRV-4"``) anywhere in its source. :func:`vehicle_clause_ids` lists the clauses the
reference model is answerable for: §2–8 of the profile, families ACK OUT INT SRV PRM JW PK OMW
MSN POS OSD LOG SET DVL SAF TIM (framing, §1, belongs to the grammar and the emulator).
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Iterable

from ..clauses import catalogue

__all__ = ["MODEL_FAMILIES", "vehicle_clause_ids", "clause_coverage"]

MODEL_FAMILIES = ("ACK", "OUT", "INT", "SRV", "PRM", "JW", "PK", "OMW", "MSN", "POS", "OSD", "LOG",
                  "SET", "DVL", "SAF", "TIM")
_SECTIONS = ("2", "3", "4", "5", "6", "7", "8")


def vehicle_clause_ids() -> list[str]:
    """The clause IDs of §2–8 that bind the vehicle, in profile order."""
    return [c.id for c in catalogue().values()
            if c.section in _SECTIONS and c.family in MODEL_FAMILIES]


def clause_coverage(files: Iterable[Path], ids: Iterable[str]) -> dict[str, list[str]]:
    """Clause ID → names of the files that mention it (``RH_X_N`` or ``RH-X-N``)."""
    texts = {Path(f).name: Path(f).read_text(encoding="utf-8") for f in files}
    out: dict[str, list[str]] = {}
    for cid in ids:
        pat = re.compile(re.escape(cid).replace(r"\-", "[-_]") + r"(?!\d)")
        out[cid] = [name for name, text in texts.items() if pat.search(text)]
    return out
