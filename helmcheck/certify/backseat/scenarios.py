"""What the tester stages while the backseat runs, and how a run's duration is split.

The run starts when the backseat's first byte arrives. The scenarios run in sequence, each in
its own time slot; by default all five, over ``--duration`` (60 s). Times below are fractions of
the scenario's slot, in wall seconds (the line rules never scale, RH-TIM-2; the vehicle's own
durations — the lockout, the servo timeout — run ``time_scale`` times faster).

``nominal``
    Nothing is staged: the reference vehicle answers exactly as the model does. The backseat
    is expected to start its mission, poll and drive.
``reject``
    From 20 % to 80 % of the slot every command other than ``$OSD`` is refused with a valid
    error ``$ACK``: status 1 and the command's own "incorrect values" error (RH-ACK-3/4, e.g.
    ``$ACK,9,1,20`` for ``$OMS``). The refused command is not passed to the vehicle, so it
    changes nothing (a servo left unrefreshed times out as it would). Judged: RH-BS-5 (no
    resend of the same refused command more than once per second).
``lockout``
    At 20 % of the slot the vehicle raises a safety violation (``Sop``, over pitch), as if a
    safety rule had triggered (RH-SAF-1): for ``lockout_s / time_scale`` wall seconds every
    command except ``$OSD`` is refused with err 26, then the vehicle ascends and does its
    SafetyAction (RH-SAF-3/4, RH-RD-11..13). The slot is long enough for the lockout to end
    and 2 s more. Judged: RH-BS-5 (only ``$OSD`` during the lockout).
``mission-end``
    At 30 % of the slot the running mission ends on the vehicle (the model is stopped off the
    wire, as when the mission finishes or the operator stops it): ``$OSI`` then reports ``S``.
    If no mission is running nothing happens (noted). Judged: RH-BS-3 (no ``$OMS``/``$OJW``/
    ``$OPK``/``$OMW`` once the vehicle reports no running mission).
``silence``
    From 20 % to 70 % of the slot the vehicle neither reads nor answers (as if its serial
    task hung): what the backseat sends meanwhile is judged but lost. Judged: RH-BS-4 (no
    retry flood), RH-BS-8 (keeps polling).

Every clause is judged all the time; the scenarios make sure each reaction is exercised.
Minimum slot lengths: 2 s (``nominal``, ``mission-end``), 2.5 s (``reject``, ``silence``) and
``(lockout wall time + 2 s) / 0.8`` (``lockout``). The lockout slot takes what it needs first,
the others share the rest equally; when ``--duration`` cannot hold every minimum, the run is
lengthened to the sum of the minimums (and says so).
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["SCENARIOS", "Slot", "Action", "Plan", "make_plan", "LOCKOUT_CODE"]

SCENARIOS = ("nominal", "reject", "lockout", "mission-end", "silence")
LOCKOUT_CODE = "Sop"

_MIN = {"nominal": 2.0, "reject": 2.5, "mission-end": 2.0, "silence": 2.5}


@dataclass(frozen=True, slots=True)
class Slot:
    """One scenario's time slot, seconds after the backseat's first byte."""

    name: str
    start: float
    end: float


@dataclass(frozen=True, slots=True)
class Action:
    """One staged step: ``kind`` is ``scenario``, ``reject``, ``lockout``, ``mission-end`` or
    ``silence``; ``on`` starts or ends a window (``reject``, ``silence``)."""

    at: float
    kind: str
    name: str = ""
    on: bool = True


@dataclass(frozen=True)
class Plan:
    slots: tuple[Slot, ...]
    actions: tuple[Action, ...]
    total: float  #: seconds of the judged run
    note: str = ""  #: why the run is longer than asked, if it is


def _lockout_min(lockout_wall: float) -> float:
    return (lockout_wall + 2.0) / 0.8


def make_plan(names: list[str] | tuple[str, ...], duration: float, *, time_scale: float,
              lockout_s: float) -> Plan:
    """Split ``duration`` across ``names`` (in the order given) and list the staged steps."""
    names = list(dict.fromkeys(names)) or list(SCENARIOS)
    unknown = [n for n in names if n not in SCENARIOS]
    if unknown:
        raise ValueError(f"unknown scenario {unknown[0]!r}; choose from {', '.join(SCENARIOS)}")
    lockout_wall = lockout_s / time_scale
    mins = {n: (_lockout_min(lockout_wall) if n == "lockout" else _MIN[n]) for n in names}
    lengths = {n: duration / len(names) for n in names}
    if "lockout" in names and lengths["lockout"] < mins["lockout"]:
        lengths["lockout"] = mins["lockout"]
        others = [n for n in names if n != "lockout"]
        if others:
            rest = max(0.0, duration - mins["lockout"]) / len(others)
            for n in others:
                lengths[n] = rest
    for n in names:
        lengths[n] = max(lengths[n], mins[n])
    total = sum(lengths.values())
    note = ""
    if total > duration + 1e-9:
        note = (f"run lengthened from {duration:g} s to {total:.1f} s so that every scenario fits "
                f"(the lockout lasts {lockout_wall:g} s of wall time at time scale {time_scale:g})")
    slots: list[Slot] = []
    actions: list[Action] = []
    t = 0.0
    for n in names:
        length = lengths[n]
        slot = Slot(n, t, t + length)
        slots.append(slot)
        actions.append(Action(t, "scenario", n))
        if n == "reject":
            actions += [Action(t + 0.2 * length, "reject", n, True), Action(t + 0.8 * length, "reject", n, False)]
        elif n == "lockout":
            actions.append(Action(t + 0.2 * length, "lockout", n))
        elif n == "mission-end":
            actions.append(Action(t + 0.3 * length, "mission-end", n))
        elif n == "silence":
            actions += [Action(t + 0.2 * length, "silence", n, True), Action(t + 0.7 * length, "silence", n, False)]
        t += length
    actions.sort(key=lambda a: a.at)
    return Plan(tuple(slots), tuple(actions), total, note)
