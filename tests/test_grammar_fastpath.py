"""Differential tests: the fast path (regexes compiled from the grammar) and Lark agree."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.lark import from_lark

from helmcheck.grammar import checksum_hex, decode, format
from helmcheck.grammar.compile import lark_parser

from .strategies import any_sentence

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
