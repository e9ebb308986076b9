"""One vehicle of a diff: opened, driven one step at a time, looked at, closed.

A :class:`Side` is a certification :class:`~helmcheck.certify.vehicle.runner.Run` used for its
machinery only — the port (or ``--exec``: the vehicle under test started on a new pty), the
recorder writing ``DIR/<side>/wire.log``, the vehicle observer (the judge ``certify vehicle``
uses) with its ledger, the session, the start-up probe and clock check, the restore and the
process record at the end. No case runs and no ``results.json`` is written: the diff's result is
``diff.json`` (:mod:`.report`).

:meth:`Side.step` carries out one step (a callable on the session) and returns its
:class:`~.view.Seen`: the ``$ACK`` of the line sent, the ``$OSI`` that ends the step, the
failures the side's judge booked meanwhile, and what the side's mirror says of the timing
(a model timer within RH-TIM-1's tolerance of the line or the report) and of its certainty
(more than one state a conforming vehicle may be in, an unseen plant event adopted). The
session does not stop at a failure (``stop_on_fail`` off): the diff compares, the judge books.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Optional

from ...judge.timing import JITTER_S
from ...model.timers import tolerance
from ...profile import Profile
from ..vehicle.clockprobe import check_clock
from ..vehicle.flow import CaseStop
from ..vehicle.runner import Options, Run
from ..vehicle.safety import BenchSafetyRefused
from .view import OsiView, Seen

__all__ = ["Side", "SideSpec"]


@dataclass
class SideSpec:
    """How to reach one vehicle: a port, or a command that starts it (``--exec``)."""

    name: str  #: ``A`` or ``B``
    port: str  #: a port URL (with ``exec_cmd``: ``pty`` or ``socket://HOST:0``)
    profile: Profile
    time_scale: float
    exec_cmd: Optional[str] = None
    link: object = None  #: the port, already opened by the command line
    line: Optional[str] = None  #: ``--line clean|noisy`` (None: guessed from the port)

    @property
    def label(self) -> str:
        return f"--exec {self.exec_cmd}" if self.exec_cmd else self.port


class Side:
    """One vehicle of the diff (module docstring)."""

    def __init__(self, spec: SideSpec, report_dir: Path, command: str = "helmcheck diff", log_opener=None):
        self.spec = spec
        self.name = spec.name
        self.dir = Path(report_dir) / spec.name
        opts = Options(port=spec.port, profile=spec.profile, time_scale=spec.time_scale, report_dir=self.dir,
                       progress=False, render=False, explore=False, command=command, link=spec.link,
                       exec_cmd=spec.exec_cmd, log_opener=log_opener, title="diff", line=spec.line)
        self.run = Run(opts)
        self.k = spec.time_scale
        self.session = None
        self.t_step = 0.0  #: this side's link time at the present step's start
        #: (name, vehicle deadline) → duration: every model timer seen armed in this sequence
        self.timers: dict = {}
        self.t_seq = 0.0  #: link time the sequence began

    # ------------------------------------------------------------------ life
    def open(self) -> None:
        """Open the link (or start the vehicle), check it answers and its clock runs at k.
        Raises LinkLost / ClockMismatch like a certification's start."""
        run = self.run
        run.open()
        run.probe()
        run.session.measure_line()  # what the line costs: the durations (:mod:`..vehicle.durations`)
        check_clock(run, True)
        ses = run.session
        ses.stop_on_fail = False  # the judge books; the diff decides what a difference is
        ses.lazy_silence = True  # a discarded line's window is not sat out (as in exploration)
        self.session = ses

    def close(self, reason: Optional[str]) -> None:
        """Leave the vehicle as found, stop it if helmcheck started it, close the record."""
        run = self.run
        try:
            try:
                run.restore()
            finally:
                try:
                    run.stop_child()
                finally:
                    run.end(reason)
        finally:
            if run.link is not None:
                run.link.close()
            if run.recorder is not None:
                run.recorder.close()

    @property
    def wire_log(self) -> Path:
        return self.dir / "wire.log"

    def findings(self) -> list[dict]:
        """Every clause the side's judge failed, with its first reason."""
        seen: dict = {}
        for cid, reason in self.run.ledger.failures_since(0):
            seen.setdefault(cid, reason)
        return [{"clause": c, "reason": r} for c, r in seen.items()]

    # ------------------------------------------------------------------ sequences
    def begin(self) -> None:
        """A new sequence: its replay trace and its timers start empty."""
        self.session.trace = []
        self.timers = {}
        self.t_seq = self.session.now()

    def trace(self) -> list:
        return list(self.session.trace or [])

    def note(self, text: str) -> None:
        self.session.note(text)

    # ------------------------------------------------------------------ steps
    def _leeway(self) -> tuple:
        b = self.session.obs.beliefs
        return len(b.cands), b.primary.events, b.desync

    def _collect_timers(self) -> None:
        for c in self.session.obs.beliefs.cands:
            t = c.model.timers
            for name in t.names():
                due = t.deadline(name)
                if due is not None:
                    self.timers[(name, round(due, 3))] = t.duration(name) or 0.0

    def _tol_wall(self, duration: float) -> float:
        ses = self.session
        return tolerance(duration) / self.k + 2 * ses.poll_gap + 2 * JITTER_S

    def _near(self, t: float) -> list:
        """(wall deadline, wall tolerance, timer) of the known model timers within tolerance of ``t``."""
        out = []
        for (name, due_v), dur in self.timers.items():
            due, tol = due_v / self.k, self._tol_wall(dur)
            if abs(t - due) <= tol:
                out.append((due, tol, name))
        return out

    def step(self, label: str, action: Callable) -> Seen:
        """Carry out ``action(session)`` (it returns the observer's record of the line it sent, or
        None), then poll; what the side showed (module docstring)."""
        ses = self.session
        mark = ses.ledger.mark()
        ses.mark = mark
        before = self._leeway()
        self._collect_timers()
        t0 = self.t_step = ses.now()
        seen = Seen(line=label)
        sent = None
        try:
            sent = action(ses)
            if sent is not None:
                seen.line = _line(sent.raw)
                seen.ack = None if sent.ack is None else (sent.ack.type, sent.ack.status, sent.ack.err)
                self._collect_timers()
                near = self._near(sent.t)
                if near:
                    seen.race = near[0][2]
            self._report(seen, t0)
        except CaseStop as e:
            seen.stop = e.reason
        except BenchSafetyRefused as e:
            seen.stop = f"not sent: {e}"
        self._judged(seen, mark, before)
        return seen

    def _judged(self, seen: Seen, mark: int, before: tuple) -> None:
        """What the judge made of the step: its failures, and the model's leeway."""
        seen.failures = self.session.ledger.failures_since(mark)
        after = self._leeway()
        if after[2]:
            seen.leeway = f"the judge lost track of the state ({after[2]})"
        elif max(before[0], after[0]) > 1:
            seen.leeway = "more than one state a conforming vehicle may be in"
        elif after[1] > before[1]:
            seen.leeway = "an unseen plant event was adopted (speeds, turn and ascent rates are freedoms)"

    def _report(self, seen: Seen, t0: float) -> None:
        ses = self.session
        osi = ses.poll()
        self._collect_timers()
        t = ses.now()
        seen.osi = OsiView.of(osi)
        seen.v_osi = (t - t0) * self.k
        seen.v_seq = (t - self.t_seq) * self.k
        seen.pending = self._near(t)

    def settle(self, until: float) -> Seen:
        """Poll again once this side's clock reaches ``until`` (wall, this side's link time): the
        report after a model timer's tolerance (its ``v_osi`` from the step's start)."""
        ses = self.session
        seen = Seen()
        mark = ses.ledger.mark()
        before = self._leeway()
        try:
            left = until - ses.now()
            if left > 0:
                ses.wait(left * self.k)
            self._report(seen, self.t_step)
        except CaseStop as e:
            seen.stop = e.reason
        self._judged(seen, mark, before)
        return seen


def _line(raw: bytes) -> str:
    from ...grammar.wirelog import escape
    return escape(raw.rstrip(b"\r\n"))
