"""Facts about the protocol the judges need, derived from the transition table, never restated.

Each set below is computed from :data:`~helmcheck.model.transitions.TABLE` by asking the table
the question (:func:`~helmcheck.model.transitions.select` with a context whose guard atoms are
set), so a change to the table changes every judge at once:

* :data:`NEEDS_MISSION` — modes a vehicle can only be in while a mission runs (RH-RD-1): every
  mode not reachable from ``S`` by accepted commands while no mission runs.
* :data:`NEEDS_RUNNING` / :data:`NEEDS_STOPPED` — command events refused (RH-ACK-4) in ``S``
  but accepted in ``N``, and the reverse: the preconditions a backseat can know (RH-BS-3).
* :data:`ENDS_SERVO` — command events that, accepted in ``A``, leave ``A``: what ends servo
  control (RH-INT-1, RH-MSN-3), so an ``$OMS`` after one of them is no refresh (RH-BS-6).
* :data:`INTERRUPTS` — command events that start remote control from ``N`` (RH-INT-1).
* :data:`LOCKOUT_REFUSED` / :data:`ASCENT_REFUSED` — command events refused with err 26 in the
  lockout and in the ascent (RH-SAF-1, RH-SAF-3).
* :data:`COMMAND_ID_OF_EVENT` — the sentence ID behind each command event.
"""

from __future__ import annotations

from types import SimpleNamespace

from ..model.transitions import COMMAND_EVENTS, GUARD_ATOMS, MODES, REMOTE_MODES, STAY, select

__all__ = ["NEEDS_MISSION", "NEEDS_RUNNING", "NEEDS_STOPPED", "ENDS_SERVO", "INTERRUPTS",
           "LOCKOUT_REFUSED", "ASCENT_REFUSED", "COMMAND_ID_OF_EVENT", "REMOTE_MODES"]

COMMAND_ID_OF_EVENT = {e: ("OMW" if e.startswith("OMW") else e) for e in COMMAND_EVENTS}


def _ctx(**atoms: bool) -> SimpleNamespace:
    base = {a: False for a in GUARD_ATOMS}
    base.update(atoms)
    return SimpleNamespace(**base)


def _accepted(mode: str, event: str, phase: str = "none", **atoms: bool):
    row = select(mode, phase, event, _ctx(**atoms))
    return row if row is not None and row.error is None else None


def _needs_mission() -> frozenset[str]:
    reach, todo = {"S"}, ["S"]
    while todo:
        m = todo.pop()
        for ev in COMMAND_EVENTS:
            if ev in ("OMSTART",):
                continue  # starting a mission is what "needs a mission" is measured against
            row = _accepted(m, ev)
            if row is not None and row.target not in (STAY,) and row.target not in reach:
                reach.add(row.target)
                todo.append(row.target)
    return frozenset(MODES) - reach


def _state_bound() -> tuple[frozenset[str], frozenset[str]]:
    running, stopped = set(), set()
    for ev in COMMAND_EVENTS:
        in_s = _accepted("S", ev, logging=True)
        in_n = _accepted("N", ev, running=True, logging=True)
        if in_s is None and in_n is not None:
            running.add(ev)
        elif in_s is not None and in_n is None:
            stopped.add(ev)
    return frozenset(running), frozenset(stopped)


def _ends_servo() -> frozenset[str]:
    out = set()
    for ev in COMMAND_EVENTS:
        row = _accepted("A", ev, running=True, logging=True)
        if row is not None and row.target not in (STAY, "A"):
            out.add(ev)
    return frozenset(out)


def _interrupts() -> frozenset[str]:
    out = set()
    for ev in COMMAND_EVENTS:
        row = _accepted("N", ev, running=True, logging=True)
        if row is not None and row.target in REMOTE_MODES:
            out.add(ev)
    return frozenset(out)


def _refused(phase: str) -> frozenset[str]:
    out = set()
    for ev in COMMAND_EVENTS:
        row = select("N", phase, ev, _ctx(running=True, logging=True))
        if row is not None and row.error == 26:
            out.add(ev)
    return frozenset(out)


NEEDS_MISSION: frozenset[str] = _needs_mission()
NEEDS_RUNNING, NEEDS_STOPPED = _state_bound()
ENDS_SERVO: frozenset[str] = _ends_servo()
INTERRUPTS: frozenset[str] = _interrupts()
LOCKOUT_REFUSED: frozenset[str] = _refused("lockout")
ASCENT_REFUSED: frozenset[str] = _refused("ascent")
