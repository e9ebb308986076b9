"""The backseat's findings in its own words: what it sent, against the rule of §1–6 it broke, quoted.

A backseat clause (RH-BS-1, RH-BS-2, RH-BS-7) is broken by a line whose framing or field the
grammar refused; the grammar names the rule in the vehicle's terms (``RH-SRV-2: $OMS timeout 3000
is outside [1, 120]``, ``RH-ACK-3: $OMP actuators: unexpected …`` — what a vehicle must refuse).
The backseat's reason leads with what it sent and quotes the text of the profile that sets the
form or the range, naming where it stands: ``$OMS timeout 3000 is outside [1, 120]; §4 gives it
“timeout integer [1,120] s” (RH-SRV-2)``. The field's clause is the one the vehicle judge books a
refused field on (:data:`helmcheck.judge.vehicle.blame.FIELD_CLAUSE`), else the range check's own.
Pure: reads the clause catalogue, nothing else.
"""

from __future__ import annotations

import re
from functools import lru_cache
from typing import Optional

from ...clauses import catalogue
from ...grammar.errors import RANGE, SentenceError
from ..vehicle.blame import FIELD_CLAUSE

__all__ = ["field_words", "framing_words", "discard_words", "finding_words", "quote"]

_QUOTE_MAX = 140
_SPLIT = re.compile(r"(?<=[.;])\s+|,\s+(?![^(\[]*[)\]])")
#: How the profile's text names a field where its name is not the field's own.
_ALIAS = {"ignore_gps": "flags", "ignore_sounder": "flags", "calibrate_pressure": "flags",
          "mission_type": "flags", "actuators": "field 1", "reserved": "field 2", "depth1": "depths",
          "depth2": "depths", "park_s": "park time", "waypoint": "n"}
#: §1 rules that define the form (quoted); the others say what a vehicle does with a line that
#: breaks them, so the backseat's own clause (RH-BS-1) is quoted instead.
_DEFINING = ("RH-FRM-1", "RH-FRM-2", "RH-FRM-6", "RH-FRM-7", "RH-RD-16")


def _find(sentences: list[str], word: str) -> Optional[str]:
    pattern = re.compile(rf"\b{re.escape(word)}\b")
    for sentence in sentences:
        bare = re.sub(r"<[^>]*>", "", sentence).lower()
        if not pattern.search(bare):
            continue
        for piece in (p.strip(" .;") for p in _SPLIT.split(sentence)):
            if piece and "<" not in piece and pattern.search(piece.lower()):
                return piece.split(": ", 1)[1] if ": " in piece and not pattern.search(
                    piece.split(": ", 1)[0].lower()) else piece
        return sentence
    return None


@lru_cache(maxsize=256)
def _quote(cid: str, field: str) -> tuple[str, bool]:
    c = catalogue().get(cid)
    if c is None:
        return "", False
    text = re.sub(r"\s*\[D[^\]]*\]", "", c.text).replace("`", "")
    sentences = [x.strip() for x in re.split(r"(?<=\.)\s+", text) if x.strip()]
    best, hit = (sentences[0] if sentences else text), False
    word = _ALIAS.get(field, field.replace("_", " ")).lower()
    if word:
        found = _find(sentences, word)
        if found is not None:
            best, hit = found, True
    best = best.rstrip(" .;")
    return (best if len(best) <= _QUOTE_MAX else best[:_QUOTE_MAX - 1].rstrip() + "…"), hit


def quote(cid: str, field: str = "") -> str:
    """The words of clause ``cid`` that speak of ``field`` (the piece of its sentence that names
    the field), else its first sentence; Markdown marks dropped, at most 140 characters."""
    return _quote(cid, field)[0]


def _where(cid: str) -> str:
    c = catalogue().get(cid)
    return f"§{c.section}" if c is not None else "the profile"


def field_words(err: SentenceError) -> str:
    """RH-BS-2's reason for a field the grammar or a range check refused (module docstring)."""
    sid = err.sentence_id or ""
    field = err.field or ""
    clause: Optional[str] = FIELD_CLAUSE.get((sid, field))
    if clause is None and err.kind == RANGE and err.clause in catalogue():
        clause = err.clause
    message = err.message
    if err.kind != RANGE and field and err.value is not None:
        message = f"${sid} {field.replace('_', ' ')} {err.value!r} does not read as the field"
    if clause is None:
        refused = f"; a vehicle refuses it with err {err.ack_err} (RH-ACK-3)" if err.ack_err is not None else ""
        return f"{message}: not a command as §4–6 give it{refused}"
    words, hit = _quote(clause, field)
    if not hit and err.clause != clause and err.clause in catalogue():
        reading, found = _quote(err.clause, field)
        if found:  # the reading that spells the clause's range out (RH-RD-6 for RH-MSN-2's flags)
            return (f"{message}; {_where(clause)} ({clause}) as {_where(err.clause)} reads it: “{reading}” "
                    f"({err.clause})")
    return f"{message}; {_where(clause)} gives it “{words}” ({clause})"


def framing_words(err: SentenceError) -> str:
    """RH-BS-1's reason for a line §1 does not allow: what is wrong, then the rule, quoted."""
    where = f" (byte {err.column})" if err.column is not None else ""
    if err.clause in _DEFINING:
        return f"{err.message}{where}; §1 says “{quote(err.clause)}” ({err.clause})"
    return f"{err.message}{where}: RH-BS-1 asks “{quote('RH-BS-1')}” (§1, {err.clause})"


def discard_words(length: int, clause: str, reason: str) -> str:
    """RH-BS-1's reason for bytes the framer set aside (noise, a torn or an overlong line)."""
    if clause in _DEFINING:
        return f"{length} byte(s) that are no sentence ({reason}); §1 says “{quote(clause)}” ({clause})"
    return f"{length} byte(s) that are no sentence ({reason}): RH-BS-1 asks “{quote('RH-BS-1')}” ({clause})"


def finding_words(message: str) -> str:
    """RH-BS-7's reason for a line it should have written otherwise."""
    return re.sub(r"\s*\(RH-BS-7\)\s*$", "", message) + ": RH-BS-7 asks for upper-case checksum hex and CR LF"
