"""The grammar is the one definition: every class mirrors exactly one grammar rule."""

from __future__ import annotations

from helmcheck.grammar import sentences as S
from helmcheck.grammar.compile import grammar_defs, specs


def _sentence_rules() -> set[str]:
    body = next(t for n, _p, t, _o in grammar_defs().rule_defs if str(n) == "body")
    return {str(v.children[0].name) for v in body.iter_subtrees() if v.data == "value"}


def test_every_grammar_sentence_rule_has_exactly_one_class():
    assert _sentence_rules() == {cls.RULE for cls in S.ALL_CLASSES}
    assert len({cls.RULE for cls in S.ALL_CLASSES}) == len(S.ALL_CLASSES)


def test_every_class_field_is_filled_by_a_grammar_rule():
    for spec in specs().values():
        filled = {f.attr for f in spec.fields}
        sub = [f for f in spec.cls.field_names() if f == "waypoint" and spec.cls is S.OMWClear]
        missing = set(spec.cls.field_names()) - filled - set(sub)
        assert not missing, f"{spec.cls.__name__}: fields {missing} are not in grammar rule {spec.rule}"


def test_every_command_of_the_paper_is_in_the_grammar():
    ids = {cls.ID for cls in S.COMMAND_CLASSES}
    paper = {"OMS", "OMP", "OJW", "OMSTOP", "OMLOAD", "OMSTART", "OPOS", "OSD", "OLOGL", "OLOGD",
             "ORWSET", "ODVL", "OPK", "OMW"}
    assert paper <= ids and "OXFLT" in ids


def test_RH_ACK_3_every_command_names_its_ack_type_and_error():
    table = {"OMSTOP": (1, 28), "OMLOAD": (2, 29), "OMSTART": (3, 30), "OLOGD": (4, 25),
             "OLOGL": (5, 24), "OPOS": (6, 18), "OJW": (7, 19), "OSD": (8, 27), "OMS": (9, 20),
             "OMP": (10, 21), "OPK": (11, 22), "ORWSET": (12, 23), "ODVL": (15, 35), "OMW": (16, 36)}
    for cls in S.COMMAND_CLASSES:
        if cls.ID == "OXFLT":
            assert cls.ACK_TYPE is None
            continue
        assert (cls.ACK_TYPE, cls.ERR) == table[cls.ID], cls.__name__
