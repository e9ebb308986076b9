"""The vehicle observer: wire events in, findings on §1–8 out, the same live and offline.

:class:`VehicleObserver` is fed :class:`~helmcheck.judge.wire.WireEvent` s (``feed``) and
``close()``. It owns, for the vehicle role:

* framing both directions (:class:`~helmcheck.grammar.Framer`) and the per-line judgement of
  what the vehicle sends (:mod:`.lines`);
* **ACK pairing**: every backseat line a vehicle must answer waits in order for an ``$ACK`` of its
  type (RH-ACK-1, RH-ACK-6); its data sentences before it (RH-ACK-5, RH-OSD-1/2); the ACK window
  (RH-ACK-2, :func:`~helmcheck.judge.timing.ack_allowance`). A command still unanswered
  :func:`~helmcheck.judge.timing.ack_fail_after` its send is missing (RH-ACK-1) — if the vehicle
  still says anything; an ACK that comes after that belongs to it (RH-ACK-2), not to the next
  command. A line the vehicle must discard passes its clause (RH-FRM-2/4/5/6/7) when the window
  passes unanswered, and fails it when answered;
* **the mirror** (:mod:`.belief`): the answered command goes in at its ACK's time; every ``$OSI``
  is judged against it (RH-OUT-4 and the clauses of what led there); unseen plant events are
  adopted with explicit time windows (:mod:`.closure`);
* the checks an ``$OSI`` allows beyond the mirror's fields (:mod:`.osichecks`);
* the one ledger it writes to, with clause attribution by :mod:`.blame` (findings inside a case
  are booked on the clauses the case is about).

Notes it acts on (:mod:`helmcheck.judge.wire`): ``case``/``case … end`` (attribution),
``not tested``/``inconclusive`` (tester facts), ``link:`` (RH-FRM-9), ``plant:`` and
``fault injected`` (exact plant events from an emulator's own log).

A driver reads, besides the ledger: :attr:`sent` (every classified backseat line, with its
outcome — the handle a live driver waits on), :attr:`last_osi`, :meth:`deadline` and
:meth:`state` (for its waits), and the timeline for the report.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
from typing import Optional

from ...grammar import Discard, Framer, Line, decode
from ...grammar import sentences as s
from ...grammar.capture import escape
from ...model import plant as P
from ...profile import Profile
from ..ledger import Evidence, Ledger
from ..timing import ACK_GRACE_S, JITTER_S, ack_allowance, ack_fail_after
from ..wire import FROM_VEHICLE, NOTE, TO_VEHICLE, WireEvent, parse_note
from . import osichecks
from .belief import Beliefs
from .blame import command_clauses, passable, targets
from .catalog import GivenMissions, KnownMissions
from .lines import Kind, OutputJudge, classify

__all__ = ["VehicleObserver", "Sent"]

_PLANT = {"WaypointReached": P.WaypointReached, "OnStation": P.OnStation,
          "QueueWaypointReached": P.QueueWaypointReached, "AtSurface": P.AtSurface,
          "Submerged": P.Submerged, "SafetyViolation": P.SafetyViolation}
_UNSOLICITED = (13, 14)
#: Wall seconds after which an unanswered command's ACK is taken never to come (RH-ACK-1).
GIVE_UP_S = 15.0
_OWN_REASON = {"RH-INT-3": "after the control that interrupted an $OPK park ended, the mission resumed, "
                           "not the park",
               "RH-OMW-5": "after the control that interrupted the $OMW queue ended, the mission resumed, "
                           "not the queue",
               "RH-SAF-2": "the commands refused during the lockout had no effect after it"}
_DATA_OF = {"G": "GPRMC", "C": "Compass", "S": "OSI", "P": "OPI", "D": "DVL", "Y": "OYSI", "T": "OCTD",
            "I": "OINS"}


@dataclass
class Sent:
    """One backseat line as the observer classified it, and what became of it."""

    seq: int
    t: float  #: wall time of the record holding its last byte
    raw: bytes
    ev: Evidence
    kind: Kind
    case: str = ""
    case_clauses: tuple = ()
    vbytes0: int = 0  #: vehicle bytes seen before it (for the transmit time of the replies)
    state: str = "pending"  #: pending | answered | missing | silent | answered-discard
    ack: Optional[s.ACK] = None
    t_ack: Optional[float] = None
    data: list = field(default_factory=list)  #: (sentence or None, class name, Evidence)
    expected: list = field(default_factory=list)
    osi: Optional[s.OSI] = None
    negative: bool = False  #: a conforming vehicle refuses it: the tester's own negative test
    overtaken: bool = False  #: the ACK of a later command came first
    waited: float = 0.0  #: how long the observer waited before calling its ACK missing
    branched: bool = False  #: a later command was answered first: taken into the mirror unanswered
    late_booked: bool = False  #: RH-ACK-2 booked: no ACK by the give-up deadline
    missing_booked: bool = False  #: RH-ACK-1 booked: no ACK at all

    @property
    def done(self) -> bool:
        return self.state != "pending"

    @property
    def accepted(self) -> bool:
        return self.ack is not None and self.ack.status == 0


class VehicleObserver:
    """See the module docstring."""

    def __init__(self, profile: Profile, ledger: Ledger, *, time_scale: float = 1.0,
                 baud: Optional[int] = None, resolution: float = 1e-6, catalog=None):
        self.profile = profile
        self.ledger = ledger
        self.k = float(time_scale)
        self.res = resolution
        self.baud = baud if baud is not None else profile.baud
        self.missions = GivenMissions(catalog) if catalog is not None else KnownMissions(profile)
        self.beliefs = Beliefs(profile, self.missions, self.k)
        self.out = OutputJudge(ledger, profile)
        self.framers = {TO_VEHICLE: Framer(profile.max_line_bytes),
                        FROM_VEHICLE: Framer(max(4096, 4 * profile.max_line_bytes))}
        self.pending: deque[Sent] = deque()
        self.silent: deque[Sent] = deque()
        self.gave_up: deque[Sent] = deque(maxlen=64)
        self.dead: list[Sent] = []  #: missing while the vehicle said nothing at all (yet)
        self.quiet: list[Sent] = []  #: discarded lines waiting for proof the vehicle listens
        self.last_osd: Optional[Sent] = None
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
        self._decoded: dict = {}
        self.closed = False
        self.aborted = ""
        #: (mode before, command ID) of every accepted control command in a remote mode (coverage)
        self.interrupt_pairs: set = set()

    # ------------------------------------------------------------------ helpers
    def v(self, t: float) -> float:
        """Vehicle seconds at wall time ``t`` (RH-TIM-2)."""
        return self.k * t

    def slack_v(self) -> float:
        """What every observation of this record cannot see: jitter and the timestamp step."""
        return self.k * (JITTER_S + self.res)

    def book(self, verdict: str, candidates: tuple[str, ...], reason: str, evidence=(),
             at: Optional["Sent"] = None) -> None:
        """Book a finding on :func:`~.blame.targets` of ``candidates``, in the case context of
        ``at`` (the line it is about) or the present one."""
        case, clauses = (at.case, at.case_clauses) if at is not None else (self.case, self.case_clauses)
        if case and verdict != "pass":
            reason = f"{case}: {reason}"
        for cid in targets(candidates, clauses):
            if verdict == "fail":
                self.ledger.failed(cid, reason, evidence, case)
            elif verdict == "inconclusive":
                self.ledger.inconclusive(cid, reason, evidence, case)
            else:
                self.ledger.passed(cid, reason, evidence, case)

    def passed(self, clauses, reason: str, evidence=()) -> None:
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
        elif ev.dir == NOTE:
            self._note(ev)

    def _frame(self, d: str, data: bytes):
        """The framer's events for ``data``; a record that is one whole line skips the framer."""
        fr = self.framers[d]
        if (not fr.pending and data[:1] == b"$" and data.count(b"$") == 1 and data.find(b"\n") == len(data) - 1
                and len(data) <= fr.max_line):
            return (Line(data, 0),)
        return fr.feed(data)

    def decode(self, raw: bytes):
        """:func:`~helmcheck.grammar.decode` with a bounded cache (sessions repeat their lines)."""
        hit = self._decoded.get(raw)
        if hit is None:
            if len(self._decoded) >= 4096:
                self._decoded.clear()
            hit = self._decoded[raw] = decode(raw, self.profile)
        return hit

    def _evidence(self, ev: WireEvent, raw: bytes, direction: str) -> Evidence:
        if raw.endswith(b"\r\n") and b"\n" not in raw[:-1]:
            return Evidence(ev.t, direction, escape(raw[:-2]), ev.lineno)
        return Evidence(ev.t, direction + "~", escape(raw[:200]), ev.lineno)

    def _note(self, ev: WireEvent) -> None:
        n = parse_note(ev.note)
        if n is None:
            return
        if n.kind == "case":
            self.case, self.case_clauses = n.case, n.clauses
        elif n.kind == "case-end":
            self.case, self.case_clauses = "", ()
        elif n.kind in ("not-tested", "inconclusive"):
            for cid in n.clauses:
                if n.kind == "not-tested":
                    self.ledger.not_tested(cid, n.text, self.case)
                else:
                    self.ledger.inconclusive(cid, n.text, [Evidence(ev.t, "!", ev.note, ev.lineno)], self.case)
        elif n.kind == "link":
            self.link_baud = n.value
            self.baud = n.value  # the line's rate as the tester opened it: what transmit times use
        elif n.kind == "aborted":
            self.aborted = n.text
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
            for c in self.beliefs.cands:
                c.model.plant(event, max(v, c.model.now or 0.0))
                c.drain()
            self.event(ev.t, "lockout" if isinstance(event, P.SafetyViolation) else "note", ev.note[:80])

    # ------------------------------------------------------------------ backseat lines
    def _backseat(self, fe, ev: WireEvent) -> None:
        if isinstance(fe, Discard):
            k = classify(None, fe.raw, self.profile, fe.clause)
            raw = fe.raw
            self.after_discard = True
        else:
            raw = fe.raw
            k = classify(self.decode(raw), raw, self.profile)
            if self.after_discard and k.kind in ("command", "error") and not k.variant:
                k = Kind(k.kind, k.item, k.ack_type, variant="RH-FRM-7")
            self.after_discard = False
        self.seq += 1
        sent = Sent(self.seq, ev.t, raw, self._evidence(ev, raw, ">"), k, self.case, self.case_clauses,
                    self.vbytes)
        self.sent.append(sent)
        if k.kind in ("command", "error"):
            if self.first_command_t is None:
                self.first_command_t = ev.t
            self.pending.append(sent)  # it goes into the mirror at its ACK (RH-RD-15)
        elif k.kind == "oxflt":
            sent.state = "silent"
            self.silent.append(sent)
            self.beliefs.command(k.item, self.v(ev.t), self.slack_v(), [])
            self.checks.oxflt_sent(k.item.code, ev.t)  # type: ignore[union-attr]
            self.event(ev.t, "lockout", f"$OXFLT,{k.item.code} sent")  # type: ignore[union-attr]
        else:
            sent.state = "silent"
            self.silent.append(sent)

    # ------------------------------------------------------------------ vehicle lines
    def _vehicle(self, fe, ev: WireEvent) -> None:
        if isinstance(fe, Discard):
            self.out.discard(fe.raw, fe.length, fe.clause, self._evidence(ev, fe.raw, "<"), self.case)
            return
        d = self.decode(fe.raw)
        evd = self._evidence(ev, fe.raw, "<")
        sent = self.out.line(d, evd, self.case)
        if sent is not None:
            self.alive_t = ev.t
            self._revive(ev.t)
            if self.link_baud is not None:
                self.ledger.passed("RH-FRM-9", f"sentences read and answered at {self.link_baud} baud 8N1 "
                                               f"as the tester opened the line", [evd], self.case)
        if isinstance(sent, s.ACK):
            self._ack(sent, ev.t, evd)
        elif sent is not None:
            self._data(sent, type(sent).__name__, ev.t, evd)
        elif d.sentence_id in _DATA_OF.values() or d.sentence_id in ("OSI", "C", "GPRMC", "OPI", "DVL",
                                                                      "OYSI", "OCTD", "OINS"):
            self._data(None, _class_of_id(d.sentence_id), ev.t, evd)

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
        p = next((q for q in self.pending if q.kind.ack_type == 8), None)
        if p is not None:
            self._processed(p, t)
        if p is None:
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

    # ------------------------------------------------------------------ ACK pairing
    def _ack(self, a: s.ACK, t: float, evd: Evidence) -> None:
        if a.type in _UNSOLICITED:
            self.ledger.passed("RH-ACK-1", "an unsolicited $ACK of its own type", [evd], self.case)
            return
        # the oldest waiting command of its type keeps the order; one the ACK of a later command
        # already overtook is matched only when no other waits (then it is out of order, RH-ACK-6)
        idx = next((i for i, p in enumerate(self.pending) if p.kind.ack_type == a.type and not p.overtaken),
                   None)
        if idx is None:
            idx = next((i for i, p in enumerate(self.pending) if p.kind.ack_type == a.type), None)
        if idx is not None:
            p = self.pending[idx]
            self._processed(p, t)
            del self.pending[idx]
            for i in range(idx):  # still waiting: an ACK that comes is out of order, none is missing
                self.pending[i].overtaken = True
            if p.overtaken:
                self.book("fail", ("RH-ACK-6",), f"$ACK,{a.type} for {_text(p)} came after the ACK of a "
                                                 f"later command (ACKs out of order)", [p.ev, evd], at=p)
            elif idx == 0:
                self.ledger.passed("RH-ACK-6", "ACKs in command order", [p.ev, evd], p.case)
            self._answered(p, a, t, evd, late=False)
            return
        late = next((q for q in self.gave_up if q.kind.ack_type == a.type and q.ack is None), None)
        if late is not None:
            self.gave_up.remove(late)
            self._answered(late, a, t, evd, late=True)
            return
        silent = next((q for q in reversed(self.silent)
                       if q.kind.kind != "oxflt" and q.kind.would_be in (a.type, None)), None)
        oxflt = next((q for q in reversed(self.silent) if q.kind.kind == "oxflt"), None)
        if oxflt is not None and silent is None:
            oxflt.state, oxflt.ack = "answered-discard", a
            self.silent.remove(oxflt)
            self.book("fail", ("RH-SAF-5",), f"$ACK,{a.type},{a.status},{a.err} answered $OXFLT, which gets "
                                             f"no ACK", [oxflt.ev, evd], at=oxflt)
            return
        if silent is not None:
            silent.state, silent.ack = "answered-discard", a
            self.silent.remove(silent)
            self.book("fail", (silent.kind.clause,), f"{_text(silent)} must be discarded silently "
                                                     f"({silent.kind.clause}); the vehicle answered "
                                                     f"$ACK,{a.type},{a.status},{a.err}", [silent.ev, evd],
                      at=silent)
            return
        if self.first_command_t is None:
            self.ledger.inconclusive("RH-ACK-1", "an $ACK before the first command of the record (its "
                                                 "command may predate it)", [evd], self.case)
            return
        self.book("fail", ("RH-ACK-1",), f"$ACK,{a.type},{a.status},{a.err} answers no command waiting "
                                         f"for one (a second ACK, or one for a line never sent)", [evd])

    def _answered(self, p: Sent, a: s.ACK, t: float, evd: Evidence, late: bool) -> None:
        p.state, p.ack, p.t_ack = "answered", a, t
        ev = [p.ev, evd]
        replies = self.vbytes - p.vbytes0
        allowance = ack_allowance(self.profile.ack_window_s, len(p.raw), replies, self.baud, self.res)
        dt = t - p.t
        if late and p.late_booked:
            pass  # RH-ACK-2 was booked when the give-up deadline passed
        elif late or dt > ack_fail_after(allowance):
            self.book("fail", ("RH-ACK-2",), f"$ACK,{a.type} came {dt:.2f} s after {_text(p)}; the window with "
                                             f"transmit time is {allowance - ACK_GRACE_S:.2f} s", ev, at=p)
        elif dt > allowance:
            self.ledger.inconclusive("RH-ACK-2", f"an $ACK came {dt:.2f} s after its command, over the "
                                                 f"{allowance:.2f} s allowed by a margin host load can explain",
                                     ev, self.case)
        elif self.res > self.profile.ack_window_s / 10:
            self.ledger.inconclusive("RH-ACK-2", f"timestamps step {self.res:g} s cannot bound a "
                                                 f"{self.profile.ack_window_s:g} s window (RH-TIM-1)", ev, self.case)
        else:
            self.ledger.passed("RH-ACK-2", f"$ACK within {dt:.3f} s (allowed {allowance:.3f} s)", ev, self.case)
        if not late:
            self.ledger.passed("RH-ACK-1", "one $ACK of its own type", ev, self.case)
        observed = [cls for _, cls, _ in p.data] + [a]
        if p.branched:  # already in the mirror, unanswered: judge the late answer's content only
            self._late_answer(p, a, observed, ev)
            return
        v_ack = self.v(t)
        res = self.beliefs.command(p.kind.item, v_ack, self.k * (dt + JITTER_S + self.res), observed)
        p.expected = res.expected
        want = next((r for r in res.expected if isinstance(r, s.ACK)), None)
        p.negative = want is not None and want.status == 1
        if a.status:
            self.event(t, "ack-error", f"{_text(p)[:40]} → $ACK,{a.type},{a.status},{a.err}",
                       negative_test=bool(p.negative and res.matched))
        elif not isinstance(p.kind.item, s.OSD):
            self.event(p.t, "command", _text(p)[:60])
            if res.before[0] in ("A", "M", "mP", "W") and res.row is not None and res.row.target != "=":
                self.interrupt_pairs.add((res.before[0], p.kind.item.ID))
        cands = command_clauses(p.kind.item, want, res.row)
        if p.kind.variant:
            cands = (p.kind.variant,) + cands
        if res.matched:
            self._matched(p, a, res, cands, ev)
        else:
            if want is not None and want.status == 1 and a.status == 1 and want.err != 26:
                # refused, as it should be, with the wrong error number: RH-ACK-4 for a refused
                # precondition, else RH-ACK-3 (each command's own "incorrect values" error)
                first = "RH-ACK-4" if "RH-ACK-4" in cands else "RH-ACK-3"
                cands = (first,) + tuple(c for c in cands if c != first)
            what = (f"{_text(p)}: a conforming vehicle in mode {res.before[0]} answers "
                    f"{_brief(res.expected)}; got {_brief(observed)}")
            if res.desync:
                self.book("inconclusive", cands, f"{what} — not judged: the observer lost track of the "
                                                 f"vehicle's state before ({res.desync})", ev, at=p)
            else:
                self.book("fail", cands, what, ev, at=p)
        for tt, verdict, reason in res.timings:
            self._timing(tt, verdict, reason, ev)
        if p.kind.ack_type == 8:
            self.last_osd = p
            self._osd_data(p, a, ev)
        self.checks.answered(p, a, res, ev)

    def _late_answer(self, p: Sent, a: s.ACK, observed: list, ev: list) -> None:
        want = next((r for r in p.expected if isinstance(r, s.ACK)), None)
        if want is None or (want.status, want.err) == (a.status, a.err):
            return
        row = self.beliefs.primary.model.row_for(p.kind.item) if not hasattr(p.kind.item, "ack_err") else None
        self.book("inconclusive", command_clauses(p.kind.item, want, row),
                  f"{_text(p)} answered late, out of order, {_brief([a])}; a conforming vehicle answers "
                  f"{_brief([want])} — not judged: the state it met is not known", ev, at=p)

    def _matched(self, p: Sent, a: s.ACK, res, cands: tuple[str, ...], ev: list) -> None:
        if res.mission_dependent:
            self.book("inconclusive", cands, f"{_text(p)} answered {_brief([a])}: the answer depends on the "
                                             f"vehicle's mission files, which the observer does not have", ev,
                      at=p)
            return
        if res.adopted:
            for cid in cands[:1]:
                self.ledger.remark(cid, f"explained by an unseen event: {res.adopted[-1]}.")
        row = res.row
        if a.status:
            self.passed(passable(cands), f"{_text(p)} refused with $ACK,{a.type},1,{a.err} as a conforming "
                                         f"vehicle in mode {res.before[0]} does", ev)
            if a.err == 26:
                self.ledger.passed("RH-SAF-1" if res.before[1] == "lockout" else "RH-SAF-3",
                                   f"{_text(p)} refused with err 26", ev, self.case)
        elif row is not None and row.target == "=" and row.phase_to is None:
            self.passed(passable(cands), f"{_text(p)} accepted in mode {res.before[0]}", ev)
        elif p.kind.variant:
            self.passed((p.kind.variant,), f"{_text(p)} read and answered", ev)

    def _osd_data(self, p: Sent, a: s.ACK, ev: list) -> None:
        """RH-ACK-5, RH-OSD-1, RH-OSD-2 for an answered ``$OSD``."""
        got = [cls for _, cls, _ in p.data]
        if a.status:
            if got:
                self.book("fail", ("RH-OSD-2",), f"a refused $OSD carried {len(got)} data sentence(s)", ev, at=p)
            return
        want = [type(r).__name__ for r in p.expected if not isinstance(r, s.ACK)]
        if got == want:
            if want:
                self.ledger.passed("RH-ACK-5", "the data came before the $ACK,8", ev, self.case)
            self.ledger.passed("RH-OSD-1", f"{len(got)} data sentence(s) in request order", ev, self.case)
        elif len(got) < len(want) and got == want[:len(got)]:
            self.book("fail", ("RH-ACK-5", "RH-OSD-1"), f"$ACK,8 came before all its data: got "
                                                       f"{_names(got)}, expected {_names(want)}", ev, at=p)
        else:
            self.book("fail", ("RH-OSD-1",), f"$OSD answered {_names(got)}; expected {_names(want)} "
                                             f"in request order", ev, at=p)

    # ------------------------------------------------------------------ $OSI
    def _osi(self, osi: s.OSI, p: Sent, t: float, evd: Evidence) -> None:
        """RH-OUT-4 and the clauses of what led to the reported state."""
        ev = [p.ev, evd]
        self.last_osi, self.last_osi_t = osi, t
        self.mode_seen(t, osi.mode)
        res = self.beliefs.osi(osi, self.v(p.t), self.v(t), self.slack_v())
        if res.findings:
            cands = ("RH-OUT-4",) + tuple(c for c in res.causes if c != "RH-OUT-4") + self.checks.recent()
            msg = res.findings[0][1]
            if res.desync:
                self.book("inconclusive", cands, f"{msg} — not judged: the observer lost track of the "
                                                 f"vehicle's state before ({res.desync})", ev, at=p)
            else:
                self.book("fail", cands, msg, ev, at=p)
            self.checks.after_osi(osi, p, t, ev, judged=False)
            return
        self.ledger.passed("RH-OUT-4", f"mode {osi.mode}, waypoint {osi.next_waypoint}, P{osi.park_time}, "
                                       f"error {osi.error_state} as a conforming vehicle reports", ev, self.case)
        if res.adopted:
            self.ledger.remark("RH-OUT-4", f"unseen events were adopted to explain reports, e.g. {res.adopted[-1]}.")
        self.passed(passable(res.passes), f"seen to take effect: $OSI mode {osi.mode}", ev)
        for cid in sorted(res.own):
            self.ledger.passed(cid, _OWN_REASON[cid], ev, self.case)
        for tt, verdict, reason in res.timings:
            self._timing(tt, verdict, reason, ev)
        self.checks.after_osi(osi, p, t, ev, judged=True, passes=res.passes)

    def _timing(self, tt, verdict: str, reason: str, ev: list) -> None:
        """RH-TIM-1 (and the timer's clause) from a transition's bracket."""
        clauses = tt.clauses + ("RH-TIM-1", "RH-TIM-2")
        for cid in clauses:
            if verdict == "pass":
                text = reason if cid != "RH-TIM-2" else f"{reason} at the declared time scale {self.k:g}"
                self.ledger.passed(cid, text, ev, self.case)
            elif verdict == "not-tested":
                self.ledger.not_tested(cid, reason, self.case)
            else:
                self.ledger.inconclusive(cid, reason, ev, self.case)

    # ------------------------------------------------------------------ time
    def _advance(self, t: float) -> None:
        """Time passed (the next event's time): windows and waits that have run out."""
        if t < self.t:
            t = self.t
        self.t = t
        while self.silent and self._silent_over(self.silent[0], t):
            q = self.silent.popleft()
            self._silence_kept(q)
        for p in list(self.pending):
            allowance = ack_allowance(self.profile.ack_window_s, len(p.raw), self.vbytes - p.vbytes0,
                                      self.baud, self.res)
            if t - p.t > ack_fail_after(allowance):
                self.pending.remove(p)
                self._missing(p, allowance)
        if self.gave_up:
            self._give_up(t)

    def _silent_over(self, q: Sent, t: float) -> bool:
        allowance = ack_allowance(self.profile.ack_window_s, len(q.raw), 0, self.baud, self.res)
        return t - q.t > allowance

    def _silence_kept(self, q: Sent) -> None:
        """RH-FRM-2/4/5/6/7: no answer within the window — passed once the vehicle is seen to be
        listening (it answers something after the line)."""
        if q.kind.kind == "oxflt":
            return
        if self.alive_t is not None and self.alive_t >= q.t:
            self.ledger.passed(q.kind.clause, f"{_text(q)} was discarded silently ({q.kind.clause})",
                               [q.ev], q.case)
        else:
            self.quiet.append(q)

    def _missing(self, p: Sent, allowance: float) -> None:
        """Past the give-up deadline unanswered. RH-ACK-2 is certain now (whatever comes later is
        too late); RH-ACK-1 only once its ACK can no longer come: :data:`GIVE_UP_S` after it was
        sent, or at the record's end — an ACK that comes before that belongs to it (RH-ACK-2),
        never to a later command."""
        p.state = "missing"
        p.waited = ack_fail_after(allowance)
        self.gave_up.append(p)
        if self.alive_t is not None and self.alive_t > p.t:
            self._book_late(p)
        else:
            self.dead.append(p)

    def _book_late(self, p: Sent) -> None:
        cands = ((p.kind.variant,) if p.kind.variant else ()) + ("RH-ACK-2",)
        self.book("fail", cands, f"{_text(p)}: no $ACK,{p.kind.ack_type} within {p.waited:.1f} s, though "
                                 f"the vehicle still answers (the window is {self.profile.ack_window_s:g} s)",
                  [p.ev], at=p)
        p.late_booked = True

    def _book_missing(self, p: Sent) -> None:
        if not p.late_booked:
            self._book_late(p)
        cands = ((p.kind.variant,) if p.kind.variant else ()) + ("RH-ACK-1",)
        self.book("fail", cands, f"{_text(p)}: no $ACK,{p.kind.ack_type} at all, though the vehicle still "
                                 f"answers", [p.ev], at=p)

    def _give_up(self, t: float) -> None:
        """RH-ACK-1 for what is unanswered :data:`GIVE_UP_S` after it was sent."""
        for p in list(self.gave_up):
            if p.ack is None and not p.missing_booked and t - p.t > GIVE_UP_S and p.late_booked:
                p.missing_booked = True
                self._book_missing(p)

    def _revive(self, t: float) -> None:
        for p in self.dead:
            self._book_late(p)
        self.dead.clear()
        for q in self.quiet:
            self._silence_kept(q)
        self.quiet.clear()

    def close(self) -> None:
        """The record ended (at the last event's time)."""
        if self.closed:
            return
        self.closed = True
        t = self.t
        for fe in self.framers[TO_VEHICLE].close():
            self._backseat(fe, WireEvent(t, TO_VEHICLE, b"", "", 0))
        while self.silent:
            q = self.silent.popleft()
            if self._silent_over(q, t):
                self._silence_kept(q)
        for p in self.pending:
            self.ledger.inconclusive("RH-ACK-1", f"the record ended {t - p.t:.2f} s after {_text(p)}, inside "
                                                 f"its ACK window", [p.ev], p.case)
        for p in self.dead:
            self.ledger.inconclusive("RH-ACK-1", f"{_text(p)}: no $ACK, and the vehicle said nothing at all "
                                                 f"afterwards (a link fault?)", [p.ev], p.case)
        for p in self.gave_up:
            if p.ack is None and p.late_booked and not p.missing_booked:
                p.missing_booked = True
                self._book_missing(p)
        self.checks.close()
        if self.aborted:
            for cid in self.ledger.order:
                if not self.ledger.judged(cid):
                    self.ledger.inconclusive(cid, f"not judged: the run ended early ({self.aborted})")


def _class_of_id(sid: Optional[str]) -> str:
    return {"C": "Compass"}.get(sid or "", sid or "?")


def _text(p: Sent) -> str:
    return escape(p.raw.rstrip(b"\r\n"))[:80]


def _brief(replies: list) -> str:
    out = []
    for r in replies:
        if isinstance(r, s.ACK):
            out.append(f"$ACK,{r.type},{r.status},{r.err}")
        else:
            out.append("$" + (r if isinstance(r, str) else type(r).__name__))
    return ", ".join(out) or "nothing"


def _names(xs: list) -> str:
    return ",".join("$" + x for x in xs) or "none"
