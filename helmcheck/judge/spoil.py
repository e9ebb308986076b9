"""What a faulty line can do to a sentence: the form rule by which a judge gives a spoilt line to the line.

A serial line flips bits, loses bytes and picks up noise; a judge that reads a broken sentence
cannot always tell whether the implementation wrote it broken or the line broke it. This module
owns the *form* half of the rule the judges use (``docs/contracts.md``, "A faulty line"):
:func:`explain` says whether a broken line has the form a line fault gives, and names it —

* **flip** — at most :data:`MAX_FLIPS` bit flips make it a well-framed line (``$``, printable
  body, ``*``, two upper-case hex digits, CR LF, the same length) whose checksum is right;
* **drop** — one byte put back (a ``$``, a checksum digit, a ``*``, a CR, an LF between two
  lines run together, or the one body byte the checksum says is missing) makes it clean
  sentences;
* **noise** — a run of at most :data:`NOISE_RUN_MAX` bytes taken out makes it a clean sentence;
* **torn** — a line shorter than any sentence (:data:`SHORTEST`, :data:`SHORTEST_COMMAND`), or
  a sentence cut short by a ``$`` (noise, or its LF lost);

and what is not one of these (commas in ``$C``, a wrong checksum many bits off, anything under a
right checksum — a field out of range, a field that does not read —, a parity bit in every byte)
is the implementation's. The other
half of the rule is repetition, :mod:`.streaks`: the line's faults are random, an
implementation's are not, so an error of line form is the implementation's only when it comes
back the same (:func:`signature`) on :data:`RERUNS` re-runs in a row.

Clean means :func:`~helmcheck.grammar.decode` reads every line of the repaired bytes as a valid
sentence with no finding, ended by CR LF. Pure: no clock, no I/O.
"""

from __future__ import annotations

import re
from typing import NamedTuple, Optional

from ..grammar import decode
from ..grammar.checksum import checksum
from ..grammar.wirelog import escape

__all__ = ["Spoil", "explain", "explain_discard", "signature", "flips_to_frame", "RERUNS", "REPEAT", "NOISE_RUN_MAX",
           "MAX_FLIPS", "SHORTEST", "SHORTEST_COMMAND"]

#: Re-runs of a spoilt observation the tester makes (and a judge waits for). An error of line form
#: is the implementation's when the original and this many re-runs show it alike (:data:`REPEAT`
#: in a row). Three: at one bit in 10,000 flipped, a 160-byte report is spoilt one time in eight,
#: and the same form (the same checksum bit off) comes back on three re-runs with a chance of
#: about (1/8 x 1/8)^3, 4e-6, per spoilt report; an $ACK lost (3 % a command at that rate) is lost
#: again three times with a chance of 3e-5.
RERUNS = 3
REPEAT = RERUNS + 1
#: Bytes of noise one line may carry and still be explained (the relay's default burst, 1-8).
NOISE_RUN_MAX = 8
#: Bit flips one line may carry and still be explained (two in one report at 1e-4 a bit: 0.8 %).
MAX_FLIPS = 2
#: ``$ACK,1,0,0*hh`` CR LF: no sentence a vehicle sends is shorter.
SHORTEST = 15
#: ``$OSD*hh`` CR LF: no command a backseat sends is shorter.
SHORTEST_COMMAND = 9

_FRAME = re.compile(rb"\$([\x20-\x23\x25-\x29\x2b-\x7e]*)\*([0-9A-F]{2})\r\n\Z")
_HEX = b"0123456789ABCDEF"
_ALLOWED = frozenset(b for b in range(0x20, 0x7F) if b not in (0x24, 0x2A))


def _popcount(x: int) -> int:
    return bin(x).count("1")


def _repairs(b: int) -> tuple[int, tuple[int, ...]]:
    """The fewest bit flips (up to two) that make ``b`` a body byte, and the bytes they give."""
    if b in _ALLOWED:
        return 0, (b,)
    one = tuple(b ^ (1 << i) for i in range(8) if b ^ (1 << i) in _ALLOWED)
    if one:
        return 1, one
    two = tuple(b ^ (1 << i) ^ (1 << j) for i in range(8) for j in range(i + 1, 8)
                if b ^ (1 << i) ^ (1 << j) in _ALLOWED)
    return (2, two) if two else (9, ())


_REPAIR = tuple(_repairs(b) for b in range(256))


class Spoil(NamedTuple):
    """A broken line of a form a line fault gives: ``kind`` (flip, drop, noise, torn), ``text``
    (for a reason: what the line may have done) and the error's form (:func:`signature`)."""

    kind: str
    text: str
    sig: tuple


def _clean(cand: bytes, profile) -> bool:
    """Every line of ``cand`` is a valid sentence with no finding, ended by CR LF."""
    if not cand.endswith(b"\r\n"):
        return False
    for piece in cand[:-1].split(b"\n"):
        line = piece + b"\n"
        if not line.endswith(b"\r\n") or line[:1] != b"$":
            return False
        d = decode(line, profile)
        if not d.valid or d.findings:
            return False
    return True


def _framed(cand: bytes) -> bool:
    m = _FRAME.match(cand)
    return m is not None and checksum(m.group(1)) == int(m.group(2), 16)


def flips_to_frame(raw: bytes) -> Optional[int]:
    """The fewest bit flips (1 to :data:`MAX_FLIPS`) that make ``raw`` a well-framed line of the same
    length with a right checksum, or None (none, or more than that, or it already is one)."""
    n = len(raw)
    if n < 8:
        return None
    fixed = (_popcount(raw[0] ^ 0x24) + _popcount(raw[-2] ^ 0x0D) + _popcount(raw[-1] ^ 0x0A)
             + _popcount(raw[-5] ^ 0x2A))
    if fixed > MAX_FLIPS:
        return None
    body = raw[1:-5]
    base = 0
    choices = []
    for b in body:
        c, opts = _REPAIR[b]
        if c:
            fixed += c
            if fixed > MAX_FLIPS:
                return None
            choices.append((b, opts))
    clean_part = bytes(b for b in body if b in _ALLOWED)
    base = checksum(clean_part)
    sums = {base}
    for b, opts in choices:  # each repair adds its byte to the checksum
        sums = {s ^ o for s in sums for o in opts}
    h1, h2 = raw[-4], raw[-3]
    cost1 = [_popcount(h1 ^ c) for c in _HEX]
    cost2 = [_popcount(h2 ^ c) for c in _HEX]
    best = MAX_FLIPS + 1
    left = MAX_FLIPS - fixed
    for s in sums:
        for v in range(256):
            c = cost1[v >> 4] + cost2[v & 15]
            if c > left:
                continue
            c += _popcount(s ^ v)  # what is still off: a flip of that bit in some body byte
            if c < best:
                best = c
    total = fixed + best
    return total if 0 < total <= MAX_FLIPS else None


def _inserts(raw: bytes) -> list[tuple[int, int]]:
    """(position, byte) of the one byte whose loss could have made ``raw`` (module docstring)."""
    n = len(raw)
    out = []
    if raw[:1] != b"$":
        out.append((0, 0x24))
    if raw.endswith(b"\n") and not raw.endswith(b"\r\n"):
        out.append((n - 1, 0x0D))
    if not raw.endswith(b"\n"):
        out.append((n, 0x0A))
    for i in range(1, n):  # two lines run together: the LF after the first one's CR
        if raw[i] == 0x24 and raw[i - 1] == 0x0D:
            out.append((i, 0x0A))
    star = raw.rfind(b"*")
    end = n - 2 if raw.endswith(b"\r\n") else n
    if star < 0 and end >= 3:
        out.append((end - 2, 0x2A))
    elif star >= 0:
        for pos in range(star + 1, min(end, star + 3) + 1):
            out += [(pos, h) for h in _HEX]
        m = re.match(rb"\$([\x20-\x23\x25-\x29\x2b-\x7e]*)\*([0-9A-F]{2})\r\n\Z", raw)
        if m is not None:
            x = checksum(m.group(1)) ^ int(m.group(2), 16)
            if x in _ALLOWED:
                out += [(i, x) for i in range(1, star + 1)]
    return out


def _one_insert(raw: bytes, profile) -> Optional[tuple[int, int]]:
    for pos, b in _inserts(raw):
        if _clean(raw[:pos] + bytes((b,)) + raw[pos:], profile):
            return pos, b
    return None


def _one_run(raw: bytes, profile) -> Optional[tuple[int, int]]:
    """(position, length) of a run of noise whose removal leaves one clean sentence."""
    n = len(raw)
    for length in range(1, NOISE_RUN_MAX + 1):
        for i in range(0, n - length):
            cand = raw[:i] + raw[i + length:]
            if _framed(cand) and _clean(cand, profile):
                return i, length
    return None


def signature(raw: bytes, d=None) -> tuple:
    """The form of a broken line's error, for repetition: the clause it breaks and its message
    without the values — and, for a wrong checksum, by which bits it is off (random damage
    scatters over them; an implementation's wrong checksum keeps its own)."""
    if d is None:
        d = decode(raw)
    err = d.error
    if err is None:
        f = d.findings[0] if d.findings else None
        return ("finding", f.clause, _shape(f.message)) if f is not None else ("terminator", d.terminator)
    if err.clause == "RH-FRM-2":
        m = re.search(rb"\*([0-9A-Fa-f]{2})\r?\n?\Z", raw)
        star = raw.rfind(b"*")
        if m is not None and star > 0:
            return ("RH-FRM-2", checksum(raw[1:star]) ^ int(m.group(1), 16))
    return (err.clause, _shape(err.message))


def _shape(message: str) -> str:
    return re.sub(r"'[^']*'|0x[0-9A-Fa-f]+|\b[0-9A-Fa-f]{2}\b|\d+", "#", message)


def explain(raw: bytes, profile, d=None, shortest: int = SHORTEST) -> Optional[Spoil]:
    """The line fault that could have made ``raw`` (a line from ``$`` to LF that is not a clean
    sentence: invalid, or with a finding) out of clean sentences, or None (module docstring).
    ``shortest``: no sentence of the sender is shorter (a vehicle's :data:`SHORTEST`; a backseat's
    ``$OSD*hh`` CR LF, :data:`SHORTEST_COMMAND`)."""
    key = (raw, id(profile), shortest)
    if key in _EXPLAINED:
        return _EXPLAINED[key]
    if len(_EXPLAINED) >= 256:
        _EXPLAINED.clear()
    got = _EXPLAINED[key] = _explain(raw, profile, d, shortest)
    return got


_EXPLAINED: dict = {}


def _explain(raw: bytes, profile, d, shortest: int) -> Optional[Spoil]:
    got = _repaired(raw, profile, d)
    if got is None and raw[:1] == b"$" and raw.endswith(b"\n") and len(raw) < shortest:
        return Spoil("torn", f"a torn line ({len(raw)} bytes: shorter than any sentence)", ("torn",))
    return got


def _repaired(raw: bytes, profile, d) -> Optional[Spoil]:
    if d is None:
        d = decode(raw, profile)
    sig = signature(raw, d)
    if _framed(raw) and not d.findings:
        # well framed with a right checksum: judged as sent, on any link — unless a run of noise
        # whose bytes cancel in the XOR (two alike) taken out makes it clean. Two flips of the same
        # bit in two bytes would hide too, but a value out of range under a right checksum is what
        # a sender wrote far more often than that
        got = _one_run(raw, profile)
        if got is not None:
            pos, length = got
            return Spoil("noise", f"a valid line with {length} bytes of noise in it "
                                  f"({escape(raw[pos:pos + length])!r} at byte {pos})", sig)
        return None
    flips = flips_to_frame(raw)
    if flips is not None:
        return Spoil("flip", f"a line {'one bit' if flips == 1 else f'{flips} bits'} from a well-framed line with "
                             "a right checksum", sig)
    got = _one_insert(raw, profile)
    if got is not None:
        pos, b = got
        what = {0x24: "its '$'", 0x0D: "a CR", 0x0A: "the LF between two lines"}.get(b, f"one byte (0x{b:02x})")
        return Spoil("drop", f"a line with {what} missing (byte {pos})", sig)
    got = _one_run(raw, profile)
    if got is not None:
        pos, length = got
        return Spoil("noise", f"a valid line with {length} byte{'s' if length > 1 else ''} of noise in it "
                              f"({escape(raw[pos:pos + length])!r} at byte {pos})", sig)
    return None


def explain_discard(raw: bytes, clause: str, reason: str, profile) -> Optional[Spoil]:
    """The line fault that could have made a run the framer discarded (module docstring): a whole
    sentence whose ``$`` was lost or flipped, a sentence cut by a ``$`` (its LF lost or flipped, or
    noise in it), or bytes between lines (noise). An overlong line (RH-FRM-6) is not explained."""
    if clause == "RH-FRM-6":
        return None
    if raw[:1] == b"$":  # a sentence cut short by a '$': its LF lost or flipped, or noise in it
        for cand, what in ((raw + b"\n", "its LF missing"), (raw[:-1] + b"\n", "its LF changed")):
            if _clean(cand, profile):
                return Spoil("drop" if what.endswith("missing") else "flip", f"a line with {what}", ("torn", what))
        return Spoil("torn", "a sentence cut short by a '$' (noise in it, or its LF lost)", ("torn",))
    if raw.endswith(b"\n"):  # a whole line without its '$'
        for cand, what in ((b"$" + raw, "drop"), (b"$" + raw[1:], "flip")):
            if _clean(cand, profile):
                return Spoil(what, "a line with its '$' " + ("missing" if what == "drop" else "changed"),
                             ("dollar", what))
    return Spoil("noise", f"{len(raw)} byte{'s' if len(raw) > 1 else ''} between lines (line noise, or bytes "
                          "the sender put there)", ("junk", raw[:32]))
