"""Where an answered command may have found a candidate: the states the mirror tries its answer in.

Besides the nominal state at the ACK's vehicle time (RH-RD-15): when the command lands within the
RH-TIM-1 tolerance of a model timer, both sides of the race (also of a timer the model already
ran: from its checkpoint, the state before it); an accepted ``$OPK`` also with its countdown
waiting for on station (RH-PK-2: where the vehicle is at the ACK, no report settles); before a
command that freezes the mission (RH-INT-1) — or a violation raised with ``$OXFLT``, which freezes
it too (RH-RD-11) — a candidate in ``N`` also with the next waypoint reached unseen just before it,
where it can have got there (:func:`~.closure.reachable`); and under every other reading of the
profile's open questions the command meets (:mod:`helmcheck.model.readings`), where the answer
differs: a vehicle may take any of them.
"""

from __future__ import annotations

from ...grammar import sentences as s
from ...grammar.errors import SentenceError
from ...model.readings import alternatives
from ...model.timers import tolerance
from ...model.vehicle import VehicleModel
from ..facts import INTERRUPTS
from .candidate import Candidate
from .closure import reachable

__all__ = ["branches"]

_WP_ALT_EVENTS = INTERRUPTS


def branches(c: Candidate, item, v: float, slack_v: float, catalog) -> list:
    """``(state, replies, row, (mode, phase) before)`` for every state ``c`` may have answered
    ``item`` in at vehicle time ``v`` (module docstring), the nominal one first."""
    m = c.model
    times = [v]
    dl = m.timer()
    if dl is not None:
        due, dur, _ = dl
        if abs(due - v) <= tolerance(dur, slack_v + c.extra_v):
            before = min(v, due - 1e-6)
            if m.now is None or before >= m.now:
                times.append(before)
            times.append(max(v, due + 1e-6))
    out, late = [], []
    base = m.checkpoint
    fired = c.timed[-1] if (base is not None and c.timed) else None
    if fired is not None and 0.0 <= v - fired.deadline <= tolerance(fired.duration, slack_v + c.extra_v):
        # the model already ran a timer this command lands within RH-TIM-1's tolerance of: on
        # a conforming vehicle it may not have run yet (the checkpoint is the state before it)
        t = c.clone()
        t.model = base.clone()
        t.model.trace = []
        t._mode, t._phase = base.mode, base.phase
        t.timed = [x for x in t.timed if x is not fired and x.deadline != fired.deadline]
        at = max(base.now if base.now is not None else fired.deadline, fired.deadline - 1e-6)
        t.model.advance(at)
        if (t.model.mode, t.model.phase) == (base.mode, base.phase):
            before = (t.model.mode, t.model.phase)
            row = None if isinstance(item, SentenceError) else t.model.row_for(item)
            late.append((t, t.model.receive(item, at), row, before))
    for at in dict.fromkeys(times):
        t = c.clone()
        t.model.advance(at)
        before = (t.model.mode, t.model.phase)
        row = None if isinstance(item, SentenceError) else t.model.row_for(item)
        replies = t.model.receive(item, at)
        out.append((t, replies, row, before))
        if isinstance(item, s.OPK) and t.model.mode == "mP" and t.model.timers.armed("opk"):
            # RH-PK-2: on station or not at the ACK is where the vehicle is then, which the
            # last report (made before it moved on) does not settle: the count may start later
            w = t.clone()
            w.model.await_on_station()
            out.append((w, replies, row, before))
    if (isinstance(item, s.Command) and m.mode == "N" and m.phase == "none" and m.mission is not None
            and (VehicleModel.event_of(item) in _WP_ALT_EVENTS or isinstance(item, s.OXFLT))
            and reachable(c, m.mission_wp, v, catalog)):  # only where it can have got there
        tp = min(max(c.seen_v if c.seen_v is not None else v, m.now or 0.0), v)
        t = c.clone()
        t.model.plant(_wp(), tp)
        if t.model.mode in ("N", "P"):
            # strictly before the command: what the command itself starts (a takeover's timeout, at
            # its ACK, RH-RD-15) is not in the window and keeps its own timing
            t.adopted(f"mission waypoint reached just before the command (v={tp:.1f}..{v:.1f})", tp, v - 1e-3)
            t.model.advance(v)
            before = (t.model.mode, t.model.phase)
            row = t.model.row_for(item)
            out.append((t, t.model.receive(item, v), row, before))
    if out:
        out += _readings(c, item, v, out)
    return out + late  # the nominal answer first: it is what a finding names


def _readings(c: Candidate, item, v: float, out: list) -> list:
    """The answers under every other reading of the profile's open questions that this command
    meets (:func:`helmcheck.model.readings.alternatives`), where they differ from the others."""
    sid = getattr(item, "ID", None) or getattr(item, "sentence_id", None)
    if sid is None:
        return []
    first = out[0][0].model
    got = []
    for key, value in alternatives(sid, first.phase, c.model.readings):
        t = c.clone()
        t.model.readings = {**t.model.readings, key: value}
        t.model.advance(v)
        before = (t.model.mode, t.model.phase)
        row = None if isinstance(item, SentenceError) else t.model.row_for(item)
        replies = t.model.receive(item, v)
        if all(replies != o[1] for o in out + got):
            t.took = t.took + (f"{key} = {value}",)
            got.append((t, replies, row, before))
    return got


def _wp():
    from ...model.plant import WaypointReached
    return WaypointReached()
