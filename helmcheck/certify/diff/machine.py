"""The generated sequences: a hypothesis state machine whose every step acts on both vehicles.

:func:`machine` builds a ``RuleBasedStateMachine`` like the exploration's
(:mod:`helmcheck.certify.vehicle.explore`; the strategies are :mod:`~helmcheck.certify.vehicle.generate`'s):
each sequence starts with the verified reset on both sides (``$OMSTOP,0`` until ``S``, then ``$OLOGL`` and
``$OMLOAD``, and the test mission started or not), then each rule sends the same line to A and
B (a valid command, a remote-control command, one mutation of a valid line, ``$OXFLT``) or lets
the same vehicle time pass, polls both, and compares what the profile pins (:mod:`.view`).
Templates such as ``{lat}`` are filled from each side's own last report (positions are a
freedom). The two sides act at once, each in its own thread (:mod:`.pair`).

A difference between the two views of a step is a **divergence** unless it is explained:

* *timing*: a model timer's deadline ± RH-TIM-1's tolerance spans a report: both sides are
  polled again once it has passed, and only what they show then is compared (a transition seen
  at slightly different times is not a divergence if both are within the tolerance); a line
  that met a timer within its tolerance on either side may be answered either way (a race);
* *the model's leeway*: the side's judge holds more than one state a conforming vehicle may be
  in, or had to adopt an unseen plant event (speeds, turn and ascent rates are freedoms).

An explained difference ends the comparison of that sequence (from there on the two vehicles
may legitimately be in different states); the judges go on. A difference is never explained
when either side's judge booked a failure in that sequence: it is a divergence, and that side
breaks the profile on the clause booked. A divergence raises :class:`Divergence`, the one
exception hypothesis is meant to find and shrink; :class:`DiffState` keeps the smallest
divergent sequence seen, with each side's replay trace. A link fault or any other exception (a
tester error) stops the search: the remaining sequences do nothing, as when the wall-clock
budget is spent.
"""

from __future__ import annotations

import time
from typing import Callable, Optional

from hypothesis import strategies as st
from hypothesis.stateful import RuleBasedStateMachine, initialize, precondition, rule

from ..vehicle.generate import control_commands, invalid_lines, valid_commands
from ..vehicle.flow import LinkLost
from ..vehicle.durations import DURATION_KEYS
from ..vehicle.interpreter import context, fill, raw_line
from ..vehicle.session import frame
from .pair import Pair
from .view import Seen, differences, seen_text


def _same_durations(ctx: dict) -> None:
    """Both sides get the same durations — the longer of the two lines' (:mod:`..vehicle.durations`):
    a timeout chosen for each side's own line would end at different times, a difference of the
    tester's making, never a divergence."""
    if len(ctx) != 2 or not all(ctx.values()):
        return
    a, b = ctx.values()
    for key in DURATION_KEYS:
        if key in a and key in b:
            longer = max(a[key], b[key], key=float)
            a[key] = b[key] = longer


__all__ = ["machine", "DiffState", "Divergence", "REPOLLS", "REPOLL_V"]

#: After a difference the model's leeway explains, both sides are polled again this many times,
#: :data:`REPOLL_V` vehicle seconds apart: two vehicles a plant event apart usually agree again.
REPOLLS = 3
REPOLL_V = 1.0


class Divergence(AssertionError):
    """The two vehicles diverged (its ``record`` says where and how)."""

    def __init__(self, record: dict):
        super().__init__(record["summary"])
        self.record = record


class DiffState:
    """Shared between the machine instances of one diff."""

    def __init__(self, pair: Pair, budget: float, examples: int, progress: Optional[Callable] = None):
        self.pair = pair
        self.budget = budget
        self.end = time.monotonic() + budget
        self.examples = examples
        self.progress = progress
        self.executions = 0  #: sequences that ran at least their reset
        self.skipped = 0  #: sequences hypothesis asked for after the search stopped
        self.divergent = 0  #: sequences that diverged (shrinking re-runs included)
        self.excused: dict = {}  #: explanation → how many sequences it ended
        self.unreset: dict = {}  #: side → sequences not compared because its reset failed
        self.found_s: Optional[float] = None  #: wall seconds from the start to the first divergence
        self.t0 = time.monotonic()
        self.best: Optional[dict] = None  #: the smallest divergence: record and both traces
        self.lost: Optional[str] = None
        self.error: Optional[BaseException] = None

    @property
    def spent(self) -> bool:
        return time.monotonic() > self.end or self.lost is not None or self.error is not None

    def keep(self, record: dict, traces: dict) -> None:
        self.divergent += 1
        if self.found_s is None:
            self.found_s = round(time.monotonic() - self.t0, 3)
        if self.best is None or len(record["steps"]) <= len(self.best["record"]["steps"]):
            self.best = {"record": record, "traces": traces}


def _raw(kind: str, body: str, profile) -> bytes:
    return frame(body) if kind == "frame" else raw_line(kind, body, profile)


def machine(state: DiffState, nwp: int, speed: float, motor: int, oxflt: bool, tos):
    pair = state.pair

    class DiffMachine(RuleBasedStateMachine):
        def __init__(self):
            super().__init__()
            self.active = not state.spent
            self.ctx: dict = {s.name: {} for s in pair.sides}
            self.steps: list[dict] = []
            self.fails: dict = {s.name: [] for s in pair.sides}
            if not self.active:
                state.skipped += 1
                return
            state.executions += 1
            for s in pair.sides:
                s.begin()
            if state.progress is not None:
                state.progress(state.executions, state.examples, max(0.0, state.end - time.monotonic()))

        # ------------------------------------------------------------------ one step on both
        def _do(self, label: str, act: Callable) -> None:
            """``act(name, session)`` on both sides (the line sent, or None), then a poll; compare."""
            if not self.active:
                return

            def one(side):
                seen = side.step(label, lambda ses: act(side.name, ses))
                if side.session.obs.last_osi is not None:
                    self.ctx[side.name] = context(side.session)
                return seen
            try:
                a, b = pair.both(one)
                _same_durations(self.ctx)
                self._compare(label, a, b)
            except Divergence:
                raise
            except LinkLost as e:
                state.lost = str(e)
                self.active = False
            except Exception as e:  # noqa: BLE001 - a tester error: kept, raised by the driver
                state.error = state.error or e
                self.active = False

        def _compare(self, label: str, a: Seen, b: Seen) -> None:
            i = len(self.steps)
            first = diffs = differences(a, b)
            if diffs and not (a.stop or b.stop):
                if a.pending or b.pending:  # a model timer's tolerance spans the reports: look past it
                    until = {s.name: max(d + tol for d, tol, _ in x.pending) if x.pending else 0.0
                             for s, x in zip(pair.sides, (a, b))}
                    self._again(a, b, lambda s: s.settle(until[s.name]))
                    diffs = differences(a, b)
                for _ in range(REPOLLS):  # an unseen plant event: the other side may be about to follow
                    if not diffs or a.ack != b.ack or a.stop or b.stop or not (a.leeway or b.leeway):
                        break
                    self._again(a, b, lambda s: s.settle(s.session.now() + REPOLL_V / s.k))
                    diffs = differences(a, b)
            for name, x in zip(self.fails, (a, b)):
                self.fails[name] += [{"step": i, "clause": c, "reason": r} for c, r in x.failures]
            self.steps.append({"step": i, "do": label, "A": seen_text(a), "B": seen_text(b),
                               "lines": {"A": a.line, "B": b.line}})
            if i == 0 and (a.stop or b.stop):  # a vehicle that could not be reset: a state the
                for s, x in zip(pair.sides, (a, b)):  # sequence before left, not this sequence's doing
                    if x.stop:
                        state.unreset[s.name] = state.unreset.get(s.name, 0) + 1
                        s.note(f"diff: the reset failed ({x.stop}); this sequence is not compared")
                self.active = False
                return
            failed = any(self.fails.values())
            if a.stop and b.stop:  # neither could go on: nothing more to compare in this sequence
                self.active = False
            if not first or (not diffs and not failed):
                return
            diffs = diffs or first  # converged, but a side broke the profile: the first difference stands
            if not failed:
                why = (f"timing race at the {a.race or b.race} timer" if (a.race or b.race) else
                       f"the model's leeway ({a.leeway or b.leeway})" if (a.leeway or b.leeway) else "")
                if why:
                    key = "timing race" if why.startswith("timing") else "the model's leeway"
                    state.excused[key] = state.excused.get(key, 0) + 1
                    for s in pair.sides:
                        s.note(f"diff: step {i} differs ({'; '.join(diffs)}), explained: {why}; the rest of "
                               f"this sequence is not compared")
                    self.active = False
                    return
            line = a.line if a.line == b.line else f"A {a.line}, B {b.line}"
            breaks = {name: f for name, f in self.fails.items() if f}
            also = "; ".join(f"{name} also fails {', '.join(sorted({x['clause'] for x in f}))}"
                             for name, f in breaks.items())
            summary = f"DIVERGED at step {i} ({line}): {diffs[0]}" + (f" — {also}" if also else "")
            record = {"step": i, "do": label, "line": {"A": a.line, "B": b.line}, "differences": diffs,
                      "A": seen_text(a), "B": seen_text(b), "breaks": breaks, "summary": summary,
                      "steps": list(self.steps)}
            for s in pair.sides:
                s.note(f"diff: {summary}")
            state.keep(record, {s.name: s.trace() for s in pair.sides})
            self.active = False
            raise Divergence(record)

        def _again(self, a: Seen, b: Seen, fn: Callable) -> None:
            """Poll both sides again (``fn(side)`` → a :class:`Seen`); the reports replace the step's."""
            a2, b2 = pair.both(fn)
            for x, y in ((a, a2), (b, b2)):
                x.failures = x.failures + y.failures
                x.osi, x.v_osi, x.v_seq, x.stop = y.osi, y.v_osi, y.v_seq, y.stop
                x.leeway = x.leeway or y.leeway

        # ------------------------------------------------------------------ rules
        @initialize(start=st.sampled_from(["N", "S"]))
        def start(self, start):
            def act(name, ses):
                mission = ses.profile.mission
                ses.reset(mission=False)
                ses.exchange(frame("OLOGL,a,b"))
                sent = ses.exchange(frame(f"OMLOAD,{mission},0"))
                if start == "N":
                    sent = ses.exchange(frame(f"OMSTART,0,0,0,0,{mission},"))
                return sent
            self._do(f"reset, {'mission started' if start == 'N' else 'mission loaded'}", act)

        def _send(self, label: str, body: str) -> None:
            self._do(label, lambda name, ses: ses.exchange(frame(fill(body, self.ctx[name]))))

        @rule(body=valid_commands(nwp, speed, motor, oxflt, tos))
        def send_valid(self, body):
            self._send(f"${body}", body)

        @rule(body=control_commands(speed, motor, tos))
        def control(self, body):
            self._send(f"${body}", body)

        @rule(line=invalid_lines())
        def send_invalid(self, line):
            kind, body = line
            self._do(f"{kind} ${body}",
                     lambda name, ses: ses.exchange(_raw(kind, fill(body, self.ctx[name]), ses.profile)))

        @rule(body=control_commands(speed, motor, tos), then=st.sampled_from(["", "", "OJW,{wp_other}", "OMW,Clr"]))
        def control_released(self, body, then):
            """A remote control (then, when drawn, another command), let run out: what each side
            does at the release is compared (RH-SRV-4, RH-PRM-4, RH-INT-2)."""
            self._send(f"${body}", body)
            if then:
                self._send(f"${then}", then)
            timeout = float(body.rsplit(",", 1)[-1]) if body.startswith(("OMS", "OMP")) else 5.0
            v = timeout + 2.0
            self._do(f"wait {v:g} s", lambda name, ses: ses.wait(v))

        @rule(v=st.sampled_from([1.0, 2.0, 5.0, 12.0]))
        def wait_a_while(self, v):
            self._do(f"wait {v:g} s", lambda name, ses: ses.wait(v))

        @rule()
        def poll(self):
            self._do("poll", lambda name, ses: None)

        @precondition(lambda self: oxflt)
        @rule(code=st.sampled_from(["Sle", "Sop", "Sed"]), go=st.integers(0, 3))
        def fault(self, code, go):
            if go == 0:  # a lockout costs lockout_s of protocol time: keep them rare
                self._send(f"$OXFLT,{code}", f"OXFLT,{code}")

    return DiffMachine
