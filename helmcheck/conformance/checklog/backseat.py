"""The backseat side of a log check: judge every line the backseat sent (RH-BS-1..8).

This module owns :class:`BackseatJudge`. It needs no model of its own: what the backseat could
know about the vehicle (a mission running, a lockout) it learns from the vehicle's replies, via
the small ``knowledge`` callbacks the checker wires to the vehicle side.

* RH-BS-1 — every sentence is well-formed (§1) with a correct checksum of exactly two hex
  digits; bytes that frame into no sentence (noise, a torn or overlong line) count too.
* RH-BS-2 — fields within the ranges of §4–6 (a syntax or range error of a known command).
* RH-BS-3 — ``$OLOGL``/``$ORWSET`` only while no mission runs; ``$OMS``/``$OJW``/``$OPK``/``$OMW``
  only while the vehicle reports one (its last ``$OSI`` mode, or an accepted ``$OMSTART`` /
  ``$OMSTOP`` since). Unknown state (no report yet) is not judged.
* RH-BS-4 — in no one-second window more bytes than ``baud/10``; with timestamps coarser than
  10 ms only a certain excess fails, otherwise the clause is INCONCLUSIVE (RH-TIM-1).
* RH-BS-5 (SHOULD) — a rejected command is not resent within a second; during a lockout nothing
  but ``$OSD`` is sent.
* RH-BS-6 (SHOULD) — an ``$OMS`` meant to keep servo control comes before the previous one's
  timeout ran out (judged on each ``$OMS`` that follows an accepted ``$OMS`` within twice its
  timeout).
* RH-BS-7 (SHOULD) — upper-case checksum hex, CR LF.
* RH-BS-8 (SHOULD) — while sending commands, an ``$OSD`` asking for ``S`` at least every 5 s.

Line budget, resend spacing and polling are wall time and never scale (RH-TIM-2).
"""

from __future__ import annotations

from collections import OrderedDict, deque
from typing import Callable, Optional

from ...grammar import sentences as s
from ...grammar.codec import Decoded
from ...grammar.errors import FRAMING
from ...profile import Profile
from .accounting import ClauseBook, Evidence

__all__ = ["BackseatJudge", "BACKSEAT_CLAUSES"]

BACKSEAT_CLAUSES = ("RH-BS-1", "RH-BS-2", "RH-BS-3", "RH-BS-4", "RH-BS-5", "RH-BS-6", "RH-BS-7", "RH-BS-8")

_NEEDS_MISSION = (s.OMS, s.OJW, s.OPK, s.OMW)
_NEEDS_STOPPED = (s.OLOGL, s.ORWSET)
POLL_S = 5.0


class BackseatJudge:
    """Judges what the backseat sent. See the module docstring."""

    def __init__(self, book: ClauseBook, profile: Profile, *, baud: int, resolution: float,
                 running: Callable[[], Optional[bool]], in_lockout: Callable[[], Optional[bool]]):
        self.book = book
        self.profile = profile
        self.budget = baud // 10
        self.r = resolution
        self.precise = resolution <= 0.01
        self.running = running
        self.in_lockout = in_lockout
        self._win: deque = deque()  # (t, nbytes) within the last second
        self._win_bytes = 0
        self._rejected: OrderedDict = OrderedDict()  # body -> t of the rejection
        self._last_sent: OrderedDict = OrderedDict()  # body -> t sent
        self._last_oms: Optional[tuple[float, int]] = None  # (t accepted, timeout s wall)
        self._last_poll: Optional[float] = None
        self._poll_gap_open = False
        self.time_scale = 1.0
        self.saw = False

    # ------------------------------------------------------------------ bytes
    def bytes_sent(self, t: float, n: int, ev: Evidence) -> None:
        """RH-BS-4: the line budget over a sliding one-second window."""
        self.saw = True
        win = self._win
        win.append((t, n))
        self._win_bytes += n
        span = 1.0 - self.r if self.r < 1.0 else 0.0
        while win and win[0][0] <= t - span:
            self._win_bytes -= win.popleft()[1]
        if self._win_bytes > self.budget:
            self.book.fail("RH-BS-4", f"{self._win_bytes} bytes within one second; the line drains "
                                      f"{self.budget} (baud/10)", [ev])
            win.clear()
            self._win_bytes = 0
        elif self.precise:
            self.book.ok("RH-BS-4")
        else:
            self.book.inconclusive("RH-BS-4", f"timestamps step {self.r:g} s cannot bound a one-second "
                                              f"window (RH-TIM-1)", [ev])

    def discarded(self, ev: Evidence, reason: str) -> None:
        """Bytes from the backseat that frame into no sentence (RH-BS-1)."""
        self.book.fail("RH-BS-1", f"bytes that are no sentence: {reason}", [ev])

    # ------------------------------------------------------------------ lines
    def line(self, d: Decoded, t: float, ev: Evidence) -> None:
        """RH-BS-1/2/3/5/7/8 for one framed line from the backseat."""
        book = self.book
        for f in d.findings:
            if f.clause in ("RH-FRM-3", "RH-FRM-7"):
                book.fail("RH-BS-7", f.message, [ev])
        if d.terminator == "":
            book.fail("RH-BS-1", "line has no terminator", [ev])
            return
        if d.error is not None:
            if d.error.kind == FRAMING or d.error.ack_type is None and d.error.clause.startswith("RH-FRM"):
                book.fail("RH-BS-1", str(d.error), [ev])
            else:
                book.ok("RH-BS-1")
                book.fail("RH-BS-2", str(d.error), [ev])
            self._lockout_check(None, ev)
            return
        sent = d.sentence
        if not isinstance(sent, s.Command):
            book.fail("RH-BS-1", f"${sent.ID} is a vehicle sentence, not a command", [ev])
            return
        book.ok("RH-BS-1")
        book.ok("RH-BS-2")
        if not d.findings:
            book.ok("RH-BS-7")
        self._preconditions(sent, ev)
        self._lockout_check(sent, ev)
        self._resend(d.raw, t, ev)
        self._poll(sent, t, ev)
        if isinstance(sent, s.OMS):
            self._servo_refresh(t, ev)

    def _preconditions(self, c: s.Command, ev: Evidence) -> None:
        """RH-BS-3."""
        if isinstance(c, _NEEDS_MISSION) or isinstance(c, _NEEDS_STOPPED):
            run = self.running()
            if run is None:
                return
            if isinstance(c, _NEEDS_MISSION) and not run:
                self.book.fail("RH-BS-3", f"${c.ID} sent while the vehicle reports no mission running", [ev])
            elif isinstance(c, _NEEDS_STOPPED) and run:
                self.book.fail("RH-BS-3", f"${c.ID} sent while a mission is running", [ev])
            else:
                self.book.ok("RH-BS-3")

    def _lockout_check(self, c: Optional[s.Command], ev: Evidence) -> None:
        """RH-BS-5, second half: nothing but ``$OSD`` during a lockout."""
        lock = self.in_lockout()
        if lock is None or not lock:
            return
        if isinstance(c, s.OSD):
            self.book.ok("RH-BS-5")
        elif not isinstance(c, s.OXFLT):
            self.book.fail("RH-BS-5", "a command other than $OSD during the safety lockout", [ev])

    def _resend(self, raw: bytes, t: float, ev: Evidence) -> None:
        """RH-BS-5, first half: a rejected command is not resent within a second."""
        body = raw.rstrip(b"\r\n")
        rej = self._rejected.get(body)
        if rej is not None:
            if t - rej < 1.0 - self.r:
                self.book.fail("RH-BS-5", f"rejected command resent after {t - rej:.3f} s (< 1 s)", [ev])
            else:
                self.book.ok("RH-BS-5")
            self._rejected[body] = t
        self._last_sent[body] = t
        self._last_sent.move_to_end(body)
        if len(self._last_sent) > 64:
            self._last_sent.popitem(last=False)

    def rejected(self, raw_text: str, t_cmd: float) -> None:
        """The vehicle rejected this command (status 1): watch for quick resends."""
        body = raw_text.encode("latin-1", "replace")
        self._rejected[body] = t_cmd
        self._rejected.move_to_end(body)
        if len(self._rejected) > 64:
            self._rejected.popitem(last=False)

    def oms_accepted(self, t: float, timeout_s: int) -> None:
        self._last_oms = (t, timeout_s)

    def control_changed(self) -> None:
        """Another command ended servo control: the next ``$OMS`` is no refresh (RH-BS-6)."""
        self._last_oms = None

    def _servo_refresh(self, t: float, ev: Evidence) -> None:
        """RH-BS-6: a refresh that comes after the previous timeout lapsed (within 2× of it)."""
        last = self._last_oms
        if last is None or self.in_lockout():
            return
        t0, timeout = last
        wall = timeout / self.time_scale
        dt = t - t0
        if dt <= wall - self.r:
            self.book.ok("RH-BS-6")
        elif dt <= 2 * wall:
            self.book.fail("RH-BS-6", f"$OMS refresh {dt:.3f} s after the last one; its timeout was "
                                      f"{wall:.3f} s (servo control lapsed)", [ev])

    def _poll(self, c: s.Command, t: float, ev: Evidence) -> None:
        """RH-BS-8: ``$OSD`` with ``S`` at least every 5 s while sending commands."""
        if self._last_poll is None:
            self._last_poll = t
        gap = t - self._last_poll
        if gap > POLL_S + self.r and not self._poll_gap_open:
            self._poll_gap_open = True
            self.book.fail("RH-BS-8", f"no $OSD state poll for {gap:.1f} s while commands were sent", [ev])
        if isinstance(c, s.OSD) and "S" in c.requested:
            if not self._poll_gap_open:
                self.book.ok("RH-BS-8")
            self._last_poll = t
            self._poll_gap_open = False
