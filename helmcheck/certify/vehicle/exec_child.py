"""The vehicle under test when helmcheck starts it (``--exec``): started on the port, watched for an
exit of its own between cases, stopped at the run's end with its exit recorded as a ``process:``
note (a run fact: ``results.json`` ``process``).

:class:`ExecChild` is the part of :class:`~.runner.Run` that looks after it, split out to keep one
concern per module; it works on the run's own state (``o``, ``child``, ``recorder``, ``link``,
``facts``) and is never used alone.
"""

from __future__ import annotations

from typing import Optional

from ...judge.runfacts import process_note
from .flow import LinkLost

__all__ = ["ExecChild"]


class ExecChild:
    """The vehicle under test (module docstring); a base of the run."""

    # ------------------------------------------------------------------ the vehicle under test (--exec)
    def _start_child(self):
        """Start the vehicle under test on the port; the link once it has opened it."""
        from ...line.exec_port import ChildNotReady, open_for_child
        from ...line.launcher import Launcher

        self.child = Launcher(self.o.exec_cmd, subject="vehicle", directory=self.dir, grace_s=self.o.exec_grace_s)
        try:
            return open_for_child(self.o.port, self.child, baud=self.p.baud, time_scale=self.k,
                                  ready_s=self.o.exec_ready_s)
        except ChildNotReady as e:
            raise LinkLost(str(e)) from None

    def child_gone(self, settle_s: float = 0.0) -> Optional[str]:
        """Why the run cannot go on when the vehicle under test has ended by itself, else None.

        *settle_s*: after a link fault, how long to give its exit to become visible (the port
        closes before the process is reaped)."""
        c = self.child
        if c is None or c.proc is None:
            return None
        if settle_s and c.stopping_at is None and not c.ended:
            c.wait(settle_s)
        if not c.ended_by_itself:
            return None
        return f"the vehicle under test {c.exit_text()} at {c.ended_at - self.t_start:.1f} s"

    def check_child(self) -> None:
        """Between cases: :class:`LinkLost` if the vehicle under test has ended."""
        gone = self.child_gone()
        if gone:
            raise LinkLost(gone)

    def stop_child(self) -> None:
        """End of the run: stop the vehicle under test and record its end as a ``process:`` note
        (a run fact: ``results.json`` ``process``), before the record closes."""
        c = self.child
        if c is None or c.proc is None:
            return
        if self.aborted and not c.ended:
            c.wait(1.0)  # a link fault may be its exit, not yet reaped
        c.stop()
        rec = c.record(epoch=self.t_start)
        if self.recorder is not None:
            t = self.link.now() if self.link is not None else self.recorder.last_t
            self.recorder.note(t, process_note(rec))
        else:
            self.facts.process = rec
