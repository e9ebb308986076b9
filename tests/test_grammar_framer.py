"""The byte-stream framer (RH-FRM-6, RH-FRM-7): same sentences however the bytes arrive."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from helmcheck.grammar import Discard, Framer, Line, format

from .strategies import any_sentence

garbage = st.binary(min_size=1, max_size=40).filter(lambda b: b"$" not in b)


def _feed_in_pieces(data: bytes, cuts: list[int]) -> list:
    f = Framer()
    out, last = [], 0
    for c in sorted(set(cuts)):
        out += f.feed(data[last:c])
        last = c
    out += f.feed(data[last:])
    return out + f.close()


@given(st.lists(any_sentence, min_size=1, max_size=8), st.data())
@settings(max_examples=150)
def test_RH_FRM_7_same_lines_whole_bytewise_and_random_splits(sentences, data):
    stream = b"".join(format(s) for s in sentences)
    whole = Framer().feed(stream)
    assert [e.raw for e in whole] == [format(s) for s in sentences]
    f = Framer()
    bytewise = [e for i in range(len(stream)) for e in f.feed(stream[i:i + 1])] + f.close()
    assert bytewise == whole
    cuts = data.draw(st.lists(st.integers(0, len(stream)), max_size=12))
    assert _feed_in_pieces(stream, cuts) == whole


@given(st.lists(st.tuples(garbage, any_sentence), min_size=1, max_size=6), st.data())
@settings(max_examples=150)
def test_RH_FRM_7_garbage_between_sentences_is_reported_never_merged(pairs, data):
    stream = b"".join(g + format(s) for g, s in pairs)
    cuts = data.draw(st.lists(st.integers(0, len(stream)), max_size=12))
    events = _feed_in_pieces(stream, cuts)
    lines = [e.raw for e in events if isinstance(e, Line)]
    assert lines == [format(s) for _, s in pairs]
    discarded = b"".join(e.raw for e in events if isinstance(e, Discard))
    assert discarded == b"".join(g for g, _ in pairs)
    assert all(e.clause == "RH-FRM-7" for e in events if isinstance(e, Discard))


def test_RH_FRM_7_torn_sentence_is_discarded_and_the_next_kept():
    events = Framer().feed(b"$OMS,1,2$OMSTOP,0*06\r\n")
    assert isinstance(events[0], Discard) and events[0].raw == b"$OMS,1,2" and events[0].clause == "RH-FRM-7"
    assert events[1] == Line(b"$OMSTOP,0*06\r\n", 8)


def test_RH_FRM_6_line_of_256_bytes_kept_257_discarded_whole():
    body256 = b"$" + b"A" * (256 - 3) + b"\r\n"
    body257 = b"$" + b"A" * (257 - 3) + b"\r\n"
    assert len(body256) == 256 and len(body257) == 257
    assert Framer().feed(body256) == [Line(body256, 0)]
    ev = Framer().feed(body257 + b"$OMSTOP,0*06\r\n")
    assert isinstance(ev[0], Discard) and ev[0].clause == "RH-FRM-6" and ev[0].length == 257
    assert ev[1].raw == b"$OMSTOP,0*06\r\n"


def test_RH_FRM_6_flood_without_terminator_keeps_memory_bounded():
    f = Framer()
    for _ in range(2000):
        assert f.feed(b"$" + b"x" * 999) != [] or True
    assert len(f._buf) <= 256  # the held copy is capped, whatever arrives
    ev = f.feed(b"$OMSTOP,0*06\r\n")
    assert ev[-1].raw == b"$OMSTOP,0*06\r\n"


def test_RH_FRM_7_pending_bytes_reported_at_close():
    f = Framer()
    assert f.feed(b"noise$OMS,1") == [Discard(b"noise", 0, 5, "RH-FRM-7", "bytes before '$' (noise)")]
    ev = f.close()
    assert len(ev) == 1 and ev[0].raw == b"$OMS,1" and ev[0].offset == 5
