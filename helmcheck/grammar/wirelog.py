"""The wire log: helmcheck's capture format, its one reader and its one writer.

A wire log is the timestamped transcript of both directions of a link. Version 1, UTF-8 text,
one record per line (the full description is in ``docs/contracts.md`` and the README)::

    # helmcheck wire-log 1
    # started 2026-11-21T19:50:00.000000Z  port /dev/pts/3  baud 19200  time_scale 20
    0.000000 > $OSD,G,C,S,P,,,,*5F
    0.012400 < $ACK,8,0,0*5D
    0.500000 >~ garbage\\x00\\xff$OM
    3.100000 ! lockout injected

This module owns all of it; nothing else in helmcheck writes or parses a record:

* **the format** — the header (:data:`HEADER`, then ``#`` comment lines, among them the one
  naming the run that wrote the log: :func:`run_header`, read by :func:`read_run_header`), the record syntax
  (:data:`RECORD_HEAD`, :func:`format_record`, :func:`column`) and the escaping
  (:func:`escape`, :func:`unescape`: bytes outside 0x20–0x7E, and ``\\``, are escaped);
* **the directions** — :data:`TO_VEHICLE` (``>``, backseat→vehicle) and :data:`FROM_VEHICLE`
  (``<``), whoever recorded; alone they mark a line that ended in CR LF (not written), with ``~``
  (:data:`TO_VEHICLE_RUN`, :data:`FROM_VEHICLE_RUN`) any other run of bytes, written in full;
  :data:`NOTE` (``!``) is a note; :data:`DIRECTIONS` is the closed set of the direction column;
* **the line's transmit time** — 8N1, :data:`BITS_PER_BYTE` bits a byte: :func:`transmit_time`
  (the judges take it through :mod:`helmcheck.judge.timing`);
* **the record** — :class:`WireEvent`: bytes one way at a time, or a note, with its log line;
  the judges are fed exactly these (:mod:`helmcheck.judge.wire` re-exports it). A line that is
  not a record reads as an :class:`Unreadable`;
* **the reader** — :func:`read_wire_log` streams the records of a log's lines (bytes), never
  raising on a bad line (``check-log``, the reports' summary, the run facts);
  :func:`read_records` is the same reader raising :class:`WireLogError` on the first bad line
  (``certify vehicle --resume``); :func:`parse_record` reads one line (``helmcheck parse``);
* **the writer** — :class:`WireLogWriter`: the header, then one record a line, flushed record by
  record (the emulator; the certifiers and ``replay`` through
  :class:`~helmcheck.line.recorder.Recorder`);
* **segments** — a long session's log may go on in further files beside the first
  (``wire.log``, ``wire.001.log``, …): a segment ends with the note :data:`CONTINUED` naming the
  next (:func:`continued_in` reads it), and the next begins with the header and a comment naming
  the one before (:meth:`WireLogWriter.continue_in`). Line numbers and time go on across
  segments, so the segments read one after another are the session's log, numbered as written
  (finding the files is :mod:`helmcheck.reports.segments`).

Pure text processing: no clock, and no I/O beyond the lines and the stream it is handed.
"""

from __future__ import annotations

import re
from typing import IO, Callable, Iterable, Iterator, NamedTuple, Optional, Union

__all__ = ["HEADER", "TAG", "VERSION", "HEADER_LINES", "TO_VEHICLE", "FROM_VEHICLE", "TO_VEHICLE_RUN",
           "FROM_VEHICLE_RUN", "NOTE", "UNREADABLE", "DIRECTIONS", "SWAPPED", "BITS_PER_BYTE", "transmit_time",
           "WireEvent", "Unreadable", "Record", "WireLogError", "escape", "unescape", "is_line", "column",
           "format_record", "RECORD_HEAD", "read_wire_log", "read_records", "parse_record", "WireLogWriter",
           "CONTINUED", "continued_in", "segment_name", "RUNS", "MISSIONS_SEP", "RunHeader", "run_header", "read_run_header"]

# ---------------------------------------------------------------------- the format
TAG = "# helmcheck wire-log"  #: the first line's start, whatever the version
VERSION = 1
HEADER = f"{TAG} {VERSION}"  #: the first line of every wire log this version writes
#: Comment lines among the first this many lines are the log's header (they may carry
#: ``time_scale K`` and ``baud N``); later comments are skipped.
HEADER_LINES = 16

#: The runs that name themselves in a log's header (:func:`run_header`).
RUNS = ("certify vehicle", "certify backseat", "monitor", "emulate", "diff", "replay")
_RUN_HEADER = re.compile(r"^helmcheck (\S+) (" + "|".join(map(re.escape, RUNS)) + r")(?=[;:\s]|$)")
_PROFILE_PART = re.compile(r";\s*profile ([^;]+)")
_MISSIONS_PART = re.compile(r";\s*missions ([^;]+)")
#: Separates the mission directories of a run header (as ``PATH`` does).
MISSIONS_SEP = ":"


class RunHeader(NamedTuple):
    """What a run's header line says (:func:`read_run_header`)."""

    version: str  #: the helmcheck that wrote the log
    run: str  #: one of :data:`RUNS`
    profile: Optional[str]  #: the profile's name as the run gave it (a path, or ``rh5``)
    missions: tuple[str, ...]  #: the mission directories the run used


def run_header(version: str, run: str, profile: str, missions: Iterable[str] = (), more: str = "") -> str:
    """The header comment naming the run that writes a log (without ``# ``):
    ``helmcheck VERSION RUN[MORE]; profile NAME[; missions DIR:DIR]`` — ``MORE`` is free text
    without ``;`` (``monitor`` names its mode and ports there)."""
    text = f"helmcheck {version} {run}{more}; profile {profile}"
    missions = [str(m) for m in missions]
    return text + (f"; missions {MISSIONS_SEP.join(missions)}" if missions else "")


def read_run_header(text: str) -> Optional[RunHeader]:
    """A header comment (without ``#``) read as :func:`run_header` writes it; ``None`` for any
    other comment."""
    m = _RUN_HEADER.match(text.strip())
    if m is None:
        return None
    p = _PROFILE_PART.search(text, m.end())
    d = _MISSIONS_PART.search(text, m.end())
    return RunHeader(m.group(1), m.group(2), (p.group(1).strip() or None) if p else None,
                     tuple(x for x in d.group(1).strip().split(MISSIONS_SEP) if x) if d else ())


# ---------------------------------------------------------------------- the directions
TO_VEHICLE = ">"  #: bytes from the backseat to the vehicle (a CR LF line when alone)
FROM_VEHICLE = "<"  #: bytes from the vehicle to the backseat (a CR LF line when alone)
TO_VEHICLE_RUN = ">~"  #: any other run of bytes to the vehicle, written in full
FROM_VEHICLE_RUN = "<~"  #: any other run of bytes from the vehicle, written in full
NOTE = "!"  #: a note by the recorder (an event, not wire bytes)
#: The direction column's values, as written.
DIRECTIONS = (TO_VEHICLE, FROM_VEHICLE, TO_VEHICLE_RUN, FROM_VEHICLE_RUN, NOTE)
#: What a reader yields for a line that is not a record (never written).
UNREADABLE = "?"
#: Each byte direction and the other one (a capture recorded with its sides exchanged).
SWAPPED = {TO_VEHICLE: FROM_VEHICLE, FROM_VEHICLE: TO_VEHICLE}

# ---------------------------------------------------------------------- the line
#: 8N1: one start bit, eight data bits, one stop bit (RH-FRM-9).
BITS_PER_BYTE = 10


def transmit_time(nbytes: int, baud: int) -> float:
    """Wall seconds the line needs for ``nbytes`` at ``baud`` (0 for an unpaced link);
    ``transmit_time(1, baud)`` is the time of one byte."""
    return nbytes * BITS_PER_BYTE / baud if baud else 0.0


# ---------------------------------------------------------------------- the record
class WireEvent(NamedTuple):
    """One record: bytes one way, or a note, at ``t`` wall seconds since the record began.
    (A named tuple: immutable, and cheap to make once per line of a long log.)"""

    t: float
    dir: str  #: ">" (:data:`TO_VEHICLE`), "<" (:data:`FROM_VEHICLE`) or "!" (:data:`NOTE`)
    data: bytes = b""  #: the exact bytes on the wire, a line's CR LF included
    note: str = ""
    lineno: int = 0  #: the record's line in the wire log (0 when not known)


class Unreadable(NamedTuple):
    """A log line that could not be read (``dir`` is :data:`UNREADABLE`): ``note`` says why,
    ``text`` is the line as written (for evidence). Its first fields are a :class:`WireEvent`'s."""

    t: float
    dir: str
    data: bytes
    note: str
    lineno: int
    text: str


#: What :func:`read_wire_log` yields.
Record = Union[WireEvent, Unreadable]


class WireLogError(ValueError):
    """A wire-log line that does not follow the format; names the line."""


# ---------------------------------------------------------------------- escaping and syntax
_ESC_RE = re.compile(rb"[^\x20-\x5b\x5d-\x7e]")
_UNESC_RE = re.compile(r"\\(x[0-9A-Fa-f]{2}|r|n|t|\\)")
_ESC = {0x0D: "\\r", 0x0A: "\\n", 0x5C: "\\\\"}
_UNESC = {"r": "\r", "n": "\n", "t": "\t", "\\": "\\"}


def _escaped(m: re.Match) -> bytes:
    b = m.group(0)[0]
    return _ESC.get(b, f"\\x{b:02x}").encode()


def escape(raw: bytes) -> str:
    """A payload as written: bytes 0x20–0x7E stand for themselves except ``\\``; the others are
    ``\\r``, ``\\n``, ``\\\\`` or ``\\xNN``. (A payload with nothing to escape, nearly every
    one, is only searched.)"""
    if _ESC_RE.search(raw) is None:
        return raw.decode("ascii")
    return _ESC_RE.sub(_escaped, raw).decode("ascii")


def unescape(text: str) -> bytes:
    """The bytes a written payload stands for (also reads ``\\t``)."""
    def sub(m: re.Match) -> str:
        e = m.group(1)
        if e[0] == "x":
            return chr(int(e[1:], 16))
        return _UNESC[e]

    return _UNESC_RE.sub(sub, text).encode("latin-1")


def is_line(raw: bytes) -> bool:
    """True when ``raw`` is one line ended by CR LF: written as ``>``/``<``, its CR LF left out."""
    return raw.endswith(b"\r\n") and b"\n" not in raw[:-1]


def column(direction: str, raw: bytes) -> str:
    """The direction column for ``raw`` seen going ``direction``: ``>``/``<`` for one CR LF
    line, ``>~``/``<~`` for any other run."""
    return direction if is_line(raw) else direction + "~"


def format_record(t: float, direction: str, raw: bytes = b"", note: str = "") -> str:
    """One log line (without newline) for bytes seen going ``direction`` at ``t``, or a note."""
    if direction == NOTE:
        return f"{t:.6f} {NOTE} {note}"
    if direction not in SWAPPED:
        raise ValueError(f"direction must be {TO_VEHICLE!r} or {FROM_VEHICLE!r}, not {direction!r}")
    if is_line(raw):
        return f"{t:.6f} {direction} {escape(raw[:-2])}"
    return f"{t:.6f} {direction}~ {escape(raw)}"


#: A record's head: seconds (group 1; group 2 the digits after the dot), the direction column
#: (group 3) and one optional space; the payload is the rest of the line less its line end (a
#: ``\n``, then a ``\r``). One alternation, longest first: no backtracking.
RECORD_HEAD = re.compile(rb"(\d+(?:\.(\d+))?) ("
                         + "|".join(sorted(DIRECTIONS, key=len, reverse=True)).encode() + rb") ?")
_NOT_A_RECORD = "not a wire-log record (want '<seconds> <dir> <payload>')"
_NOT_ASCII = "payload is not ASCII (bytes must be escaped as \\xNN)"
#: direction column → (the record's direction, a whole CR LF line); as written, and swapped
_COLUMNS = {d.encode(): (d[0], len(d) == 1) for d in DIRECTIONS if d != NOTE}
_SWAPPED_COLUMNS = {k: (SWAPPED[d], whole) for k, (d, whole) in _COLUMNS.items()}
_NOTE_COLUMN = NOTE.encode()


# ---------------------------------------------------------------------- the reader
def read_wire_log(lines: Iterable[bytes], *, swap: bool = False,
                  progress: Optional[Callable[[int], None]] = None,
                  comment: Optional[Callable[[str], None]] = None, first: int = 1) -> Iterator[Record]:
    """The records of a wire log's lines (bytes, each with or without its line end; a binary
    file will do), streaming: a :class:`WireEvent` per record, an :class:`Unreadable` per line
    that is not one (blank lines and ``#`` comments are skipped). Never raises on a bad line.

    ``swap`` exchanges the byte directions; ``progress`` is called with each line's size;
    ``comment`` with each header comment (:data:`HEADER_LINES`); ``first`` is the first line's
    number. Speed matters here (``check-log`` of a million-line log): one regular expression per
    line, the payload unescaped only when it holds a ``\\``, and each :class:`WireEvent` made
    by ``tuple.__new__`` (the named tuple's own ``__new__`` is Python code, and costs nearly as
    much as the regular expression)."""
    n = first - 1
    match = RECORD_HEAD.match
    columns = _SWAPPED_COLUMNS if swap else _COLUMNS
    new, event, note = tuple.__new__, WireEvent, _NOTE_COLUMN
    for raw in lines:
        n += 1
        if progress is not None:
            progress(len(raw))
        m = match(raw)
        if m is None:
            if raw[:1] == b"#":
                if comment is not None and n <= HEADER_LINES:
                    comment(raw.decode("utf-8", "replace").rstrip("\r\n"))
                continue
            if not raw.strip():
                continue
            yield Unreadable(0.0, UNREADABLE, b"", _NOT_A_RECORD, n,
                             raw.decode("utf-8", "replace").rstrip("\r\n")[:200])
            continue
        stamp, _, d = m.groups()
        t = float(stamp)
        payload = raw[m.end():-1] if raw[-1:] == b"\n" else raw[m.end():]
        if payload[-1:] == b"\r":
            payload = payload[:-1]
        if d == note:
            yield new(event, (t, NOTE, b"", payload.decode("utf-8", "replace"), n))
            continue
        if not payload.isascii():
            yield Unreadable(t, UNREADABLE, b"", _NOT_ASCII, n, payload.decode("utf-8", "replace")[:200])
            continue
        if b"\\" in payload:
            payload = unescape(payload.decode("ascii"))
        direction, whole = columns[d]
        if whole:
            yield new(event, (t, direction, payload + b"\r\n", "", n))
        else:
            yield new(event, (t, direction, payload, "", n))


def read_records(lines: Iterable[bytes], *, first: int = 1) -> Iterator[WireEvent]:
    """The records of a wire log, as :func:`read_wire_log` reads them; raises
    :class:`WireLogError` naming the first line that is not a record."""
    for rec in read_wire_log(lines, first=first):
        if rec.dir == UNREADABLE:
            raise WireLogError(f"line {rec.lineno}: {rec.note}")
        yield rec  # type: ignore[misc]


def parse_record(line: bytes, lineno: int = 0) -> Optional[WireEvent]:
    """The record of one log line; None for a comment or a blank line; :class:`WireLogError`
    (naming ``lineno``) for anything else that is not a record."""
    for rec in read_records((line,), first=lineno):
        return rec
    return None


# ---------------------------------------------------------------------- segments
#: The note that ends a segment: the session's log goes on in the file it names, beside this one.
CONTINUED = "continued in "


def continued_in(note: str) -> Optional[str]:
    """The file name a :data:`CONTINUED` note names (a plain name in the same directory), or None."""
    if not note.startswith(CONTINUED):
        return None
    name = note[len(CONTINUED):].strip()
    if not name or "/" in name or "\\" in name or name in (".", "..") or name.startswith("."):
        return None
    return name


def segment_name(first: str, n: int) -> str:
    """The name of segment ``n`` (0 is ``first`` itself) of a log named ``first``:
    ``wire.log`` → ``wire.001.log``, ``wire.002.log``, …"""
    if n == 0:
        return first
    stem, dot, ext = first.rpartition(".")
    return f"{stem}.{n:03d}.{ext}" if dot and stem else f"{first}.{n:03d}"


# ---------------------------------------------------------------------- the writer
class WireLogWriter:
    """Writes a wire log to a text stream: the header, then one record a line, each flushed so a
    crash loses nothing recorded. Each record's time is rounded to the microsecond the log shows
    and, with ``monotonic`` (the default), never goes back: what :meth:`bytes` and :meth:`note`
    return is the :class:`WireEvent` exactly as written, line number included, so a reader of
    the log gets the same events.

    ``meta``: header comment lines (one string is one line). ``after=(lines, last_t)``: the
    stream continues a log that already holds ``lines`` lines up to time ``last_t`` (a resumed
    run): no header; numbering and time go on. ``stream=None`` writes nothing but numbers the
    records all the same. A write that fails with ``OSError`` (a full disk) is remembered in
    :attr:`write_error` and nothing more is written; other errors propagate."""

    def __init__(self, stream: Optional[IO[str]], meta: Union[str, Iterable[str]] = (), *,
                 after: Optional[tuple[int, float]] = None, monotonic: bool = True):
        self._f = stream
        self.monotonic = monotonic
        self.lineno = 0  #: the number of the last line written
        self.records = 0  #: records written (notes included)
        self.write_error: Optional[str] = None
        self._last_t = 0.0
        if after is not None:
            self.lineno, self._last_t = after
            return
        self._write(HEADER)
        for m in ([meta] if meta else []) if isinstance(meta, str) else meta:
            self._write(f"# {m}".replace("\n", " "))

    @property
    def last_t(self) -> float:
        """The time of the latest record (0 before the first)."""
        return self._last_t

    def _write(self, text: str) -> int:
        self.lineno += 1
        if self._f is not None and self.write_error is None:
            try:
                self._f.write(text + "\n")
                self._f.flush()
            except OSError as e:
                self.write_error = f"{getattr(e, 'strerror', None) or e}"
        return self.lineno

    def _time(self, t: float) -> float:
        t = float(f"{max(t, self._last_t) if self.monotonic else t:.6f}")
        self._last_t = t
        return t

    def bytes(self, t: float, direction: str, raw: bytes) -> Optional[WireEvent]:
        """Bytes seen going ``direction`` (:data:`TO_VEHICLE` or :data:`FROM_VEHICLE`) at ``t``;
        the record as written (None for no bytes: nothing is written)."""
        if not raw:
            return None
        t = self._time(t)
        n = self._write(format_record(t, direction, raw))
        self.records += 1
        return WireEvent(t, direction, raw, "", n)

    def note(self, t: float, text: str) -> WireEvent:
        """A note (``!``) at ``t``, on one line; the record as written."""
        t = self._time(t)
        text = text.replace("\n", " ").replace("\r", " ")
        n = self._write(format_record(t, NOTE, note=text))
        self.records += 1
        return WireEvent(t, NOTE, b"", text, n)

    def continue_in(self, stream: IO[str], previous: str) -> None:
        """Go on in a new segment ``stream`` (the caller wrote the :data:`CONTINUED` note to the
        old one, and closes it): the header and a comment naming ``previous`` first; numbering
        and time go on (module docstring, *segments*)."""
        self._f = stream
        self._write(HEADER)
        self._write(f"# continues {previous}")

    def close(self) -> None:
        if self._f is not None:
            try:
                self._f.close()
            except OSError as e:
                self.write_error = self.write_error or f"{getattr(e, 'strerror', None) or e}"
            self._f = None
