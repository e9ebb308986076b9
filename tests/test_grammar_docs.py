"""The checked-in grammar reference is generated from the grammar and is current."""

from helmcheck.grammar import docs
from helmcheck.grammar import sentences as S


def test_grammar_reference_is_current():
    assert not docs.stale(), "docs/grammar.md is stale: run 'helmcheck docs'"


def test_grammar_reference_lists_every_sentence():
    text = docs.render_markdown()
    for cls in S.ALL_CLASSES:
        assert f"`{cls.__name__}`" in text


def test_fast_path_tables_are_current():
    from helmcheck.grammar import derive

    assert not derive.stale(), "helmcheck/grammar/derived.py is stale: run 'helmcheck docs'"


def test_checked_in_tables_are_the_derivation(monkeypatch):
    """specs() from the checked-in tables equals specs() derived from the grammar now, and a
    grammar whose digest differs from the tables' is derived again, not read from them."""
    from helmcheck.grammar import compile as C
    from helmcheck.grammar import derived

    def shape(sp):
        return {r: (s.cls, s.regex.pattern, [(f.rule, f.attr, f.kind, f.convert,
                                               f.item_regex.pattern if f.item_regex else None, f.item_converts)
                                              for f in s.fields]) for r, s in sp.items()}

    loaded = shape(C.specs())
    monkeypatch.setattr(derived, "GRAMMAR_DIGEST", "not the grammar's")
    monkeypatch.setattr(derived, "RULES", {})
    C.specs.cache_clear()
    try:
        assert shape(C.specs()) == loaded
    finally:
        C.specs.cache_clear()
