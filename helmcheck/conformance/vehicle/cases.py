"""The clause cases: numbered, data-described, run in order with a verified reset before each.

A :class:`Case` names the clauses it speaks to (the first is its subject), a description, the
expectation in words, the state it starts from (``S``: no mission; ``N``: the profile's mission
started by name; ``P``: that mission in its mission park) and a list of steps. Steps are plain
data (:class:`Send`, :class:`Raw`, :class:`Poll`, :class:`Wait`, :class:`Settle`, …); the
interpreter (:func:`run_case`) turns them into :class:`~.session.Session` calls. The *oracle*
for every reply and every ``$OSI`` is the mirrored reference model (:mod:`.mirror`); the
``expect`` text a step carries is for people and replay files, and the interpreter checks that
it agrees with the model (a disagreement is a tester fault: INCONCLUSIVE, never FAIL).

Two cases start a mission other than the plain test mission. RH-MSN-4 (V-47) starts the
profile's ``end_mission`` by name and waits for its end (:class:`MissionEnd`). The ``srp``
branch of RH-SAF-4 (V-63; V-61 is the ``park`` branch) writes ``SafetyAction = srp`` in ``S``
(:class:`WithSetting`, written back afterwards), starts the test mission with the profile's
``srp_mission`` as its SRP (RH-RD-6), raises a violation and checks the vehicle runs the SRP
at the surface (RH-RD-12, RH-RD-13). An empty ``end_mission`` or ``srp_mission`` makes its case
NOT-TESTED with that reason.

Templates in step text: ``{mission}`` the profile's mission, ``{speed}`` a speed within the
bench-safety limit, ``{motor}`` a motor byte within it, ``{lat}``/``{lon}`` the vehicle's last
reported position, ``{near_lat}`` a point ~110 m north of it, ``{far_lat}`` one ~111 km north,
``{wp_last}``/``{wp_bad}`` the last and one-past-the-last waypoint number, ``{depth_over}`` a
depth just over ``max_depth``, ``{speed_over}`` a speed just over ``max_speed_kn``.

Negative framing lines (:class:`Raw` kinds) are derived from a valid sentence by one mutation
each, tied to its clause: ``badck`` wrong checksum (RH-FRM-2/4), ``lowerck`` lower-case hex
(RH-FRM-3), ``nock`` no ``*hh`` and ``shortck`` one hex digit (RH-FRM-4), ``unknown`` an unknown
ID and ``lowerid`` a lower-case ID (RH-FRM-5, RH-RD-16), ``exact256``/``overlong`` a line of
exactly 256 bytes and one of 257 (RH-FRM-6), ``noise`` bytes before ``$``, ``torn`` a sentence
cut by the next ``$`` and ``barelf`` a bare LF terminator (RH-FRM-7).
"""

from __future__ import annotations

from dataclasses import dataclass
from decimal import Decimal
from fnmatch import fnmatchcase
from typing import Optional

from ...grammar import checksum_hex
from ...grammar import sentences as s
from ...profile import Profile
from .judge import CaseFail, CaseInconclusive, CaseNotTested
from .safety import BenchSafetyRefused
from .session import Session, frame

__all__ = ["Case", "Send", "Raw", "Poll", "Wait", "Settle", "Until", "Fault", "Start", "MissionEnd",
           "WithSetting", "Burst", "SetRoundTrip", "Octd", "CASES", "select_cases", "run_case", "raw_line",
           "context"]


# ============================================================================ step vocabulary

@dataclass(frozen=True)
class Send:
    """Send a framed command; the model decides the right answer. ``expect``: the answer in words."""

    body: str
    clause: Optional[str] = None
    expect: str = ""


@dataclass(frozen=True)
class Raw:
    """Send a mutated line (module docstring lists the kinds)."""

    kind: str
    body: str
    clause: Optional[str] = None


@dataclass(frozen=True)
class Poll:
    """``$OSD,S``; the ``$OSI`` is judged by the model, and by the explicit field checks given."""

    clause: Optional[str] = None
    mode: Optional[str] = None
    mode_not: Optional[str] = None
    waypoint: Optional[int] = None
    actuators: Optional[str] = None
    error_state: Optional[str] = None
    park_below: Optional[int] = None
    park: Optional[int] = None
    lat_near: Optional[str] = None
    srp_active: Optional[bool] = None


@dataclass(frozen=True)
class Wait:
    """Let protocol time pass (vehicle seconds), polling and judging; ``probe`` is sent each round."""

    vehicle_s: float
    clause: Optional[str] = None
    probe: Optional[str] = None


@dataclass(frozen=True)
class Settle:
    """Poll past a model timer's deadline + RH-TIM-1 tolerance + slack."""

    clause: str
    timer: Optional[str] = None
    probe: Optional[str] = None


@dataclass(frozen=True)
class Until:
    """Poll until the ``$OSI`` shows ``mode`` (and ``park_below``); NOT-TESTED past the budget."""

    what: str
    mode: Optional[str] = None
    park_below: Optional[int] = None
    budget_v: float = 600.0
    clause: Optional[str] = None
    estimate: bool = False
    surface: bool = False
    srp_active: Optional[bool] = None


@dataclass(frozen=True)
class Fault:
    """``$OXFLT,<code>``: raise a safety violation (RH-SAF-5); no ACK is due."""

    code: str = "Sle"


@dataclass(frozen=True)
class Start:
    """Start a mission by name (rh5 form): the profile key ``which`` names it (``mission``, the
    test mission, or ``end_mission``); ``srp`` gives the profile's ``srp_mission`` as the SRP
    name (``$OMSTART,…,<name>,<srp>``, RH-RD-6); ``ignore_gps`` sets the first flag."""

    ignore_gps: int = 0
    clause: str = "RH-MSN-2"
    which: str = "mission"
    srp: bool = False


@dataclass(frozen=True)
class MissionEnd:
    """Wait for the running mission to end (``S``, RH-MSN-4): :meth:`~.session.Session.mission_end`
    with a fixed cap of ``cap_v`` vehicle seconds and a case budget of ``wall_s`` wall seconds."""

    clause: str = "RH-MSN-4"
    cap_v: float = 1800.0
    wall_s: float = 600.0


@dataclass(frozen=True)
class WithSetting:
    """Read ``setting`` (in ``S``), write state 1 and ``value``, run ``steps``; then stop the
    mission (the verified reset, waiting out a lockout) and write back what was read, so later
    cases meet the vehicle as it was (RH-SET-1/2)."""

    setting: str
    value: str
    steps: tuple
    clause: str = "RH-SET-1"


@dataclass(frozen=True)
class Burst:
    """Several commands written back to back before any reply is read (RH-ACK-6)."""

    bodies: tuple
    clause: str = "RH-ACK-6"


@dataclass(frozen=True)
class SetRoundTrip:
    """Read a setting, write a changed state and value, read it back, restore it (RH-SET-2)."""

    setting: str
    clause: str = "RH-SET-2"


@dataclass(frozen=True)
class Octd:
    """``$OSD,T``: the ``$OCTD`` shows the conductivity and temperature last given by ``$OPOS``."""

    conductivity: str
    temperature: str
    clause: str = "RH-POS-2"


@dataclass(frozen=True)
class Case:
    id: str
    clauses: tuple
    title: str
    expectation: str
    start: str
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


# ============================================================================ the cases

OMS = "OMS,90,2,20,{speed},10"
OMS0 = "OMS,90,2,20,0,10"  # speed 0: the vehicle holds its position
FAR_OMW = "OMW,{near_lat},{lon},2,,15,{speed},0,"


def _c(id_, clauses, title, expectation, start, *steps, needs=()):
    return Case(id_, tuple(clauses.split()), title, expectation, start, tuple(steps), tuple(needs))


CASES: tuple[Case, ...] = (
    # --- §1 framing -----------------------------------------------------------------------
    _c("V-01", "RH-FRM-1", "A well-formed sentence is answered",
       "$OSD in positional and letter form each get their data and $ACK,8; every vehicle line is "
       "$ID,fields*hh CR LF", "S",
       Send("OSD,G,C,S,P,,,,", expect="data, then $ACK,8,0,0"), Send("OSD,S"), Poll()),
    _c("V-02", "RH-FRM-2 RH-FRM-4", "A wrong checksum is discarded",
       "no ACK within the ACK window, the next $OSD is answered, the mode stays N", "N",
       Raw("badck", "OMSTOP,0", "RH-FRM-2"), Raw("badck", "OMS,90,2,20,0,10", "RH-FRM-2"),
       Poll("RH-FRM-2", mode="N")),
    _c("V-03", "RH-FRM-3", "Lower-case checksum hex is accepted",
       "a command with lower-case hex is answered as with upper case; vehicle output uses upper case",
       "N", Raw("lowerck", "OSD,S", "RH-FRM-3"), Raw("lowerck", "OJW,1", "RH-FRM-3"),
       Poll("RH-FRM-3", waypoint=1)),
    _c("V-04", "RH-FRM-4", "A missing or malformed checksum is discarded",
       "no ACK for a line without *hh or with one hex digit; no state change", "N",
       Raw("nock", "OMSTOP,0"), Raw("shortck", "OMSTOP,0"), Raw("twostar", "OMSTOP,0"),
       Poll(mode="N")),
    _c("V-05", "RH-FRM-5", "An unknown ID is discarded",
       "no ACK for $OXYZ or a lower-case $omstop; no state change", "N",
       Raw("unknown", "OXYZ,1"), Raw("lowerid", "OMSTOP,0"), Poll(mode="N")),
    _c("V-06", "RH-FRM-6", "256 bytes is the line limit",
       "a valid 256-byte line is answered; a 257-byte line is discarded and the receiver resyncs at "
       "the next $", "N",
       Raw("exact256", "OSD,S"), Raw("overlong", "OSD,S"), Raw("overlong", "OMSTOP,0"), Poll(mode="N")),
    _c("V-07", "RH-FRM-7", "Noise, torn lines and bare LF",
       "noise before $ is skipped; a sentence cut by the next $ is never merged or executed; a bare LF "
       "ends a line", "N",
       Raw("noise", "OSD,S"), Raw("torn", "OMSTOP,0"), Raw("barelf", "OSD,S"), Poll(mode="N")),
    _c("V-08", "RH-FRM-8", "The $C compass sentence has no commas",
       "$OSD,C returns $C<hdg>P<pitch>R<roll>T<temp>D<depth>*hh", "S",
       Send("OSD,C"), needs=("letter:C",)),
    _c("V-09", "RH-FRM-9", "The link carries 8N1 sentences both ways",
       "sentences sent at the profile's baud are read and answered", "S", Send("OSD,S")),
    # --- §2 acknowledgements -----------------------------------------------------------------
    _c("V-10", "RH-ACK-1", "One ACK of its own type for every command type",
       "each command type, sent where it changes nothing, gets exactly one $ACK of its type", "S",
       Send("OSD,S"), Send("OPOS,{lat},{lon},0,,"), Send("OJW,0", expect="$ACK,7,1,19"),
       Send(OMS, expect="$ACK,9,1,20"), Send("OPK,{lat},{lon},1,{speed}", expect="$ACK,11,1,22"),
       Send(FAR_OMW, expect="$ACK,16,1,36"), Send("OLOGD,1", expect="$ACK,4,1,25"),
       Send("ORWSET,Sle,R"), Send("ODVL,0,0,1"), Send("OMLOAD,helmcheck-missing.mis,0", expect="$ACK,2,1,1"),
       Send("OMSTART,0,0,0,0,helmcheck-missing.mis,", expect="$ACK,3,1,1"), Wait(1.0)),
    _c("V-11", "RH-ACK-2", "ACKs come within the ACK window",
       "every $ACK arrives within ack_window_s plus transmit time of the command's last byte", "N",
       Send("OSD,S"), Send("OPOS,{lat},{lon},0,,"), Send("OSD,G,S")),
    _c("V-12", "RH-ACK-3", "Bad fields are rejected with the command's own error",
       "wrong field count, unparseable or out-of-range values get that command's incorrect-values "
       "error; nothing changes", "N",
       Send("OMS,90,2,20", expect="$ACK,9,1,20"), Send("OMS,400,2,20,{speed},10", expect="$ACK,9,1,20"),
       Send("OMP,8080,00,5", expect="$ACK,10,1,21"), Send("OJW,x", expect="$ACK,7,1,19"),
       Send("OPK,{lat},{lon},0,{speed}", expect="$ACK,11,1,22"), Send("ORWSET", expect="$ACK,12,1,23"),
       Send("OPOS,91,{lon},0,,", expect="$ACK,6,1,18"), Send("ODVL,9,0,5", expect="$ACK,15,1,35"),
       Send("OMW,,{lat},{lon},2,,15,{speed},0,", expect="$ACK,16,1,36"),
       Send("OSD,Q", expect="$ACK,8,1,27"), Send("OMSTOP,1", expect="$ACK,1,1,28"),
       Send("OMLOAD,,0", expect="$ACK,2,1,29"),
       Send("OMSTART,2,0,0,0,{mission},", expect="$ACK,3,1,30"), Poll(mode="N")),
    _c("V-13", "RH-ACK-4", "Commands not allowed in S are rejected",
       "$OMS, $OJW, $OPK, $OMW, $OLOGD without a mission get their incorrect-values error", "S",
       Send(OMS, expect="$ACK,9,1,20"), Send("OJW,1", expect="$ACK,7,1,19"),
       Send("OPK,{lat},{lon},1,{speed}", expect="$ACK,11,1,22"), Send(FAR_OMW, expect="$ACK,16,1,36"),
       Poll(mode="S")),
    _c("V-14", "RH-ACK-4", "Commands allowed only in S are rejected during a mission",
       "$OLOGL, $ORWSET, $OMLOAD, $OMSTART while a mission runs get their incorrect-values error", "N",
       Send("OLOGL,a,b", expect="$ACK,5,1,24"), Send("ORWSET,Sle,R", expect="$ACK,12,1,23"),
       Send("OMLOAD,{mission},0", expect="$ACK,2,1,29"),
       Send("OMSTART,0,0,0,0,{mission},", expect="$ACK,3,1,30"), Poll(mode="N")),
    _c("V-15", "RH-ACK-5", "$OSD data comes before its ACK",
       "every data sentence of an $OSD precedes its $ACK,8", "N", Send("OSD,G,C,S,P,Y,D,T,I")),
    _c("V-16", "RH-ACK-6", "Commands are answered in arrival order",
       "three commands written back to back are acknowledged 8, 6, 7 in that order", "N",
       Burst(("OSD,S", "OPOS,{lat},{lon},0,,", "OJW,0"))),
    # --- §3 output ---------------------------------------------------------------------------
    _c("V-17", "RH-OUT-1", "$OSI has the profile's fields",
       "$OSI has osi_fields fields, upper-case fins/motor hex, a known mode and error state", "N",
       Poll(), Send(OMS), Poll(mode="A")),
    _c("V-18", "RH-OUT-2", "Data sentence formats",
       "each letter the profile serves returns its sentence, in the order requested", "S",
       Send("OSD,I,T,D,Y,P,S,C,G")),
    _c("V-19", "RH-OUT-3", "Numeric fields within physical ranges",
       "headings [0,360), pitch/roll [-90,90], positions, percent, speeds ≥ 0 in every sentence", "N",
       Send("OSD,G,C,S,P,Y,D,T,I"), Wait(20.0)),
    _c("V-20", "RH-OUT-4", "$OSI agrees with the model over time",
       "mode, next waypoint, park time and error state match the model within tolerance", "N",
       Wait(40.0)),
    # --- §4 control and interrupts -----------------------------------------------------------
    _c("V-21", "RH-INT-1", "Each control command ends the active one",
       "A → M → mP → W → A by $OMS/$OMP/$OPK/$OMW; when the last $OMS times out the mission resumes (N), "
       "not an earlier control: there is no stack", "N",
       Send(OMS0), Poll(mode="A"), Send("OMP,8080808080,00,60"), Poll(mode="M"),
       Send("OPK,{lat},{lon},5,{speed}"), Poll(mode="mP"), Send(FAR_OMW), Poll(mode="W"),
       Send(OMS0), Poll(mode="A"), Settle("RH-INT-1", "remote"), Poll(mode="N")),
    _c("V-22", "RH-INT-2", "Control released to the mission (N)",
       "after a servo timeout the vehicle resumes N toward the same next waypoint", "N",
       Send("OJW,1"), Send(OMS), Poll(mode="A", waypoint=1), Settle("RH-INT-2", "remote"),
       Poll(mode="N", waypoint=1)),
    _c("V-23", "RH-INT-2", "Control released to the mission park (P)",
       "a servo control taken during a mission park ends in P with the park time left at takeover",
       "P", Send(OMS), Poll(mode="A"), Wait(5.0), Settle("RH-INT-2", "remote"), Poll(mode="P")),
    _c("V-24", "RH-INT-3", "An interrupted $OPK park is abandoned",
       "$OPK then $OMS: when the servo times out the mission resumes (N), not the park", "N",
       Send("OPK,{lat},{lon},5,{speed}"), Poll(mode="mP"), Send(OMS), Poll(mode="A"),
       Settle("RH-INT-3", "remote"), Poll(mode="N", mode_not="mP")),
    _c("V-25", "RH-SRV-1", "$OMS only while a mission runs",
       "$OMS in S is rejected (20); in N it is accepted", "S",
       Send(OMS, expect="$ACK,9,1,20"), Start(), Send(OMS, expect="$ACK,9,0,0"), Poll(mode="A")),
    _c("V-26", "RH-SRV-2", "$OMS field ranges",
       "heading 360, depth over max, pitch 46, timeout 0, 121 or 1.5 are rejected (20); heading 359.9 "
       "is accepted", "N",
       Send("OMS,360,2,20,{speed},10", expect="$ACK,9,1,20"),
       Send("OMS,90,{depth_over},20,{speed},10", expect="$ACK,9,1,20"),
       Send("OMS,90,2,46,{speed},10", expect="$ACK,9,1,20"),
       Send("OMS,90,2,20,{speed},0", expect="$ACK,9,1,20"),
       Send("OMS,90,2,20,{speed},121", expect="$ACK,9,1,20"),
       Send("OMS,90,2,20,{speed},1.5", expect="$ACK,9,1,20"),
       Send("OMS,90,2,20,{speed_over},10", expect="$ACK,9,1,20"),
       Poll(mode="N"), Send("OMS,359.9,2,20,{speed},10", expect="$ACK,9,0,0"), Poll(mode="A")),
    _c("V-27", "RH-SRV-3", "A new $OMS restarts the servo timeout",
       "mode A after acceptance; an $OMS 6 s into a 10 s timeout keeps A until 16 s", "N",
       Send(OMS), Poll(mode="A"), Wait(6.0), Send(OMS), Wait(6.0), Poll(mode="A"),
       Settle("RH-SRV-3", "remote"), Poll(mode="N")),
    _c("V-28", "RH-SRV-4", "The servo timeout releases control",
       "with no new $OMS the vehicle leaves A when the timeout runs out, within tolerance", "N",
       Send(OMS), Poll(mode="A"), Settle("RH-SRV-4", "remote"), Poll(mode="N")),
    _c("V-29", "RH-PRM-1", "$OMP is accepted from S",
       "$OMP without a mission is accepted and the mode is M", "S",
       Send("OMP,80808080{motor},00,10", expect="$ACK,10,0,0"), Poll(mode="M")),
    _c("V-30", "RH-PRM-2", "$OMP fields",
       "nine hex digits, a non-hex digit, reserved other than 00 and timeout 0 are rejected (21); "
       "lower-case hex is accepted and echoed in upper case", "S",
       Send("OMP,808080808,00,10", expect="$ACK,10,1,21"), Send("OMP,80808080GG,00,10", expect="$ACK,10,1,21"),
       Send("OMP,8080808080,01,10", expect="$ACK,10,1,21"), Send("OMP,8080808080,00,0", expect="$ACK,10,1,21"),
       Poll(mode="S"), Send("OMP,7f7f7f7f80,00,10", expect="$ACK,10,0,0"),
       Poll(mode="M", actuators="7F7F7F7F80")),
    _c("V-31", "RH-PRM-3", "$OSI echoes the commanded fins and motor",
       "after $OMP the mode is M and field 1 is the commanded bytes in upper case", "N",
       Send("OMP,8a8a7676{motor},00,20"), Poll(mode="M", actuators="8A8A7676{motor}")),
    _c("V-32", "RH-PRM-4", "$OMP timeout from S returns to S, neutral",
       "when the primitive times out without a mission the mode is S with 8080808080", "S",
       Send("OMP,8a8a7676{motor},00,10"), Poll(mode="M"), Settle("RH-PRM-4", "remote"),
       Poll(mode="S", actuators="8080808080")),
    _c("V-33", "RH-JW-1", "$OJW preconditions and range",
       "$OJW in S is rejected (19); past the last waypoint is rejected (19); a valid n is accepted",
       "S", Send("OJW,1", expect="$ACK,7,1,19"), Start(), Send("OJW,{wp_bad}", expect="$ACK,7,1,19"),
       Send("OJW,-1", expect="$ACK,7,1,19"), Send("OJW,2", expect="$ACK,7,0,0"), Poll(mode="N", waypoint=2)),
    _c("V-34", "RH-JW-2", "$OJW ends remote control",
       "$OJW from A, M, mP and W gives N with the new next waypoint", "N",
       Send(OMS), Send("OJW,2"), Poll(mode="N", waypoint=2), Send("OMP,8080808080,00,20"),
       Send("OJW,1"), Poll(mode="N", waypoint=1), Send("OPK,{lat},{lon},5,{speed}"), Send("OJW,2"),
       Poll(mode="N", waypoint=2), Send(FAR_OMW), Send("OJW,0"), Poll(mode="N", waypoint=0)),
    _c("V-35", "RH-JW-2", "$OJW ends a mission park",
       "$OJW during the mission park gives N with the new next waypoint", "P",
       Send("OJW,0"), Poll(mode="N", waypoint=0)),
    _c("V-36", "RH-PK-1", "$OPK preconditions and ranges",
       "rejected in S (22), minutes 0 or 1441 (22), farther than 10 miles (40); accepted in N", "S",
       Send("OPK,{lat},{lon},1,{speed}", expect="$ACK,11,1,22"), Start(),
       Send("OPK,{lat},{lon},0,{speed}", expect="$ACK,11,1,22"),
       Send("OPK,{lat},{lon},1441,{speed}", expect="$ACK,11,1,22"),
       Send("OPK,{far_lat},{lon},1,{speed}", expect="$ACK,11,1,40"),
       Send("OPK,{lat},{lon},1,{speed}", expect="$ACK,11,0,0"), Poll(mode="mP")),
    _c("V-37", "RH-PK-2", "$OPK park counts down on station",
       "mode mP; field 10 counts down from minutes×60 once on station (parked where the vehicle is)",
       "N", Send(OMS0), Poll(), Send("OPK,{lat},{lon},2,{speed}"), Poll(mode="mP"),
       Until("the $OPK countdown", mode="mP", park_below=120, budget_v=60.0, clause="RH-PK-2"),
       Wait(10.0), Poll(mode="mP", park_below=115)),
    _c("V-38", "RH-PK-3", "The mission resumes when the park time is up",
       "a 1-minute $OPK park at the vehicle's position ends in N within tolerance", "N",
       Send(OMS0), Poll(), Send("OPK,{lat},{lon},1,{speed}"),
       Until("the $OPK countdown", mode="mP", park_below=60, budget_v=60.0, clause="RH-PK-2"),
       Settle("RH-PK-3", "opk"), Poll(mode="N")),
    _c("V-39", "RH-OMW-1", "$OMW only while a mission runs",
       "$OMW in S is rejected (36); in N it is accepted and the mode is W", "S",
       Send(FAR_OMW, expect="$ACK,16,1,36"), Start(), Send(FAR_OMW, expect="$ACK,16,0,0"), Poll(mode="W")),
    _c("V-40", "RH-OMW-2", "$OMW waypoints queue",
       "two waypoints are queued and the mode stays W", "N",
       Send(FAR_OMW), Send("OMW,{near_lat},{near_lon},2,3,15,{speed},0,"), Poll(mode="W"), Wait(5.0),
       Poll(mode="W")),
    _c("V-41", "RH-OMW-3", "$OMW,Clr and its synonyms",
       "Clr, CLEAR and STOP clear the queue and resume N; in N the keyword changes nothing", "N",
       Send(FAR_OMW), Send("OMW,Clr"), Poll(mode="N"), Send(FAR_OMW), Send("OMW,CLEAR"), Poll(mode="N"),
       Send(FAR_OMW), Send("OMW,STOP"), Poll(mode="N"), Send("OMW,Clr", expect="$ACK,16,0,0"),
       Poll(mode="N")),
    _c("V-42", "RH-OMW-4", "The mission resumes when the queue is done",
       "a queued waypoint at the vehicle's position is reached at once; the mode returns to N", "N",
       Send(OMS0), Poll(), Send("OMW,{lat},{lon},2,,15,{speed},0,"),
       Until("the end of the $OMW queue", mode="N", budget_v=120.0, clause="RH-OMW-4")),
    _c("V-43", "RH-OMW-5", "Another control command interrupts W and clears the queue",
       "$OMS in W gives A; when it times out the mission resumes (N), not W", "N",
       Send(FAR_OMW), Poll(mode="W"), Send(OMS), Poll(mode="A"), Settle("RH-OMW-5", "remote"),
       Poll(mode="N")),
    # --- §5 missions -------------------------------------------------------------------------
    _c("V-44", "RH-MSN-1", "$OMLOAD stays inside the mission directory",
       "the test mission loads; '..', an absolute path and a drive letter are rejected (29); a missing "
       "file is err 1; during a mission $OMLOAD is rejected (29)", "S",
       Send("OMLOAD,{mission},0", expect="$ACK,2,0,0"), Send("OMLOAD,../{mission},0", expect="$ACK,2,1,29"),
       Send("OMLOAD,/etc/passwd,0", expect="$ACK,2,1,29"), Send("OMLOAD,C:\\x.mis,0", expect="$ACK,2,1,29"),
       Send("OMLOAD,sub/../../x.mis,0", expect="$ACK,2,1,29"),
       Send("OMLOAD,helmcheck-missing.mis,0", expect="$ACK,2,1,1"), Start(),
       Send("OMLOAD,{mission},0", expect="$ACK,2,1,29")),
    _c("V-45", "RH-MSN-2", "$OMSTART, paper and rh5 forms",
       "paper form starts the loaded mission (N, waypoint 0); rejected while running (30); a missing "
       "name is err 1; the rh5 form starts by name", "S",
       Send("OMLOAD,{mission},0"), Send("OMSTART,0", expect="$ACK,3,0,0"), Poll(),
       Send("OMSTART,0", expect="$ACK,3,1,30"), Send("OMSTOP,0"),
       Send("OMSTART,0,0,0,0,helmcheck-missing.mis,", expect="$ACK,3,1,1"),
       Send("OMSTART,0,0,0,0,{mission},", expect="$ACK,3,0,0"), Poll()),
    _c("V-46", "RH-MSN-3", "$OMSTOP from any mode",
       "$OMSTOP in N, A and M gives S with neutral fins and motor", "N",
       Send(OMS), Send("OMSTOP,0"), Poll(mode="S", actuators="8080808080"), Start(),
       Send("OMP,8a8a7676{motor},00,30"), Send("OMSTOP,0"), Poll(mode="S", actuators="8080808080")),
    _c("V-47", "RH-MSN-4", "The mission ends at its last waypoint",
       "the profile's end_mission, started by name, ends in S after its last waypoint (and its park), "
       "within twice the time left the vehicle reports (remaining time, distance and speed) + 60 s, "
       "or a cap of 1800 s of vehicle time", "S",
       Start(which="end_mission", clause="RH-MSN-4"), MissionEnd("RH-MSN-4"), needs=("end_mission",)),
    # --- §6 read/write -----------------------------------------------------------------------
    _c("V-48", "RH-POS-1", "$OPOS forms",
       "accepted with empty or given conductivity/temperature and a sixth empty field, in S and N; "
       "latitude 91 is rejected (18)", "S",
       Send("OPOS,{lat},{lon},0.5,,", expect="$ACK,6,0,0"), Send("OPOS,{lat},{lon},0.5,40,15"),
       Send("OPOS,{lat},{lon},0.5,40,15,"), Send("OPOS,91,{lon},0.5,,", expect="$ACK,6,1,18"), Start(),
       Send("OPOS,{lat},{lon},0.5,,", expect="$ACK,6,0,0")),
    _c("V-49", "RH-POS-2", "$OPOS applies position only without a GPS fix",
       "in S at the surface the position is not applied, conductivity/temperature are; after an "
       "ignore-GPS start the position is applied", "S",
       Until("the surface in S", mode="S", surface=True, budget_v=300.0),
       Send("OPOS,{near_lat},{lon},0.5,33.3,12.5"), Poll(lat_near="{lat}"),
       Octd("33.3", "12.5"), Start(ignore_gps=1), Send(OMS0), Poll(),
       Send("OPOS,{near_lat},{lon},0,,"), Poll(lat_near="{near_lat}")),
    _c("V-50", "RH-OSD-1", "$OSD forms and order",
       "positional and free order both work, replies come in request order, a repeated letter is "
       "served twice", "N",
       Send("OSD,G,C,S,P,,,,"), Send("OSD,S,G"), Send("OSD,P,C"), Send("OSD,S,S"), Send("OSD,,,,")),
    _c("V-51", "RH-OSD-2", "Unknown $OSD letters",
       "a letter outside GCSPYDTI rejects the request (27) with no data", "N",
       Send("OSD,S,Q", expect="$ACK,8,1,27"), Send("OSD,s", expect="$ACK,8,1,27"),
       Send("OSD,SG", expect="$ACK,8,1,27")),
    _c("V-52", "RH-LOG-1", "$OLOGL only before a mission",
       "1–12 labels accepted in S; 13 labels rejected (24); rejected during a mission (24)", "S",
       Send("OLOGL,a,b,c", expect="$ACK,5,0,0"), Send("OLOGL,1,2,3,4,5,6,7,8,9,10,11,12,13", expect="$ACK,5,1,24"),
       Start(), Send("OLOGL,a", expect="$ACK,5,1,24")),
    _c("V-53", "RH-LOG-2", "$OLOGD after $OLOGL during a mission",
       "values are accepted up to the number of labels; more values are rejected (25)", "S",
       Send("OLOGL,a,b"), Start(), Send("OLOGD,1,2", expect="$ACK,4,0,0"), Send("OLOGD,1,", expect="$ACK,4,0,0"),
       Send("OLOGD,1,2,3", expect="$ACK,4,1,25")),
    _c("V-54", "RH-SET-1", "$ORWSET only before a mission, with its reply form",
       "a read in S is answered $ACK,12,0,0,<setting>,<n>,<values>; during a mission it is rejected (23)",
       "S", Send("ORWSET,Sle,R", expect="$ACK,12,0,0,Sle,…"), Send("ORWSET,SafetyAction,R"), Start(),
       Send("ORWSET,Sle,R", expect="$ACK,12,1,23")),
    _c("V-55", "RH-SET-2", "$ORWSET write then read",
       "a write is read back exactly; unknown settings are rejected (23); the original is restored", "S",
       SetRoundTrip("Sop"), Send("ORWSET,Bogus,R", expect="$ACK,12,1,23"),
       Send("ORWSET,sle,R", expect="$ACK,12,1,23")),
    _c("V-56", "RH-DVL-1", "$ODVL outside the lockout",
       "accepted in S and N; x out of [-5,5] rejected (35)", "S",
       Send("ODVL,0.5,0,5", expect="$ACK,15,0,0"), Start(), Send("ODVL,0.5,-0.2,5", expect="$ACK,15,0,0"),
       Send("ODVL,9,0,5", expect="$ACK,15,1,35"), Send("ODVL,0,0,0", expect="$ACK,15,1,35")),
    # --- §7 safety -------------------------------------------------------------------------------
    _c("V-57", "RH-SAF-5", "$OXFLT raises a violation at once",
       "no ACK; the next $OSI shows the safety code", "N",
       Fault("Sle"), Poll("RH-SAF-5", error_state="Sle"), needs=("oxflt",)),
    _c("V-58", "RH-SAF-1", "The lockout refuses everything but $OSD for lockout_s",
       "field 8 shows the code; $OMS, $OMSTOP, $ODVL get 26, $OSD is served; the refusal ends after "
       "the lockout within tolerance", "N",
       Fault("Sle"), Poll(error_state="Sle"), Send(OMS, expect="$ACK,9,1,26"),
       Send("OMSTOP,0", expect="$ACK,1,1,26"), Send("ODVL,0,0,5", expect="$ACK,15,1,26"),
       Send("OSD,S,G", "RH-OSD-1"), Settle("RH-SAF-1", "lockout", probe="ORWSET,Sle,R"), needs=("oxflt",)),
    _c("V-59", "RH-SAF-2", "Commands during the lockout have no effect afterwards",
       "an $OMP refused during the lockout does not take effect when it ends", "N",
       Fault("Sop"), Send("OMP,8080808080,00,60", expect="$ACK,10,1,26"),
       Settle("RH-SAF-2", "lockout", probe="ORWSET,Sle,R"), Poll(mode_not="M"), needs=("oxflt",)),
    _c("V-60", "RH-SAF-3", "After the lockout only $OMP is released until the surface",
       "after the lockout, while still under water, $OMS is refused (26) and $OMP is accepted", "N",
       Wait(12.0), Fault("Sed"), Settle("RH-SAF-3", "lockout"), Send(OMS),
       Send("OMP,8080808080,00,5", expect="$ACK,10,0,0"), Poll(mode="M"), needs=("oxflt",)),
    _c("V-61", "RH-SAF-4", "At the surface the SafetyAction runs",
       "with SafetyAction park the vehicle parks at the surface: mode P, P0, the code kept", "N",
       Fault("Sfp"), Settle("RH-SAF-4", "lockout"),
       Until("the surface after the lockout", mode="P", budget_v=600.0, clause="RH-SAF-4"),
       Poll(mode="P", park=0, error_state="Sfp"), needs=("oxflt", "safety_action:park")),
    _c("V-63", "RH-SAF-4", "At the surface SafetyAction srp runs the SRP",
       "with SafetyAction written srp in S and the test mission started with the profile's srp_mission, "
       "a violation ends at the surface in the SRP: mode N, next waypoint 0, $OSI field 17 True, the "
       "code kept (RH-RD-12, RH-RD-13); SafetyAction is written back afterwards", "S",
       WithSetting("SafetyAction", "srp", (
           Start(srp=True, clause="RH-SAF-4"), Fault("Sfp"), Settle("RH-SAF-4", "lockout"),
           Until("the SRP after the surface", mode="N", srp_active=True, budget_v=600.0, clause="RH-SAF-4"),
           Poll("RH-SAF-4", mode="N", error_state="Sfp", srp_active=True))),
       needs=("oxflt", "srp_mission", "srp_field", "cmd:ORWSET")),
    # --- §8 time ---------------------------------------------------------------------------------
    _c("V-62", "RH-TIM-1 RH-TIM-2", "Durations hold at the declared time scale",
       "a 20 s servo timeout and a 10 s primitive timeout end within max(0.5 s, 5 %) plus the "
       "measured slack, at the declared time scale k", "N",
       Send("OMS,90,2,20,{speed},20"), Settle("RH-TIM-1", "remote"), Poll(mode="N"),
       Send("OMP,8080808080,00,10"), Settle("RH-TIM-2", "remote"), Poll(mode="N")),
)


# ============================================================================ selection

def select_cases(patterns: Optional[list[str]], profile: Profile) -> list[Case]:
    """The cases whose clauses match any of the ``--select`` IDs or globs (all when none)."""
    if not patterns:
        return list(CASES)
    out = []
    for c in CASES:
        if any(fnmatchcase(cid, p) for cid in c.clauses for p in patterns):
            out.append(c)
    return out


def unmet_need(case: Case, profile: Profile) -> Optional[str]:
    for need in case.needs:
        kind, _, arg = need.partition(":")
        if kind == "oxflt" and profile.fault_injection != "oxflt":
            return ("the profile declares fault_injection = \"none\": no safety violation can be raised "
                    "on demand (RH-SAF-5), so the lockout is only judged if one happens by itself")
        if kind == "letter" and arg not in profile.osd_letters:
            return f"the profile's osd_letters lack {arg}"
        if kind == "safety_action" and profile.safety_action != arg:
            return f"the profile's safety_action is {profile.safety_action}, this case needs {arg}"
        if kind == "end_mission" and not profile.end_mission:
            return ("the profile names no end_mission (a short mission whose end a run can wait for): "
                    "the test mission is too long to reach its end (RH-MSN-4)")
        if kind == "srp_mission" and not profile.srp_mission:
            return ("the profile names no srp_mission: the srp branch of SafetyAction cannot be "
                    "exercised (RH-SAF-4)")
        if kind == "srp_field" and profile.protocol != "rh5" and profile.osi_fields < 16:
            return f"the profile's $OSI has {profile.osi_fields} fields: none shows whether the SRP runs"
        if kind == "cmd" and arg not in profile.commands:
            return f"the profile does not claim {arg}"
    cmds = {b.body.split(",")[0] for b in case.steps if isinstance(b, Send)}
    missing = [c for c in cmds if c in s.__dict__ and c not in profile.commands and c != "OSD"]
    if missing:
        return f"the profile does not claim {', '.join(sorted(missing))}"
    return None


# ============================================================================ templates

def context(session: Session) -> dict:
    p = session.profile
    lat, lon = session.here()
    bench = p.bench_safety
    speed = Decimal(str(min(2.0, p.max_speed_kn, bench.max_speed_kn if not bench.in_water else 99)))
    motor = min(0x90, p.bench_safety.max_motor_byte if not bench.in_water else 0x90)
    motor = max(0x80, motor)
    nwp = p.mission_waypoints
    base = p.waypoint_base
    return {
        "mission": p.mission, "speed": f"{speed.normalize():f}", "motor": f"{motor:02X}",
        "lat": lat, "lon": lon, "near_lat": f"{float(lat) + 0.001:.6f}",
        "near_lon": f"{float(lon) + 0.001:.6f}", "far_lat": f"{float(lat) + 1.0:.6f}",
        "wp_last": str(nwp - 1 + base), "wp_bad": str(nwp + base),
        "depth_over": f"{p.max_depth + 1:g}", "speed_over": f"{p.max_speed_kn + 0.5:g}",
    }


def _fill(text: str, ctx: dict) -> str:
    return text.format(**ctx) if "{" in text else text


def raw_line(kind: str, body: str, profile: Profile) -> bytes:
    """One negative (or boundary) line derived from ``body`` (module docstring)."""
    good = frame(body)
    if kind == "badck":
        ck = int(checksum_hex(body), 16) ^ 0x5A
        return b"$" + body.encode() + b"*" + f"{ck:02X}".encode() + b"\r\n"
    if kind == "lowerck":
        pad = body
        while body.startswith("OSD") and not any(c in "ABCDEF" for c in checksum_hex(pad)) and len(pad) < 60:
            pad += ","  # $OSD takes empty fields (RH-RD-7): find a checksum with a hex letter
        return frame(pad, lowercase=True)
    if kind == "nock":
        return b"$" + body.encode() + b"\r\n"
    if kind == "shortck":
        return b"$" + body.encode() + b"*" + checksum_hex(body)[:1].encode() + b"\r\n"
    if kind == "twostar":
        b2 = body + "*"
        return b"$" + b2.encode() + b"*" + checksum_hex(b2).encode() + b"\r\n"
    if kind == "unknown":
        return good
    if kind == "lowerid":
        return frame(body.lower())
    if kind in ("exact256", "overlong"):
        want = profile.max_line_bytes + (1 if kind == "overlong" else 0)
        pad = body
        while len(frame(pad)) < want:
            pad += ","
        line = frame(pad)
        if len(line) > want:  # cannot hit the size exactly with commas only (never happens)
            line = line[:want - 2] + b"\r\n"
        return line
    if kind == "noise":
        return b"\x00\xffnoise,junk*7F" + good
    if kind == "torn":
        return b"$" + body.encode() + b"," + frame("OSD,S")
    if kind == "barelf":
        return frame(body, terminator="\n")
    raise ValueError(f"unknown raw line kind {kind!r}")


# ============================================================================ interpreter

def _check_expect(ex, text: str, clause: Optional[str]) -> None:
    """The case's ``expect`` words must agree with the model (else it is a tester fault)."""
    if not text.startswith("$ACK,") or ex.ack is None:
        return
    want = text[5:].split(",")
    model_ack = next((r for r in ex.expected if isinstance(r, s.ACK)), None)
    if model_ack is None:
        return
    got = [str(model_ack.type), str(model_ack.status), str(model_ack.err)]
    if want[:3] != got:
        raise CaseInconclusive(f"tester fault: the case expects $ACK,{','.join(want[:3])} but the model "
                               f"says $ACK,{','.join(got)}", clause)


def _poll_checks(session: Session, st: Poll, ctx: dict, clause: str) -> None:
    o = session.poll(st.clause or clause)
    c = st.clause or clause

    def bad(what: str) -> CaseFail:
        return session.fail(c, f"$OSI {what}")

    if st.mode is not None and o.mode != st.mode:
        raise bad(f"mode is {o.mode}, expected {st.mode}")
    if st.mode_not is not None and o.mode == st.mode_not:
        raise bad(f"mode is {o.mode}, which it must not be")
    if st.waypoint is not None and o.next_waypoint != st.waypoint:
        raise bad(f"next waypoint is {o.next_waypoint}, expected {st.waypoint}")
    if st.actuators is not None and o.actuators != _fill(st.actuators, ctx):
        raise bad(f"fins and motor are {o.actuators}, expected {_fill(st.actuators, ctx)}")
    if st.error_state is not None and o.error_state != st.error_state:
        raise bad(f"error state is {o.error_state}, expected {st.error_state}")
    if st.park is not None and o.park_time != st.park:
        raise bad(f"park time is P{o.park_time}, expected P{st.park}")
    if st.park_below is not None and not o.park_time < st.park_below:
        raise bad(f"park time is P{o.park_time}, expected below P{st.park_below} (counting down)")
    if st.lat_near is not None:
        want = float(_fill(st.lat_near, ctx))
        if abs(float(o.lat) - want) > 0.0004:
            raise bad(f"latitude is {o.lat}, expected about {want:.6f}")
    if st.srp_active is not None:
        flag = srp_flag(o, session.profile)
        if flag is not None and flag != ("True" if st.srp_active else "False"):
            raise bad(f"SRP active (field 17) is {flag}, expected {st.srp_active}")


def srp_flag(o, profile: Profile) -> Optional[str]:
    """The SRP-active field of an ``$OSI``: rh5 field 17, older profiles field 16; ``None`` if absent."""
    return o.srp_active if profile.protocol == "rh5" else o.battery


def _here(session: Session, ctx: dict) -> None:
    """Refresh the position templates from the last ``$OSI``."""
    lat, lon = session.here()
    ctx.update(lat=lat, lon=lon, near_lat=f"{float(lat) + 0.001:.6f}", near_lon=f"{float(lon) + 0.001:.6f}",
               far_lat=f"{float(lat) + 1.0:.6f}")


def run_step(session: Session, st, ctx: dict, clause: str) -> None:
    """Carry out one step of a case (the primary clause is ``clause``)."""
    if isinstance(st, Send):
        ex = session.exchange(frame(_fill(st.body, ctx)), st.clause or clause)
        _check_expect(ex, st.expect, st.clause or clause)
    elif isinstance(st, Raw):
        raw = raw_line(st.kind, _fill(st.body, ctx), session.profile)
        session.exchange(raw, st.clause or clause, variant=True)
    elif isinstance(st, Poll):
        _poll_checks(session, st, ctx, clause)
        _here(session, ctx)
    elif isinstance(st, Wait):
        session.wait(st.vehicle_s, st.clause or clause, frame(_fill(st.probe, ctx)) if st.probe else None)
    elif isinstance(st, Settle):
        session.settle(st.clause, st.timer, frame(_fill(st.probe, ctx)) if st.probe else None)
    elif isinstance(st, Until):
        fix = session.profile.gps_fix_depth_m
        srp = None if st.srp_active is None else ("True" if st.srp_active else "False")

        def pred(o, st=st):
            return ((st.mode is None or o.mode == st.mode)
                    and (st.park_below is None or o.park_time < st.park_below)
                    and (not st.surface or (o.depth is not None and float(o.depth) <= fix))
                    and (srp is None or srp_flag(o, session.profile) == srp))
        session.until(st.what, pred, st.budget_v, st.clause or clause, estimate=st.estimate)
        _here(session, ctx)
    elif isinstance(st, Fault):
        session.exchange(frame(f"OXFLT,{st.code}"), "RH-SAF-5")
    elif isinstance(st, Start):
        _start(session, st, ctx)
    elif isinstance(st, MissionEnd):
        session.mission_end(f"the end of {session.profile.end_mission}", st.clause, st.cap_v, st.wall_s)
        _here(session, ctx)
    elif isinstance(st, WithSetting):
        _with_setting(session, st, ctx, clause)
    elif isinstance(st, Burst):
        session.burst([frame(_fill(b, ctx)) for b in st.bodies], st.clause)
    elif isinstance(st, SetRoundTrip):
        _set_round_trip(session, st)
    elif isinstance(st, Octd):
        if "T" not in session.profile.osd_letters:
            return
        ex = session.exchange(frame("OSD,T"), st.clause)
        octd = next((d for d in ex.data if isinstance(d, s.OCTD)), None)
        if octd is None:
            raise session.fail("RH-OSD-1", "$OSD,T returned no $OCTD")
        if (octd.conductivity != Decimal(st.conductivity) or octd.temperature != Decimal(st.temperature)):
            raise session.fail(st.clause, f"$OCTD shows {octd.conductivity} mS/cm, {octd.temperature} °C; "
                                          f"$OPOS gave {st.conductivity}, {st.temperature} (always applied)")
    else:  # pragma: no cover
        raise TypeError(st)


def _start(session: Session, st: Start, ctx: dict) -> None:
    """``$OMSTART`` by name (rh5 form, RH-MSN-2, RH-RD-6). The test mission must start (else
    FAIL); a mission named by ``end_mission`` or an SRP named by ``srp_mission`` the vehicle does
    not have is the profile's mistake (INCONCLUSIVE, with the vehicle's answer)."""
    p = session.profile
    name = getattr(p, st.which)
    srp = p.srp_mission if st.srp else ""
    plain = st.which == "mission" and not srp
    ex = session.exchange(frame(f"OMSTART,{st.ignore_gps},0,0,0,{name},{srp}"), st.clause, judge=plain)
    if not ex.accepted:
        if plain:
            raise session.fail(st.clause, f"the test mission did not start: {ex.ack}")
        named = f"{st.which} {name!r}" + (f" with srp_mission {srp!r}" if srp else "")
        raise CaseInconclusive(f"the profile's {named} did not start: {_ack(ex.ack)} (is it on the "
                               f"vehicle?)", st.clause)
    session.poll(st.clause)
    _here(session, ctx)


def _with_setting(session: Session, st: WithSetting, ctx: dict, clause: str) -> None:
    """:class:`WithSetting`: RH-SET-1 read and write in ``S``; what was read is always written back."""
    ex = session.exchange(frame(f"ORWSET,{st.setting},R"), st.clause)
    if not ex.accepted:
        raise session.fail(st.clause, f"reading {st.setting} in S was refused: {ex.ack}")
    orig = list(ex.ack.extra[2:])  # type: ignore[union-attr]
    if not orig and st.setting == "SafetyAction":
        orig = ["1", session.profile.safety_action]
    w = session.exchange(frame(f"ORWSET,{st.setting},W,1,{st.value}"), st.clause)
    if not w.accepted:
        raise session.fail(st.clause, f"writing {st.setting} = {st.value} in S was refused: {w.ack}")
    try:
        for sub in st.steps:
            run_step(session, sub, ctx, clause)
    except (CaseFail, CaseInconclusive, CaseNotTested):
        _restore_setting(session, st, orig, quiet=True)
        raise
    _restore_setting(session, st, orig, quiet=False)


def _ack(a) -> str:
    return "no $ACK" if a is None else "$ACK," + ",".join(map(str, (a.type, a.status, a.err, *a.extra)))


def _restore_setting(session: Session, st: WithSetting, orig: list, quiet: bool) -> None:
    """Stop the mission (verified reset) and write ``orig`` back; ``quiet``: a case already ended."""
    if not orig:
        return
    try:
        session.reset(mission=False)
        ex = session.exchange(frame(f"ORWSET,{st.setting},W,{','.join(orig)}"), st.clause, judge=False)
        if not ex.accepted:
            raise CaseInconclusive(f"could not write {st.setting} back to {','.join(orig)}: {_ack(ex.ack)}",
                                   st.clause)
    except (CaseFail, CaseInconclusive):
        if not quiet:
            raise


def _set_round_trip(session: Session, st: SetRoundTrip) -> None:
    """RH-SET-2 (module docstring of :class:`SetRoundTrip`); the original is always restored."""
    ex = session.exchange(frame(f"ORWSET,{st.setting},R"), st.clause)
    if not ex.accepted:
        raise session.fail(st.clause, f"reading {st.setting} was refused: {ex.ack}")
    orig = list(ex.ack.extra[2:])  # type: ignore[union-attr]
    state = orig[0] if orig else "1"
    new_state = "0" if state == "1" else "1"
    new_vals = ["7"]
    try:
        w = session.exchange(frame(f"ORWSET,{st.setting},W,{new_state},{','.join(new_vals)}"), st.clause)
        if not w.accepted:
            raise session.fail(st.clause, f"writing {st.setting} was refused: {w.ack}")
        r = session.exchange(frame(f"ORWSET,{st.setting},R"), st.clause)
        got = list(r.ack.extra[2:]) if r.ack is not None else []
        if got != [new_state, *new_vals]:
            raise session.fail(st.clause, f"wrote {st.setting} state {new_state} value {new_vals[0]}, read back "
                                          f"{','.join(got) or 'nothing'}")
    finally:
        if orig:
            try:
                session.exchange(frame(f"ORWSET,{st.setting},W,{','.join(orig)}"), st.clause, judge=False)
            except CaseFail:
                pass


def run_case(session: Session, case: Case) -> tuple[str, str, Optional[str]]:
    """Run one case: (verdict, reason, clause that failed or None). Link faults propagate."""
    why = unmet_need(case, session.profile)
    if why:
        raise CaseNotTested(why)
    session.reset(mission=case.start in ("N", "P"), park=case.start == "P")
    ctx = context(session)
    for st in case.steps:
        try:
            run_step(session, st, ctx, case.subject)
        except BenchSafetyRefused as e:
            session.book.add(getattr(st, "clause", None) or case.subject, "not-tested",
                             f"part of {case.id} was not sent: {e}", case.id)
    return "pass", f"{case.id}: {case.title.lower()} — as expected", None
