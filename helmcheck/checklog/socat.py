"""The socat capture reader: ``socat -v``, ``socat -x`` and ``socat -v -x`` dumps.

``socat-v``
    ``socat -v`` text dump. Each block starts with a header
    ``> 2026/11/21 19:50:00.000123456  length=24 from=0 to=23`` (``>`` left-to-right, ``<``
    right-to-left) followed by exactly ``length`` data bytes, written as text: ``\\r``, ``\\a``,
    ``\\b``, ``\\v``, ``\\f`` and ``\\\\`` as two-character escapes, LF and TAB as themselves,
    other unprintable bytes as ``.`` (lossy: socat's own choice). A block that does not end in
    LF is followed on the same text line by the next header.

``socat-x``
    ``socat -x`` hex dump: the same header, then the bytes as `` 2f 24 ...`` on one line; and the
    ``socat -v -x`` combination: lines of at most 16 hex bytes (48 columns) plus two spaces and
    an ASCII column, each block ended by a ``--`` line.

Direction: by default ``>`` (socat's left-to-right) is backseat→vehicle, as in the wire log
(the records carry the wire log's directions, :mod:`helmcheck.grammar.wirelog`);
``swap=True`` (``--swap-directions``) exchanges them for a socat started with the vehicle side as
its first address.

socat timestamps: the fraction of a second is detected per file
---------------------------------------------------------------
The digits after the seconds' dot do not have one meaning. socat 1.7.4.x as packaged by Debian
and Ubuntu (1.7.4.4 checked) writes a *microsecond* count zero-padded to nine digits
(``10:23:04.000278241`` is 0.278241 s); a build formatting a nanosecond clock writes nine digits
of nanoseconds; hand-made or converted captures often carry six digits. The width alone cannot
tell the two nine-digit kinds apart, so :func:`socat_time_unit` decides from the header lines
of the head of the file (the first :data:`HEAD_BYTES`, the same bytes the checker reads first;
only header lines complete in the head count):

1. no header has a fraction: whole seconds (``none``);
2. fractions of any width other than nine are decimal fractions of a second (six digits are
   ``us``, three ``ms``, other widths ``decimal``);
3. nine digits, and some fraction's first three digits are not ``000``: **nanoseconds** — a
   microsecond count never reaches 1 000 000, so this is proof;
4. nine digits, every one beginning ``000``: **microseconds zero-padded to nine digits**. Read as
   nanoseconds, every block would fall in the first millisecond of its second: for one whole
   second that is a 1-in-1000 coincidence, for blocks in *k* distinct whole seconds about
   1000^-k. With *k* ≥ 2 the decision is taken as settled. With *k* = 1 (the head lies within
   one clock second: a capture shorter than a second, or a very fast link) both readings fit the
   data; the file is still read as microseconds, the choice 1000 times likelier, and
   :class:`LogMeta` says it was ambiguous.

The reader keeps checking past the head: a nine-digit fraction that cannot be a microsecond
count (≥ 1 000 000) while microseconds were chosen switches the rest of the file to nanoseconds,
re-bases the start time, and yields a note (direction ``!``) naming the line; the block times
before it came from nanosecond fractions below 1 ms read as microseconds, each off by less than
one second.
:func:`timestamp_resolution` follows the detected unit (a zero-padded microsecond clock has a
resolution of 1 µs, not 1 ns). :class:`LogMeta` records the unit (``time_unit``), the width
(``time_digits``) and the evidence in one sentence (``time_unit_basis``) for the report.

A line the reader cannot read becomes an :class:`~.records.Unreadable` record with a reason.
"""

from __future__ import annotations

import itertools
import re
from dataclasses import dataclass
from datetime import datetime
from typing import BinaryIO, Iterable, Iterator, Optional

from ..grammar.wirelog import FROM_VEHICLE, SWAPPED, TO_VEHICLE, WireEvent
from .records import HEAD_BYTES, NOTE, UNREADABLE, Chunk, LogMeta, Progress, Unreadable, decimals_resolution, \
    header_comment

__all__ = ["TimeUnit", "socat_time_unit", "socat_resolution", "read_socat", "SOCAT_HEADER", "HEX_LINE"]

SOCAT_HEADER = re.compile(
    rb"([<>]) (\d{4})/(\d\d)/(\d\d) (\d\d):(\d\d):(\d\d)(?:\.(\d+))?\s+length=(\d+) from=(\d+) to=(-?\d+)\s*$")
_SOCAT_HEADER_ANYWHERE = re.compile(
    rb"([<>]) (\d{4})/(\d\d)/(\d\d) (\d\d):(\d\d):(\d\d)(?:\.(\d+))?\s+length=(\d+) from=(\d+) to=(-?\d+)[ \t]*\r?\n?$")
HEX_LINE = re.compile(rb"^(?: [0-9a-fA-F]{2})+\s*$")


#: A complete socat block header anywhere in a text line (a ``-v`` block without a final LF is
#: followed by the next header on the same line): groups are the whole second and the fraction.
_SOCAT_STAMP = re.compile(
    rb"[<>] (\d{4}/\d\d/\d\d \d\d:\d\d:\d\d)(?:\.(\d+))?[ \t]+length=\d+ from=\d+ to=-?\d+[ \t]*\r?\n")
_PADDED_WIDTH = 9  #: the width at which a microsecond and a nanosecond count look alike
_NAMED_WIDTHS = {3: "ms", 6: "us"}


@dataclass(frozen=True)
class TimeUnit:
    """How the digits after a socat timestamp's seconds are read (module docstring, rules 1-4).

    ``padded_us``: nine digits hold a microsecond count (socat 1.7.4.x). ``ambiguous``: the head
    of the file fitted nanoseconds too (all its blocks within one clock second).
    """

    name: str
    digits: Optional[int]
    basis: str
    padded_us: bool = False
    ambiguous: bool = False

    def seconds(self, frac: Optional[bytes]) -> float:
        """The fraction of a second that ``frac`` (the digits after the dot) stands for."""
        if not frac:
            return 0.0
        if self.padded_us and len(frac) == _PADDED_WIDTH:
            return int(frac) / 1e6
        return int(frac) / 10 ** len(frac)

    def contradicted_by(self, frac: Optional[bytes]) -> bool:
        """True when ``frac`` cannot be a microsecond count although microseconds were chosen."""
        return (self.padded_us and frac is not None and len(frac) == _PADDED_WIDTH
                and frac[:3] != b"000")

    def resolution(self, frac: Optional[bytes]) -> float:
        """The timestamp step that ``frac`` shows, in seconds."""
        if self.padded_us and frac is not None and len(frac) == _PADDED_WIDTH:
            frac = frac[3:]
        return decimals_resolution(frac)


def socat_time_unit(head: bytes) -> TimeUnit:
    """The unit of the socat timestamp fractions in ``head`` (the first bytes of a capture).

    Only header lines complete in ``head`` count (one cut at the end of the head is skipped).
    The rule is the module docstring's, rules 1-4.
    """
    widths: dict[int, int] = {}
    nine = 0
    seconds: set[bytes] = set()  # distinct clock seconds of the 000-prefixed nine-digit stamps
    proof: Optional[bytes] = None  # the first nine-digit stamp that is no microsecond count
    for m in _SOCAT_STAMP.finditer(head):
        frac = m.group(2)
        if not frac:
            continue
        widths[len(frac)] = widths.get(len(frac), 0) + 1
        if len(frac) == _PADDED_WIDTH:
            nine += 1
            if frac[:3] == b"000":
                seconds.add(m.group(1))
            elif proof is None:
                proof = m.group(1) + b"." + frac
    if not widths:
        return TimeUnit("none", None, "the socat headers show whole seconds only")
    others = sorted(w for w in widths if w != _PADDED_WIDTH)
    if not nine:
        w = others[0] if len(others) == 1 else None
        name = _NAMED_WIDTHS.get(w, "decimal") if w is not None else "decimal"
        shown = " or ".join(str(x) for x in others)
        return TimeUnit(name, w, f"{sum(widths.values())} socat timestamp(s) with {shown} digits after "
                                 f"the dot: a decimal fraction of a second")
    mixed = f" ({sum(widths[w] for w in others)} with other widths read as decimals)" if others else ""
    if proof is not None:
        return TimeUnit("ns", _PADDED_WIDTH,
                        f"a 9-digit fraction ({proof.decode()}) is 1 000 000 or more, which no "
                        f"microsecond count reaches: nanoseconds{mixed}")
    k = len(seconds)
    if k >= 2:
        return TimeUnit("us", _PADDED_WIDTH,
                        f"all {nine} 9-digit fractions begin 000 across {k} distinct clock seconds: "
                        f"microseconds zero-padded to 9 digits (socat 1.7.4); read as nanoseconds "
                        f"every block would fall in the first millisecond of its second{mixed}",
                        padded_us=True)
    return TimeUnit("us", _PADDED_WIDTH,
                    f"all {nine} 9-digit fractions begin 000 but lie within one clock second, so "
                    f"nanoseconds fit too: read as microseconds zero-padded to 9 digits (1000 times "
                    f"likelier){mixed}", padded_us=True, ambiguous=True)


def socat_resolution(head: bytes) -> float:
    """The finest timestamp step in the socat headers of ``head``, in the unit
    :func:`socat_time_unit` detects (1 µs for socat 1.7.4's nine digits, not 1 ns)."""
    best = 1.0
    unit = socat_time_unit(head)
    for m in _SOCAT_STAMP.finditer(head):
        best = min(best, unit.resolution(m.group(2)))
    return best


#: socat's arrow → the record's direction (:mod:`helmcheck.grammar.wirelog`): left to right is
#: backseat→vehicle unless the directions are swapped.
_ARROWS = {b">": TO_VEHICLE, b"<": FROM_VEHICLE}
_SWAPPED_ARROWS = {arrow: SWAPPED[d] for arrow, d in _ARROWS.items()}

_V_ESC = {ord("r"): 13, ord("a"): 7, ord("b"): 8, ord("v"): 11, ord("f"): 12, ord("\\"): 92,
          ord("n"): 10, ord("t"): 9}


class _SocatClock:
    """Seconds since the first block header, with the fraction read in the detected unit."""

    def __init__(self, unit: TimeUnit, meta: LogMeta):
        self.unit = unit
        self.meta = meta
        self.first: Optional[tuple[float, Optional[bytes]]] = None  # whole seconds, fraction
        self.note = ""  #: set when the unit changed at the last header read
        self.record()

    def record(self) -> None:
        """Write the unit in use into the log's :class:`LogMeta`."""
        u = self.unit
        self.meta.time_unit, self.meta.time_digits = u.name, u.digits
        self.meta.time_unit_basis, self.meta.time_unit_ambiguous = u.basis, u.ambiguous

    def started(self) -> bool:
        return self.first is not None

    def t(self, m: re.Match, lineno: int) -> float:
        y, mo, d, hh, mm, ss = (int(m.group(i)) for i in range(2, 8))
        whole = datetime(y, mo, d, hh, mm, ss).timestamp()
        frac = m.group(8)
        if self.unit.contradicted_by(frac):
            was = self.unit
            self.unit = TimeUnit("ns", _PADDED_WIDTH,
                                 f"{was.basis}; but line {lineno} has the fraction .{frac.decode()}, "
                                 f"which no microsecond count reaches: nanoseconds from there on")
            self.record()
            self.note = (f"socat timestamps: line {lineno} shows .{frac.decode()}, so the 9-digit "
                         f"fractions are nanoseconds, not microseconds as the head suggested; earlier "
                         f"block times may be off by up to 1 s")
        if self.first is None:
            self.first = (whole, frac)
        w0, f0 = self.first
        return (whole - w0) + (self.unit.seconds(frac) - self.unit.seconds(f0))


def _with_head(f: Iterable[bytes]) -> tuple[bytes, Iterator[bytes]]:
    """The first :data:`HEAD_BYTES` of the line iterator ``f``, and all its lines again."""
    lines = iter(f)
    kept: list[bytes] = []
    size = 0
    for raw in lines:
        kept.append(raw)
        size += len(raw)
        if size >= HEAD_BYTES:
            break
    return b"".join(kept)[:HEAD_BYTES], itertools.chain(kept, lines)


def read_socat(f: BinaryIO, meta: LogMeta, swap: bool, progress: Progress, hex_mode: bool) -> Iterator[Chunk]:
    """``socat -v`` / ``socat -x`` / ``socat -v -x`` blocks (see the module docstring)."""
    head, lines = _with_head(f)
    clock = _SocatClock(socat_time_unit(head), meta)
    del head
    n = 0
    block: Optional[dict] = None  # direction, t, lineno, want, got(bytearray)

    arrows = _SWAPPED_ARROWS if swap else _ARROWS

    def new_block(m: re.Match, lineno: int) -> dict:
        return {"dir": arrows[m.group(1)], "t": clock.t(m, lineno), "lineno": lineno, "want": int(m.group(9)),
                "got": bytearray(), "text": []}

    def finish(b: dict, short_reason: str = "") -> Iterator[Chunk]:
        data = bytes(b["got"])
        text = "".join(b["text"])[:300]
        if len(data) != b["want"]:
            yield Unreadable(b["t"], UNREADABLE, b"",
                             f"socat block announces length={b['want']} but carries {len(data)} bytes"
                             + (f" ({short_reason})" if short_reason else ""), b["lineno"], text)
        if data:
            yield WireEvent(b["t"], b["dir"], data, "", b["lineno"])

    for raw in lines:
        n += 1
        if progress is not None:
            progress(len(raw))
        line = raw
        while True:
            if block is None:
                if not line.strip():
                    break
                if line.startswith(b"#") and not clock.started():
                    header_comment(line.decode("utf-8", "replace").rstrip("\r\n"), meta)
                    break
                m = _SOCAT_HEADER_ANYWHERE.match(line)
                if m is None:
                    if hex_mode and line.strip() == b"--":
                        break
                    yield Unreadable(0.0, UNREADABLE, b"", "not a socat block header or data", n,
                                     line.decode("utf-8", "replace")[:200])
                    break
                block = new_block(m, n)
                if clock.note:
                    yield WireEvent(block["t"], NOTE, b"", clock.note, n)
                    clock.note = ""
                if block["want"] == 0:
                    yield from finish(block)
                    block = None
                break
            # inside a block: consume data from this text line
            if hex_mode:
                consumed_all = _hex_consume(line, block)
                if consumed_all is None:
                    yield from finish(block, "hex dump line unreadable")
                    block = None
                    yield Unreadable(0.0, UNREADABLE, b"", "not a socat hex dump line", n,
                                     line.decode("utf-8", "replace")[:200])
                    break
                if len(block["got"]) >= block["want"]:
                    yield from finish(block)
                    block = None
                break
            rest = _text_consume(line, block)
            if len(block["got"]) >= block["want"]:
                yield from finish(block)
                block = None
                if rest.strip():
                    line = rest  # the next header follows on the same text line
                    continue
            break
    if block is not None:
        yield from finish(block, "log ended inside the block")


def _text_consume(line: bytes, block: dict) -> bytes:
    """Decode ``socat -v`` text into the block until it has ``want`` bytes; returns the rest."""
    got = block["got"]
    want = block["want"]
    i, n = 0, len(line)
    start = 0
    while i < n and len(got) < want:
        c = line[i]
        if c == 92 and i + 1 < n and line[i + 1] in _V_ESC:  # backslash escape
            got.append(_V_ESC[line[i + 1]])
            i += 2
        else:
            got.append(c)
            i += 1
    block["text"].append(line[start:i].decode("latin-1").replace("\n", ""))
    return line[i:]


def _hex_consume(line: bytes, block: dict) -> Optional[bool]:
    """Add the hex bytes of one ``-x`` (or ``-v -x``) dump line; None when unreadable."""
    s = line.rstrip(b"\r\n")
    if s.strip() == b"--":
        return True
    hex_part = s[:48] if len(s) > 48 and s[48:50] == b"  " else s
    toks = hex_part.split()
    try:
        vals = bytes(int(t, 16) for t in toks)
    except ValueError:
        return None
    if any(len(t) != 2 for t in toks):
        return None
    block["got"] += vals
    block["text"].append(vals.decode("latin-1"))
    return True
