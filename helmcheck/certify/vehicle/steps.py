"""The step vocabulary of the clause cases: plain data, interpreted by :mod:`.interpreter`.

A step says what the tester does; it never says what verdict follows — the vehicle observer
judges every reply and report. Where a step names a state (``Poll(mode="A")``) it is an
*exercise condition*: the case needs the vehicle there to exercise its clause. A conforming
vehicle that is elsewhere (the observer found nothing wrong) means the case could not exercise
the clause on this vehicle: INCONCLUSIVE with that reason, never PASS.

Templates in step text (and in the numbers a step takes as text, ``Wait("{gap}")``): the durations
the line budget allows (``{to}``, ``{to_long}``, ``{to_tim}``, ``{to_restart}``, ``{gap}``,
``{opk_min}``, ``{opk_s}``, ``{dive_depth}``, ``{dive_at}``: :mod:`.durations`; ``{opos_lat}`` a point
far enough north that an ``$OPOS`` there is told applied or not by the next report), ``{mission}`` the profile's mission, ``{speed}`` a speed within the
bench-safety limit, ``{motor}`` a motor byte within it, ``{lat}``/``{lon}`` the vehicle's last
reported position, ``{near_lat}``/``{near_lon}`` a point ~110 m north/east of it, ``{far_lat}`` one
~111 km north, ``{km_lat}`` one ~1.1 km north, ``{wp_last}``/``{wp_bad}`` the last and one-past-the-last waypoint number,
``{wp_other}`` a waypoint of the test mission other than its learnt park waypoint,
``{depth_over}`` a depth just over ``max_depth``, ``{speed_over}`` a speed just over
``max_speed_kn``. The profile's own bounds at their edges (:func:`.edges.edge_values`): ``{to_lo}``/``{to_hi}``
the ends of ``timeout_range`` and ``{to_under}``/``{to_over}`` one past them, ``{depth_max}``/``{depth_out}``
and ``{speed_max}``/``{speed_out}`` the ceiling and 0.1 past it, ``{wp_first}``/``{wp_under}`` the first
waypoint and one below; ``{opk_in_lat}``/``{opk_out_lat}`` a point due north of the vehicle's last
reported position just inside and just outside the ``$OPK`` limit (``opk_max_distance_m``, :data:`.edges.OPK_EDGE`);
``{kw_a}``, ``{kw_b}``, ``{kw_c}`` the profile's ``$OMW`` keywords (``omw_clear_keywords``), the first three, repeated
when there are fewer.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

__all__ = ["Send", "Raw", "Poll", "Wait", "Settle", "Until", "Fault", "Start", "MissionEnd", "WithSetting",
           "Burst", "SetRoundTrip", "Octd", "ClearWords", "Quiet", "Case", "RAW_KINDS"]

#: Mutations of a valid sentence (:func:`.interpreter.raw_line`), each tied to its clause.
RAW_KINDS = {
    "badck": "RH-FRM-4: a wrong checksum (discarded; RH-FRM-2 defines the right one)",
    "zerock": "RH-FRM-2: a right checksum under 0x10, written zero-padded (read and answered)",
    "lowerck": "RH-FRM-3: lower-case checksum hex",
    "nock": "RH-FRM-4: no *hh",
    "shortck": "RH-FRM-4: one hex digit",
    "longck": "RH-FRM-4: three hex digits",
    "hexck": "RH-FRM-4: two characters that are not hex digits",
    "twostar": "RH-FRM-4, RH-RD-16: two '*'",
    "unknown": "RH-FRM-5: an unknown ID (sent as is)",
    "lowerid": "RH-FRM-5, RH-RD-16: a lower-case ID",
    "exact256": "RH-FRM-6: exactly max_line_bytes with CR LF",
    "overlong": "RH-FRM-6: one byte more",
    "noise": "RH-FRM-7: bytes before '$'",
    "torn": "RH-FRM-7: a sentence cut by the next '$'",
    "barelf": "RH-FRM-7: a bare LF terminator",
}


@dataclass(frozen=True)
class Send:
    """Send a framed command. ``expect``: the answer in words, for people and replay files; the
    interpreter checks it agrees with the model (a disagreement is the case's fault)."""

    body: str
    expect: str = ""


@dataclass(frozen=True)
class Raw:
    """Send a mutated line (:data:`RAW_KINDS`)."""

    kind: str
    body: str


@dataclass(frozen=True)
class Poll:
    """``$OSD,S``. ``mode``/``mode_not``/``park_below``/``submerged`` (a depth below the
    profile's ``gps_fix_depth_m``): exercise conditions (module docstring)."""

    mode: Optional[str] = None
    mode_not: Optional[str] = None
    park_below: Optional[int | str] = None
    submerged: Optional[bool] = None


@dataclass(frozen=True)
class Wait:
    """Let protocol time pass (vehicle seconds, or a template such as ``"{gap}"``), polling;
    ``probe`` is sent each round."""

    vehicle_s: float | str
    probe: Optional[str] = None


@dataclass(frozen=True)
class Settle:
    """Poll across a model timer's deadline until the vehicle left the state before it."""

    timer: Optional[str] = None
    probe: Optional[str] = None


@dataclass(frozen=True)
class Until:
    """Poll until the ``$OSI`` shows ``mode`` (and ``park_below``, the surface, the SRP flag)."""

    what: str
    mode: Optional[str] = None
    park_below: Optional[int | str] = None
    budget_v: float = 600.0
    surface: bool = False
    srp_active: Optional[bool] = None
    submerged: Optional[bool] = None  #: True: until the depth is below the GPS-fix depth
    depth_at_least: Optional[float | str] = None  #: until ``$OSI`` field 15 shows at least this depth
    refresh: Optional[str] = None  #: a control sent again at half its timeout while waiting (a slow dive)
    #: only when something was made again since the last ``Until`` confirmed the state (a faulty
    #: line): that re-run may have outlasted the control; else skipped (a poll costs time)
    after_reruns: bool = False


@dataclass(frozen=True)
class Fault:
    """Raise a safety violation the profile's way (RH-SAF-5: ``$OXFLT,<code>``, no ACK is due; a
    mission's own rule; an operator). ``then``: commands written in one burst right after it (with
    the ``$OXFLT``, in the same write), so that they reach the vehicle inside the lockout on any
    line and at any time scale the line budget allows (RH-SAF-1)."""

    code: str = "Sle"
    then: tuple = ()


@dataclass(frozen=True)
class Start:
    """Start a mission by name (rh5 form): the profile key ``which`` names it; ``srp`` gives the
    profile's ``srp_mission`` as the SRP (RH-RD-6); ``ignore_gps`` sets the first flag."""

    ignore_gps: int = 0
    which: str = "mission"
    srp: bool = False


@dataclass(frozen=True)
class MissionEnd:
    """Poll until the running mission ends (``S``), at most ``cap_v`` vehicle seconds."""

    cap_v: float = 1800.0


@dataclass(frozen=True)
class WithSetting:
    """Read ``setting`` (in ``S``), write state 1 and ``value``, run ``steps``; then stop the
    mission (the verified reset) and write back what was read, verified by a read."""

    setting: str
    value: str
    steps: tuple


@dataclass(frozen=True)
class Burst:
    """Several commands written back to back before any reply is read (RH-ACK-6); ``expect``: the
    answer to each, in words (as :class:`Send`'s)."""

    bodies: tuple
    expect: tuple = ()


@dataclass(frozen=True)
class SetRoundTrip:
    """Read a setting, write a changed state and value, read it back, restore it (RH-SET-2)."""

    setting: str


@dataclass(frozen=True)
class ClearWords:
    """RH-RD-4: every ``$OMW`` keyword the profile names (``omw_clear_keywords``) in lower, upper and
    title case, each sent with ``queue`` queued before it (a waypoint: mode ``W``), where it must
    clear the queue and resume the mission (a report after each); then each word beside them that
    must be refused — the keyword edges of :func:`.edges.edge_list`."""

    queue: str


@dataclass(frozen=True)
class Quiet:
    """The line goes quiet: nothing is sent for ``wall_s`` wall seconds (no poll either). With
    ``reopen`` the tester then closes its end of the link and opens it again under the same name,
    where a name can be opened again (a device path, ``socket://``: a client reconnecting; not a
    pseudo-terminal the run made, nor a vehicle it started). The next step is the first command
    after it (RH-ACK-1: every command gets its ``$ACK``, the first after a silence too)."""

    wall_s: float = 5.0
    reopen: bool = False


@dataclass(frozen=True)
class Octd:
    """``$OSD,T`` after an ``$OPOS`` that gave conductivity and temperature (RH-POS-2)."""


@dataclass(frozen=True)
class Case:
    """One numbered case: the clauses it speaks to (the first is its subject), what it does."""

    id: str
    clauses: tuple
    title: str
    expectation: str
    start: str  #: S (no mission), N (the test mission running), P (in its mission park)
    steps: tuple
    needs: tuple = ()

    @property
    def subject(self) -> str:
        return self.clauses[0]

    def describe(self) -> dict:
        return {"id": self.id, "clauses": list(self.clauses), "title": self.title,
                "expectation": self.expectation, "start": self.start,
                "steps": [f"{type(st).__name__}{_args(st)}" for st in self.steps]}


def _args(st) -> str:
    parts = [repr(v) for v in vars(st).values() if v not in (None, "", ())] if hasattr(st, "__dict__") else []
    return "(" + ", ".join(parts) + ")"
