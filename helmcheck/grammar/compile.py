"""Loads ``remote_helm.lark`` and derives everything else from it.

Two things come out of the one grammar file:

1. ``LARK``: the Lark LALR parser — the reference reading of every sentence.
2. ``SPECS``: for every sentence rule, a Python regular expression *compiled from the grammar's
   own rule tree* (the fast path), plus the field layout that turns a match into a typed
   sentence object. The grammar is regular (no recursion), so this translation is exact;
   ``tests/test_grammar_fastpath.py`` proves with hypothesis that both readings agree on valid
   and mutated input.

Naming conventions the translation relies on are written at the top of the grammar file.
The translation itself is :mod:`.derive`, which reads the grammar with Lark; its result is
checked in as :mod:`.derived`, and :func:`specs` compiles that while the grammar's digest
matches, so the fast path neither imports Lark nor derives anything at start-up. Lark is
imported when it is asked for: the reference engine, locating a syntax error, the derivation.
"""

from __future__ import annotations

import contextlib
import os
import re
import typing
import zlib
from dataclasses import dataclass, fields
from decimal import Decimal
from functools import lru_cache
from pathlib import Path
from typing import Any, Callable, Optional

from . import sentences as S

__all__ = ["grammar_text", "lark_parser", "specs", "SentenceSpec", "FieldSpec", "build_sentence",
           "sentence_classes_by_rule"]

GRAMMAR_FILE = "remote_helm.lark"


@lru_cache(maxsize=1)
def grammar_text() -> str:
    """The grammar file's text: beside this module, or through importlib.resources where the
    package is not a directory (a zip); the direct read spares every start-up that import."""
    try:
        with open(os.path.join(os.path.dirname(__file__), GRAMMAR_FILE), encoding="utf-8") as f:
            return f.read()
    except OSError:
        from importlib import resources

        return resources.files("helmcheck.grammar").joinpath(GRAMMAR_FILE).read_text(encoding="utf-8")


def grammar_digest(text: str) -> str:
    """CRC-32 of the grammar's text: the tables in :mod:`.derived` are for that grammar only.
    (It tells an edited grammar from the one the tables were made from; the suite checks the
    tables against the derivation itself. CRC-32, not a cryptographic hash: loading OpenSSL
    for it would cost more start-up than the tables save.)"""
    return f"{zlib.crc32(text.encode('utf-8')):08x}"


#: The reference parser's options (:func:`lark_parser`).
_LARK_OPTIONS = {"parser": "lalr", "start": ["line", "body"], "maybe_placeholders": True}


def lark_cache_path(text: str) -> Path:
    """Where the built reference parser is kept between processes: the user's cache directory
    (``$XDG_CACHE_HOME`` or ``~/.cache``), ``helmcheck/``, a file named for the grammar's text, the
    parser's options and the Lark and Python versions (SHA-256). Lark checks its cache's grammar
    too, but one file for all would be rebuilt and rewritten each time two checkouts of different
    grammars (or two interpreters) take turns: a file each keeps both built."""
    import hashlib
    import sys

    import lark

    key = hashlib.sha256(f"{text}\0{sorted(_LARK_OPTIONS.items())}\0{lark.__version__}\0{sys.version_info[:2]}"
                         .encode("utf-8")).hexdigest()[:24]
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "helmcheck" / f"lark-{key}.pickle"


@lru_cache(maxsize=1)
def lark_parser():
    """The reference parser (LALR, contextual lexer) with ``line`` and ``body`` start rules.

    Built on first use only (the Lark engine, locating an error, the property tests): the fast
    path needs just the rule definitions (:func:`grammar_defs`). Building its tables takes most of a
    second of CPU, so the parser built is kept (:func:`lark_cache_path`, with its grammar, which the
    property tests' strategy reads) and loaded by the next process; a cache that cannot be read or
    written is built without.
    """
    from lark import Lark

    text = grammar_text()
    path = lark_cache_path(text)
    with contextlib.suppress(OSError):
        path.parent.mkdir(parents=True, exist_ok=True, mode=0o700)
    # Lark's own cache: a file whose first line is the digest of the grammar and options it was
    # built from; one that is partial, foreign or unreadable is built again (and written again)
    return Lark(text, cache=str(path), cache_grammar=True, **_LARK_OPTIONS)


@lru_cache(maxsize=1)
def grammar_defs():
    """The grammar's rule and terminal definitions, loaded without building a parser."""
    from lark.load_grammar import load_grammar

    grammar, _used = load_grammar(grammar_text(), GRAMMAR_FILE, None, False)
    return grammar


@lru_cache(maxsize=None)
def type_hints(cls: type) -> dict[str, Any]:
    """``typing.get_type_hints(cls)``, evaluated once per class (the annotations are strings)."""
    return typing.get_type_hints(cls)


def sentence_classes_by_rule() -> dict[str, type[S.Sentence]]:
    return {cls.RULE: cls for cls in S.ALL_CLASSES}


# --------------------------------------------------------------------------- field layout

@dataclass(frozen=True)
class FieldSpec:
    """How one grammar field rule fills one attribute of a sentence class."""

    rule: str  #: grammar rule name (also the regex group name)
    attr: str  #: sentence class attribute
    kind: str  #: "scalar" | "opt" | "items" | "flag"
    convert: Callable[[str], Any]  #: text of one terminal -> typed value
    item_regex: Optional[re.Pattern] = None  #: for "items": one element, groups per terminal
    item_converts: tuple = ()  #: for "items": converter per group


@dataclass(frozen=True)
class SentenceSpec:
    """A sentence rule compiled: its class, the body regex and the field layout."""

    rule: str
    cls: type
    regex: re.Pattern
    fields: tuple[FieldSpec, ...]


def _park(text: str) -> int:
    return int(text[1:])


#: The converters a field row names (:mod:`.derived`): the text of one terminal -> its value
#: (the types themselves where they convert: a builder calls one per field of every line).
CONVERTERS: dict[str, Callable[[str], Any]] = {"decimal": Decimal, "park": _park, "int": int, "str": str,
                                                "bool": bool}


def _rows() -> dict:
    """The derived tables: :mod:`.derived` while it was made from this grammar, else derived now."""
    from . import derived

    if getattr(derived, "GRAMMAR_DIGEST", None) == grammar_digest(grammar_text()):
        return derived.RULES
    from .derive import derive_rows  # the grammar changed since `helmcheck docs`: Lark reads it

    return derive_rows()


@lru_cache(maxsize=1)
def specs() -> dict[str, SentenceSpec]:
    """Every sentence rule of the grammar, compiled. Keyed by rule name."""
    by_rule = sentence_classes_by_rule()
    out: dict[str, SentenceSpec] = {}
    for rule, (rx, rows) in _rows().items():
        layout = tuple(FieldSpec(fr, attr, kind, CONVERTERS[conv], re.compile(item) if item else None,
                                 tuple(CONVERTERS[c] for c in item_convs))
                       for fr, attr, kind, conv, item, item_convs in rows)
        out[rule] = SentenceSpec(rule, by_rule[rule], re.compile(rx), layout)
    return out


# --------------------------------------------------------------------------- building objects

def _sub_sentence_attrs(cls: type) -> dict[str, type]:
    hints = type_hints(cls)
    subs = {}
    for name, ann in hints.items():
        if typing.get_origin(ann) is typing.Union:
            for a in typing.get_args(ann):
                if isinstance(a, type) and issubclass(a, S.Sentence):
                    subs[name] = a
    return subs


def build_sentence(spec: SentenceSpec, raw: dict[str, Any]) -> S.Sentence:
    """Make the typed object from raw field texts.

    ``raw`` maps field rule name to: the terminal's text (scalar), the text including its
    leading separator (opt), the whole repeated region (items), or ``None`` when absent.
    """
    kwargs: dict[str, Any] = {}
    for f in spec.fields:
        text = raw.get(f.rule)
        if f.kind == "flag":
            kwargs[f.attr] = text is not None
        elif text is None:
            continue
        elif f.kind == "scalar":
            kwargs[f.attr] = f.convert(text)
        elif f.kind == "opt":
            body = text[1:]
            kwargs[f.attr] = f.convert(body) if (body or f.convert is str) else None
        else:
            items = []
            for m in f.item_regex.finditer(text):
                vals = tuple(("" if g is None else conv(g)) for g, conv in zip(m.groups(), f.item_converts))
                items.append(vals if len(vals) > 1 else vals[0])
            kwargs[f.attr] = tuple(items)
    cls = spec.cls
    for attr, sub in _SUBS.get(cls, {}).items():
        sub_spec = _SPEC_BY_CLASS[sub]
        sub_raw = {f.rule: raw.get(f.rule) for f in sub_spec.fields}
        if any(v is not None for v in sub_raw.values()):
            sub_obj = build_sentence(sub_spec, sub_raw)
            for f in sub_spec.fields:
                kwargs.pop(f.attr, None)
            kwargs[attr] = sub_obj
    # A field the grammar left out ("[field]" not taken) is "" when it is text, else None.
    for attr, is_text in _REQUIRED.get(cls, ()):
        if attr not in kwargs:
            kwargs[attr] = "" if is_text else None
    return cls(**kwargs)


_SUBS: dict[type, dict[str, type]] = {}
_SPEC_BY_CLASS: dict[type, SentenceSpec] = {}
_REQUIRED: dict[type, tuple[tuple[str, bool], ...]] = {}


def _init_tables() -> None:
    from dataclasses import MISSING

    for spec in specs().values():
        _SPEC_BY_CLASS[spec.cls] = spec
        subs = _sub_sentence_attrs(spec.cls)
        if subs:
            _SUBS[spec.cls] = subs
        hints = type_hints(spec.cls)
        _REQUIRED[spec.cls] = tuple(
            (f.name, hints[f.name] is str)
            for f in fields(spec.cls)
            if f.default is MISSING and f.default_factory is MISSING
        )


_init_tables()


# --------------------------------------------------------------------------- fast builders

_TEXT_ITEMS = (str,)  #: the converters of items kept as their text

def _items(f: FieldSpec, text: Optional[str]) -> tuple:
    if not text:
        return ()
    convs = f.item_converts
    if convs == _TEXT_ITEMS and f.item_regex.groups == 1:
        return tuple(f.item_regex.findall(text))  # its "" is an absent group's "" below too
    out = []
    single = len(convs) == 1
    for m in f.item_regex.finditer(text):
        if single:
            g = m.group(1)
            out.append("" if g is None else convs[0](g))
        else:
            out.append(tuple(("" if g is None else c(g)) for g, c in zip(m.groups(), convs)))
    return tuple(out)


def _builder_args(spec: SentenceSpec, index: dict, env: dict, tag: str) -> list[str]:
    """Source of the field values of ``spec.cls``, in field order, from ``g0``, ``g1``, … (the
    groups of a match whose group numbers are ``index``); embedded sentences are built from the
    same groups."""
    cls = spec.cls
    by_attr = {f.attr: f for f in spec.fields}
    required = dict(_REQUIRED.get(cls, ()))
    subs = _SUBS.get(cls, {})
    hints = type_hints(cls)
    args = []
    for i, fld in enumerate(fields(cls)):
        name, k = fld.name, f"{tag}_{i}"
        if name in subs:
            sub_spec = _SPEC_BY_CLASS[subs[name]]
            first = index[sub_spec.fields[0].rule] - 1
            env[f"cls{k}"] = sub_spec.cls
            sub_args = ", ".join(_builder_args(sub_spec, index, env, k))
            args.append(f"(cls{k}({sub_args}) if g{first} is not None else None)")
            continue
        f = by_attr.get(name)
        if f is None:
            args.append(repr(fld.default))
            continue
        env[f"c{k}"] = f.convert
        conv = f"c{k}" if f.convert is not str else ""
        g = f"g{index[f.rule] - 1}"
        if f.kind == "flag":
            args.append(f"({g} is not None)")
        elif f.kind == "items":
            env[f"f{k}"] = f
            args.append(f"_items(f{k}, {g})")
        elif f.kind == "opt":
            empty = "''" if f.convert is str else "None"
            args.append(f"(None if (v{k} := {g}) is None else ({conv}(v{k}[1:]) if len(v{k}) > 1 else {empty}))")
        elif name in required and typing.get_origin(hints[name]) is not typing.Union:
            # required and never None: the grammar always supplies it (text may be empty)
            args.append(f"({g} or '')" if f.convert is str else f"{conv}({g})")
        else:
            absent = ("''" if required[name] else "None") if name in required else repr(fld.default)
            args.append(f"(({conv}(v{k})) if (v{k} := {g}) is not None else {absent})")
    return args


@lru_cache(maxsize=None)
def fast_builder(rule: str) -> Callable[[re.Match], S.Sentence]:
    """A function ``match -> sentence`` generated from the rule's field layout.

    It does what :func:`build_sentence` does, without interpreting the layout per line: the
    fast path calls it once per line. ``tests/test_grammar_roundtrip.py`` checks both agree.
    """
    spec = specs()[rule]
    cls = spec.cls
    env: dict[str, Any] = {"_items": _items, "_new": object.__new__, "cls": cls}
    args = _builder_args(spec, spec.regex.groupindex, env, "")
    # The object is filled through its slot descriptors, as the frozen dataclass __init__ would
    # do field by field, at half the cost (the classes have no __post_init__ to skip).
    # The groups are unpacked into locals once: reading a local is cheaper than indexing a tuple.
    n = spec.regex.groups
    lines = ["def build(m):", *([f"    {''.join(f'g{i}, ' for i in range(n))}= m.groups()"] if n else []),
             "    o = _new(cls)"]
    for i, (f, expr) in enumerate(zip(fields(cls), args)):
        env[f"set{i}"] = getattr(cls, f.name).__set__
        lines.append(f"    set{i}(o, {expr})")
    lines.append("    return o")
    exec(compile("\n".join(lines) + "\n", f"<builder {rule}>", "exec"), env)
    return env["build"]
