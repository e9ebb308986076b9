"""Judging a session while it runs: check-log's judges, in a process of their own, following the log.

:class:`LiveJudge` starts a second process that follows the session's wire log as
:class:`.sessionlog.SessionLog` writes it — new whole lines, read with the one wire-log reader
(:func:`helmcheck.grammar.wirelog.read_wire_log`), through each ``continued in`` note to the next
segment — and feeds every record to a :class:`helmcheck.checklog.checker.SessionJudge`: the
observers ``check-log`` runs, vehicle (§1–8) and backseat (§9). It reads the very records
``check-log`` reads from the same files, so the verdicts are ``check-log``'s by construction.

The judges are a process, not a thread, so that judging never takes the interpreter from the
relay: if judging falls behind, it falls behind on the file, and forwarding does not wait. The
process runs at the lowest priority of the normal class (:data:`NICE`, batch scheduling where
there is one) and, while the session runs, takes at most :data:`DUTY` of a CPU
(``benchmarks/monitor_bench.py``); once the log is closed it judges the rest flat out. The process sends back, over a pipe, the first failure of each
clause as a :class:`Finding` the moment it is made (what a person watching must see), and a few
times a second a state snapshot for a view (the count of all findings, the newest one, the
clauses so far); :meth:`LiveJudge.poll` collects them in the caller's thread.
:meth:`LiveJudge.finish` (after the log is closed) lets it read to the end and returns what
:func:`helmcheck.checklog.check_log` returns for the session's log. The process ignores the
signals that end a session (they are the parent's to act on), dies with its parent (Linux), and
never writes a file.
"""

from __future__ import annotations

import multiprocessing as mp
import os
import signal
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Optional

from ..checklog.checker import CheckOutcome, SessionJudge, log_meta
from ..grammar.wirelog import NOTE, continued_in, read_wire_log
from ..profile import Profile

__all__ = ["LiveJudge", "Finding", "LogFollower", "helper_process"]

#: How often the judging process looks for new lines when it has none, seconds.
FOLLOW_S = 0.02
#: How long the monitor waits for the judging process to be ready before it starts the session
#: anyway (its findings then come that much later), seconds.
READY_S = 30.0
#: How often it sends a state snapshot, seconds.
STATE_S = 0.25
#: How much lower the judges' priority is (``nice``). Not the idle scheduling class: measured on a
#: 2-CPU Linux 6.x machine, a busy process in the idle class next to the relay raised the relay's
#: p99 at 115200 baud to 3.2 ms, a busy process at nice 19 to 0.5–0.7 ms (``monitor_bench.py``).
NICE = 19
#: The most the follower reads at once (memory stays flat when judging is far behind).
BLOCK = 1 << 16
#: The share of one CPU the judges take at most while the session runs (on a small machine a
#: process that never sleeps costs the relay its latency, whatever its priority); after the
#: session they run flat out.
DUTY = 0.5


@dataclass(frozen=True)
class Finding:
    t: float  #: session seconds of the record that revealed it
    role: str  #: "vehicle" or "backseat"
    clause: str
    reason: str
    first: bool  #: the first finding of this clause in the session
    lineno: int  #: the wire-log line of that record


class LogFollower:
    """The records of a session's log as it grows: whole lines only, numbered as check-log numbers
    them, through ``continued in`` notes from segment to segment."""

    def __init__(self, first: Path):
        self.path = Path(first)
        self.offset = 0
        self.lineno = 0  #: lines read so far (all segments)
        self.rest = b""
        self.next_name: Optional[str] = None
        self._f = None

    def read(self) -> list:
        """The records of the whole lines written since the last call, up to :data:`BLOCK` bytes
        of them (maybe none)."""
        if self.next_name is not None:  # the segment ended: go on in the next once it exists
            nxt = self.path.parent / self.next_name
            if not nxt.exists():
                return []
            self.close()
            self.path, self.offset, self.rest, self.next_name = nxt, 0, b"", None
        if self._f is None:
            try:
                self._f = open(self.path, "rb")  # kept open: the writer only ever appends
            except FileNotFoundError:
                return []
        data = self._f.read(BLOCK)
        self.offset += len(data)
        data = self.rest + data
        cut = data.rfind(b"\n") + 1
        self.rest = data[cut:]
        if not cut:
            return []
        lines = data[:cut].splitlines(keepends=True)
        records = list(read_wire_log(lines, first=self.lineno + 1))
        self.lineno += len(lines)
        for r in records:
            if r.dir == NOTE:
                name = continued_in(r.note)
                if name is not None:
                    self.next_name = name
        return records

    def close(self) -> None:
        if self._f is not None:
            self._f.close()
            self._f = None

    @property
    def at_end(self) -> bool:
        """Nothing unread is known of (a partial last line aside)."""
        try:
            return self.next_name is None and os.path.getsize(self.path) <= self.offset
        except OSError:
            return True


class LiveJudge:
    """The judging process (module docstring); the caller's side of its pipe."""

    def __init__(self, first: Path, profile: Profile, *, role: str, time_scale: float, baud: int):
        ctx = mp.get_context("spawn")
        self._conn, child = ctx.Pipe(duplex=True)
        self.proc = ctx.Process(target=_judge_process, name="helmcheck-monitor-judge", daemon=True,
                                args=(child, str(first), profile, role, time_scale, baud))
        self.proc.start()
        child.close()
        self.findings = 0
        self.last: Optional[Finding] = None
        self._state: dict = {}
        self.error: Optional[str] = None
        self._outcome: Optional[CheckOutcome] = None
        self.ready = False

    def wait_ready(self, timeout: float = READY_S) -> bool:
        """Wait until the process has imported the judges and built its own (a spawned Python
        starts in a second or two on a small machine): a session started before that would see
        its first findings that much later. False when it is not ready within ``timeout``. Then
        :meth:`follow` tells it the log is there."""
        self._receive_until(lambda: self.ready or self.error is not None or self._outcome is not None,
                            time.monotonic() + timeout, 0.1, [])
        return self.ready

    def follow(self) -> None:
        """The log is there (a new one, in place of any earlier run's): the process follows it."""
        self._conn.send(("follow", None))

    def poll(self) -> list[Finding]:
        """New findings since the last call (and the latest state, :meth:`state`)."""
        out = []
        try:
            while self._conn.poll():
                self._take(self._conn.recv(), out)
        except (EOFError, OSError):
            if self.error is None and self._outcome is None:
                self.error = "the judging process ended unexpectedly"
        return out

    def _take(self, msg: tuple, out: list) -> None:
        kind, payload = msg
        if kind == "finding":
            self.findings += 1
            self.last = payload
            out.append(payload)
        elif kind == "state":
            self._state = payload
            self.findings = max(self.findings, payload.get("findings", 0))
            if payload.get("newest") is not None:
                self.last = payload["newest"]
        elif kind == "outcome":
            self._outcome = payload
        elif kind == "error":
            self.error = payload
        elif kind == "ready":
            self.ready = True

    def state(self) -> dict:
        return self._state

    def finish(self, sha256: str, timeout: Optional[float] = None) -> tuple[CheckOutcome, list[Finding]]:
        """The log is closed: let the process judge the rest, and return its outcome (for a log
        whose session's bytes hash to ``sha256``) and the findings it sent meanwhile. Raises
        ``RuntimeError`` when the process failed."""
        self._conn.send(("end", sha256))
        late: list[Finding] = []
        got = self._receive_until(lambda: self._outcome is not None or self.error is not None,
                                  None if timeout is None else time.monotonic() + timeout, 0.5, late)
        if got == "time":
            raise RuntimeError("the judging process did not finish in time")
        if got == "closed":
            self.error = self.error or "the judging process ended unexpectedly"
        elif got == "gone":
            self.poll()
            self.error = self.error or f"the judging process ended (exit code {self.proc.exitcode})"
        self.proc.join(5)
        if self.error is not None:
            raise RuntimeError(self.error)
        return self._outcome, late  # type: ignore[return-value]

    def _receive_until(self, done, end: Optional[float], step: float, into: list) -> str:
        """Take the process's messages (findings into ``into``) until ``done()``: ``"done"``;
        ``"time"`` when ``end`` (monotonic) passed first, ``"closed"`` when the pipe ended,
        ``"gone"`` when the process ended with nothing more sent."""
        while not done():
            left = None if end is None else end - time.monotonic()
            if left is not None and left <= 0:
                return "time"
            if self._conn.poll(step if left is None else min(left, step)):
                try:
                    self._take(self._conn.recv(), into)
                except (EOFError, OSError):
                    return "closed"
            elif not self.proc.is_alive():
                return "gone"
        return "done"

    def stop(self) -> None:
        """End the process now (nothing is judged any more)."""
        if self.proc.is_alive():
            self.proc.kill()
            self.proc.join(5)


# ---------------------------------------------------------------------- the judging process
def helper_process() -> None:
    """In a process the monitor started: it yields the CPU to the relay (batch scheduling where
    there is one — it never preempts on waking — at :data:`NICE`: when the machine is busy, judging
    waits, not forwarding); the session's end is the parent's to decide — Ctrl-C, SIGTERM and
    SIGHUP (sent to the whole process group by a terminal or ``kill -- -PGID``) are ignored here —
    and the process dies with its parent (Linux: SIGKILL on the parent's death)."""
    try:
        os.sched_setscheduler(0, os.SCHED_BATCH, os.sched_param(0))
    except (AttributeError, OSError):  # not Linux
        pass
    try:
        os.nice(NICE)
    except OSError:
        pass
    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(sig, signal.SIG_IGN)
    try:
        import ctypes

        ctypes.CDLL(None).prctl(1, signal.SIGKILL, 0, 0, 0)  # PR_SET_PDEATHSIG
    except Exception:  # noqa: BLE001 - not Linux: the daemon flag still ends it with the parent's exit
        pass


def _judge_process(conn, first: str, profile: Profile, role: str, time_scale: float, baud: int) -> None:
    helper_process()
    try:
        conn.send(("outcome", _follow(conn, Path(first), profile, role, time_scale, baud)))
    except Exception as e:  # noqa: BLE001 - a tester error, reported to the session
        import traceback

        conn.send(("error", f"{type(e).__name__}: {e}\n{traceback.format_exc()}"))


def _follow(conn, first: Path, profile: Profile, role: str, time_scale: float, baud: int) -> CheckOutcome:
    judge = SessionJudge(profile, role, None, time_scale, 1e-6, baud)
    conn.send(("ready", None))
    sha: Optional[str] = None
    while True:  # the log is followed once it is the session's own (LiveJudge.follow)
        kind, payload = conn.recv()
        if kind == "follow":
            break
        if kind == "end":  # ended before it began: the log as it is
            sha = payload
            break
    sides = [(name, side.ledger) for name, side in (("vehicle", judge.vehicle), ("backseat", judge.backseat))
             if side is not None]
    marks = {name: ledger.mark() for name, ledger in sides}
    seen: set = set()
    follower = LogFollower(first)
    last_state = 0.0
    count, newest = 0, None
    while True:
        busy = time.process_time()
        records = follower.read()
        for ev in records:
            judge.chunk(ev)
            for name, ledger in sides:
                if ledger.mark() == marks[name]:
                    continue
                for clause, reason in ledger.failures_since(marks[name]):
                    count += 1
                    newest = Finding(ev.t, name, clause, reason, (name, clause) not in seen, ev.lineno)
                    if newest.first:  # each clause's first at once; the rest counted, the newest shown
                        seen.add((name, clause))
                        conn.send(("finding", newest))
                marks[name] = ledger.mark()
        now = time.monotonic()
        if now - last_state >= STATE_S:
            last_state = now
            conn.send(("state", {**_state(judge, sides), "findings": count, "newest": newest}))
        if sha is None and conn.poll():
            kind, payload = conn.recv()
            if kind == "end":
                sha = payload
        if sha is not None and not records and follower.at_end:
            break
        if not records:
            time.sleep(FOLLOW_S)
        elif sha is None:  # while the session runs, judging takes at most DUTY of a CPU: it waits, not forwarding
            time.sleep((time.process_time() - busy) * (1 - DUTY) / DUTY)
    follower.close()
    judge.close()
    conn.send(("state", {**_state(judge, sides), "findings": count, "newest": newest}))
    fmt, meta = log_meta(first)
    return judge.outcome(first, fmt, meta, sha or "")


def _state(judge: SessionJudge, sides: list) -> dict[str, Any]:
    out: dict[str, Any] = {"records": judge.stats["records"], "clauses": {}}
    for _, ledger in sides:
        for cid in ledger.order:
            c = ledger.counts(cid)
            v = "fail" if c.get("fail") else "inconclusive" if c.get("inconclusive") else "pass" if c.get("pass") else ""
            if v:
                out["clauses"][cid] = v
    if judge.vehicle is not None:
        tl = judge.vehicle.observer.timeline
        out["mode"] = tl[-1][1] if tl else ""
    return out
