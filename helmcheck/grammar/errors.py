"""Errors and findings of the wire layer, each tagged with the clause it enforces.

A :class:`SentenceError` says which clause a line breaks, where (1-based column), which field,
and — for a well-framed command of a known type — which ``$ACK`` a vehicle answers with
(RH-ACK-3: the command's own "incorrect values" error). Framing faults (RH-FRM-2/4/5/6/7) get no
``$ACK`` at all: a vehicle discards such lines silently.

``kind`` sorts errors for the backseat judge: ``framing`` (RH-BS-1), ``syntax`` and ``range``
(RH-BS-2). A :class:`Finding` is a SHOULD-level remark (lower-case checksum hex, bare LF) that
does not make a line invalid. A field error of a command whose fields could be told apart carries
the command read with its bad fields left out (``partial``), for a reader that takes a field the
profile leaves open another way (:mod:`helmcheck.model.readings`).
"""

from __future__ import annotations

from dataclasses import dataclass, field as _field
from typing import Any, Optional

__all__ = ["SentenceError", "Finding", "FRAMING", "SYNTAX", "RANGE"]

FRAMING = "framing"
SYNTAX = "syntax"
RANGE = "range"


@dataclass(eq=True, unsafe_hash=True)
class SentenceError(Exception):
    """A line that is not a valid sentence. ``str()`` is ``CLAUSE: message at column N``."""

    clause: str
    message: str
    column: Optional[int] = None
    kind: str = FRAMING
    sentence_id: Optional[str] = None  #: the ID when the frame was readable
    field: Optional[str] = None  #: the field's name for syntax/range errors
    ack_type: Optional[int] = None  #: the $ACK type a vehicle answers with, None = silent discard
    ack_err: Optional[int] = None  #: the error number in that $ACK
    value: Optional[str] = None  #: the field's text as sent, for a field error (``field`` names it)
    #: the command read with its bad fields as None (a field error only; not part of equality)
    partial: Any = _field(default=None, compare=False, hash=False, repr=False)

    def __str__(self) -> str:
        where = f" at column {self.column}" if self.column is not None else ""
        return f"{self.clause}: {self.message}{where}"

    @property
    def answered(self) -> bool:
        """True when a vehicle must answer this line with an error ``$ACK`` (RH-ACK-3)."""
        return self.ack_type is not None

    def as_dict(self) -> dict:
        return {"clause": self.clause, "message": self.message, "column": self.column,
                "kind": self.kind, "field": self.field, "ack_type": self.ack_type,
                "ack_err": self.ack_err, "value": self.value, "text": str(self)}


@dataclass(frozen=True)
class Finding:
    """A SHOULD-level remark about a valid line (e.g. RH-BS-7 lower-case hex)."""

    clause: str
    message: str
    column: Optional[int] = None

    def __str__(self) -> str:
        where = f" at column {self.column}" if self.column is not None else ""
        return f"{self.clause}: {self.message}{where}"

    def as_dict(self) -> dict:
        return {"clause": self.clause, "message": self.message, "column": self.column, "text": str(self)}
