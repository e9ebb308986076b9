"""Time passing for the vehicle observer: ACK windows and give-up deadlines that run out.

:class:`Deadlines` is the part of :class:`~helmcheck.judge.vehicle.observer.VehicleObserver` that
acts when time passes without an answer, split out to keep one concern per module; it works on the
observer's own state (``pending``, ``silent``, ``gave_up``, ``dead``, ``quiet``, the ledger) and is
never used alone. A command unanswered past its give-up deadline, once the vehicle is seen to
still answer, would fail RH-ACK-2 and RH-ACK-1 — but a faulty line may have lost the command on its
way (which the tester's record cannot show) or its ``$ACK`` on the way back, so both are held
until the command is sent again (the repetition rule, :mod:`helmcheck.judge.streaks`): answered
then, they were the line's; unanswered :data:`~helmcheck.judge.spoil.REPEAT` times in a row, they
are the vehicle's. In a line-fault relay's record the line is known: a lost answer no note
explains is booked at once. A line the vehicle must discard passes its clause (RH-FRM-2/4/5/6/7)
when its window passes unanswered.
"""

from __future__ import annotations

from ..spoil import REPEAT
from ..timing import ack_allowance, ack_give_up_after
from .sent import Sent, text_of

__all__ = ["Deadlines", "GIVE_UP_S"]

#: Wall seconds after which an unanswered command's ACK is taken never to come (RH-ACK-1).
GIVE_UP_S = 15.0


class Deadlines:
    """Windows and waits that run out (module docstring); a base of the vehicle observer."""

    # ------------------------------------------------------------------ time
    def _advance(self, t: float) -> None:
        """Time passed (the next event's time): windows and waits that have run out."""
        if t < self.t:
            t = self.t
        self.t = t
        while self.silent and self._silent_over(self.silent[0], t):
            q = self.silent.popleft()
            self._silence_kept(q)
        window = self.profile.ack_window_s
        over = None
        for p in self.pending:
            if t - p.t <= window:
                continue  # inside the bare window: inside every allowance (ack_allowance ≥ the window)
            allowance = ack_allowance(window, len(p.raw), self.vbytes - p.vbytes0, self.baud, self.res, self.jitter)
            if t - p.t > ack_give_up_after(allowance):
                if over is None:
                    over = []
                over.append((p, allowance))
        if over is not None:
            for p, allowance in over:  # in order (each one's allowance does not depend on the others)
                self.pending.remove(p)
                self._missing(p, allowance)
        if self.gave_up:
            self._give_up(t)

    def give_up_at(self, p: Sent) -> float:
        """When the observer will take ``p``'s ``$ACK`` as missing (RH-ACK-1), as things stand (the
        replies seen since it was sent count in its allowance): a driver that sends anything of
        the same type before then has its answer taken for ``p``'s."""
        allowance = ack_allowance(self.profile.ack_window_s, len(p.raw), self.vbytes - p.vbytes0, self.baud,
                                  self.res, self.jitter)
        return p.t + ack_give_up_after(allowance)

    def _silent_over(self, q: Sent, t: float) -> bool:
        allowance = ack_allowance(self.profile.ack_window_s, len(q.raw), 0, self.baud, self.res, self.jitter)
        return t - q.t > allowance

    def _silence_kept(self, q: Sent) -> None:
        """RH-FRM-2/4/5/6/7: no answer within the window — passed once the vehicle is seen to be
        listening (it answers something after the line)."""
        if q.kind.kind == "oxflt" or q.state == "answered-discard":
            return
        if self.alive_t is not None and self.alive_t >= q.t:
            self.ledger.passed(q.kind.clause, f"{text_of(q)} was discarded silently ({q.kind.clause})",
                               [q.ev], q.case)
        else:
            self.quiet.append(q)

    def _missing(self, p: Sent, allowance: float) -> None:
        """Past the give-up deadline unanswered. RH-ACK-2 is certain now (whatever comes later is
        too late); RH-ACK-1 only once its ACK can no longer come: :data:`GIVE_UP_S` after it was
        sent, or at the record's end — an ACK that comes before that belongs to it (RH-ACK-2),
        never to a later command."""
        p.state = "missing"
        p.waited = ack_give_up_after(allowance)
        if p.first_contact:
            return  # a vehicle not heard from yet (still starting up): not judged (answers.py)
        self.gave_up.append(p)
        if not p.branched:
            # it may have been acted on, its answer lost: both stay candidates (as for a command a
            # later answer overtook, RH-ACK-6)
            p.branched = True
            p.expected = self.beliefs.unanswered(p.kind.item, self.v(p.t))
        if self.alive_t is not None and self.alive_t > p.t:
            self._hold_missing(p)
        else:
            self.dead.append(p)

    def _hold_missing(self, p: Sent) -> None:
        """No ``$ACK`` though the vehicle still answers: RH-ACK-2 and RH-ACK-1, held until the command
        is sent again (module docstring), or booked at once where a relay's record shows the line
        did nothing to it."""
        from .observer import LOST
        known = next((text for text, _need, k, _sig in p.spoils if k), None) or self.faults.held_between(p.t, self.t)
        if self.faults.instrumented and known is None:
            self._book_late(p)
            p.missing_booked = True
            self._book_missing(p)
            return
        p.holding = True
        try:
            self._book_late(p)
            p.missing_booked = True
            self._book_missing(p)
        finally:
            p.holding = False
        text = known or (p.spoils[0][0] if p.spoils else LOST)
        self.hold_command(p, ("cmd", "no $ACK"), text, REPEAT, known is not None)

    def _book_late(self, p: Sent) -> None:
        cands = ((p.kind.variant,) if p.kind.variant else ()) + ("RH-ACK-2",)
        self.book("fail", cands, f"{text_of(p)}: no $ACK,{p.kind.ack_type} within {p.waited:.1f} s, though "
                                 f"the vehicle still answers (the window is {self.profile.ack_window_s:g} s)",
                  [p.ev], at=p)
        p.late_booked = True

    def _book_missing(self, p: Sent) -> None:
        if not p.late_booked:
            self._book_late(p)
        cands = ((p.kind.variant,) if p.kind.variant else ()) + ("RH-ACK-1",)
        self.book("fail", cands, f"{text_of(p)}: no $ACK,{p.kind.ack_type} at all, though the vehicle still "
                                 f"answers", [p.ev], at=p)

    def _give_up(self, t: float) -> None:
        """RH-ACK-1 for what is unanswered :data:`GIVE_UP_S` after it was sent."""
        for p in list(self.gave_up):
            if p.ack is None and not p.missing_booked and t - p.t > GIVE_UP_S and p.late_booked:
                p.missing_booked = True
                self._book_missing(p)

    def _revive(self, t: float) -> None:
        for p in self.dead:
            self._hold_missing(p)
        self.dead.clear()
        for q in self.quiet:
            self._silence_kept(q)
        self.quiet.clear()
