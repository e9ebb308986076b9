"""Driving a vehicle step by step and judging every reply against the mirrored model.

:class:`Session` is the one place that talks to the vehicle during a run. Its primitives are
what cases (:mod:`.cases`) and exploration (:mod:`.explore`) are made of:

* :meth:`Session.exchange` — send one line, collect replies up to its ``$ACK`` and judge them:
  exactly one ACK of the command's type (RH-ACK-1) within the ACK window plus transmit time
  (RH-ACK-2), data before the ACK (RH-ACK-5), no foreign ACK in between (RH-ACK-6), the ACK's
  status and error number equal to the model's (RH-ACK-3/4 and the command's own clauses), the
  data sentence kinds in request order (RH-OSD-1/2), every ``$OSI`` consistent with the model
  (RH-OUT-4). A line the vehicle must discard (RH-FRM-4/5/6/7) must get no ACK within the window.
* :meth:`Session.poll` — ``$OSD,S`` and the judged ``$OSI``.
* :meth:`Session.wait` and :meth:`Session.settle` — protocol time passing (scaled by k,
  RH-TIM-2), polled and judged all along; ``settle`` waits past a model timer's deadline plus
  the RH-TIM-1 tolerance widened by the measured slack, and reports INCONCLUSIVE when that
  slack is too large for the duration to be judged.
* :meth:`Session.mission_end` — poll until the running mission ends (RH-MSN-4), within a bound
  derived from the time left, distance and speed the vehicle reports, or a fixed cap.
* :meth:`Session.reset` — the verified reset between cases: ``$OMSTOP,0`` (waiting out a
  lockout), ``$OSI`` shows ``S``; then the profile's mission started by name with the rh5 form
  ``$OMSTART,0,0,0,0,<mission>,`` and ``N`` verified.

Every received line is also checked on its own (RH-FRM-1/2/3/8, RH-OUT-1/2/3). Lines that are not
well-framed cannot be attributed (line noise looks the same) and count as garbage; a link that
carries only garbage, or nothing, is a link fault (INCONCLUSIVE).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Optional

from ...grammar import Framer, Line, SentenceError, checksum_hex, decode
from ...grammar import sentences as s
from ...grammar.capture import escape
from ...model.timers import tolerance
from ...model.transitions import REMOTE_MODES
from ...profile import Profile
from .judge import Book, CaseFail, CaseInconclusive, CaseNotTested
from .link import LinkLost, Rx, TesterLink
from .mirror import Mirror, same_replies

__all__ = ["Session", "Exchange", "LinkSilent", "frame", "ACK_GRACE_S", "END_MARGIN_V"]

#: Wall seconds of host jitter allowed on top of the ACK window and transmit time (RH-ACK-2).
ACK_GRACE_S = 0.25
#: Vehicle seconds added to twice the time a vehicle says its mission has left (RH-MSN-4).
END_MARGIN_V = 60.0
_KN = 1852.0 / 3600.0
_INTERRUPTS = ("OMS", "OMP", "OPK", "OMW", "OJW")
_UNSOLICITED_ACKS = (13, 14)


class LinkSilent(LinkLost):
    """The vehicle stopped answering anything at all (a link fault, INCONCLUSIVE)."""


def frame(body: str, lowercase: bool = False, terminator: str = "\r\n") -> bytes:
    """``$body*HH`` + terminator with the body's checksum (RH-FRM-1/2)."""
    raw = body.encode("latin-1")
    cks = checksum_hex(raw)
    return b"$" + raw + b"*" + (cks.lower() if lowercase else cks).encode() + terminator.encode()


@dataclass
class Exchange:
    """One command and what came back."""

    raw: bytes
    item: object
    t_sent: float
    t_ack: Optional[float] = None
    ack: Optional[s.ACK] = None
    data: list = field(default_factory=list)
    expected: list = field(default_factory=list)
    osi: Optional[s.OSI] = None

    @property
    def accepted(self) -> bool:
        return self.ack is not None and self.ack.status == 0


def _ack_text(a) -> str:
    if a is None:
        return "no $ACK"
    extra = "".join("," + x for x in a.extra)
    return f"$ACK,{a.type},{a.status},{a.err}{extra}"


def _replies_text(replies: list) -> str:
    if not replies:
        return "nothing (a silent discard)"
    return ", ".join(_ack_text(r) if isinstance(r, s.ACK) else "$" + r.ID for r in replies)


class Session:
    """One tester session on one link. See the module docstring."""

    def __init__(self, link: TesterLink, profile: Profile, time_scale: float, book: Book,
                 recorder=None):
        self.link = link
        self.profile = profile
        self.k = float(time_scale)
        self.book = book
        self.rec = recorder
        self.mirror = Mirror(profile, self.k)
        self.case = ""
        self.case_t0 = 0.0
        self.last_osi: Optional[s.OSI] = None
        self.last_osi_t = 0.0
        self.poll_gap = max(0.02, min(0.25, 1.0 / self.k))
        self.forced_wait = 0.0  #: wall seconds spent waiting for protocol durations
        self.garbage_reported = 0
        self.trace: Optional[list] = None  #: replay steps while recording
        self.lazy_silence = False  #: do not sit out the ACK window after a discarded line
        self.last_slack = 0.0  #: vehicle seconds of uncertainty of the last judged $OSI
        self.on_poll: Optional[Callable[[], None]] = None

    # ================================================================ helpers
    def now(self) -> float:
        return self.link.now()

    def evidence(self, t0: Optional[float] = None) -> list:
        return self.link.excerpt(self.case_t0 if t0 is None else t0, self.now())

    def fail(self, clause: str, reason: str, also=()) -> CaseFail:
        return CaseFail(clause, reason, self.case_t0, also)

    def _trace(self, step: dict) -> None:
        if self.trace is not None:
            self.trace.append(step)

    # ================================================================ per-line checks
    def _judge_line(self, rx: Rx) -> None:
        """RH-FRM-1/2/3/8, RH-OUT-1/2/3 for one line the vehicle sent."""
        d = rx.decoded
        if d is None or (d.error is not None and d.error.clause in ("RH-FRM-1", "RH-FRM-2", "RH-FRM-4",
                                                                     "RH-FRM-5", "RH-FRM-6", "RH-FRM-7")):
            self.garbage_reported += 1
            return
        ev = [{"t": round(rx.t, 6), "dir": "<", "line": escape(rx.raw.rstrip(b"\r\n"))}]
        if d.error is not None:
            self.book.add(d.error.clause, "fail", f"the vehicle sent an invalid {d.sentence_id or 'line'}: "
                                                  f"{d.error}", self.case, ev)
            return
        for f in d.findings:
            if f.clause == "RH-FRM-3":
                self.book.add("RH-FRM-3", "fail", f"the vehicle emitted lower-case checksum hex: {f.message}",
                              self.case, ev)
            elif f.clause == "RH-FRM-7":
                self.book.add("RH-FRM-1", "fail", "the vehicle ended a sentence with a bare LF, not CR LF",
                              self.case, ev)
        if not d.findings:
            self.book.ok("RH-FRM-1")
            self.book.ok("RH-FRM-2")
            self.book.ok("RH-FRM-3")
        sent = d.sentence
        if isinstance(sent, s.OSI):
            self.book.ok("RH-OUT-1")
        elif isinstance(sent, s.Compass):
            self.book.ok("RH-FRM-8")
        if not isinstance(sent, s.ACK):
            self.book.ok("RH-OUT-3")
            if not isinstance(sent, s.OSI):
                self.book.ok("RH-OUT-2")

    def _unsolicited(self, rxs: list[Rx]) -> None:
        for rx in rxs:
            self._judge_line(rx)
            sent = rx.sentence
            if isinstance(sent, s.ACK) and sent.type not in _UNSOLICITED_ACKS:
                raise self.fail("RH-ACK-1", f"an $ACK,{sent.type} arrived that answers no pending command "
                                            f"(a second ACK for one command, or a late one)")

    # ================================================================ exchange
    def item_of(self, raw: bytes):
        """What a conforming vehicle reads from ``raw``: a command, an answered error, or None.

        ``raw`` is cut into lines as a conforming vehicle does (RH-FRM-6/7); the last line counts.
        """
        lines = [e.raw for e in Framer(self.profile.max_line_bytes).feed(raw) if isinstance(e, Line)]
        if not lines:
            return None
        d = decode(lines[-1], self.profile)
        if d.sentence is not None and isinstance(d.sentence, s.Command):
            if d.sentence.ID not in self.profile.commands and not isinstance(d.sentence, s.OXFLT):
                return None
            return d.sentence
        if d.error is not None and d.error.answered:
            return d.error
        return None

    def exchange(self, raw: bytes, clause: Optional[str] = None, *, judge: bool = True,
                 variant: bool = False) -> Exchange:
        """Send ``raw`` and judge the replies (module docstring). ``clause``: whom a wrong answer fails.

        ``variant``: ``raw`` is a mutated form (lower-case hex, noise, bare LF…) of a command; a
        missing ACK then fails ``clause`` (the form was not read), not RH-ACK-1.
        """
        item = self.item_of(raw)
        self._unsolicited(self.link.drain())
        if judge and isinstance(item, s.Command) and not isinstance(item, (s.OSD, s.OXFLT)) and (
                self._ascending() or (self.mirror.mode in ("N", "P") and type(item).__name__ in _INTERRUPTS)):
            # Plant progress (a waypoint reached, the surface after the ascent) shows only in an
            # $OSI: observe just before a command whose answer or effect depends on it.
            self.poll(clause)
        mode_before = self.mirror.mode
        t_sent = self.link.send(raw)
        self._trace({"send": escape(raw), "t": round(t_sent, 6)})
        ex = Exchange(raw, item, t_sent)
        ack_type = None
        if isinstance(item, s.Command):
            ack_type = item.ACK_TYPE
        elif isinstance(item, SentenceError):
            ack_type = item.ack_type
        if self.rec is not None:
            self.rec.command(t_sent, raw)
        if ack_type is None:
            self._silent(ex, clause, item)
            return ex
        self._collect(ex, ack_type, clause if variant else None)
        latency = ex.t_ack - t_sent  # type: ignore[operator]
        observed = ex.data + [ex.ack]
        ex.expected = self.mirror.receive(item, ex.t_ack, latency, observed)  # type: ignore[arg-type]
        self._trace({"expect": _replies_text(ex.expected)})
        if self.rec is not None:
            self.rec.answered(ex, mode_before, self.mirror.mode)
        if judge and not same_replies(ex.expected, observed):
            want, got = ex.expected, observed
            wa = next((r for r in want if isinstance(r, s.ACK)), None)
            target = clause or self._clause_for(item)
            if wa is not None and ex.ack is not None and (wa.status, wa.err) == (ex.ack.status, ex.ack.err):
                target = "RH-OSD-2" if isinstance(item, s.OSD) and not want[:-1] else "RH-OSD-1"
            raise self.fail(target, f"sent {escape(raw.rstrip(bytes([13, 10])))}: a conforming vehicle in mode "
                                    f"{mode_before} answers {_replies_text(want)}; got {_replies_text(got)}")
        if judge and isinstance(item, s.ORWSET) and ex.ack is not None and ex.ack.status == 0:
            self._check_orwset_reply(ex, clause)
        if ex.osi is not None:
            self._judge_osi(ex.osi, ex.t_sent, ex.t_ack, clause)  # type: ignore[arg-type]
        return ex

    def _ascending(self) -> bool:
        m = self.mirror.model
        if m.phase == "none":
            return False
        c = m.clone()
        c.checkpoints = False
        c.advance(self.mirror.v(self.now()))
        return c.phase == "ascent"

    def _clause_for(self, item) -> str:
        row = self.mirror.model.last_row
        if isinstance(item, SentenceError):
            return "RH-ACK-3"
        if row is not None:
            for c in row.clauses:
                if not c.startswith("RH-RD"):
                    return c
        return "RH-ACK-3"

    def _check_orwset_reply(self, ex: Exchange, clause: Optional[str]) -> None:
        """RH-SET-1: ``$ACK,12,0,0,<setting>,<n>,<values…>`` with n counting what follows."""
        a = ex.ack
        extra = a.extra  # type: ignore[union-attr]
        ok = (len(extra) >= 2 and extra[0] == ex.item.setting  # type: ignore[union-attr]
              and extra[1].isdigit() and int(extra[1]) == len(extra) - 2)
        if not ok:
            raise self.fail(clause or "RH-SET-1", f"$ORWSET reply {_ack_text(a)} is not "
                                                  f"$ACK,12,0,0,<setting>,<n>,<state>,<values…>")
        self.book.ok("RH-SET-1")

    def _silent(self, ex: Exchange, clause: Optional[str], item) -> None:
        """A line with no ACK due (discard, or $OXFLT): nothing may answer it within the window."""
        window = self.profile.ack_window_s + self.link.transmit_time(len(ex.raw)) + ACK_GRACE_S
        if isinstance(item, s.OXFLT) or self.lazy_silence:
            # RH-SAF-5: no ACK. Its effect is timed (the lockout), so the tester does not sit out
            # the ACK window here: a stray ACK is caught by the next exchange (RH-ACK-1). The
            # exploration checks every discard this way too (a stray ACK fails the next step).
            window = 0.02
        end = ex.t_sent + window
        while True:
            rx = self.link.next(end)
            if rx is None:
                break
            self._judge_line(rx)
            sent = rx.sentence
            if isinstance(sent, s.ACK) and sent.type not in _UNSOLICITED_ACKS:
                what = "RH-SAF-5" if isinstance(item, s.OXFLT) else (clause or "RH-FRM-4")
                raise self.fail(what, f"sent {escape(ex.raw.rstrip(bytes([13, 10])))}: no $ACK is due "
                                      f"(it must be discarded silently), got {_ack_text(sent)}")
        self.forced_wait += max(0.0, self.now() - ex.t_sent)
        if isinstance(item, s.OXFLT):
            self.mirror.receive(item, ex.t_sent, 0.0)
            if self.rec is not None:
                self.rec.event(ex.t_sent, "lockout", f"$OXFLT,{item.code} sent")
        self._trace({"expect": "nothing (a silent discard)"})

    def _collect(self, ex: Exchange, ack_type: int, clause: Optional[str]) -> None:
        window = self.profile.ack_window_s
        tx = self.link.transmit_time(len(ex.raw))
        hard = ex.t_sent + 3 * window + tx + 1.0
        want_data = 0
        if isinstance(ex.item, s.OSD):
            letters = ex.item.requested
            if all(x in "GCSPYDTI" for x in letters):
                want_data = sum(1 for x in letters if x in self.profile.osd_letters)
        got_bytes = 0
        while True:
            rx = self.link.next(hard)
            if rx is None:
                break
            got_bytes += len(rx.raw)
            self._judge_line(rx)
            sent = rx.sentence
            if sent is None:
                continue
            if isinstance(sent, s.ACK):
                if sent.type == ack_type:
                    ex.ack, ex.t_ack = sent, rx.t
                    break
                if sent.type in _UNSOLICITED_ACKS:
                    continue
                raise self.fail("RH-ACK-6", f"sent {escape(ex.raw.rstrip(bytes([13, 10])))}: an $ACK,{sent.type} "
                                            f"came before its own $ACK,{ack_type} (ACKs out of order or "
                                            f"for the wrong command)")
            ex.data.append(sent)
            if isinstance(sent, s.OSI):
                ex.osi = sent
        if ex.ack is None:
            if not self._alive():
                raise LinkSilent(f"the vehicle answered nothing at all for {hard - ex.t_sent:.1f} s "
                                 f"(device off, wrong port or baud?)")
            raise self.fail(clause or "RH-ACK-1", f"sent {escape(ex.raw.rstrip(bytes([13, 10])))}: no "
                                                  f"$ACK,{ack_type} within {hard - ex.t_sent:.1f} s, though the "
                                                  f"vehicle still answers")
        allowed = window + tx + self.link.transmit_time(got_bytes) + ACK_GRACE_S
        latency = ex.t_ack - ex.t_sent
        if latency > allowed:
            if latency <= 2 * allowed + 0.5:
                self.book.add("RH-ACK-2", "inconclusive", f"an $ACK came {latency:.2f} s after the command, "
                              f"over the {allowed:.2f} s allowed by a margin host load can explain",
                              self.case, self.evidence(ex.t_sent))
            else:
                raise self.fail("RH-ACK-2", f"$ACK,{ack_type} came {latency:.2f} s after the command; the "
                                            f"window with transmit time is {allowed - ACK_GRACE_S:.2f} s")
        else:
            self.book.ok("RH-ACK-2")
        self.book.ok("RH-ACK-1")
        if want_data and len(ex.data) < want_data and ex.ack.status == 0:
            late_end = self.now() + min(0.5, window)
            while len(ex.data) < want_data:
                rx = self.link.next(late_end)
                if rx is None:
                    break
                self._judge_line(rx)
                if rx.sentence is not None and not isinstance(rx.sentence, s.ACK):
                    raise self.fail("RH-ACK-5", f"$OSD data ${rx.sentence.ID} came after $ACK,8 "
                                                f"(data must come before the ACK)")
        if want_data and ex.ack.status == 0 and len(ex.data) >= want_data:
            self.book.ok("RH-ACK-5")

    def _alive(self) -> bool:
        """Does the vehicle still answer anything? (an ``$OSD,S`` probe, not judged)."""
        self.link.note("liveness probe")
        self.link.send(frame("OSD,S"))
        end = self.now() + 2 * self.profile.ack_window_s + 0.5
        alive = False
        while True:
            rx = self.link.next(end)
            if rx is None:
                break
            if rx.valid:
                alive = True
                if isinstance(rx.sentence, s.ACK) and rx.sentence.type == 8:
                    break
        self.link.sleep(0.05)
        self.link.drain()
        self.mirror_dirty = True
        return alive

    def burst(self, raws: list[bytes], clause: str) -> list[Exchange]:
        """Write several commands at once, then read their ACKs in order (RH-ACK-6)."""
        self._unsolicited(self.link.drain())
        items = [self.item_of(r) for r in raws]
        t_sent = self.link.send(b"".join(raws))
        self._trace({"send": escape(b"".join(raws)), "t": round(t_sent, 6)})
        out = []
        for raw, item in zip(raws, items):
            ex = Exchange(raw, item, t_sent)
            if not isinstance(item, s.Command) or item.ACK_TYPE is None:
                continue
            self._collect(ex, item.ACK_TYPE, clause)
            observed = ex.data + [ex.ack]
            ex.expected = self.mirror.receive(item, ex.t_ack, ex.t_ack - t_sent, observed)  # type: ignore[operator]
            if not same_replies(ex.expected, observed):
                raise self.fail(clause, f"burst command {escape(raw.rstrip(bytes([13, 10])))}: expected "
                                        f"{_replies_text(ex.expected)}; got {_replies_text(observed)}")
            if ex.osi is not None:
                self._judge_osi(ex.osi, t_sent, ex.t_ack, None)  # type: ignore[arg-type]
            out.append(ex)
        self.book.ok("RH-ACK-6", len(out))
        return out

    # ================================================================ $OSI
    def _judge_osi(self, osi: s.OSI, t_sent: float, t_recv: float, clause: Optional[str]) -> None:
        """RH-OUT-4: the ``$OSI`` is one a conforming vehicle may report then."""
        half = max(0.0, (t_recv - t_sent) / 2)
        t = t_sent + half
        problems, exp = self.mirror.check_osi(osi, t, half)
        self.last_slack = self.mirror.slack(half)
        if self.rec is not None:
            self.rec.mode(t, osi.mode)
        self.last_osi, self.last_osi_t = osi, t
        if problems:
            cid, msg = problems[0]
            raise self.fail(clause or cid, msg, also=(cid,))
        self.book.ok("RH-OUT-4")

    def poll(self, clause: Optional[str] = None) -> s.OSI:
        ex = self.exchange(frame("OSD,S"), clause)
        if ex.osi is None:
            if "S" not in self.profile.osd_letters:
                raise CaseNotTested("the profile's osd_letters lack S: the state cannot be observed")
            raise self.fail("RH-OSD-1", "$OSD,S was acknowledged without an $OSI")
        if self.on_poll is not None:
            self.on_poll()
        return ex.osi

    # ================================================================ time
    def wait(self, vehicle_s: float, clause: Optional[str] = None, probe: Optional[bytes] = None) -> None:
        """Let ``vehicle_s`` of protocol time pass (÷k in wall time), polling and judging."""
        end = self.now() + vehicle_s / self.k
        self._trace({"wait": round(vehicle_s, 3)})
        t0 = self.now()
        trace, self.trace = self.trace, None  # a replay's wait step polls by itself
        try:
            while self.now() < end:
                nxt = min(end, self.now() + self.poll_gap)
                self.link.sleep(max(0.0, nxt - self.now()))
                if probe is not None:
                    self.exchange(probe, clause)
                self.poll(clause)
        finally:
            self.trace = trace
            self.forced_wait += self.now() - t0

    def settle(self, clause: str, timer: Optional[str] = None, probe: Optional[bytes] = None,
               after_v: float = 0.0) -> None:
        """Poll past the deadline of a model timer + RH-TIM-1 tolerance + slack (module docstring)."""
        dl = self.mirror.deadline(timer)
        if dl is None:
            raise CaseInconclusive(f"the model has no {timer or ''} timer running to wait for", clause)
        due, dur, name = dl
        t0 = self.now()
        worst = 0.0
        while True:
            if probe is not None:
                self.exchange(probe, clause)
            self.poll(clause)
            slack = self.last_slack
            worst = max(worst, slack)
            if self.mirror.v(self.now()) > due + tolerance(dur, slack) + after_v:
                break
            self.link.sleep(self.poll_gap)
            if self.now() - t0 > (dur + 60.0) / self.k + 30.0:
                raise CaseInconclusive(f"waited {self.now() - t0:.1f} s for the {name} timer", clause)
        self.forced_wait += self.now() - t0
        self.poll(clause)
        if worst > 0.5 * max(dur, 1.0):
            self.book.add("RH-TIM-1", "inconclusive", f"timing too noisy to judge a {dur:g} s duration: the "
                          f"observer's slack reached {worst:.1f} s of vehicle time", self.case)
            raise CaseInconclusive(f"timing too noisy: slack {worst:.1f} s for a {dur:g} s duration", clause)
        self.book.add("RH-TIM-1", "pass", f"the {name} duration ({dur:g} s) held within "
                      f"max(0.5 s, 5 %) + {worst:.2f} s of measured slack", self.case)

    def until(self, what: str, pred: Callable[[s.OSI], bool], budget_v: float,
              clause: Optional[str] = None, wall_cap: float = 30.0, estimate: bool = False) -> s.OSI:
        """Poll until ``pred(osi)``; NOT-TESTED when the vehicle does not get there in the budget.

        With ``estimate``, the travel time left (``$OSI`` distance ÷ speed) is compared with the
        budget as soon as the vehicle is under way, and a hopeless wait is not started.
        """
        t0 = self.now()
        end = t0 + min(budget_v / self.k, wall_cap)
        n = 0
        while True:
            osi = self.poll(clause)
            n += 1
            if pred(osi):
                self.forced_wait += self.now() - t0
                return osi
            speed = float(osi.speed) * 1852.0 / 3600.0
            if estimate and n >= 3 and speed > 0.05:
                need_v = float(osi.distance) / speed
                if need_v / self.k > end - self.now():
                    raise CaseNotTested(f"{what} needs about {need_v:.0f} s of vehicle time "
                                        f"({need_v / self.k:.0f} s at k={self.k:g}) for this leg alone, over the "
                                        f"case budget of {end - t0:.0f} s; a shorter test mission or a larger "
                                        f"time scale would reach it")
            if self.now() > end:
                raise CaseNotTested(f"the vehicle did not reach {what} within {self.now() - t0:.1f} s "
                                    f"({budget_v:g} s of vehicle time budgeted)")
            self.link.sleep(max(self.poll_gap, 0.05))

    def mission_end(self, what: str, clause: str, cap_v: float, wall_budget: float) -> s.OSI:
        """RH-MSN-4: poll until the running mission ends (``S``); FAIL when it does not in time.

        The bound is derived from what the vehicle reports: twice the time it says is left, plus
        :data:`END_MARGIN_V` (turns, dives, slowing near a waypoint); each poll may tighten it,
        and progress (a new mode or next waypoint) derives it afresh. The time left is the larger
        of ``$OSI`` field 13 (rh5: remaining mission time in hours) and the leg (field 7
        distance ÷ field 6 speed) plus a park shown; with neither usable (not under way, field 13
        absent or 0) the bound is the fixed cap, ``cap_v`` vehicle seconds from the start, which
        no bound passes. A vehicle that says more is left than the cap allows, a bound that does
        not fit ``wall_budget`` wall seconds at time scale k, or a wait without an estimate that
        outlasts that budget, is INCONCLUSIVE (a shorter mission or a larger k would fit). The ``$OSI`` showing ``S`` is judged by the mirror like
        every other (RH-OUT-4 tolerance).
        """
        t0 = self.now()
        v0 = self.mirror.v(t0)
        cap_end = v0 + cap_v
        deadline = cap_end
        basis = f"the cap of {cap_v:g} s of vehicle time (no usable estimate reported)"
        seen: Optional[tuple] = None
        estimated = False
        while True:
            osi = self.poll(clause)
            if osi.mode == "S":
                self.forced_wait += self.now() - t0
                return osi
            vt = self.mirror.v(self.now())
            key = (osi.mode, osi.next_waypoint)
            progress, seen = key != seen, key
            if progress:
                deadline, estimated = cap_end, False
                basis = f"the cap of {cap_v:g} s of vehicle time (no usable estimate reported)"
            left = self._time_left(osi)
            if left is not None:
                if vt + left > cap_end:
                    raise CaseInconclusive(
                        f"{what}: the vehicle reports about {left:.0f} s of vehicle time left "
                        f"{vt - v0:.0f} s after the start, past the cap of {cap_v:g} s; a shorter mission "
                        f"would be judged", clause)
                bound = min(cap_end, vt + 2.0 * left + END_MARGIN_V)
                if not estimated or bound < deadline:
                    deadline, estimated = bound, True
                    basis = (f"it reported about {left:.0f} s left in mode {osi.mode} toward waypoint "
                             f"{osi.next_waypoint} at {vt - v0:.0f} s")
            if estimated and (deadline - v0) / self.k > wall_budget:
                raise CaseInconclusive(
                    f"{what} may take up to {deadline - v0:.0f} s of vehicle time "
                    f"({(deadline - v0) / self.k:.0f} s at k={self.k:g}), over the case budget of "
                    f"{wall_budget:g} s; a shorter mission or a larger time scale would fit", clause)
            if not estimated and self.now() - t0 > wall_budget and vt <= deadline:
                raise CaseInconclusive(
                    f"{what}: no time left, distance or speed reported to bound the wait, and the case "
                    f"budget of {wall_budget:g} s ran out before the cap of {cap_v:g} s of vehicle time", clause)
            if vt > deadline:
                raise self.fail(clause, f"{what}: {vt - v0:.0f} s of vehicle time after the start $OSI still "
                                        f"shows mode {osi.mode}, next waypoint {osi.next_waypoint}, not S; "
                                        f"{basis}, so it should have ended by {deadline - v0:.0f} s")
            self.link.sleep(max(self.poll_gap, 0.05))

    def _time_left(self, osi: s.OSI) -> Optional[float]:
        """Vehicle seconds of the mission left by the vehicle's own report, or ``None``."""
        found = []
        if (self.profile.protocol == "rh5" and osi.remaining_time is not None
                and osi.remaining_time > 0):
            found.append(float(osi.remaining_time) * 3600.0)
        park = float(osi.park_time) if osi.mode == "P" else 0.0
        speed = float(osi.speed) * _KN
        if speed > 0.05:
            found.append(float(osi.distance) / speed + park)
        elif park > 0:
            found.append(park)
        return max(found) if found else None

    # ================================================================ reset
    def reset(self, mission: bool = True, park: bool = False) -> None:
        """The verified reset: ``$OMSTOP,0`` → ``S``; optionally the mission by name → ``N``."""
        t0 = self.now()
        self._unsolicited_quiet()
        end = t0 + (self.profile.lockout_s * 1.5 + 60.0) / self.k + 5.0
        while True:
            ex = self.exchange(frame("OMSTOP,0"), "RH-MSN-3", judge=False)
            if ex.ack is not None and ex.ack.status == 0:
                break
            if ex.ack is not None and ex.ack.err == 26 and self.now() < end:
                self.link.sleep(max(0.05, self.poll_gap))
                continue
            raise CaseInconclusive(f"verified reset failed: $OMSTOP,0 answered {_ack_text(ex.ack)}", "RH-MSN-3")
        self.mirror.fresh()
        self.mirror.receive(s.OMSTOP(0), ex.t_ack, ex.t_ack - ex.t_sent)  # type: ignore[operator]
        osi = self.poll("RH-MSN-3")
        if osi.mode != "S":
            raise self.fail("RH-MSN-3", f"after an accepted $OMSTOP,0 the vehicle reports mode {osi.mode}, not S")
        if mission:
            ex = self.exchange(frame(f"OMSTART,0,0,0,0,{self.profile.mission},"), "RH-MSN-2")
            if not ex.accepted:
                raise CaseInconclusive(f"the profile's mission {self.profile.mission!r} did not start: "
                                       f"{_ack_text(ex.ack)}", "RH-MSN-2")
            osi = self.poll("RH-MSN-2")  # the model judges it (N, waypoint 0 or already past it)
            if osi.mode not in ("N", "P"):
                raise self.fail("RH-MSN-2", f"after $OMSTART the vehicle reports mode {osi.mode}, not N")
        if park:
            self.reach_park()
        self.mirror.settle()
        self.forced_wait += 0.0

    def _unsolicited_quiet(self) -> None:
        try:
            self._unsolicited(self.link.drain())
        except CaseFail:
            self.link.drain()

    def reach_park(self) -> s.OSI:
        """From ``N``: get to the mission's park (``P``), jumping straight to its waypoint once known."""
        wp = self.mirror.stub.park_waypoint
        if wp is not None and wp > 0:
            self.exchange(frame(f"OJW,{wp + self.profile.waypoint_base}"), "RH-JW-2")
        budget = 3600.0
        osi = self.until("a mission park (mode P) on the test mission", lambda o: o.mode == "P", budget,
                         wall_cap=max(20.0, 900.0 / self.k))
        return osi

    # ================================================================ context
    def here(self) -> tuple[str, str]:
        """The vehicle's last reported position, as sentence fields."""
        o = self.last_osi
        if o is None:
            o = self.poll()
        return f"{float(o.lat):.6f}", f"{float(o.lon):.6f}"

    @property
    def remote_active(self) -> bool:
        return self.mirror.mode in REMOTE_MODES
