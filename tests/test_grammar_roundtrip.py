"""Round trips and grammar-generated input for every sentence type (issue: grammar, acceptance)."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.lark import from_lark

from helmcheck.grammar import checksum_hex, decode, format, parse
from helmcheck.grammar import sentences as S
from helmcheck.grammar.compile import lark_parser
from helmcheck.grammar.errors import RANGE
from helmcheck.profile import DEFAULT

from .strategies import ALL


def test_every_sentence_class_has_a_strategy():
    assert set(ALL) == set(S.ALL_CLASSES)


@pytest.mark.parametrize("cls", S.ALL_CLASSES, ids=lambda c: c.__name__)
def test_RH_FRM_1_parse_of_format_is_identity(cls):
    @given(ALL[cls])
    @settings(max_examples=60)
    def check(s):
        b = format(s)
        assert b.endswith(b"\r\n")
        assert parse(b) == s
        assert parse(b, engine="lark") == s
        # canonical bytes survive the other way round, byte for byte
        assert format(parse(b)) == b

    check()


@pytest.mark.parametrize("cls", S.ALL_CLASSES, ids=lambda c: c.__name__)
def test_repr_is_valid_python(cls):
    from decimal import Decimal  # noqa: F401 - used by eval

    @given(ALL[cls])
    @settings(max_examples=20)
    def check(s):
        namespace = {"Decimal": Decimal, **{c.__name__: c for c in S.ALL_CLASSES}}
        assert eval(repr(s), namespace) == s

    check()


def _frame(body: str) -> bytes:
    return f"${body}*{checksum_hex(body)}\r\n".encode("latin-1")


@given(from_lark(lark_parser(), start="body"))
@settings(max_examples=400)
def test_RH_FRM_1_strings_generated_from_the_grammar_parse(body):
    """Anything the grammar generates is read by both engines; only range checks may refuse it
    — and the line length: the grammar does not bound it, framing does (RH-FRM-6), so a
    generated line over ``max_line_bytes`` must be refused with RH-FRM-6 and read in full when
    the limit allows it."""
    line = _frame(body)
    d = decode(line)
    if len(line) > DEFAULT.max_line_bytes:
        assert d.error is not None and d.error.clause == "RH-FRM-6", (len(line), d.error)
        d = decode(line, DEFAULT.replace(max_line_bytes=len(line)))
    if d.error is not None:
        assert d.error.kind == RANGE, str(d.error)
    profile = DEFAULT if len(line) <= DEFAULT.max_line_bytes else DEFAULT.replace(max_line_bytes=len(line))
    lark = decode(line, profile, engine="lark")
    assert (lark.sentence, lark.error) == (d.sentence, d.error)


def test_RH_FRM_6_the_generated_257_byte_OYSI_line_is_refused_for_its_length():
    """The line hypothesis once generated (a flake on main): 257 bytes with CR LF."""
    body = "OYSI," + "A" * (257 - len("$OYSI,*hh\r\n"))
    line = _frame(body)
    assert len(line) == 257
    d = decode(line)
    assert d.error is not None and d.error.clause == "RH-FRM-6", d.error


@given(st.sampled_from(sorted(ALL, key=lambda c: c.__name__)).flatmap(lambda c: ALL[c]), st.data())
@settings(max_examples=400)
def test_single_byte_mutations_are_valid_or_clause_tagged(s, data):
    raw = bytearray(format(s))
    i = data.draw(st.integers(0, len(raw) - 1))
    raw[i] = data.draw(st.integers(0, 255))
    d = decode(bytes(raw))  # must not raise
    if d.error is not None:
        assert d.error.clause.startswith("RH-"), d.error
        assert str(d.error).startswith(d.error.clause + ": ")
    lark = decode(bytes(raw), engine="lark")
    assert (lark.sentence, lark.error) == (d.sentence, d.error)
