"""The mirror: every state a conforming vehicle may be in, given everything seen on the wire.

:class:`Beliefs` holds a small set of :class:`~.candidate.Candidate` s (reference models plus
what was adopted to explain the wire), most plausible first (fewest unseen events). Two inputs:

* :meth:`Beliefs.command` — a command the vehicle answered, at the vehicle time its ACK went out
  (RH-RD-15; vehicle time is wall time × the declared time scale, RH-TIM-2). Each candidate
  answers it in every state it may have met it in (:mod:`.branches`): nominally and, when the
  command lands within the RH-TIM-1 tolerance of a model timer, on both sides of the race (also of
  a timer the model already ran: from its checkpoint, the state before it); an accepted ``$OPK``
  also with its countdown waiting for on station (RH-PK-2: where the vehicle is at the ACK, no
  report settles); before a command that freezes the mission (RH-INT-1) a candidate in ``N`` also
  offers the state where the next waypoint was reached unseen just before it, where it can have
  got there (:func:`~.closure.reachable`); an ``$OSD`` that every candidate can only have met
  in one state is answered in place, not on copies (it changes no state; ``_poll``). The
  candidates whose answer is the vehicle's survive.
  When none does, unseen events that change the answer are tried (:func:`~.closure.explain_reply`,
  for every candidate);
  when that fails too, the answer is a finding, and the observer follows the nominal state marked
  *desynchronised* until a state that is known again (an accepted ``$OMSTOP`` or ``$OMSTART``).
* :meth:`Beliefs.osi` — an ``$OSI`` produced between ``v_sent`` and ``v_recv``. The candidates
  that explain it survive (:meth:`~.candidate.Candidate.check`, the RH-TIM-1 shadows of
  :mod:`helmcheck.model.observe`); when none does, unseen plant events are adopted
  (:func:`~.closure.explain_osi`); when that fails, it is a finding. The surviving candidates are
  brought to ``v_sent`` and *confirmed*: the rows they applied since the last ``$OSI`` have been
  seen to take effect (their clauses pass), timer transitions get their RH-TIM-1 bracket
  (:class:`~.candidate.Timed`, :mod:`.brackets`), and the ``$OSI``'s position, speed and depth
  become the plant snapshot (GPS fix and surface rules, ``$OPK`` distance) — not the depth during
  the ascent, where reaching the surface is an event to be adopted.

An accepted command that changes the mode is *unconfirmed* until the next ``$OSI``: nothing on the
wire shows yet that the vehicle carried it out. When the next command's answer is one no candidate
gives but the state before that command gives (``$OMSTOP,0`` accepted, then an ``$OLOGL`` refused
as a running vehicle refuses it), the evidence names two faults, either of which explains it: the
answer, or the command before it not carried out. :attr:`CommandResult.ignored` says so, and the
next report tells them apart (:attr:`OsiResult.ignored`: whether the state of a vehicle that did
not carry it out explains that report).

Decision (spec open): at most :data:`CAP` candidates are kept; beyond, the least plausible go.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Optional

from ...grammar import sentences as s
from ...grammar.errors import SentenceError
from ...model.readings import taken as taken_readings
from ...model.timers import tolerance
from ...model.transitions import INTERNAL_EVENTS, REMOTE_MODES, STAY, rows_for
from ...model.vehicle import VehicleModel
from ...profile import Profile
from ..facts import ASCENT_REFUSED, LOCKOUT_REFUSED
from .brackets import bracket, pre_shown, retime
from .branches import branches
from .candidate import Candidate
from .closure import VERTICAL_MPS, explain_osi, explain_reply, osi_depth_m, osi_numbers, reply_keys
from .sent import brief

__all__ = ["Beliefs", "CommandResult", "OsiResult", "CAP"]

CAP = 6
#: Commands that may set a timer going when accepted (their ACK instant's uncertainty is the
#: timer's, :attr:`Beliefs.arm_v`); a refused one, or any other, sets none going.
_ARMING = frozenset({s.OMS, s.OMP, s.OPK, s.OMW, s.ODVL, s.OJW, s.OMSTART, s.OMSTARTPaper, s.OXFLT})
#: Command events the lockout refuses (err 26) and the ascent does not: their answer tells them apart.
_LOCK_ONLY = LOCKOUT_REFUSED - ASCENT_REFUSED


@dataclass(slots=True)
class CommandResult:
    """What the mirror made of one answered command."""

    expected: list  #: the replies of the explanation chosen (the nominal ones when none)
    matched: bool
    row: object = None  #: the table row the command met (None for a malformed command)
    before: tuple = ("", "")  #: (mode, phase) of the chosen state just before the command
    adopted: tuple = ()  #: unseen events adopted to explain the answer
    mission_dependent: bool = False  #: the answer depends on mission files the observer lacks
    desync: str = ""  #: why the state was already unknown (findings are then INCONCLUSIVE)
    timings: list = field(default_factory=list)  #: (Timed, verdict, reason): the lockout's end
    #: (command, row, ACK) of the accepted command before this one, with no report between, whose
    #: not being carried out explains this answer too (module docstring); () when none does
    ignored: tuple = ()
    #: the readings of the profile's open questions the chosen state took to explain the answer
    reading: tuple = ()


@dataclass(slots=True)
class OsiResult:
    """What the mirror made of one ``$OSI``."""

    findings: list = field(default_factory=list)  #: (clause, message) when nothing explains it
    passes: set = field(default_factory=set)  #: clauses whose effect this $OSI confirmed
    timings: list = field(default_factory=list)  #: (Timed, verdict, reason)
    adopted: tuple = ()
    desync: str = ""
    causes: tuple = ()  #: clauses of what changed since the last confirmed report (for blame)
    #: the clause whose rule the report itself shows broken, booked even inside another clause's case
    #: (that case's subject named as related): a remote control back after a lockout that refused
    #: commands is RH-SAF-2's ("no effect even after the lockout ends"), not the lockout's own
    diagnosis: tuple = ()
    own: set = field(default_factory=set)  #: clauses this report passes by their own evidence
    #: after a :attr:`CommandResult.ignored` answer: whether the state of a vehicle that did not
    #: carry out the command before it explains this report (None: no such question)
    ignored: Optional[bool] = None


class Beliefs:
    """The candidate set (module docstring)."""

    def __init__(self, profile: Profile, catalog, k: float):
        self.profile = profile
        self.catalog = catalog
        self.k = k
        self.cands: list[Candidate] = [Candidate(VehicleModel(profile, catalog))]
        #: why the vehicle's state is not known (findings are INCONCLUSIVE until it is again)
        self.desync = "the record begins with the vehicle's state unknown"
        #: vehicle seconds: the widest window in which an accepted command that may arm a timer
        #: (:data:`_ARMING`) went into effect since the state was last known (RH-RD-15: its ACK
        #: going out, which the ACK's arrival less the replies' transmit time bounds). A refused
        #: command, an ``$OSD`` or any other arms nothing: their answers' timing widens nothing.
        self.arm_v = 0.0
        #: the last ``$OSI`` and the vehicle second it arrived (its depth is read only when needed)
        self.last_osi: Optional[tuple[s.OSI, float]] = None
        #: (the primary candidate before it, command, row, ACK) of the last accepted command that
        #: changed the mode, while no report has come since (module docstring)
        self.unconfirmed: Optional[tuple] = None
        #: the state of a vehicle that did not carry that command out, after the answer it explains
        self.ignoring: Optional[Candidate] = None

    @property
    def primary(self) -> Candidate:
        return self.cands[0]

    def _reported_depth(self) -> Optional[float]:
        """The depth the last ``$OSI`` showed, metres (None: none, or no depth in it)."""
        if self.last_osi is None:
            return None
        return osi_depth_m(self.last_osi[0], self.profile.depth_unit)

    # ------------------------------------------------------------------ commands
    def command(self, item, v: float, slack_v: float, observed: list) -> CommandResult:
        """Feed an answered command (module docstring); ``observed`` is the vehicle's replies."""
        desync = self.desync
        ack = observed[-1] if observed and isinstance(observed[-1], s.ACK) else None
        if type(item) in _ARMING and (ack is None or ack.status == 0):
            self.arm_v = max(self.arm_v, slack_v)  # it may have set a timer going (RH-RD-15)
        if type(item) is s.OSD:
            result = self._poll(item, v, slack_v, observed, desync)
            if result is not None:
                return result
            prev = self.unconfirmed
        else:
            prev, self.unconfirmed, self.ignoring = self.unconfirmed, None, None
        before = None
        if type(item) is not s.OSD and not isinstance(item, SentenceError):
            r = self.cands[0].model.row_for(item)
            if r is not None and r.error is None and (r.target != STAY or r.phase_to is not None):
                before = self.cands[0].clone()  # the state it leaves, until a report confirms it
        options = []
        for c in self.cands:
            options += branches(c, item, v, slack_v, self.catalog)
        nominal = options[0]
        got = reply_keys(observed)
        match = [o for o in options if reply_keys(o[1]) == got]
        if match:
            base = len(self.cands[0].story)
            took = len(self.cands[0].took)
            self._keep([o[0] for o in match])
            chosen = match[0]
            result = CommandResult(chosen[1], True, chosen[2], chosen[3], chosen[0].story[base:], False, desync)
            sid = getattr(item, "ID", None) or getattr(item, "sentence_id", None) or ""
            result.reading = chosen[0].took[took:] or taken_readings(sid, chosen[0].model.readings)
        else:
            explanations = []  # each candidate's own (they may differ in what no report shows yet)
            for c in self.cands:
                tp = c.seen_v if c.seen_v is not None else (c.model.now or v)
                got = explain_reply(c, item, v, observed, tp, self.catalog, self.profile.gps_fix_depth_m,
                                    reported_depth=self._reported_depth())
                if got is not None:
                    explanations.append(got)
            if explanations:
                cand, replies, mission_dep = explanations[0]
                base = len(self.cands[0].story)
                self._keep([e[0] for e in explanations])
                result = CommandResult(replies, True, nominal[2], nominal[3], cand.story[base:], mission_dep,
                                       desync)
            else:
                result = CommandResult(nominal[1], False, nominal[2], nominal[3], (), False, desync)
                if prev is not None:
                    result.ignored = self._ignored(prev, item, v, observed)
                want = nominal[1][-1] if nominal[1] and isinstance(nominal[1][-1], s.ACK) else None
                got = observed[-1] if observed and isinstance(observed[-1], s.ACK) else None
                if got is not None and got.status == 1:
                    pass  # refused (rightly or not): a refused command changes nothing (RH-ACK-3)
                elif want is not None and want.status == 0:
                    self._keep([nominal[0]])  # accepted as it should be; only its data differ
                else:  # accepted where a conforming vehicle refuses: its state is now unknown
                    self._keep([nominal[0]])
                    if (not desync and want is not None and want.err == 26 and nominal[3] == ("M", "ascent")
                            and self._surface_reachable(v)):
                        # the $OMP that holds the depth defers the surface (RH-RD-12), but the vehicle
                        # may have reached it before that $OMP: the mirror does not replay the two in
                        # that order, so the answer cannot be judged
                        desync = ("in the ascent the vehicle may have reached the surface before the $OMP "
                                  "that holds its depth (RH-RD-12), which the observer does not replay")
                        result.desync = desync
                        self.desync = desync
                    if not self.desync:
                        self.desync = (f"the vehicle answered {brief(observed)} where a conforming "
                                       f"vehicle answers {brief(nominal[1])}")
        self._after_command(item, observed, v, slack_v, result)
        ack = observed[-1] if observed and isinstance(observed[-1], s.ACK) else None
        row = result.row
        if (before is not None and result.matched and ack is not None and ack.status == 0 and row is not None
                and (row.target != STAY or row.phase_to is not None)):
            self.unconfirmed = (before, item, row, ack)
        return result

    def _ignored(self, prev: tuple, item, v: float, observed: list) -> tuple:
        """(command, row, ACK) of ``prev`` (:attr:`unconfirmed`) when the state before it answers
        ``item`` as the vehicle did (the vehicle may not have carried it out); else ()."""
        before, cmd, row, ack = prev
        c = before.clone()
        c.model.advance(v)
        replies = c.model.receive(item, v)
        c.drain()
        if reply_keys(replies) != reply_keys(observed):
            return ()
        self.ignoring = c
        return (cmd, row, ack)

    def _poll(self, item: s.OSD, v: float, slack_v: float, observed: list, desync: str
              ) -> Optional[CommandResult]:
        """:meth:`command` for an ``$OSD`` that every candidate can only have met in one state:
        no timer of its model runs by ``v`` or races it (RH-TIM-1), none it already ran does
        (:func:`~.branches.branches` offers no other side), and an ``$OSD`` changes no state (a
        row that stays, no phase change; its data are answered by class name). Each candidate
        then answers it in place — what :func:`~.branches.branches` does on a copy of it, the
        same state, without copying every candidate at every poll. ``None`` (every candidate
        as it was) when that does not hold or no answer is the vehicle's: the general path."""
        cands = self.cands
        for c in cands:
            m = c.model
            due = m.timers.due
            if due is not None and (due <= v or abs(due - v) <= tolerance(m.timer()[1], slack_v + c.extra_v)):
                return None
            if m.checkpoint is not None and c.timed:
                fired = c.timed[-1]
                if 0.0 <= v - fired.deadline <= tolerance(fired.duration, slack_v + c.extra_v):
                    return None
        got = None
        saved, options, match = [], [], []
        for c in cands:
            m = c.model
            saved.append((m.now, m._pending, m.last_row, len(m.trace)))
            m.advance(v)
            before = (m.mode, m.phase)
            row = m.row_for(item)
            replies = m.receive(item, v)
            options.append((c, replies, row, before))
            # equal replies have equal keys; only unequal ones need their keys compared
            if replies == observed or reply_keys(replies) == (got if got is not None else
                                                              (got := reply_keys(observed))):
                match.append(options[-1])
        if not match:
            for c, (now, pending, last_row, n) in zip(cands, saved):
                m = c.model
                m.now, m._pending, m.last_row = now, pending, last_row
                del m.trace[n:]
            return None
        base = len(cands[0].story)
        self._keep([o[0] for o in match])
        chosen = match[0]
        result = CommandResult(chosen[1], True, chosen[2], chosen[3], chosen[0].story[base:], False, desync)
        self._after_command(item, observed, v, slack_v, result)
        return result

    def unanswered(self, item, v: float) -> list:
        """A command the vehicle has processed — a later one is being answered (RH-ACK-6) — but not
        answered (yet): it may have acted on it, or dropped it. Both stay candidates (acted on
        first: a vehicle acts on every command it reads); returns the replies a conforming
        vehicle owes it."""
        out, replies = [], []
        for c in self.cands:
            t = c.clone()
            t.model.advance(v)
            got = t.model.receive(item, v)
            t.drain()
            if not replies:
                replies = got
            out += [t, c]
        self._keep(out)
        return replies

    def _after_command(self, item, observed: list, v: float, slack_v: float, result: CommandResult) -> None:
        """Bookkeeping after an answered command: the trace, the lockout's evidence (RH-SAF-1:
        an err 26 to a command only the lockout refuses is the lockout seen; any other answer to
        one, the lockout over), a known state again after ``$OMSTOP``/``$OMSTART``."""
        ack = observed[-1] if observed and isinstance(observed[-1], s.ACK) else None
        for c in self.cands:
            c.drain()
        if ack is None:
            return
        if ack.status == 0 and isinstance(item, (s.OMSTOP, s.OMSTART, s.OMSTARTPaper)):
            self.desync = ""
            self.arm_v = slack_v
        event = VehicleModel.event_of(item) if not isinstance(item, SentenceError) else None
        if event is None and isinstance(item, SentenceError) and item.ack_type is not None:
            from ...model.transitions import EVENT_OF_ACK_TYPE
            event = EVENT_OF_ACK_TYPE.get(item.ack_type)
        telling = event in _LOCK_ONLY
        for c in self.cands:
            m = c.model
            if ack.err == 26 and m.phase == "lockout":
                c.refused_locked = True
                if telling:
                    c.locked_v = v
            elif telling and ack.err != 26:
                for tt in list(c.timed):
                    if tt.timer == "lockout":
                        c.timed.remove(tt)
                        if c is self.cands[0]:
                            result.timings.append(bracket(tt, v, slack_v))

    def _keep(self, cands: list[Candidate]) -> None:
        if len(cands) == 1:
            self.cands = cands
            return
        seen: dict = {}
        for c in sorted(cands, key=lambda c: c.events):
            key = c.signature()
            if key not in seen:
                seen[key] = c
        self.cands = list(seen.values())[:CAP]

    # ------------------------------------------------------------------ $OSI
    def osi(self, osi: s.OSI, v_sent: float, v_recv: float, slack_v: float) -> OsiResult:
        """Judge an ``$OSI`` produced in ``[v_sent, v_recv]`` (module docstring)."""
        v = (v_sent + v_recv) / 2
        slack = (v_recv - v_sent) / 2 + slack_v + self.arm_v
        self.last_osi = (osi, v_recv)
        self.unconfirmed = None
        ignoring, self.ignoring = self.ignoring, None
        ignored = None if ignoring is None else not ignoring.check(osi, v, slack)
        for c in self.cands:
            if c.code_unknown and osi.error_state != "N" and c.model.phase != "none":
                c.model.error_state = osi.error_state
                c.code_unknown = False
        if self.desync and self._adopt(osi, v_sent):
            self.desync = ""
        explained = [c for c in self.cands if not c.check(osi, v, slack)]
        result = OsiResult(desync=self.desync, ignored=ignored)
        if not explained:
            fix = self.profile.gps_fix_depth_m
            for c in self.cands:
                tp = c.seen_v if c.seen_v is not None else (c.model.now or v_sent)
                got = explain_osi(c, osi, v, slack, tp, self.catalog, fix, self.profile.depth_unit)
                if got is not None:  # each candidate's own explanation: they differ in what no
                    explained.append(got)  # report shows (a mission frozen in N or in P)
                    result.adopted = result.adopted or got.story[len(c.story):]
        if not explained:
            p = self.primary
            result.findings = p.check(osi, v, slack)
            if not self.desync:
                self.desync = f"an $OSI no conforming state explains ({result.findings[0][1]})"
            if p.model.now is None or v_sent > p.model.now:
                p.model.advance(v_sent)
            p.drain()
            rows = list(p.pending)
            if osi.mode != p.model.mode:
                # a wrong mode: the rows that set a mode since the last report, latest first, are
                # what the vehicle got wrong (a lockout's start or end changes no mode)
                setters = [row for row in reversed(rows) if row.target != STAY]
                # then an internal transition open to the model now that gives the reported mode
                # under another guard (at the surface: park instead of the SRP, RH-SAF-4); not a
                # violation when field 8 shows no new code (it always shows it, RH-SAF-1)
                m = p.model
                opened = [row for ev in INTERNAL_EVENTS for row in rows_for(m.mode, m.phase, ev)
                          if row.target == osi.mode and row not in setters
                          and (ev != "violation" or osi.error_state != m.error_state)]
                # a control left early after it was updated: the restart the update owed (RH-RD-3)
                if opened:
                    setters += [row for row in p.refresh if row not in setters]
                setters += opened
                rows = setters + [row for row in rows if row not in setters]
            # a timer due within the report's uncertainty may have run on the vehicle: what it does
            # is blamed too, last (a release reported a little before the observer's deadline)
            ahead = []
            due = p.model.timer()
            if due is not None and due[0] <= v + tolerance(due[1], slack):
                t = p.clone()
                t.model.advance(due[0])
                t.drain()
                ahead = [row for row in t.pending if row not in p.pending]
            causes = [c for row in rows for c in row.clauses]
            causes += [c for tt in p.timed for c in tt.row.clauses]
            causes += [c for row in ahead for c in row.clauses]
            released = any("RH-INT-2" in row.clauses for row in p.pending + ahead)
            if released and "opk" in p.abandoned:
                causes.insert(0, "RH-INT-3")  # the interrupted park came back: not abandoned
            if released and "queue" in p.abandoned:
                causes.insert(0, "RH-OMW-5")
            released_from = {src for row in p.pending + ahead if "RH-INT-2" in row.clauses for src in row.sources}
            if released and osi.mode in _REMOTE and osi.mode not in released_from:
                # another remote control came back after the release: there is no stack of remote
                # controls (RH-INT-1), after the interrupted kind's own clause
                at = sum(1 for c in causes[:2] if c in ("RH-INT-3", "RH-OMW-5"))
                causes.insert(at, "RH-INT-1")
            elif released and osi.mode in released_from and _release_last(p.pending + ahead):
                # still in the remote control the release ends, and nothing took control after it:
                # the trigger's clause (the timeout, $OMW,Clr, the queue done, the park time up) is
                # what failed; RH-INT-2, what the vehicle resumes once control ends, is not yet in
                # question
                causes = [c for c in causes if c != "RH-INT-2"]
            elif (released and osi.mode == p.model.mode and osi.mode not in _REMOTE
                  and all(f.field in _RESUMED for f in result.findings)):
                # released into the behaviour it should resume — as the trigger's clause says,
                # also where it says the mission resumes (RH-PK-3, RH-OMW-4) — but toward another
                # waypoint or with another park time left: RH-INT-2's alone. (Released into another
                # mode breaks both where the trigger's clause says the mission resumes: both stay.)
                causes.insert(0, "RH-INT-2")
            m = p.model
            if m.mode == "N" and m.mission is not None and osi.mode != "S" and (
                    (not m.mission.is_open and m.mission_wp == m.mission.last)
                    or (osi.mode == "N" and osi.next_waypoint < m.mission_wp)):
                # on the way to the last waypoint (or, in a mission of unknown length, seen going
                # back to an earlier one, as a mission that did not end at its last would): the
                # end it owes there
                causes.append("RH-MSN-4")
            if p.refused_locked and (p.model.phase != "lockout" or any(r.event == "lockout_end" for r in ahead)):
                # a command refused in the lockout, and the lockout over (or ending within the
                # tolerance before this report): what changed may be that command, carried out
                causes.insert(0, "RH-SAF-2")
                if osi.mode in _REMOTE and osi.mode != p.model.mode:
                    result.diagnosis = ("RH-SAF-2",)
            if osi.mode == p.model.mode:  # the mode is right: a countdown is what differs
                causes += {"mP": ["RH-PK-2"], "W": ["RH-OMW-4"]}.get(osi.mode, [])
            if (p.resumed and osi.mode == p.model.mode == "P"
                    and all(f.field == "park_time" for f in result.findings)):
                causes.insert(0, "RH-INT-2")  # a park resumed after remote control: its time left
            if p.timed or any(tt for tt in (p.model.timer(),) if tt is not None and abs(tt[0] - v) <= 2 * tt[1]):
                causes += ["RH-TIM-1", "RH-TIM-2"]  # a duration was being timed around this report
            result.causes = tuple(dict.fromkeys(c for c in causes if c != "RH-OUT-4"))
            self._confirm(p, osi, v_sent, v_recv, slack_v, passes=None, own=set())
            return result
        self._keep(explained)
        for i, c in enumerate(self.cands):
            own: set = set()
            got = self._confirm(c, osi, v_sent, v_recv, slack_v + self.arm_v,
                                passes=result.timings if i == 0 else [], own=own)
            if i == 0:  # what the most plausible state says was seen to happen
                result.passes, result.own = got, own
        if osi.mode == "S" and osi.error_state == "N" and self.primary.model.mode == "S":
            self.desync = ""
        return result

    def _surface_reachable(self, v: float) -> bool:
        """Whether the vehicle may have reached the GPS-fix depth (RH-RD-10) by ``v``, rising at most
        :data:`~.closure.VERTICAL_MPS` from the depth the last report showed (unknown: it may)."""
        if self.last_osi is None:
            return True
        osi, at = self.last_osi
        depth = osi_depth_m(osi, self.profile.depth_unit)
        return depth is None or depth - VERTICAL_MPS * max(0.0, v - at) <= self.profile.gps_fix_depth_m

    def _adopt(self, osi: s.OSI, v: float) -> bool:
        """While the state is unknown: take it from an ``$OSI`` that shows it whole — ``S``, or a
        mission running (``N``, ``P``) with no remote control and no safety episode. What a
        report does not show (set-points, timers of remote control, settings) is not needed in
        those states; the mission is looked up by field 12's name (unknown names: known by name
        from now on). Returns whether a state was adopted."""
        if osi.error_state != "N" or osi.mode not in ("S", "N", "P"):
            return False
        old = self.primary.model
        m = VehicleModel(self.profile, self.catalog)
        m.settings, m.log_labels, m.loaded = old.settings, old.log_labels, old.loaded
        m.now = v
        if osi.mode in ("N", "P"):
            name = osi.mission_name or self.profile.mission
            found = self.catalog.lookup(name)
            if not hasattr(found, "waypoints"):
                self.catalog.learn_present(name)
                found = self.catalog.lookup(name)
            if not hasattr(found, "waypoints") or osi.next_waypoint >= len(found.waypoints):
                return False
            m.mission = m.loaded = found
            m.mission_wp = osi.next_waypoint
            m.mission_mode = m.mode = osi.mode
            if osi.mode == "P":
                m.timers.arm("park", v, float(osi.park_time))
        self.cands = [Candidate(m)]
        if osi.mode == "P":
            self.cands[0].adopted("the mission park's time as the first report shows it", v - 1.0, v)
        return True

    def _confirm(self, c: Candidate, osi: s.OSI, v_sent: float, v_recv: float, slack_v: float,
                 passes: Optional[list], own: set) -> set:
        m = c.model
        if m.now is None or v_sent > m.now:
            m.advance(v_sent)
        c.drain()
        out: set = set()
        for tt in list(c.timed):
            shown = pre_shown(tt, osi)
            if shown is None:
                continue
            if shown:
                tt.t_old = v_sent
                continue
            c.timed.remove(tt)
            if passes is not None:
                passes.append(bracket(tt, v_recv, slack_v))
        released = False
        if osi.mode == m.mode:  # the rows' effect is visible (a report still showing the state
            for row in c.pending:  # before a timer, within its tolerance, confirms nothing yet)
                out.update(row.clauses)
                if "RH-INT-2" in row.clauses and row.event not in ("violation",):
                    released = True
            c.pending = []
        if released and m.mode not in ("mP", "W", "A", "M"):
            if "opk" in c.abandoned and osi.mode != "mP":
                own.add("RH-INT-3")
            if "queue" in c.abandoned and osi.mode != "W":
                own.add("RH-OMW-5")
            c.abandoned.clear()
        if c.refused_locked and m.phase != "lockout":
            own.add("RH-SAF-2")
            c.refused_locked = False
        self._plant(c, osi)
        c.saw(v_sent, osi.mode)
        retime(c, osi, v_sent, v_recv, slack_v)
        c.lapse_uncertainty()
        if not c.timed:
            m.drop_checkpoint()
        return out

    def _plant(self, c: Candidate, osi: s.OSI) -> None:
        """The ``$OSI``'s measured values become the candidate's plant snapshot."""
        m = c.model
        lat, lon, speed = osi_numbers(osi)[:3]
        depth = osi_depth_m(osi, self.profile.depth_unit)
        if depth is not None and m.phase == "ascent":
            depth = None
        snap = m.snapshot
        if ((lat is not None and snap.lat != lat) or (lon is not None and snap.lon != lon)
                or (speed is not None and snap.speed_kn != speed) or (depth is not None and snap.depth_m != depth)):
            # (a field the report does not show readably leaves the plant's value as it was)
            changes = {k: x for k, x in (("lat", lat), ("lon", lon), ("speed_kn", speed), ("depth_m", depth))
                       if x is not None}
            m.update_plant(snap.with_(**changes))
            c.drain()


#: the modes of remote-helm control (RH-INT-1)
_REMOTE = frozenset(REMOTE_MODES)


def _release_last(rows) -> bool:
    """Whether the last of ``rows`` that sets a mode is a release (RH-INT-2): no control was taken
    again after it (an ``$OMS`` after ``$OMW,Clr`` leaves the vehicle in ``A`` again)."""
    last = next((row for row in reversed(rows) if row.target != STAY), None)
    return last is not None and "RH-INT-2" in last.clauses


#: The report fields RH-INT-2 sets besides the mode: the next waypoint, the park time left.
_RESUMED = frozenset({"next_waypoint", "park_time"})


def finite(x: Optional[float]) -> bool:
    return x is not None and math.isfinite(x)
