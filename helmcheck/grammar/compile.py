"""Loads ``remote_helm.lark`` and derives everything else from it.

Two things come out of the one grammar file:

1. ``LARK``: the Lark LALR parser — the reference reading of every sentence.
2. ``SPECS``: for every sentence rule, a Python regular expression *compiled from the grammar's
   own rule tree* (the fast path), plus the field layout that turns a match into a typed
   sentence object. The grammar is regular (no recursion), so this translation is exact;
   ``tests/test_grammar_fastpath.py`` proves with hypothesis that both readings agree on valid
   and mutated input.

Naming conventions the translation relies on are written at the top of the grammar file.
"""

from __future__ import annotations

import re
import typing
from dataclasses import dataclass, fields
from decimal import Decimal
from functools import lru_cache
from importlib import resources
from typing import Any, Callable, Optional

from lark import Lark, Token, Tree
from lark.grammar import NonTerminal, Terminal

from . import sentences as S

__all__ = ["grammar_text", "lark_parser", "specs", "SentenceSpec", "FieldSpec", "build_sentence",
           "sentence_classes_by_rule"]

GRAMMAR_FILE = "remote_helm.lark"
_NONCAPTURING = re.compile(r"(?<!\\)\((?!\?)")


@lru_cache(maxsize=1)
def grammar_text() -> str:
    return resources.files("helmcheck.grammar").joinpath(GRAMMAR_FILE).read_text(encoding="utf-8")


@lru_cache(maxsize=1)
def lark_parser() -> Lark:
    """The reference parser (LALR, contextual lexer) with ``line`` and ``body`` start rules.

    Built on first use only (the Lark engine, locating an error, the property tests): the fast
    path needs just the rule definitions (:func:`grammar_defs`).
    """
    return Lark(grammar_text(), parser="lalr", start=["line", "body"], maybe_placeholders=True)


@lru_cache(maxsize=1)
def grammar_defs():
    """The grammar's rule and terminal definitions, loaded without building a parser."""
    from lark.load_grammar import load_grammar

    grammar, _used = load_grammar(grammar_text(), GRAMMAR_FILE, None, False)
    return grammar


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


def _decimal(text: str) -> Decimal:
    return Decimal(text)


def _park(text: str) -> int:
    return int(text[1:])


def _converter(annotation: Any, terminal: str | None) -> Callable[[str], Any]:
    if terminal == "PARK":
        return _park
    origin = typing.get_origin(annotation)
    if origin is typing.Union:
        annotation = next(a for a in typing.get_args(annotation) if a is not type(None))
    if annotation is Decimal:
        return _decimal
    if annotation is int:
        return int
    return str


def _attr_for(cls: type, rule: str) -> tuple[str, str]:
    """Map a field rule name to (attribute, kind) following the grammar's naming conventions."""
    names = {f.name for f in fields(cls)}
    kind = "scalar"
    base = rule
    if rule.endswith("_item"):
        kind, base = "items", rule[: -len("_item")]
    elif rule.endswith("_opt"):
        kind, base = "opt", rule[: -len("_opt")]
    prefix = cls.RULE.split("_")[0] + "_"
    candidates = [base]
    if base.startswith(prefix):
        candidates.insert(0, base[len(prefix):])
    for family in ("omstart_", "omw_"):  # rule-family prefixes shared by two sentence forms
        if base.startswith(family):
            candidates.append(base[len(family):])
    for c in candidates:
        if c in names:
            return c, kind
    raise LookupError(f"grammar rule {rule!r} names no field of {cls.__name__}")


# --------------------------------------------------------------------------- regex derivation

class _Deriver:
    """Translates Lark's EBNF rule trees into Python regular expressions."""

    def __init__(self, grammar):
        self.rules = {str(name): tree for name, _params, tree, _opts in grammar.rule_defs}
        self.terms = {str(name): tree for name, (tree, _prio) in grammar.term_defs}
        self.field_rules: list[str] = []

    # Terminals ---------------------------------------------------------------------------
    def literal(self, tok: Token) -> str:
        text = str(tok)
        if tok.type == "STRING":
            flags = text[text.rindex('"') + 1:]
            body = text[1: text.rindex('"')].encode().decode("unicode_escape")
            out = re.escape(body)
            return f"(?i:{out})" if "i" in flags else out
        # REGEXP /.../flags; its own groups become non-capturing so group numbers stay ours
        end = text.rindex("/")
        body, flags = _NONCAPTURING.sub("(?:", text[1:end]), text[end + 1:]
        return f"(?{flags}:{body})" if flags else f"(?:{body})"

    def terminal_regex(self, name: str) -> str:
        return self.tree(self.terms[name], inline_fields=False)

    def terminal_of(self, rule: str) -> Optional[str]:
        """The single named terminal a field rule holds, if any."""
        for t in self.rules[rule].iter_subtrees():
            for c in t.children:
                if isinstance(c, Terminal):
                    return c.name
        return None

    # Rules -------------------------------------------------------------------------------
    def tree(self, t: Any, inline_fields: bool) -> str:
        if isinstance(t, Token):
            return self.literal(t)
        if isinstance(t, Terminal):
            return self.terminal_regex(t.name)
        if isinstance(t, NonTerminal):
            return self.nonterminal(t.name, inline_fields)
        data = t.data
        kids = t.children
        if data == "expansions":
            alts = [self.tree(k, inline_fields) for k in kids]
            return alts[0] if len(alts) == 1 else "(?:" + "|".join(alts) + ")"
        if data == "expansion":
            return "".join(self.tree(k, inline_fields) for k in kids)
        if data in ("value", "literal"):
            return self.tree(kids[0], inline_fields)
        if data == "maybe":
            return "(?:" + self.tree(kids[0], inline_fields) + ")?"
        if data == "expr":
            inner_t = kids[0]
            op = str(kids[1])
            item_rule = self._item_rule(inner_t)
            inner = self.tree(inner_t, inline_fields=False if item_rule else inline_fields)
            if op == "~":
                lo, hi = int(kids[2]), int(kids[3]) if len(kids) > 3 else int(kids[2])
                q = f"{{{lo},{hi}}}"
            else:
                q = op
            rx = f"(?:{inner}){q}"
            if item_rule and inline_fields:
                self.field_rules.append(item_rule)
                return f"(?P<{item_rule}>{rx})"
            return rx
        raise ValueError(f"unsupported grammar construct {data!r}")

    @staticmethod
    def _item_rule(t: Any) -> Optional[str]:
        if isinstance(t, Tree) and t.data == "value" and isinstance(t.children[0], NonTerminal):
            name = t.children[0].name
            if name.endswith("_item"):
                return name
        return None

    def nonterminal(self, name: str, inline_fields: bool) -> str:
        if name.startswith("_"):  # an inlined helper rule: its fields belong to the sentence
            return self.tree(self.rules[name], inline_fields)
        body = self.tree(self.rules[name], inline_fields=False)
        if not inline_fields:
            return body
        self.field_rules.append(name)
        return f"(?P<{name}>{body})"

    def sentence(self, rule: str) -> tuple[str, list[str]]:
        self.field_rules = []
        rx = self.tree(self.rules[rule], inline_fields=True)
        return rx, list(self.field_rules)

    def item_pattern(self, rule: str) -> tuple[re.Pattern, int]:
        """A regex for one item with one capturing group per terminal, for ``finditer``."""
        groups = 0

        def walk(t: Any) -> str:
            nonlocal groups
            if isinstance(t, Terminal):
                groups += 1
                return "(" + self.terminal_regex(t.name) + ")"
            if isinstance(t, Token):
                if t.type == "REGEXP":
                    groups += 1
                    return "(" + self.literal(t) + ")"
                return self.literal(t)
            if isinstance(t, NonTerminal):
                return walk(self.rules[t.name])
            d, k = t.data, t.children
            if d == "expansions":
                return "(?:" + "|".join(walk(x) for x in k) + ")"
            if d == "expansion":
                return "".join(walk(x) for x in k)
            if d in ("value", "literal"):
                return walk(k[0])
            if d == "maybe":
                return "(?:" + walk(k[0]) + ")?"
            raise ValueError(f"unsupported construct {d!r} in item rule {rule!r}")

        rx = walk(self.rules[rule])
        return re.compile(rx), groups


@lru_cache(maxsize=1)
def specs() -> dict[str, SentenceSpec]:
    """Every sentence rule of the grammar, compiled. Keyed by rule name."""
    d = _Deriver(grammar_defs())
    by_rule = sentence_classes_by_rule()
    out: dict[str, SentenceSpec] = {}
    for rule, cls in by_rule.items():
        rx, field_rules = d.sentence(rule)
        hints = typing.get_type_hints(cls)
        layout = []
        for fr in field_rules:
            try:
                attr, kind = _attr_for(cls, fr)
                ann = hints[attr]
            except LookupError:  # a field of an embedded sentence ($OMW,CLEAR,<waypoint>)
                sub = next(iter(_sub_sentence_attrs(cls).values()), None)
                if sub is None:
                    raise
                attr, kind = _attr_for(sub, fr)
                ann = typing.get_type_hints(sub)[attr]
            if kind == "items":
                pattern, ngroups = d.item_pattern(fr)
                elem = typing.get_args(ann)[0]
                if typing.get_origin(elem) is tuple:
                    convs = tuple(_converter(a, None) for a in typing.get_args(elem))
                else:
                    convs = (_converter(elem, None),)
                if len(convs) != ngroups:
                    raise ValueError(f"{fr}: {ngroups} terminals but {cls.__name__}.{attr} holds {len(convs)}")
                layout.append(FieldSpec(fr, attr, kind, str, pattern, convs))
            elif ann is bool:
                layout.append(FieldSpec(fr, attr, "flag", bool))
            else:
                layout.append(FieldSpec(fr, attr, kind, _converter(ann, d.terminal_of(fr))))
        out[rule] = SentenceSpec(rule, cls, re.compile(rx), tuple(layout))
    return out


# --------------------------------------------------------------------------- building objects

def _sub_sentence_attrs(cls: type) -> dict[str, type]:
    hints = typing.get_type_hints(cls)
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
        hints = typing.get_type_hints(spec.cls)
        _REQUIRED[spec.cls] = tuple(
            (f.name, hints[f.name] is str)
            for f in fields(spec.cls)
            if f.default is MISSING and f.default_factory is MISSING
        )


_init_tables()


# --------------------------------------------------------------------------- fast builders

def _items(f: FieldSpec, text: Optional[str]) -> tuple:
    if not text:
        return ()
    out = []
    convs = f.item_converts
    single = len(convs) == 1
    for m in f.item_regex.finditer(text):
        if single:
            g = m.group(1)
            out.append("" if g is None else convs[0](g))
        else:
            out.append(tuple(("" if g is None else c(g)) for g, c in zip(m.groups(), convs)))
    return tuple(out)


def _builder_args(spec: SentenceSpec, index: dict, env: dict, tag: str) -> list[str]:
    """Source of the field values of ``spec.cls``, in field order, from ``t`` (the groups of a
    match whose group numbers are ``index``); embedded sentences are built from the same groups."""
    cls = spec.cls
    by_attr = {f.attr: f for f in spec.fields}
    required = dict(_REQUIRED.get(cls, ()))
    subs = _SUBS.get(cls, {})
    hints = typing.get_type_hints(cls)
    args = []
    for i, fld in enumerate(fields(cls)):
        name, k = fld.name, f"{tag}_{i}"
        if name in subs:
            sub_spec = _SPEC_BY_CLASS[subs[name]]
            first = index[sub_spec.fields[0].rule] - 1
            env[f"cls{k}"] = sub_spec.cls
            sub_args = ", ".join(_builder_args(sub_spec, index, env, k))
            args.append(f"(cls{k}({sub_args}) if t[{first}] is not None else None)")
            continue
        f = by_attr.get(name)
        if f is None:
            args.append(repr(fld.default))
            continue
        env[f"c{k}"] = f.convert
        conv = f"c{k}" if f.convert is not str else ""
        g = f"t[{index[f.rule] - 1}]"
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
    lines = ["def build(m):", "    t = m.groups()", "    o = _new(cls)"]
    for i, (f, expr) in enumerate(zip(fields(cls), args)):
        env[f"set{i}"] = getattr(cls, f.name).__set__
        lines.append(f"    set{i}(o, {expr})")
    lines.append("    return o")
    exec(compile("\n".join(lines) + "\n", f"<builder {rule}>", "exec"), env)
    return env["build"]
