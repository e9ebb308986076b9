"""What the backseat could know, and from when: the vehicle's reports, the answers, the lockout.

A backseat is judged only on what the vehicle had told it. Everything here is timed by when a
report had *fully arrived* at the backseat: the record time of the vehicle's bytes plus their
transmit time at the baud (:func:`~helmcheck.judge.timing.transmit_time`), queued behind the
vehicle bytes before them as a UART queues them (:class:`Arrivals`). Rules then add the
profile's ``reaction_s`` (RH-BS-3/5) to that arrival.

* :class:`StateReports` — the mission state as reported (RH-BS-3): ``$OSI`` field 2 in a mode of
  :data:`~helmcheck.judge.facts.NEEDS_MISSION` says *running*, ``S`` says *not running*, any
  other mode (``M``) says nothing (RH-RD-1); an accepted ``$OMSTART`` (``$ACK,3,0,…``) says
  running, an accepted ``$OMSTOP`` (``$ACK,1,0,…``) not running.
* :class:`Pending` — the backseat's commands waiting for their ``$ACK``. ACKs come in command
  order (RH-ACK-6), so an ``$ACK`` of type ``n`` answers the oldest waiting command of that
  type; older ones of other types that it overtakes will never be answered and are dropped.
  An ``$ACK`` no waiting command expects is ignored. Decision: a command still unanswered
  when an ``$ACK`` is no longer awaited (:func:`~helmcheck.judge.timing.ack_give_up_after`
  of the longest :func:`~helmcheck.judge.timing.ack_allowance`) waits no more: the vehicle
  missed it (RH-ACK-1), and a later answer is not taken for it.
* :class:`Lockout` — the safety lockout as the backseat could know it (RH-BS-5, RH-SAF-1).
  See its docstring for where an episode starts and ends.
"""

from __future__ import annotations

from bisect import bisect_right
from collections import deque
from dataclasses import dataclass
from typing import Optional

from ..timing import slack, tolerance, transmit_time
from .common import SentLine

__all__ = ["Arrivals", "StateReports", "Pending", "Lockout", "Episode"]

_MAX_REPORTS = 4096
_BY_ERR26 = "?"  #: latched by an err 26 before field 8 showed the code


class Arrivals:
    """When the vehicle's bytes had fully arrived: record time, queued behind earlier bytes,
    plus transmit time at the baud (0 for an unpaced link)."""

    def __init__(self, baud: int):
        self.baud = baud
        self._free = 0.0  #: when the line has carried every byte recorded so far
        self._start = 0.0  #: when the present record's first byte started on the line

    def record(self, t: float, nbytes: int) -> None:
        """A vehicle record of ``nbytes`` at ``t``: call before :meth:`arrival` for its lines."""
        self._start = max(t, self._free)
        self._free = self._start + transmit_time(nbytes, self.baud)

    def arrival(self, end: int) -> float:
        """Arrival of the present record's bytes up to offset ``end`` (exclusive) in it."""
        return self._start + transmit_time(end, self.baud)


class StateReports:
    """The running/not-running reports, as changes in order: when each was recorded (sent) and
    when it had fully arrived (:class:`Arrivals`)."""

    def __init__(self) -> None:
        self._arr: list[float] = []
        self._rec: list[float] = []
        self._v: list[bool] = []
        self._seen: deque[tuple[float, bool]] = deque(maxlen=64)  #: every report's (arrival, running)
        self._broken: deque[float] = deque(maxlen=64)  #: arrivals of vehicle lines a faulty line broke

    def report(self, recorded: float, arrived: float, running: bool) -> None:
        self._seen.append((arrived, running))
        if self._v and self._v[-1] == running:
            return
        if self._arr and arrived < self._arr[-1]:
            arrived = self._arr[-1]
        self._arr.append(arrived)
        self._rec.append(recorded)
        self._v.append(running)
        if len(self._v) > _MAX_REPORTS:
            for lst in (self._arr, self._rec, self._v):
                del lst[:_MAX_REPORTS // 2]

    def contradicts(self, t: float, at: float, need: bool) -> Optional[bool]:
        """Is a command sent at ``at`` that needs state ``need`` certainly against what the
        backseat knew? It knew the last report that had fully arrived by ``t``; a later report
        saying ``need`` that had been *sent* by ``at`` excuses it (the backseat may have acted
        on it at once). None: no report had arrived by ``t`` (nothing to judge against)."""
        i = bisect_right(self._arr, t)
        if not i:
            return None
        if self._v[i - 1] == need:
            return False
        return not (i < len(self._v) and self._rec[i] <= at)  # the next change says ``need``

    def known(self, t: float) -> Optional[tuple[float, bool]]:
        """The last state report that had fully arrived by ``t``: (when it arrived, running), or None."""
        i = bisect_right(self._arr, t)
        return (self._arr[i - 1], self._v[i - 1]) if i else None

    def broken(self, arrived: float) -> None:
        """A vehicle line that reached the backseat broken (bytes that frame into nothing, a
        checksum that does not match): what it said, the backseat may or may not have read."""
        self._broken.append(arrived)

    def uncertain(self, t: float, at: float) -> Optional[float]:
        """A contradiction found at ``t`` for a command sent at ``at`` rests on a report the
        backseat may no longer have believed: a vehicle line broken on its way arrived by ``at``
        after the last whole report of that state that had arrived by ``t`` (it may have been
        the change, read in part). The broken line's arrival, or None."""
        i = bisect_right(self._arr, t)
        if not i:
            return None
        v = self._v[i - 1]
        last = max((a for a, r in self._seen if r == v and a <= t), default=self._arr[i - 1])
        late = [b for b in self._broken if last < b <= at]
        return late[-1] if late else None

class Pending:
    """Commands waiting for their ``$ACK`` (module docstring)."""

    def __init__(self, limit: int = 512):
        self._q: deque[SentLine] = deque()
        self._limit = limit

    def __iter__(self):
        return iter(self._q)

    def __reversed__(self):
        return reversed(self._q)

    def expect(self, line: SentLine) -> None:
        self._q.append(line)
        if len(self._q) > self._limit:
            self._q.popleft()

    def expire(self, t: float, max_wait: float) -> None:
        """Give up on commands sent more than ``max_wait`` before ``t`` (module docstring)."""
        q = self._q
        while q and q[0].t < t - max_wait:
            q.popleft()

    def answer(self, ack_type: int) -> Optional[SentLine]:
        """The waiting command an ``$ACK`` of ``ack_type`` answers (removed), or None."""
        for i, line in enumerate(self._q):
            if line.ack_type == ack_type:
                for _ in range(i + 1):
                    self._q.popleft()
                return line
        return None

    def latest(self, event: str) -> Optional[SentLine]:
        """The most recent waiting command of table event ``event``."""
        for line in reversed(self._q):
            if line.event == event:
                return line
        return None

    def clear(self) -> list[SentLine]:
        out = list(self._q)
        self._q.clear()
        return out


@dataclass
class Episode:
    """One lockout as the backseat could know it."""

    code: str
    known: Optional[float] = None  #: first sign arrived + ``reaction_s`` (None: no sign yet)
    start: Optional[float] = None  #: the ``lockout starts`` note's time (None: no notes)
    end: Optional[float] = None  #: when it ends (None: until a ``lockout ends`` note)
    noted: bool = False  #: announced by a ``lockout starts`` note
    offences: int = 0
    osd: int = 0
    case: str = ""


class Lockout:
    """The safety lockout (RH-SAF-1) as the backseat could know it, for RH-BS-5.

    *Start of knowledge.* The first sign of the lockout to reach the backseat: an ``$ACK`` with
    err 26, or a safety code in ``$OSI`` field 8, arrived; the backseat is then given
    ``reaction_s``. Commands before that are not judged.

    *End.* When the log has lockout notes (``lockout starts (<code>)`` / ``lockout ends``, which
    ``certify backseat`` writes), an episode is the time between the notes, and only signs
    inside it count. Otherwise (a capture of a real line) the end is the earliest one a
    conforming vehicle allows, so that only certain violations are judged: the lockout cannot
    have started before the last record that showed the vehicle out of it — an ``$OSI`` with
    field 8 ``N``, or an accepted command that a lockout refuses
    (:data:`~helmcheck.judge.facts.LOCKOUT_REFUSED`) — so it cannot have ended before that
    time plus ``lockout_s / time_scale`` minus the RH-TIM-1 tolerance (widened by the observer's
    slack, :func:`~helmcheck.judge.timing.slack`). Decision: an episode with no such record
    before its first sign (the log starts inside it) is not judged; a record showing the
    vehicle out of the lockout ends an episode at once. Without notes a new episode starts at a
    sign while none is latched: field 8 keeps the code after the lockout (RH-RD-13) and err 26
    goes on during the ascent (RH-RD-12), so the code is latched until field 8 reads ``N`` or
    an ``$OMSTART``/``$OMSTOP`` is accepted; a *different* code in field 8 is a new violation
    (RH-RD-11).
    """

    def __init__(self, settings) -> None:
        self.s = settings
        self.noted = False  #: the log carries lockout notes
        self.episode: Optional[Episode] = None
        self._latched: Optional[str] = None
        self._clear: Optional[float] = None  #: last record showing the vehicle out of the lockout
        self.count = 0

    # ------------------------------------------------------------------ notes
    def note_start(self, t: float, code: str) -> Optional[Episode]:
        """``lockout starts (code)``; returns the episode it closes (a restart keeps it)."""
        self.noted = True
        ep = self.episode
        if ep is not None and ep.noted:
            return None
        self.episode = Episode(code, noted=True, case=self.s.case, start=t)
        self.count += 1
        return ep

    def note_end(self, t: float) -> Optional[Episode]:
        """``lockout ends``; returns the finished episode."""
        self.noted = True
        ep = self.episode
        if ep is None:
            return None
        ep.end = t if ep.end is None else min(ep.end, t)
        self.episode = None
        return ep

    # ------------------------------------------------------------------ the wire
    def sign(self, arrived: float, code: str, from_field8: bool) -> Optional[Episode]:
        """A sign reached the backseat at ``arrived``; returns an episode this one replaces."""
        ep = self.episode
        if self.noted:
            if ep is not None and ep.known is None:
                ep.known = arrived + self.s.reaction_s
            return None
        if from_field8:
            if code == self._latched:
                return None
            if self._latched == _BY_ERR26:  # the code behind an err 26 already taken as a sign
                self._latched = code
                return None
            self._latched = code
        else:
            if self._latched is not None:
                return None  # err 26 while a code is latched: the same episode or its ascent
            self._latched = _BY_ERR26
        old = self.episode
        if self._clear is None:
            self.episode = None  # the log starts inside it: no bound on its end (not judged)
            return old
        k = self.s.time_scale
        L = self.s.lockout_s
        tol = tolerance(L, slack(k, self._clear, self._clear, self.s.resolution))
        end = self._clear + (L - tol) / k
        self.episode = Episode(code, known=arrived + self.s.reaction_s, end=end, case=self.s.case)
        self.count += 1
        return old

    def clear(self, t: float, reset_code: bool) -> Optional[Episode]:
        """A record at ``t`` showed the vehicle out of the lockout; ``reset_code`` when field 8
        reads ``N`` again. Returns the episode it ends (notes absent)."""
        self._clear = t
        if reset_code:
            self._latched = None
        if self.noted:
            return None
        ep = self.episode
        if ep is not None:
            ep.end = t if ep.end is None else min(ep.end, t)
            self.episode = None
        return ep

    # ------------------------------------------------------------------ queries
    def window(self, t: float) -> Optional[Episode]:
        """The episode whose judged window holds ``t``: known by then, not yet over."""
        ep = self.episode
        if ep is None or ep.known is None or t < ep.known:
            return None
        if ep.end is not None and t >= ep.end:
            return None
        return ep
