"""Derives the fast path's tables from ``remote_helm.lark``, and writes them to :mod:`.derived`.

The grammar's rule tree (read by Lark, without building a parser) is translated into one Python
regular expression per sentence rule, and each field rule is mapped onto its sentence class's
attribute with its converter (see :mod:`.compile` for why the translation is exact).
:func:`derive_rows` is the derivation; :func:`render_table` writes its result as the module
:mod:`.derived`, checked in, which :func:`helmcheck.grammar.compile.specs` loads instead of
deriving while the grammar's digest matches (a process that only reads valid lines never
imports Lark). ``helmcheck docs`` regenerates it; ``helmcheck docs --check`` and
``tests/test_grammar_docs.py`` fail when it is stale.
"""

from __future__ import annotations

import re
import typing
from dataclasses import fields
from decimal import Decimal
from pathlib import Path
from typing import Any, Optional

from lark import Token, Tree
from lark.grammar import NonTerminal, Terminal

from .compile import (_sub_sentence_attrs, grammar_defs, grammar_digest, grammar_text, sentence_classes_by_rule,
                      type_hints)

__all__ = ["derive_rows", "render_table", "TABLE_FILE", "stale"]

TABLE_FILE = Path(__file__).resolve().parent / "derived.py"
_NONCAPTURING = re.compile(r"(?<!\\)\((?!\?)")

#: A field row: (field rule, attribute, kind, converter, item regex or None, item converters).
Row = tuple[str, str, str, str, Optional[str], tuple[str, ...]]


def _converter(annotation: Any, terminal: str | None) -> str:
    """The name of the converter (:data:`helmcheck.grammar.compile.CONVERTERS`) of a field."""
    if terminal == "PARK":
        return "park"
    origin = typing.get_origin(annotation)
    if origin is typing.Union:
        annotation = next(a for a in typing.get_args(annotation) if a is not type(None))
    if annotation is Decimal:
        return "decimal"
    if annotation is int:
        return "int"
    return "str"


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

    def item_pattern(self, rule: str) -> tuple[str, int]:
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
        return rx, groups


def derive_rows() -> dict[str, tuple[str, tuple[Row, ...]]]:
    """Every sentence rule: its body regex and its field rows, in the grammar's group order."""
    d = _Deriver(grammar_defs())
    out: dict[str, tuple[str, tuple[Row, ...]]] = {}
    for rule, cls in sentence_classes_by_rule().items():
        rx, field_rules = d.sentence(rule)
        hints = type_hints(cls)
        layout: list[Row] = []
        for fr in field_rules:
            try:
                attr, kind = _attr_for(cls, fr)
                ann = hints[attr]
            except LookupError:  # a field of an embedded sentence ($OMW,CLEAR,<waypoint>)
                sub = next(iter(_sub_sentence_attrs(cls).values()), None)
                if sub is None:
                    raise
                attr, kind = _attr_for(sub, fr)
                ann = type_hints(sub)[attr]
            if kind == "items":
                pattern, ngroups = d.item_pattern(fr)
                elem = typing.get_args(ann)[0]
                if typing.get_origin(elem) is tuple:
                    convs = tuple(_converter(a, None) for a in typing.get_args(elem))
                else:
                    convs = (_converter(elem, None),)
                if len(convs) != ngroups:
                    raise ValueError(f"{fr}: {ngroups} terminals but {cls.__name__}.{attr} holds {len(convs)}")
                layout.append((fr, attr, kind, "str", pattern, convs))
            elif ann is bool:
                layout.append((fr, attr, "flag", "bool", None, ()))
            else:
                layout.append((fr, attr, kind, _converter(ann, d.terminal_of(fr)), None, ()))
        out[rule] = (rx, tuple(layout))
    return out


def render_table() -> str:
    """The text of :mod:`.derived` for the grammar as it is now."""
    lines = [
        '"""The fast path\'s tables, derived from ``remote_helm.lark`` by :mod:`.derive`.',
        "",
        "Generated by ``helmcheck docs``; do not edit. :func:`helmcheck.grammar.compile.specs` uses",
        "them only while ``GRAMMAR_DIGEST`` is the digest of the grammar file, and derives them",
        "again otherwise.",
        '"""',
        "",
        f"GRAMMAR_DIGEST = {grammar_digest(grammar_text())!r}",
        "",
        "#: sentence rule -> (body regex, field rows: (field rule, attribute, kind, converter,",
        "#: item regex, item converters))",
        "RULES = {",
    ]
    for rule, (rx, rows) in derive_rows().items():
        lines.append(f"    {rule!r}: (")
        lines.append(f"        {rx!r},")
        lines.append("        (")
        lines += [f"            {row!r}," for row in rows]
        lines.append("        ),")
        lines.append("    ),")
    lines.append("}")
    return "\n".join(lines) + "\n"


def stale() -> bool:
    """Whether the checked-in :mod:`.derived` differs from what the grammar gives now."""
    return not TABLE_FILE.exists() or TABLE_FILE.read_text(encoding="utf-8") != render_table()
