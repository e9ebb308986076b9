"""What the vehicle answered: ACK pairing, the command's effect, and every ``$OSI`` judged.

:class:`Answers` is the part of :class:`~helmcheck.judge.vehicle.observer.VehicleObserver` that
judges replies, split out to keep one concern per module; it works on the observer's own state
(``pending``, ``silent``, ``gave_up``, ``beliefs``, ``checks``, the ledger) and is never used alone.

* **ACK pairing** (RH-ACK-1, RH-ACK-6): the oldest waiting command of the ACK's type takes it;
  one that a later command's ACK overtook is matched only when no other waits. An ACK after the
  give-up deadline belongs to its late command (RH-ACK-2); one answering a line that must be
  discarded fails that line's clause (RH-FRM-2/4/5/6/7, RH-SAF-5 for ``$OXFLT``) — for a line of
  an unknown ID (RH-FRM-5) an ACK of any type, or one whose fields do not decode, is an answer.
* **The ACK window** (RH-ACK-2, :func:`~helmcheck.judge.timing.ack_allowance`; an ACK later
  than the window, transmit time and the observer's own uncertainty is a FAIL), the answer
  against the mirror (:mod:`.belief`), and ``$OSD``'s data before its ACK (RH-ACK-5, RH-OSD-1).
  Decision (the profile is silent): a line a tester sent after opening the link (its ``link:``
  note) and before the vehicle had answered anything — the link check's probe of a vehicle still
  starting up — is not timed, nor missed (:attr:`~.sent.Sent.first_contact`): the link check waits
  for the vehicle to answer at all. A capture's first lines are judged like any other.
* **A faulty line** (module :mod:`.observer`, "a faulty line"): an answer whose replies the line
  may have spoilt (a broken run came while it waited), or that came later than its window (a
  stall of the line can hold it), is *held*: what it would book goes to the repetition rule
  (:mod:`helmcheck.judge.streaks`) under the command, which decides when it is sent again; an
  answer in full and on time with nothing spoilt makes what was held for that command (and the
  replies held for its earlier sendings) the line's.
* **Every** ``$OSI`` against the mirror (RH-OUT-4 and the clauses of what led there, attributed by
  :mod:`.blame`), the timers it brackets (RH-TIM-1/2), and the checks beyond the mirror
  (:mod:`.osichecks`).
"""

from __future__ import annotations

from typing import Optional

from ...grammar import sentences as s
from ...grammar.wirelog import escape
from ...model.readings import BY_KEY as _READINGS
from ...model.timers import tolerance
from ..ledger import Evidence
from ..spoil import REPEAT
from ..streaks import OTHER_REPEAT
from ..timing import ack_allowance, ack_uncertainty, ack_verdict, transmit_time
from .blame import command_clauses, looked_up, passable, stated_by
from .sent import Sent, brief, names, text_of

__all__ = ["Answers", "UNSOLICITED", "OWN_REASON"]

#: ACK types a vehicle sends unasked (RH-ACK-1).
UNSOLICITED = (13, 14)
OWN_REASON = {"RH-INT-3": "after the control that interrupted an $OPK park ended, the mission resumed, "
                          "not the park",
              "RH-OMW-5": "after the control that interrupted the $OMW queue ended, the mission resumed, "
                          "not the queue",
              "RH-SAF-2": "the commands refused during the lockout had no effect after it"}


def reading_clause(taken: str) -> str:
    """The clause of a reading taken (``key = value``)."""
    r = _READINGS.get(taken.split(" = ")[0])
    return r.clause if r is not None else "a reading"


class Answers:
    """ACK pairing and ``$OSI`` judging (module docstring); a base of the vehicle observer."""

    # ------------------------------------------------------------------ ACK pairing
    def _ack(self, a: s.ACK, t: float, evd: Evidence) -> None:
        if a.type in UNSOLICITED:
            self.ledger.passed("RH-ACK-1", "an unsolicited $ACK of its own type", [evd], self.case)
            return
        # the oldest waiting command of its type keeps the order; one the ACK of a later command
        # already overtook is matched only when no other waits (then it is out of order, RH-ACK-6)
        idx = first = None
        for i, q in enumerate(self.pending):
            if q.kind.ack_type == a.type:
                if not q.overtaken:
                    idx = i
                    break
                if first is None:
                    first = i
        if idx is None:
            idx = first
        if idx is not None:
            p = self.pending[idx]
            self._processed(p, t)
            del self.pending[idx]
            for i in range(idx):  # still waiting: an ACK that comes is out of order, none is missing
                self.pending[i].overtaken = True
            for q in self.gave_up:  # given up on, sent before it: an ACK that still comes came after
                if q.ack is None and q.seq < p.seq:
                    q.overtaken = True
            if p.overtaken:
                self.book("fail", ("RH-ACK-6",), f"$ACK,{a.type} for {text_of(p)} came after the ACK of a "
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
        if self._discard_answered(a.type, f"$ACK,{a.type},{a.status},{a.err}", a, evd):
            return
        if self.first_command_t is None:
            self.ledger.inconclusive("RH-ACK-1", "an $ACK before the first command of the record (its "
                                                 "command may predate it)", [evd], self.case)
            return
        self.book("fail", ("RH-ACK-1",), f"$ACK,{a.type},{a.status},{a.err} answers no command waiting "
                                         f"for one (a second ACK, or one for a line never sent)", [evd])

    def _discard_answered(self, ack_type, text: str, a, evd: Evidence) -> bool:
        """An ``$ACK`` (``text``; ``ack_type`` None when unreadable) no waiting command takes: does
        it answer a line the vehicle must discard? Then that line's clause fails (RH-FRM-2/4/5/6/7;
        RH-SAF-5 for ``$OXFLT``), whatever else is wrong with the answer. A line of an ID the
        vehicle does not know (RH-FRM-5) has no ACK type of its own: an ACK of any type answers it."""
        silent = next((q for q in reversed(self.silent)
                       if q.kind.kind != "oxflt" and q.kind.would_be in (ack_type, None)), None)
        oxflt = next((q for q in reversed(self.silent) if q.kind.kind == "oxflt"), None)
        if oxflt is not None and silent is None:
            oxflt.state, oxflt.ack = "answered-discard", a
            self.silent.remove(oxflt)
            self.book("fail", ("RH-SAF-5",), f"{text} answered $OXFLT, which gets no ACK", [oxflt.ev, evd],
                      at=oxflt)
            return True
        if silent is None:
            silent = next((q for q in reversed(self.silent)
                           if q.kind.kind == "discard" and q.kind.clause == "RH-FRM-5"), None)
        if silent is None:
            return False
        silent.state, silent.ack = "answered-discard", a
        self.silent.remove(silent)
        self.book("fail", (silent.kind.clause,), f"{text_of(silent)} must be discarded silently "
                                                 f"({silent.kind.clause}); the vehicle answered {text}",
                  [silent.ev, evd], at=silent)
        return True

    def _invalid_ack(self, raw: bytes, evd: Evidence) -> bool:
        """A well-framed ``$ACK`` whose fields do not decode (``$ACK,0,1,0``: a type no command has).
        When no waiting command can own it and it answers a line the vehicle must discard, that
        line's clause fails (:meth:`_discard_answered`) and True is returned: the answer is that
        line's fault, not an output fault of its own. Otherwise False (judged as output)."""
        fields = raw.rstrip(b"\r\n").split(b"*", 1)[0].split(b",")
        try:
            ack_type = int(fields[1]) if len(fields) > 1 else None
        except ValueError:
            ack_type = None
        waiting = [q.kind.ack_type for q in self.pending] + [q.kind.ack_type for q in self.gave_up
                                                             if q.ack is None]
        if (ack_type is None and waiting) or ack_type in waiting:
            return False  # perhaps a waiting command's own ACK, malformed
        return self._discard_answered(ack_type, escape(raw.rstrip(b"\r\n")), None, evd)

    def _bound_oxflt(self, p: Sent, t_reply: float) -> None:
        """An ``$OXFLT`` raises its violation when the vehicle processes it (RH-SAF-5), which no
        answer shows: some time after it was sent and before the vehicle answers a line sent after
        it (RH-ACK-6: arrival order). The mirror takes it in at the first such answer, at the
        instant that answer went out (the latest it can have been), and every candidate carries the
        window since the send as uncertainty on the timers it started (the lockout, RH-SAF-1), as
        for an unseen event (:mod:`.closure`): a vehicle that answers every line late has its
        lockout timed from about when it began, whatever its latency."""
        if self.oxflt_open is None or p.seq < self.oxflt_open[1]:
            return
        self._apply_oxflt(t_reply)

    def _apply_oxflt(self, t_reply: float) -> None:
        """The pending ``$OXFLT`` into the mirror, taken in by ``t_reply`` (:meth:`_bound_oxflt`)."""
        t0, _, item = self.oxflt_open
        self.oxflt_open = None
        t1 = max(t0, t_reply)
        self.beliefs.command(item, self.v(t1), self.slack_v(), [])
        lo, hi = self.v(t0), self.v(t1)
        for c in self.beliefs.cands:
            c.extra_v = max(c.extra_v, hi - lo)
            c.window = (lo, hi)
            c.carried = c.carried | {"lockout"}

    def _answered(self, p: Sent, a: s.ACK, t: float, evd: Evidence, late: bool) -> None:
        p.state, p.ack, p.t_ack = "answered", a, t
        if late and p.held_item is not None:  # it did answer, late: no longer a lost answer (RH-ACK-1)
            p.held = [f for f in self.streaks.release(p.held_item) if f[0] != "RH-ACK-1"]
            p.held_item = None
            why = self._late_text(p, t - p.t)
            if why is None:  # a relay's record: the line did not hold it up
                for cid, reason, evidence, case in p.held:
                    self.ledger.failed(cid, reason, evidence, case)
                p.held = []
            p.late_text = why or ""
        p.holding = bool(p.spoils)  # a broken run came while it waited: what it leaves wrong is held
        try:
            on_time = self._answered_held(p, a, t, evd, late)
        finally:
            p.holding = False
        self._settle_held(p, on_time)

    def _settle_held(self, p: Sent, on_time: bool = True) -> None:
        """What an answered command's findings were held for goes to the repetition rule; an answer
        with nothing spoilt and nothing wrong makes the command's earlier sendings' held
        observations the line's (module docstring)."""
        if p.held and p.spoils:
            spoils = p.spoils
            known = next((text for text, _need, k, _sig in spoils if k), None)
            text = known or spoils[0][0]
            need = max(n for _t, n, _k, _sig in spoils)
            # the same error: the same clauses, and the same damage to the replies
            sig = ("cmd",) + tuple(sorted({f[0] for f in p.held})) + tuple(x[3] for x in spoils)
            self.hold_command(p, sig, text, need, known is not None)
        elif p.held:
            # late, nothing spoilt: a stall holds up what is sent during it, so an $ACK late is the
            # vehicle's when the one before it was late too and it was sent after that one came
            # back (the line seen flowing again), with no $ACK on time in between; the same
            # command answered on time later makes it the line's
            sig = ("late",) if p.t >= self.late_until else ("late", "held up with the one before", p.seq)
            self.late_until = max(self.late_until, p.t_ack or p.t)
            self.hold_command(p, sig, p.late_text, OTHER_REPEAT, False, key=("late",))
        elif on_time and not p.spoils:
            self.answered_clean(p)

    def answered_clean(self, p: Sent) -> None:
        """``p`` was answered in full and on time, nothing spoilt: its earlier sendings' held
        observations (and the replies held for them) were the line's."""
        self.clean_sendings[p.ident] = p.seq
        if len(self.clean_sendings) > 512:
            self.clean_sendings.pop(next(iter(self.clean_sendings)))
        if self.streaks:
            self.streaks.clean(("cmd", p.ident))
            if p.t >= self.late_until:  # sent after the last late one came back, answered on time:
                self.streaks.interrupt(("late",))  # late ones before it are not a run
            self.streaks.clean_owned(p.ident, p.mark)

    def hold_command(self, p: Sent, sig: tuple, text: str, need: int, known: bool,
                     key: Optional[tuple] = None) -> None:
        """What ``p``'s answer would book, held under the command (module docstring) — or
        dismissed at once when a later sending of it was already answered in full."""
        if key is None and self.clean_sendings.get(p.ident, 0) > p.seq:
            self.streaks.made_again(text, p.held)
            p.held = []
            return
        p.held_item = self.streaks.hold(key or ("cmd", p.ident), sig, text, p.held, need=need, known=known,
                                        owners=(p.ident,))
        p.held = []
        if p.held_item is not None:
            p.spoil = p.spoil or text

    def _may_answer_later(self, p: Sent, t: float) -> Optional[Sent]:
        """A later command of ``p``'s ``$ACK`` type, still waiting, that an ``$ACK`` at ``t`` came
        within the window of (RH-ACK-2): the line may have lost ``p`` (its own never came, RH-ACK-1)
        and this one answers that (a tester that sends without waiting, as the clock check does)."""
        for q in self.pending:
            if (q.seq > p.seq and q.kind.ack_type == p.kind.ack_type and q.t <= t
                    and t - q.t <= self.profile.ack_window_s):
                return q
        return None

    def _late_text(self, p: Sent, dt: float) -> Optional[str]:
        """Why an ``$ACK`` ``dt`` s late may be the line's (a stall held it), or None when it cannot
        be (a later command's ``$ACK`` came first: a stall delays everything, in order; or a relay's
        record shows the line did not hold it): then it is booked at once."""
        if p.overtaken:  # a later command was answered first: a stall holds the line up in order
            return None
        note = self.faults.held_between(p.t, p.t + dt)
        if note is not None:
            return f"the line held it (the relay's note: {note})"
        if self.faults.clean:
            return (f"an $ACK {dt:.2f} s after its command: the link is clean, but an implementation on a pty "
                    f"or local TCP shares this host's CPU, whose stall may have held it")
        if self.faults.instrumented:
            return None
        return f"an $ACK {dt:.2f} s after its command: a stall of the line (or of the host) may have held it"

    def _answered_held(self, p: Sent, a: s.ACK, t: float, evd: Evidence, late: bool) -> bool:
        """Judge the answer (module docstring); True when the ``$ACK`` came within its window."""
        ev = [p.ev, evd]
        replies = self.vbytes - p.vbytes0
        window = self.profile.ack_window_s
        allowance = ack_allowance(window, len(p.raw), replies, self.baud, self.res, self.jitter)
        dt = t - p.t
        verdict = "fail" if late else ack_verdict(dt, allowance, window, self.res, self.jitter)
        if p.first_contact and not late:
            pass  # the first answer of a vehicle not heard from yet (still starting): not timed
        elif late and p.late_booked:
            pass  # RH-ACK-2 was booked when the give-up deadline passed
        elif verdict == "fail":
            why = self._late_text(p, dt)
            later = None if why is not None and why.startswith("the line held") else self._may_answer_later(p, t)
            if later is not None:
                why = (f"the $ACK came {t - later.t:.2f} s after a later {text_of(later)}: the line may have lost "
                       f"{text_of(p)}, and the $ACK answers that one")
            if why is not None and not p.holding:
                p.holding, p.late_text = True, why
                if why.startswith("the line held") or later is not None:
                    p.spoils.append((why, REPEAT, later is None, ("late",) if later is None else ("lost",)))
            self.book("fail", ("RH-ACK-2",), f"$ACK,{a.type} came {dt:.2f} s after {text_of(p)}; allowed "
                                             f"{allowance:.2f} s: the {window:g} s window, "
                                             f"{transmit_time(len(p.raw) + replies, self.baud):.3f} s of transmit "
                                             f"time, {ack_uncertainty(self.res, self.jitter):.3f} s of observer "
                                             f"uncertainty", ev, at=p)
        elif verdict == "inconclusive":
            self.ledger.inconclusive("RH-ACK-2", f"an $ACK came {dt:.2f} s after its command: timestamps step "
                                                 f"{self.res:g} s cannot tell whether that was within the "
                                                 f"{window:g} s window (RH-TIM-1)", ev, self.case)
        elif self.ledger.keeps("RH-ACK-2", "pass", self.case):
            self.ledger.passed("RH-ACK-2", f"$ACK within {dt:.3f} s (allowed {allowance:.3f} s)", ev, self.case)
        else:
            self.ledger.passed("RH-ACK-2", "", (), self.case)  # counted; what is kept is full
        if not late:
            self.ledger.passed("RH-ACK-1", "one $ACK of its own type", ev, self.case)
        observed = [cls for _, cls, _ in p.data] + [a]
        if p.branched:  # already in the mirror, unanswered: judge the late answer's content only
            self._late_answer(p, a, observed, ev)
            return verdict == "pass" and not late
        if self.held is not None and not isinstance(p.kind.item, s.OSD):
            self._settle(None, False, [])  # another command before any report: both stay named
        # RH-RD-15: the command took effect the instant its ACK went out, which its arrival bounds
        # (less the replies' transmit time), however long the vehicle took to answer
        took = min(dt, transmit_time(replies, self.baud))
        self._bound_oxflt(p, t - took)
        res = self.beliefs.command(p.kind.item, self.k * (t - took), self.k * (took + self.jitter + self.res),
                                   observed)
        p.expected = res.expected
        want = next((r for r in res.expected if isinstance(r, s.ACK)), None)
        p.negative = want is not None and want.status == 1
        if a.status:
            self.event(t, "ack-error", f"{text_of(p)[:40]} → $ACK,{a.type},{a.status},{a.err}",
                       negative_test=bool(p.negative and res.matched))
        elif not isinstance(p.kind.item, s.OSD) and len(self.events) < 5000:
            self.event(p.t, "command", text_of(p)[:60])
            if res.before[0] in ("A", "M", "mP", "W") and res.row is not None and res.row.target != "=":
                self.interrupt_pairs.add((res.before[0], p.kind.item.ID))
        cands = command_clauses(p.kind.item, want, res.row, res.before[0], res.before[1])
        if p.kind.variant and a.status == 1 and (want is None or want.status == 0):
            # refused where a conforming vehicle accepts: the form it must still read (RH-FRM-2/3/6/7)
            # first; a wrong answer to a line it did read is about the command, not the form
            cands = (p.kind.variant,) + cands
        if res.matched:
            self._matched(p, a, res, cands, ev)
        else:
            if want is not None and want.status == 1 and a.status == 1 and want.err != 26:
                # refused, as it should be, with the wrong error number: RH-ACK-4 for a refused
                # precondition, else RH-ACK-3 (each command's own "incorrect values" error)
                first = "RH-ACK-4" if "RH-ACK-4" in cands else "RH-ACK-3"
                first = looked_up(p.kind.item, a.err) or first
                cands = (first,) + tuple(c for c in cands if c != first)
            what = (f"{text_of(p)}: a conforming vehicle in mode {res.before[0]} answers "
                    f"{brief(res.expected)}; got {brief(observed)}")
            # refused where a conforming vehicle accepts: on the clauses that name that behaviour
            stated = (stated_by(p.kind.item, a.err, res.row, res.before[1])
                      if a.status == 1 and want is not None and want.status == 0 else ())
            if res.desync:
                self.book("inconclusive", cands, f"{what} — not judged: the observer lost track of the "
                                                 f"vehicle's state before ({res.desync})", ev, at=p, stated=stated)
            elif res.ignored:  # or the command before it was not carried out: the next report says
                self._hold(p, cands, res.ignored, what, ev)
            else:
                self.book("fail", cands, what, ev, at=p, stated=stated)
        for tt, verdict, reason in res.timings:
            self._timing(tt, verdict, reason, ev)
        if p.kind.ack_type == 8:
            self.last_osd = p
            self._osd_data(p, a, ev)
        self.checks.answered(p, a, res, ev)
        return verdict == "pass" and not late

    def _late_answer(self, p: Sent, a: s.ACK, observed: list, ev: list) -> None:
        want = next((r for r in p.expected if isinstance(r, s.ACK)), None)
        if want is None or (want.status, want.err) == (a.status, a.err):
            return
        row = self.beliefs.primary.model.row_for(p.kind.item) if not hasattr(p.kind.item, "ack_err") else None
        self.book("inconclusive", command_clauses(p.kind.item, want, row),
                  f"{text_of(p)} answered late, out of order, {brief([a])}; a conforming vehicle answers "
                  f"{brief([want])} — not judged: the state it met is not known", ev, at=p)

    def _matched(self, p: Sent, a: s.ACK, res, cands: tuple[str, ...], ev: list) -> None:
        if res.mission_dependent:
            item = p.kind.item
            if not a.status and isinstance(item, s.OMSTART):
                names = {item.name} | ({item.srp} if item.srp else set())
                self.mission_shown.append((p, a, cands, ev, names))  # judged by the reports to come
                return
            self._mission_unknown(p, a, cands, ev)
            return
        if res.adopted:
            for cid in cands[:1]:
                self.ledger.remark(cid, f"explained by an unseen event: {res.adopted[-1]}.")
        if res.reading:
            p.reading = res.reading
            for taken in res.reading:  # named in the clause's reason at the end (observer.close)
                r = _READINGS.get(taken.split(" = ")[0])
                cid = r.books if r is not None and r.books else (cands[0] if cands else "")
                self.readings_shown.setdefault(taken.split(" = ")[0], (taken, cid, p.ev))
                if cid:
                    self.ledger.passed(cid, lambda: f"{text_of(p)} answered {brief([a])} as a conforming vehicle "
                                                    f"taking the reading {taken} does", ev, self.case)
        row = res.row
        if a.status:
            self.passed(passable(cands), lambda: f"{text_of(p)} refused with $ACK,{a.type},1,{a.err} as a conforming "
                                         f"vehicle in mode {res.before[0]} does", ev)
            if a.err == 26:
                self.ledger.passed("RH-SAF-1" if res.before[1] == "lockout" else "RH-SAF-3",
                                   f"{text_of(p)} refused with err 26", ev, self.case)
        elif row is not None and row.target == "=" and row.phase_to is None:
            self.passed(passable(cands), lambda: f"{text_of(p)} accepted in mode {res.before[0]}", ev)
        if p.kind.variant:  # answered as a conforming vehicle answers: the form was read (RH-FRM-2/3/6/7)
            self.passed((p.kind.variant,), lambda: f"{text_of(p)} read and answered", ev)

    def _mission_unknown(self, p: Sent, a: s.ACK, cands: tuple[str, ...], ev: list, why: str = "") -> None:
        self.book("inconclusive", cands, f"{text_of(p)} answered {brief([a])}: the answer depends on the "
                                         f"vehicle's mission files, which the observer does not have{why}", ev,
                  at=p)

    def _mission_seen(self, osi: s.OSI, evd: Evidence) -> None:
        """``$OMSTART`` by names the observer has no file for, accepted: the vehicle's own reports
        decide. Each mission it names seen running under that name (field 12, in any mode but
        ``S``) was on the vehicle, so accepting the start was right (RH-MSN-2); a start whose names
        are not all seen by the end of the record stays unjudged (:meth:`_mission_unshown`)."""
        if osi.mode == "S" or not osi.mission_name:
            return
        left = []
        for p, a, cands, ev, unseen in self.mission_shown:
            unseen = unseen - {osi.mission_name}
            if unseen:
                left.append((p, a, cands, ev, unseen))
                continue
            ran = " and ".join(sorted({p.kind.item.name} | ({p.kind.item.srp} if p.kind.item.srp else set())))
            for cid in passable(cands):
                self.ledger.passed(cid, f"{text_of(p)} accepted, and the vehicle was later seen running {ran} "
                                        f"(field 12): the mission files are on the vehicle", ev + [evd], p.case)
        self.mission_shown = left

    def _osd_data(self, p: Sent, a: s.ACK, ev: list) -> None:
        """RH-ACK-5, RH-OSD-1, RH-OSD-2 for an answered ``$OSD``."""
        got = [cls for _, cls, _ in p.data]
        if a.status:
            if got:
                self.book("fail", ("RH-OSD-2",), f"a refused $OSD carried {len(got)} data sentence(s)", ev, at=p)
            return
        want = [r if isinstance(r, str) else type(r).__name__ for r in p.expected if not isinstance(r, s.ACK)]
        if got == want:
            if want:
                self.ledger.passed("RH-ACK-5", "the data came before the $ACK,8", ev, self.case)
            self.ledger.passed("RH-OSD-1", lambda: f"{len(got)} data sentence(s) in request order", ev, self.case)
        elif len(got) < len(want) and got == want[:len(got)]:
            self.book("fail", ("RH-ACK-5", "RH-OSD-1"), f"$ACK,8 came before all its data: got "
                                                       f"{names(got)}, expected {names(want)}", ev, at=p)
        else:
            self.book("fail", ("RH-OSD-1",), f"$OSD answered {names(got)}; expected {names(want)} "
                                             f"in request order", ev, at=p)

    # ------------------------------------------------------------------ $OSI
    def _osi(self, osi: s.OSI, p: Sent, t: float, evd: Evidence) -> None:
        """RH-OUT-4 and the clauses of what led to the reported state."""
        ev = [p.ev, evd]
        if self.mission_shown:
            self._mission_seen(osi, evd)
        self.last_osi, self.last_osi_t = osi, t
        self.mode_seen(t, osi.mode)
        # the report shows the state the instant it was sent (RH-OUT-4), which its arrival bounds
        # less its own transmit time (RH-RD-15: the $OSD is processed as its ACK goes out)
        t_from = max(p.t, t - transmit_time(len(evd.text) + 2, self.baud))
        self._bound_oxflt(p, t_from)
        res = self.beliefs.osi(osi, self.v(t_from), self.v(t), self.slack_v())
        if self.held is not None:
            self._settle(res.ignored, not res.findings, ev)
        if res.findings:
            named = tuple(dict.fromkeys(c for c, _ in res.findings if c != "RH-OUT-4"))  # a field's own clause
            cands = (("RH-OUT-4",) + named + tuple(c for c in res.causes if c != "RH-OUT-4" and c not in named)
                     + self.checks.recent())
            msg = res.findings[0][1]
            if res.desync:
                self.book("inconclusive", cands, f"{msg} — not judged: the observer lost track of the "
                                                 f"vehicle's state before ({res.desync})", ev, at=p)
            else:
                self.book("fail", cands, msg, ev, at=p, stated=res.diagnosis)
            self.checks.after_osi(osi, p, t, ev, judged=False)
            return
        m = self.beliefs.primary.model
        if osi.mode == "P" and m.mode == "P" and osi.next_waypoint == m.mission_wp + 1:  # park_waypoint = next
            self.readings_shown.setdefault("park_waypoint", ("park_waypoint = next", "RH-OUT-4", evd))
        self.ledger.passed("RH-OUT-4", lambda: f"mode {osi.mode}, waypoint {osi.next_waypoint}, P{osi.park_time}, "
                                       f"error {osi.error_state} as a conforming vehicle reports", ev, self.case)
        if res.adopted:
            self.ledger.remark("RH-OUT-4", f"unseen events were adopted to explain reports, e.g. {res.adopted[-1]}.")
        self.passed(passable(res.passes), lambda: f"seen to take effect: $OSI mode {osi.mode}", ev)
        for cid in sorted(res.own):
            self.ledger.passed(cid, OWN_REASON[cid], ev, self.case)
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
                if tt.widened is not None:
                    self.ledger.precision(cid, tolerance(tt.duration), tt.widened, self.k)
            elif verdict == "not-tested":
                self.ledger.not_tested(cid, reason, self.case)
            else:
                self.ledger.inconclusive(cid, reason, ev, self.case)
