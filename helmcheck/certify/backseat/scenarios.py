"""What the tester stages while the backseat runs, and how long each scenario is planned to last.

The run starts when the backseat's first byte arrives. The scenarios run in sequence, each in
its own time slot; by default all five. Each slot is as long as what the scenario must show
needs (:func:`make_plan`, printed by ``certify backseat --plan``), at the run's time scale (the
vehicle's durations — the lockout, the ascent — run ``time_scale`` times faster, RH-TIM-2) and on
its line (a report reaches the backseat after the ACK window and the transmit time of a reply at
the baud, 10 bits a byte; the backseat then gets ``reaction_s``). Times are wall seconds. The
staged step of a scenario comes :data:`LEAD_S` into it, so the backseat is first seen in the
state before it.

``nominal`` (:data:`NOMINAL_S`: two of RH-BS-8's longest poll intervals)
    Nothing is staged: the reference vehicle answers exactly as the model does. The backseat
    is expected to start its mission, poll and drive.
``reject`` (the lead, a window of one of RH-BS-8's poll intervals, a reach and a resend spacing, :data:`TAIL_S`)
    In the window every command other than ``$OSD`` is refused with a valid error ``$ACK``: status
    1 and the command's own "incorrect values" error (RH-ACK-3/4, e.g. ``$ACK,9,1,20`` for
    ``$OMS``). The refused command is not passed to the vehicle, so it changes nothing (a servo
    left unrefreshed times out as it would). Judged: RH-BS-5 (no resend of the same refused
    command more than once per second).
``lockout`` (the lead, the lockout and the ascent from the test mission's deepest waypoint, a reach)
    The vehicle raises a safety violation (``Sop``, over pitch), as if a safety rule had
    triggered (RH-SAF-1): for ``lockout_s / time_scale`` wall seconds every command except
    ``$OSD`` is refused with err 26, then the vehicle ascends and does its SafetyAction
    (RH-SAF-3/4, RH-RD-11..13). Judged: RH-BS-5 (only ``$OSD`` during the lockout).
``mission-end`` (the lead, a reach and a resend spacing)
    The running mission ends on the vehicle (the model is stopped off the wire, as when the
    mission finishes or the operator stops it): ``$OSI`` then reports ``S``. Judged: RH-BS-3 (no
    ``$OMS``/``$OJW``/``$OPK``/``$OMW`` once the vehicle reports no running mission).
``silence`` (the lead, :data:`SILENCE_S`, :data:`TAIL_S`)
    The vehicle neither reads nor answers (as if its serial task hung): what the backseat sends
    meanwhile is judged but lost. Judged: RH-BS-4 (no retry flood), RH-BS-8 (keeps polling).

Every clause is judged all the time; the scenarios make sure each reaction is exercised. A run
longer than the plan (``--duration``) shares the surplus in proportion to the slots; a shorter
one is named before the run starts and the plan's lengths are kept (:attr:`Plan.short`). At run
time a scenario whose moment has not reached the backseat by its planned end is extended, by at
most :attr:`Slot.limit` (:mod:`.stage`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ...judge.backseat import POLL_INTERVAL_S, RESEND_SPACING_S
from ...judge.timing import transmit_time

__all__ = ["SCENARIOS", "Slot", "Action", "Plan", "make_plan", "reach_s", "LOCKOUT_CODE", "LEAD_S", "TAIL_S",
           "NOMINAL_S", "SILENCE_S", "REPLY_BYTES"]

SCENARIOS = ("nominal", "reject", "lockout", "mission-end", "silence")
LOCKOUT_CODE = "Sop"

#: Seconds into a scenario before its staged step (the backseat seen in the state before it).
LEAD_S = 1.0
#: Seconds a staged window (reject, silence) ends before its scenario does.
TAIL_S = 1.0
#: The nominal scenario: two of RH-BS-8's longest poll intervals (a backseat polling as seldom as
#: the clause allows is seen polling twice, and has time to start its mission and take control).
NOMINAL_S = 2 * POLL_INTERVAL_S
#: The silence: one of RH-BS-8's longest poll intervals (a backseat polling as seldom as the clause
#: allows is seen polling into it, and retrying); the run extends it to outlast the backseat's own
#: timeout and two of its polls (:mod:`.stage`).
SILENCE_S = POLL_INTERVAL_S
#: Bytes of a reply a report may wait behind on the line (an ``$OSD`` of every letter, with its
#: ``$ACK``; the same figure the ACK window's allowance uses).
REPLY_BYTES = 1024


def reach_s(baud: int, ack_window_s: float, reaction_s: float) -> float:
    """Wall seconds from a vehicle event to the backseat acting on the report of it: the ACK
    window, a reply's transmit time at ``baud`` (:data:`REPLY_BYTES`) and ``reaction_s``."""
    return ack_window_s + transmit_time(REPLY_BYTES, baud) + reaction_s


@dataclass(frozen=True, slots=True)
class Slot:
    """One scenario's time slot, seconds after the backseat's first byte; ``needs`` is what it
    must show needs (its planned length before any surplus), ``why`` says what that is, ``limit``
    the seconds the run may extend it by."""

    name: str
    start: float
    end: float
    needs: float = 0.0
    why: str = ""
    limit: float = 0.0

    @property
    def length(self) -> float:
        return self.end - self.start


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
    total: float  #: seconds of the judged run, as planned (extensions come on top, :mod:`.stage`)
    note: str = ""  #: why the run is longer than asked, if it is
    needed: float = 0.0  #: what every scenario needs, together (the default ``--duration``)
    short: tuple[str, ...] = ()  #: the scenarios a ``--duration`` was too short for, each "name (needs N s: why)"
    time_scale: float = 1.0
    baud: int = 0
    extras: dict = field(default_factory=dict)  #: the figures the lengths were made from

    def describe(self) -> list[str]:
        """The plan as lines (``certify backseat --plan``)."""
        k = self.time_scale
        out = [f"plan at ×{k:g} on {self.baud} baud: {self.total:.1f} s of judged run after the backseat's "
               f"first byte ({', '.join(s.name for s in self.slots)})"]
        w = max(len(s.name) for s in self.slots) if self.slots else 0
        for s in self.slots:
            out.append(f"  {s.name:<{w}}  {s.length:6.1f} s  {s.why} (held open up to {s.limit:.0f} s more "
                       f"until its moment reaches the backseat)")
        if self.note:
            out.append(self.note)
        return out


def _fmt(x: float) -> str:
    return f"{x:.2f}".rstrip("0").rstrip(".") if x < 10 else f"{x:.1f}".rstrip("0").rstrip(".")


def make_plan(names: list[str] | tuple[str, ...], duration: float | None = None, *, time_scale: float,
              lockout_s: float, baud: int = 19200, ack_window_s: float = 1.0, reaction_s: float = 0.25,
              timeout_max_s: float = 120.0, ascent_depth_m: float = 0.0, ascent_mps: float = 0.3) -> Plan:
    """Each scenario of ``names`` (in the order given) as long as what it must show needs (module
    docstring), the surplus of a longer ``duration`` shared in proportion; the staged steps."""
    names = list(dict.fromkeys(names)) or list(SCENARIOS)
    unknown = [n for n in names if n not in SCENARIOS]
    if unknown:
        raise ValueError(f"unknown scenario {unknown[0]!r}; choose from {', '.join(SCENARIOS)}")
    k = float(time_scale)
    reach = reach_s(baud, ack_window_s, reaction_s)
    lockout_wall = lockout_s / k
    ascent_wall = (ascent_depth_m / ascent_mps if ascent_mps > 0 else 0.0) / k
    tx = transmit_time(REPLY_BYTES, baud)
    line = (f"{ack_window_s:g} s ACK window, {_fmt(tx)} s for a reply on {baud} baud, "
            f"{reaction_s:g} s to react")
    cycles = 2 * timeout_max_s / k + 2 * POLL_INTERVAL_S
    needs: dict[str, tuple[float, str, float]] = {}
    for n in names:
        if n == "nominal":
            needs[n] = (NOMINAL_S, f"the backseat polls, starts its mission and takes control: two of RH-BS-8's "
                                   f"{POLL_INTERVAL_S:g} s poll intervals", cycles)
        elif n == "reject":
            length = LEAD_S + POLL_INTERVAL_S + reach + RESEND_SPACING_S + TAIL_S
            needs[n] = (length, f"a command within one of RH-BS-8's {POLL_INTERVAL_S:g} s poll intervals, its "
                                f"staged refusal reaching the backseat ({line}) and a {RESEND_SPACING_S:g} s resend "
                                f"spacing after it", 0.0)
        elif n == "lockout":
            length = LEAD_S + lockout_wall + ascent_wall + reach
            asc = (f" and the ascent from {ascent_depth_m:g} m at {ascent_mps:g} m/s ({_fmt(ascent_wall)} s)"
                   if ascent_wall > 0 else "")
            needs[n] = (length, f"a {lockout_s:g} s lockout ({_fmt(lockout_wall)} s at ×{k:g}){asc}, its end "
                                f"reaching the backseat ({line})", 0.0)
        elif n == "mission-end":
            length = LEAD_S + reach + RESEND_SPACING_S
            needs[n] = (length, f"the test mission's end reaching the backseat ({line}) and a "
                                f"{RESEND_SPACING_S:g} s spacing of its commands after it", 0.0)
        else:  # silence
            length = LEAD_S + SILENCE_S + TAIL_S
            needs[n] = (length, f"{_fmt(SILENCE_S)} s of silence (one of RH-BS-8's longest poll intervals), "
                                f"extended to outlast the backseat's own timeout and two of its polls",
                        timeout_max_s / k + 2 * POLL_INTERVAL_S)
    needed = sum(v[0] for v in needs.values())
    lengths = {n: needs[n][0] for n in names}
    note, short = "", ()
    if duration is not None and duration > needed + 1e-9:
        for n in names:
            lengths[n] *= duration / needed
    elif duration is not None and duration < needed - 1e-9:
        short = tuple(f"{n} (needs {needs[n][0]:.1f} s: {needs[n][1]})" for n in names)
        note = (f"--duration {duration:g} s is too short at ×{k:g} on {baud} baud: the scenarios need "
                f"{needed:.1f} s ({', '.join(f'{n} {needs[n][0]:.1f} s' for n in names)}); the run takes "
                f"{needed:.1f} s (helmcheck certify backseat --plan shows why)")
    slots: list[Slot] = []
    actions: list[Action] = []
    t = 0.0
    for n in names:
        length = lengths[n]
        limit = max(needs[n][2], length, 2 * POLL_INTERVAL_S)
        slots.append(Slot(n, t, t + length, needs[n][0], needs[n][1], limit))
        actions.append(Action(t, "scenario", n))
        if n == "reject":
            actions += [Action(t + LEAD_S, "reject", n, True), Action(t + length - TAIL_S, "reject", n, False)]
        elif n == "lockout":
            actions.append(Action(t + LEAD_S, "lockout", n))
        elif n == "mission-end":
            actions.append(Action(t + LEAD_S, "mission-end", n))
        elif n == "silence":
            actions += [Action(t + LEAD_S, "silence", n, True), Action(t + length - TAIL_S, "silence", n, False)]
        t += length
    actions.sort(key=lambda a: a.at)
    return Plan(tuple(slots), tuple(actions), t, note, needed, short, k, baud,
                {"reach_s": round(reach, 3), "lockout_wall_s": lockout_wall, "ascent_wall_s": round(ascent_wall, 3)})
