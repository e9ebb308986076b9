"""Records the model keeps for its owner: logged rows (RH-LOG-2) and ``$OPOS`` outcomes (RH-POS-2)."""

from __future__ import annotations

from dataclasses import dataclass

from ..grammar import sentences as s

__all__ = ["LogRow", "OposRecord"]


@dataclass(frozen=True, slots=True)
class LogRow:
    """One accepted ``$OLOGD``: when, the labels in force and the values (RH-LOG-2)."""

    at: float
    labels: tuple[str, ...]
    values: tuple[str, ...]


@dataclass(frozen=True, slots=True)
class OposRecord:
    """One accepted ``$OPOS`` and whether its position and speed were applied (RH-POS-2)."""

    at: float
    command: s.OPOS
    position_applied: bool
