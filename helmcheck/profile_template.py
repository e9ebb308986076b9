"""A commented profile for a real vehicle to fill in: the text ``helmcheck profile init`` writes.

Everything in it comes from :class:`~helmcheck.profile.Profile` itself — the keys are its
fields (:func:`~helmcheck.profile.profile_keys`), the comments each field's documentation
(its metadata: what it is, its clauses, ``FILL IN`` for a value only the vehicle can give),
the allowed values the rules the loader checks (:func:`~helmcheck.profile.key_rule`), and the
values the defaults, or the field's safe value for a real vehicle where it has one (no
violation raised, no mission assumed but the test mission). Nothing is copied by hand, so a new
key appears in the template the day it is added to the dataclass.

:func:`render` returns the text; :func:`check` loads it back the way ``--profile`` will
(``ProfileError`` if it would not). Values given with ``prefill`` (``--set``, ``--name``, …)
replace the starting value and drop that key's ``FILL IN`` mark.
"""

from __future__ import annotations

import dataclasses
import textwrap
import tomllib
from typing import Any, Mapping

from .profile import BenchSafety, Profile, key_rule, profile_from_dict, profile_keys
from .profile_toml import toml_value

__all__ = ["GROUPS", "render", "check", "starting_values", "TABLE"]

#: Sections of the file, in order: (group of a field's metadata, heading).
GROUPS = (
    ("identity", "What is tested: shown in every report, never judged"),
    ("link", "The serial line and the vehicle's clock"),
    ("missions", "Missions present on the vehicle, started by name"),
    ("safety", "Safety violations (RH-SAF-*) and the SafetyAction"),
    ("protocol", "Protocol claims: the rh5 defaults; change a key only where the vehicle differs"),
    ("backseat", "Judging a backseat (certify backseat)"),
)
#: The one table key: written last, as ``[bench_safety]``.
TABLE = "bench_safety"
WIDTH = 99

HEADER = """\
helmcheck profile: what the vehicle under test claims (reference profile rh5, §10).
Written by `helmcheck profile init`. It loads as it is, and its starting values are safe on the
bench: no safety violation is raised (violation_trigger = "none"), no mission is assumed on the
vehicle but the test mission, and bench safety holds motor and speed down. Give a value to
every key marked FILL IN before a run; each of them says what to put. A key you delete takes
the rh5 default.
  helmcheck certify vehicle --port /dev/ttyUSB0 --profile THIS-FILE --time-scale 1"""


def starting_values(prefill: Mapping[str, Any] = ()) -> dict[str, Any]:
    """Every key's value for a new file (``bench_safety.*`` flattened), *prefill* applied."""
    out: dict[str, Any] = {}
    for f in profile_keys():
        if f.name == TABLE:
            for g in dataclasses.fields(BenchSafety):
                out[f"{TABLE}.{g.name}"] = g.metadata.get("real", g.default)
        else:
            out[f.name] = f.metadata.get("real", f.default)
    out.update(dict(prefill))
    return out


_KEEP = (">= ", "> ", "<= ", "at most ", "at least ", "one of ")  #: never broken after


def _comment(text: str) -> list[str]:
    for phrase in _KEEP:
        text = text.replace(phrase, phrase.replace(" ", "\0"))
    lines = textwrap.wrap(text, WIDTH - 2, initial_indent="# ", subsequent_indent="# ",
                          break_on_hyphens=False, break_long_words=False)
    return [ln.replace("\0", " ") for ln in lines]


def _value(key: str, value: Any, meta: Mapping[str, Any]) -> str:
    if meta.get("hex") and isinstance(value, int) and not isinstance(value, bool):
        return f"0x{value:02X}"
    return toml_value(value)


def _entry(key: str, f: dataclasses.Field, value: Any, prefilled: bool) -> list[str]:
    """One key: its comment (what, clauses, values, default, FILL IN) and its line."""
    meta = f.metadata
    doc = meta.get("doc", "")
    text = doc[:1].upper() + doc[1:]
    if meta.get("clause"):
        text += f" ({meta['clause']})"
    text += "."
    rule = key_rule(key)
    if rule:
        text += f" Values: {rule}."
    default = f.default if f.default is not dataclasses.MISSING else None
    if default not in (None, "") and default != value:
        text += f" Default: {_value(key, default, meta)}."
    lines = _comment(text)
    if meta.get("fill") and not prefilled:
        lines += _comment(f"FILL IN: {meta['fill']}.")
    lines.append(f"{f.name} = {_value(key, value, meta)}")
    return lines


EMULATOR_HEADER = """\
helmcheck profile of the built-in emulator (`helmcheck emulate`): what it claims, every key.
Written by `helmcheck profile init --emulator`: the $OXFLT test extension (so the lockout
clauses are judged) and the missions the emulator ships (short.mis, srp.mis); nothing to fill in.
  helmcheck emulate --port pty --time-scale 20 &
  helmcheck certify vehicle --port /dev/pts/N --time-scale 20 --profile THIS-FILE"""


def render(prefill: Mapping[str, Any] = (), *, emulator: bool = False) -> str:
    """The commented TOML text (module docstring). *prefill* maps keys (``bench_safety.x`` for
    the table's) to values. *emulator*: the file describes the built-in emulator (its own
    header, no FILL IN marks: the caller prefills its profile)."""
    prefill = dict(prefill)
    values = starting_values(prefill)
    out = ["# " + ln if ln else "#" for ln in (EMULATOR_HEADER if emulator else HEADER).splitlines()]
    if emulator:
        prefill.update({k: None for k in values if k not in prefill})  # nothing left to fill in
    fields = [f for f in profile_keys() if f.name != TABLE]
    for group, heading in GROUPS:
        mine = [f for f in fields if f.metadata.get("group") == group]
        if not mine and group != "safety":
            continue
        out += ["", f"# ---- {heading} " + "-" * max(3, WIDTH - 12 - len(heading))]
        for f in mine:
            out.append("")
            out += _entry(f.name, f, values[f.name], f.name in prefill)
        if group == "safety":
            out += ["", "# Bench safety: the [bench_safety] table at the end of the file."]
    table = next(f for f in profile_keys() if f.name == TABLE)
    out += ["", f"# ---- [{TABLE}]: {table.metadata.get('doc', '')} ".ljust(WIDTH, "-"), f"[{TABLE}]"]
    for i, g in enumerate(dataclasses.fields(BenchSafety)):
        key = f"{TABLE}.{g.name}"
        out += ([""] if i else []) + _entry(key, g, values[key], key in prefill)
    return "\n".join(out) + "\n"


def check(text: str, where: str = "<profile init>") -> Profile:
    """Load *text* as ``--profile`` would; :class:`~helmcheck.profile.ProfileError` if it does not."""
    return profile_from_dict(tomllib.loads(text), where=where)
