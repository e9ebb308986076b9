"""The log checker: one pass over a capture, fed to the same observers a live run feeds.

This module owns :func:`check_log` — Jepsen's ``analyze`` / TLA+ trace validation for the remote
helm line: the whole log is consumed, in order, and every byte is attributed. Its steps:

1. detect the format and the timestamp resolution from the first 64 KiB (:mod:`.readers`); a wire
   log in segments (``wire.log``, ``wire.001.log``, …) is read as one session, the segments one
   after another (:mod:`helmcheck.reports.segments`);
2. stream the records (:class:`~helmcheck.grammar.wirelog.WireEvent` s, with their time and log
   line; a wire log through the one wire-log reader, :mod:`helmcheck.grammar.wirelog`)
   and feed each to the role's observer: the vehicle observer
   (:class:`~helmcheck.judge.vehicle.VehicleObserver`, the judge ``certify vehicle`` uses) for
   §1–8 and the backseat observer (:class:`~helmcheck.judge.backseat.BackseatObserver`, the judge
   ``certify backseat`` uses) for §9, each with its own :class:`~helmcheck.judge.ledger.Ledger`.
   Notes go to them too (a certification's ``case``/``not tested``/``link:`` notes, an
   emulator's ``plant:`` notes), so a certification's own log gets the verdicts the run got;
3. a log line that cannot be read is a finding with its line number (INCONCLUSIVE for RH-FRM-1 /
   RH-BS-1: the bytes there are unknown);
4. the notes are read for the run facts too (:class:`~helmcheck.judge.runfacts.RunFacts`: a
   certification's selection, the clauses it did not judge, the end of the implementation it
   started, a run cut short), and the clause facts are booked into each role's ledger, as the
   live run booked them; the facts go out with the outcome for
   :func:`helmcheck.reports.assemble.assemble`.

No judging happens here. Memory is bounded: the ledgers keep a few evidence lines per clause;
timeline and events are capped by the observers. While the records are fed the cyclic garbage
collector runs rarely (:func:`_few_collections`): the records make short-lived objects that
reference counting frees.
"""

from __future__ import annotations

import gc
import hashlib
import io
import itertools
import os
import time
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import BinaryIO, Callable, Optional

from ..clauses import vehicle_clauses
from ..grammar.wirelog import FROM_VEHICLE, HEADER_LINES, TO_VEHICLE, WireEvent
from ..judge.backseat import BS_CLAUSES, BackseatObserver
from ..judge.ledger import Evidence as LedgerEvidence, Ledger
from ..judge.linemodel import PREFIX as LINE_PREFIX, given, line_note
from ..judge.runfacts import RunFacts
from ..judge.vehicle import VehicleObserver
from ..judge.wire import Decodings
from ..model.missions import MissionCatalog
from ..profile import DEFAULT, Profile
from ..reports.segments import session_files
from .readers import (HEAD_BYTES, NOTE, UNREADABLE, Chunk, LogMeta, Unreadable, detect_format, header_comment, read_chunks,
                      timestamp_resolution)
from .origin import read_origin
from .sidejob import SideJob, SideJobLost, cores

__all__ = ["check_log", "log_meta", "CheckOutcome", "LogFormatError", "SessionJudge", "ROLES", "VEHICLE_CLAUSES"]

ROLES = ("vehicle", "backseat", "both")
MAX_FINDINGS = 50
#: From this size on, ``role="both"`` judges the backseat role in a second process (when the
#: machine has a second core): below it, starting that process costs more than it saves.
PARALLEL_BYTES = 4 * 1024 * 1024
VEHICLE_CLAUSES = tuple(c.id for c in vehicle_clauses())


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
    facts: RunFacts = field(default_factory=RunFacts)  #: the run facts of the log's notes
    segments: list = field(default_factory=list)  #: the names of the session's further segments


def check_log(path: Path | str, *, profile: Profile = DEFAULT, role: Optional[str] = "both",
              catalog: Optional[MissionCatalog] = None, time_scale: Optional[float] = None,
              swap: bool = False, progress: Optional[Callable[[int], None]] = None,
              parallel: Optional[bool] = None, line: Optional[str] = None) -> CheckOutcome:
    """Check one log file. ``OSError`` if it cannot be read, :class:`LogFormatError` if it is
    no known log format.

    ``parallel``: judge the backseat role of ``role="both"`` in a second process (the roles are
    independent; the verdicts are the same either way). ``None`` decides by itself: for a log of
    at least :data:`PARALLEL_BYTES` on a machine with more than one core.

    ``role=None``: the role the run that wrote the log tested, as its header names it
    (:mod:`.origin`), else both.

    ``line``: ``clean`` or ``noisy`` (``--line``) overrides the log's ``line model:`` note; None
    takes the log's, and a log without one (a ``socat -v`` capture) is noisy
    (:mod:`helmcheck.judge.linemodel`).

    The file is judged as it was when the check began: a log still being written is checked up
    to the size it had then (in both processes alike)."""
    if role is not None and role not in ROLES:
        raise ValueError(f"role must be one of {ROLES}")
    path = Path(path)
    started = time.monotonic()
    session = session_files(path)
    with ExitStack() as stack:
        files = [stack.enter_context(open(p, "rb")) for p in session.files]
        sizes = [os.fstat(f.fileno()).st_size for f in files]
        fmt, meta = _head(files[0], path, sizes[0])
        if role is None:
            role = read_origin(meta).role or "both"
        scale = time_scale if time_scale is not None else (meta.time_scale or profile.time_scale or 1.0)
        baud = meta.baud or profile.baud
        if parallel is None:
            parallel = role == "both" and sum(sizes) >= PARALLEL_BYTES and cores() > 1
        job = ([str(p) for p in session.files], fmt, profile, scale, meta.resolution, baud, swap, sizes, line)
        side = None
        if parallel and role == "both":
            try:
                side = SideJob(_backseat_entries, *job)
            except Exception:  # no second process (none can start, or the job does not pickle): judge here
                side = None
        try:
            checker = SessionJudge(profile, role, catalog, scale, meta.resolution, baud,
                                   judge_backseat=side is None, line=line)
            sha = _feed(files, sizes, checker, fmt, meta, swap, progress, session.missing)
            if side is not None:
                try:
                    entries, side_sha = side.result()
                except SideJobLost:  # judge it here after all
                    entries, side_sha = _backseat_entries(*job)
                if side_sha != sha:
                    raise LogFormatError(f"{path}: the file changed while it was being checked")
                checker.backseat_entries = entries
        finally:
            if side is not None:
                side.stop()
    out = checker.outcome(path, fmt, meta, sha)
    out.segments = [p.name for p in session.files[1:]]
    out.seconds = time.monotonic() - started
    return out


def log_meta(path: Path | str) -> tuple[str, LogMeta]:
    """The format of the log at ``path`` and what its head says, as :func:`check_log` reads them
    (``OSError``; :class:`LogFormatError` for no known format)."""
    path = Path(path)
    with open(path, "rb") as f:
        return _head(f, path, os.fstat(f.fileno()).st_size)


def _head(f: BinaryIO, path: Path, size: int) -> tuple[str, LogMeta]:
    """The format and what the first :data:`HEAD_BYTES` (of ``size``) say (timestamp step,
    header); ``f`` is left at its start."""
    head = f.read(min(HEAD_BYTES, size))
    fmt = detect_format(head)
    if fmt is None:
        raise LogFormatError(f"{path}: not a helmcheck wire log, socat -v or socat -x capture")
    f.seek(0)
    meta = LogMeta(format=fmt, resolution=timestamp_resolution(head, fmt))
    if fmt == "wirelog":
        for ln in head.split(b"\n")[:HEADER_LINES]:
            if ln.startswith(b"#"):
                header_comment(ln.decode("utf-8", "replace"), meta)
    meta.header = meta.header[:8]
    return fmt, meta


def _feed(files: list[BinaryIO], sizes: list[int], checker: "SessionJudge", fmt: str, meta: LogMeta, swap: bool,
          progress: Optional[Callable[[int], None]], missing: Optional[str] = None) -> str:
    """Every record in the first ``sizes[i]`` bytes of each of ``files`` (a session's segments,
    :mod:`helmcheck.reports.segments`) to ``checker``, then close it; returns the SHA-256 of the
    bytes read. A segment the session names but that is not there (``missing``) is a log line
    that cannot be read: what it held is unknown."""
    sha = hashlib.sha256()
    lines = _Hashing(list(zip(files, sizes)), sha)
    with _few_collections():
        for chunk in read_chunks(lines, fmt, meta, swap=swap, progress=progress):
            checker.chunk(chunk)
    if missing is not None:
        checker.chunk(Unreadable(checker.last_t, UNREADABLE, b"", f"the log continues in {missing}, which is "
                                 f"not there", lines.count + 1, ""))
    checker.close()
    return sha.hexdigest()


def _backseat_entries(paths: list[str], fmt: str, profile: Profile, scale: float, resolution: float, baud: int,
                      swap: bool, sizes: list[int], line: Optional[str] = None) -> tuple[list, str]:
    """The backseat role of a check on its own (the side job of a parallel check) over the first
    ``sizes[i]`` bytes of each segment: its ledger entries, and the SHA-256 of the bytes it read."""
    with ExitStack() as stack:
        files = [stack.enter_context(open(p, "rb")) for p in paths]
        fmt2, meta = _head(files[0], Path(paths[0]), sizes[0])
        if fmt2 != fmt:
            raise LogFormatError(f"{paths[0]}: the file changed while it was being checked")
        checker = SessionJudge(profile, "backseat", None, scale, resolution, baud, line=line)
        sha = _feed(files, sizes, checker, fmt, meta, swap, None)
    return checker.backseat.ledger.entries(), sha  # type: ignore[union-attr]


#: The cyclic collector's first threshold while the records are fed (Python's default is 700).
GC_THRESHOLD = 50_000


@contextmanager
def _few_collections():
    """The cyclic garbage collector run rarely while the records are fed: the observers make a
    few short-lived objects per record (records, decodings, evidence, replies), which reference
    counting frees, and at the default threshold a collection every few hundred records would
    walk them and the observers' long-lived state again and again for almost no garbage. The
    collector still runs (after :data:`GC_THRESHOLD` net allocations of the objects it tracks),
    so memory stays bounded; the thresholds are restored afterwards."""
    old = gc.get_threshold()
    if old[0]:  # (0: collection switched off by whoever runs the check; left so)
        gc.set_threshold(max(old[0], GC_THRESHOLD), *old[1:])
    try:
        yield
    finally:
        gc.set_threshold(*old)


class _Hashing:
    """Iterates the lines (each ending in LF, as a binary file's lines do; a file's last may not)
    of the first ``limit`` bytes of each ``(file, limit)`` — a session's segments, one after
    another — while hashing them. Each file is read in blocks of whole lines, and each block's
    lines come from :class:`io.BytesIO`: no Python code runs per line here. ``count`` is the
    number of lines read so far (known once the iteration is over)."""

    BLOCK = 1 << 20

    def __init__(self, files: list, h):
        self.files = files
        self.h = h
        self.count = 0

    def __iter__(self):
        return itertools.chain.from_iterable(map(io.BytesIO, self._blocks()))

    def _blocks(self):
        for f, limit in self.files:
            yield from self._file(f, limit)

    def _file(self, f, limit: int):
        left = limit
        carry = b""
        while left > 0:
            block = f.read(min(self.BLOCK, left))
            if not block:
                break
            left -= len(block)
            self.h.update(block)
            buf = carry + block if carry else block
            cut = buf.rfind(b"\n") + 1
            carry = buf[cut:]
            if cut:
                out = buf[:cut]
                self.count += out.count(b"\n")
                yield out
        if carry:  # a segment whose last line has no end: a line of its own, never joined to the next
            self.count += 1
            yield carry


class _Side:
    """One role's observer and ledger; each record goes to the observer as the live recorder fed
    it (same times, same line numbers, notes included), so a wire log gets the run's verdicts."""

    unreadable_clause = ""  #: the clause an unreadable log line leaves INCONCLUSIVE
    ledger: Ledger
    observer: "BackseatObserver | VehicleObserver"

    def unreadable(self, c: Unreadable) -> None:
        """A log line that could not be read: the bytes there are unknown."""
        self.ledger.inconclusive(self.unreadable_clause, "a log line could not be read; the bytes there "
                                                         "are unknown",
                                 [LedgerEvidence(c.t, "!", f"{c.note}: {c.text[:120]}", c.lineno)])


class _Backseat(_Side):
    """The backseat side of a check: every record to the backseat observer, its own ledger.

    The records are fed exactly as ``certify backseat``'s recorder fed them live (same times,
    same line numbers, notes included), so a wire log gets the verdicts the run got."""

    unreadable_clause = "RH-BS-1"

    def __init__(self, profile: Profile, scale: float, resolution: float, baud: int, lines: Decodings):
        self.ledger = Ledger(BS_CLAUSES)
        self.observer = BackseatObserver(profile, self.ledger, time_scale=scale, baud=baud,
                                         resolution=resolution, decodings=lines)

    def close(self, t: float, backseat_traffic: bool) -> None:
        if not backseat_traffic:
            for c in BS_CLAUSES:
                self.ledger.not_tested(c, "One-direction log: it has no backseat→vehicle traffic.")
        self.observer.close(t)


class _Vehicle(_Side):
    """The vehicle side of a check: every record to the vehicle observer, its own ledger — as
    ``certify vehicle``'s recorder fed them live."""

    unreadable_clause = "RH-FRM-1"

    def __init__(self, profile: Profile, catalog, scale: float, resolution: float, baud: int, lines: Decodings):
        self.ledger = Ledger(VEHICLE_CLAUSES)
        self.observer = VehicleObserver(profile, self.ledger, time_scale=scale, baud=baud,
                                        resolution=resolution, catalog=catalog, decodings=lines)

    def entries(self, to_vehicle: bool, from_vehicle: bool, facts: RunFacts) -> list:
        if not from_vehicle and not self.observer.aborted:
            led = Ledger(VEHICLE_CLAUSES)
            facts.book(led)
            for c in VEHICLE_CLAUSES:
                led.not_tested(c, "One-direction log: it has no vehicle→backseat traffic, so the vehicle's "
                                  "answers cannot be judged.")
            return led.entries()
        if not to_vehicle:
            for c in ("RH-ACK-1", "RH-ACK-2", "RH-ACK-3", "RH-ACK-4", "RH-ACK-5", "RH-ACK-6", "RH-OUT-4"):
                self.ledger.not_tested(c, "One-direction log: without the commands the answers cannot be "
                                          "matched; only framing and sentence contents are judged.")
        return self.ledger.entries()


class SessionJudge:
    """Every record of a session, in order, to each role's observer (:meth:`chunk`), the run facts
    its notes give, and at the end (:meth:`close`, :meth:`outcome`) what :func:`check_log`
    returns. ``check-log`` feeds it a log's records; ``helmcheck monitor`` feeds it the records of
    a live session as they are written — the same judges, the same verdicts."""

    def __init__(self, profile: Profile, role: str, catalog, scale: float, resolution: float, baud: int,
                 judge_backseat: bool = True, line: Optional[str] = None):
        self.profile = profile
        self.role = role
        lines = Decodings(profile)  # each line read once, whichever roles read it
        self.vehicle = (_Vehicle(profile, catalog, scale, resolution, baud, lines)
                        if role in ("vehicle", "both") else None)
        self.backseat = (_Backseat(profile, scale, resolution, baud, lines)
                         if role in ("backseat", "both") and judge_backseat else None)
        #: the backseat role's entries when a side job judged it (:func:`check_log`)
        self.backseat_entries: Optional[list] = None
        self.sides: list[_Side] = [x for x in (self.vehicle, self.backseat) if x is not None]
        self.facts = RunFacts()
        #: the observers' ``feed`` s (the run facts are in notes alone: :meth:`chunk` gives them those)
        self.feeds = [x.observer.feed for x in self.sides]
        self.scale = scale
        self.r = resolution
        self.mission_known = catalog is not None
        self.findings: list = []
        self.finding_count = 0
        self._records = {TO_VEHICLE: 0, FROM_VEHICLE: 0, NOTE: 0, UNREADABLE: 0}  #: per direction
        self._bytes = {TO_VEHICLE: 0, FROM_VEHICLE: 0}
        self.last_t = 0.0
        #: ``--line`` given: its note goes first, and the log's own ``line model:`` notes are not read
        self.line_given = line is not None
        if line is not None:
            self._note(WireEvent(0.0, NOTE, b"", line_note(given(line)), 0))

    @property
    def stats(self) -> dict:
        """Counts for the report (a new dict each time)."""
        n, b = self._records, self._bytes
        return {"records": sum(n.values()), "notes": n[NOTE], "unreadable": n[UNREADABLE],
                "records_to_vehicle": n[TO_VEHICLE], "records_from_vehicle": n[FROM_VEHICLE],
                "bytes_to_vehicle": b[TO_VEHICLE], "bytes_from_vehicle": b[FROM_VEHICLE]}

    def chunk(self, c: Chunk) -> None:
        d = c.dir
        self._records[d] += 1
        if c.t > self.last_t:
            self.last_t = c.t
        if d == TO_VEHICLE or d == FROM_VEHICLE:
            self._bytes[d] += len(c.data)
            for feed in self.feeds:  # the same event to both observers (neither changes it)
                feed(c)
            return
        if d != NOTE:
            self.finding_count += 1
            if len(self.findings) < MAX_FINDINGS:
                self.findings.append({"line": c.lineno, "finding": c.note})
            for side in self.sides:
                side.unreadable(c)  # type: ignore[arg-type]
            return
        if self.line_given and c.note.startswith(LINE_PREFIX):
            return  # the user's --line stands (its note went first)
        self._note(c)

    def _note(self, c) -> None:
        for feed in self.feeds:
            feed(c)
        self.facts.feed(c)

    def close(self) -> None:
        for side in self.sides:
            self.facts.book(side.ledger)
        if self.vehicle is not None:
            self.vehicle.observer.close()
        if self.backseat is not None:
            self.backseat.close(self.last_t, bool(self.stats["bytes_to_vehicle"]))

    def outcome(self, path: Path, fmt: str, meta: LogMeta, sha: str) -> CheckOutcome:
        st = self.stats
        to_v, from_v = bool(st["bytes_to_vehicle"]), bool(st["bytes_from_vehicle"])
        one = None
        if not from_v:
            one = "backseat"
        if not to_v:
            one = "vehicle" if one is None else "empty"
        clauses: list = []
        timeline: list = []
        events: list = []
        if self.vehicle is not None:
            clauses += self.vehicle.entries(to_v, from_v, self.facts)
            obs = self.vehicle.observer
            timeline = [{"t": t, "mode": m} for t, m in obs.timeline]
            events = list(obs.events)
            st["vehicle_discards"] = obs.out.discards
        if self.backseat is not None:
            clauses += self.backseat.ledger.entries()
        elif self.backseat_entries is not None:
            clauses += self.backseat_entries
        return CheckOutcome(path=path, format=fmt, role=self.role, clauses=clauses, meta=meta,
                            time_scale=self.scale, resolution=self.r, stats=dict(st),
                            findings=list(self.findings), timeline=timeline, events=events, sha256=sha,
                            one_direction=one, mission_known=self.mission_known,
                            notes=[f"{self.finding_count} log line(s) that could not be read"], facts=self.facts)
