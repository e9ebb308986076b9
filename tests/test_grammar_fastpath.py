"""Differential tests: the fast path (regexes compiled from the grammar) and Lark agree; the
``$OSI`` range shortcut and its rule agree."""

from __future__ import annotations

from decimal import Decimal

from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.lark import from_lark

from helmcheck.grammar import checksum_hex, decode, format
from helmcheck.grammar import sentences as S
from helmcheck.grammar.compile import lark_parser

from .strategies import REPLIES, any_sentence

FIELD_ALPHABET = "0123456789.-,ABCDEFGHIJKLMNOPQRSTUVWXYZabcxyz PCRTD:/\\_"


def _both(raw: bytes):
    fast, lark = decode(raw), decode(raw, engine="lark")
    assert (fast.sentence, fast.error) == (lark.sentence, lark.error), raw
    return fast


@given(from_lark(lark_parser(), start="body"), st.data())
@settings(max_examples=300)
def test_engines_agree_on_grammar_strings_and_their_mutations(body, data):
    raw = f"${body}*{checksum_hex(body)}\r\n".encode("latin-1")
    _both(raw)
    # mutate the body, then re-checksum so the body reading (not the frame) is what differs
    chars = list(body)
    i = data.draw(st.integers(0, max(len(chars) - 1, 0)))
    op = data.draw(st.sampled_from(["replace", "insert", "delete"]))
    c = data.draw(st.sampled_from(FIELD_ALPHABET))
    if op == "replace" and chars:
        chars[i] = c
    elif op == "insert":
        chars.insert(i, c)
    elif chars:
        del chars[i]
    mutated = "".join(chars)
    if "*" in mutated or "$" in mutated:
        return
    _both(f"${mutated}*{checksum_hex(mutated)}\r\n".encode("latin-1"))


@given(st.sampled_from(["OMS", "OMP", "OSD", "OMW", "OSI", "ACK", "OMSTART", "ORWSET", "OLOGL", "C"]),
       st.text(alphabet=FIELD_ALPHABET, max_size=60))
@settings(max_examples=400)
def test_engines_agree_on_random_field_text(sid, tail):
    body = sid + ("," if sid != "C" and tail and not tail.startswith(",") else "") + tail
    _both(f"${body}*{checksum_hex(body)}\r\n".encode("latin-1"))


@given(any_sentence)
@settings(max_examples=200)
def test_shortcut_and_full_reading_agree(s):
    raw = format(s)
    from helmcheck.grammar import codec
    from helmcheck.profile import DEFAULT
    assert codec._fast(raw, DEFAULT) == decode(raw.rstrip(b"\r\n") + b"\r\n", engine="lark").sentence


def _chars_outside(items, allowed: set[int]) -> list[str]:
    """Every way the parsed regex ``items`` could match a character not in ``allowed``."""
    out: list[str] = []
    for op, av in items:
        name = str(op)
        if name == "LITERAL":
            out += [] if av in allowed else [chr(av)]
        elif name == "IN":
            for iop, iav in av:
                kind = str(iop)
                if kind == "LITERAL":
                    out += [] if iav in allowed else [chr(iav)]
                elif kind == "RANGE":
                    out += [chr(c) for c in range(iav[0], iav[1] + 1) if c not in allowed]
                else:  # NEGATE, CATEGORY (\s, \w, ...): more than the listed characters
                    out.append(kind)
        elif name == "SUBPATTERN":
            out += _chars_outside(av[3], allowed)
        elif name in ("MAX_REPEAT", "MIN_REPEAT"):
            out += _chars_outside(av[2], allowed)
        elif name == "BRANCH":
            for branch in av[1]:
                out += _chars_outside(branch, allowed)
        elif name != "AT":  # ANY ("."), NOT_LITERAL, back references, ...
            out.append(name)
    return out


def test_fast_path_regexes_match_only_clean_bodies():
    """The fast path does not scan a line's body for bytes the framing forbids (RH-FRM-1, a
    second '*'): it relies on every compiled sentence regex matching only printable ASCII
    without '$' and '*'. A grammar change that breaks that premise fails here."""
    import re._parser as sre_parse

    from helmcheck.grammar.compile import specs

    allowed = set(range(0x20, 0x7F)) - {ord("$"), ord("*")}
    for rule, spec in specs().items():
        assert _chars_outside(sre_parse.parse(spec.regex.pattern), allowed) == [], rule
        for f in spec.fields:
            if f.item_regex is not None:
                assert _chars_outside(sre_parse.parse(f.item_regex.pattern), allowed) == [], (rule, f.rule)
    assert _chars_outside(sre_parse.parse(r"A[^,a]\s.[^,]"), allowed) == ["NEGATE", "CATEGORY", "ANY", "NOT_LITERAL"]
    assert _chars_outside(sre_parse.parse(r"(?:x|\$)"), allowed) == ["$"]


@given(REPLIES[S.OSI], st.data())
@settings(max_examples=300)
def test_osi_ranges_shortcut_agrees_with_the_rule(osi, data):
    # _osi_fine answers True only when the rule finds nothing; check_ranges gives the rule's word
    from dataclasses import replace

    from helmcheck.grammar.ranges import _RULES, check_ranges
    from helmcheck.profile import DEFAULT

    field = data.draw(st.sampled_from(["lat", "lon", "speed", "distance", "true_heading", "battery", "mode",
                                       "actuators", None]))
    if field is not None:
        bad = {"lat": Decimal("90.5"), "lon": Decimal("-180.5"), "speed": Decimal("-1"),
               "distance": Decimal("-0.01"), "true_heading": Decimal("360"), "battery": "x1",
               "mode": "Mp", "actuators": "b0b0a0a0b8"}[field]
        osi = replace(osi, **{field: bad})
    rule = next(iter(_RULES[S.OSI](osi, DEFAULT)), None)
    got = check_ranges(osi, DEFAULT)
    assert (got is None) == (rule is None)
    if rule is not None:
        assert (got.clause, got.field) == (rule[0], rule[1])
