"""Field syntax and ranges of each command, as the vehicle judges them (RH-ACK-3, RH-RD-9).

The grammar (``helmcheck.grammar``: ``remote_helm.lark`` for syntax, ``ranges.py`` for the
profile's bounds) is the one judge of field values. The model receives sentence *objects*,
which may have been built by hand, by Hypothesis, or parsed under another profile, so it asks
the grammar again about the object's canonical text: a command whose canonical form does not
read back as a valid sentence under the model's profile gets its "incorrect values" error.
:func:`field_error` answers that error or ``None``.
"""

from __future__ import annotations

from typing import Optional

from ..grammar import sentences as s
from ..grammar.codec import decode, format
from ..profile import SAFETY_CODES, Profile

__all__ = ["field_error", "SETTING_NAMES", "SAFETY_ACTIONS"]

#: ``$ORWSET`` setting names (RH-RD-8): the §7 safety codes plus ``SafetyAction``.
SETTING_NAMES = frozenset(SAFETY_CODES) | {"SafetyAction"}
SAFETY_ACTIONS = ("park", "srp")


#: Verdicts already given, keyed by (command, profile): backseats repeat themselves ($OSD polls,
#: servo refreshes), and the verdict of a frozen object under a frozen profile never changes.
_SEEN: dict = {}
_SEEN_MAX = 4096
#: The same, by the command object itself (``id`` → (command, profile, verdict)): a judge asks
#: about one decoded ``$OSD`` at every poll, and this skips hashing its fields each time.
_SAME: dict = {}


def field_error(cmd: s.Command, profile: Profile) -> Optional[int]:
    """The command's "incorrect values" error when a field is bad (RH-ACK-3), else ``None``."""
    if cmd.ERR is None:
        return None
    same = _SAME.get(id(cmd))
    if same is not None and same[0] is cmd and same[1] is profile:
        return same[2]
    try:
        key = (cmd, id(profile))
        hit = _SEEN.get(key)
    except TypeError:  # an unhashable field: certainly not a valid command
        return cmd.ERR
    if hit is not None:
        verdict = hit[1]
    else:
        try:
            raw = format(cmd)
        except (TypeError, ValueError, ArithmeticError, AttributeError):
            return cmd.ERR
        d = decode(raw, profile)
        verdict = cmd.ERR if (d.error is not None or type(d.sentence) is not type(cmd)) else None
        if len(_SEEN) >= _SEEN_MAX:
            _SEEN.clear()
        _SEEN[key] = (profile, verdict)  # holding the profile keeps its id from being reused
    if len(_SAME) >= _SEEN_MAX:
        _SAME.clear()
    _SAME[id(cmd)] = (cmd, profile, verdict)  # holding both keeps their ids from being reused
    return verdict
