"""Exploration: hypothesis sequences of valid and invalid commands, judged step by step.

:class:`VehicleMachine` is a hypothesis ``RuleBasedStateMachine`` whose rules send a valid
command, send an invalid line (one mutation of a valid one: out-of-range field, wrong field
count, bad checksum, lower-case ID), let protocol time pass (vehicle seconds ÷ k, RH-TIM-2),
poll ``$OSD,S`` and, when the profile declares it, raise a safety violation with ``$OXFLT``.
Every reply and every ``$OSI`` is judged by the vehicle observer, as everywhere else; an example
fails when the observer booked a failure during it (the example stops there, raising
:class:`VehicleFailure`: the one exception hypothesis is meant to find and shrink).

Each example starts from a verified reset (with ``$OLOGL`` and ``$OMLOAD`` in ``S`` so that the
observer knows the log labels and the loaded mission), then optionally starts the test mission.

Shrinking re-runs candidates against the live vehicle. The run keeps the smallest failing
sequence it saw and saves that as a version-independent replay file (:mod:`.replay`), whatever
hypothesis ends with, and re-drives it twice to say whether it fails again. Exploration has a
wall-clock budget (``fast``: emulators, ``patient``: hardware); when it is spent, the remaining
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
from typing import Optional

from hypothesis import HealthCheck, Phase, seed, settings, strategies as st
from hypothesis.database import DirectoryBasedExampleDatabase
from hypothesis.errors import Flaky
from hypothesis.stateful import RuleBasedStateMachine, initialize, precondition, rule, run_state_machine_as_test

from ...judge.timing import JITTER_S
from .flow import CaseStop, LinkLost
from .interpreter import _here, context, fill, raw_line
from .replay import save_replay
from .safety import BenchSafetyRefused
from .session import frame

__all__ = ["explore", "PROFILES", "valid_commands", "control_commands", "invalid_lines", "VehicleFailure"]

#: name -> (examples, steps per example, wall budget in seconds)
PROFILES = {"fast": (20, 10, 25.0), "patient": (6, 8, 600.0)}

#: Remote-control timeouts the exploration draws from (seconds), before :func:`timeouts` keeps those
#: the observer can time at the time scale.
TIMEOUT_CHOICES = (2, 3, 5, 8, 12, 20, 30)


def timeouts(k: float, timeout_range=(1, 120)):
    """The timeouts an exploration sends at time scale ``k``: those whose RH-TIM-1 judgement the
    observer's own uncertainty cannot spoil (k × its jitter and a pty's transmit time, twice over
    for margin, within half the duration: :func:`~helmcheck.judge.timing.judgeable`), within the
    profile's ``timeout_range``. A case that cannot time its own timeout is the tester's defect."""
    lo, hi = int(timeout_range[0]), int(timeout_range[1])
    shortest = 4.0 * k * (JITTER_S + 0.01)
    keep = [d for d in TIMEOUT_CHOICES if lo <= d <= hi and d >= shortest]
    if not keep:
        keep = [max(lo, min(hi, int(shortest) + 1))]
    return st.sampled_from(keep[:5])


_TIMEOUTS = timeouts(1.0)


def _num(lo: float, hi: float, places: int = 1):
    return st.integers(int(lo * 10 ** places), int(hi * 10 ** places)).map(lambda n: f"{n / 10 ** places:g}")


def valid_commands(nwp: int, speed: float, motor: int, oxflt: bool, tos=_TIMEOUTS):
    """Bodies (with ``{lat}``-style templates) of well-formed commands, bench-safe."""
    spd = _num(0, speed)
    hexb = st.integers(0x60, 0xA0).map(lambda b: f"{b:02X}")
    mot = st.integers(0x80, max(0x80, motor)).map(lambda b: f"{b:02X}")
    return st.one_of(
        st.builds(lambda h, d, p, v, t: f"OMS,{h},{d},{p},{v},{t}", _num(0, 359), _num(0, 4), _num(0, 45, 0), spd,
                  tos),
        st.builds(lambda a, b, m, t: f"OMP,{a}{a}{b}{b}{m},00,{t}", hexb, hexb, mot, tos),
        st.builds(lambda n: f"OJW,{n}", st.integers(0, nwp)),
        st.builds(lambda m, v: f"OPK,{{lat}},{{lon}},{m},{v}", st.integers(1, 2), spd),
        st.builds(lambda v, p: f"OMW,{{near_lat}},{{lon}},2,,15,{v},{p},", spd, st.sampled_from([0, 5])),
        st.sampled_from(["OMW,Clr", "OMW,CLEAR", "OMW,stop", "OMSTOP,0", "OMSTART,0,0,0,0,{mission},",
                         "OMLOAD,{mission},0", "OMSTART,0", "OLOGD,1,2", "ORWSET,Sle,R", "OLOGL,x,y",
                         "OPOS,{lat},{lon},0.5,,", "ODVL,0.5,0,3", "OSD,G,C,S,P,,,,", "OSD,S,S", "OSD,S,Q"]),
    )


def control_commands(speed: float, motor: int, tos=_TIMEOUTS):
    """The remote-control commands (RH-INT-1), drawn more often than the rest."""
    spd = _num(0, speed)
    mot = st.integers(0x80, max(0x80, motor)).map(lambda b: f"{b:02X}")
    return st.one_of(
        st.builds(lambda v, t: f"OMS,90,2,20,{v},{t}", spd, tos),
        st.builds(lambda m, t: f"OMP,80808080{m},00,{t}", mot, tos),
        st.builds(lambda v: f"OPK,{{lat}},{{lon}},1,{v}", spd),
        st.builds(lambda v: f"OMW,{{near_lat}},{{lon}},2,,15,{v},0,", spd),
    )


def invalid_lines():
    """(kind, body) pairs: one mutation of a valid command each."""
    return st.one_of(
        st.tuples(st.just("frame"), st.sampled_from(["OMS,400,2,20,0,5", "OMS,90,2,20,0,0", "OMP,80808080,00,5",
                                                      "OJW,-1", "OPK,{lat},{lon},0,0", "ODVL,9,0,3",
                                                      "OMSTOP,2", "OMW,,1,2,3", "OSD,x", "OMS,90,2,20"])),
        st.tuples(st.sampled_from(["badck", "lowerid", "nock"]),
                  st.sampled_from(["OMSTOP,0", "OMS,90,2,20,0,5", "OJW,1", "OSD,S"])),
    )


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

    def __init__(self, run, budget: float):
        self.run = run
        self.budget = budget
        self.end = time.monotonic() + budget
        self.executions = 0  #: sequences that ran at least their reset
        self.skipped = 0  #: sequences hypothesis asked for after the budget was spent
        self.best: Optional[dict] = None  #: smallest failing trace so far
        self.examples = 0
        self.progress = None
        self.failures = 0
        self.passes_after_fail = 0
        self.lost: Optional[str] = None
        self.error: Optional[Exception] = None  #: the first tester error (module docstring)

    @property
    def spent(self) -> bool:
        return time.monotonic() > self.end or self.lost is not None or self.error is not None

    def tester_error(self, e: Exception) -> None:
        if self.error is None:
            self.error = e


def _machine(state: _State, start_states, nwp, speed, motor, oxflt, tos=_TIMEOUTS):
    session = state.run.session

    class VehicleMachine(RuleBasedStateMachine):
        def __init__(self):
            super().__init__()
            self.active = not state.spent
            self.ctx: dict = {}
            self.steps = 0
            if self.active:
                state.executions += 1
                session.trace = []
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
            state.failures += 1
            trace = list(session.trace or [])
            if state.best is None or len(trace) < len(state.best["steps"]):
                state.best = {"clause": f.clause or "", "reason": f.reason, "steps": trace}

        @initialize(start=st.sampled_from(start_states))
        def start(self, start):
            def go():
                session.mark = session.ledger.mark()
                self.ctx = context(session)  # a rule after a failed start still has its fields
                session.reset(mission=False)
                session.exchange(frame("OLOGL,a,b"))
                session.exchange(frame(f"OMLOAD,{session.profile.mission},0"))
                if start == "N":
                    session.exchange(frame(f"OMSTART,0,0,0,0,{session.profile.mission},"))
                    session.poll()
                self.ctx = context(session)
            self._guard(go)

        @rule(body=valid_commands(nwp, speed, motor, oxflt, tos))
        def send_valid(self, body):
            self._guard(lambda: session.exchange(frame(fill(body, self.ctx))))

        @rule(body=control_commands(speed, motor, tos))
        def control(self, body):
            self._guard(lambda: session.exchange(frame(fill(body, self.ctx))))

        @rule(line=invalid_lines())
        def send_invalid(self, line):
            kind, body = line
            self._guard(lambda: session.exchange(_raw(kind, fill(body, self.ctx), session.profile)))

        @rule(v=st.sampled_from([1.0, 2.0, 5.0, 12.0]))
        def wait_a_while(self, v):
            def go():
                session.wait(v)
                _here(session, self.ctx)
            self._guard(go)

        @rule()
        def poll(self):
            self._guard(lambda: (session.poll(), _here(session, self.ctx)))

        @precondition(lambda self: oxflt)
        @rule(code=st.sampled_from(["Sle", "Sop", "Sed"]), go=st.integers(0, 3))
        def fault(self, code, go):
            if go == 0:  # a lockout costs lockout_s of protocol time: keep them rare
                self._guard(lambda: session.exchange(frame(f"OXFLT,{code}")))

        def teardown(self):
            session.trace = None

    return VehicleMachine


def _confirm(run, best: dict) -> int:
    """Re-drive the smallest failing sequence twice; how many times it failed again."""
    from .replay import redrive
    n = 0
    for _ in range(2):
        try:
            verdict, _, _ = redrive({"steps": best["steps"]}, run.session)
        except LinkLost:
            raise
        n += verdict == "fail"
    return n


def explore(run) -> None:
    """Run the exploration for a :class:`~.runner.Run` and record what it found."""
    o = run.o
    p = run.p
    examples, steps, budget = PROFILES.get(o.hypothesis_profile, PROFILES["fast"])
    if o.examples is not None:
        examples = o.examples
    if o.explore_budget_s is not None:
        budget = o.explore_budget_s
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
    bench = p.bench_safety
    speed = min(2.0, p.max_speed_kn, bench.max_speed_kn if not bench.in_water else 99.0)
    motor = min(0x90, bench.max_motor_byte) if not bench.in_water else 0x90
    factory = _machine(state, ["N", "S"], p.mission_waypoints, speed, motor, p.fault_injection == "oxflt",
                       timeouts(run.session.k, p.timeout_range))
    if o.seed is not None:
        factory = seed(o.seed)(factory)
    db = DirectoryBasedExampleDatabase(str(run.dir / ".hypothesis"))
    cfg = settings(max_examples=examples, stateful_step_count=steps, deadline=None, database=db,
                   suppress_health_check=list(HealthCheck), report_multiple_bugs=False, print_blob=False,
                   phases=(Phase.explicit, Phase.reuse, Phase.generate, Phase.shrink))
    session = run.session
    session.note(f"exploration: {examples} examples of up to {steps} steps, budget {budget:g} s")
    session.note("held: the exploration's violations wait for their re-runs after shrinking")
    session.begin_case("explore", ("RH-OUT-4",), "hypothesis exploration of command sequences")
    t0 = time.monotonic()
    outcome = "pass"
    session.lazy_silence = True
    try:
        run_state_machine_as_test(factory, settings=cfg)
    except Exception as e:  # noqa: BLE001 - a finding about the vehicle, or a tester error
        if _vehicle_finding(e, state.failures):
            outcome = type(e).__name__
        else:
            state.tester_error(e)
    finally:
        session.trace = None
        session.lazy_silence = False
        session.end_case()
    error = state.error
    spent = error is None and (state.skipped > 0 or time.monotonic() > state.end)
    run.stats["explore"] = {"examples": examples, "ran": state.executions, "failures": state.failures,
                            "budget_s": budget, "budget_spent": spent,
                            "wall_s": round(time.monotonic() - t0, 3),
                            "outcome": outcome if error is None else "tester error"}
    if error is not None:
        first = (str(error).splitlines() or [""])[0][:160]
        run.stats["explore"]["error"] = f"{type(error).__name__}{': ' + first if first else ''}"
        session.note(f"exploration: tester error after {state.executions} sequence(s) "
                     f"({run.stats['explore']['error']}); the run stops")
        raise error
    session.note(f"exploration: {state.executions} sequence(s) ran" +
                 (f"; the {budget:g} s budget was spent before {examples} examples" if spent else ""))
    if state.best is not None:
        run.stats["explore"]["found"] = state.best["reason"]
    if state.lost:
        raise LinkLost(state.lost)
    best = state.best
    if best is None:
        session.note("confirmed: the exploration found no violation")
        return
    cid = best["clause"] or best["reason"].split(":", 1)[0]
    session.begin_case("explore-confirm", ("RH-OUT-4",), "the smallest failing sequence, driven again")
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
