"""Log readers: one streaming reader per capture format, and the format detector.

This module owns turning a capture file into a stream of :class:`Chunk` objects — timed runs of
wire bytes with the log line they came from — without keeping the file in memory. It judges
nothing; the checker (:mod:`.checker`) re-frames the bytes (RH-FRM-6/7) and judges them.

Formats (detected from the first non-blank lines, :func:`detect_format`):

``wirelog``
    helmcheck wire-log 1 (``docs/contracts.md``): ``<seconds> <dir> <payload>`` per line,
    ``#`` comments (the header may carry ``time_scale K`` and ``baud N``), ``!`` notes.

``socat-v``
    ``socat -v`` text dump. Each block starts with a header
    ``> 2026/11/21 19:50:00.123456  length=24 from=0 to=23`` (``>`` left-to-right, ``<``
    right-to-left) followed by exactly ``length`` data bytes, written as text: ``\\r``, ``\\a``,
    ``\\b``, ``\\v``, ``\\f`` and ``\\\\`` as two-character escapes, LF and TAB as themselves,
    other unprintable bytes as ``.`` (lossy: socat's own choice). A block that does not end in
    LF is followed on the same text line by the next header.

``socat-x``
    ``socat -x`` hex dump: the same header, then the bytes as `` 2f 24 ...`` on one line; and the
    ``socat -v -x`` combination: lines of at most 16 hex bytes plus an ASCII column, ended by
    ``--``.

Direction: by default ``>`` (socat's left-to-right) is backseat→vehicle, as in the wire log;
``swap=True`` (``--swap-directions``) exchanges them for a socat started with the vehicle side as
its first address.

Every text line is accounted for: a line the reader cannot read becomes a ``Chunk`` with
direction ``?`` and a reason (the checker reports it as a finding with its line number).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from datetime import datetime
from typing import BinaryIO, Callable, Iterator, Optional

from ...grammar.capture import unescape

__all__ = ["Chunk", "LogMeta", "detect_format", "read_chunks", "FORMATS", "UNREADABLE", "NOTE"]

FORMATS = ("wirelog", "socat-v", "socat-x")
UNREADABLE = "?"
NOTE = "!"


@dataclass(slots=True)
class Chunk:
    """Bytes seen on the wire at ``t`` (seconds since the log began) going ``direction``.

    ``direction`` is ``>`` (to the vehicle), ``<`` (from the vehicle), ``!`` (a recorder
    note, text in ``note``) or ``?`` (a log line that could not be read; ``note`` says why).
    ``complete`` is True when the record is a whole CR LF line by itself (wire-log ``>``/``<``).
    """

    t: float
    direction: str
    data: bytes
    lineno: int
    note: str = ""
    complete: bool = False
    text: str = ""  #: the payload as written in the log (for evidence)


@dataclass
class LogMeta:
    """What the log says about itself; filled in as the header is read."""

    format: str = "wirelog"
    time_scale: Optional[float] = None
    baud: Optional[int] = None
    resolution: float = 1e-6  #: finest timestamp step the log can show, seconds
    header: list = None  # type: ignore[assignment]

    def __post_init__(self) -> None:
        if self.header is None:
            self.header = []


# --------------------------------------------------------------------------- detection

_SOCAT_HEADER = re.compile(
    rb"([<>]) (\d{4})/(\d\d)/(\d\d) (\d\d):(\d\d):(\d\d)(?:\.(\d+))?\s+length=(\d+) from=(\d+) to=(-?\d+)\s*$")
_SOCAT_HEADER_ANYWHERE = re.compile(
    rb"([<>]) (\d{4})/(\d\d)/(\d\d) (\d\d):(\d\d):(\d\d)(?:\.(\d+))?\s+length=(\d+) from=(\d+) to=(-?\d+)[ \t]*\r?\n?$")
_WIRE_RECORD = re.compile(rb"^(\d+(?:\.(\d+))?) (>~|<~|>|<|!) ?(.*?)\r?\n?$", re.S)
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
        if _WIRE_RECORD.match(ln):
            return "wirelog"
        return None
    return None


def _decimals_resolution(frac: Optional[bytes]) -> float:
    if not frac:
        return 1.0
    stripped = frac.rstrip(b"0")
    return 10.0 ** -len(stripped) if stripped else 1.0


def timestamp_resolution(head: bytes, fmt: str) -> float:
    """The finest timestamp step seen in the first records: a clock that never shows more
    than whole seconds gives 1.0 even if it prints six decimals."""
    best = 1.0
    for ln in head.split(b"\n")[:2000]:
        if fmt == "wirelog":
            m = _WIRE_RECORD.match(ln)
            if m and m.group(3) != b"!":
                best = min(best, _decimals_resolution(m.group(2)))
        else:
            m = _SOCAT_HEADER.match(ln.rstrip(b"\r"))
            if m:
                best = min(best, _decimals_resolution(m.group(8)))
    return best


# --------------------------------------------------------------------------- readers

Progress = Optional[Callable[[int], None]]


def read_chunks(f: BinaryIO, fmt: str, meta: LogMeta, *, swap: bool = False,
                progress: Progress = None) -> Iterator[Chunk]:
    """Chunks of an open binary log file in format ``fmt`` (streaming, constant memory)."""
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


def _header_comment(text: str, meta: LogMeta) -> None:
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
    n = 0
    match = _WIRE_RECORD.match
    for raw in f:
        n += 1
        if progress is not None:
            progress(len(raw))
        if raw[:1] == b"#":
            if n <= 16:
                _header_comment(raw.decode("utf-8", "replace").rstrip("\r\n"), meta)
            continue
        m = match(raw)
        if m is None:
            if not raw.strip():
                continue
            yield Chunk(0.0, UNREADABLE, b"", n, "not a wire-log record (want '<seconds> <dir> <payload>')",
                        text=raw.decode("utf-8", "replace").rstrip("\r\n")[:200])
            continue
        t = float(m.group(1))
        d = m.group(3).decode()
        payload = m.group(4)
        if d == "!":
            yield Chunk(t, NOTE, b"", n, payload.decode("utf-8", "replace"))
            continue
        try:
            text = payload.decode("ascii")
        except UnicodeDecodeError:
            yield Chunk(t, UNREADABLE, b"", n, "payload is not ASCII (bytes must be escaped as \\xNN)",
                        text=payload.decode("utf-8", "replace")[:200])
            continue
        data = unescape(text) if "\\" in text else text.encode("ascii")
        direction = d[0]
        if swap:
            direction = _SWAP[direction]
        if len(d) == 1:
            yield Chunk(t, direction, data + b"\r\n", n, complete=True, text=text)
        else:
            yield Chunk(t, direction, data, n, text=text)


_V_ESC = {ord("r"): 13, ord("a"): 7, ord("b"): 8, ord("v"): 11, ord("f"): 12, ord("\\"): 92,
          ord("n"): 10, ord("t"): 9}


def _socat_time(m: re.Match, t0: list) -> float:
    y, mo, d, hh, mm, ss = (int(m.group(i)) for i in range(2, 8))
    frac = m.group(8) or b"0"
    base = datetime(y, mo, d, hh, mm, ss).timestamp() + int(frac) / 10 ** len(frac)
    if not t0:
        t0.append(base)
    return base - t0[0]


def _read_socat(f: BinaryIO, meta: LogMeta, swap: bool, progress: Progress, hex_mode: bool) -> Iterator[Chunk]:
    """``socat -v`` / ``socat -x`` / ``socat -v -x`` blocks (see the module docstring)."""
    t0: list = []
    n = 0
    block: Optional[dict] = None  # direction, t, lineno, want, got(bytearray)

    def new_block(m: re.Match, lineno: int) -> dict:
        d = m.group(1).decode()
        if swap:
            d = _SWAP[d]
        return {"dir": d, "t": _socat_time(m, t0), "lineno": lineno, "want": int(m.group(9)),
                "got": bytearray(), "text": []}

    def finish(b: dict, short_reason: str = "") -> Iterator[Chunk]:
        data = bytes(b["got"])
        text = "".join(b["text"])[:300]
        if len(data) != b["want"]:
            yield Chunk(b["t"], UNREADABLE, b"", b["lineno"],
                        f"socat block announces length={b['want']} but carries {len(data)} bytes"
                        + (f" ({short_reason})" if short_reason else ""), text=text)
        if data:
            yield Chunk(b["t"], b["dir"], data, b["lineno"], text=text)

    for raw in f:
        n += 1
        if progress is not None:
            progress(len(raw))
        line = raw
        while True:
            if block is None:
                if not line.strip():
                    break
                if line.startswith(b"#") and t0 == []:
                    _header_comment(line.decode("utf-8", "replace").rstrip("\r\n"), meta)
                    break
                m = _SOCAT_HEADER_ANYWHERE.match(line)
                if m is None:
                    if hex_mode and line.strip() == b"--":
                        break
                    yield Chunk(t0 and 0.0 or 0.0, UNREADABLE, b"", n,
                                "not a socat block header or data", text=line.decode("utf-8", "replace")[:200])
                    break
                block = new_block(m, n)
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
                    yield Chunk(0.0, UNREADABLE, b"", n, "not a socat hex dump line",
                                text=line.decode("utf-8", "replace")[:200])
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
