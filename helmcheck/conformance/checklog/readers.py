"""Log readers: one streaming reader per capture format, and the format detector.

This module owns turning a capture file into a stream of records (:data:`Chunk`): timed runs of
wire bytes with the log line they came from, as the :class:`~helmcheck.judge.wire.WireEvent` s the
observers are fed, without keeping the file in memory. It judges nothing; the checker
(:mod:`.checker`) hands the records to the observers, which re-frame the bytes (RH-FRM-6/7) and
judge them.

Formats (detected from the first non-blank lines, :func:`detect_format`):

``wirelog``
    helmcheck wire-log 1 (``docs/contracts.md``): ``<seconds> <dir> <payload>`` per line,
    ``#`` comments (the header may carry ``time_scale K`` and ``baud N``), ``!`` notes.

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

Direction: by default ``>`` (socat's left-to-right) is backseat→vehicle, as in the wire log;
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

Every text line is accounted for: a line the reader cannot read becomes an :class:`Unreadable`
record (direction ``?``) with a reason (the checker reports it as a finding with its line number).
"""

from __future__ import annotations

import itertools
import re
from dataclasses import dataclass
from datetime import datetime
from typing import BinaryIO, Callable, Iterable, Iterator, NamedTuple, Optional, Union

from ...grammar.capture import unescape
from ...judge.wire import WireEvent

__all__ = ["Chunk", "Unreadable", "LogMeta", "TimeUnit", "detect_format", "socat_time_unit", "timestamp_resolution",
           "read_chunks", "FORMATS", "UNREADABLE", "NOTE", "HEAD_BYTES"]

FORMATS = ("wirelog", "socat-v", "socat-x")
UNREADABLE = "?"
NOTE = "!"
#: How much of a file decides its format and timestamp unit (the checker reads as much first).
HEAD_BYTES = 64 * 1024


class Unreadable(NamedTuple):
    """A log line that could not be read (``dir`` is ``?``): ``note`` says why, ``text`` is the
    line as written (for evidence). Its first fields are a :class:`~helmcheck.judge.wire.WireEvent`'s."""

    t: float
    dir: str
    data: bytes
    note: str
    lineno: int
    text: str


#: What a reader yields: a record as the :class:`~helmcheck.judge.wire.WireEvent` the observers
#: are fed (bytes ``>`` to or ``<`` from the vehicle at ``t`` seconds since the log began, or a
#: ``!`` note), or an :class:`Unreadable` line.
Chunk = Union[WireEvent, Unreadable]


@dataclass
class LogMeta:
    """What the log says about itself; filled in as the header is read."""

    format: str = "wirelog"
    time_scale: Optional[float] = None
    baud: Optional[int] = None
    resolution: float = 1e-6  #: finest timestamp step the log can show, seconds
    header: list = None  # type: ignore[assignment]
    #: How the digits after the seconds' dot are read: ``us``, ``ns``, ``ms``, ``decimal``
    #: (a decimal fraction of a second) or ``none`` (whole seconds); None until reading begins.
    time_unit: Optional[str] = None
    time_digits: Optional[int] = None  #: width of the fraction as written (9 for socat 1.7.4)
    time_unit_basis: str = ""  #: the evidence for ``time_unit``, one sentence
    time_unit_ambiguous: bool = False  #: both readings of nine digits fitted the head

    def __post_init__(self) -> None:
        if self.header is None:
            self.header = []


# --------------------------------------------------------------------------- detection

_SOCAT_HEADER = re.compile(
    rb"([<>]) (\d{4})/(\d\d)/(\d\d) (\d\d):(\d\d):(\d\d)(?:\.(\d+))?\s+length=(\d+) from=(\d+) to=(-?\d+)\s*$")
_SOCAT_HEADER_ANYWHERE = re.compile(
    rb"([<>]) (\d{4})/(\d\d)/(\d\d) (\d\d):(\d\d):(\d\d)(?:\.(\d+))?\s+length=(\d+) from=(\d+) to=(-?\d+)[ \t]*\r?\n?$")
#: A record's head: seconds, direction, one optional space; the payload is the rest of the line
#: less its line end (a "\n", then a "\r").
_WIRE_HEAD = re.compile(rb"(\d+(?:\.(\d+))?) (>~|<~|>|<|!) ?")
_HEX_LINE = re.compile(rb"^(?: [0-9a-fA-F]{2})+\s*$")


def detect_format(head: bytes) -> Optional[str]:
    """The format of a log from its first bytes (a few KiB), or None when none fits."""
    lines = [ln for ln in head.split(b"\n")[:50] if ln.strip()]
    if not lines:
        return None
    if lines[0].startswith(b"# helmcheck wire-log"):
        return "wirelog"
    for i, ln in enumerate(lines):
        if ln.startswith(b"#"):
            continue
        if _SOCAT_HEADER.match(ln.rstrip(b"\r")):
            nxt = lines[i + 1] if i + 1 < len(lines) else b""
            if _HEX_LINE.match(nxt) or (len(nxt) > 50 and nxt[:1] == b" " and b"  " in nxt[48:]):
                return "socat-x"
            return "socat-v"
        if _WIRE_HEAD.match(ln):
            return "wirelog"
        return None
    return None


def _decimals_resolution(frac: Optional[bytes]) -> float:
    if not frac:
        return 1.0
    stripped = frac.rstrip(b"0")
    return 10.0 ** -len(stripped) if stripped else 1.0


# --------------------------------------------------------------------------- socat time unit

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
        return _decimals_resolution(frac)


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


def timestamp_resolution(head: bytes, fmt: str) -> float:
    """The finest timestamp step seen in the first records: a clock that never shows more
    than whole seconds gives 1.0 even if it prints six decimals. For socat captures the
    fractions are read in the unit :func:`socat_time_unit` detects (1 µs for socat 1.7.4's
    nine digits, not 1 ns)."""
    best = 1.0
    if fmt == "wirelog":
        for ln in head.split(b"\n")[:2000]:
            m = _WIRE_HEAD.match(ln)
            if m and m.group(3) != b"!":
                best = min(best, _decimals_resolution(m.group(2)))
        return best
    unit = socat_time_unit(head)
    for m in _SOCAT_STAMP.finditer(head):
        best = min(best, unit.resolution(m.group(2)))
    return best


# --------------------------------------------------------------------------- readers

Progress = Optional[Callable[[int], None]]


def read_chunks(f: BinaryIO, fmt: str, meta: LogMeta, *, swap: bool = False,
                progress: Progress = None) -> Iterator[Chunk]:
    """The records of an open binary log file in format ``fmt`` (streaming, constant memory)."""
    if fmt == "wirelog":
        return _read_wirelog(f, meta, swap, progress)
    if fmt == "socat-v":
        return _read_socat(f, meta, swap, progress, hex_mode=False)
    if fmt == "socat-x":
        return _read_socat(f, meta, swap, progress, hex_mode=True)
    raise ValueError(f"unknown log format {fmt!r}; known: {', '.join(FORMATS)}")


_SCALE = re.compile(r"\btime_scale[ =:]+([0-9.]+(?:[eE][-+]?\d+)?)")
_BAUD = re.compile(r"\bbaud[ =:]+(\d+)")
_SWAP = {">": "<", "<": ">"}


def header_comment(text: str, meta: LogMeta) -> None:
    if len(meta.header) < 8:
        meta.header.append(text[1:].strip())
    m = _SCALE.search(text)
    if m:
        try:
            v = float(m.group(1))
            if v > 0:
                meta.time_scale = v
        except ValueError:
            pass
    m = _BAUD.search(text)
    if m:
        meta.baud = int(m.group(1))


def _read_wirelog(f: BinaryIO, meta: LogMeta, swap: bool, progress: Progress) -> Iterator[Chunk]:
    """helmcheck wire-log 1 records (docs/contracts.md)."""
    meta.time_unit = "decimal"
    meta.time_unit_basis = "wire-log 1 times are decimal seconds since the log began"
    n = 0
    match = _WIRE_HEAD.match
    dirs = _SWAPPED_DIRS if swap else _DIRS
    for raw in f:
        n += 1
        if progress is not None:
            progress(len(raw))
        m = match(raw)
        if m is None:
            if raw[:1] == b"#":
                if n <= 16:
                    header_comment(raw.decode("utf-8", "replace").rstrip("\r\n"), meta)
                continue
            if not raw.strip():
                continue
            yield Unreadable(0.0, UNREADABLE, b"", "not a wire-log record (want '<seconds> <dir> <payload>')",
                             n, raw.decode("utf-8", "replace").rstrip("\r\n")[:200])
            continue
        stamp, _, d = m.groups()
        t = float(stamp)
        payload = raw[m.end():-1] if raw[-1:] == b"\n" else raw[m.end():]
        if payload[-1:] == b"\r":
            payload = payload[:-1]
        if d == b"!":
            yield WireEvent(t, NOTE, b"", payload.decode("utf-8", "replace"), n)
            continue
        if not payload.isascii():
            yield Unreadable(t, UNREADABLE, b"", "payload is not ASCII (bytes must be escaped as \\xNN)", n,
                             payload.decode("utf-8", "replace")[:200])
            continue
        if b"\\" in payload:
            payload = unescape(payload.decode("ascii"))
        direction, whole = dirs[d]
        if whole:
            yield WireEvent(t, direction, payload + b"\r\n", "", n)
        else:
            yield WireEvent(t, direction, payload, "", n)


#: wire-log direction → (the chunk's direction, a whole CR LF line); as written, and swapped
_DIRS = {b">": (">", True), b"<": ("<", True), b">~": (">", False), b"<~": ("<", False)}
_SWAPPED_DIRS = {b">": ("<", True), b"<": (">", True), b">~": ("<", False), b"<~": (">", False)}


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


def _read_socat(f: BinaryIO, meta: LogMeta, swap: bool, progress: Progress, hex_mode: bool) -> Iterator[Chunk]:
    """``socat -v`` / ``socat -x`` / ``socat -v -x`` blocks (see the module docstring)."""
    head, lines = _with_head(f)
    clock = _SocatClock(socat_time_unit(head), meta)
    del head
    n = 0
    block: Optional[dict] = None  # direction, t, lineno, want, got(bytearray)

    def new_block(m: re.Match, lineno: int) -> dict:
        d = m.group(1).decode()
        if swap:
            d = _SWAP[d]
        return {"dir": d, "t": clock.t(m, lineno), "lineno": lineno, "want": int(m.group(9)),
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
