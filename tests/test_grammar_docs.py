"""The checked-in grammar reference is generated from the grammar and is current."""

from helmcheck.grammar import docs
from helmcheck.grammar import sentences as S


def test_grammar_reference_is_current():
    assert not docs.stale(), "docs/grammar.md is stale: run 'helmcheck docs'"


def test_grammar_reference_lists_every_sentence():
    text = docs.render_markdown()
    for cls in S.ALL_CLASSES:
        assert f"`{cls.__name__}`" in text
