"""The vehicle observer: wire events in, findings on §1–8 out, the same live and offline.

:class:`VehicleObserver` is fed :class:`~helmcheck.judge.wire.WireEvent` s (``feed``) and
``close()``. It owns, for the vehicle role:

* framing both directions (:class:`~helmcheck.grammar.Framer`) and the per-line judgement of
  what the vehicle sends (:mod:`.lines`);
* **ACK pairing**: every backseat line a vehicle must answer waits in order for an ``$ACK`` of its
  type (RH-ACK-1, RH-ACK-6); its data sentences before it (RH-ACK-5, RH-OSD-1/2); the ACK window
  (RH-ACK-2, :func:`~helmcheck.judge.timing.ack_allowance`). A command still unanswered
  :func:`~helmcheck.judge.timing.ack_give_up_after` its send is missing (RH-ACK-1) — if the vehicle
  still says anything; an ACK that comes after that belongs to it (RH-ACK-2), not to the next
  command. A line the vehicle must discard passes its clause (RH-FRM-2/4/5/6/7) when the window
  passes unanswered, and fails it when answered (the windows that run out: :mod:`.deadlines`);
* **the mirror** (:mod:`.belief`): the answered command goes in at its ACK's time; every ``$OSI``
  is judged against it (RH-OUT-4 and the clauses of what led there); unseen plant events are
  adopted with explicit time windows (:mod:`.closure`);
* the checks an ``$OSI`` allows beyond the mirror's fields (:mod:`.osichecks`);
* the one ledger it writes to, with clause attribution by :mod:`.blame` (findings inside a case
  are booked on the clauses the case is about).

* **a faulty line** (``docs/contracts.md``, "A faulty line"): an error the line could have caused
  — a broken vehicle line (its form: :mod:`helmcheck.judge.spoil`), bytes that frame into
  nothing, a lost or late ``$ACK``, a reply left incomplete by a broken line — is held
  (:mod:`helmcheck.judge.streaks`) until the observation is made again: the same command re-sent,
  the same sentence read again. Made again clean, it was the line's (counted, not judged); the
  same error again, as often as its form needs, it is the vehicle's; never made again (the case
  or the record ends), INCONCLUSIVE naming what the line may have done. :attr:`Sent.spoil` tells
  a live driver which observation to make again. A record that carries a line-fault relay's
  notes (:mod:`helmcheck.judge.linefaults`) is judged exactly: what a note touched is the line's,
  what none touched is the vehicle's.

Notes it acts on (:mod:`helmcheck.judge.wire`): ``case``/``case … end`` (attribution; a case's
end concludes what it held), ``not tested``/``inconclusive`` (tester facts), ``link:``
(RH-FRM-9), ``plant:`` and ``fault injected`` (exact plant events from an emulator's own log: applied after a report asked
for before them and still on its way, which shows the state before them; a mission waypoint
reached whose park or end the observer has not learnt is left to the reports, from the note's
moment on),
``line fault …`` and ``relay started:`` (a line-fault relay's record), ``line model:`` (a clean
link: nothing is held, every error is the vehicle's at once, :mod:`helmcheck.judge.linemodel`).

A driver reads, besides the ledger: :attr:`sent` (every classified backseat line, with its
outcome — the handle a live driver waits on), :attr:`last_osi`, :meth:`deadline` and
:meth:`state` (for its waits), and the timeline for the report.
"""

from __future__ import annotations

import re
from collections import deque
from typing import Optional

from ...grammar import Discard, Framer, Line
from ...grammar import sentences as s
from ...grammar.wirelog import escape
from ...model import plant as P
from ...profile import Profile
from ..ledger import Evidence, Ledger, Reason
from ..linefaults import LineFaults
from ..linemodel import UNKNOWN
from ..spoil import REPEAT, explain, explain_discard, signature
from ..streaks import OTHER_REPEAT, Streaks
from ..timing import JITTER_S
from ..wire import FROM_VEHICLE, LINE_CACHE, NOTE, TO_VEHICLE, Decodings, WireEvent, parse_note
from . import osichecks
from .belief import Beliefs
from .answers import Answers, reading_clause
from .blame import command_clauses, targets, vehicle_clause
from .catalog import GivenMissions, KnownMissions
from .deadlines import Deadlines
from .lines import PREFIX_REPEAT, Kind, OutputJudge, classify
from .sent import Sent, class_of_id, text_of

__all__ = ["VehicleObserver", "Sent"]

#: Never named as the related clause of a finding: the generic report check and time.
_NOT_RELATED = frozenset({"RH-OUT-4", "RH-TIM-1", "RH-TIM-2"})

_PLANT = {"WaypointReached": P.WaypointReached, "OnStation": P.OnStation,
          "QueueWaypointReached": P.QueueWaypointReached, "AtSurface": P.AtSurface,
          "Submerged": P.Submerged, "SafetyViolation": P.SafetyViolation}
_new_tuple = tuple.__new__
_DATA_OF = {"G": "GPRMC", "C": "Compass", "S": "OSI", "P": "OPI", "D": "DVL", "Y": "OYSI", "T": "OCTD",
            "I": "OINS"}
_OUT_ID = re.compile(rb"\$?([A-Z]+)(?:,([0-9]{1,3}))?")
#: What a lost answer may be, when nothing else says (the line's bytes to the vehicle are not seen)
LOST = "no $ACK: the line may have lost the command or its $ACK"


def out_key(raw: bytes) -> tuple:
    """The observation a vehicle line is, to know it again: its ID as read (and an ``$ACK``'s
    type), or ``?`` when none can be read."""
    m = _OUT_ID.match(raw)
    if m is None:
        return ("out", "?")
    sid = m.group(1).decode()
    if sid == "ACK":
        return ("out", "ACK", (m.group(2) or b"?").decode())
    return ("out", sid)


class VehicleObserver(Answers, Deadlines):
    """See the module docstring."""

    def __init__(self, profile: Profile, ledger: Ledger, *, time_scale: float = 1.0,
                 baud: Optional[int] = None, resolution: float = 1e-6, catalog=None,
                 decodings: Optional[Decodings] = None):
        self.profile = profile
        self.ledger = ledger
        self.k = float(time_scale)
        self.res = resolution
        self.jitter = JITTER_S  #: the host's jitter: more where a ``line budget:`` note measured more
        self.baud = baud if baud is not None else profile.baud
        self.missions = GivenMissions(catalog) if catalog is not None else KnownMissions(profile)
        self.beliefs = Beliefs(profile, self.missions, self.k)
        self.out = OutputJudge(ledger, profile)
        self.out.holder = self._hold_out
        #: observations a faulty line may have spoilt, held until made again (module docstring)
        self.streaks = Streaks(ledger)
        self.faults = LineFaults()  #: what a line-fault relay's notes say the line did
        self.line_model = UNKNOWN  #: whether the link can damage bytes, as the record states it
        #: a command's bytes -> the latest sending of it answered in full, on time, nothing spoilt
        self.clean_sendings: dict = {}
        #: key -> (``key = value``, the clause it was seen on, the first evidence) of every reading of the profile's open
        #: questions the vehicle was seen to take (:mod:`helmcheck.model.readings`)
        self.readings_shown: dict = {}
        self.late_until = 0.0  #: when the latest late $ACK came (what was sent before may share its stall)
        self._unit_fault: Optional[str] = None  #: the relay's note on the vehicle run being judged
        self._junk_wait: Optional[tuple] = None  #: bytes between lines, waiting for what follows them
        self.framers = {TO_VEHICLE: Framer(profile.max_line_bytes),
                        FROM_VEHICLE: Framer(max(4096, 4 * profile.max_line_bytes))}
        self.pending: deque[Sent] = deque()
        self.silent: deque[Sent] = deque()
        self.gave_up: deque[Sent] = deque(maxlen=64)
        self.dead: list[Sent] = []  #: missing while the vehicle said nothing at all (yet)
        self.quiet: list[Sent] = []  #: discarded lines waiting for proof the vehicle listens
        self.last_osd: Optional[Sent] = None
        #: (wall time, line number, sentence) of an ``$OXFLT`` no later reply has bounded yet
        #: (answers.py)
        self.oxflt_open: Optional[tuple] = None
        self.mission_shown: list[tuple] = []  #: $OMSTARTs the reports to come judge (answers.py)
        self.sent: deque[Sent] = deque(maxlen=256)
        self.seq = 0
        self.t = 0.0
        self.vbytes = 0
        self.alive_t: Optional[float] = None  #: time of the vehicle's last valid line
        self.first_command_t: Optional[float] = None
        self.case = ""
        self.case_clauses: tuple[str, ...] = ()
        self.link_baud: Optional[int] = None
        self.after_discard = False
        self.last_osi: Optional[s.OSI] = None
        self.last_osi_t = 0.0
        self.timeline: list[tuple[float, str]] = []
        self.events: list[dict] = []
        self.checks = osichecks.OsiChecks(self)
        #: lines read (shared with the session's other observer when it is given one)
        self.decode = decodings if decodings is not None and decodings.profile is profile else Decodings(profile)
        self._escaped: dict = {}  #: a line's evidence text (sessions repeat their lines)
        self._kinds: dict = {}  #: a backseat line's :class:`~.lines.Kind`, by its bytes
        #: per direction, a record's bytes → the one line it is, or () when it needs the framer
        self._whole: dict = {TO_VEHICLE: {}, FROM_VEHICLE: {}}
        self.closed = False
        self.aborted = ""
        #: (mode before, command ID) of every accepted control command in a remote mode (coverage)
        self.interrupt_pairs: set = set()
        #: an answer that names two faults, held until a report tells them apart (:meth:`_hold`)
        self.held: Optional[tuple] = None
        #: plant notes waiting for a report on its way to be judged first (:meth:`_note`)
        self.notes_held: list = []

    # ------------------------------------------------------------------ helpers
    def v(self, t: float) -> float:
        """Vehicle seconds at wall time ``t`` (RH-TIM-2)."""
        return self.k * t

    def slack_v(self) -> float:
        """What every observation of this record cannot see: jitter and the timestamp step."""
        return self.k * (self.jitter + self.res)

    def book(self, verdict: str, candidates: tuple[str, ...], reason: str, evidence=(),
             at: Optional["Sent"] = None, stated: tuple[str, ...] = ()) -> None:
        """Book a finding on :func:`~.blame.targets` of ``candidates`` (on ``stated``, the clauses
        that name the broken behaviour, when given), in the case context of ``at`` (the line it is
        about) or the present one."""
        case, clauses = (at.case, at.case_clauses) if at is not None else (self.case, self.case_clauses)
        if case and verdict != "pass":
            reason = f"{case}: {reason}"
        booked = targets(candidates, clauses, stated)
        if verdict == "fail":
            # the other clauses the evidence fits, named beside the one whose rule it broke (the
            # traceability table, helmcheck/spec/rules.toml)
            related = [c for c in dict.fromkeys(candidates) if c not in booked and vehicle_clause(c)
                       and c not in _NOT_RELATED]
            if related:
                reason = f"{reason} (related: {', '.join(related)})"
        for cid in booked:
            if verdict == "fail":
                if at is not None and at.holding:  # the line may have spoilt it: held (module docstring)
                    at.held.append((cid, reason, list(evidence), case))
                    continue
                self.ledger.failed(cid, reason, evidence, case)
            elif verdict == "inconclusive":
                self.ledger.inconclusive(cid, reason, evidence, case)
            else:
                self.ledger.passed(cid, reason, evidence, case)

    def passed(self, clauses, reason: Reason, evidence=()) -> None:
        for cid in clauses:
            self.ledger.passed(cid, reason, evidence, self.case)

    def event(self, t: float, kind: str, label: str, **extra) -> None:
        if len(self.events) < 5000:
            self.events.append({"t": round(max(0.0, t), 6), "kind": kind, "label": label[:120], **extra})

    def mode_seen(self, t: float, mode: str) -> None:
        if not self.timeline or self.timeline[-1][1] != mode:
            if len(self.timeline) < 5000:
                self.timeline.append((round(t, 6), mode))

    def state(self):
        """The most plausible model state (for a driver's waits; never for judging)."""
        return self.beliefs.primary.model

    def deadline(self, name: Optional[str] = None) -> Optional[tuple[float, float, str]]:
        """(wall deadline, duration in vehicle seconds, name) of a model timer, or None."""
        got = self.beliefs.primary.model.timer(name)
        if got is None:
            return None
        due, dur, nm = got
        return due / self.k, dur, nm

    # ------------------------------------------------------------------ an answer naming two faults
    def _hold(self, p: Sent, cands: tuple, ignored: tuple, what: str, ev: list) -> None:
        """An answer no conforming state gives, which the state before the accepted command just
        before it gives (:attr:`~.belief.CommandResult.ignored`): either the answer is wrong, or
        that command was not carried out. Held until the next report tells them apart
        (:meth:`_settle`)."""
        cmd, row, ack = ignored
        q = next((q for q in reversed(self.sent) if q.kind.item is cmd and q is not p), None)
        self.held = (p, cands, command_clauses(cmd, ack, row), what, ev,
                     text_of(q) if q is not None else f"${cmd.ID}", [q.ev] if q is not None else [])

    def _settle(self, ignored: Optional[bool], explained: bool, report: list) -> None:
        """Book the held answer: on its own clauses when the next report shows the command before
        it carried out (the mirror explains the report, a vehicle that did not carry it out does
        not); on that command's clauses when the report shows it not carried out; on both when
        the report tells nothing apart, or none comes before another command or the record's end."""
        p, cands, other, what, ev, text, before_ev = self.held  # type: ignore[misc]
        self.held = None
        if ignored and not explained:
            self.book("fail", other, f"{text} was accepted but not carried out: the next report shows the state "
                                     f"before it, and {what} — as that state answers", before_ev + ev + report, at=p)
        elif explained and ignored is False:
            self.book("fail", cands, what, ev, at=p)
        else:
            self.book("fail", cands, f"{what}; or else {text} before it, accepted with no report between, was not "
                                     f"carried out (the state before it answers so): no report tells which",
                      before_ev + ev, at=p)
            self.book("fail", other, f"{text}, accepted, may not have been carried out: {what}, as the state before "
                                     f"it answers; or else that answer is wrong: no report tells which",
                      before_ev + ev, at=p)

    # ------------------------------------------------------------------ input
    def feed(self, ev: WireEvent) -> None:
        self._advance(ev.t)
        if ev.dir == TO_VEHICLE:
            for fe in self._frame(TO_VEHICLE, ev.data):
                self._backseat(fe, ev)
        elif ev.dir == FROM_VEHICLE:
            self.vbytes += len(ev.data)
            for fe in self._frame(FROM_VEHICLE, ev.data):
                self._vehicle(fe, ev)
            if self.notes_held:
                self._release_notes()
        elif ev.dir == NOTE:
            self._note(ev)

    def _frame(self, d: str, data: bytes):
        """The framer's events for ``data``; a record that is one whole line skips the framer."""
        fr = self.framers[d]
        if not fr.pending:
            known = self._whole[d]
            whole = known.get(data)
            if whole is None:  # sessions repeat their lines: the shape of each is worked out once
                if len(known) >= LINE_CACHE:
                    known.clear()
                whole = known[data] = ((Line(data, 0),) if data[:1] == b"$" and data.count(b"$") == 1
                                       and data.find(b"\n") == len(data) - 1 and len(data) <= fr.max_line
                                       else ())
            if whole:
                return whole
        return fr.feed(data)

    def _evidence(self, ev: WireEvent, raw: bytes, direction: str) -> Evidence:
        """The line's :class:`~helmcheck.judge.ledger.Evidence` (made by ``tuple.__new__``, as the
        wire-log reader makes its records: the named tuple's own ``__new__`` is Python code)."""
        text = self._escaped.get(raw)  # only whole CR LF lines are kept
        if text is not None:
            return _new_tuple(Evidence, (ev.t, direction, text, ev.lineno))
        if raw.endswith(b"\r\n") and raw.find(b"\n") == len(raw) - 1:
            if len(self._escaped) >= LINE_CACHE:
                self._escaped.clear()
            text = self._escaped[raw] = escape(raw[:-2])
            return _new_tuple(Evidence, (ev.t, direction, text, ev.lineno))
        return Evidence(ev.t, direction + "~", escape(raw[:200]), ev.lineno)

    def _note(self, ev: WireEvent) -> None:
        n = parse_note(ev.note)
        if n is None:
            return
        if n.kind == "line-fault":
            self.faults.note(ev.t, n.value)
        elif n.kind == "relay":
            self.faults.relay_started()
        elif n.kind == "line-model":
            self.line_model = n.value
            if not n.value.can_damage:
                self.faults.clean_link()
        elif n.kind == "case":
            self.case, self.case_clauses = n.case, n.clauses
        elif n.kind == "case-end":
            self._junk_settle(False)
            if self.streaks:
                self.streaks.conclude("the case ended before it was made again")
            self.case, self.case_clauses = "", ()
        elif n.kind in ("not-tested", "inconclusive"):
            for cid in n.clauses:
                if n.kind == "not-tested":
                    self.ledger.not_tested(cid, n.text, self.case)
                else:
                    self.ledger.inconclusive(cid, n.text, [Evidence(ev.t, "!", ev.note, ev.lineno)], self.case)
        elif n.kind == "budget":
            self.jitter = max(JITTER_S, n.value.jitter_s)
        elif n.kind == "link":
            self.link_baud = n.value
            self.baud = n.value  # the line's rate as the tester opened it: what transmit times use
        elif n.kind == "aborted":
            self.aborted = n.text
        elif n.kind == "held":
            self.ledger.hold()
        elif n.kind in ("confirmed", "unconfirmed"):
            self.ledger.release(n.kind == "confirmed", n.text, n.clauses)
        elif n.kind == "resumed":
            if self.ledger.holding:
                self.ledger.release(False, "not confirmed: the run was interrupted before the re-runs")
            self._resume(ev, n.text)
        elif n.kind in ("plant", "fault"):
            if n.kind == "fault":
                event, v = P.SafetyViolation(n.code), self.v(ev.t)
            else:
                name, kwargs, v = n.value
                cls = _PLANT.get(name)
                if cls is None:
                    return
                try:
                    event = cls(**kwargs)
                except TypeError:
                    return
            # a report asked for before the event, still on its way, shows the state before it (the
            # vehicle answers an $OSD when it processes it): the event waits until it is judged
            asked = next((q for q in self.pending if q.kind.ack_type == 8 and q.osi is None
                          and "S" in getattr(q.kind.item, "requested", ())), None)
            if asked is not None:
                self.notes_held.append((event, v, ev, asked))
            else:
                self._plant_note(event, v, ev)

    def _plant_note(self, event, v: float, ev: WireEvent) -> None:
        """A plant event from a note, at vehicle time ``v``, to every candidate."""
        for c in self.beliefs.cands:
            if isinstance(event, P.WaypointReached) and self._unknown_waypoint(c.model, event.index):
                # what the waypoint holds is learnt from the reports (the closure), in a window
                # that begins when the note says it was reached: the model is brought to then
                c.model.advance(max(v, c.model.now or 0.0))
                c.noted = c.model.now
            else:
                c.model.plant(event, max(v, c.model.now or 0.0))
            c.drain()
        self.event(ev.t, "lockout" if isinstance(event, P.SafetyViolation) else "note", ev.note[:80])

    def _release_notes(self, all_: bool = False) -> None:
        """Plant notes held for a report on its way (:meth:`_note`), once it has come (or gone)."""
        while self.notes_held:
            event, v, ev, asked = self.notes_held[0]
            if not all_ and asked.osi is None and any(q is asked for q in self.pending):
                return
            self.notes_held.pop(0)
            self._plant_note(event, v, ev)

    def _unknown_waypoint(self, m, index: Optional[int]) -> bool:
        """Whether reaching mission waypoint ``index`` (the next one when None) does what the
        observer does not know yet: a mission learnt from the reports (no mission files given)
        whose park at that waypoint, or whose length, has not been seen. A plant note of such a
        waypoint reached is left to the reports, which the closure learns it from (as in a log
        without notes); applied, it would take the waypoint as holding nothing."""
        run = m.mission
        if run is None or m.mode != "N":
            return False
        entry = self.missions.entry(run.name)
        if entry is None:
            return False  # the mission files were given (or the name is unknown: nothing to learn)
        return run.is_open or not entry.park_known(m.mission_wp if index is None else index)

    # ------------------------------------------------------------------ backseat lines
    def _backseat(self, fe, ev: WireEvent) -> None:
        if isinstance(fe, Discard):
            k = classify(None, fe.raw, self.profile, fe.clause)
            raw = fe.raw
            self.after_discard = True
        else:
            raw = fe.raw
            k = self._kinds.get(raw)
            if k is None:  # a line's kind depends on its bytes alone (sessions repeat their lines)
                if len(self._kinds) >= LINE_CACHE:
                    self._kinds.clear()
                k = self._kinds[raw] = classify(self.decode(raw), raw, self.profile)
            if self.after_discard and k.kind in ("command", "error") and not k.variant:
                k = Kind(k.kind, k.item, k.ack_type, variant="RH-FRM-7")
            self.after_discard = False
        if self.faults.instrumented:
            self.faults.take(TO_VEHICLE)  # what the vehicle got, as recorded: judged as it is
        self.seq += 1
        sent = Sent(self.seq, ev.t, raw, self._evidence(ev, raw, ">"), k, self.case, self.case_clauses,
                    self.vbytes)
        sent.mark = self.streaks.mark()
        # a tester that opened the link (its ``link:`` note) probes a vehicle that may still be
        # starting: its lines before the first answer are not timed (answers.py); a capture's are
        sent.first_contact = self.alive_t is None and self.link_baud is not None
        self.sent.append(sent)
        if k.kind in ("command", "error"):
            if self.first_command_t is None:
                self.first_command_t = ev.t
            self.pending.append(sent)  # it goes into the mirror at its ACK (RH-RD-15)
        elif k.kind == "oxflt":
            sent.state = "silent"
            self.silent.append(sent)
            if self.oxflt_open is not None:  # an earlier one, unanswered: taken in before this one
                self._apply_oxflt(ev.t)
            # into the mirror at the next reply, which bounds when it took effect (answers.py)
            self.oxflt_open = (ev.t, sent.seq, k.item)
            self.checks.oxflt_sent(k.item.code, ev.t)  # type: ignore[union-attr]
            self.event(ev.t, "lockout", f"$OXFLT,{k.item.code} sent")  # type: ignore[union-attr]
        else:
            sent.state = "silent"
            self.silent.append(sent)

    # ------------------------------------------------------------------ vehicle lines
    def _vehicle(self, fe, ev: WireEvent) -> None:
        if self.faults.instrumented:
            self._unit_fault = self.faults.take(FROM_VEHICLE)
        if isinstance(fe, Discard):
            self.out.discard(fe.raw, fe.length, fe.clause, self._evidence(ev, fe.raw, "<"), self.case)
            return
        d = self.decode(fe.raw)
        evd = self._evidence(ev, fe.raw, "<")
        if (d.sentence is None and d.sentence_id == "ACK" and d.error is not None
                and not d.error.clause.startswith("RH-FRM") and self._invalid_ack(fe.raw, evd)):
            # a malformed $ACK answering a line the vehicle must discard: booked on that line's
            # clause (whatever else is wrong with the answer); the bytes before it are still read
            self.out.before_line, self.out.noise_before = self.out.noise_before, None
            return
        sent = self.out.line(d, evd, self.case)
        if self._junk_wait is not None:
            self._junk_settle(d.sentence is not None)
        if self.streaks and d.sentence is not None and not d.findings and d.terminator == "\r\n":
            # the sentence read whole: what was held for it (and for the bytes before it) was the line's
            self.streaks.clean(out_key(fe.raw))
            if self.out.before_line is None:
                self.streaks.clean(("junk",))
        if sent is not None:
            self.alive_t = ev.t
            if self.dead or self.quiet:
                self._revive(ev.t)
            if self.link_baud is not None:
                if self.ledger.keeps("RH-FRM-9", "pass", self.case):
                    self.ledger.passed("RH-FRM-9", f"sentences read and answered at {self.link_baud} baud 8N1 "
                                                   f"as the tester opened the line", [evd], self.case)
                else:
                    self.ledger.passed("RH-FRM-9", "", (), self.case)  # counted; what is kept is full
        if isinstance(sent, s.ACK):
            self._ack(sent, ev.t, evd)
        elif sent is not None:
            self._data(sent, type(sent).__name__, ev.t, evd)
        elif d.sentence_id in _DATA_OF.values() or d.sentence_id in ("OSI", "C", "GPRMC", "OPI", "DVL",
                                                                      "OYSI", "OCTD", "OINS"):
            self._data(None, class_of_id(d.sentence_id), ev.t, evd)

    def _hold_out(self, raw: bytes, d, fails: list, ev: Evidence, case: str, discard: str) -> bool:
        """The failures of a broken vehicle run, held until it is read again (module docstring):
        False when they are booked at once (a line-fault relay's record in which no note touched it)."""
        fault, self._unit_fault = self._unit_fault, None
        if self.faults.instrumented and fault is None:
            return False  # the relay says the line did nothing to it: what it is, the vehicle sent
        junk = d is None and raw[:1] != b"$"
        if junk and fault is None:  # bytes between lines: judged with what follows them (_junk_settle)
            self._junk_settle(False)
            self._junk_wait = (raw, fails, ev, case, discard)
            return True
        key = ("junk",) if junk else out_key(raw)
        if fault is not None:
            text, sig, need = f"the line touched it (the relay's note: {fault})", ("note",), REPEAT
        else:
            sig = ("junk", raw[:32]) if junk else (signature(raw, d) if d is not None else ("discard", discard))
            spoil = None
            if not self.streaks.proven(key, sig):
                spoil = explain_discard(raw, discard, "", self.profile) if d is None else explain(raw, self.profile, d)
            if junk:
                text, need = spoil.text if spoil is not None else "bytes between lines", PREFIX_REPEAT
            elif spoil is not None:
                text, need = spoil.text, REPEAT
            else:
                text, need = "a broken line (of a form no one fault of a line gives)", OTHER_REPEAT
        if self.alive_t is None:  # nothing read whole from it yet: garbage at another baud rate, or a
            sig = ("before any sentence", ev.lineno)  # line too noisy, repeats; not a vehicle fault
        findings = [(cid, reason, [ev], case) for cid, reason in fails]
        owners = tuple(q.ident for q in self.pending)
        held = self.streaks.hold(key, sig, text, findings, need=need, owners=owners, known=fault is not None,
                                 raw=raw if self.alive_t is not None else None)
        if held is not None:
            for q in self.pending:
                q.spoils.append((text, need, fault is not None, sig))
                if not q.spoil:
                    q.spoil = text
        return True

    def _junk_settle(self, reply: bool) -> None:
        """Bytes between lines, now that what follows them is known: before a reply, they are held
        with the bytes before the replies next to it (the same bytes before reply after reply are a
        vehicle or modem prefix, RH-FRM-1, :data:`~.lines.PREFIX_REPEAT` in a row); before
        anything else (more garbage: a wrong baud rate, a line too noisy), they are held alone."""
        if self._junk_wait is None:
            return
        raw, fails, ev, case, discard = self._junk_wait
        self._junk_wait = None
        spoil = explain_discard(raw, discard, "", self.profile)
        text = spoil.text if spoil is not None else "bytes between lines"
        findings = [(cid, reason, [ev], case) for cid, reason in fails]
        key, sig = (("junk",), ("junk", raw[:32])) if reply else (("junk", "alone"), ("junk", "alone", ev.lineno))
        self.streaks.hold(key, sig, text, findings, need=PREFIX_REPEAT)  # (the same bytes: the prefix rule)

    def awaits(self, p: Sent) -> bool:
        """Something is held that sending ``p`` again would make again (module docstring)."""
        return bool(self.streaks) and self.streaks.awaits(p.ident)

    def _processed(self, upto: "Sent", t: float) -> None:
        """Commands sent before ``upto`` that the vehicle is answering: it has processed them
        (RH-ACK-6), answered or not; the unanswered ones go into the mirror unanswered."""
        for q in self.pending:
            if q is upto:
                break
            if not q.branched:
                q.branched = True
                q.expected = self.beliefs.unanswered(q.kind.item, self.v(t))

    def _data(self, sentence, cls: str, t: float, evd: Evidence) -> None:
        """A data sentence: it belongs to the oldest ``$OSD`` still waiting (RH-ACK-5)."""
        p = first = None  # the oldest $OSD waiting that no later command's ACK overtook (RH-ACK-6:
        for q in self.pending:  # an $OSD overtaken was processed before it, its data before its ACK)
            if q.kind.ack_type == 8:
                if not q.overtaken:
                    p = q
                    break
                if first is None:
                    first = q
        if p is None:
            p = first
        if p is not None:
            self._processed(p, t)
        if p is None:
            q = next((q for q in reversed(self.silent) if q.kind.kind == "discard" and q.kind.would_be == 8), None)
            if q is not None:  # RH-FRM-2/4/5/6/7: the data answers an $OSD line it must discard
                if q.state == "silent":
                    q.state = "answered-discard"
                    self.book("fail", (q.kind.clause,), f"{text_of(q)} must be discarded silently "
                                                        f"({q.kind.clause}); the vehicle answered ${cls}",
                              [q.ev, evd], at=q)
                return
            last = self.last_osd
            if self.first_command_t is None:
                self.ledger.inconclusive("RH-ACK-5", "a data sentence before the first command of the "
                                                     "record (its request may predate it)", [evd], self.case)
            elif last is not None and last.accepted and len(last.data) < len(last.expected) - 1:
                self.book("fail", ("RH-ACK-5",), f"${cls} came after the $ACK,8 of its $OSD (data must come "
                                                 f"before the ACK)", [last.ev, evd])
            else:
                self.book("fail", ("RH-ACK-5",), f"${cls} answers no $OSD", [evd])
            return
        p.data.append((sentence, cls, evd))
        if isinstance(sentence, s.OSI):
            p.osi = sentence
            self._osi(sentence, p, t, evd)

    # ------------------------------------------------------------------ resume and end
    def _resume(self, ev: WireEvent, what: str) -> None:
        """An interrupted run goes on (``run resumed`` note): what the interruption cut off is not
        judged (a command still inside its ACK window: a remark on RH-ACK-1, never a verdict), the vehicle's
        state is unknown again (taken from the next report that shows it whole, as at the start of
        a record), and the run is no longer ended early."""
        t = ev.t
        if self.held is not None:
            self._settle(None, False, [])
        self.notes_held = []
        self.framers = {TO_VEHICLE: Framer(self.profile.max_line_bytes),  # a line cut by the
                        FROM_VEHICLE: Framer(max(4096, 4 * self.profile.max_line_bytes))}  # stop is nobody's
        cut = list(self.pending) + self.dead
        if cut:  # decision: what the cut left unanswered was never observed, so it is not judged
            self.ledger.remark("RH-ACK-1", f"{len(cut)} command(s) left unanswered when the run was cut were not "
                                           f"judged (first: {text_of(cut[0])}; {what})")
        for q in self.silent:
            q.state = "silent"
        self._junk_settle(False)
        self.streaks.conclude("the run was interrupted before it was made again")
        self.pending.clear()
        self.silent.clear()
        self.dead.clear()
        self.quiet.clear()
        self.gave_up.clear()
        self.last_osd = None
        self._mission_unshown("the run was interrupted")
        self.after_discard = False
        self.last_osi = None
        self.case, self.case_clauses = "", ()
        self.beliefs = Beliefs(self.profile, self.missions, self.k)
        self.checks = osichecks.OsiChecks(self)
        self.aborted = ""
        self.t = max(self.t, t)

    def _mission_unshown(self, why: str) -> None:
        for p, a, cands, ev, names in self.mission_shown:
            self._mission_unknown(p, a, cands, ev, f" ({', '.join(sorted(names))} not seen running: {why})")
        self.mission_shown = []

    def close(self) -> None:
        """The record ended (at the last event's time)."""
        if self.closed:
            return
        self.closed = True
        for taken, cid, _ev in self.readings_shown.values():
            if cid:
                self.ledger.remark(cid, f"the vehicle takes the reading {taken} ({reading_clause(taken)}; every "
                                        f"reading is accepted: helmcheck profile readings).")
        t = self.t
        for fe in self.framers[TO_VEHICLE].close():
            self._backseat(fe, WireEvent(t, TO_VEHICLE, b"", "", 0))
        while self.silent:
            q = self.silent.popleft()
            if self._silent_over(q, t):
                self._silence_kept(q)
        if self.pending:  # decision: the record's end is not the vehicle's (a session's duration, a
            # capture stopped): what it cut off inside its ACK window was never observed, so it is
            # not judged, as for a cut run (_resume); with nothing else seen the clause is NOT-TESTED
            p = self.pending[0]
            why = (f"{len(self.pending)} command(s) still inside their ACK window when the record ended were not "
                   f"judged (first: {text_of(p)}, {t - p.t:.2f} s before the end)")
            self.ledger.remark("RH-ACK-1", why)
            self.ledger.not_tested("RH-ACK-1", why, p.case)
        for p in self.dead:
            self.ledger.inconclusive("RH-ACK-1", f"{text_of(p)}: no $ACK, and the vehicle said nothing at all "
                                                 f"afterwards (a link fault?)", [p.ev], p.case)
        for p in self.gave_up:
            if p.ack is None and p.late_booked and not p.missing_booked:
                p.missing_booked = True
                self._book_missing(p)
        self._junk_settle(False)
        self.streaks.conclude("the record ended before it was made again")
        self._mission_unshown("the record ended")
        self._release_notes(all_=True)
        if self.held is not None:
            self._settle(None, False, [])
        self.checks.close()
        if self.ledger.holding:
            self.ledger.release(False, "not confirmed: the record ended before the re-runs")
        if self.aborted:
            for cid in self.ledger.order:
                if not self.ledger.judged(cid):
                    self.ledger.inconclusive(cid, f"not judged: the run ended early ({self.aborted})")
