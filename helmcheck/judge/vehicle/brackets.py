"""RH-TIM-1 as the mirror times a timer: which side of it a report shows, how closely the
observations bracket its transition, and how a displayed park time narrows the start of a
countdown an adopted event began (its time window, :mod:`.closure`).
"""

from __future__ import annotations

from typing import Optional

from ...grammar import sentences as s
from ...model.timers import tolerance
from ..timing import judgeable
from .candidate import Candidate, Timed

__all__ = ["pre_shown", "bracket", "retime"]


def pre_shown(tt: Timed, osi: s.OSI) -> Optional[bool]:
    """Does ``osi`` show the state before timer ``tt`` (True), after it (False), or neither?"""
    if tt.timer == "lockout":
        return None
    if tt.timer == "qpark":
        return osi.mode == "W" and osi.park_time > 0
    return osi.mode == tt.pre_mode


def bracket(tt: Timed, v_new: float, slack_v: float) -> tuple:
    """RH-TIM-1: how closely the observations bracket a timer's transition.

    ``pass`` — the before-state was seen close enough before the deadline and the after-state
    close enough after it (within half the duration, RH-TIM-1's last sentence, widened by the
    tolerance); ``inconclusive`` — the observer's own measuring uncertainty (timestamp step,
    jitter, the arming command's round trip) is already too large; ``not-tested`` — the timer
    started with an unseen event placed within a window too wide to time it (nobody set it
    going where it could be timed), or the transition was seen but not sampled near its
    deadline, so its timing was not exercised (a later, closer observation may time it).
    """
    tol = tolerance(tt.duration)
    own = slack_v + tt.extra_v
    what = f"the {tt.duration:g} s {_name(tt)}"
    if not judgeable(tt.duration, slack_v):
        return (tt, "inconclusive", f"the observer's own uncertainty of {slack_v:.1f} s of vehicle time "
                                    f"cannot bound {what} (RH-TIM-1)")
    if not judgeable(tt.duration, own):
        return (tt, "not-tested", f"{what} started with an unseen event placed within {tt.extra_v:.1f} s of "
                                  f"vehicle time, too wide to time it: its timing was not exercised")
    if tt.t_old is None:
        return (tt, "not-tested", f"{what} ended, but the state before it was not observed after it "
                                  f"started, so its timing was not exercised")
    u = max(0.0, (tt.deadline - tol) - tt.t_old, v_new - (tt.deadline + tol)) + own
    if judgeable(tt.duration, u):
        # the precision it was judged with: a transition later (or earlier) than the tolerance,
        # the observer's own uncertainty and the spacing of the reports around the deadline is
        # certain to be seen on the wrong side (RH-TIM-1)
        tt.widened = tol + own + max(0.0, v_new - tt.t_old)
        return (tt, "pass", f"{what} ended within max(0.5 s, 5 %) = {tol:g} s, bracketed to ±{u:.2f} s "
                            f"of vehicle time by the observations")
    return (tt, "not-tested", f"{what} ended, but observations {u:.1f} s of vehicle time from its end "
                              f"did not time it")


def retime(c: Candidate, osi: s.OSI, v_sent: float, v_recv: float, slack_v: float) -> None:
    """A countdown started by an adopted event: the displayed park time narrows its start."""
    if c.window is None or c.extra_v <= 0:
        return
    m = c.model
    name = {"mP": "opk", "P": "park", "W": "qpark"}.get(m.mode)
    if name is None or not m.timers.armed(name) or osi.mode != m.mode:
        return
    dur = m.timers.duration(name) or 0.0
    deadline = m.timers.deadline(name) or 0.0
    start = deadline - dur
    lo_w, hi_w = c.window
    if not lo_w - 1e-6 <= start <= hi_w + 1e-6:
        if name in c.carried:  # resumed after a freeze: what was left carries the window's width
            _redate(c, name, dur, deadline, osi, v_sent, v_recv, slack_v)
        return
    lo = max(lo_w, v_sent - dur + osi.park_time - 1.0 - slack_v)
    hi = min(hi_w, v_recv - dur + osi.park_time + slack_v)
    if lo > hi:
        return
    mid = (lo + hi) / 2
    m.timers.arm(name, mid, dur)
    c.window = (lo, hi)
    c.extra_v = (hi - lo) / 2
    for tt in c.timed:
        tt.extra_v = min(tt.extra_v, c.extra_v)


def _redate(c: Candidate, name: str, dur: float, deadline: float, osi: s.OSI, v_sent: float, v_recv: float,
            slack_v: float) -> None:
    """A countdown frozen and resumed since an adopted event started it (``Candidate.carried``):
    its deadline is uncertain by the window either way; the displayed park time narrows it."""
    width = c.extra_v
    lo = max(deadline - width, v_sent + osi.park_time - 1.0 - slack_v)
    hi = min(deadline + width, v_recv + osi.park_time + slack_v)
    if lo > hi:
        return
    mid = (lo + hi) / 2
    c.model.timers.arm(name, mid - dur, dur)
    c.extra_v = (hi - lo) / 2
    for tt in c.timed:
        tt.extra_v = min(tt.extra_v, c.extra_v)


def _name(tt: Timed) -> str:
    return {"remote": "timeout", "opk": "$OPK park", "qpark": "park on a queued waypoint",
            "park": "mission park", "lockout": "lockout"}.get(tt.timer, tt.timer)
