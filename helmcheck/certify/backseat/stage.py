"""What each scenario exists for, whether it reached the backseat in time, and how long the run waits.

A scenario is staged for its *moments* (:mod:`.scenarios` plans their lengths); the run holds a
scenario open, past its planned end, until they have reached the backseat — by at most the slot's
:attr:`~.scenarios.Slot.limit` — and a scenario whose moment did not reach it leaves its clauses'
observations in that scenario out of the claim (a ``not claimed`` note, :mod:`helmcheck.judge.runfacts`;
the run is then partial, not a certificate). Times are seconds since the certifier started.

=========== ============================================================== ==========================
scenario    its moments (the run waits for each)                           not claimed when missing
=========== ============================================================== ==========================
nominal     the servo timeout the backseat chose, seen run out twice after RH-BS-6 (its refreshes)
            its first accepted ``$OMS`` (if it took servo control in it)
reject      a staged refusal reaching the backseat, and a resend spacing   RH-BS-5
            and ``reaction_s`` after it (the window stays open until then)
lockout     its start reaching the backseat *in time* — the first sign     RH-BS-5
            (``$OSI`` field 8, err 26) arrived within the backseat's poll
            cycle (at most RH-BS-8's 5 s), the ACK window and a reply's
            transmit time of the start, so the lockout is judged whole —
            and its end reaching it (the first ``$OSI`` the vehicle made
            after the end had arrived)
mission-end a running mission to end (the run waits for one), and its end  RH-BS-3
            reaching the backseat (the first ``$OSI`` saying ``S``)
silence     the silence outlasting the timeout the backseat chose (its     RH-BS-4, RH-BS-8
            latest accepted ``$OMS``) and two of its poll cycles
=========== ============================================================== ==========================

When a report reached the backseat is when its bytes had fully arrived: the vehicle's release of
the sentence (the emulator core's output pacing, :attr:`~helmcheck.emulator.outbox.Outbox.on_release`)
plus its transmit time at the baud; what the vehicle made during a silence never reaches it. The
lockout's start is the backseat observer's own: the first sign it takes as known
(:class:`~helmcheck.judge.backseat.knowledge.Episode`), so the claim and the judged window agree.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Optional

from ...judge.backseat import POLL_INTERVAL_S, RESEND_SPACING_S
from ...judge.runfacts import UNEXERCISED, not_claimed_note
from ...judge.timing import JITTER_S, transmit_time
from .scenarios import REPLY_BYTES, SILENCE_S, Action, Plan, Slot

__all__ = ["Stage", "Moment", "ScenarioRun"]


@dataclass
class Moment:
    """One thing a scenario exists for: when it happened, when the report of it reached the backseat."""

    what: str
    at: Optional[float] = None
    reached: Optional[float] = None
    in_time: Optional[bool] = None  #: None: no bound on when it had to reach (only within the scenario)
    limit_s: Optional[float] = None  #: the bound, seconds after ``at``

    def as_dict(self) -> dict:
        return {"what": self.what, "at_s": _r(self.at), "reached_at_s": _r(self.reached),
                "after_s": None if self.at is None or self.reached is None else round(self.reached - self.at, 3),
                "in_time": self.in_time, "limit_s": _r(self.limit_s)}


def _r(x: Optional[float]) -> Optional[float]:
    return None if x is None else round(x, 3)


@dataclass
class ScenarioRun:
    """One scenario as it ran."""

    slot: Slot
    started: float
    ended: Optional[float] = None
    extended: float = 0.0
    waiting_for: str = ""  #: what the run holds it open for, now
    moments: list[Moment] = field(default_factory=list)
    unclaimed: list[tuple[tuple[str, ...], str]] = field(default_factory=list)
    facts: dict = field(default_factory=dict)  #: figures for the summary (counts, spans)

    def as_dict(self) -> dict:
        ran = None if self.ended is None else self.ended - self.started
        return {"name": self.slot.name, "planned_s": round(self.slot.length, 3), "needs_s": round(self.slot.needs, 3),
                "why": self.slot.why, "started_at_s": round(self.started, 3), "ended_at_s": _r(self.ended),
                "ran_s": _r(ran), "extended_s": round(self.extended, 3), "limit_s": round(self.slot.limit, 3),
                "finished": self.ended is not None, "claimed": self.ended is not None and not self.unclaimed,
                "moments": [m.as_dict() for m in self.moments],
                "not_claimed": [{"clauses": list(c), "reason": r} for c, r in self.unclaimed],
                "exercised": self.summary()}

    def summary(self) -> str:
        """What the scenario exercised, and for how long, in one line."""
        f = self.facts
        ran = (self.ended if self.ended is not None else f.get("now", self.started)) - self.started
        name = self.slot.name
        if name == "nominal":
            text = f"{ran:.1f} s of the vehicle answering as the model does: {f.get('polls', 0)} state poll(s)"
            if f.get("servo"):
                text += f"; servo control from {f['servo']}"
            return text
        if name == "reject":
            text = f"a {f.get('window', 0.0):.1f} s refusal window: {f.get('refusals', 0)} staged refusal(s)"
        elif name == "lockout":
            text = f.get("lockout", "no lockout was raised")
        elif name == "mission-end":
            text = f.get("ended", "no mission was running to end")
        else:
            text = f"{f.get('silent', 0.0):.1f} s of silence"
        reached = [m for m in self.moments if m.reached is not None and m.at is not None]
        if reached:
            text += "; " + ", ".join(f"{m.what} {m.reached - m.at:.2f} s after it" for m in reached)
        missing = [m.what for m in self.moments if m.reached is None]
        if missing:
            text += "; never reached the backseat: " + ", ".join(missing)
        return text + f" ({ran:.1f} s in all)"


class Stage:
    """The scenarios' moments for one run (module docstring). The runner calls :meth:`hold` before
    each staged action, :meth:`acted` after it, :meth:`open`/:meth:`close` at scenario bounds,
    :meth:`extend` with the time it held one open; the emulator core calls :meth:`released`."""

    def __init__(self, plan: Plan, *, observer: Any, core: Any, rel: Callable[[float], float],
                 ack_window_s: float, reaction_s: float, baud: int):
        self.plan = plan
        self.o = observer
        self.core = core
        self.rel = rel
        self.ack_window_s = ack_window_s
        self.reaction_s = reaction_s
        self.baud = baud
        self.runs: list[ScenarioRun] = []
        self.current: Optional[ScenarioRun] = None
        self._silent = False
        self._staged: set[float] = set()  #: core times of staged refusals queued, not yet out
        self._osi_marks: list[tuple[Moment, bool]] = []  #: moments an ``$OSI`` made after ``at`` reaches (S only?)
        self._rejection: Optional[Moment] = None
        self._reject_on: Optional[float] = None
        self._silence_on: Optional[float] = None
        self._episode: Any = None

    # ------------------------------------------------------------------ scenario bounds
    def open(self, slot_name: str, t: float) -> None:
        slot = next(s for s in self.plan.slots if s.name == slot_name)
        run = ScenarioRun(slot, t)
        run.facts["polls_at_open"] = self.o.polling.polls
        self.runs.append(run)
        self.current = run

    def restart(self, slot_name: str, t: float) -> None:
        """A link gap cut the current scenario: it runs again from its start (its record starts afresh)."""
        if self.current is not None and self.current.ended is None and self.current in self.runs:
            self.runs.remove(self.current)
        self.current = None
        self._osi_marks.clear()
        self._rejection = self._reject_on = self._silence_on = None
        self._silent = False

    def extend(self, dt: float, why: str) -> Optional[str]:
        """The current scenario was held open ``dt`` more seconds for ``why``; a note the first time."""
        run = self.current
        if run is None:
            return None
        first = not run.waiting_for
        run.extended += dt
        run.waiting_for = why
        if first:
            return (f"scenario {run.slot.name} extended: waiting for {why} (at most {run.slot.limit:.1f} s past its "
                    f"planned {run.slot.length:.1f} s)")
        return None

    def close(self, t: float) -> list[str]:
        """The current scenario ends at ``t``: what it exercised, and a ``not claimed`` note for
        each moment that did not reach the backseat (returned, in order, to record)."""
        run = self.current
        if run is None:
            return []
        run.ended = t
        run.facts["now"] = t
        self._finish(run, t)
        self.current = None
        self._osi_marks.clear()  # what reaches the backseat from now on is the next scenario's
        self._rejection = None
        notes = [not_claimed_note(c, run.slot.name, why) for c, why in run.unclaimed]
        notes.append(f"scenario {run.slot.name} ends after {t - run.started:.2f} s"
                     + (f" (extended by {run.extended:.2f} s)" if run.extended > 1e-6 else "")
                     + f": {run.summary()}")
        return notes

    def partial_reason(self) -> Optional[str]:
        """The run's ``run partial`` reason when a scenario's moment did not reach the backseat."""
        parts = [f"{r.slot.name}: {why}" for r in self.runs for _, why in r.unclaimed]
        return UNEXERCISED + "; ".join(parts) if parts else None

    def record(self, t: float) -> list[dict]:
        """Every scenario as it ran (``coverage.scenarios`` in results.json)."""
        out = []
        for r in self.runs:
            if r.ended is None:
                r.facts["now"] = t
                self._facts(r, t)
            out.append(r.as_dict())
        return out

    # ------------------------------------------------------------------ the line
    def released(self, raw: bytes, queued: float, released: float) -> None:
        """The emulator core let a sentence go (core times): when it has arrived, it reached the backseat."""
        if self._silent:
            return  # a silent vehicle's output is thrown away: it reaches nobody
        arrived = self.rel(released) + transmit_time(len(raw), self.baud)
        if raw.startswith(b"$ACK,") and queued in self._staged:
            self._staged.discard(queued)
            m = self._rejection
            if m is not None and m.reached is None:
                m.reached = arrived
            if self.current is not None:
                self.current.facts["refusals"] = self.current.facts.get("refusals", 0) + 1
            return
        if raw.startswith(b"$OSI,") and self._osi_marks:
            q = self.rel(queued)
            fields = raw.split(b",", 3)
            mode = fields[2] if len(fields) > 2 else b""
            keep = []
            for m, need_s in self._osi_marks:
                if m.reached is None and q >= (m.at or 0.0) and (not need_s or mode == b"S"):
                    m.reached = arrived
                else:
                    keep.append((m, need_s))
            self._osi_marks = [(m, s) for m, s in keep if m.reached is None]

    def staged_refusal(self, now: float) -> None:
        """A staged refusal was queued at core time ``now`` (:meth:`released` sees it leave)."""
        self._staged.add(now)

    # ------------------------------------------------------------------ vehicle events
    def lockout_ended(self, t: float) -> None:
        run = self.current
        if run is None or run.slot.name != "lockout":
            return
        m = Moment("the lockout's end", t)
        run.moments.append(m)
        self._osi_marks.append((m, False))

    # ------------------------------------------------------------------ actions
    def _poll_cycle(self) -> float:
        gap = self.o.polling.max_gap
        return min(gap, POLL_INTERVAL_S) if gap > 0 else POLL_INTERVAL_S

    def _reach_limit(self) -> float:
        """Seconds after a vehicle event by which its report reaches a backseat on a line that keeps
        up: its poll cycle, the ACK window, a reply's transmit time."""
        return self._poll_cycle() + self.ack_window_s + transmit_time(REPLY_BYTES, self.baud)

    def acted(self, a: Action, t: float, *, mission_ended: bool = False) -> None:
        """After the runner carried out a staged action at ``t``."""
        run = self.current
        if a.kind == "reject":
            if a.on:
                self._reject_on = t
                self._rejection = Moment("a staged refusal", t)
                if run is not None:
                    run.moments.append(self._rejection)
            elif run is not None and self._reject_on is not None:
                run.facts["window"] = t - self._reject_on
                self._reject_on = None
        elif a.kind == "silence":
            self._silent = a.on
            if a.on:
                self._silence_on = t
            elif run is not None and self._silence_on is not None:
                run.facts["silent"] = t - self._silence_on
                self._silence_on = None
        elif a.kind == "lockout" and run is not None:
            eps = self.o.episodes
            self._episode = eps[-1] if eps else None
            m = Moment("the lockout's start", t, limit_s=self._reach_limit())
            run.moments.insert(0, m)
        elif a.kind == "mission-end" and run is not None:
            if mission_ended:
                m = Moment("the mission's end", t)
                run.moments.append(m)
                self._osi_marks.append((m, True))
                run.facts["ended_at"] = t

    def hold(self, a: Action, t: float) -> Optional[str]:
        """Why the run waits before action ``a`` (None: carry it out now)."""
        run = self.current
        if run is None:
            return None
        if run.extended >= run.slot.limit - 1e-9:
            return None  # held open as long as it may be: what is missing is not claimed
        if a.kind in ("scenario", "end"):
            return self._close_need(run, t)
        if a.kind == "reject" and not a.on:
            m = self._rejection
            if m is None or m.reached is None:
                return "a staged refusal to reach the backseat"
            if t < m.reached + RESEND_SPACING_S + self.reaction_s + JITTER_S:
                return "a resend spacing after the staged refusal reached the backseat"
            return None
        if a.kind == "silence" and not a.on and self._silence_on is not None:
            need, what = self._silence_need()
            if t < self._silence_on + need:
                return f"the silence to outlast {what}"
            return None
        if a.kind == "mission-end" and not self.core.mission_running:
            return "a running mission to end"
        return None

    def _silence_need(self) -> tuple[float, str]:
        """How long the silence must last, and what that outlasts (a noun phrase)."""
        need, what = SILENCE_S, f"the planned {SILENCE_S:g} s"
        cycle = 2 * self._poll_cycle()
        if cycle > need:
            need, what = cycle, f"two of the backseat's poll cycles ({self._poll_cycle():.1f} s)"
        last = self.o.servo.last_accept
        if last is not None:
            _, wall, tol = last
            if wall + tol + JITTER_S > need:
                need, what = wall + tol + JITTER_S, f"the {wall:.2f} s servo timeout the backseat chose"
        return need, what

    def _close_need(self, run: ScenarioRun, t: float) -> Optional[str]:
        name = run.slot.name
        if name == "nominal":
            first = self.o.servo.first_accept
            if first is not None and run.started <= first[0] <= run.started + run.slot.length:
                t_ack, wall, tol = first
                if t < t_ack + 2 * (wall + tol) + JITTER_S:
                    return "the servo timeout the backseat chose to run out twice"
            return None
        if name == "lockout":
            ends = [m for m in run.moments if m.what == "the lockout's end"]
            if not ends or ends[-1].reached is None:
                return "the lockout's end to reach the backseat"
            if t < ends[-1].reached + self.reaction_s:
                return "the backseat to read the lockout's end"
            return None
        if name == "mission-end":
            ends = [m for m in run.moments if m.what == "the mission's end"]
            if ends and ends[-1].reached is None:
                return "the mission's end to reach the backseat"
            if ends and t < ends[-1].reached + self.reaction_s + RESEND_SPACING_S:
                return "a resend spacing after the mission's end reached the backseat"
            return None
        return None

    # ------------------------------------------------------------------ the verdict on a scenario
    def _facts(self, run: ScenarioRun, t: float) -> None:
        f = run.facts
        f["polls"] = self.o.polling.polls - f.get("polls_at_open", 0)
        if run.slot.name == "nominal":
            first = self.o.servo.first_accept
            if first is not None and first[0] >= run.started:
                f["servo"] = (f"{first[0] - run.started:.1f} s in (its {first[1]:.2f} s timeout"
                              + (" seen run out twice)" if t >= first[0] + 2 * (first[1] + first[2]) else ")"))
        elif run.slot.name == "lockout":
            ep = self._episode
            if ep is not None:
                end = ep.end if ep.end is not None else t
                length = end - (ep.start or run.started)
                if ep.known is not None and ep.known < end:
                    f["lockout"] = (f"the {ep.code} lockout ({length:.1f} s) judged from {ep.known - (ep.start or 0):.2f} s "
                                    f"after it began to its end: {end - ep.known:.1f} s of it")
                else:
                    f["lockout"] = f"the {ep.code} lockout ({length:.1f} s) was over before the backseat could know of it"
        elif run.slot.name == "mission-end" and "ended_at" in f:
            f["ended"] = f"the mission ended on the vehicle {f['ended_at'] - run.started:.1f} s in"
        elif run.slot.name == "silence" and self._silence_on is not None:
            f["silent"] = t - self._silence_on

    def _finish(self, run: ScenarioRun, t: float) -> None:
        """At the scenario's end: what reached the backseat in time, what is not claimed."""
        self._facts(run, t)
        name = run.slot.name
        limit = f"within its {run.slot.length + run.extended:.1f} s"
        if name == "nominal":
            first = self.o.servo.first_accept
            if (first is not None and run.started <= first[0] <= run.started + run.slot.length
                    and t < first[0] + 2 * (first[1] + first[2])):
                run.unclaimed.append((("RH-BS-6",), (
                    f"the {first[1]:.2f} s servo timeout the backseat chose was not seen run out twice {limit} "
                    f"(at most {run.slot.limit:.1f} s past the plan): a refresh after it would not have been seen")))
        elif name == "reject":
            m = self._rejection
            if m is None or m.reached is None:
                run.unclaimed.append((("RH-BS-5",), f"no staged refusal reached the backseat {limit} (it sent no "
                                                     f"command but $OSD in the refusal window)"))
        elif name == "lockout":
            ep = self._episode
            start = run.moments[0] if run.moments and run.moments[0].what == "the lockout's start" else None
            if ep is None or start is None:
                run.unclaimed.append((("RH-BS-5",), "no lockout was raised"))
            else:
                arrived = None if ep.known is None else ep.known - self.reaction_s
                start.reached = arrived
                start.in_time = arrived is not None and arrived <= start.at + (start.limit_s or 0.0)
                end = ep.end if ep.end is not None else t
                if arrived is None or arrived >= end:
                    run.unclaimed.append((("RH-BS-5",), (
                        f"the lockout's start never reached the backseat while the lockout lasted ({end - start.at:.1f} s)")))
                elif not start.in_time:
                    run.unclaimed.append((("RH-BS-5",), (
                        f"the lockout's start reached the backseat {arrived - start.at:.1f} s after it began, later than "
                        f"its poll cycle, the ACK window and a reply's transmit time allow ({start.limit_s:.1f} s): "
                        f"only {end - arrived:.1f} s of the {end - start.at:.1f} s lockout could be judged")))
                ends = [m for m in run.moments if m.what == "the lockout's end"]
                if not ends or ends[-1].reached is None:
                    run.unclaimed.append((("RH-BS-5",), f"the lockout's end did not reach the backseat {limit}"))
        elif name == "mission-end":
            ends = [m for m in run.moments if m.what == "the mission's end"]
            if not ends:
                run.unclaimed.append((("RH-BS-3",), f"no mission was running to end {limit}"))
            elif ends[-1].reached is None:
                run.unclaimed.append((("RH-BS-3",), f"the mission's end (an $OSI saying S) did not reach the "
                                                     f"backseat {limit}"))
        elif name == "silence":
            silent = run.facts.get("silent", 0.0)
            need, what = self._silence_need()
            if silent + 1e-6 < need:
                run.unclaimed.append((("RH-BS-4", "RH-BS-8"), (
                    f"the silence lasted {silent:.1f} s and did not outlast {what} ({need:.1f} s)")))
