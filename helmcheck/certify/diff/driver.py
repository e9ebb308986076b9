"""One diff: open both vehicles, run the generated sequences, shrink, save, close.

:func:`diff` is the library entry point behind ``helmcheck diff``. It opens both sides at once
(:mod:`.side`: each a certification run's machinery, its own wire log in ``DIR/A`` and
``DIR/B``), runs the state machine of :mod:`.machine` under hypothesis within a wall-clock
budget (sequences asked for after it do nothing; shrinking a divergence found uses what is
left), closes both sides (restored as found, a started vehicle stopped), saves one replay file
per side of the smallest divergent sequence (``DIR/replays/A-….json``, ``B-….json``, each
re-drivable with ``helmcheck replay FILE --port``) and writes ``DIR/diff.json`` (:mod:`.report`).

Exit code of the outcome: 1 a divergence was found, 0 none within the budget, 2 nothing could
be compared (a link fault, a vehicle whose clock is not at its time scale, no sequence ran, an
interruption) or a tester error — a divergence found before a link fault is still 1.
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Optional

from hypothesis import HealthCheck, Phase, seed, settings
from hypothesis.errors import Flaky
from hypothesis.stateful import run_state_machine_as_test

from ...failures import describe_interrupt
from ...grammar import prepare
from ..vehicle.clockprobe import ClockMismatch
from ..vehicle.explore import timeouts
from ..vehicle.flow import LinkLost
from ..vehicle.replay import save_replay
from . import report
from .machine import DiffState, Divergence, machine
from .pair import Pair
from .side import Side, SideSpec

__all__ = ["DiffOptions", "DiffOutcome", "diff"]


@dataclass
class DiffOptions:
    sides: list  #: two :class:`~.side.SideSpec`, A then B
    report_dir: Path
    examples: int = 50
    steps: int = 10  #: steps per sequence after its reset
    budget_s: float = 60.0
    seed: Optional[int] = None
    progress: bool = True
    command: str = "helmcheck diff"
    log_opener: object = None  #: how to open each side's wire log (the command's hook)


@dataclass
class DiffOutcome:
    result: str  #: ``diverged`` | ``no divergence`` | ``inconclusive``
    line: str  #: the one-line result
    exit_code: int
    report_dir: Path
    doc: dict = field(default_factory=dict)  #: what ``diff.json`` holds


def _say(opts: DiffOptions, text: str) -> None:
    if opts.progress:
        print(f"diff: {text}", file=sys.stderr, flush=True)


def _search(opts: DiffOptions, pair: Pair, state: DiffState) -> None:
    """Run the sequences; a finding ends as ``state.best``, a tester error as ``state.error``."""
    pa, pb = pair.a.spec.profile, pair.b.spec.profile

    def bench(p):
        b = p.bench_safety
        return (min(2.0, p.max_speed_kn, b.max_speed_kn if not b.in_water else 99.0),
                min(0x90, b.max_motor_byte) if not b.in_water else 0x90)
    speed = min(bench(pa)[0], bench(pb)[0])
    motor = min(bench(pa)[1], bench(pb)[1])
    lo = max(pa.timeout_range[0], pb.timeout_range[0])
    hi = min(pa.timeout_range[1], pb.timeout_range[1])
    durs = [side.session.durations(fresh=True).to for side in (pair.a, pair.b)]  # timeable on both lines
    tos = timeouts(None if None in durs else max(durs), (lo, max(lo, hi)))
    oxflt = pa.fault_injection == "oxflt" and pb.fault_injection == "oxflt"
    factory = machine(state, min(pa.mission_waypoints, pb.mission_waypoints), speed, motor, oxflt, tos)
    if opts.seed is not None:
        factory = seed(opts.seed)(factory)
    cfg = settings(max_examples=opts.examples, stateful_step_count=opts.steps, deadline=None, database=None,
                   suppress_health_check=list(HealthCheck), report_multiple_bugs=False, print_blob=False,
                   phases=(Phase.explicit, Phase.generate, Phase.shrink))
    try:
        run_state_machine_as_test(factory, settings=cfg)
    except Divergence:
        pass
    except Exception as e:  # noqa: BLE001 - hypothesis ends on a finding, or a tester error
        finding = state.best is not None and (isinstance(e, Flaky) or isinstance(e, BaseExceptionGroup))
        if not finding and state.error is None:
            state.error = e


def _save_replays(opts: DiffOptions, pair: Pair, best: dict) -> dict:
    out = {}
    rec = best["record"]
    for s in pair.sides:
        breaks = rec["breaks"].get(s.name) or []
        # the clause the fault speaks to, rather than RH-OUT-4 ("reports the state") booked beside it
        breaks = sorted(breaks, key=lambda f: f["clause"] == "RH-OUT-4")
        clause = breaks[0]["clause"] if breaks else ""
        rel = f"replays/{s.name}-{clause or 'divergence'}.json"
        reason = (f"{breaks[0]['clause']}: {breaks[0]['reason']}" if breaks else
                  f"side {s.name} of a divergence: {rec['summary']}")
        save_replay(Path(opts.report_dir) / rel, clause, reason, best["traces"][s.name], s.k, s.spec.profile)
        out[s.name] = rel
    return out


def diff(opts: DiffOptions) -> DiffOutcome:
    """Run one diff (module docstring); never raises for vehicle or link faults."""
    a_spec, b_spec = opts.sides
    rdir = Path(opts.report_dir)
    t0 = time.monotonic()
    prepare()
    sides = [Side(spec, rdir, opts.command, opts.log_opener) for spec in (a_spec, b_spec)]
    pair = Pair(*sides)
    state: Optional[DiffState] = None
    stopped: Optional[str] = None  #: why nothing (more) could be compared
    error: Optional[BaseException] = None
    try:
        try:
            for s in sides:
                _say(opts, f"{s.name}: {s.spec.label} (time scale {s.k:g}, profile {s.spec.profile.name})")
            pair.both(lambda s: s.open())
            state = DiffState(pair, opts.budget_s, opts.examples,
                              lambda n, total, left: _say(opts, f"sequence {n}: {opts.budget_s - left:.0f} of "
                                                               f"{opts.budget_s:g} s of the budget used"))
            _search(opts, pair, state)
            if state.error is not None:
                error = state.error
            elif state.lost:
                stopped = f"link fault: {state.lost}"
        except ClockMismatch as e:
            stopped = str(e)
        except LinkLost as e:
            stopped = f"link fault: {e}"
        except KeyboardInterrupt as e:
            stopped = describe_interrupt(e)
    finally:
        reason = (f"tester error ({type(error).__name__})" if error is not None else stopped)
        try:
            for s in sides:
                try:
                    s.close(reason)
                except Exception as e:  # noqa: BLE001 - never lose the other side's record over one
                    _say(opts, f"{s.name}: not closed cleanly: {type(e).__name__}: {e}")
        finally:
            pair.close()
    replays = _save_replays(opts, pair, state.best) if state is not None and state.best is not None else {}
    doc = report.document(opts, pair, state, replays, stopped, error, time.monotonic() - t0)
    report.write(rdir, doc)
    if error is not None:
        raise error
    return DiffOutcome(doc["result"], doc["line"], doc["exit_code"], rdir, doc)
