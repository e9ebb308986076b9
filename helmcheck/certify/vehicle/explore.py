"""Exploration: hypothesis sequences aimed at the model, judged step by step.

The state machine (:mod:`.machine`) is a hypothesis ``RuleBasedStateMachine``. Its rules draw from
:mod:`.generate` (every claimed command at the edges of its ranges, and with one field at a time
at an edge or one past it; every error code, every mutation of a line, bursts), and walk the
model's map: the remote controls (drawn more often, so that each control mode meets each command:
the interrupt pairs; an ``$OPK`` park interrupted and released; a steer to the wrap of the compass
read with every ``$OSD`` letter), the mission park (``P`` as a
start, or reached from ``N``), a report landed just *before* the next model timer's deadline and
the timer polled *across* it (RH-TIM-1's brackets; the lockout's end with a probe), a safety
violation (``$OXFLT``, when the profile declares it) and ``$ORWSET`` written then read. Protocol
time passes in vehicle seconds ÷ k (RH-TIM-2). Every reply and every ``$OSI`` is judged by the
vehicle observer, as everywhere else; an example fails when the observer booked a failure during
it (the example stops there, raising :class:`VehicleFailure`: the one exception hypothesis is
meant to find and shrink). Steering is hypothesis's own: ``@initialize`` for the start state,
``@precondition`` on what the example has sent (never on the live vehicle, whose timing hypothesis
cannot replay: a rule whose state the vehicle is not in does nothing), and its swarm testing of
rules. What the run's lines reached of the model is counted (:mod:`.modelcover`, the cases' apart)
and the exploration's reach kept in ``stats.explore.model_coverage``.

The batches take turns by the time each kind has used (:data:`SHARES`): random sequences that
wait for nothing, random episodes, and tours aimed at what the run has not reached yet on this
vehicle (:mod:`.aim` lists it as targets before each aimed batch, :mod:`.tour` drives them). When
the budget is spent by time, one target no aimed batch's share could hold (the vehicle's own
mission toured to its long park's end), if the run has not reached what it reaches, is driven
after it, the budget extended by its estimated cost and a quarter (:func:`_long_tour`; never when
``--explore-budget`` is given: that budget is kept as given).

Each example starts from a verified reset, at the surface (a dive before it: the vehicle's GPS fix
back, :meth:`.session.Session.outwait_surface`), with ``$OLOGL`` and ``$OMLOAD`` in ``S`` so that the
observer knows the log labels and the loaded mission, and an ``$OPOS`` at the vehicle's own
position so that the conductivity and temperature it reports are the sequence's own, not what
came before the reset; then starts the test mission or reaches
its park if drawn — all of it recorded from the reset on (the reset itself is not: a replay
begins with one of its own) — and ends with a verified reset of its own, inside the example: a
lockout or a park it set going is judged within it, never in the next one, so the replay of a
failure holds everything from the reset that led to it.

Shrinking re-runs candidates against the live vehicle, for at most :data:`SHRINK_SHARE` of the
budget from a batch's first failure. A finding does not end the exploration: the batches after it
do not stop at the clauses already found (:attr:`.session.Session.ignore`; their violations are
still held and booked), so they look on for the others; nor does a sequence stop at a clause its
starting reset already shows violated (carried over from an earlier sequence). The run keeps the
smallest failing sequence of each clause, whatever hypothesis ends with, and re-drives each
(the others found not stopped at) to say whether it fails again on its clause, inside its steps,
until two re-runs count, at most four times: a re-drive in which the vehicle went another way
than recorded and the failure did not come says nothing either way and is not counted
(:func:`counts`), nor is one that failed before the steps or could not run them.
2 of 2 books that clause's held violations as violations (``confirmed RH-X: …``) and saves the
sequence as a version-independent replay file (:mod:`.replay`); fewer books them INCONCLUSIVE
(``unconfirmed RH-X: …``) and keeps the sequence in ``replays/unconfirmed/`` for people. Held
violations of no clause found (seen only in a reset between sequences) are INCONCLUSIVE too. Exploration has a
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

from hypothesis import HealthCheck, Phase, Verbosity, seed, settings
from hypothesis.database import DirectoryBasedExampleDatabase
from hypothesis.errors import Flaky
from hypothesis.stateful import run_state_machine_as_test

from .aim import MissionSurvey, targets
from .flow import LinkLost
from .generate import control_commands, invalid_lines, timeouts, valid_commands
from .machine import VehicleFailure, machine
from .tour import TOUR_MAX
from .replay import save_replay

__all__ = ["explore", "PROFILES", "Budget", "aimed_steps", "valid_commands", "control_commands", "invalid_lines", "timeouts",
           "VehicleFailure"]


class Budget(NamedTuple):
    """An exploration budget: examples, steps per example, wall seconds, vehicle seconds. The
    exploration stops at whichever of the two clocks runs out first: on an emulator at a high time
    scale the wall clock binds, on a vehicle at ×1 the forced waits (vehicle time) do."""

    examples: int
    steps: int
    wall_s: float
    vehicle_s: float


#: Examples asked of hypothesis at a time (:func:`explore`), and the share of the time each kind
#: of batch takes: sequences that wait for nothing (:func:`.machine.machine`, ``deep=False``), the
#: episodes (``deep=True``), and the tours aimed at what the run has not reached (:mod:`.tour`).
BATCH = 2
SHARES = {"shallow": 0.1, "deep": 0.2, "aimed": 0.7}
#: Examples in an aimed batch: one sequence that drives the batch's whole list, a tour of
#: :data:`.tour.TOUR_MAX` targets at a time (the aim is made again before every batch).
AIMED_BATCH = 1
#: The share of the wall budget one aimed batch may take (its list made for that much).
AIMED_SLICE = 0.35
#: A target no aimed batch's share holds (:func:`.aim.targets`, ``whole_v``: the vehicle's own
#: mission toured to its park's end — a third vehicle's 165 s park and its legs are longer than a
#: slice at ×20) is driven once, after the budget, which it extends by its estimated cost × this
#: at most (:func:`_long_tour`).
LONG_MARGIN = 1.25
#: … and costs at most this share of the budget (in vehicle seconds): a longer tour is not owed,
#: the budget asked for was not sized for that vehicle's mission (``--explore-budget`` is).
LONG_AT_MOST = 0.5
#: The order the kinds take their first turn (and the tie-break after).
_FIRST = ("shallow", "aimed", "deep")
#: The share of the wall budget one finding's shrinking may take (from its first failure); the
#: exploration then goes on looking for violations of other clauses with the rest.
SHRINK_SHARE = 0.2

#: name -> :class:`Budget`
PROFILES = {"fast": Budget(400, 40, 30.0, 1500.0), "patient": Budget(8, 10, 900.0, 600.0)}


def aimed_steps(targets: int) -> int:
    """hypothesis's ``stateful_step_count`` for an aimed batch of ``targets``: one ``tour`` step per
    :data:`~.tour.TOUR_MAX` of them, and one for the verified reset — hypothesis counts the
    ``@initialize`` rule as a step too (with one fewer, a list of eight or fewer was never driven)."""
    return 1 + -(-targets // TOUR_MAX)


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
        self.steps = 0  #: steps the sequences ran (for the progress display and stats.explore)
        self.skipped = 0  #: sequences hypothesis asked for after the budget was spent
        #: clause -> the smallest failing trace of it so far ({clause, reason, steps}), in the order found
        self.found: dict[str, dict] = {}
        self.ignored: frozenset = frozenset()  #: the clauses found before the present batch
        self.batch_end = self.end  #: when the present batch stops (its shrinking is capped: :meth:`shrink_from`)
        self.examples = 0
        self.progress = None
        self.failures = 0
        self.lost: Optional[str] = None
        self.error: Optional[Exception] = None  #: the first tester error (module docstring)
        self.coverage = run.session.cover  #: the run's model coverage (:mod:`.modelcover`)
        #: the mutations of a line sent so far (:data:`.steps.RAW_KINDS`) and the aim's probes driven
        self.lines_sent: set = set()
        #: the vehicle's mission as its reports describe it (:mod:`.aim`)
        self.survey = MissionSurvey(max(1, run.p.mission_waypoints))
        self.seq0 = run.session.obs.seq  #: the observer's line count when the exploration began
        self.long_done = False  #: the long tour after the budget was considered (:func:`_long_tour`)
        self.long_tour: Optional[dict] = None  #: what it drove, and the extension it took

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

    @property
    def batch_spent(self) -> bool:
        """The whole budget is spent, or the present batch's share of it."""
        return self.spent or time.monotonic() > self.batch_end

    def new_batch(self, share: float = 1.0) -> None:
        """A batch begins: it may run until the budget is spent, or for ``share`` of the wall budget."""
        self.batch_end = min(self.end, time.monotonic() + share * self.budget.wall_s)

    def shrink_from(self) -> None:
        """A failure in the present batch: its shrinking gets :data:`SHRINK_SHARE` of the budget,
        counted from the batch's first failure, and the batches after it the rest."""
        if self.batch_end >= self.end:
            self.batch_end = min(self.end, time.monotonic() + self.budget.wall_s * SHRINK_SHARE)

    def show_progress(self) -> None:
        """The share of the budget used and the sequences run so far, to the progress display
        (at each sequence's start and after each step)."""
        if self.progress is not None:
            self.progress.explore(self.executions, time.monotonic() - self.t0, self.budget.wall_s,
                                  self.vehicle_spent, self.budget.vehicle_s, steps=self.steps)

    def tester_error(self, e: Exception) -> None:
        if self.error is None:
            self.error = e


#: A finding is confirmed when this many re-runs of its smallest failing sequence reproduce it …
CONFIRM_RERUNS = 2
#: … counting only re-runs that say something (:func:`counts`); at most this many re-drives.
CONFIRM_TRIES = 4


def counts(got, also) -> Optional[bool]:
    """Whether a re-drive (a :class:`~.replay.Redrive`) counts as a re-run of a finding booked on
    the clauses ``also``, and if so whether it reproduced it: ``True`` it failed again on one of
    them, within the steps; ``False`` the steps ran the recorded way and it did not (a pass, or a
    failure on another clause first); ``None`` it says nothing either way — the vehicle failed
    already in the verified reset before the steps, the steps could not be run or judged
    (INCONCLUSIVE), or the vehicle went another way than when they were recorded and the failure
    did not come (a timer raced a line differently: the steps did not lead where they led)."""
    if got.verdict == "fail" and got.ran and got.clause in also:
        return True
    if got.verdict == "inconclusive" or not got.faithful:
        return None
    return False


def _confirm(run, best: dict) -> tuple[int, int, list[str]]:
    """Re-drive the smallest failing sequence of one clause until :data:`CONFIRM_RERUNS` re-runs
    count (:func:`counts`), at most :data:`CONFIRM_TRIES` times: how many reproduced the failure
    on that clause (the other clauses found are not stopped at: :attr:`.session.Session.ignore`),
    how many re-drives did not count, and what each said (those that did not count marked so)."""
    from .replay import redrive
    n = counted = 0
    said = []
    for _ in range(CONFIRM_TRIES):
        doc = {"steps": best["steps"], "time_scale": run.k, "lazy_silence": True, "origin": best.get("origin")}
        got = redrive(doc, run.session)
        again = counts(got, best["also"])
        said.append(f"{got.verdict}{' (not counted)' if again is None else ''}: {got.reason}"[:300])
        if again is not None:
            counted += 1
            n += again
            if counted == CONFIRM_RERUNS:
                break
    return n, len(said) - counted, said


def _found_clauses(found: dict) -> frozenset:
    """Every clause the findings so far were booked on (each finding's own and those its
    observation was booked on too, :meth:`.machine.VehicleMachine._failed`)."""
    return frozenset(c for f in found.values() for c in f["also"])


def _aim(run, state, left_v: Optional[float] = None, whole_v: Optional[float] = None) -> list:
    """The targets of the next aimed batch (:func:`.aim.targets`), from what the run reached so far
    and the vehicle's mission as its reports showed it: those that fit in ``left_v`` vehicle
    seconds (by default what is left of the batch), or (``whole_v``) one long target alone."""
    session = run.session
    entry = session.obs.missions.entry(run.p.mission)
    park_wp = entry.park_waypoint if entry is not None else None
    park_s = float(entry.parks.get(park_wp) or 0.0) if park_wp is not None else 0.0
    if left_v is None:
        left_v = min(state.budget.vehicle_s - state.vehicle_spent, (state.batch_end - time.monotonic()) * state.k)
    lines = max(1, session.obs.seq - state.seq0)
    per_line = (time.monotonic() - state.t0) / lines
    return targets(state.coverage, session.edges, run.p, state.survey, park_wp=park_wp, park_s=park_s,
                   durations=session.durations().context(), k=state.k, line_wall_s=per_line, left_v=left_v,
                   lines_sent=state.lines_sent, whole_v=whole_v)


def _long_tour(run, state) -> Optional[list]:
    """Once the budget is spent by time (not by examples): the one target no aimed batch could hold
    — its estimated cost more than :data:`AIMED_SLICE` of the budget, at most :data:`LONG_AT_MOST`
    of it; the vehicle's own mission toured to its long park's end — as one more batch,
    the budget extended by its cost × :data:`LONG_MARGIN` (the tour ends the batch when done).
    None when nothing is owed: such a target was driven already, none is left uncovered, or the
    run stopped for another reason (a tester error, the link lost)."""
    if state.long_done or state.error is not None or state.lost is not None or state.which_spent is None:
        return None
    state.long_done = True
    b, k = state.budget, state.k
    slice_v = AIMED_SLICE * min(b.vehicle_s, b.wall_s * k)
    aim = _aim(run, state, left_v=slice_v, whole_v=LONG_AT_MOST * min(b.vehicle_s, b.wall_s * k))
    if len(aim) != 1 or aim[0].cost_v <= slice_v:
        return None
    extra_v = LONG_MARGIN * aim[0].cost_v
    now = time.monotonic()
    state.end = state.batch_end = now + extra_v / k
    state.budget = b._replace(vehicle_s=state.vehicle_spent + extra_v)
    state.long_tour = {"reaches": list(aim[0].reaches), "cost_v": round(aim[0].cost_v, 1),
                       "extended_wall_s": round(extra_v / k, 1)}
    run.session.note(f"exploration: the budget spent; one tour no batch's share could hold, after it "
                     f"({', '.join(aim[0].reaches)}): about {aim[0].cost_v:.0f} s of vehicle time, the "
                     f"budget extended by {extra_v / k:.1f} s of wall time at most")
    return aim


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
    tos = timeouts(run.session.durations(fresh=True).to, p.timeout_range)  # timeable on this line
    kinds = (machine(state, p, tos, deep=False), machine(state, p, tos, deep=True))
    db = DirectoryBasedExampleDatabase(str(run.dir / ".hypothesis"))
    session = run.session
    session.note(f"exploration: {examples} examples of up to {steps} steps, budget {budget.wall_s:g} s wall "
                 f"and {budget.vehicle_s:g} s vehicle time")
    session.note("held: the exploration's violations wait for their re-runs after shrinking")
    session.begin_case("explore", (), "hypothesis exploration of command sequences")
    t0 = time.monotonic()
    outcome = "pass"
    session.lazy_silence = True
    state.coverage.source = "explore"
    on_poll, session.on_poll = session.on_poll, lambda: (state.survey.seen(session.obs.last_osi),
                                                         on_poll and on_poll())
    try:
        # in batches: hypothesis runs its examples to the end even when the budget is spent (each
        # still drawing its steps), so the exploration asks for a batch at a time until it is spent;
        # the batches take turns by time (SHARES): sequences that wait for nothing (many lines
        # each, the one-step paths), those with the episodes that wait out timers, parks and the
        # lockout, and tours aimed at what the run has not reached yet (:mod:`.aim`), the aim
        # made again before each of their batches; shallow first, then aimed
        done = 0
        batch = 0
        spent_by = dict.fromkeys(SHARES, 0.0)  # wall seconds spent on each kind of batch
        aim_empty = False
        while done < examples:
            long_aim = None
            if state.spent:  # the budget is spent: one long tour after it, if one is owed (_long_tour)
                long_aim = _long_tour(run, state) if o.explore_budget_s is None else None
                if long_aim is None:
                    break
            # a clause found is not stopped at again: the sequences look on for the others
            state.ignored = session.ignore = _found_clauses(state.found)
            state.new_batch()
            order = sorted(SHARES, key=lambda x: (spent_by[x] / SHARES[x], _FIRST.index(x)))
            which = next(x for x in order if not (x == "aimed" and aim_empty))
            n, count = min(BATCH, examples - done), steps
            if long_aim is not None:
                which = "aimed"
                kind = machine(state, p, tos, deep=True, aim=long_aim)
                n, count = 1, aimed_steps(1)
            elif which == "aimed":
                state.new_batch(AIMED_SLICE)  # the random batches take their turns between
                aim = _aim(run, state)
                if not aim:
                    aim_empty = True  # nothing left to aim at: the random batches share the rest
                    session.note("exploration: nothing left to aim at")
                    continue
                kind = machine(state, p, tos, deep=True, aim=aim)
                n, count = min(AIMED_BATCH, examples - done), aimed_steps(len(aim))
            else:
                kind = kinds[which == "deep"]
            factory = kind if o.seed is None else seed(o.seed * 1000 + batch)(kind)
            b0 = time.monotonic()
            cfg = settings(max_examples=n, stateful_step_count=count, deadline=None, database=db,
                           suppress_health_check=list(HealthCheck), report_multiple_bugs=False, print_blob=False,
                           # quiet: hypothesis would print the steps of a failing example to stdout;
                           # the run records its own (the replay, the wire log)
                           verbosity=Verbosity.quiet,
                           # once something is found, reusing the saved examples would replay that finding
                           phases=(Phase.explicit, *(() if state.found else (Phase.reuse,)), Phase.generate,
                                   Phase.shrink))
            try:
                run_state_machine_as_test(factory, settings=cfg)
            except Exception as e:  # noqa: BLE001 - a finding about the vehicle, or a tester error
                if _vehicle_finding(e, state.failures):
                    outcome = type(e).__name__ if outcome == "pass" else outcome
                else:
                    state.tester_error(e)
            spent_by[which] += time.monotonic() - b0
            done += n
            batch += 1
        if outcome == "pass" and state.failures:  # found, and the budget ran out while shrinking
            outcome = "VehicleFailure"
    finally:
        session.trace = None
        session.ignore = frozenset()
        session.lazy_silence = False
        session.on_poll = on_poll
        state.coverage.source = None  # the re-drives below are not counted: they repeat a sequence
        for eid, case in session.edges.reached.items():  # for the traceability table (modelcover.keys)
            if case == "explore":
                state.coverage.reach["explore"].edges.add(eid)
        session.end_case()
    error = state.error
    which = state.which_spent
    spent = error is None and (state.skipped > 0 or which is not None)
    run.stats["explore"] = {"examples": examples, "ran": state.executions, "steps": state.steps,
                            "failures": state.failures,
                            "budget_s": budget.wall_s, "budget_vehicle_s": budget.vehicle_s,
                            "budget_spent": spent, "wall_s": round(time.monotonic() - t0, 3),
                            "vehicle_s": round(state.vehicle_spent, 1),
                            "outcome": outcome if error is None else "tester error",
                            **({"long_tour": state.long_tour} if state.long_tour else {}),
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
    if state.lost:
        raise LinkLost(state.lost)
    if not state.found:
        session.note("confirmed: the exploration found no violation")
        return
    findings = []
    session.begin_case("explore-confirm", (), "the smallest failing sequence of each clause found, driven again")
    try:
        for cid, best in state.found.items():
            session.ignore = _found_clauses(state.found) - set(best["also"])
            try:
                confirmed, idle, reruns = _confirm(run, best)
            finally:
                session.ignore = frozenset()
            session.note(f"{'confirmed' if confirmed == CONFIRM_RERUNS else 'unconfirmed'} "
                         f"{','.join(best['also'])}: reproduced {confirmed} of {CONFIRM_RERUNS} re-runs after shrinking"
                         + (f" ({idle} more re-drive{'s' if idle > 1 else ''} went another way than recorded "
                            f"or could not run the steps: not counted)" if idle else ""))
            findings.append({"clause": cid, "reason": best["reason"], "confirmed": f"{confirmed}/{CONFIRM_RERUNS}",
                             "flaky": confirmed < CONFIRM_RERUNS, "steps": len(best["steps"]), "reruns": reruns})
        if run.ledger.held_clauses():  # seen in the verified reset between two sequences only: never re-driven
            session.note("unconfirmed: seen between the exploration's sequences (in a verified reset), "
                         "not re-driven on its own")
        else:  # holding ends: what is observed from here on is booked as it comes
            session.note("confirmed: every clause found was re-driven on its own")
    finally:
        session.end_case()
    from ...reports import results as R
    for f in findings:
        cid = f["clause"]
        if cid not in run.ledger:
            continue
        steps = state.found[cid]["steps"]
        if f["flaky"]:  # kept for people, but no replay of the clause: it did not fail again twice
            rel = f"replays/unconfirmed/{cid}.json"
            save_replay(run.dir / rel, cid, f["reason"], steps, run.k, p, origin=state.found[cid].get("origin"))
            f["unconfirmed_trace"] = rel
            continue
        n = sum(1 for r in run.results["replays"] if r["clause"] == cid) + 1
        rel = f"replays/{cid}-{n}.json"
        save_replay(run.dir / rel, cid, f["reason"], steps, run.k, p, origin=state.found[cid].get("origin"))
        R.add_replay(run.results, cid, steps, file=rel)
        f["replay"] = rel
    ex = run.stats["explore"]
    ex["findings"] = findings
    first = findings[0]  # the first clause found, as one line
    ex.update(found=first["reason"], confirmed=first["confirmed"], flaky=first["flaky"])
    if first.get("replay"):
        ex["replay"] = first["replay"]
