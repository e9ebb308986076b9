"""Driving a vehicle step by step: the primitives cases and exploration are made of.

:class:`Session` talks to the vehicle through a :class:`~.link.TesterLink`, whose every byte
and note the run's recorder writes to the wire log and feeds to the vehicle observer
(:class:`~helmcheck.judge.vehicle.VehicleObserver`). **It judges nothing**: the observer does,
into the ledger. The session only decides what to send next and how long to wait:

* :meth:`Session.exchange` — send one line and wait until the observer has settled it (its
  ``$ACK`` arrived, or the window of a line the vehicle must discard went by). A command left
  unanswered is followed by a liveness probe (``$OSD,S``), which is also what lets the observer
  tell a missing ACK (RH-ACK-1) from a dead link (a probe whose answer the line broke is asked
  again). When a faulty line may have spoilt the observation (the observer holds it: a lost or
  late ``$ACK``, a broken reply, :attr:`~helmcheck.judge.vehicle.Sent.spoil`), the line is sent
  again, up to :data:`~helmcheck.judge.spoil.RERUNS` times, each re-run a ``re-run`` note naming
  why: a clean answer makes the spoilt one the line's, the same error every time makes it the
  vehicle's (the observer's repetition rule, :mod:`helmcheck.judge.streaks`). A command whose
  second sending would change what the first did (``$OMW`` appends to the queue) is not sent
  again, and neither is a :meth:`Session.burst` (its point is when its commands arrive): what the
  line spoilt of them stays INCONCLUSIVE. When the observer has booked a failure inside
  the present case, the case stops (:class:`~.flow.CaseStop`): the first fail is the root cause —
  except a bad field of a report the observer still read (RH-OUT-1/3 on one field of an ``$OSI``,
  :mod:`helmcheck.judge.vehicle.lines`), which causes nothing after it, unless the case is about
  that clause.
* :meth:`Session.poll` — ``$OSD,S``; the ``$OSI`` the observer judged (read without its bad
  fields, if it has any; one whose state fields cannot be read, or that the line spoilt on every
  re-run, ends the case INCONCLUSIVE).
* :meth:`Session.wait`, :meth:`Session.settle`, :meth:`Session.until` — protocol time passing
  (vehicle seconds ÷ k, RH-TIM-2), polling all along. ``settle`` polls across a model timer's
  deadline until the vehicle is seen to have left the state before it, so the observer can
  bracket it (RH-TIM-1). Waits end as soon as an ``$OSI`` decides them; one past its budget is
  INCONCLUSIVE with the reason and the option that extends it (``--max-wait``).
* :meth:`Session.reset` — the verified reset between cases: ``$OMSTOP,0`` (waiting out a
  lockout), ``S`` seen (then the settings a case may write are read, :mod:`.restore`); then the
  profile's mission started by name (rh5 form) and seen running.

Every line and report is also counted for what it reached of the reference model
(:attr:`Session.cover`, :mod:`.modelcover`: for the cases or the exploration, as its ``source``
says) and of the range edges (:attr:`Session.edges`); counting never judges.

Tester facts go to the log as notes (``not tested …``, ``inconclusive …``) so that an offline
check of the log reaches the same verdicts.
"""

from __future__ import annotations

from contextlib import contextmanager
from typing import Callable, Optional

from ...grammar import checksum_hex
from ...grammar import sentences as s
from ...judge.spoil import RERUNS
from ...judge.timing import ack_allowance, tolerance
from ...judge.vehicle import Sent, VehicleObserver
from ...judge.wire import case_end_note, case_note, tester_note
from ...profile import Profile
from .durations import Durations, derive
from .edges import EdgeTally
from .modelcover import ModelCoverage
from .safety import BenchSafetyRefused
from .flow import CaseStop, LinkSilent
from .link import TesterLink
from .linemeter import LINK_PROBES, LineMeter

__all__ = ["Session", "frame"]


def frame(body: str, lowercase: bool = False, terminator: str = "\r\n") -> bytes:
    """``$body*HH`` + terminator with the body's checksum (RH-FRM-1/2)."""
    raw = body.encode("latin-1")
    cks = checksum_hex(raw)
    return b"$" + raw + b"*" + (cks.lower() if lowercase else cks).encode() + terminator.encode()


class Session:
    """One tester session on one link. See the module docstring."""

    def __init__(self, link: TesterLink, profile: Profile, time_scale: float, observer: VehicleObserver,
                 max_wait: Optional[float] = None):
        self.link = link
        self.profile = profile
        self.k = float(time_scale)
        self.obs = observer
        self.ledger = observer.ledger
        self.max_wait = max_wait
        self.case = ""
        self.case_clauses: tuple = ()
        self.mark = 0
        self.poll_gap = max(0.02, min(0.25, 1.0 / self.k))
        self.forced_wait = 0.0  #: wall seconds spent waiting for protocol durations
        self.trace: Optional[list] = None  #: replay steps while recording
        #: where the vehicle was when the recorded steps began (lat, lon; :mod:`.relocate`)
        self.trace_origin: Optional[tuple[float, float]] = None
        self.lazy_silence = False  #: do not sit out the window after a line the vehicle discards
        self.stop_on_fail = True
        #: clauses whose violations do not stop a step (:meth:`check`): the exploration, once it
        #: has one of a clause, looks on for others (they are still booked, :mod:`.explore`)
        self.ignore: frozenset = frozenset()
        self.on_poll: Optional[Callable[[], None]] = None
        #: the mission the verified reset starts: the profile's test mission, or for a case that
        #: waits for a mission's own safety rule, ``violation_mission`` (RH-SAF-5)
        self.mission_override: Optional[str] = None
        self.mission_started_at: Optional[float] = None  #: wall time of the last accepted $OMSTART
        self.case_needs: tuple = ()  #: the present case's needs (catalogue)
        #: tells the person at the terminal what to do (``violation_trigger = "operator"``); None
        #: when nobody is there
        self.operator: Optional[Callable[[str], None]] = None
        #: closes the tester's end of the link and opens it again under the same name (a client
        #: reconnecting, :class:`.steps.Quiet`); returns what it did, or None where the name cannot
        #: be opened again (the run's own pty, a vehicle it started). None: never (a plan)
        self.reopen: Optional[Callable[[], Optional[str]]] = None
        #: keeps what the vehicle was found in and puts it back (:mod:`.restore`); None: not kept
        self.custodian = None
        #: what the line costs (:mod:`.linemeter`), and the durations chosen from it (:mod:`.durations`)
        self.meter = LineMeter(self.k, profile.baud, profile.ack_window_s)
        self._durations: Optional[Durations] = None
        self.reruns = 0  #: re-runs the last :meth:`exchange` took (a faulty line spoilt what came before)
        self.reruns_total = 0  #: every observation made again so far (a case step's state may be stale)
        #: the range edges of §4–8b the lines sent reached (:mod:`.edges`; ``stats.edges``)
        self.edges = EdgeTally(profile)
        #: what the lines reached of the model, for the cases and the exploration (:mod:`.modelcover`)
        self.cover = ModelCoverage(profile)
        self._covering: list = []  #: (sent, what it met, source) until the observer settles it

    # ================================================================ the line budget
    def measure_line(self, host: bool = True) -> None:
        """The link check's measurement (:mod:`.linemeter`): the host's jitter (not on a line in
        virtual time: ``host`` false), then :data:`~.linemeter.LINK_PROBES` ``$OSD,S`` round trips;
        writes the ``line budget:`` note."""
        if host:
            self.meter.measure_host()
        body = "OSD,S" if "S" in self.profile.osd_letters else "OSD"  # no letters: ACK alone (RH-RD-7)
        with self.not_stopping():  # what the judge finds in them is booked; the run goes on
            unanswered = 0
            for _ in range(LINK_PROBES):
                sent = self.exchange(frame(body))
                unanswered = unanswered + 1 if sent is not None and sent.ack is None else 0
                if unanswered >= 2:  # a vehicle that does not acknowledge the probe (each made again
                    break  # already, RH-ACK-1): no latency to measure; the judge has what it needs
        self.meter.measured = True
        self.durations(fresh=True)

    def durations(self, fresh: bool = False) -> Durations:
        """The durations the line allows (:mod:`.durations`), chosen again when ``fresh`` (a case or
        a sequence starts) from the latencies measured so far; a budget that moved is noted."""
        if fresh or self._durations is None:
            changed = self.meter.changed()
            if changed is not None and self.meter.measured:
                self.note(changed.note())
            self._durations = derive(self.profile, self.meter.budget())
        return self._durations

    def _sample(self, sent: Sent) -> None:
        if sent.ack is not None and sent.t_ack is not None and not sent.branched:
            replies = self.obs.vbytes - sent.vbytes0
            self.meter.sample(sent.t, len(sent.raw), sent.t_ack, replies)
            for _, cls, evd in sent.data:
                if cls == "OSI":
                    self.meter.saw_osi(len(evd.text) + 2)

    # ================================================================ helpers
    def now(self) -> float:
        return self.link.now()

    def note(self, text: str) -> None:
        self.link.note(text)

    def tester(self, kind: str, clauses, reason: str) -> None:
        """A tester fact for the log (and so for every judge): ``not-tested`` / ``inconclusive``."""
        clauses = [c for c in clauses if c]
        if clauses:
            self.note(tester_note(kind, clauses, reason))

    def begin_case(self, case_id: str, clauses, title: str) -> None:
        self.case, self.case_clauses = case_id, tuple(clauses)
        self.note(case_note(case_id, clauses, title))
        self.mark = self.ledger.mark()

    def end_case(self) -> None:
        if self.case:
            self.note(case_end_note(self.case))
        self.case, self.case_clauses = "", ()

    def failures(self) -> list[tuple[str, str]]:
        """Failures the observer booked since the present case (or exploration step) began."""
        return self.ledger.failures_since(self.mark)

    def check(self) -> None:
        """Stop the case when the observer booked a failure inside it."""
        got = self.failures()
        if self.ignore:
            got = [f for f in got if f[0] not in self.ignore]
        read = self.obs.out.read_anyway
        if read:  # a bad field of a report still read is no cause of what follows (judge.vehicle.lines;
            # booked after the repetition rule held it, its reason says so after it)
            got = [f for f in got if f[0] in self.case_clauses
                   or not any(f[0] == c and f[1].startswith(r) for c, r in read)]
        if got and self.stop_on_fail:
            cid, reason = got[0]
            raise CaseStop("fail", f"{cid}: {reason}", cid)

    def _trace(self, step: dict) -> None:
        if self.trace is not None:
            self.trace.append(step)

    # ================================================================ exchange
    def send(self, raw: bytes) -> Optional[Sent]:
        """Write ``raw``; the observer's record of its last line (``None`` if nothing framed)."""
        seq = self.obs.seq
        if self.custodian is not None:
            self.custodian.check_write(raw)  # no setting is written unless its restore is known
        at = self.edges.before(raw, self.obs.state())
        met = self.cover.before(self.obs.state(), raw)
        try:
            t = self.link.send(raw)
        except BenchSafetyRefused:
            self.edges.refused(at, "bench safety")
            raise
        self._trace({"send": _esc(raw), "t": round(t, 6)})
        for sent in reversed(self.obs.sent):
            if sent.seq <= seq:
                break
            self.edges.track(sent, at)
            self._cover(sent, met)
            return sent
        return None

    def _cover(self, sent: Optional[Sent], met) -> None:
        """Count for the model coverage what the lines the observer has settled met (``sent``
        with what it met, when given, waits until it is settled)."""
        if sent is not None and met is not None and self.cover.source:
            self._covering.append((sent, met, self.cover.source))
        keep = []
        for x, m, source in self._covering:
            if not x.done:
                keep.append((x, m, source))
                continue
            was, self.cover.source = self.cover.source, source
            try:
                self.cover.command(m, x.expected, self.obs.state())
            finally:
                self.cover.source = was
        self._covering = keep

    def exchange(self, raw: bytes) -> Optional[Sent]:
        """Send ``raw`` and wait until the observer has settled it; made again while a faulty line
        may have spoilt it (module docstring). The last sending is returned; :attr:`reruns` says
        how many re-runs it took."""
        sent = self._exchange_once(raw)
        self.reruns = 0
        while (sent is not None and sent.spoil and self.reruns < RERUNS and _rerunnable(sent)
               and self.obs.awaits(sent)):
            self.reruns += 1
            self.reruns_total += 1
            self.note(f"re-run {self.reruns} of {RERUNS}: {_line_text(raw)}: {sent.spoil}")
            sent = self._exchange_once(raw)
        return sent

    def _exchange_once(self, raw: bytes) -> Optional[Sent]:
        self.link.drain()
        sent = self.send(raw)
        if sent is None:
            return None
        allowance = ack_allowance(self.profile.ack_window_s, len(raw), 0, self.profile.baud)
        if sent.kind.ack_type is None:
            wait = 0.02 if (self.lazy_silence or sent.kind.kind == "oxflt") else allowance
            self.link.sleep(max(0.0, sent.t + wait - self.now()))
            self.check()
            return sent
        # long enough to see a late ACK (RH-ACK-2), and until the observer has given up on it: a
        # probe sent sooner would have its answer taken for this line's
        while not sent.done:
            hard = self.obs.give_up_at(sent) + 0.05
            rx = self.link.next(hard)
            if rx is None and self.now() >= self.obs.give_up_at(sent) + 0.05:
                break
        if sent.done:
            self._sample(sent)
            self._cover(None, None)
            self._trace({"expect": _brief(sent.expected)})
            self.check()
            return sent
        self._probe(self.now())
        self.check()
        return sent

    @contextmanager
    def not_stopping(self):
        """A block in which a failure the observer books does not stop the case (``stop_on_fail``
        off; put back as it was after): a reset, a restore, a survey — the judge still books."""
        stop, self.stop_on_fail = self.stop_on_fail, False
        try:
            yield
        finally:
            self.stop_on_fail = stop

    def outwait_lockout(self) -> None:
        """Poll until the lockout (RH-SAF-1) the observer's mirror still counts is over (at most 1.5 times the
        profile's lockout and 30 s more, vehicle time): a sequence or a re-drive then starts from
        the same state on any vehicle, whether its lockout ended sooner (a finding of whatever set
        it going, not of what comes next) or not. Stops at nothing: call it inside
        :meth:`not_stopping`."""
        end = self.now() + (self.profile.lockout_s * 1.5 + 30.0) / self.k
        while self.obs.state().phase == "lockout" and self.now() < end:
            self.poll()
            self.link.sleep(max(self.poll_gap, 0.05))

    def outwait_surface(self, within_v: float = 120.0) -> None:
        """Poll until the vehicle reports itself at the surface (depth within ``gps_fix_depth_m``:
        it has a GPS fix, RH-POS-2, RH-RD-10), for at most ``within_v`` vehicle seconds: after a
        reset that found it under water (a dive or a safety episode before it), a sequence or a
        re-drive then starts from the same state on any vehicle — an ``$OPOS`` is applied or not
        as on a fresh one. A vehicle still under water after that starts where it is."""
        from ...judge.vehicle.closure import osi_depth_m

        def under(osi) -> bool:
            depth = osi_depth_m(osi, self.profile.depth_unit)
            return depth is not None and depth > self.profile.gps_fix_depth_m
        self.poll_while(under, within_v)

    def poll_while(self, keep, within_v: float, judge: bool = False):
        """Poll, a poll gap apart, while ``keep(report)`` holds of the last report (one is polled
        when none was seen), for at most ``within_v`` vehicle seconds; stop on a failure after each
        report when ``judge`` (:meth:`check`). Returns the last report. Running out of time is
        silent: the caller says what a vehicle still ``keep``-ing means (:meth:`until` makes it
        INCONCLUSIVE instead)."""
        end = self.now() + within_v / self.k
        osi = self.obs.last_osi or self.poll()
        while keep(osi) and self.now() < end:
            self.link.sleep(max(self.poll_gap, 0.05))
            osi = self.poll()
            if judge:
                self.check()
        return osi

    def finish(self, linger_v: float = 0.0) -> None:
        """Let every line sent so far be settled by the observer — a line answered late or not at
        all, which a ``lazy_silence`` exchange did not wait for, is judged now — then poll once (so
        that an unanswered line is told from a dead link), go on polling for ``linger_v`` vehicle
        seconds (a report late by more than a timer's tolerance shows only after it), and stop on a
        failure (:meth:`check`)."""
        pending = [x for x in self.obs.sent if not x.done]
        if pending:
            while any(not x.done for x in pending):
                hard = max(self.obs.give_up_at(x) for x in pending if not x.done) + 0.05
                if self.now() >= hard:
                    break
                self.link.next(hard)
            self.poll()
        self.rerun_spoilt()
        self.check()
        if linger_v > 0:
            self.wait(linger_v)
            self.check()

    def rerun_spoilt(self) -> None:
        """Make again what a faulty line may have spoilt among the lines sent so far that were not
        exchanged one by one (a ``lazy_silence`` step, the clock check): each such line once more,
        through :meth:`exchange` (its own re-runs as ever)."""
        done: set = set()
        for x in list(self.obs.sent):
            if x.spoil and x.ident not in done and _rerunnable(x) and self.obs.awaits(x):
                done.add(x.ident)
                self.note(f"re-run of {_line_text(x.raw)}: {x.spoil}")
                self.reruns_total += 1
                self.exchange(x.raw)

    def _probe(self, after: float) -> None:
        """A command got no ACK in time: does the vehicle still answer anything? (an ``$OSD,S``
        the observer judges like any other — its answer decides RH-ACK-1 against a link fault).
        A probe left unanswered is asked again (a faulty line may have lost it or broken its
        answer), up to :data:`~helmcheck.judge.spoil.RERUNS` times."""
        self.link.sleep(max(0.0, after - self.now()))
        self.note("liveness probe")
        alive = False
        for _ in range(RERUNS + 1):
            self.link.drain()
            probe = self.send(frame("OSD,S"))
            while probe is not None and not probe.done:  # until the observer gives up on it (exchange)
                end = self.obs.give_up_at(probe) + 0.05
                if self.now() >= end:
                    break
                self.link.next(end)
            alive = ((probe is not None and probe.ack is not None)
                     or (self.obs.alive_t is not None and self.obs.alive_t >= (probe.t if probe else self.now())))
            if alive and not (probe is not None and probe.spoil and self.obs.awaits(probe)):
                return
            # nothing, nothing that reads, or an answer the line spoilt: asked again
            if alive:
                self.note(f"re-run of the liveness probe: {probe.spoil}")
        if alive:
            return  # alive, its answers spoilt every time: held by the observer, INCONCLUSIVE at worst
        raise LinkSilent(f"the vehicle answered nothing at all for {self.now() - after:.1f} s "
                         f"(device off, wrong port or baud?)")

    def burst(self, raws: list[bytes]) -> list[Sent]:
        """Write several commands at once, then wait for all their answers (RH-ACK-6)."""
        self.link.drain()
        seq = self.obs.seq
        if self.custodian is not None:
            for raw in raws:
                self.custodian.check_write(raw)
        state = self.obs.state()  # each line's edges as met in the state before the burst (:mod:`.edges`)
        ats = [self.edges.before(raw, state) for raw in raws]
        mets = [self.cover.before(state, raw) for raw in raws]
        try:
            t = self.link.send(b"".join(raws))
        except BenchSafetyRefused:
            for at in ats:
                self.edges.refused(at, "bench safety")
            raise
        self._trace({"send": _esc(b"".join(raws)), "t": round(t, 6)})
        sents = [x for x in self.obs.sent if x.seq > seq]
        if len(sents) == len(raws):
            for sent, at, met in zip(sents, ats, mets):
                self.edges.track(sent, at)
                self._cover(sent, met)
        while any(not x.done for x in sents):  # until each is answered or the observer gave up on it
            hard = max(self.obs.give_up_at(x) for x in sents if not x.done) + 0.05
            if self.link.next(hard) is None and self.now() >= hard:
                break
        for x in sents:
            if x.done:
                self._sample(x)
        self._cover(None, None)
        if any(not x.done for x in sents):
            self._probe(hard)
        self.check()  # a burst is about its timing (a lockout's commands): what the line spoilt of
        return sents  # it is not made again later (it stays INCONCLUSIVE unless sent again)

    def poll(self) -> s.OSI:
        """``$OSD,S`` and the ``$OSI`` the observer judged."""
        sent = self.exchange(frame("OSD,S"))
        osi = sent.osi if sent is not None else None
        if osi is None:
            if "S" not in self.profile.osd_letters:
                self.tester("not-tested", self.case_clauses, "the profile's osd_letters lack S: the "
                                                             "vehicle's state cannot be observed")
                raise CaseStop("not-tested", "the profile's osd_letters lack S")
            if sent is not None and sent.spoil:
                raise CaseStop("inconclusive", f"$OSD,S was answered without a readable $OSI {self.reruns + 1} "
                                               f"time(s) in a row: {sent.spoil} (a faulty line?)")
            if sent is not None and any(cls == "OSI" for _, cls, _ in sent.data):
                # an $OSI came, but its state fields could not be read (booked on their clause)
                raise CaseStop("inconclusive", "the $OSI answering $OSD,S shows no readable state (mode, "
                                               "waypoint, park time, error state)")
            raise CaseStop("fail", "$OSD,S was answered without an $OSI", "RH-OSD-1")
        self.cover.report(self.obs.state())
        if self.on_poll is not None:
            self.on_poll()
        return osi

    # ================================================================ time
    def _budget(self, what: str, wall: float, clause: Optional[str], option: str) -> None:
        reason = (f"{what}: not decided within {wall:.0f} s of wall time ({wall * self.k:.0f} s of vehicle "
                  f"time at time scale {self.k:g}); {option}")
        self.tester("inconclusive", [clause or (self.case_clauses[0] if self.case_clauses else "")], reason)
        raise CaseStop("inconclusive", reason, clause)

    def _cap(self, wall: float) -> float:
        return wall if self.max_wait is None else min(wall, self.max_wait)

    def wait(self, vehicle_s: float, probe: Optional[bytes] = None) -> None:
        """Let ``vehicle_s`` of protocol time pass (÷ k in wall time), polling all along."""
        end = self.now() + vehicle_s / self.k
        self._trace({"wait": round(vehicle_s, 3)})
        t0 = self.now()
        trace, self.trace = self.trace, None  # a replay's wait step polls by itself
        try:
            while self.now() < end:
                nxt = min(end, self.now() + self.poll_gap)
                self.link.sleep(max(0.0, nxt - self.now()))
                if probe is not None:
                    self.exchange(probe)
                self.poll()
        finally:
            self.trace = trace
            self.forced_wait += self.now() - t0

    def quiet(self, wall_s: float, reopen: bool = False) -> None:
        """The line goes quiet for ``wall_s`` (nothing sent, replies still read), then, with
        ``reopen``, the link is closed and opened again where its name allows (:class:`.steps.Quiet`)."""
        self.link.note(f"line quiet: the tester sends nothing for {wall_s:g} s")
        t0 = self.now()
        self.link.sleep(wall_s)
        self.forced_wait += self.now() - t0
        if reopen:
            did = self.reopen() if self.reopen is not None else None
            self.link.note(did or "line quiet: the link is kept open (its name cannot be opened again)")

    def settle(self, timer: Optional[str] = None, probe: Optional[bytes] = None,
               clause: Optional[str] = None) -> s.OSI:
        """Poll across the deadline of a model timer until the vehicle has left the state before
        it (the observer brackets the transition, RH-TIM-1). The lockout's end shows in no
        ``$OSI``: with a ``probe`` (a command only the lockout refuses) it is left when the probe
        is answered without err 26 (RH-SAF-1), so what follows is judged after it for certain."""
        dl = self.obs.deadline(timer)
        if (dl is None and timer == "lockout" and self.obs.state().phase != "lockout"
                and self.obs.state().error_state != "N"):
            if self.profile.trigger in ("mission-rule", "operator"):
                # the vehicle's own rule (or the operator) tripped and its lockout ran out before the
                # case could watch it end: what follows is judged; the lockout's length is not, here
                self.note(f"{self.case}: the lockout ended before the case could watch it (the vehicle's own "
                          f"violation came while it was busy): its length is not judged in this case")
                return self.poll()
            # raised by the tester, and over before the line brought back an answer from inside
            # it: this line cannot carry the case at this time scale (the tester's choice, not a
            # finding, and not INCONCLUSIVE)
            d = self.durations(fresh=True)
            reason = (f"{self.case}: the {self.profile.lockout_s:g} s lockout was over before an answer from "
                      f"inside it came back on this line at time scale {self.k:g} (RH-SAF-1, the line: "
                      f"{d.budget.describe()}); run at {d.advice('lockout')}")
            self.tester("not-tested", [clause] if clause else self.case_clauses[:1], reason)
            raise CaseStop("not-tested", reason)
        if dl is None:
            self._budget(f"the {timer or 'next'} timer", 0.0, clause,
                         "the case did not reach the state whose timer it waits for")
        due_wall, dur, name = dl
        tol_wall = (tolerance(dur) + self.k * 2 * self.poll_gap) / self.k
        t0 = self.now()
        cap = self._cap(max(0.0, due_wall - t0) + 2 * tol_wall + 5.0)
        before = self.obs.state().mode
        phase_before = self.obs.state().phase
        # quietly until close to the deadline, then poll closely: over the tolerance and over the
        # last quarter of the duration, where a clock off by tens of percent ends it (RH-TIM-2)
        close = max(tol_wall + 2 * self.poll_gap, dur / 4 / self.k)
        while self.now() < due_wall - close:
            self.link.sleep(min(self.poll_gap * 4, max(0.0, due_wall - close - self.now())))
            self.poll() if probe is None else self.exchange(probe)
        answered = None
        osi = None
        # the lockout's end is shown by the probe (a command only the lockout refuses): a report
        # between two probes would only space them further apart on a slow line
        by_probe = name == "lockout" and probe is not None
        while True:
            if probe is not None:
                answered = self.exchange(probe)
            over = by_probe and answered is not None and answered.ack is not None and answered.ack.err != 26
            if not by_probe or over or self.now() - t0 > cap:
                osi = self.poll()
            st = self.obs.state()
            armed = st.timers.armed(name)
            if name != "lockout":
                left = osi is not None and osi.mode != before
            else:
                left = st.phase != phase_before and (over or not by_probe)
            if not armed and left and self.now() > due_wall:
                break
            if self.now() - t0 > cap:
                self.forced_wait += self.now() - t0
                self._budget(f"the end of the {dur:g} s {name} timer", self.now() - t0, clause,
                             "--max-wait raises the cap" if self.max_wait is not None else
                             "the vehicle did not leave the state the timer ends")
            # across the tolerance itself, reports a fifth of it apart: a transition late (or
            # early) by more than the tolerance and the observer's own slack is seen to be
            # (RH-TIM-1 widens the tolerance by the polling interval: keep that small)
            near = abs(self.now() - due_wall) <= tol_wall + self.poll_gap
            self.link.sleep(max(0.005, min(self.poll_gap, tolerance(dur) / self.k / 5)) if near else self.poll_gap)
        self.forced_wait += self.now() - t0
        return osi

    def until(self, what: str, pred: Callable[[s.OSI], bool], budget_v: float,
              clause: Optional[str] = None, refresh: Optional[tuple[bytes, float]] = None) -> s.OSI:
        """Poll until ``pred(osi)``; past ``budget_v`` vehicle seconds, INCONCLUSIVE. ``refresh``:
        ``(line, every_v)`` — the control that gets the vehicle there, sent again every ``every_v``
        vehicle seconds (RH-RD-3: its timeout restarts), so a slow vehicle is not let go on the way."""
        t0 = self.now()
        wall = self._cap(budget_v / self.k)
        again = t0
        while True:
            if refresh is not None and self.now() - again >= refresh[1] / self.k:
                self.exchange(refresh[0])
                again = self.now()
            osi = self.poll()
            if pred(osi):
                self.forced_wait += self.now() - t0
                return osi
            if self.now() - t0 > wall:
                self.forced_wait += self.now() - t0
                option = ("--max-wait raises the cap" if self.max_wait is not None and wall < budget_v / self.k
                          else "a larger time scale, or a test mission that gets there sooner, would reach it")
                self._budget(f"the vehicle did not reach {what}", self.now() - t0, clause, option)
            self.link.sleep(max(self.poll_gap, 0.05))

    # ================================================================ reset
    def reset(self, mission: bool = True, park: bool = False) -> None:
        """The verified reset: ``$OMSTOP,0`` → ``S``; optionally the mission by name → running."""
        p = self.profile
        if "OMSTOP" not in p.commands:
            why = "the verified reset needs $OMSTOP, which the profile does not claim"
            self.tester("not-tested", self.case_clauses, why)
            raise CaseStop("not-tested", why)
        t0 = self.now()
        end = t0 + self._cap((p.lockout_s * 1.5 + 60.0) / self.k + 5.0)
        with self.not_stopping():
            while True:
                sent = self.exchange(frame("OMSTOP,0"))
                if sent is not None and sent.accepted:
                    break
                if sent is not None and sent.ack is not None and sent.ack.err == 26 and self.now() < end:
                    self.link.sleep(max(0.05, self.poll_gap))
                    continue
                raise CaseStop("inconclusive", f"the reset failed: $OMSTOP,0 answered "
                                               f"{_brief([sent.ack]) if sent and sent.ack else 'nothing'}")
        osi = self.poll()
        if osi.mode != "S":
            raise CaseStop("inconclusive", f"after an accepted $OMSTOP,0 the vehicle reports {osi.mode}")
        if self.custodian is not None:
            self.custodian.survey(self)  # in S: read what a case may write, before it does
        if mission:
            self.start_mission(self.mission_override or p.mission, clause="RH-MSN-2")
        if park:
            self.reach_park()

    def start_mission(self, name: str, srp: str = "", ignore_gps: int = 0, clause: str = "RH-MSN-2") -> s.OSI:
        """``$OMSTART`` by name (rh5 form, RH-MSN-2); INCONCLUSIVE when the vehicle lacks it."""
        sent = self.exchange(frame(f"OMSTART,{ignore_gps},0,0,0,{name},{srp}"))
        if sent is not None and not sent.accepted and self.reruns:
            # sent again after the line spoilt its answer: the first sending may have started it
            osi = self.poll()
            if osi.mode in ("N", "P"):
                self.mission_started_at = self.now()
                return osi
        if sent is None or not sent.accepted:
            what = f"mission {name!r}" + (f" with SRP {srp!r}" if srp else "")
            why = (f"the profile's {what} did not start: {_brief([sent.ack]) if sent and sent.ack else 'no answer'}"
                   f" (is it on the vehicle?)")
            self.tester("inconclusive", self.case_clauses or (clause,), why)
            raise CaseStop("inconclusive", why, clause)
        self.mission_started_at = sent.t_ack if sent.t_ack is not None else self.now()
        osi = self.poll()
        if osi.mode not in ("N", "P"):
            raise CaseStop("inconclusive", f"after $OMSTART the vehicle reports {osi.mode}, not a running mission")
        return osi

    def reach_park(self) -> s.OSI:
        """From ``N``: get to the mission park (``P``), jumping to its waypoint once it is known."""
        entry = self.obs.missions.entry(self.profile.mission)
        wp = entry.park_waypoint if entry is not None else None
        if wp is not None and self.obs.state().mission_wp != wp:
            self.exchange(frame(f"OJW,{wp + self.profile.waypoint_base}"))
        return self.until("a mission park (mode P) on the test mission", lambda o: o.mode == "P", 3600.0)

    # ================================================================ context
    def here(self) -> tuple[str, str]:
        """The vehicle's last reported position, as sentence fields."""
        o = self.obs.last_osi
        if o is None:
            o = self.poll()
        if o.lat is None or o.lon is None:
            raise CaseStop("inconclusive", "the vehicle's last $OSI does not show its position readably "
                                           "(fields 4 and 5)")
        return f"{float(o.lat):.6f}", f"{float(o.lon):.6f}"


def _rerunnable(sent: Sent) -> bool:
    """A line whose second sending does what its first did (module docstring): not an ``$OMW``
    that queues a waypoint (the keyword forms are)."""
    if sent.kind.kind not in ("command", "error"):
        return False
    return not isinstance(sent.kind.item, s.OMW)


def _line_text(raw: bytes) -> str:
    return _esc(raw.rstrip(b"\r\n"))


def _esc(raw: bytes) -> str:
    from ...grammar.wirelog import escape
    return escape(raw)


def _brief(replies: list) -> str:
    out = []
    for r in replies:
        if isinstance(r, s.ACK):
            out.append("$ACK," + ",".join(map(str, (r.type, r.status, r.err, *r.extra))))
        elif r is not None:
            out.append("$" + (r if isinstance(r, str) else type(r).__name__))
    return ", ".join(out) or "nothing"
