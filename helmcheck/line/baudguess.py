"""Which baud rate would make a capture sentences: :func:`guess_baud`, for a wrong baud rate.

A receiver set to the wrong rate reads garbage, and the garbage is not random: the sender's
frames, re-sampled at the receiver's rate (:mod:`.uart`, the same model as the relay's
``rx-baud``), give each pair of rates its own pattern of bytes (a 19200-baud receiver reading a
115200-baud sender, for one, mostly reads bytes whose bit 0 is 1). The capture itself cannot be
turned back into sentences: a receiver slower than the sender samples one bit in several and
loses the rest, a faster one loses the length of every run of 1 bits between its frames. So
each candidate rate is scored by how well it predicts the bytes captured:

1. at the declared rate the capture is read as it is: when the lines with a valid checksum
   (``$…*hh`` CR LF, RH-FRM-1/2) hold at least :data:`SENTENCE_SHARE` of its bytes, the declared
   rate is right (noise and all);
2. otherwise each candidate rate (:data:`COMMON_BAUDS`) is a model: NMEA-like sentences
   (generated here, from a fixed seed: talker and field shapes, not any vehicle's text) sent
   at that rate in bursts with idle time between, read by a receiver at the declared rate; the
   bytes it reads, counted, are the model's distribution (the declared rate's own model is the
   text itself). The score is the mean log-likelihood per byte of the capture under each model;
   the best wins when it beats the second by :data:`MARGIN_BITS` bits a byte and a uniform
   (random noise) model too, with at least :data:`MIN_BYTES` bytes captured, not all of one
   value (a line held low reads as 0x00s at any rate). Otherwise no rate is named, and the
   reason says why.

Pure: no clock, no I/O. The models are made once per declared rate and kept.
"""

from __future__ import annotations

import math
import random
import re
from functools import lru_cache
from typing import NamedTuple, Optional

from ..grammar.checksum import checksum
from .uart import Receiver, SenderLine, Ticks

__all__ = ["COMMON_BAUDS", "BaudGuess", "guess_baud", "valid_sentence_bytes", "MIN_BYTES", "MARGIN_BITS",
           "SENTENCE_SHARE"]

COMMON_BAUDS = (4800, 9600, 19200, 38400, 57600, 115200)
MIN_BYTES = 48  #: fewer bytes than this name no rate
MARGIN_BITS = 0.25  #: bits a byte the best model must beat the next (and the uniform one) by
SENTENCE_SHARE = 0.5  #: bytes in valid sentences that make the declared rate right
_MODEL_BYTES = 40000  # sentence bytes sent for a model, at most
_MODEL_READ = 16000  # bytes read for a model, at most (a slow sender read fast gives many)
_SENTENCE_RE = re.compile(rb"\$([\x20-\x7e]{1,250}?)\*([0-9A-Fa-f]{2})\r\n")


class BaudGuess(NamedTuple):
    """What :func:`guess_baud` found. ``baud`` is the rate that makes the capture sentences
    (``declared`` when it already is), or None; ``scores`` the mean log2-likelihood per byte of
    each candidate (and ``0`` for the uniform model, as ``-8``); ``reason`` one line."""

    baud: Optional[int]
    declared: int
    sentence_bytes: int
    scores: dict
    reason: str


def valid_sentence_bytes(data: bytes) -> int:
    """Bytes of ``data`` in lines ``$…*hh`` CR LF whose checksum is right."""
    n = 0
    for m in _SENTENCE_RE.finditer(data):
        if checksum(m.group(1)) == int(m.group(2), 16):
            n += len(m.group(0))
    return n


def _sentences(rng: random.Random, n_bytes: int) -> list[bytes]:
    """NMEA-like sentences, ``n_bytes`` or so in all (module docstring)."""
    out, total = [], 0
    letters = "ABCDEFGHIJKLMNOPQRSTUVWXYZ"
    while total < n_bytes:
        fields = []
        for _ in range(rng.randint(1, 18)):
            shape = rng.random()
            if shape < 0.08:
                fields.append("")
            elif shape < 0.35:
                fields.append(str(rng.randint(0, 99999) if rng.random() < 0.5 else rng.randint(0, 9)))
            elif shape < 0.75:
                whole = rng.randint(0, 180) * (-1 if rng.random() < 0.2 else 1)
                fields.append(f"{whole}.{rng.randint(0, 10 ** rng.randint(1, 8) - 1)}")
            elif shape < 0.9:
                fields.append(rng.choice(letters))
            else:
                word = "".join(rng.choice(letters) for _ in range(rng.randint(2, 9)))
                fields.append(word if rng.random() < 0.5 else word.capitalize())
        talker = "".join(rng.choice(letters) for _ in range(rng.randint(3, 5)))
        body = ",".join([talker, *fields]).encode()
        s = b"$" + body + b"*" + f"{checksum(body):02X}".encode() + b"\r\n"
        out.append(s)
        total += len(s)
    return out


@lru_cache(maxsize=64)
def _model(sent_at: int, read_at: int) -> tuple[float, ...]:
    """log2 probabilities of the 256 byte values a receiver at ``read_at`` reads from NMEA-like
    text sent at ``sent_at`` (add-one smoothing)."""
    rng = random.Random(f"helmcheck-baudguess/{sent_at}/{read_at}")
    counts = [1] * 256
    sentences = _sentences(rng, _MODEL_BYTES)
    if sent_at == read_at:
        for s in sentences:
            for b in s:
                counts[b] += 1
    else:
        t = Ticks(sent_at, read_at)
        line, rcv = SenderLine(t), Receiver(t)
        at = t.tx_bit
        i = read = 0
        while i < len(sentences) and read < _MODEL_READ:
            for _ in range(rng.randint(1, 3)):  # a burst of sentences back to back
                if i >= len(sentences):
                    break
                for b in sentences[i]:
                    line.add(at, b)
                    at += t.tx_frame
                i += 1
            at += rng.randint(1, 400) * t.tx_bit  # then the line rests
            for got in rcv.run(line, at):
                counts[got.byte] += 1
                read += 1
    total = sum(counts)
    return tuple(math.log2(c / total) for c in counts)


def guess_baud(data: bytes, declared: int, candidates: tuple[int, ...] = COMMON_BAUDS) -> BaudGuess:
    """Which rate would make ``data`` (captured at ``declared`` baud) sentences (module docstring)."""
    good = valid_sentence_bytes(data)
    if data and good >= SENTENCE_SHARE * len(data):
        return BaudGuess(declared, declared, good, {}, f"{good} of {len(data)} bytes are sentences with a valid "
                                                         f"checksum at the declared {declared} baud")
    if len(data) < MIN_BYTES:
        return BaudGuess(None, declared, good, {}, f"{len(data)} bytes are too few to tell a baud rate "
                                                    f"(at least {MIN_BYTES})")
    counts = [0] * 256
    for b in data:
        counts[b] += 1
    if counts.count(0) == 255:
        return BaudGuess(None, declared, good, {}, f"the {len(data)} bytes are all 0x{data[0]:02x}: a line held "
                                                    "at one level or a dead device, which no baud rate explains")
    scores = {}
    for c in dict.fromkeys((*candidates, declared)):
        model = _model(c, declared)
        scores[c] = sum(n * model[v] for v, n in enumerate(counts) if n) / len(data)
    ranked = sorted(scores.items(), key=lambda kv: kv[1], reverse=True)
    (best, s1), (second, s2) = ranked[0], ranked[1]
    scores[0] = -8.0
    if s1 - max(s2, -8.0) < MARGIN_BITS:
        rival = f"{second} baud" if s2 >= -8.0 else "random noise"
        return BaudGuess(None, declared, good, scores,
                         f"no baud rate stands out: {best} baud explains the bytes no better than {rival} "
                         f"({s1:.2f} against {max(s2, -8.0):.2f} bits a byte)")
    if best == declared:
        return BaudGuess(declared, declared, good, scores,
                         f"the bytes look like text at the declared {declared} baud, spoilt ({good} of {len(data)} "
                         "bytes in sentences with a valid checksum)")
    return BaudGuess(best, declared, good, scores,
                     f"the bytes read at {declared} baud look like sentences sent at {best} baud "
                     f"({s1:.2f} bits a byte against {s2:.2f} for {second} baud)")
