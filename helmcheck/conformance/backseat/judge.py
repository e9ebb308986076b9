"""The backseat judge, sans-IO: every byte a backseat sends in, per-clause findings out (§9).

:class:`BackseatJudge` is fed, with the wall time ``t`` of each call (never read from a clock):

* ``backseat_bytes(data, t) -> [Piece]`` — bytes from the backseat, split anywhere. Returns the
  complete framing events (a line, or a discarded run) as :class:`Piece` s holding their exact
  bytes, so the caller can hand the vehicle exactly the lines the judge saw.
* ``vehicle_bytes(data, t)`` — bytes the vehicle sent the backseat, when they went out. They
  are what the backseat *could know*: the reported mode (``$OSI`` field 2), the safety code
  (field 8) and every ``$ACK``.
* ``lockout(active, t)``, ``silence(active, t)``, ``scenario(name, t)`` — facts only the
  vehicle side knows: when its safety lockout really runs (RH-SAF-1), when it stops answering,
  which scenario is being staged.
* ``close(t)`` — the end of the run (or of the link); flushes what is pending.

``results()`` then gives one :class:`ClauseResult` per §9 clause with its verdict, the number of
offending sentences and the first few of them quoted.

Knowledge and reaction (decisions where §9 is silent; each is a constructor setting):

* ``reaction_s`` (0.5 s wall): a backseat is judged on what the vehicle told it at least this
  long before a sentence arrived. Sentences in flight when a report went out are not blamed.
* ``jitter_s`` (0.2 s wall): scheduling and transmit slack allowed on every spacing rule.
* Wall-time rules (RH-TIM-2: never scaled): the line budget (RH-BS-4), the one-second resend
  spacing (RH-BS-5) and the 5 s polling interval (RH-BS-8). The servo timeout the backseat
  chose (RH-BS-6) is a protocol duration: ``timeout / time_scale`` of wall time, measured from
  the ``$ACK`` (RH-RD-15), with the RH-TIM-1 tolerance plus ``jitter_s``.
"""

from __future__ import annotations

import re
from collections import OrderedDict, deque
from dataclasses import dataclass, field
from typing import Optional

from ...grammar import Decoded, Discard, Framer, Line, decode
from ...grammar import sentences as s
from ...grammar.capture import escape
from ...model.validate import field_error
from ...profile import Profile

__all__ = ["BackseatJudge", "Piece", "Offence", "ClauseResult", "BS_CLAUSES", "EVIDENCE_LIMIT",
           "line_budget", "window_violations"]

BS_CLAUSES = tuple(f"RH-BS-{i}" for i in range(1, 9))
EVIDENCE_LIMIT = 5  #: offending lines quoted per clause
POLL_INTERVAL_S = 5.0  #: RH-BS-8
RESEND_SPACING_S = 1.0  #: RH-BS-5

#: Modes of ``$OSI`` field 2 that say a mission is running (RH-RD-1); ``M`` says nothing.
_RUNNING_MODES = frozenset({"N", "P", "mP", "Mp", "A", "W"})
#: RH-BS-3: commands a backseat may send only while the vehicle reports a running mission …
_NEED_RUNNING = frozenset({"OMS", "OJW", "OPK", "OMW"})
#: … and only while it reports none ("before starting a mission").
_NEED_STOPPED = frozenset({"OLOGL", "ORWSET"})
#: Commands that end servo control when the backseat sends them (RH-INT-1, RH-MSN-3).
_ENDS_SERVO = frozenset({"OMP", "OJW", "OPK", "OMW", "OMSTOP", "OMSTART"})
_ID = re.compile(rb"\$([A-Z]+)[,*]")
_BODY_MEMORY = 1024  #: command texts remembered for the resend rule (bounded memory)


def line_budget(baud: int) -> int:
    """RH-BS-4: bytes a line drains in one second, 10 bits per byte (8N1)."""
    return baud // 10


def window_violations(arrivals: list[tuple[float, int]], budget: int, window: float = 1.0) -> bool:
    """Reference rule for RH-BS-4: is there a window ``[a, a + window)`` holding more than
    ``budget`` bytes? ``arrivals`` are (time, bytes) in time order. Quadratic; for tests."""
    for i, (ti, _) in enumerate(arrivals):
        total = sum(n for tj, n in arrivals[i:] if tj < ti + window)
        if total > budget:
            return True
    return False


@dataclass(frozen=True, slots=True)
class Piece:
    """One complete framing event from the backseat, with its exact bytes."""

    raw: bytes
    t: float  #: wall time its last byte arrived
    decoded: Optional[Decoded] = None  #: None for a discarded run (noise, torn, overlong)
    discard: Optional[Discard] = None

    @property
    def command(self) -> Optional[s.Command]:
        d = self.decoded
        return d.sentence if d is not None and isinstance(d.sentence, s.Command) else None


@dataclass(frozen=True, slots=True)
class Offence:
    """One offending sentence (or run of bytes) under one clause."""

    clause: str
    t: float
    dir: str  #: wire-log direction: ">" (a CR LF line) or ">~" (any other run)
    line: str  #: escaped as in the wire log
    reason: str
    scenario: str = ""

    def evidence(self) -> dict:
        return {"t": round(self.t, 6), "dir": self.dir, "line": self.line}


@dataclass
class ClauseResult:
    """The judgement of one clause: verdict word, reason, count and quoted evidence."""

    id: str
    verdict: str
    reason: str
    level: str
    offending_count: int = 0
    evidence: list[dict] = field(default_factory=list)
    cases: list[str] = field(default_factory=list)


@dataclass
class _Sent:
    """A command the vehicle will answer, waiting for its ``$ACK`` (RH-ACK-6: in order)."""

    ack_type: int
    sid: str
    body: str
    t: float
    piece: Piece
    timeout: Optional[int] = None  #: $OMS timeout (RH-BS-6)
    deferred: list = field(default_factory=list)  #: RH-BS-3 checks waiting for this ACK


def _wire(raw: bytes) -> tuple[str, str]:
    if raw.endswith(b"\r\n") and b"\n" not in raw[:-1]:
        return ">", escape(raw[:-2])
    return ">~", escape(raw)


class BackseatJudge:
    """Judges a backseat against RH-BS-1..8. See the module docstring."""

    def __init__(self, profile: Profile, *, time_scale: float = 1.0, reaction_s: float = 0.5,
                 jitter_s: float = 0.2, baud: Optional[int] = None):
        self.profile = profile
        self.time_scale = float(time_scale)
        self.reaction_s = reaction_s
        self.jitter_s = jitter_s
        self.baud = baud if baud is not None else profile.baud
        self.budget = line_budget(self.baud)
        self._framer = Framer(profile.max_line_bytes)
        self._vframer = Framer(max(profile.max_line_bytes, 1024))
        self._pending = bytearray()  # bytes of the backseat's unfinished event
        self._consumed = 0  # stream offset of _pending[0]
        self.scenario_name = ""
        self.started: Optional[float] = None
        self.ended: Optional[float] = None
        self.offences: dict[str, list[Offence]] = {c: [] for c in BS_CLAUSES}
        self.counts: dict[str, int] = {c: 0 for c in BS_CLAUSES}
        self.judged: dict[str, int] = {c: 0 for c in BS_CLAUSES}
        self.cases: dict[str, list[str]] = {c: [] for c in BS_CLAUSES}
        self.stats = {"bytes": 0, "lines": 0, "commands": 0, "rejections": 0, "lockouts": 0,
                      "polls": 0, "servo_accepted": 0}
        # RH-BS-4
        self._window: deque[tuple[float, int]] = deque()
        self._window_bytes = 0
        self.max_window_bytes = 0
        self._over_unclaimed = False
        # RH-BS-3 reported state: (t, running) changes
        self._reported: list[tuple[float, bool]] = []
        self._awaiting: deque[_Sent] = deque()
        # RH-BS-5
        self._lockout_active = False
        self._lockout_known: Optional[float] = None
        self._last_send: OrderedDict[str, float] = OrderedDict()
        self._rejected: dict[str, float] = {}  # body -> time the rejection went out
        # RH-BS-6
        self._servo: Optional[tuple[float, float]] = None  # (deadline, tolerance) wall
        # RH-BS-8
        self._last_poll: Optional[tuple[float, Optional[Piece]]] = None
        # vehicle facts
        self._silent = False
        self.reported_mode = ""

    # ================================================================ facts from the vehicle side
    def scenario(self, name: str, t: float) -> None:
        """The scenario being staged from ``t`` on (offences are tagged with it)."""
        self.scenario_name = name

    def silence(self, active: bool, t: float) -> None:
        """The vehicle stops (or resumes) answering; what the backseat sends meanwhile is lost."""
        self._silent = active
        if active:
            self._servo = None  # RH-BS-6 is not judged across a silence
            self._awaiting.clear()

    def lockout(self, active: bool, t: float) -> None:
        """The vehicle's safety lockout really starts or ends (RH-SAF-1, RH-RD-11)."""
        if active and not self._lockout_active:
            self._lockout_known = None
            self.stats["lockouts"] += 1
            self.judged["RH-BS-5"] += 1
            self._servo = None
        self._lockout_active = active

    # ================================================================ what the vehicle said
    def vehicle_bytes(self, data: bytes, t: float) -> None:
        """Bytes the vehicle sent the backseat at ``t``."""
        for ev in self._vframer.feed(data):
            if isinstance(ev, Line):
                self._vehicle_line(ev.raw, t)

    def _vehicle_line(self, raw: bytes, t: float) -> None:
        d = decode(raw, self.profile)
        r = d.sentence
        if isinstance(r, s.OSI):
            self.reported_mode = r.mode
            if r.mode in _RUNNING_MODES:
                self._report(t, True)
            elif r.mode == "S":
                self._report(t, False)
                self._servo = None
            if r.error_state != "N" and self._lockout_active and self._lockout_known is None:
                self._lockout_known = t
        elif isinstance(r, s.ACK):
            self._ack(r, t)

    def _report(self, t: float, running: bool) -> None:
        if not self._reported or self._reported[-1][1] != running:
            self._reported.append((t, running))
            if len(self._reported) > 4096:
                del self._reported[:2048]

    def _ack(self, a: s.ACK, t: float) -> None:
        if a.err == 26 and self._lockout_active and self._lockout_known is None:
            self._lockout_known = t
        if a.type == 3 and a.status == 0:
            self._report(t, True)
        elif a.type == 1 and a.status == 0:
            self._report(t, False)
            self._servo = None
        sent = None
        while self._awaiting:
            cand = self._awaiting.popleft()
            if cand.ack_type == a.type:
                sent = cand
                break
        if sent is None:
            return
        if a.status != 0:
            self.stats["rejections"] += 1
            # the first rejection of this text is when the backseat could start to know
            self._rejected.setdefault(sent.body, t)
            self.judged["RH-BS-5"] += 1
            if sent.sid == "OMS":
                self._servo = None
        else:
            self._rejected.pop(sent.body, None)
            if sent.sid == "OMS" and sent.timeout is not None:
                deadline, tol = self._servo_window(t, sent.timeout)
                if self._servo is not None and self._servo[0] > deadline:
                    deadline, tol = self._servo  # a later refresh is already on its way
                self._servo = (deadline, tol)
                self.stats["servo_accepted"] += 1
                self.judged["RH-BS-6"] += 1
        for piece, sid, need_running, at in sent.deferred:
            if a.status != 0:  # the start (stop) it relied on was refused: judge it as sent
                self._precondition(piece, sid, need_running, at, deferred=False)

    # ================================================================ what the backseat sent
    def backseat_bytes(self, data: bytes, t: float) -> list[Piece]:
        """Bytes from the backseat at ``t``; returns the framing events they completed."""
        if self.started is None:
            self.started = t
            self._last_poll = (t, None)
        self.stats["bytes"] += len(data)
        over = self._budget(len(data), t)
        out: list[Piece] = []
        events = self._framer.feed(data)
        self._pending += data
        for ev in events:
            end = ev.offset + (ev.length if isinstance(ev, Discard) else len(ev.raw))
            cut = end - self._consumed
            raw = bytes(self._pending[:cut])
            del self._pending[:cut]
            self._consumed = end
            piece = self._event(ev, raw, t)
            out.append(piece)
        if len(self._pending) > 65536:  # noise with no '$' in sight: hand it on, keep judging
            self._consumed += len(self._pending)
            out.append(Piece(bytes(self._pending), t))
            self._pending.clear()
        if over and not events:
            self._over_unclaimed = True
        return out

    def close(self, t: float) -> list[Piece]:
        """The run (or the link) ended at ``t``: pending bytes are a discarded run."""
        out: list[Piece] = []
        self._framer.close()  # a line cut short by the end of the run is nobody's fault
        if self._over_unclaimed:  # RH-BS-4: an over-budget second that completed no line
            self._claim_budget(t, bytes(self._pending[:self.profile.max_line_bytes]))
        if self._pending:
            out.append(Piece(bytes(self._pending), t))
            self._pending.clear()
        self.ended = t
        if self._last_poll is not None and self.started is not None:
            last_t, last_piece = self._last_poll
            if t - last_t > POLL_INTERVAL_S + self.jitter_s:
                raw = last_piece.raw if last_piece is not None else b""
                self._offend("RH-BS-8", last_t, raw,
                             f"no $OSD state poll in the last {t - last_t:.1f} s of the run "
                             f"(at most {POLL_INTERVAL_S:g} s apart)")
        return out

    def _event(self, ev, raw: bytes, t: float) -> Piece:
        if isinstance(ev, Discard):
            piece = Piece(raw, t, None, ev)
            self.judged["RH-BS-1"] += 1
            self._offend("RH-BS-1", t, raw, f"{ev.clause}: {ev.reason}")
            self._claim_budget(t, raw)
            return piece
        d = decode(raw, self.profile)
        piece = Piece(raw, t, d)
        self.stats["lines"] += 1
        self._claim_budget(t, raw)
        self._line(piece, d, t)
        return piece

    # ---------------------------------------------------------------- RH-BS-4
    def _budget(self, n: int, t: float) -> bool:
        """RH-BS-4: add ``n`` bytes at ``t``; True when the window (t-1, t] is over budget."""
        w = self._window
        w.append((t, n))
        self._window_bytes += n
        while w and w[0][0] <= t - 1.0:
            self._window_bytes -= w.popleft()[1]
        self.max_window_bytes = max(self.max_window_bytes, self._window_bytes)
        self._over_now = self._window_bytes > self.budget
        return self._over_now

    _over_now = False

    def _claim_budget(self, t: float, raw: bytes) -> None:
        """RH-BS-4: a sentence completed while its one-second window is over budget offends."""
        self.judged["RH-BS-4"] = 1
        if self._over_now or self._over_unclaimed:
            self._over_unclaimed = False
            self._offend("RH-BS-4", t, raw,
                         f"{self._window_bytes} bytes in the second up to this sentence; the line "
                         f"drains {self.budget} ({self.baud} baud / 10)")

    # ---------------------------------------------------------------- one line
    def _line(self, piece: Piece, d: Decoded, t: float) -> None:
        """RH-BS-1 (framing), RH-BS-2 (fields), RH-BS-7 (hex case, CR LF), then the behaviour
        rules for a well-formed command (RH-BS-3, RH-BS-5, RH-BS-6, RH-BS-8)."""
        raw = piece.raw
        self.judged["RH-BS-1"] += 1
        self.judged["RH-BS-7"] += 1
        for f in d.findings:  # RH-BS-7 (SHOULD): upper-case hex, CR LF
            self._offend("RH-BS-7", t, raw, str(f))
            break
        if d.error is not None:
            if d.error.kind == "framing":  # RH-BS-1, RH-FRM-*
                self._offend("RH-BS-1", t, raw, str(d.error))
            else:  # RH-BS-2: syntax or range
                self.judged["RH-BS-2"] += 1
                self._offend("RH-BS-2", t, raw, str(d.error))
            if d.error.answered and not self._silent:
                self._expect_ack(piece, d.error.sentence_id or "", d.error.ack_type, raw, t)
            m = _ID.match(raw)  # a damaged $OSD is still a poll attempt, not a command
            self._lockout_rule(piece, d.error.sentence_id or (m.group(1).decode() if m else ""), t)
            return
        cmd = d.sentence
        if not isinstance(cmd, s.Command):
            return  # a vehicle-side sentence: a vehicle ignores it (not a §9 matter)
        sid = cmd.ID
        if sid not in self.profile.commands and not isinstance(cmd, s.OXFLT):
            return
        self.stats["commands"] += 1
        self.judged["RH-BS-2"] += 1
        err = field_error(cmd, self.profile)
        if err is not None:
            self._offend("RH-BS-2", t, raw, f"${sid}: a field is out of range (the vehicle answers err {err})")
        self._lockout_rule(piece, sid, t)
        self._resend_rule(piece, cmd, t)
        self._servo_rule(piece, cmd, t)
        if sid in _NEED_RUNNING:
            self._precondition(piece, sid, True, t)
        elif sid in _NEED_STOPPED:
            self._precondition(piece, sid, False, t)
        if isinstance(cmd, s.OSD) and "S" in cmd.letters:
            self._poll(piece, t)
        if cmd.ACK_TYPE is not None and not self._silent:
            self._expect_ack(piece, sid, cmd.ACK_TYPE, raw, t,
                             timeout=cmd.timeout if isinstance(cmd, s.OMS) else None)

    def _expect_ack(self, piece: Piece, sid: str, ack_type: int, raw: bytes, t: float,
                    timeout: Optional[int] = None) -> None:
        body = raw.split(b"*", 1)[0].decode("latin-1")
        self._awaiting.append(_Sent(ack_type, sid, body, t, piece, timeout))
        if len(self._awaiting) > 4096:
            self._awaiting.popleft()

    # ---------------------------------------------------------------- RH-BS-3
    def _state_at(self, t: float) -> Optional[bool]:
        state = None
        for at, running in self._reported:
            if at > t:
                break
            state = running
        return state

    def _precondition(self, piece: Piece, sid: str, need_running: bool, t: float,
                      deferred: bool = True) -> None:
        """RH-BS-3: ``$OMS``/``$OJW``/``$OPK``/``$OMW`` only while the vehicle reports a running
        mission; ``$OLOGL``/``$ORWSET`` only while it reports none.

        Judged on what the vehicle reported at least ``reaction_s`` before the command arrived
        (and not since contradicted); a command sent behind an unanswered ``$OMSTART`` (or
        ``$OMSTOP``) is judged by that command's outcome. Nothing is judged before the vehicle
        first reported its state.
        """
        if deferred:
            starter = "OMSTART" if need_running else "OMSTOP"
            for sent in reversed(self._awaiting):
                if sent.sid == starter:
                    sent.deferred.append((piece, sid, need_running, t))
                    return
        before = self._state_at(t - self.reaction_s)
        if before is None:
            return
        self.judged["RH-BS-3"] += 1
        if before == need_running:
            return
        for at, running in self._reported:
            if t - self.reaction_s < at <= t and running == need_running:
                return
        if need_running:
            why = f"${sid} sent while the vehicle reported no running mission"
        else:
            why = f"${sid} sent while the vehicle reported a running mission (only before a start)"
        self._offend("RH-BS-3", t, piece.raw, why)

    # ---------------------------------------------------------------- RH-BS-5
    def _lockout_rule(self, piece: Piece, sid: str, t: float) -> None:
        """RH-BS-5 (SHOULD): during a lockout the backseat sends nothing but ``$OSD``, from
        ``reaction_s`` after the vehicle first showed it (a safety code in ``$OSI`` field 8 or
        an ``$ACK`` with err 26) until the lockout really ends."""
        if not self._lockout_active or self._lockout_known is None or sid == "OSD":
            return
        if t >= self._lockout_known + self.reaction_s:
            self._offend("RH-BS-5", t, piece.raw,
                         f"${sid or '?'} sent during the safety lockout (only $OSD is allowed)")

    def _resend_rule(self, piece: Piece, cmd: s.Command, t: float) -> None:
        """RH-BS-5 (SHOULD): once a command was rejected (status 1) and the backseat had
        ``reaction_s`` to see it, the same command text is not sent again sooner than 1 s
        (less ``jitter_s``) after its previous sending."""
        body = piece.raw.split(b"*", 1)[0].decode("latin-1")
        prev = self._last_send.get(body)
        rejected_at = self._rejected.get(body)
        if (prev is not None and rejected_at is not None and t >= rejected_at + self.reaction_s
                and t - prev < RESEND_SPACING_S - self.jitter_s):
            self._offend("RH-BS-5", t, piece.raw,
                         f"${cmd.ID} resent {t - prev:.2f} s after the same command, which the "
                         f"vehicle had rejected (at most once per second)")
        self._last_send[body] = t
        self._last_send.move_to_end(body)
        if len(self._last_send) > _BODY_MEMORY:
            old, _ = self._last_send.popitem(last=False)
            self._rejected.pop(old, None)

    # ---------------------------------------------------------------- RH-BS-6
    def _servo_rule(self, piece: Piece, cmd: s.Command, t: float) -> None:
        """RH-BS-6 (SHOULD): an ``$OMS`` that follows an accepted ``$OMS`` after that one's
        timeout ran out (``timeout / time_scale`` wall seconds after its ACK — or after a later
        refresh arrived in time — plus the RH-TIM-1 tolerance and ``jitter_s``) came too late:
        servo control had lapsed. Another control
        command, a stop or start, a reported stop, a rejection, a lockout or a silence ends
        the tracking (the backseat then no longer holds servo control by its own choice)."""
        sid = cmd.ID
        if sid in _ENDS_SERVO:
            self._servo = None
            return
        if sid != "OMS" or self._servo is None:
            return
        deadline, tol = self._servo
        if t > deadline + tol:
            self._offend("RH-BS-6", t, piece.raw,
                         f"$OMS refresh {t - deadline:.2f} s after the previous one's timeout ran out "
                         f"(servo control had lapsed)")
            self._servo = None
        elif isinstance(cmd, s.OMS):  # in time: the vehicle restarts its timeout (RH-SRV-3)
            self._servo = max(self._servo, self._servo_window(t, cmd.timeout))

    def _servo_window(self, t: float, timeout: int) -> tuple[float, float]:
        """Wall deadline and tolerance of a servo timeout restarted at ``t`` (RH-TIM-1/2)."""
        tol = max(0.5, 0.05 * timeout) / self.time_scale + self.jitter_s
        return t + timeout / self.time_scale, tol

    # ---------------------------------------------------------------- RH-BS-8
    def _poll(self, piece: Piece, t: float) -> None:
        """RH-BS-8 (SHOULD): ``$OSD`` with ``S`` at most 5 s (plus ``jitter_s``) apart while
        the backseat is active (from its first byte to the end of the run)."""
        self.stats["polls"] += 1
        self.judged["RH-BS-8"] += 1
        if self._last_poll is not None:
            last_t = self._last_poll[0]
            if t - last_t > POLL_INTERVAL_S + self.jitter_s:
                self._offend("RH-BS-8", t, piece.raw,
                             f"state poll {t - last_t:.1f} s after the previous one (at most "
                             f"{POLL_INTERVAL_S:g} s apart)")
        self._last_poll = (t, piece)

    # ================================================================ bookkeeping
    def _offend(self, clause: str, t: float, raw: bytes, reason: str) -> None:
        self.counts[clause] += 1
        if self.scenario_name and self.scenario_name not in self.cases[clause]:
            self.cases[clause].append(self.scenario_name)
        if len(self.offences[clause]) < EVIDENCE_LIMIT:
            direction, text = _wire(raw)
            self.offences[clause].append(Offence(clause, t, direction, text, reason, self.scenario_name))

    def violated(self, clause: str) -> bool:
        return self.counts[clause] > 0

    def results(self, levels: dict[str, str]) -> list[ClauseResult]:
        """One :class:`ClauseResult` per §9 clause. ``levels`` maps clause ID to MUST/SHOULD."""
        out = []
        for cid in BS_CLAUSES:
            level = levels[cid]
            n = self.counts[cid]
            ev = [o.evidence() for o in self.offences[cid]]
            cases = list(self.cases[cid])
            if n:
                verdict = "fail" if level == "MUST" else "non-strict"
                first = self.offences[cid][0]
                more = f" (and {n - 1} more)" if n > 1 else ""
                reason = f"{n} offending sentence(s); first at {first.t:.3f} s: {first.reason}{more}"
            elif self.judged[cid]:
                verdict, reason = "pass", _PASS[cid](self)
            else:
                verdict, reason = "not-tested", _NOT_TESTED[cid]
            out.append(ClauseResult(cid, verdict, reason, level, n, ev, cases))
        return out


_PASS = {
    "RH-BS-1": lambda j: f"all {j.stats['lines']} line(s) were well framed with a correct checksum",
    "RH-BS-2": lambda j: f"every field of {j.stats['commands']} command(s) was within its range",
    "RH-BS-3": lambda j: f"{j.judged['RH-BS-3']} state-bound command(s) respected what the vehicle reported",
    "RH-BS-4": lambda j: (f"at most {j.max_window_bytes} bytes in any second; the line drains "
                          f"{j.budget} ({j.baud} baud / 10)"),
    "RH-BS-5": lambda j: (f"reacted properly to {j.stats['rejections']} rejection(s) and "
                          f"{j.stats['lockouts']} lockout(s)"),
    "RH-BS-6": lambda j: f"every $OMS refresh came before the previous timeout ({j.stats['servo_accepted']} accepted)",
    "RH-BS-7": lambda j: "every line used upper-case checksum hex and CR LF",
    "RH-BS-8": lambda j: f"{j.stats['polls']} state poll(s), never more than {POLL_INTERVAL_S:g} s apart",
}
_NOT_TESTED = {
    "RH-BS-1": "the backseat sent no line",
    "RH-BS-2": "the backseat sent no well-framed command",
    "RH-BS-3": "no $OMS/$OJW/$OPK/$OMW/$OLOGL/$ORWSET was sent while the vehicle's state was known",
    "RH-BS-4": "the backseat sent nothing",
    "RH-BS-5": "no command was rejected and no lockout occurred",
    "RH-BS-6": "the backseat never held servo control ($OMS accepted)",
    "RH-BS-7": "the backseat sent no line",
    "RH-BS-8": "the backseat was never active",
}
