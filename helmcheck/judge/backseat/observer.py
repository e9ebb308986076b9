"""The backseat observer: the facade every driver feeds, and the dispatch of each event to its rule.

:class:`BackseatObserver` is sans-IO. A driver hands it every record of a run as a
:class:`~helmcheck.judge.wire.WireEvent`, in order — ``certify backseat`` through its
:class:`~helmcheck.line.recorder.Recorder` as the bytes cross the line, ``check-log``
from the wire log (or a socat capture) — and calls :meth:`~BackseatObserver.close` at the end
of the run or of the log. Every finding goes to the :class:`~helmcheck.judge.ledger.Ledger` it
was given; the same events give the same ledger, whoever feeds them.

Dispatch:

* backseat bytes (``>``) — RH-BS-4 per record (:mod:`.budget`); re-framed exactly as a receiver
  frames them (:class:`~helmcheck.grammar.Framer`), each line keeping the time and log line of
  the record that held its first byte (:class:`~.common.SentLine`); each line to RH-BS-1/2/7
  (:mod:`.lines`), each decoded command to RH-BS-3 (:mod:`.preconditions`), RH-BS-6
  (:mod:`.servo`), RH-BS-8 (:mod:`.polling`), each line with a sentence ID to RH-BS-5
  (:mod:`.reaction`); a line a vehicle answers waits for its ``$ACK`` (:class:`~.knowledge.Pending`);
* vehicle bytes (``<``) — re-framed; each ``$OSI`` and ``$ACK`` is knowledge
  (:mod:`.knowledge`) from the time it had fully arrived; an ``$ACK`` answers a waiting command;
* a faulty line: the backseat's broken lines are held until it sends the sentence again
  (:mod:`.lines`; a line-fault relay's notes, :mod:`helmcheck.judge.linefaults`, say exactly which
  the line broke; a ``line model: clean`` note, :mod:`helmcheck.judge.linemodel`, says the line
  broke none). A report the line broke on its way to the backseat is still taken as known
  (decision: a backseat may read a damaged line; the live certification cannot tell either);
* notes (``!``, :func:`~helmcheck.judge.wire.parse_note`) — ``scenario X starts`` (findings
  then carry ``X`` as their case), ``lockout starts (<code>)`` / ``lockout ends``, ``silence
  starts`` / ``silence ends`` (no answer is expected meanwhile, and servo control is not
  judged across it), ``link: <baud> baud 8N1`` (the line's baud from then on), ``run resumed:
  …`` (the record goes on after a gap it did not see, :meth:`BackseatObserver._resume`). Other
  notes are not needed: a staged rejection is an ``$ACK`` like any other.

The observer imports no ``serial``, ``time``, ``threading`` or ``asyncio``.
"""

from __future__ import annotations

from collections import deque
from typing import Optional

from ...grammar import Discard, Framer, Line
from ...grammar import sentences as s
from ...grammar.wirelog import TO_VEHICLE_RUN, escape, is_line
from ...profile import Profile
from ..facts import LOCKOUT_REFUSED, NEEDS_MISSION
from ..ledger import Evidence, Ledger
from ..linefaults import LineFaults
from ..linemodel import UNKNOWN
from ..timing import ack_allowance, ack_give_up_after
from ..wire import FROM_VEHICLE, NOTE, TO_VEHICLE, Decodings, WireEvent, parse_note
from .budget import LineBudget
from .common import BS_CLAUSES, SentLine, Settings
from .knowledge import Arrivals, Lockout, Pending, StateReports
from .lines import LineRules
from .polling import Polling
from .preconditions import LISTED, Preconditions
from .reaction import Reaction
from .servo import ServoRefresh

__all__ = ["BackseatObserver", "BS_CLAUSES"]

#: The vehicle's lines the backseat role reads (what the backseat could know: its state reports
#: and acknowledgements); the first five bytes of each. Any other line (``$GPRMC``, ``$C``, the
#: other data) is neither, however it reads, so it is not decoded at all.
_READ = frozenset({b"$OSI,", b"$ACK,"})

_NOT_TESTED = {
    "RH-BS-1": "the backseat sent no line",
    "RH-BS-2": "the backseat sent no well-framed command",
    "RH-BS-3": ("no command the clause names ("
                + ", ".join("$" + c for c in LISTED["stopped"] + LISTED["running"])
                + ") was sent while the vehicle's state was known"),
    "RH-BS-4": "the backseat sent nothing",
    "RH-BS-5": "no command was rejected and no lockout was known to the backseat",
    "RH-BS-6": "the backseat never refreshed an accepted $OMS while it held servo control",
    "RH-BS-7": "the backseat sent no line",
    "RH-BS-8": "the backseat was never active",
}


class BackseatObserver:
    """Judges a backseat against RH-BS-1..8 from wire events (module docstring)."""

    def __init__(self, profile: Profile, ledger: Ledger, *, time_scale: float, baud: int,
                 resolution: float = 1e-6, decodings: Optional[Decodings] = None):
        self.profile = profile
        self.ledger = ledger
        ledger.track_cases()  # a scenario's observations may be left out of the claim (``not claimed``)
        self.settings = st = Settings(profile, float(time_scale), int(baud), float(resolution),
                                      float(profile.reaction_s), float(profile.lockout_s))
        self._framer = Framer(profile.max_line_bytes)
        self._vframer = Framer(max(profile.max_line_bytes, 1024))
        self._records: deque[tuple[int, float, int]] = deque()  # (stream offset, t, lineno)
        # stream offsets count only the bytes that went through the framers
        self._offset = 0  #: backseat framer offset of the next byte
        self._consumed = 0  #: backseat framer offset of the first byte not yet framed
        self._voffset = 0
        #: lines read (shared with the session's other observer when it is given one)
        self._decode = decodings if decodings is not None and decodings.profile is profile else Decodings(profile)
        self.arrivals = Arrivals(st.baud)
        self.reports = StateReports()
        self.pending = Pending()
        self.lockout = Lockout(st)
        self.lines = LineRules(st, ledger)
        self.budget = LineBudget(st, ledger)
        self.preconditions = Preconditions(st, ledger, self.reports, self.pending)
        self.reaction = Reaction(st, ledger, self.lockout)
        self.servo = ServoRefresh(st, ledger)
        self.polling = Polling(st, ledger)
        #: how long an answer may be awaited (RH-ACK-2's allowance for the longest line and
        #: the most replies before it, and how long a late ACK is still awaited)
        self.max_wait = ack_give_up_after(ack_allowance(profile.ack_window_s, profile.max_line_bytes, 1024,
                                                        st.baud, st.resolution))
        self.silent = False
        self.faults = LineFaults()  #: what a line-fault relay's notes say the line did
        self.line_model = UNKNOWN  #: whether the link can damage bytes, as the record states it
        #: the lockouts the record's notes announced, in order (each as the backseat could know it)
        self.episodes: deque = deque(maxlen=16)
        self.started: Optional[float] = None  #: time of the backseat's first byte
        self.ended: Optional[float] = None

    # ================================================================ read-only facts
    @property
    def stats(self) -> dict:
        """Counts for the report."""
        return {"bytes": self.budget.bytes, "lines": self.lines.lines, "commands": self.lines.commands,
                "rejections": self.reaction.rejections, "lockouts": self.lockout.count,
                "polls": self.polling.polls, "servo_accepted": self.servo.accepted,
                "max_window_bytes": self.budget.max_window_bytes}

    def offences(self) -> dict[str, int]:
        """Violations so far per clause (for a progress display)."""
        return {c: self.ledger.counts(c)["fail"] for c in BS_CLAUSES if c in self.ledger}

    # ================================================================ input
    def feed(self, ev: WireEvent) -> None:
        """One record, in order."""
        if ev.dir == TO_VEHICLE:
            self._backseat(ev)
        elif ev.dir == FROM_VEHICLE:
            self._vehicle(ev)
        elif ev.dir == NOTE:
            self._note(ev)

    def close(self, t: float) -> None:
        """The run (or the log) ended at ``t``. Of the bytes not yet framed, a line begun with
        ``$`` is not judged (the recording cut it); bytes before any ``$`` are noise whatever
        follows (RH-BS-1)."""
        if self.ended is not None:
            return
        self.ended = t
        if self._records:
            for e in self._framer.close():
                if e.raw[:1] != b"$":
                    rt, lineno = self._first_byte(e.offset)
                    self.lines.discarded(SentLine(e.raw, rt, lineno, None, e))
        self.polling.close(t)
        ep = self.lockout.episode
        if ep is not None:
            if ep.end is None or ep.end > t:
                ep.end = t
            self.reaction.episode_over(ep)
        self.reaction.close()
        self.lines.close()
        self.budget.close()
        self.pending.clear()
        for cid, why in _NOT_TESTED.items():
            self.ledger.not_tested(cid, why)

    # ================================================================ the backseat
    def _first_byte(self, offset: int) -> tuple[float, int]:
        t, lineno = self._records[0][1], self._records[0][2]
        for start, rt, rl in self._records:
            if start > offset:
                break
            t, lineno = rt, rl
        return t, lineno

    @staticmethod
    def _whole_line(fr: Framer, data: bytes) -> bool:
        """A record that is exactly one line, with nothing pending before it: the framer would
        return it whole, so it is taken as it is (the common case, and the fast one)."""
        return (not fr.pending and data[:1] == b"$" and data.count(b"$") == 1
                and data.find(b"\n") == len(data) - 1 and len(data) <= fr.max_line)

    def _backseat(self, ev: WireEvent) -> None:
        data = ev.data
        if not data:
            return
        line_like = is_line(data)
        rec = Evidence(ev.t, TO_VEHICLE if line_like else TO_VEHICLE_RUN,
                       escape((data[:-2] if line_like else data)[:200]), ev.lineno)
        if self.started is None:
            self.started = ev.t
            self.polling.start(ev.t, rec)
        self.budget.record(ev.t, len(data), rec)
        if self._whole_line(self._framer, data):
            self._records.clear()
            self._touched()
            self._line(SentLine(data, ev.t, ev.lineno, self._decode(data)))
            return
        self._records.append((self._offset, ev.t, ev.lineno))
        self._offset += len(data)
        for e in self._framer.feed(data):
            t, lineno = self._first_byte(e.offset)
            self._touched()
            if isinstance(e, Discard):
                self.lines.discarded(SentLine(e.raw, t, lineno, None, e))
                self._consumed = e.offset + e.length
            else:
                self._line(SentLine(e.raw, t, lineno, self._decode(e.raw)))
                self._consumed = e.offset + len(e.raw)
        # Every byte not yet framed belongs to the one open run, which begins at ``_consumed``:
        # keep only the record holding that byte (later events begin in records still to come).
        recs = self._records
        while len(recs) > 1 and recs[1][0] <= self._consumed:
            recs.popleft()
        while len(recs) > 1:
            recs.pop()

    def _touched(self) -> None:
        """The relay's note on the backseat's run about to be judged (:mod:`.lines`)."""
        if self.faults.instrumented:
            self.lines.instrumented = True
            self.lines.fault = self.faults.take(TO_VEHICLE)

    def _line(self, line: SentLine) -> None:
        self.pending.expire(line.t, self.max_wait)
        self.lines.line(line)
        d = line.decoded
        cmd = line.command
        if cmd is not None:
            line.ack_type = cmd.ACK_TYPE
            self.preconditions.command(line)
            self.servo.sent(line)
            self.polling.sent(line)
        elif d.error is not None and d.error.answered:
            line.ack_type = d.error.ack_type
        if line.sid:
            self.reaction.sent(line)
        if line.ack_type is not None and not self.silent:
            self.pending.expect(line)

    # ================================================================ the vehicle
    def _vehicle(self, ev: WireEvent) -> None:
        data = ev.data
        if not data:
            return
        self.pending.expire(ev.t, self.max_wait)
        self.arrivals.record(ev.t, len(data))
        if self._whole_line(self._vframer, data):
            self._taken()
            self._report(data, ev.t, self.arrivals.arrival(len(data)))
            return
        base = self._voffset
        self._voffset += len(data)
        for e in self._vframer.feed(data):
            self._taken()
            if isinstance(e, Line):
                self._report(e.raw, ev.t, self.arrivals.arrival(e.offset + len(e.raw) - base))
            else:  # bytes that frame into nothing: a line broken on its way (RH-BS-3's uncertainty),
                # readable in part from when its first bytes had arrived
                self.reports.broken(self.arrivals.arrival(max(0, e.offset - base) + min(e.length, 16)))

    def _taken(self) -> None:
        """A relay's note on a vehicle run is used up by it (it touched that run and no other). A
        report the line broke on its way is still taken as known: a backseat may read it anyway,
        and the live certification, which sees what it sent, takes it so too."""
        if self.faults.instrumented:
            self.faults.take(FROM_VEHICLE)

    def _report(self, raw: bytes, t: float, arrived: float) -> None:
        r = self._decode(raw).sentence
        if r is None:  # a line of the vehicle's that does not read (a faulty line, maybe)
            self.reports.broken(arrived)
            return
        if raw[:5] not in _READ:  # nothing else tells the backseat what it could know
            return
        if isinstance(r, s.OSI):
            self._osi(r, t, arrived)
        elif isinstance(r, s.ACK):
            self._ack(r, t, arrived)

    def _osi(self, r: s.OSI, t: float, arrived: float) -> None:
        """``$OSI``: field 2 is a state report (RH-BS-3), field 8 a lockout sign (RH-BS-5)."""
        if r.mode in NEEDS_MISSION:
            self.reports.report(t, arrived, True)
        elif r.mode == "S":
            self.reports.report(t, arrived, False)
            self.servo.end(arrived)
        if r.error_state == "N":
            self.reaction.episode_over(self.lockout.clear(t, reset_code=True))
        else:
            self._sign(arrived, r.error_state, True)

    def _sign(self, arrived: float, code: str, field8: bool) -> None:
        before = self.lockout.episode
        known = before.known if before is not None else None
        self.reaction.episode_over(self.lockout.sign(arrived, code, field8))
        ep = self.lockout.episode
        if ep is not None and ep.known is not None and (ep is not before or known is None):
            self.servo.end(arrived)  # remote control ends for good at a violation (RH-RD-11)

    def _ack(self, a: s.ACK, t: float, arrived: float) -> None:
        """``$ACK``: an accepted start/stop is a state report; err 26 a lockout sign; it answers
        the oldest waiting command of its type (RH-ACK-6)."""
        if a.status == 0 and a.type == 3:
            self.reports.report(t, arrived, True)
        elif a.status == 0 and a.type == 1:
            self.reports.report(t, arrived, False)
        if a.status != 0 and a.err == 26:
            self._sign(arrived, "", False)
        line = self.pending.answer(a.type)
        if line is None:
            return
        accepted = a.status == 0
        self.reaction.answered(line, a.status, arrived)
        self.preconditions.answered(line, accepted)
        event = line.event
        if event == "OMS" or (not accepted and line.sid == "OMS"):  # a refused $OMS, readable or not
            self.servo.answered(line, accepted, t)
        if accepted and event in LOCKOUT_REFUSED:
            ended = self.lockout.clear(t, reset_code=event in ("OMSTART", "OMSTOP"))
            self.reaction.episode_over(ended)

    # ================================================================ notes
    def _note(self, ev: WireEvent) -> None:
        n = parse_note(ev.note)
        if n is None:
            return
        st = self.settings
        if n.kind == "scenario":
            st.case = n.text
        elif n.kind == "lockout":
            self.reaction.episode_over(self.lockout.note_start(ev.t, n.code))
            if self.lockout.episode is not None and self.lockout.episode not in self.episodes:
                self.episodes.append(self.lockout.episode)
        elif n.kind == "lockout-end":
            self.reaction.episode_over(self.lockout.note_end(ev.t))
        elif n.kind == "silence":
            self.silent = True
            self.pending.clear()
            self.servo.end(ev.t)
        elif n.kind == "silence-end":
            self.silent = False
        elif n.kind == "line-fault":
            self.faults.note(ev.t, n.value)
        elif n.kind == "relay":
            self.faults.relay_started()
        elif n.kind == "line-model":
            self.line_model = n.value
            st.clean = not n.value.can_damage
            if not n.value.can_damage:
                self.faults.clean_link()
        elif n.kind == "link" and n.value:
            st.baud = int(n.value)
            self.arrivals.baud = st.baud
        elif n.kind == "resumed":
            self._resume(ev)
        elif n.kind == "overrun":
            self.ledger.remark("RH-BS-4", f"line overrun (a remark, not a verdict: the clause bounds the bytes the "
                                          f"backseat sends, not the replies it asks for): {n.text}")

    def _resume(self, ev: WireEvent) -> None:
        """``run resumed``: the record goes on after a gap in what it saw (an interrupted run,
        a port that vanished and came back, a side of a monitored line gone). What the gap cut
        is not judged, and what the backseat may have learnt in it is not known: a line it cut
        is nobody's (the framers start afresh), no answer is awaited, servo control is not held
        (RH-BS-6), the next poll is due :data:`~.polling.POLL_INTERVAL_S` from here (RH-BS-8),
        and the state reports, the lockout and the rejections as the backseat knew them start
        unknown again (RH-BS-3, RH-BS-5): only what it is seen to learn from here is held
        against it. Decision: an interval that spans the gap is never judged, whichever way."""
        t = ev.t
        st = self.settings
        self._framer = Framer(self.profile.max_line_bytes)
        self._vframer = Framer(max(self.profile.max_line_bytes, 1024))
        self._records.clear()
        self._offset = self._consumed = self._voffset = 0
        self.pending.clear()
        self.servo.end(t)
        self.polling.resume(t, Evidence(t, NOTE, ev.note[:200], ev.lineno))
        self.reports = self.preconditions.reports = StateReports()
        ep = self.lockout.episode
        if ep is not None:
            ep.end = t if ep.end is None else min(ep.end, t)
            self.reaction.episode_over(ep)
        old = self.lockout
        self.lockout = self.reaction.lockout = Lockout(st)
        self.lockout.noted, self.lockout.count = old.noted, old.count
        self.reaction.forget()
