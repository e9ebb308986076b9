"""The profile as TOML text: a small, deterministic emitter for :class:`~helmcheck.profile.Profile`.

Every run directory holds the exact profile its judges used as ``profile.toml``, written by
:func:`emit_profile`; ``helmcheck verify`` reads it back with :func:`helmcheck.profile.load_profile`
and re-judges the wire log under it. So the emitter has one contract, tested as a property:
``load_profile(emit_profile(p)) == p`` for every valid profile, except the ``name`` field (where
the profile came from; not a TOML key).

The output is deterministic — the same profile always gives the same bytes, hence the same
SHA-256 — because every key is written, in the dataclass's field order, with one spelling per
value:

* strings as TOML basic strings, escaping ``"``, ``\\`` and control characters (``\\uXXXX``);
  every other character is written as itself (the file is UTF-8);
* booleans ``true``/``false``; integers in decimal; floats with Python's shortest round-trip
  ``repr`` (always with a ``.`` or an exponent, so they stay floats);
* tuples as one-line arrays; :class:`~helmcheck.profile.BenchSafety` as the ``[bench_safety]``
  table, last.

``violation_trigger = ""`` means "derived from ``fault_injection``" (:attr:`Profile.trigger`) and
is not a value a file may hold, so it is left out; every other key is written, defaults included,
so the file means the same whatever a later version's defaults are.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

from .profile import BenchSafety, Profile

__all__ = ["emit_profile", "toml_value", "HEADER"]

HEADER = "# helmcheck profile: the resolved profile a run used (every key written)\n"


def _string(value: str) -> str:
    out = ['"']
    for ch in value:
        code = ord(ch)
        if ch == '"':
            out.append('\\"')
        elif ch == "\\":
            out.append("\\\\")
        elif code < 0x20 or code == 0x7F:
            out.append(f"\\u{code:04X}")
        else:
            out.append(ch)
    out.append('"')
    return "".join(out)


def toml_value(value: Any) -> str:
    """One TOML value for a profile field's value (``ValueError`` for anything else)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            raise ValueError(f"a profile number must be finite, not {value!r}")
        text = repr(value)
        return text if any(c in text for c in ".eE") else text + ".0"
    if isinstance(value, str):
        return _string(value)
    if isinstance(value, (tuple, list)):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    raise ValueError(f"no TOML form for a profile value of type {type(value).__name__}")


def emit_profile(profile: Profile) -> str:
    """The TOML text of *profile* (module docstring); ``load_profile`` of it gives *profile* back."""
    lines = [HEADER.rstrip("\n")]
    tables: list[tuple[str, Any]] = []
    for f in dataclasses.fields(profile):
        if f.name == "name":
            continue
        value = getattr(profile, f.name)
        if f.name == "violation_trigger" and value == "":
            continue
        if isinstance(value, BenchSafety):
            tables.append((f.name, value))
            continue
        lines.append(f"{f.name} = {toml_value(value)}")
    for name, table in tables:
        lines.append("")
        lines.append(f"[{name}]")
        for f in dataclasses.fields(table):
            lines.append(f"{f.name} = {toml_value(getattr(table, f.name))}")
    return "\n".join(lines) + "\n"
