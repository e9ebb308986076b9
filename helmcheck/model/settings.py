"""The ``$ORWSET`` settings store (RH-SET-1, RH-SET-2, RH-RD-8).

Names are the §7 safety codes (``Sop`` … ``Sti``, case-sensitive) plus ``SafetyAction``. A
setting holds a state (0|1) and 0–3 text values; a write stores exactly what was written and is
answered like a read: ``$ACK,12,0,0,<setting>,<n>,<state>,<value>…`` where ``n`` counts the
fields after it, the state first.

Defaults (decision, spec open): every safety rule enabled (state 1, no values);
``SafetyAction`` state 1 with the profile's ``safety_action`` (``park`` unless the profile says
otherwise). The stored settings are echoed only: a rule written with state 0 still triggers
when the vehicle (or ``$OXFLT``) raises it, so a test extension can always raise a violation;
``SafetyAction``'s *value* decides the at-surface action (RH-SAF-4) whatever its state.
"""

from __future__ import annotations

from ..profile import SAFETY_CODES, Profile

__all__ = ["SettingsStore"]


class SettingsStore:
    """Setting name → (state, values). The mapping is never changed in place (a write makes a
    new one), so a copy shares it until either side writes."""

    __slots__ = ("_values",)

    def __init__(self, profile: Profile) -> None:
        self._values: dict[str, tuple[int, tuple[str, ...]]] = {c: (1, ()) for c in SAFETY_CODES}
        self._values["SafetyAction"] = (1, (profile.safety_action,))

    def copy(self) -> "SettingsStore":
        new = SettingsStore.__new__(SettingsStore)
        new._values = self._values  # shared: write() replaces, never mutates
        return new

    def read(self, name: str) -> tuple[int, tuple[str, ...]]:
        return self._values[name]

    def write(self, name: str, state: int, values: tuple[str, ...]) -> None:
        self._values = {**self._values, name: (state, tuple(values))}

    def reply_extra(self, name: str) -> tuple[str, ...]:
        """The ``$ACK,12`` tail for ``name``: setting, n, state, values (RH-RD-8)."""
        state, values = self._values[name]
        return (name, str(1 + len(values)), str(state), *values)

    @property
    def safety_action(self) -> str:
        values = self._values["SafetyAction"][1]
        return values[0] if values else "park"

    def as_dict(self) -> dict[str, tuple[int, tuple[str, ...]]]:
        return dict(self._values)
