"""The log checker: one pass over a capture, the vehicle judge and the backseat observer, per-clause results.

This module owns :func:`check_log` — Jepsen's ``analyze`` / TLA+ trace validation for the remote
helm line: the whole log is consumed, in order, and every byte is attributed. Its steps:

1. detect the format and the timestamp resolution from the first 64 KiB (:mod:`.readers`);
2. stream :class:`~.readers.Chunk` s; per direction a :class:`~helmcheck.grammar.Framer`
   re-frames the bytes exactly as a receiver would (RH-FRM-6/7) and each event keeps the log
   line it started on;
3. decode every line (:func:`helmcheck.grammar.decode`); vehicle output is judged for framing
   (RH-FRM-1/2/3, RH-FRM-8 via the grammar) and content (RH-OUT-1/2/3), then handed to the
   vehicle judge (:mod:`.vehicle`); backseat lines go to the vehicle judge too;
   for role ``backseat``/``both`` every record (notes included) is also fed, as a
   :class:`~helmcheck.judge.wire.WireEvent`, to the backseat observer
   (:class:`~helmcheck.judge.backseat.BackseatObserver`, the judge ``certify backseat`` uses),
   which writes RH-BS-1..8 into its own :class:`~helmcheck.judge.ledger.Ledger` (:class:`_Backseat`);
4. recorder notes are applied as plant events when they are (``plant: …``) and otherwise
   attributed as notes; a log line that cannot be read is a finding with its line number
   (charged to RH-FRM-1 / RH-BS-1 as INCONCLUSIVE: the bytes there are unknown).

Memory is bounded: nothing keeps a record once it is judged; the clause book keeps at most a few
evidence lines per clause; timeline and events are capped.
"""

from __future__ import annotations

import hashlib
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Optional

from ...grammar import Discard, Framer, Line, decode
from ...grammar import sentences as s
from ...grammar.capture import escape
from ...judge.backseat import BS_CLAUSES, BackseatObserver
from ...judge.ledger import Evidence as LedgerEvidence, Ledger
from ...judge.wire import WireEvent
from ...model.missions import MissionCatalog
from ...profile import DEFAULT, Profile
from .accounting import ClauseBook, Evidence
from .readers import NOTE, UNREADABLE, Chunk, LogMeta, detect_format, read_chunks, timestamp_resolution
from .vehicle import VEHICLE_CLAUSES, VehicleJudge, parse_plant_note

__all__ = ["check_log", "CheckOutcome", "LogFormatError", "ROLES"]

ROLES = ("vehicle", "backseat", "both")
HEAD_BYTES = 64 * 1024
MAX_TIMELINE = 2000
MAX_EVENTS = 500
MAX_FINDINGS = 50

#: Vehicle output decode errors → the clause a vehicle breaks by sending it.
_VEHICLE_FRAMING = {"RH-FRM-2": "RH-FRM-2", "RH-FRM-3": "RH-FRM-3", "RH-FRM-4": "RH-FRM-2",
                    "RH-FRM-5": "RH-FRM-1", "RH-FRM-6": "RH-FRM-6", "RH-FRM-7": "RH-FRM-1",
                    "RH-FRM-1": "RH-FRM-1"}


class LogFormatError(ValueError):
    """The file is not a log in any format this checker reads."""


@dataclass
class CheckOutcome:
    """Everything a check found, ready for :mod:`helmcheck.reports.results`."""

    path: Path
    format: str
    role: str
    clauses: list
    meta: LogMeta
    time_scale: float
    resolution: float
    stats: dict
    findings: list
    timeline: list
    events: list
    sha256: str
    one_direction: Optional[str] = None
    mission_known: bool = False
    seconds: float = 0.0
    notes: list = field(default_factory=list)


class _Stream:
    """One direction: a framer plus the log line where its pending run began."""

    __slots__ = ("framer", "pending_line", "pending_t")

    def __init__(self, max_line: int):
        self.framer = Framer(max_line)
        self.pending_line = 0
        self.pending_t = 0.0

    def feed(self, c: Chunk):
        fr = self.framer
        had = fr.pending
        data = c.data
        if not had and c.complete and data[:1] == b"$" and data.count(b"$") == 1 \
                and data.find(b"\n") == len(data) - 1 and len(data) <= fr.max_line:
            return ((Line(data, 0), c.lineno),)
        evs = fr.feed(data)
        out = []
        for i, e in enumerate(evs):
            out.append((e, self.pending_line if (i == 0 and had) else c.lineno))
        if fr.pending:
            if not (had and not evs):
                self.pending_line = c.lineno
                self.pending_t = c.t
        return out

    def close(self):
        return [(e, self.pending_line) for e in self.framer.close()]


def check_log(path: Path | str, *, profile: Profile = DEFAULT, role: str = "both",
              catalog: Optional[MissionCatalog] = None, time_scale: Optional[float] = None,
              swap: bool = False, progress: Optional[Callable[[int], None]] = None) -> CheckOutcome:
    """Check one log file. ``OSError`` if it cannot be read, :class:`LogFormatError` if it is
    no known log format."""
    if role not in ROLES:
        raise ValueError(f"role must be one of {ROLES}")
    path = Path(path)
    started = time.monotonic()
    with open(path, "rb") as f:
        head = f.read(HEAD_BYTES)
        fmt = detect_format(head)
        if fmt is None:
            raise LogFormatError(f"{path}: not a helmcheck wire log, socat -v or socat -x capture")
        f.seek(0)
        meta = LogMeta(format=fmt, resolution=timestamp_resolution(head, fmt))
        for ln in head.split(b"\n")[:16]:
            if ln.startswith(b"#") and fmt == "wirelog":
                from .readers import _header_comment
                _header_comment(ln.decode("utf-8", "replace"), meta)
        meta.header = meta.header[:8]
        scale = time_scale if time_scale is not None else (meta.time_scale or profile.time_scale or 1.0)
        baud = meta.baud or profile.baud
        checker = _Checker(profile, role, catalog, scale, meta.resolution, baud)
        sha = hashlib.sha256()
        f.seek(0)

        def prog(n: int) -> None:
            if progress is not None:
                progress(n)

        reader = read_chunks(_Hashing(f, sha), fmt, meta, swap=swap, progress=prog)
        for chunk in reader:
            checker.chunk(chunk)
        checker.close()
    out = checker.outcome(path, fmt, meta, sha.hexdigest())
    out.seconds = time.monotonic() - started
    return out


class _Hashing:
    """Iterates the lines of a binary file while hashing them."""

    def __init__(self, f, h):
        self.f = f
        self.h = h

    def __iter__(self):
        upd = self.h.update
        for raw in self.f:
            upd(raw)
            yield raw


class _Backseat:
    """The backseat side of a check: every record to the backseat observer, its own ledger.

    The records are fed exactly as ``certify backseat``'s recorder fed them live (same times,
    same line numbers, notes included), so a wire log gets the verdicts the run got."""

    def __init__(self, profile: Profile, scale: float, resolution: float, baud: int):
        self.ledger = Ledger(BS_CLAUSES)
        self.observer = BackseatObserver(profile, self.ledger, time_scale=scale, baud=baud,
                                         resolution=resolution)

    def chunk(self, c: Chunk) -> None:
        if c.direction == NOTE:
            self.observer.feed(WireEvent(c.t, NOTE, b"", c.note, c.lineno))
        elif c.direction == UNREADABLE:
            self.ledger.inconclusive("RH-BS-1", "a log line could not be read; the bytes there are unknown",
                                     [LedgerEvidence(c.t, "!", f"{c.note}: {c.text[:120]}", c.lineno)])
        else:
            self.observer.feed(WireEvent(c.t, c.direction, c.data, "", c.lineno))

    def close(self, t: float, backseat_traffic: bool) -> None:
        if not backseat_traffic:
            for c in BS_CLAUSES:
                self.ledger.not_tested(c, "One-direction log: it has no backseat→vehicle traffic.")
        self.observer.close(t)


class _Checker:
    def __init__(self, profile: Profile, role: str, catalog, scale: float, resolution: float, baud: int):
        self.profile = profile
        self.role = role
        ids: list[str] = []
        if role in ("vehicle", "both"):
            ids += list(VEHICLE_CLAUSES)
        self.book = ClauseBook(ids)
        self.backseat = _Backseat(profile, scale, resolution, baud) if role in ("backseat", "both") else None
        self.scale = scale
        self.r = resolution
        self.timeline: list = []
        self.events: list = []
        self.findings: list = []
        self.finding_count = 0
        self.stats = {"records": 0, "notes": 0, "unreadable": 0, "lines_to_vehicle": 0,
                      "lines_from_vehicle": 0, "discarded_to_vehicle": 0, "discarded_from_vehicle": 0,
                      "plant_notes": 0, "bytes_to_vehicle": 0, "bytes_from_vehicle": 0}
        self.last_t = 0.0
        self.vehicle = VehicleJudge(self.book, profile, catalog, time_scale=scale, resolution=resolution,
                                    baud=baud, on_mode=self._mode, on_event=self._event)
        self.streams = {">": _Stream(profile.max_line_bytes), "<": _Stream(profile.max_line_bytes)}
        self._mode(0.0, "S")
        self._cache: dict = {}

    # ------------------------------------------------------------------ hooks
    def _mode(self, t: float, mode: str) -> None:
        if len(self.timeline) < MAX_TIMELINE:
            t = max(t, self.timeline[-1]["t"] if self.timeline else 0.0)
            if not self.timeline or self.timeline[-1]["mode"] != mode:
                self.timeline.append({"t": round(t, 6), "mode": mode})

    def _event(self, t: float, kind: str, label: str) -> None:
        if len(self.events) < MAX_EVENTS:
            self.events.append({"t": round(max(0.0, t), 6), "kind": kind, "label": label})

    def _finding(self, lineno: int, text: str) -> None:
        self.finding_count += 1
        if len(self.findings) < MAX_FINDINGS:
            self.findings.append({"line": lineno, "finding": text})

    # ------------------------------------------------------------------ input
    def chunk(self, c: Chunk) -> None:
        self.stats["records"] += 1
        if c.t > self.last_t:
            self.last_t = c.t
        if self.backseat is not None:
            self.backseat.chunk(c)
        d = c.direction
        if d == ">" or d == "<":
            st = self.streams[d]
            for e, lineno in st.feed(c):
                if type(e) is Line:
                    self._line(d, e.raw, c.t, lineno)
                else:
                    self._discard(d, e, c.t, lineno)
            if d == ">":
                self.stats["bytes_to_vehicle"] += len(c.data)
            else:
                self.stats["bytes_from_vehicle"] += len(c.data)
            return
        if d == NOTE:
            self.stats["notes"] += 1
            got = parse_plant_note(c.note)
            if got is not None:
                self.stats["plant_notes"] += 1
                self.vehicle.plant_note(got[0], got[1], c.t)
            return
        if d == UNREADABLE:
            self.stats["unreadable"] += 1
            self._finding(c.lineno, c.note)
            ev = Evidence(c.t, "!", c.lineno, f"{c.note}: {c.text[:120]}")
            self.book.inconclusive("RH-FRM-1", "a log line could not be read; the bytes there are unknown", [ev])

    def _discard(self, d: str, e: Discard, t: float, lineno: int) -> None:
        ev = Evidence(t, d + "~", lineno, escape(e.raw[:120]))
        self._finding(lineno, f"{'backseat' if d == '>' else 'vehicle'} bytes that frame into no sentence: "
                              f"{e.reason} ({e.length} bytes)")
        if d == ">":
            self.stats["discarded_to_vehicle"] += 1
            self.vehicle.silent_recent.append((t, lineno, ev.text, None))
            self.book.ok("RH-FRM-6" if e.clause == "RH-FRM-6" else "RH-FRM-7")
        else:
            self.stats["discarded_from_vehicle"] += 1
            self.book.fail("RH-FRM-6" if e.clause == "RH-FRM-6" else "RH-FRM-1",
                           f"vehicle output that is no sentence: {e.reason}", [ev])

    def _line(self, d: str, raw: bytes, t: float, lineno: int) -> None:
        hit = self._cache.get(raw)
        if hit is None:
            # Sessions repeat the same lines (polls, ACKs, refreshes): decode each text once.
            if len(self._cache) >= 4096:
                self._cache.clear()
            hit = self._cache[raw] = (decode(raw, self.profile),
                                      escape(raw[:-2] if raw.endswith(b"\r\n") else raw))
        dec, text = hit
        if d == ">":
            self.stats["lines_to_vehicle"] += 1
            sent = dec.sentence
            if sent is not None:
                if isinstance(sent, s.Command):
                    self.vehicle.command(sent, t, lineno, text)
            elif dec.error is not None and dec.error.answered:
                self.vehicle.command(dec.error, t, lineno, text)
            elif dec.error is not None:
                self.vehicle.silent_recent.append((t, lineno, text, None))
                self.vehicle.advance(t)
                self.book.ok(dec.error.clause if dec.error.clause in ("RH-FRM-4", "RH-FRM-5") else "RH-FRM-4")
            return
        self.stats["lines_from_vehicle"] += 1
        ev = Evidence(t, "<", lineno, text)
        book = self.book
        if dec.terminator != "\r\n":
            book.fail("RH-FRM-1", "vehicle line not ended by CR LF", [ev])
        for f in dec.findings:
            if f.clause == "RH-FRM-3":
                book.fail("RH-FRM-3", "vehicle checksum in lower-case hex", [ev])
        sent = dec.sentence
        if sent is None:
            err = dec.error
            clause = _VEHICLE_FRAMING.get(err.clause, err.clause) if err is not None else "RH-FRM-1"
            if clause == "RH-ACK-3":
                clause = "RH-FRM-1"
            book.fail(clause, f"vehicle sent an invalid line: {err}", [ev])
            sid = dec.sentence_id
            from .vehicle import _ID_CLASS
            if sid in _ID_CLASS:
                self.vehicle.data(_ID_CLASS[sid], None, t, lineno, text)
            return
        passes = book.passes
        passes["RH-FRM-1"] += 1
        passes["RH-FRM-2"] += 1
        if not dec.findings:
            passes["RH-FRM-3"] += 1
        if isinstance(sent, s.ACK):
            self.vehicle.ack(sent, t, lineno, text)
            return
        if isinstance(sent, s.Command):
            book.fail("RH-FRM-1", f"the vehicle sent a command sentence ${sent.ID}", [ev])
            return
        passes["RH-OUT-3"] += 1
        if isinstance(sent, s.OSI):
            passes["RH-OUT-1"] += 1
        else:
            passes["RH-OUT-2"] += 1
            if isinstance(sent, s.Compass):
                passes["RH-FRM-8"] += 1
        self.vehicle.data(type(sent), sent, t, lineno, text)

    def close(self) -> None:
        for d, st in self.streams.items():
            for e, lineno in st.close():
                self._discard(d, e, self.last_t, lineno)
        if self.backseat is not None:
            self.backseat.close(self.last_t, bool(self.stats["bytes_to_vehicle"]))

    # ------------------------------------------------------------------ result
    def outcome(self, path: Path, fmt: str, meta: LogMeta, sha: str) -> CheckOutcome:
        v = self.vehicle
        one = None
        if self.stats["lines_from_vehicle"] == 0 and self.stats["discarded_from_vehicle"] == 0:
            one = "backseat"
            v.pending.clear()
            for c in VEHICLE_CLAUSES:
                self.book.untested(c, "One-direction log: it has no vehicle→backseat traffic, so the "
                                      "vehicle's answers cannot be judged.")
        if self.stats["lines_to_vehicle"] == 0 and self.stats["discarded_to_vehicle"] == 0:
            one = "vehicle" if one is None else "empty"
            for c in ("RH-ACK-1", "RH-ACK-2", "RH-ACK-3", "RH-ACK-4", "RH-ACK-5", "RH-ACK-6", "RH-OUT-4"):
                self.book.untested(c, "One-direction log: without the commands the answers cannot be "
                                      "matched; only framing and sentence contents are judged.")
        v.finish(self.last_t)
        clauses = self.book.verdicts() + (self.backseat.ledger.entries() if self.backseat is not None else [])
        return CheckOutcome(path=path, format=fmt, role=self.role, clauses=clauses, meta=meta,
                            time_scale=self.scale, resolution=self.r, stats=dict(self.stats),
                            findings=list(self.findings), timeline=list(self.timeline),
                            events=list(self.events), sha256=sha, one_direction=one,
                            mission_known=v.mission_known,
                            notes=[f"{self.finding_count} finding(s) of unattributed bytes or log lines"])
