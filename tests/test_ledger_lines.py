"""The offending wire-log lines a clause verdict names (``results.json`` ``lines``, and the
reason's "wire-log lines …"): each line once, in the order first met, at most ``MAX_LINES``
kept — several findings on one line (RH-BS-5's resend on line 2534, twice) name it once."""

from __future__ import annotations

import re

from hypothesis import given, strategies as st

from helmcheck.judge.ledger import MAX_LINES, Evidence, Ledger

CLAUSE = "RH-ACK-3"  # a MUST: violations give FAIL


@given(st.lists(st.integers(min_value=0, max_value=80), min_size=1, max_size=200))
def test_each_offending_line_is_named_once_in_the_order_first_met(linenos):
    led = Ledger([CLAUSE])
    for n in linenos:
        led.failed(CLAUSE, "wrong err", [Evidence(1.0, "<", "$ACK,9,1,20*5C", n)])
    v = led.verdict(CLAUSE)
    expected = list(dict.fromkeys(n for n in linenos if n))[:MAX_LINES]
    assert list(v.lines) == expected
    assert v.offending_count == len(linenos)  # every violation still counts
    named = re.search(r"\(wire-log lines? ([\d, ]+)(?: and (at least )?(\d+) more)?\)", v.reason)
    assert (named is not None) == bool(expected), v.reason
    if named:
        listed = [int(x) for x in named.group(1).split(", ")]
        assert listed == expected[:10]
        assert int(named.group(3) or 0) == len(expected) - len(listed)
        assert bool(named.group(2)) == (len(expected) >= MAX_LINES and len(expected) > 10)


def test_two_findings_on_one_line_name_it_once():
    led = Ledger([CLAUSE])
    for n in (2528, 2534, 2534, 2536):
        led.failed(CLAUSE, "resent too soon", [Evidence(1.0, ">", "$OMS,…", n)])
    v = led.verdict(CLAUSE)
    assert v.lines == (2528, 2534, 2536)
    assert "(wire-log lines 2528, 2534, 2536)" in v.reason and v.reason.startswith("4 violation(s)")
