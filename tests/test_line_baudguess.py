"""Which baud rate makes a capture sentences (:func:`helmcheck.line.baudguess.guess_baud`).

The captures are the reference emulator's own sentences (not the generic text the models are
made of), sent at one rate and read at another by the relay's ``rx-baud`` stage — the garbage a
receiver at the wrong rate really reads — in bursts with the line idle between them, as a
vehicle answers polls.
"""

from __future__ import annotations

import random

import pytest

from helmcheck.grammar.wirelog import FROM_VEHICLE
from helmcheck.line.baudguess import MIN_BYTES, guess_baud, valid_sentence_bytes
from helmcheck.line.impair import BYTES, ImpairedLine
from helmcheck.line.impair_spec import parse_impairment
from helmcheck.profile import load_profile
from tests.virtual_vehicle import VirtualVehicle

POLLS = ["OSD,G,C,S,P,Y,D,T,I", "OSD,S", "ORWSET,Sop,R", "OSD,G,C", "OMSTOP,0", "OSD,S"]


@pytest.fixture(scope="module")
def answers() -> list[bytes]:
    """The emulator's answers to a few polls, one burst each."""
    v = VirtualVehicle(load_profile(None))
    out = []
    for body in POLLS * 3:
        out.append(v.send(body))
        v.now += 0.5
    return out


def seen(bursts: list[bytes], sent_at: int, read_at: int) -> bytes:
    """The bursts sent at ``sent_at`` baud, 0.2 s apart, as a receiver at ``read_at`` reads them."""
    spec = f"baud={sent_at}" + (f",rx-baud={read_at}" if read_at != sent_at else "")
    line = ImpairedLine(parse_impairment(spec), 0.0)
    for i, b in enumerate(bursts):
        line.push(0.2 * i, FROM_VEHICLE, b)
    return b"".join(a.data for a in line.due(1e6) if a.kind == BYTES)


def test_sentences_sent_at_115200_and_read_at_19200_name_115200(answers):
    """The acceptance case: a vehicle at 115200 behind a 19200 receiver."""
    capture = seen(answers, 115200, 19200)
    assert valid_sentence_bytes(capture) == 0 and len(capture) >= MIN_BYTES
    g = guess_baud(capture, 19200)
    assert g.baud == 115200, g.reason
    assert "sent at 115200 baud" in g.reason and "\n" not in g.reason


@pytest.mark.parametrize("sent_at, read_at", [(9600, 19200), (4800, 19200), (38400, 19200), (57600, 19200),
                                              (19200, 115200), (115200, 9600)])
def test_other_wrong_rates_are_named_too(answers, sent_at, read_at):
    assert guess_baud(seen(answers, sent_at, read_at), read_at).baud == sent_at


def test_the_declared_rate_when_the_bytes_are_sentences_even_spoilt(answers):
    clean = seen(answers, 19200, 19200)
    g = guess_baud(clean, 19200)
    assert g.baud == 19200 and g.sentence_bytes == len(clean)
    rng = random.Random(3)
    spoilt = bytes(b ^ (1 << rng.randrange(8)) if rng.random() < 0.05 else b for b in clean)
    assert valid_sentence_bytes(spoilt) < len(spoilt) / 2  # most sentences broken: read by the models
    assert guess_baud(spoilt, 19200).baud == 19200


def test_no_rate_for_noise_a_dead_line_or_too_few_bytes():
    rng = random.Random(1)
    noise = guess_baud(bytes(rng.getrandbits(8) for _ in range(3000)), 19200)
    assert noise.baud is None and "no baud rate stands out" in noise.reason
    assert guess_baud(b"\x00" * 500, 19200).baud is None
    few = guess_baud(b"\xf0\x0f" * 10, 19200)
    assert few.baud is None and "too few" in few.reason
