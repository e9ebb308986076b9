"""The I/O loop of ``certify backseat``: one link, the reference vehicle, the recorder, the plan.

This module owns the clock, the descriptors and the recording; the vehicle's behaviour is the
emulator core's (:class:`~helmcheck.emulator.core.EmulatorCore`, exactly the
model's), the judging is the backseat observer's
(:class:`~helmcheck.judge.backseat.BackseatObserver`, fed by the
:class:`~helmcheck.line.recorder.Recorder`, which writes ``wire.log`` too) and the
staging is :mod:`.scenarios`'. The loop judges nothing itself: it records every byte from the
backseat as it is read (``>``), every byte to the backseat as it is written (``<``) and every
staged fact as a note (``scenario X starts``, ``reject: …``, ``silence starts``/``ends``,
``lockout starts (<code>)``/``lockout ends``, the emulator core's own notes), so that
``check-log`` of the same ``wire.log`` judges what the certification judged.

Driving: the backseat's bytes are framed here (:class:`~helmcheck.grammar.Framer`) and each
complete line goes to the vehicle unless a scenario says otherwise (a ``silence`` drops it, a
``reject`` window answers a command with an error ``$ACK`` in the vehicle's place, queued by
the core behind its own output, in order and paced like it). Before the bytes of a read are
recorded the vehicle is brought up to that moment, so a lockout that has ended is noted before
the bytes that follow it.

Link life (decisions): the run starts at the backseat's first byte; none within
``connect_timeout`` is "never connected". On a pty the loop lets go of its own copy of the
slave side once the backseat is there, so the backseat closing the port (or dying) is seen as
a hang-up; on a TCP serial server it is the client's disconnect. Either is the backseat leaving,
and before the run's end it is "disconnected" (the report says when). On a device (``port``:
helmcheck's own serial adapter, or any name that can come back, :mod:`helmcheck.line.reopen`)
a device that disappears is helmcheck's side of the line going away, not the backseat's doing:
the loop waits for it under the same name for ``reconnect_wait`` seconds (:meth:`Runner._gap_start`),
keeping the vehicle's clock going (what it says meanwhile is lost, as on a cut line) and the
scenarios' schedule still. Back in time, the record gets a ``run resumed`` note (the judge does not
hold the gap against the backseat: the next poll is due from there, what it knew is unknown
again, :class:`~helmcheck.judge.backseat.BackseatObserver`), any staged window still open is
closed, and the scenario the gap cut starts again from its start, the rest of the schedule after
it (``link_gaps`` in ``results.json``). Not back in time, the run is "disconnected", its reason
naming the port and the wait. The loop waits in ``select`` at most 50 ms at a time;
SIGINT/SIGTERM (or :meth:`Runner.stop`) end it early as "interrupted". When helmcheck started the backseat (``child``, a
:class:`~helmcheck.line.launcher.Launcher`), the loop also ends, as "exited", as soon as
that process has ended (checked every tick).

Moments (:mod:`.stage`): before each staged step the loop asks whether the scenario must stay
open (its moment has not reached the backseat yet); if so the step, and the schedule after it,
wait — by at most the scenario's limit. Each scenario's end is a note saying what it exercised,
with a ``not claimed`` note for a moment that did not reach the backseat.

The vehicle's line (:mod:`helmcheck.emulator.outbox`): its output leaves at the baud, 10 bits a
byte; requests asking for more replies than that are queued or dropped as ``overrun`` says
(default ``drop``: a request whose replies could not start within the ACK window goes
unanswered; ``queue``: every reply waits its turn). At the run's end a ``line overrun:`` note says
how far the backseat over-asked the line (a remark beside RH-BS-4).

Run facts (:mod:`helmcheck.judge.runfacts`): before the record closes, the loop stops the
backseat it started and records its end (``not judged`` notes for the clauses its exit cut
short, a ``process:`` note, :mod:`.process`), a ``not judged`` note for every clause when the
backseat never connected, and a ``run partial:`` note when the run did not complete, or when it
did but a scenario's moment did not reach the backseat — so the results (:mod:`.report`) and
``helmcheck verify`` assemble the same verdicts from the record.
"""

from __future__ import annotations

import re
import select
import time
from collections import deque
from dataclasses import dataclass, field
from typing import IO, Any, Callable, Iterable, Optional

from ...grammar import Discard, Framer, decode
from ...grammar import sentences as s
from ...grammar.wirelog import FROM_VEHICLE, TO_VEHICLE
from ...judge.backseat import BS_CLAUSES, BackseatObserver
from ...judge.ledger import Ledger
from ...judge.runfacts import RunFacts, not_judged_note, overrun_note, partial_note
from ...model.missions import MissionCatalog
from ...profile import Profile
from ...emulator.core import EmulatorCore
from ...emulator.freedoms import DEFAULT_SETTINGS
from ...emulator.outload import describe as describe_overrun
from ...line.recorder import Recorder
from ...line.reopen import DEFAULT_WAIT_S, RETRY_S, wait_for_port
from ...line.transport import Link, LinkClosed
from .link import HangupPty
from .scenarios import LOCKOUT_CODE, Action, Plan
from .stage import Stage

__all__ = ["Runner", "RunRecord", "HangupPty", "MAX_OUT"]

MAX_OUT = 256 * 1024  #: bytes waiting for a link nobody reads; beyond this they are dropped
MAX_COMMAND_EVENTS = 5000  #: the backseat's commands marked on the report's timeline; the rest are in the wire log
_TICK = 0.05
#: the core's note about an overlong run it logged in part; the recorder here logs every byte
_PARTIAL = re.compile(r"^RH-FRM-\d+: \d+ bytes discarded, first \d+ logged$")


class _CoreNotes:
    """The emulator core's log: its notes go to the recorder; its bytes do not, because the
    loop records the bytes itself as they cross the link."""

    def __init__(self, recorder: Recorder):
        self.recorder = recorder

    def bytes(self, t: float, direction: str, raw: bytes) -> None:
        pass

    def note(self, t: float, text: str) -> None:
        if not _PARTIAL.match(text):
            self.recorder.note(t, text)


@dataclass
class RunRecord:
    """How a run ended and what it saw; times are seconds since the certifier started."""

    status: str  #: complete | never-connected | disconnected | interrupted | exited
    reason: str
    observer: BackseatObserver
    connected_at: Optional[float] = None
    ended_at: float = 0.0
    planned: float = 0.0
    events: list[tuple[float, str, str]] = field(default_factory=list)
    modes: list[tuple[float, str]] = field(default_factory=list)
    scenarios_run: list[str] = field(default_factory=list)
    vehicle_stats: dict = field(default_factory=dict)
    facts: RunFacts = field(default_factory=RunFacts)  #: the run facts, as the record's notes gave them
    process: Optional[dict] = None  #: the backseat's ``process`` object, when helmcheck started it
    #: helmcheck's port gone and waited for: when (seconds since the certifier started), how long,
    #: why, the scenario it cut, whether it came back
    gaps: list[dict] = field(default_factory=list)
    #: every scenario as it ran: its moments, how long, what is not claimed (:mod:`.stage`)
    coverage: list[dict] = field(default_factory=list)
    #: how far the backseat's requests over-asked the vehicle's line (None: they did not)
    overrun: Optional[dict] = None


class Runner:
    """Runs one certification on ``link``. See the module docstring."""

    def __init__(self, link: Link, profile: Profile, plan: Plan, *, time_scale: float,
                 missions: Optional[MissionCatalog] = None, log: Optional[IO[str]] = None,
                 meta: Iterable[str] = (), connect_timeout: float = 30.0,
                 clock: Callable[[], float] = time.monotonic, progress: Any = None, child: Any = None,
                 port: Optional[str] = None, reconnect_wait: float = DEFAULT_WAIT_S, overrun: str = "drop"):
        self.link = link
        #: the name to open again when the link's device vanishes (None: not waited for)
        self.port = port if reconnect_wait > 0 else None
        self.reconnect_wait = reconnect_wait
        self._gap: Optional[dict] = None  #: the gap under way (its entry in ``outcome.gaps``)
        self._gap_slot = None  #: the scenario slot it cut
        self._retry_at = 0.0
        self._shift = 0.0  #: seconds the schedule moved on by the gaps (the cut scenarios run again)
        self.profile = profile
        self.plan = plan
        self.time_scale = time_scale
        self.connect_timeout = connect_timeout
        self.clock = clock
        self.progress = progress
        self.child = child  #: the backseat process under test, when helmcheck started it
        self.launch = clock()
        self.ledger = Ledger(BS_CLAUSES)
        self.observer = BackseatObserver(profile, self.ledger, time_scale=time_scale, baud=profile.baud)
        self.facts = RunFacts()
        self.recorder = Recorder(log, meta, observers=[self.observer, self.facts])
        self.core = EmulatorCore(profile.replace(fault_injection="none"), missions, start=self.launch,
                                 time_scale=time_scale, baud=profile.baud, log=_CoreNotes(self.recorder),
                                 settings=DEFAULT_SETTINGS.replace(overrun=overrun))
        self.stage = Stage(plan, observer=self.observer, core=self.core, rel=self.rel,
                           ack_window_s=profile.ack_window_s, reaction_s=profile.reaction_s, baud=profile.baud)
        self.core.on_release = self.stage.released
        #: the staged steps, and the run's end (held like the steps, :mod:`.stage`)
        self._schedule = (*plan.actions, Action(plan.total, "end"))
        self._done = False
        self._extended = 0.0  #: seconds the scenarios were held open past their plan
        self._framer = Framer(profile.max_line_bytes)
        self._stop: Optional[str] = None
        self._out = bytearray()
        self._actions = deque(self._schedule)
        self._silent = False
        self._rejecting = False
        self._silence_noted = False
        self._commands_marked = 0
        self._unsent = 0  #: bytes of replies the silent vehicle did not send
        self._lockout = False
        self._mode = ""
        self._scenario = ""
        self._dropped_out = 0
        self._dropped_total = 0  #: bytes the loop never wrote (nobody read the port), over the run
        self.connected_at: Optional[float] = None
        self.outcome = RunRecord("interrupted", "", self.observer, planned=plan.total, facts=self.facts)

    # ------------------------------------------------------------------ control
    def stop(self, why: str = "interrupted") -> None:
        """End the run early (safe from a signal handler)."""
        self._stop = why

    def rel(self, now: float) -> float:
        return now - self.launch

    # ------------------------------------------------------------------ the loop
    def run(self) -> RunRecord:
        o = self.outcome
        status, reason = "interrupted", "the run was interrupted"
        try:
            while True:
                now = self.clock()
                if self._stop is not None:
                    status, reason = "interrupted", f"the run was {self._stop} after {self._elapsed(now):.1f} s"
                    break
                if self.child is not None and self.child.ended:
                    status = "exited"
                    reason = (f"the backseat under test {self.child.exit_text()} after {self._elapsed(now):.1f} s "
                              f"of the {self.plan.total:.1f} s run")
                    break
                if self.connected_at is None and self.rel(now) > self.connect_timeout:
                    status = "never-connected"
                    reason = (f"the backseat never connected: no byte arrived on {self.link.name} "
                              f"within {self.connect_timeout:g} s")
                    break
                if self._gap is not None:
                    back = self._gap_tick(now)
                    if back is False:
                        gap = self._gap
                        status = "disconnected"
                        reason = (f"helmcheck's port {self.port} was gone at {gap['lost_at_s']:.1f} s and did not "
                                  f"come back within {self.reconnect_wait:g} s (--reconnect-wait; {gap['why']})")
                        break
                    continue
                if self._done:
                    status, reason = "complete", "the run completed"
                    break
                if self.connected_at is not None:
                    self._due(now)
                self._service(now)
                try:
                    gone = self._wait_and_read(now)
                except LinkClosed as e:
                    gone = f"the link was lost ({e})"
                if gone:
                    now = self.clock()
                    if self.connected_at is None:
                        continue
                    if self.port is not None and not gone.startswith("disconnect"):
                        self._gap_start(now, gone)  # helmcheck's own device: waited for
                        continue
                    status = "disconnected"
                    reason = (f"the backseat closed the port or crashed after {self._elapsed(now):.1f} s "
                              f"of the {self.plan.total:.1f} s run ({gone})")
                    break
        finally:
            now = self.clock()
            end = self.recorder.note(self.rel(now), f"run ended: {reason}")
            o.status, o.reason = status, reason
            o.connected_at = self.connected_at
            o.ended_at = self.rel(now)
            o.vehicle_stats = dict(self.core.stats)
            try:
                self._record_end(status, end)
                self._record_facts(status, reason, end)
            finally:
                self.observer.close(end)
                self.recorder.close()
        return o

    def _record_end(self, status: str, t: float) -> None:
        """The scenarios' record and the line overrun, as notes at *t*."""
        o = self.outcome
        if self.stage.current is not None and status == "complete":
            for text in self.stage.close(t):
                self.recorder.note(t, text)
        o.coverage = self.stage.record(t)
        summary = self.core.load.summary(ack_window_s=self.profile.ack_window_s)
        if self._dropped_total:
            summary = dict(summary or {"asked_Bps": 0.0, "line_Bps": self.profile.baud / 10.0, "baud": self.profile.baud,
                                       "max_lag_s": 0.0, "dropped_bytes": 0, "dropped_sets": 0, "by": "",
                                       "over_capacity": False})
            summary["unread_bytes"] = self._dropped_total
        if summary is not None:
            o.overrun = summary
            text = describe_overrun(summary)
            if self._dropped_total:
                text += (f"; {self._dropped_total} more byte(s) were never written: nobody read the port "
                         f"({MAX_OUT // 1024} KiB waiting)")
            self.recorder.note(t, overrun_note(text))
        partial = self.stage.partial_reason()
        if partial is not None and status == "complete":
            self.recorder.note(t, partial_note(partial))

    def _record_facts(self, status: str, reason: str, t: float) -> None:
        """The run facts of the run's end, as notes at *t* (module docstring)."""
        if self.child is not None:
            from .process import end_backseat, process_notes

            o = self.outcome
            o.process = end_backseat(self.child, epoch=self.launch, link_lost=status in ("disconnected", "exited"))
            started = None if self.connected_at is None else self.connected_at + self._shift
            finished = {r["name"] for r in o.coverage if r["finished"]}
            for text in process_notes(o.process, clauses=BS_CLAUSES, plan=self.plan,
                                      connected_at=started, ended_at=o.ended_at, finished=finished):
                self.recorder.note(t, text)
        if status == "never-connected":
            self.recorder.note(t, not_judged_note(BS_CLAUSES, f"not judged: {reason}"))
        if status != "complete":
            self.recorder.note(t, partial_note(reason))

    def _elapsed(self, now: float) -> float:
        """Seconds of the run so far (a gap's scenario, run again, is counted once; a scenario held
        open past its plan counts)."""
        return 0.0 if self.connected_at is None else self.rel(now) - self.connected_at - self._shift + self._extended

    # ------------------------------------------------------------------ helmcheck's port gone and back
    def _gap_start(self, now: float, why: str) -> None:
        """The link's device vanished (module docstring): note it, wait for it from the loop."""
        t = self.rel(now)
        try:
            self.link.close()
        except Exception:  # noqa: BLE001
            pass
        self._note(now, f"link lost: {why}")
        self._note(now, f"link gap: waiting up to {self.reconnect_wait:g} s for {self.port} to come back "
                        f"(--reconnect-wait)")
        self._gap_slot = self._scenario_at(self._elapsed(now))
        self._gap = {"lost_at_s": round(t, 6), "back_at_s": None, "gap_s": None, "port": self.port, "why": why,
                     "cut": self._gap_slot.name if self._gap_slot is not None else None}
        self.outcome.gaps.append(self._gap)
        self._retry_at = now
        self._framer = Framer(self.profile.max_line_bytes)  # a line the gap cut is nobody's
        self._out.clear()
        if self.progress is not None and hasattr(self.progress, "note"):
            self.progress.note(f"{self.port} is gone ({why}); waiting up to {self.reconnect_wait:g} s for it")

    def _gap_tick(self, now: float) -> Optional[bool]:
        """One turn of the loop while the port is gone: True back, False given up, None waiting."""
        gap = self._gap
        assert gap is not None
        self._service(now)  # the vehicle goes on; what it says is lost (:meth:`_write`)
        if now >= self._retry_at:
            link, _ = wait_for_port(self.port, baud=self.profile.baud, within_s=0.0)  # type: ignore[arg-type]
            if link is not None:
                self._gap_end(self.clock(), link)
                return True
            self._retry_at = now + RETRY_S
        if self.rel(now) - gap["lost_at_s"] >= self.reconnect_wait:
            return False
        time.sleep(min(_TICK, RETRY_S))
        return None

    def _gap_end(self, now: float, link: Link) -> None:
        """The port is back: the record says so, staged windows close, the cut scenario starts again."""
        gap = self._gap
        assert gap is not None
        self.link = link
        t = self.rel(now)
        gap.update(back_at_s=round(t, 6), gap_s=round(t - gap["lost_at_s"], 6))
        cut = self._gap_slot
        again = f"scenario {cut.name} starts again" if cut is not None else "the run goes on"
        self._note(now, f"run resumed: helmcheck's port came back after a gap of {t - gap['lost_at_s']:.2f} s "
                        f"({self.port} was gone from {gap['lost_at_s']:.3f} s to {t:.3f} s: {gap['why']}); what "
                        f"crossed the line meanwhile was not seen; {again}")
        self._note(now, f"link reopened: {self.port} is back after {t - gap['lost_at_s']:.2f} s")
        self._gap = None
        if self._rejecting:
            self._rejecting = False
            self._note(now, "reject: window ends")
        if self._silent:
            self._silent = False
            self._note(now, "silence ends")
        if cut is not None:  # the schedule goes on from the cut scenario's start
            self._shift = t - (self.connected_at or 0.0) - cut.start
            self._extended = 0.0
            self._actions = deque(a for a in self._schedule if a.at >= cut.start)
            self.stage.restart(cut.name, t)
        if self.progress is not None and hasattr(self.progress, "note"):
            self.progress.note(f"{self.port} is back after {t - gap['lost_at_s']:.1f} s; {again}")
        self._due(now)

    def _scenario_at(self, elapsed: float):
        """The scenario slot the schedule is in at ``elapsed`` seconds of it (the last one after)."""
        slots = self.plan.slots
        for slot in slots:
            if elapsed < slot.end:
                return slot
        return slots[-1] if slots else None

    def _wait_and_read(self, now: float) -> str:
        """Wait for input (at most one tick) and handle it; a reason when the peer is gone."""
        fd = self.link.fileno()
        wfds = [fd] if self._out and self.link.connected else []
        timeout = _TICK
        due = self.core.next_wakeup()
        if due is not None:
            timeout = max(0.0, min(timeout, due - now))
        try:
            r, w, _ = select.select([fd], wfds, [], timeout)
        except (OSError, ValueError):
            return "the link's descriptor was closed"
        if w:
            self._write(self.clock())
        if not r:
            return ""
        for ev in self.link.poll():
            t = self.clock()
            if ev.kind == "data":
                self._backseat(ev.data, t)
            elif ev.kind == "connect":
                self._note(t, f"link: client connected {ev.info}")
            elif ev.kind == "disconnect":
                return f"disconnect: {ev.info}".strip()
        return ""

    # ------------------------------------------------------------------ input
    def _backseat(self, data: bytes, now: float) -> None:
        if self.connected_at is None:
            self.connected_at = self.rel(now)
            if isinstance(self.link, HangupPty):
                self.link.peer_seen()
            self._note(now, "backseat connected (first byte); the judged run starts")
            self.outcome.events.append((self.rel(now), "note", "backseat connected"))
            self._actions = deque(self._schedule)
            if self.progress is not None:
                self.progress.start(self.plan.total)
            self._due(now)
        self._service(now)  # the vehicle up to now first: a lockout that ended is noted before
        at = self.recorder.bytes(self.rel(now), TO_VEHICLE, data)  # the time the wire log gives them
        for ev in self._framer.feed(data):
            if not isinstance(ev, Discard):
                self._mark_command(ev.raw, at)
            self._deliver(ev.raw, None if isinstance(ev, Discard) else ev.raw, now)
            self._after_vehicle(now)

    def _mark_command(self, line: bytes, at: float) -> None:
        """A sentence the backseat sent (not its ``$OSD`` polls), for the report's timeline at the
        time the wire log has it (``at``): the same marks a vehicle run gives the tester's
        commands. A malformed or out-of-range command is marked too (it is often the finding).
        Judges nothing."""
        if self._commands_marked >= MAX_COMMAND_EVENTS or not line.startswith(b"$") or line.startswith(b"$OSD,"):
            return
        self._commands_marked += 1
        self.outcome.events.append((at, "command", line.decode("latin-1", "replace").rstrip("\r\n")[:60]))

    def _deliver(self, raw: bytes, line: Optional[bytes], now: float) -> None:
        """One framed run from the backseat to the vehicle (``line`` None: a discarded run)."""
        if self._silent:
            if not self._silence_noted:
                self._silence_noted = True
                self._note(now, "silence: the vehicle neither reads nor answers")
            return
        if self._rejecting and line is not None:
            cmd = decode(line, self.profile).sentence
            if (isinstance(cmd, s.Command) and cmd.ACK_TYPE is not None and not isinstance(cmd, s.OSD)
                    and cmd.ID in self.profile.commands):
                t = self.rel(now)
                if len(self.outcome.events) < 500:
                    self.outcome.events.append((t, "ack-error", f"staged rejection of ${cmd.ID}: err {cmd.ERR}"))
                self.stage.staged_refusal(now)
                self._emit(self.core.queue_reply(s.ACK(cmd.ACK_TYPE, 1, cmd.ERR), now))
                return
        self._emit(self.core.feed(raw, now))

    # ------------------------------------------------------------------ vehicle side
    def _service(self, now: float) -> None:
        out = self.core.tick(now)
        if self._silent:
            if out:
                if not self._unsent:
                    self._note(now, "silence: the vehicle's replies are not sent from here on")
                self._unsent += len(out)
        else:
            self._emit(out)
        self._after_vehicle(now)
        self._write(now)

    def _emit(self, data: bytes) -> None:
        if not data:
            return
        if len(self._out) + len(data) > MAX_OUT:
            if not self._dropped_out:
                self._note(self.clock(), "link: output dropped, nobody is reading the port")
            self._dropped_out += len(data)
            self._dropped_total += len(data)
            return
        self._out += data
        self._write(self.clock())

    def _write(self, now: float) -> None:
        if self._gap is not None:  # nothing crosses a line whose port is gone: lost, not recorded
            self._out.clear()
            return
        while self._out:
            try:
                n = self.link.write_some(bytes(self._out[:65536]))
            except OSError:
                self._out.clear()
                return
            if n <= 0:
                return
            self.recorder.bytes(self.rel(now), FROM_VEHICLE, bytes(self._out[:n]))
            del self._out[:n]
        self._dropped_out = 0

    def _after_vehicle(self, now: float) -> None:
        core = self.core
        m = core.model
        lock = core.lockout_active
        if lock != self._lockout:
            self._lockout = lock
            self._note(now, f"lockout starts ({m.error_state})" if lock else "lockout ends")
            if not lock:
                self.stage.lockout_ended(self.rel(now))
            self.outcome.events.append((self.rel(now), "lockout",
                                        f"lockout {'starts' if lock else 'ends'} ({m.error_state})"))
        if m.mode != self._mode:
            self._mode = m.mode
            self.outcome.modes.append((self.rel(now), m.mode))

    # ------------------------------------------------------------------ staging
    def _due(self, now: float) -> None:
        start = self.launch + (self.connected_at or 0.0) + self._shift
        while self._actions and start + self._actions[0].at <= now:
            a = self._actions[0]
            why = self.stage.hold(a, self.rel(now))
            if why is not None:  # the scenario stays open: this step and the rest of the schedule wait
                late = now - (start + a.at)
                self._shift += late
                self._extended += late
                note = self.stage.extend(late, why)
                if note:
                    self._note(now, note)
                break
            self._act(self._actions.popleft(), now)
        if self.progress is not None:
            self.progress.update(self._elapsed(now), self._scenario, self.observer.offences(),
                                 self.plan.total + self._extended)

    def _act(self, a, now: float) -> None:
        t = self.rel(now)
        if a.kind in ("scenario", "end"):
            for text in self.stage.close(t):
                self._note(now, text)
        if a.kind == "end":
            self._done = True
            return
        if a.kind == "scenario":
            self.stage.open(a.name, t)
            self._scenario = a.name
            self.outcome.scenarios_run.append(a.name)
            self._note(now, f"scenario {a.name} starts")
            self.outcome.events.append((t, "note", f"scenario {a.name}"))
        elif a.kind == "reject":
            self._rejecting = a.on
            self._note(now, "reject: every command but $OSD is refused" if a.on else "reject: window ends")
            self.stage.acted(a, t)
        elif a.kind == "silence":
            if not a.on and self._unsent:
                self._note(now, f"silence: {self._unsent} bytes of replies were not sent")
            self._silent = a.on
            self._silence_noted = False
            self._unsent = 0
            self._note(now, "silence starts" if a.on else "silence ends")
            self.outcome.events.append((t, "note", "silence starts" if a.on else "silence ends"))
            self.stage.acted(a, t)
        elif a.kind == "lockout":
            out = self.core.inject_fault(LOCKOUT_CODE, now, source="scenario lockout")
            self.outcome.events.append((t, "lockout", f"safety violation {LOCKOUT_CODE} raised"))
            self._after_vehicle(now)  # the note before any byte that could show the lockout
            self.stage.acted(a, t)
            self._emit(out)
        elif a.kind == "mission-end":
            self.stage.acted(a, t, mission_ended=self._end_mission(now))

    def _end_mission(self, now: float) -> bool:
        """The running mission ends on the vehicle, off the wire (scenario ``mission-end``); whether
        one was running to end."""
        core = self.core
        self._emit(core.tick(now))
        if not core.mission_running:
            self._note(now, "mission-end: no mission was running; nothing to end")
            return False
        self._note(now, "mission-end: the mission ended on the vehicle")
        self.outcome.events.append((self.rel(now), "note", "mission ended on the vehicle"))
        self._emit(core.end_mission(now))
        self._after_vehicle(now)
        return True

    # ------------------------------------------------------------------ notes
    def _note(self, now: float, text: str) -> None:
        self.recorder.note(self.rel(now), text)
