"""Exploration: hypothesis sequences aimed at the model, judged step by step.

:class:`VehicleMachine` is a hypothesis ``RuleBasedStateMachine``. Its rules draw from
:mod:`.generate` (every claimed command at the edges of its ranges, every error code, every
mutation of a line, bursts), and walk the model's map: the remote controls (drawn more often, so
that each control mode meets each command: the interrupt pairs), the mission park (``P`` as a
start, or reached from ``N``), a report landed just *before* the next model timer's deadline and
the timer polled *across* it (RH-TIM-1's brackets; the lockout's end with a probe), a safety
violation (``$OXFLT``, when the profile declares it) and ``$ORWSET`` written then read. Protocol
time passes in vehicle seconds ÷ k (RH-TIM-2). Every reply and every ``$OSI`` is judged by the
vehicle observer, as everywhere else; an example fails when the observer booked a failure during
it (the example stops there, raising :class:`VehicleFailure`: the one exception hypothesis is
meant to find and shrink). Steering is hypothesis's own: ``@initialize`` for the start state,
``@precondition`` on what the example has sent (never on the live vehicle, whose timing hypothesis
cannot replay: a rule whose state the vehicle is not in does nothing), and its swarm testing of
rules. What the sequences reached of the model is counted (:mod:`.modelcover`) and kept in
``stats.explore.model_coverage``.

Each example starts from a verified reset (with ``$OLOGL`` and ``$OMLOAD`` in ``S`` so that the
observer knows the log labels and the loaded mission), then starts the test mission or reaches
its park if drawn — all of it recorded — and ends with a verified reset of its own, inside the
example: a lockout or a park it set going is judged within it, never in the next one, so the
replay of a failure holds everything from the reset that led to it.

Shrinking re-runs candidates against the live vehicle. The run keeps the smallest failing
sequence it saw and saves that as a version-independent replay file (:mod:`.replay`), whatever
hypothesis ends with, and re-drives it twice to say whether it fails again. Exploration has a
budget (:data:`PROFILES`: ``fast`` for emulators, ``patient`` for hardware) in wall seconds and in
vehicle seconds, whichever runs out first; when it is spent, the remaining
candidates do nothing, so hypothesis finishes quickly — and the report says so: only the
sequences that really ran are counted.

A tester error — any other exception from the machine or from hypothesis, i.e. a bug in
helmcheck, not a finding about the vehicle — stops the exploration at once (the remaining
candidates do nothing) and is raised again from :func:`explore`: the run ends with exit 2, its
results partial (never a PASS) and the traceback beside them (:func:`~.runner.certify`,
:mod:`helmcheck.cli`). What hypothesis may end with on a finding (:func:`_vehicle_finding`):
:class:`VehicleFailure`; or, once the vehicle has failed at least once, hypothesis's ``Flaky``
family — ``FlakyFailure`` (a failure its replay did not reproduce: a flaky vehicle, or the budget
spent) holding only those, or ``FlakyStrategyDefinition`` (an example that stopped at a failure
once and ran on when replayed drew more data). The vehicle can change nothing else in what the
machine draws.

Bench safety: the strategies keep speeds and the motor byte within ``[bench_safety]``, and the
link's send function refuses anything above it anyway (:mod:`.safety`).
"""

from __future__ import annotations

import time
from typing import NamedTuple, Optional

from hypothesis import HealthCheck, Phase, seed, settings, strategies as st
from hypothesis.database import DirectoryBasedExampleDatabase
from hypothesis.errors import Flaky
from hypothesis.stateful import RuleBasedStateMachine, initialize, precondition, rule, run_state_machine_as_test

from ...model.timers import tolerance
from .flow import CaseStop, LinkLost
from .generate import (bench_motor, bench_speed, commands, control_commands, invalid_lines, timeouts,
                       valid_commands)
from .interpreter import _here, context, fill, raw_line
from .modelcover import ModelCoverage
from .replay import save_replay
from .safety import BenchSafetyRefused
from .session import frame
from .steps import SetRoundTrip

__all__ = ["explore", "PROFILES", "Budget", "valid_commands", "control_commands", "invalid_lines", "timeouts",
           "VehicleFailure"]


class Budget(NamedTuple):
    """An exploration budget: examples, steps per example, wall seconds, vehicle seconds. The
    exploration stops at whichever of the two clocks runs out first: on an emulator at a high time
    scale the wall clock binds, on a vehicle at ×1 the forced waits (vehicle time) do."""

    examples: int
    steps: int
    wall_s: float
    vehicle_s: float


#: Examples asked of hypothesis at a time (:func:`explore`).
BATCH = 8

#: name -> :class:`Budget`
PROFILES = {"fast": Budget(400, 40, 30.0, 1500.0), "patient": Budget(8, 10, 900.0, 600.0)}


def _raw(kind: str, body: str, profile) -> bytes:
    """The line of one drawn mutation: a framed body as it is, or :func:`.interpreter.raw_line`'s."""
    return frame(body) if kind == "frame" else raw_line(kind, body, profile)


class VehicleFailure(AssertionError):
    """An example failed: the observer booked a failure about the vehicle (the reason)."""


def _vehicle_finding(e: BaseException, failures: int) -> bool:
    """Whether hypothesis ended on a finding about the vehicle (module docstring), not on a tester
    error; *failures*: how many examples the vehicle failed."""
    if isinstance(e, VehicleFailure):
        return True
    if isinstance(e, BaseExceptionGroup):  # FlakyFailure: what each replay ended on
        return bool(e.exceptions) and all(_vehicle_finding(x, failures) for x in e.exceptions)
    return isinstance(e, Flaky) and failures > 0


class _State:
    """Shared between the machine instances of one exploration."""

    def __init__(self, run, budget: Budget):
        self.run = run
        self.budget = budget
        self.t0 = time.monotonic()
        self.end = self.t0 + budget.wall_s
        self.k = float(run.session.k)
        self.executions = 0  #: sequences that ran at least their reset
        self.skipped = 0  #: sequences hypothesis asked for after the budget was spent
        self.best: Optional[dict] = None  #: smallest failing trace so far
        self.examples = 0
        self.progress = None
        self.failures = 0
        self.lost: Optional[str] = None
        self.error: Optional[Exception] = None  #: the first tester error (module docstring)
        self.dirty = False  #: the last example ended on a failure, before its closing reset
        self.coverage = ModelCoverage(run.p)

    @property
    def vehicle_spent(self) -> float:
        """Vehicle seconds the exploration has used (wall time × k, RH-TIM-2)."""
        return (time.monotonic() - self.t0) * self.k

    @property
    def which_spent(self) -> Optional[str]:
        if time.monotonic() > self.end:
            return "wall"
        if self.vehicle_spent > self.budget.vehicle_s:
            return "vehicle"
        return None

    @property
    def spent(self) -> bool:
        return self.which_spent is not None or self.lost is not None or self.error is not None

    def tester_error(self, e: Exception) -> None:
        if self.error is None:
            self.error = e


#: Vehicle seconds ahead within which a timer's deadline is waited for (:meth:`boundary`), and
#: the longest a sequence waits for the mission to reach its park.
HORIZON_V = 40.0
PARK_WITHIN_V = 240.0


def _reach_park(session, ctx: dict) -> None:
    """From ``N``: jump to the test mission's park waypoint (once it is known) and poll until ``P``,
    at most :data:`PARK_WITHIN_V`; a vehicle that is not there by then is left where it is (the
    observer judges every report on the way; no tester note: the exploration needs no state)."""
    entry = session.obs.missions.entry(session.profile.mission)
    wp = entry.park_waypoint if entry is not None else None
    if wp is not None and session.obs.state().mission_wp != wp:
        session.exchange(frame(f"OJW,{wp + session.profile.waypoint_base}"))
    end = session.now() + PARK_WITHIN_V / session.k
    while session.now() < end:
        if session.poll().mode != "N":
            break
        session.link.sleep(max(session.poll_gap, 0.05))
    _here(session, ctx)


def _machine(state: _State, p, tos):
    session = state.run.session
    cov = state.coverage
    obs = session.obs
    speed, motor = bench_speed(p), bench_motor(p)
    oxflt = p.fault_injection == "oxflt"
    claimed = set(p.commands)

    def send(raw: bytes):
        """One line, exchanged, its model coverage counted."""
        met = cov.before(obs.state(), raw)
        sent = session.exchange(raw)
        cov.command(met, sent.expected if sent is not None else [])
        return sent

    def mode() -> str:
        return obs.state().mode

    class VehicleMachine(RuleBasedStateMachine):
        def __init__(self):
            super().__init__()
            self.active = not state.spent
            self.ctx: dict = {}
            self.failed = False
            # what this example has sent, for the preconditions: they read only the machine's own
            # record, never the live vehicle, so hypothesis draws the same data when it replays
            # (the rules themselves look at the vehicle and do nothing where it is elsewhere)
            self.mission = False
            self.timed = False
            self.faults = 0
            if self.active:
                state.executions += 1
                if state.progress is not None:
                    try:
                        state.progress.explore(state.executions, state.examples,
                                               max(0.0, state.end - time.monotonic()))
                    except Exception as e:  # noqa: BLE001 - a tester error: kept, raised by explore()
                        state.tester_error(e)
                        self.active = False
            else:
                state.skipped += 1

        def _guard(self, fn):
            if not self.active:
                return
            try:
                fn()
                session.check()
            except CaseStop as f:
                if f.outcome == "fail":
                    self._failed(f)
                    raise VehicleFailure(f.reason) from None
                return
            except BenchSafetyRefused:
                return
            except LinkLost as e:
                state.lost = str(e)
                self.active = False
            except Exception as e:  # noqa: BLE001 - a tester error: kept, raised by explore()
                state.tester_error(e)
                self.active = False

        def _failed(self, f: CaseStop) -> None:
            self.failed = True
            state.failures += 1
            trace = list(session.trace or [])
            if state.best is None or len(trace) < len(state.best["steps"]):
                state.best = {"clause": f.clause or "", "reason": f.reason, "steps": trace}

        @initialize(start=st.sampled_from(["S", "S", "N", "N", "N", "P"]))
        def start(self, start):
            """From a verified reset, traced: the replay of a failure begins here (:mod:`.replay`)."""
            self.mission = start != "S"
            self.timed = start == "P"
            if not self.active:
                return
            if state.dirty:  # the last example stopped at a failure: back to S first, untraced
                state.dirty = False
                stop, session.stop_on_fail = session.stop_on_fail, False
                try:
                    session.reset(mission=False)
                except CaseStop:
                    pass
                except LinkLost as e:
                    state.lost = str(e)
                    self.active = False
                    return
                finally:
                    session.stop_on_fail = stop
            session.trace = []

            def go():
                session.mark = session.ledger.mark()
                self.ctx = context(session)  # a rule after a failed start still has its fields
                session.reset(mission=False)
                if "OLOGL" in claimed:
                    send(frame("OLOGL,a,b"))
                if "OMLOAD" in claimed:
                    send(frame(f"OMLOAD,{p.mission},0"))
                if start in ("N", "P"):
                    send(frame(f"OMSTART,0,0,0,0,{p.mission},"))
                    session.poll()
                if start == "P":
                    _reach_park(session, self.ctx)
                self.ctx = context(session)
            self._guard(go)

        def _sent(self, body: str) -> None:
            self.mission = self.mission or body.startswith("OMSTART")
            self.timed = self.timed or body.startswith(("OMS,", "OMP,", "OPK,", "OMW,", "ODVL,"))

        def _command(self, body):
            self._sent(body)
            self._guard(lambda: send(frame(fill(body, self.ctx))))

        @rule(body=commands(p, tos, "motion"))
        def motion(self, body):
            self._command(body)

        @rule(body=commands(p, tos, "navigation"))
        def navigation(self, body):
            self._command(body)

        @rule(body=commands(p, tos, "mission"))
        def mission_command(self, body):
            self._command(body)

        @rule(body=commands(p, tos, "data"))
        def data(self, body):
            self._command(body)

        @rule(body=control_commands(speed, motor, tos))
        def control(self, body):
            self._command(body)

        @rule(line=invalid_lines("framing"))
        def framing(self, line):
            """A line the vehicle must read as written or discard (§1: RH-FRM-2..7)."""
            kind, body = line
            self._guard(lambda: send(_raw(kind, fill(body, self.ctx), p)))

        @rule(line=invalid_lines("refused"))
        def refused(self, line):
            """A well-framed line the vehicle must refuse, or discard for its ID (RH-ACK-3, RH-FRM-5)."""
            kind, body = line
            self._guard(lambda: send(_raw(kind, fill(body, self.ctx), p)))

        @rule(bodies=st.lists(st.one_of(commands(p, tos), control_commands(speed, motor, tos)), min_size=2,
                              max_size=3))
        def burst(self, bodies):
            """Lines written back to back before any answer is read (RH-ACK-6)."""
            for b in bodies:
                self._sent(b)

            def go():
                raws = [frame(fill(b, self.ctx)) for b in bodies]
                mets = [cov.before(obs.state(), r) for r in raws]
                for met, sent in zip(mets, session.burst(raws)):
                    cov.command(met, sent.expected)
            self._guard(go)

        @rule(v=st.sampled_from([0.5, 1.0, 2.0, 5.0]))
        def wait_a_while(self, v):
            def go():
                session.wait(v)
                _here(session, self.ctx)
            self._guard(go)

        @rule()
        def poll(self):
            self._guard(lambda: (session.poll(), _here(session, self.ctx)))

        @precondition(lambda self: self.timed)
        @rule(side=st.sampled_from(["before", "after", "after"]))
        def boundary(self, side):
            """Land a report just before the next model timer's deadline, or poll across it until the
            vehicle has left the state (RH-TIM-1's brackets). Timers due past :data:`HORIZON_V` are
            left alone: waiting for them would spend the budget on one sequence."""
            def go():
                got = obs.state().timer()
                if got is None:
                    return
                due_v, dur, name = got
                due_wall = due_v / session.k
                if (due_wall - session.now()) * session.k > HORIZON_V:
                    return
                tol_wall = (tolerance(dur) + session.k * 2 * session.poll_gap) / session.k
                # the lockout's end shows in no report: a command only the lockout refuses shows it
                probe = None
                if name == "lockout":
                    probe = next((frame(b) for b in ("ORWSET,Sle,R", "OLOGL,probe") if b[:b.index(",")]
                                  in claimed), None)
                if side == "before":
                    before = due_wall - 2 * tol_wall - session.poll_gap
                    if before > session.now():
                        session.wait((before - session.now()) * session.k)
                        if obs.state().timer(name) is not None:
                            if probe is not None:
                                send(probe)
                            cov.boundary(name, "before")
                else:
                    session.settle(name, probe)
                    cov.boundary(name, "after")
                _here(session, self.ctx)
            self._guard(go)

        # ---------------------------------------------------------------- episodes
        # the model's deeper paths, one draw each: a control interrupted and released, a timer
        # bracketed, a safety episode with commands inside the lockout and the ascent

        def _settle_next(self, name: Optional[str] = None) -> None:
            got = obs.state().timer(name)
            if got is not None and (got[0] / session.k - session.now()) * session.k <= HORIZON_V:
                session.settle(got[2])
                cov.boundary(got[2], "after")
                _here(session, self.ctx)

        @precondition(lambda self: self.mission)
        @rule(first=control_commands(speed, motor, tos), then=st.one_of(control_commands(speed, motor, tos),
                                                                       st.sampled_from(["OJW,{wp_other}",
                                                                                        "OMW,Clr", "OMSTOP,0"])),
              release=st.booleans())
        def interrupt(self, first, then, release):
            """A control (or the mission park) interrupted by another command, then — when drawn —
            the interrupting control let run out (RH-INT-1..3, RH-OMW-5, RH-JW-2, RH-MSN-3)."""
            self.timed = True

            def go():
                send(frame(fill(first, self.ctx)))
                session.poll()
                _here(session, self.ctx)
                send(frame(fill(then, self.ctx)))
                session.poll()
                if release:
                    self._settle_next("remote")
            self._guard(go)

        @precondition(lambda self: self.mission)
        @rule(then=st.one_of(control_commands(speed, motor, tos), st.sampled_from(["OJW,{wp_other}", "OMW,Clr"])))
        def interrupt_park(self, then):
            """The mission park interrupted, the interruption let run out (RH-INT-2, RH-PK-3)."""
            self.timed = True

            def go():
                if mode() == "N":
                    _reach_park(session, self.ctx)
                if mode() != "P":
                    return
                send(frame(fill(then, self.ctx)))
                session.poll()
                self._settle_next()
            self._guard(go)

        @precondition(lambda self: self.mission)
        @rule(body=control_commands(speed, motor, tos), refresh=st.booleans())
        def timed_control(self, body, refresh):
            """A control bracketed at its timeout; ``refresh``: the same control sent again halfway,
            which must restart its timeout (RH-SRV-3/4, RH-PRM-4, RH-TIM-1)."""
            self.timed = True

            def go():
                send(frame(fill(body, self.ctx)))
                got = obs.state().timer()
                if refresh and got is not None:
                    session.wait(max(0.0, (got[0] / session.k - session.now()) * session.k / 2))
                    send(frame(fill(body, self.ctx)))
                self._settle_next()
            self._guard(go)

        @precondition(lambda self: oxflt and self.faults == 0)
        @rule(code=st.sampled_from(["Sle", "Sop", "Sed"]), inside=commands(p, tos, "motion"),
              after=st.one_of(control_commands(speed, motor, tos), commands(p, tos, "navigation")),
              dive=st.booleans())
        def safety(self, code, inside, after, dive):
            """A whole safety episode (RH-SAF-1..4): optionally dive first, the violation, a command
            inside the lockout, the lockout's end bracketed with a probe, a command in the ascent,
            then the surface."""
            self.faults += 1
            self.timed = True

            def go():
                if obs.state().phase != "none":
                    return
                if dive and mode() in ("N", "P"):
                    send(frame(fill("OMS,90,{dive_depth},20,{speed},120", self.ctx)))
                    session.wait(10.0)
                session.exchange(frame(f"OXFLT,{code}"))
                session.poll()
                send(frame(fill(inside, self.ctx)))
                probe = next((frame(b) for b in ("ORWSET,Sle,R", "OLOGL,probe") if b[:b.index(",")] in claimed),
                             None)
                if probe is not None:
                    send(probe)
                got = obs.state().timer("lockout")
                if got is None:
                    return
                session.settle("lockout", probe)
                cov.boundary("lockout", "after")
                send(frame(fill(after, self.ctx)))
                session.poll()
                _here(session, self.ctx)
            self._guard(go)

        @precondition(lambda self: self.mission)
        @rule()
        def mission_park(self):
            """Get the running mission to its park (then the other rules interrupt it)."""
            self.timed = True

            def go():
                if mode() == "N":
                    _reach_park(session, self.ctx)
            self._guard(go)

        @precondition(lambda self: not self.mission and "ORWSET" in claimed)
        @rule(setting=st.sampled_from(["Sle", "Sop", "Sed"]))
        def write_then_read(self, setting):
            """RH-SET-2: write a changed state and value, read it back; the original written back."""
            from .interpreter import run_step
            self._guard(lambda: run_step(session, SetRoundTrip(setting), self.ctx) if mode() == "S" else None)

        @precondition(lambda self: oxflt and self.faults == 0)
        @rule(code=st.sampled_from(["Sle", "Sop", "Sed"]))
        def fault(self, code):
            """A safety violation (RH-SAF-5): one per sequence; the lockout and the ascent follow."""
            self.faults += 1
            self.timed = True
            self._guard(lambda: session.exchange(frame(f"OXFLT,{code}")) if obs.state().phase == "none" else None)

        def teardown(self):
            """Back to a verified reset inside the example, so that whatever the example set going (a
            lockout, a park, a timer) is judged within it and its replay holds all of it."""
            try:
                if self.active and not self.failed and not state.spent:
                    self._guard(lambda: (session.finish(), session.reset(mission=False)))
            finally:
                if self.failed or not self.active:
                    state.dirty = True
                session.trace = None

    return VehicleMachine


def _confirm(run, best: dict) -> int:
    """Re-drive the smallest failing sequence twice; how many times it failed again."""
    from .replay import redrive
    n = 0
    for _ in range(2):
        try:
            doc = {"steps": best["steps"], "time_scale": run.k, "lazy_silence": True}
            verdict, _, _ = redrive(doc, run.session)
        except LinkLost:
            raise
        n += verdict == "fail"
    return n


def explore(run) -> None:
    """Run the exploration for a :class:`~.runner.Run` and record what it found."""
    o = run.o
    p = run.p
    budget = PROFILES.get(o.hypothesis_profile, PROFILES["fast"])
    if o.examples is not None:
        budget = budget._replace(examples=o.examples)
    if o.explore_budget_s is not None:
        budget = budget._replace(wall_s=o.explore_budget_s)
    examples, steps = budget.examples, budget.steps
    if examples <= 0:
        return
    if "OMSTOP" not in p.commands:  # every sequence starts from a verified reset ($OMSTOP,0 until S)
        run.session.note("exploration: not run: the verified reset needs $OMSTOP, which the profile "
                         "does not claim")
        run.stats["explore"] = {"examples": 0, "ran": 0, "outcome": "not run (no $OMSTOP claimed)"}
        return
    state = _State(run, budget)
    state.examples = examples
    state.progress = run.progress
    machine = _machine(state, p, timeouts(run.session.k, p.timeout_range))
    db = DirectoryBasedExampleDatabase(str(run.dir / ".hypothesis"))
    session = run.session
    session.note(f"exploration: {examples} examples of up to {steps} steps, budget {budget.wall_s:g} s wall "
                 f"and {budget.vehicle_s:g} s vehicle time")
    session.note("held: the exploration's violations wait for their re-runs after shrinking")
    session.begin_case("explore", (), "hypothesis exploration of command sequences")
    t0 = time.monotonic()
    outcome = "pass"
    session.lazy_silence = True
    on_poll, session.on_poll = session.on_poll, lambda: (state.coverage.report(session.obs.state()),
                                                         on_poll and on_poll())
    try:
        # in batches: hypothesis runs its examples to the end even when the budget is spent (each
        # still drawing its steps), so the exploration asks for BATCH at a time until it is spent
        done = 0
        batch = 0
        while done < examples and not state.spent and outcome == "pass":
            n = min(BATCH, examples - done)
            factory = machine if o.seed is None else seed(o.seed * 1000 + batch)(machine)
            cfg = settings(max_examples=n, stateful_step_count=steps, deadline=None, database=db,
                           suppress_health_check=list(HealthCheck), report_multiple_bugs=False, print_blob=False,
                           phases=(Phase.explicit, Phase.reuse, Phase.generate, Phase.shrink))
            try:
                run_state_machine_as_test(factory, settings=cfg)
            except Exception as e:  # noqa: BLE001 - a finding about the vehicle, or a tester error
                if _vehicle_finding(e, state.failures):
                    outcome = type(e).__name__
                else:
                    state.tester_error(e)
            done += n
            batch += 1
        if outcome == "pass" and state.failures:  # found, and the budget ran out while shrinking
            outcome = "VehicleFailure"
    finally:
        session.trace = None
        session.lazy_silence = False
        session.on_poll = on_poll
        session.end_case()
    error = state.error
    which = state.which_spent
    spent = error is None and (state.skipped > 0 or which is not None)
    run.stats["explore"] = {"examples": examples, "ran": state.executions, "failures": state.failures,
                            "budget_s": budget.wall_s, "budget_vehicle_s": budget.vehicle_s,
                            "budget_spent": spent, "wall_s": round(time.monotonic() - t0, 3),
                            "vehicle_s": round(state.vehicle_spent, 1),
                            "outcome": outcome if error is None else "tester error",
                            "model_coverage": state.coverage.summary()}
    if error is not None:
        first = (str(error).splitlines() or [""])[0][:160]
        run.stats["explore"]["error"] = f"{type(error).__name__}{': ' + first if first else ''}"
        session.note(f"exploration: tester error after {state.executions} sequence(s) "
                     f"({run.stats['explore']['error']}); the run stops")
        raise error
    session.note(state.coverage.line())
    clock = {"wall": f"the {budget.wall_s:g} s wall budget", "vehicle": f"the {budget.vehicle_s:g} s vehicle-time "
             f"budget"}.get(which or "wall")
    session.note(f"exploration: {state.executions} sequence(s) ran" +
                 (f"; {clock} was spent before {examples} examples" if spent else ""))
    if state.best is not None:
        run.stats["explore"]["found"] = state.best["reason"]
    if state.lost:
        raise LinkLost(state.lost)
    best = state.best
    if best is None:
        session.note("confirmed: the exploration found no violation")
        return
    cid = best["clause"] or best["reason"].split(":", 1)[0]
    session.begin_case("explore-confirm", (), "the smallest failing sequence, driven again")
    try:
        confirmed = _confirm(run, best)
    finally:
        session.end_case()
    session.note(f"{'confirmed' if confirmed == 2 else 'unconfirmed'}: reproduced {confirmed} of 2 re-runs "
                 f"after shrinking")
    flaky = confirmed < 2
    run.stats["explore"]["confirmed"] = f"{confirmed}/2"
    if cid not in run.ledger:
        return
    n = sum(1 for r in run.results["replays"] if r["clause"] == cid) + 1
    rel = f"replays/{cid}-{n}.json"
    save_replay(run.dir / rel, cid, best["reason"], best["steps"], run.k, p)
    from ...reports import results as R
    R.add_replay(run.results, cid, best["steps"], file=rel)
    run.stats["explore"]["replay"] = rel
    run.stats["explore"]["flaky"] = flaky
