"""The traceability table (``helmcheck/spec/rules.toml``, :mod:`helmcheck.rules`) in step with the
profile and the case catalogue.

* every quoted rule is in its clause's text, word for word;
* every rule-bearing word (:data:`helmcheck.rules.RULE_WORDS`: "only", "after", "first", "exactly",
  "until" …) and every number of every clause of §1–8b lies inside some row's quote of that clause:
  a clause that gains a rule the table does not split out fails here;
* every step a row names exists in the catalogue and is the step named (the text after the colon
  is in it); every observer module and exploration draw it names exists;
* a row either names steps or says why none can fail it, and books a vehicle clause (a reading's
  rule is booked on the clause it reads);
* every new probe of the table (:mod:`helmcheck.certify.vehicle.rulecases`) is a case of the catalogue.
"""

from __future__ import annotations

import importlib
import importlib.resources
import re

import pytest

from helmcheck.certify.vehicle.catalogue import CASES
from helmcheck.certify.vehicle.rulecases import RULE_CASES
from helmcheck.clauses import catalogue
from helmcheck.rules import RULE_WORDS, STEP_REF, reading_books, rules

SECTIONS = ("1", "2", "3", "4", "5", "6", "7", "8", "8b")
BY_ID = {c.id: c for c in CASES}
#: Clause IDs, section references and file names carry digits that are not numbers of a rule.
_NOT_NUMBERS = re.compile(r"RH-[A-Z]+-\d+|§[\dIVXA-Z.\-–b]+|[\w-]+\.md|\[D[^\]]*\]|OS5000")
_NUMBER = re.compile(r"(?<![\w.−-])[−-]?\d+(?:[.,]\d+)?(?:–\d+)?")
_WORD = re.compile(r"\b(" + "|".join(re.escape(w) for w in sorted(set(x.lower() for x in RULE_WORDS), key=len,
                                                                  reverse=True)) + r")\b", re.I)


def _clauses():
    return [c for c in catalogue().values() if c.section in SECTIONS]


def _spans(text: str, quotes: list[str]) -> list[tuple[int, int]]:
    out = []
    for q in quotes:
        for m in re.finditer(re.escape(q), text):
            out.append((m.start(), m.end()))
    return out


def uncovered(text: str, quotes: list[str]) -> list[str]:
    """The rule-bearing words and numbers of ``text`` outside every quote (with some context)."""
    spans = _spans(text, quotes)
    masked = _NOT_NUMBERS.sub(lambda m: " " * len(m.group()), text)
    hits = [m for m in _WORD.finditer(text)] + [m for m in _NUMBER.finditer(masked)]
    out = []
    for m in hits:
        if not any(a <= m.start() and m.end() <= b for a, b in spans):
            out.append(f"{m.group()!r} in …{text[max(0, m.start() - 30):m.end() + 30]}…")
    return out


def test_every_quote_is_in_its_clause():
    cat = catalogue()
    spec = (importlib.resources.files("helmcheck.spec") / "reference-profile.md").read_text(encoding="utf-8")
    spec = re.sub(r"\s*\n\s*", " ", spec)  # a section's own text, as one paragraph
    bad = []
    for r in rules():
        if r.clause.startswith("§"):
            if r.clause[1:] not in SECTIONS or r.words not in spec:
                bad.append((r.clause, r.words))
        elif r.clause not in cat or r.words not in cat[r.clause].text:
            bad.append((r.clause, r.words))
    assert not bad, bad


@pytest.mark.parametrize("clause", [c.id for c in _clauses()])
def test_every_rule_of_the_clause_is_a_row(clause):
    """Each "only", "after", "first", "exactly", range end and error number of the clause is inside
    a row's quote: the clause split into its rules, nothing left over."""
    c = catalogue()[clause]
    quotes = [r.words for r in rules() if r.clause == clause]
    assert quotes, f"{clause} has no row in the table"
    left = uncovered(c.text, quotes)
    assert not left, f"{clause}: rule words no row quotes: {left}"


def test_the_coverage_check_can_fail():
    """A clause with a new condition, or a new number, is caught."""
    c = catalogue()["RH-SRV-3"]
    quotes = [r.words for r in rules() if r.clause == "RH-SRV-3"]
    assert not uncovered(c.text, quotes)
    assert uncovered(c.text + " Only after a second $OMS.", quotes)
    assert uncovered(c.text + " Timeout 7 s.", quotes)


def _step_problem(ref: str):
    m = STEP_REF.match(ref)
    if m:
        case = BY_ID.get(m.group(1))
        if case is None:
            return f"{ref}: no case {m.group(1)}"
        i = int(m.group(2))
        if not 1 <= i <= len(case.steps):
            return f"{ref}: {m.group(1)} has {len(case.steps)} steps"
        if m.group(3) and m.group(3) not in repr(case.steps[i - 1]):
            return f"{ref}: step {i} is {case.steps[i - 1]!r}"
        return None
    kind, _, target = ref.partition(": ")
    if kind == "every line":
        try:
            importlib.import_module(target)
        except ImportError:
            return f"{ref}: no module {target}"
        return None
    if kind == "explore":
        mod, _, attr = target.rpartition(".")
        try:
            if not hasattr(importlib.import_module(mod), attr):
                return f"{ref}: {mod} has no {attr}"
        except ImportError:
            return f"{ref}: no module {mod}"
        return None
    return f"{ref}: not a step reference"


def test_every_step_named_exists():
    bad = [p for r in rules() for ref in r.probe for p in [_step_problem(ref)] if p]
    assert not bad, bad


def test_a_missing_step_is_caught():
    assert _step_problem("V-24 step 5: Settle") is None
    assert _step_problem("V-24 step 99")
    assert _step_problem("V-24 step 5: OMSTART")
    assert _step_problem("V-999 step 1")
    assert _step_problem("explore: helmcheck.certify.vehicle.generate.no_such_draw")


def test_each_row_is_probed_or_says_why_and_books_a_vehicle_clause():
    cat = catalogue()
    bad = []
    for r in rules():
        if bool(r.probe) == bool(r.why):
            bad.append(f"{r.clause} {r.words!r}: probe and why")
        if r.probe and (r.books not in cat or cat[r.books].role != "vehicle"):
            bad.append(f"{r.clause} {r.words!r}: books {r.books}")
    assert not bad, bad


def test_the_readings_of_the_third_vehicle_are_decided():
    """Issue 42: the five readings a third vehicle's faults break, each booked on the clause it reads."""
    assert reading_books() == {"RH-RD-16": "RH-FRM-5", "RH-RD-2": "RH-SAF-1", "RH-RD-13": "RH-SAF-1",
                               "RH-RD-4": "RH-OMW-3", "RH-RD-9": "RH-PK-1"}


def test_every_rule_case_is_named_by_a_row_and_in_the_catalogue():
    named = {STEP_REF.match(ref).group(1) for r in rules() for ref in r.probe if STEP_REF.match(ref)}
    for case in RULE_CASES:
        assert BY_ID.get(case.id) is case
        assert case.id in named, f"{case.id} probes no rule of the table"
    assert len(BY_ID) == len(CASES), "case IDs repeat"
