"""The clause cases of ``certify vehicle``: numbered, data only (the vocabulary is :mod:`.steps`).

Every vehicle clause of §1–8 has a case that is about it (its first clause). Each starts from
a verified reset: ``S`` (no mission), ``N`` (the profile's test mission started by name) or
``P`` (that mission in its mission park). Cases are written for *any* test mission §10
allows — a mission park on any early waypoint, including 0; legs of any length; a vehicle that
stays where ``$OMSTOP`` left it — so they name no waypoint positions and no park waypoint
(``{wp_other}`` stands for one that is not the park), and their state conditions ask only for
what the clause needs (a control mode, not a particular next waypoint: the observer judges that).

Designed so a conforming and a faulty vehicle give different observations: whatever is
"restored", "resumed" or "restarted" is observed after part of it has elapsed (a park taken over
after 5 s of it, a servo timeout restarted 6 s in, a setting read back after it was written).
"""

from __future__ import annotations

from fnmatch import fnmatchcase
from typing import Optional

from ...grammar import sentences as s
from ...profile import Profile
from .rulecases import RULE_CASES
from .steps import (Burst, Case, ClearWords, Fault, MissionEnd, Octd, Poll, Raw, Send, SetRoundTrip, Settle, Start,
                    Until, Wait, WithSetting)

__all__ = ["CASES", "select_cases", "unmet_need", "line_needs"]

# Durations are the line budget's (:mod:`.durations`): ``{to}`` a timeout the observer can time on
# this line at this time scale, ``{to_long}`` one that outlasts several steps, and so on.
OMS = "OMS,90,2,20,{speed},{to}"
OMS0 = "OMS,90,2,20,0,{to}"  # speed 0: the vehicle holds its position
OMS_DIVE = "OMS,90,{dive_depth},20,{speed},{to_hi}"  # down to a depth an ascent takes a while to leave
OMP_HOLD = "OMP,8080808080,00,{to_long}"  # neutral: holds depth, outlasts what follows (RH-RD-12)
OMS_RESTART = "OMS,90,2,20,{speed},{to_restart}"  # restarted {gap} into it, both deadlines told apart
FAR_OMW = "OMW,{near_lat},{lon},2,,15,{speed},0,"
HOLD_SURFACE = "OMS,90,0,20,0,{to_long}"  # stays where it is, at the surface, for several steps
#: V-70's controls, each sent again just before its $OPOS so that what follows fits its timeout on a slow line;
#: the state each $OPOS needs is confirmed again right before it (a re-run on a faulty line can outlast the control)
_DIVE_HOLD = "OMS,90,1.5,45,{speed},{to_long}"  # down to 1.5 m and held there
_RISE = "OMS,90,0,45,{speed},{to_long}"  # back up to the surface, under way
OPOS_FAR = "OPOS,{opos_lat},{lon},0,,"  # far enough that the next report tells applied from not (RH-POS-2)
ACCEPTED = {"OMS": "$ACK,9,0,0", "OMP": "$ACK,10,0,0", "OPK": "$ACK,11,0,0", "OMW": "$ACK,16,0,0",
            "OPOS": "$ACK,6,0,0", "ODVL": "$ACK,15,0,0", "OMSTART": "$ACK,3,0,0", "ORWSET": "$ACK,12,0,0",
            "OLOGL": "$ACK,5,0,0", "OLOGD": "$ACK,4,0,0", "OJW": "$ACK,7,0,0"}
REFUSED = {"OMS": "$ACK,9,1,20", "OMP": "$ACK,10,1,21", "OPK": "$ACK,11,1,22", "OMW": "$ACK,16,1,36",
           "OPOS": "$ACK,6,1,18", "ODVL": "$ACK,15,1,35", "OMSTART": "$ACK,3,1,30", "ORWSET": "$ACK,12,1,23",
           "OLOGL": "$ACK,5,1,24", "OLOGD": "$ACK,4,1,25", "OJW": "$ACK,7,1,19", "OMLOAD": "$ACK,2,1,29"}


def _ok(*bodies: str) -> tuple:
    """Sends a conforming vehicle accepts."""
    return tuple(Send(b, expect=ACCEPTED[b.split(",")[0]]) for b in bodies)


def _off(base: str, *changes: tuple) -> tuple:
    """Sends of ``base`` with one field at a time (1 = the first after the ID) set to a value just
    past its bound: each refused with the command's own error (RH-ACK-3)."""
    out = []
    for i, value in changes:
        f = base.split(",")
        f[i] = value
        out.append(Send(",".join(f), expect=REFUSED[f[0]]))
    return tuple(out)


def _no(*bodies: str) -> tuple:
    """Sends a conforming vehicle refuses with the command's own error."""
    return tuple(Send(b, expect=REFUSED[b.split(",")[0]]) for b in bodies)


def _c(id_, clauses, title, expectation, start, *steps, needs=()):
    return Case(id_, tuple(clauses.split()), title, expectation, start, tuple(steps), tuple(needs))


CASES: tuple[Case, ...] = (
    # --- §1 framing -----------------------------------------------------------------------
    _c("V-01", "RH-FRM-1", "A well-formed sentence is answered",
       "$OSD in positional and letter form each get their data and $ACK,8; every vehicle line is "
       "$ID,fields*hh CR LF", "S",
       Send("OSD,G,C,S,P,,,,", expect="data, then $ACK,8,0,0"), Send("OSD,S"), Poll()),
    _c("V-02", "RH-FRM-2", "A checksum under 0x10 is written and read zero-padded",
       "a request whose checksum is 0X is answered with its data and $ACK,8; every checksum the "
       "vehicle writes is the XOR of the bytes between $ and *, two upper-case hex digits", "N",
       Raw("zerock", "OSD,S"), Poll()),
    _c("V-03", "RH-FRM-3", "Lower-case checksum hex is accepted",
       "a command with lower-case hex is answered as with upper case; vehicle output uses upper case",
       "N", Raw("lowerck", "OSD,S"), Raw("lowerck", "OJW,{wp_other}"), Poll()),
    _c("V-04", "RH-FRM-4", "A missing, malformed or wrong checksum is discarded",
       "no ACK for a line with a wrong checksum, without *hh, with one hex digit or with two '*'; "
       "the next $OSD is answered; no state change (the mode stays N)", "N",
       Raw("badck", "OMSTOP,0"), Raw("badck", OMS0), Raw("nock", "OMSTOP,0"), Raw("shortck", "OMSTOP,0"),
       Raw("twostar", "OMSTOP,0"), Poll(mode="N|P")),
    _c("V-05", "RH-FRM-5", "An unknown ID is discarded",
       "no ACK for $OXYZ or a lower-case $omstop; no state change", "N",
       Raw("unknown", "OXYZ,1"), Raw("lowerid", "OMSTOP,0"), Poll(mode="N|P")),
    _c("V-06", "RH-FRM-6", "256 bytes is the line limit",
       "a valid 256-byte line is answered; a 257-byte line is discarded and the receiver resyncs at "
       "the next $", "N",
       Raw("exact256", "OSD,S"), Raw("overlong", "OSD,S"), Raw("overlong", "OMSTOP,0"), Poll(mode="N|P")),
    _c("V-07", "RH-FRM-7", "Noise, torn lines and bare LF",
       "noise before $ is skipped; a sentence cut by the next $ is never merged or executed; a bare LF "
       "ends a line", "N",
       Raw("noise", "OSD,S"), Raw("torn", "OMSTOP,0"), Raw("barelf", "OSD,S"), Poll(mode="N|P")),
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
       Send("OMSTART,2,0,0,0,{mission},", expect="$ACK,3,1,30"), Poll(mode="N|P")),
    _c("V-13", "RH-ACK-4", "Commands not allowed in S are rejected",
       "$OMS, $OJW, $OPK, $OMW without a mission get their incorrect-values error", "S",
       Send(OMS, expect="$ACK,9,1,20"), Send("OJW,0", expect="$ACK,7,1,19"),
       Send("OPK,{lat},{lon},1,{speed}", expect="$ACK,11,1,22"), Send(FAR_OMW, expect="$ACK,16,1,36"),
       Poll(mode="S")),
    _c("V-14", "RH-ACK-4", "Commands allowed only in S are rejected during a mission",
       "$OLOGL, $ORWSET, $OMLOAD, $OMSTART while a mission runs get their incorrect-values error", "N",
       Send("OLOGL,a,b", expect="$ACK,5,1,24"), Send("ORWSET,Sle,R", expect="$ACK,12,1,23"),
       Send("OMLOAD,{mission},0", expect="$ACK,2,1,29"),
       Send("OMSTART,0,0,0,0,{mission},", expect="$ACK,3,1,30"), Poll(mode="N|P")),
    _c("V-15", "RH-ACK-5", "$OSD data comes before its ACK",
       "every data sentence of an $OSD precedes its $ACK,8", "N", Send("OSD,G,C,S,P,Y,D,T,I")),
    _c("V-16", "RH-ACK-6", "Commands are answered in arrival order",
       "three commands written back to back are acknowledged 8, 6, 7 in that order", "N",
       Burst(("OSD,S", "OPOS,{lat},{lon},0,,", "OJW,{wp_other}"))),
    # --- §3 output ---------------------------------------------------------------------------
    _c("V-17", "RH-OUT-1", "$OSI has the profile's fields",
       "$OSI has osi_fields fields, upper-case fins/motor hex, a known mode and error state", "N",
       Poll(), Send(OMS), Poll(mode="A")),
    _c("V-18", "RH-OUT-2", "Data sentence formats",
       "each letter the profile serves returns its sentence, in the order requested", "S",
       Send("OSD,I,T,D,Y,P,S,C,G")),
    _c("V-19", "RH-OUT-3", "Numeric fields within physical ranges",
       "headings [0,360), pitch/roll [-90,90], positions, percent, speeds ≥ 0 in every sentence, "
       "at the start and again under way 20 s later", "N",
       Send("OSD,G,C,S,P,Y,D,T,I"), Wait(20.0), Send("OSD,G,C,S,P,Y,D,T,I")),
    _c("V-20", "RH-OUT-4", "$OSI agrees with the model over time",
       "mode, next waypoint, park time and error state match the model within tolerance", "N",
       Wait(40.0)),
    # --- §4 control and interrupts -----------------------------------------------------------
    _c("V-21", "RH-INT-1", "Each control command ends the active one",
       "A → M → mP → W → A by $OMS/$OMP/$OPK/$OMW; when the last $OMS times out the mission resumes, "
       "not an earlier control: there is no stack", "N",
       Send(OMS0), Poll(mode="A"), Send("OMP,8080808080,00,{to_long}"), Poll(mode="M"),
       Send("OPK,{lat},{lon},5,{speed}"), Poll(mode="mP"), Send(FAR_OMW), Poll(mode="W"),
       Send(OMS0), Poll(mode="A"), Settle("remote"), Poll(mode="N|P")),
    _c("V-22", "RH-INT-2", "Control released to the mission",
       "after a servo timeout the vehicle resumes the mission behaviour it had at takeover: toward the "
       "same next waypoint, whose distance a report showed before the takeover", "N",
       Send("OJW,{wp_other}"), Poll(mode="N"), Send(OMS), Poll(mode="A"), Settle("remote"), Poll(mode="N|P")),
    _c("V-23", "RH-INT-2", "Control released to the mission park (P)",
       "a servo control taken 5 s into a mission park ends in P with the park time left at takeover",
       "P", Wait(5.0), Send(OMS), Poll(mode="A"), Settle("remote"), Poll(mode="P")),
    _c("V-24", "RH-INT-3", "An interrupted $OPK park is abandoned",
       "$OPK then $OMS: when the servo times out the mission resumes, not the park", "N",
       Send("OPK,{lat},{lon},5,{speed}"), Poll(mode="mP"), Send(OMS), Poll(mode="A"),
       Settle("remote"), Poll(mode="N|P")),
    _c("V-25", "RH-SRV-1", "$OMS only while a mission runs",
       "$OMS in S is rejected (20); in N it is accepted", "S",
       Send(OMS, expect="$ACK,9,1,20"), Start(), Send(OMS, expect="$ACK,9,0,0"), Poll(mode="A")),
    _c("V-26", "RH-SRV-2", "$OMS field ranges",
       "heading 360, depth over max, pitch 46, timeout 0, 121 or 1.5, speed over max are rejected (20); "
       "heading 359.9 is accepted", "N",
       Send("OMS,360,2,20,{speed},10", expect="$ACK,9,1,20"),
       Send("OMS,90,{depth_over},20,{speed},10", expect="$ACK,9,1,20"),
       Send("OMS,90,2,46,{speed},10", expect="$ACK,9,1,20"),
       Send("OMS,90,2,20,{speed},0", expect="$ACK,9,1,20"),
       Send("OMS,90,2,20,{speed},121", expect="$ACK,9,1,20"),
       Send("OMS,90,2,20,{speed},1.5", expect="$ACK,9,1,20"),
       Send("OMS,90,2,20,{speed_over},10", expect="$ACK,9,1,20"),
       Poll(mode="N|P"), Send("OMS,359.9,2,20,{speed},{to}", expect="$ACK,9,0,0"), Poll(mode="A")),
    _c("V-27", "RH-SRV-3", "A new $OMS restarts the servo timeout",
       "mode A after acceptance; an $OMS sent well into the timeout keeps A until the restarted timeout "
       "ends, past the first one's end (both told apart on this line: a gap of their tolerances, the "
       "observer's uncertainty and a report between them)", "N",
       Send(OMS_RESTART), Poll(mode="A"), Wait("{gap}"), Send(OMS_RESTART), Poll(mode="A"),
       Settle("remote"), Poll(mode="N|P")),
    _c("V-28", "RH-SRV-4", "The servo timeout releases control",
       "with no new $OMS the vehicle leaves A when the timeout runs out, within tolerance", "N",
       Send(OMS), Poll(mode="A"), Settle("remote"), Poll(mode="N|P")),
    _c("V-29", "RH-PRM-1", "$OMP is accepted from S",
       "$OMP without a mission is accepted and the mode is M", "S",
       Send("OMP,80808080{motor},00,{to}", expect="$ACK,10,0,0"), Poll(mode="M")),
    _c("V-30", "RH-PRM-2", "$OMP fields",
       "nine hex digits, a non-hex digit, reserved other than 00 and timeout 0 are rejected (21); "
       "lower-case hex is accepted and echoed in upper case", "S",
       Send("OMP,808080808,00,10", expect="$ACK,10,1,21"), Send("OMP,80808080GG,00,10", expect="$ACK,10,1,21"),
       Send("OMP,8080808080,01,10", expect="$ACK,10,1,21"), Send("OMP,8080808080,00,0", expect="$ACK,10,1,21"),
       Poll(mode="S"), Send("OMP,7f7f7f7f80,00,{to}", expect="$ACK,10,0,0"), Poll(mode="M")),
    _c("V-31", "RH-PRM-3", "$OSI echoes the commanded fins and motor",
       "after $OMP the mode is M and field 1 is the commanded bytes in upper case", "N",
       Send("OMP,8a8a7676{motor},00,{to}"), Poll(mode="M")),
    _c("V-32", "RH-PRM-4", "$OMP timeout from S returns to S, neutral",
       "when the primitive times out without a mission the mode is S with 8080808080", "S",
       Send("OMP,8a8a7676{motor},00,{to}"), Poll(mode="M"), Settle("remote"), Poll(mode="S")),
    _c("V-33", "RH-JW-1", "$OJW preconditions and range",
       "$OJW in S is rejected (19); past the last waypoint and below the first are rejected (19); "
       "the last waypoint is accepted", "S",
       Send("OJW,0", expect="$ACK,7,1,19"), Start(), Send("OJW,{wp_bad}", expect="$ACK,7,1,19"),
       Send("OJW,-1", expect="$ACK,7,1,19"), Send("OJW,{wp_last}", expect="$ACK,7,0,0"), Poll()),
    _c("V-34", "RH-JW-2", "$OJW ends remote control",
       "$OJW from A, M, mP and W gives the mission toward the new next waypoint", "N",
       Send(OMS), Send("OJW,{wp_other}"), Poll(mode_not="A"), Send("OMP,8080808080,00,{to}"),
       Send("OJW,{wp_first}"), Poll(mode_not="M"), Send("OPK,{lat},{lon},5,{speed}"), Send("OJW,{wp_other}"),
       Poll(mode_not="mP"), Send(FAR_OMW), Send("OJW,{wp_first}"), Poll(mode_not="W")),
    _c("V-35", "RH-JW-2", "$OJW ends a mission park",
       "$OJW during the mission park gives the mission toward the new next waypoint", "P",
       Send("OJW,{wp_other}"), Poll()),
    _c("V-36", "RH-PK-1", "$OPK preconditions and ranges",
       "rejected in S (22), minutes 0 or 1441 (22), farther than 10 miles (40); accepted in N", "S",
       Send("OPK,{lat},{lon},1,{speed}", expect="$ACK,11,1,22"), Start(),
       Send("OPK,{lat},{lon},0,{speed}", expect="$ACK,11,1,22"),
       Send("OPK,{lat},{lon},1441,{speed}", expect="$ACK,11,1,22"),
       Send("OPK,{far_lat},{lon},1,{speed}", expect="$ACK,11,1,40"),
       Send("OPK,{lat},{lon},1,{speed}", expect="$ACK,11,0,0"), Poll(mode="mP")),
    _c("V-37", "RH-PK-2", "$OPK park counts down on station",
       "mode mP; field 10 counts down from minutes×60 once on station (parked where the vehicle is)",
       "N", Send(OMS0), Poll(), Send("OPK,{lat},{lon},{opk_long},{speed}"), Poll(mode="mP"),
       Until("the $OPK countdown", mode="mP", park_below="{opk_long_s}", budget_v=60.0),
       Wait(10.0), Poll(mode="mP", park_below="{opk_long_below}")),
    _c("V-64", "RH-PK-2", "$OPK counts only once on station",
       "an $OPK 15 m away: mode mP at once, field 10 stays at minutes×60 while field 7 shows more than "
       "3 m, then counts down once on station (RH-RD-5)", "N",
       Send(OMS0), Poll(), Send("OPK,{stn_lat},{lon},2,{speed}"), Poll(mode="mP"),
       Until("the $OPK countdown", mode="mP", park_below=120, budget_v=400.0), Poll(mode="mP")),
    _c("V-38", "RH-PK-3", "The mission resumes when the park time is up",
       "an $OPK park at the vehicle's position (1 minute, or the shortest the observer can time on this "
       "line) ends in the mission within tolerance", "N",
       Send(OMS0), Poll(), Send("OPK,{lat},{lon},{opk_min},{speed}"),
       Until("the $OPK countdown", mode="mP", park_below="{opk_s}", budget_v=60.0),
       Settle("opk"), Poll(mode="N|P")),
    _c("V-39", "RH-OMW-1", "$OMW only while a mission runs",
       "$OMW in S is rejected (36); in N it is accepted and the mode is W", "S",
       Send(FAR_OMW, expect="$ACK,16,1,36"), Start(), Send(FAR_OMW, expect="$ACK,16,0,0"), Poll(mode="W")),
    _c("V-40", "RH-OMW-2", "$OMW waypoints queue",
       "two waypoints are queued and the mode stays W", "N",
       Send(FAR_OMW), Send("OMW,{near_lat},{near_lon},2,3,15,{speed},0,"), Poll(mode="W"), Wait(5.0),
       Poll(mode="W")),
    _c("V-41", "RH-OMW-3", "$OMW,Clr and its synonyms",
       "Clr, CLEAR and STOP (the profile's omw_clear_keywords) clear the queue and resume the mission; in N "
       "the keyword changes nothing",
       "N",
       Send(FAR_OMW), Send("OMW,{kw_a}"), Poll(mode="N|P"), Send(FAR_OMW), Send("OMW,{kw_b}"), Poll(mode="N|P"),
       Send(FAR_OMW), Send("OMW,{kw_c}"), Poll(mode="N|P"), Send("OMW,{kw_a}", expect="$ACK,16,0,0"),
       Poll(mode="N|P")),
    _c("V-42", "RH-OMW-4", "The mission resumes when the queue is done",
       "a queued waypoint at the vehicle's position is reached at once; the mission resumes", "N",
       Send(OMS0), Poll(), Send("OMW,{lat},{lon},2,,15,{speed},0,"),
       Until("the end of the $OMW queue", mode="N|P", budget_v=120.0)),
    _c("V-43", "RH-OMW-5", "Another control command interrupts W and clears the queue",
       "$OMS in W gives A; when it times out the mission resumes, not W", "N",
       Send(FAR_OMW), Poll(mode="W"), Send(OMS), Poll(mode="A"), Settle("remote"), Poll(mode="N|P")),
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
       Send(OMS), Send("OMSTOP,0"), Poll(mode="S"), Start(),
       Send("OMP,8a8a7676{motor},00,{to}"), Send("OMSTOP,0"), Poll(mode="S")),
    _c("V-47", "RH-MSN-4", "The mission ends at its last waypoint",
       "the profile's end_mission (without one: the test mission, when the vehicle reports it short enough "
       "to wait for), started by name, ends in S after its last waypoint (and its park)",
       "S", Start(which="end_mission"), MissionEnd(), needs=("end_mission",)),
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
       Send("OPOS,{opos_lat},{lon},0.5,33.3,12.5"), Poll(), Octd(), Start(ignore_gps=1), Send(OMS0), Poll(),
       Send("OPOS,{opos_lat},{lon},0,,"), Poll()),
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
       Send("ORWSET,sle,R", expect="$ACK,12,1,23"), needs=("cmd:ORWSET",)),
    _c("V-56", "RH-DVL-1", "$ODVL outside the lockout",
       "accepted in S and N; x out of [-5,5] rejected (35)", "S",
       Send("ODVL,0.5,0,5", expect="$ACK,15,0,0"), Start(), Send("ODVL,0.5,-0.2,5", expect="$ACK,15,0,0"),
       Send("ODVL,9,0,5", expect="$ACK,15,1,35"), Send("ODVL,0,0,0", expect="$ACK,15,1,35")),
    # --- §7 safety -------------------------------------------------------------------------------
    _c("V-57", "RH-SAF-5", "A violation raised by the vehicle shows in field 8",
       "the profile's violation trigger raises one: $OXFLT gets no ACK and the next $OSI shows the "
       "code; the vehicle's own rule (or a sensor an operator trips) shows its code in field 8", "N",
       Fault("Sle"), Poll(), needs=("violation",)),
    _c("V-58", "RH-SAF-1", "The lockout refuses everything but $OSD for lockout_s",
       "field 8 shows the code; $OMS, $OMSTOP, $ODVL get 26, $OSD is served (written in one burst right "
       "after the violation, so they arrive inside the lockout on any line); the refusal ends after the "
       "lockout within tolerance", "N",
       Fault("Sle", then=("OSD,S", OMS, "OMSTOP,0", "ODVL,0,0,5", "OSD,S,G")),
       Settle("lockout", probe="ORWSET,Sle,R"), needs=("violation", "lockout")),
    _c("V-59", "RH-SAF-2", "Commands during the lockout have no effect afterwards",
       "an $OMP refused during the lockout does not take effect when it ends", "N",
       Fault("Sop", then=("OMP,8080808080,00,{to_long}",)),
       Settle("lockout", probe="ORWSET,Sle,R"), Poll(mode_not="M"), needs=("violation", "lockout")),
    _c("V-60", "RH-SAF-3", "After the lockout only $OMP is released until the surface",
       "brought under water by a servo dive first; the lockout's end is found with an $OMP (refused "
       "only by the lockout: the first one accepted after it holds the depth, RH-RD-12), then, still "
       "under water, $OMS is refused (26)", "N",
       Send(OMS_DIVE), Until("under water", mode="A", submerged=True, depth_at_least="{dive_at}", budget_v=300.0,
                             refresh=OMS_DIVE),
       Fault("Sed"), Settle("lockout", probe=OMP_HOLD), Poll(mode="M", submerged=True),
       Send(OMS, expect="$ACK,9,1,26"), Poll(mode="M"), needs=("violation", "ascent")),
    _c("V-61", "RH-SAF-4", "At the surface the SafetyAction runs",
       "with SafetyAction park the vehicle parks at the surface: mode P, P0, the code kept", "N",
       Fault("Sfp"), Settle("lockout"),
       Until("the surface after the lockout", mode="P", budget_v=600.0),
       Poll(mode="P"), needs=("violation", "safety_action:park")),
    _c("V-63", "RH-SAF-4", "At the surface SafetyAction srp runs the SRP",
       "with SafetyAction written srp in S and the test mission started with the profile's srp_mission, "
       "a violation ends at the surface in the SRP: mode N, next waypoint 0, $OSI field 17 True, the "
       "code kept (RH-RD-12, RH-RD-13); SafetyAction is written back afterwards", "S",
       WithSetting("SafetyAction", "srp", (
           Start(srp=True), Fault("Sfp"), Settle("lockout"),
           Until("the SRP after the surface", mode="N", srp_active=True, budget_v=600.0), Poll(mode="N"))),
       needs=("violation", "srp_mission", "srp_field", "cmd:ORWSET")),
    # --- range edges (§4–8b): both sides of every bound, :mod:`.edges` --------------------------
    _c("V-65", "RH-SRV-2", "$OMS at each edge of its ranges",
       "heading 0 and 359.9, depth 0 and max_depth, pitch 0 and 45, speed 0 and max_speed_kn, the timeout "
       "range's ends are accepted (its lowest with a second $OMS in the same write, which restarts it, "
       "RH-RD-3); 0.1 (or 1) past each is refused (20), every other field inside", "N",
       *_ok("OMS,359.9,{depth_max},45,{speed},{to_hi}", "OMS,90,2,20,{speed_max},{to}"),
       *_off("OMS,90,2,20,{speed},{to}", (1, "-0.1"), (1, "360"), (2, "-0.1"), (2, "{depth_out}"), (3, "-0.1"),
             (3, "45.1"), (4, "-0.1"), (4, "{speed_out}"), (5, "{to_under}"), (5, "{to_over}")),
       Burst(("OMS,0,0,0,0,{to_lo}", OMS0), expect=("$ACK,9,0,0", "$ACK,9,0,0")), Poll(mode="A")),
    _c("V-66", "RH-PRM-2", "$OMP at each edge of its fields",
       "lower-case hex and the timeout range's ends are accepted (the lowest with a second $OMP in the same "
       "write); nine and eleven hex digits, reserved 01 and one past each timeout end are refused (21)", "S",
       *_ok("OMP,7f7f808080,00,{to_hi}"),
       *_off("OMP,8080808080,00,{to}", (3, "{to_under}"), (3, "{to_over}"), (2, "01"), (1, "808080808"),
             (1, "80808080800")),
       Burst(("OMP,8080808080,00,{to_lo}", "OMP,8080808080,00,{to}"), expect=("$ACK,10,0,0", "$ACK,10,0,0")),
       Poll(mode="M")),
    _c("V-67", "RH-PK-1 RH-RD-9", "$OPK just inside and just outside 10 miles, and at each edge of its ranges",
       "after an ignore-GPS start (no fix, RH-RD-10) an $OPOS puts the vehicle where it reported itself; "
       "an $OPK 0.5 % beyond opk_max_distance_m from there is refused (40), one 0.5 % inside it accepted "
       "(mP; the park is too far to start counting); minutes 1 and 1440 and speed 0 and max_speed_kn are "
       "accepted; a latitude ±90 or longitude ±180 is in range (refused for the distance, 40); 0.1 (or 1) "
       "past each bound is refused (22)", "S",
       Start(ignore_gps=1), *_ok(HOLD_SURFACE), Poll(mode="A"), *_ok("OPOS,{lat},{lon},0,,"),
       Send("OPK,{opk_out_lat},{lon},{opk_min},{speed}", expect="$ACK,11,1,40"),
       *_ok("OPK,{opk_in_lat},{lon},1,0"), Poll(mode="mP"),
       *_ok("OPK,{opk_in_lat},{lon},1440,{speed}", "OPK,{opk_in_lat},{lon},{opk_min},{speed_max}"),
       *(Send(b, expect="$ACK,11,1,40") for b in ("OPK,90,{lon},{opk_min},{speed}", "OPK,-90,{lon},{opk_min},{speed}",
                                                   "OPK,{lat},180,{opk_min},{speed}", "OPK,{lat},-180,{opk_min},{speed}")),
       *_off("OPK,{opk_in_lat},{lon},{opk_min},{speed}", (1, "90.1"), (1, "-90.1"), (2, "180.1"), (2, "-180.1"),
             (3, "0"), (3, "1441"), (4, "-0.1"), (4, "{speed_out}")),
       Poll(mode="mP")),
    _c("V-68", "RH-ACK-3 RH-RD-9", "$OMW at each edge of its ranges",
       "waypoints at latitude ±90, longitude ±180, depths ±100, pitch 0 and 45, speed 0 and max_speed_kn, "
       "park 0 and 86400 s are queued (W); 0.1 (or 1) past each bound is refused (36); Clr ends the queue",
       "N",
       *_ok("OMW,90,180,100,100,45,{speed},86400,", "OMW,-90,-180,-100,-100,0,0,0,",
            "OMW,{near_lat},{lon},2,,15,{speed_max},0,"),
       *_off("OMW,{near_lat},{lon},2,,15,{speed},0,", (1, "90.1"), (1, "-90.1"), (2, "180.1"), (2, "-180.1"),
             (3, "100.1"), (3, "-100.1"), (4, "100.1"), (4, "-100.1"), (5, "-0.1"), (5, "45.1"), (6, "-0.1"),
             (6, "{speed_out}"), (7, "-1"), (7, "86401")),
       Poll(mode="W"), *_ok("OMW,{kw_a}"), Poll(mode="N|P")),
    _c("V-69", "RH-OMW-3 RH-RD-4", "$OMW keywords in any case",
       "each keyword of omw_clear_keywords in lower, upper and title case (clr, Clear, stop …) clears a "
       "queued waypoint and resumes the mission; a word beside them (CLEARS) is refused (36)", "N",
       ClearWords(FAR_OMW)),
    _c("V-70", "RH-POS-2 RH-RD-10", "$OPOS on each side of the GPS fix",
       "an $OPOS is applied at the surface in a mission started with ignore-GPS; once that mission is "
       "stopped, at the surface in S, it is not; in a mission started normally it is applied under water "
       "and not at the surface (each judged by the next report, the depth held steady around it)", "S",
       Until("the surface in S", mode="S", surface=True, budget_v=300.0),
       Start(ignore_gps=1), *_ok(HOLD_SURFACE),
       Until("the surface in A", mode="A", surface=True, budget_v=300.0, refresh=HOLD_SURFACE),
       *_ok(HOLD_SURFACE), Wait(2.0),
       Until("the surface in A", mode="A", surface=True, budget_v=300.0, refresh=HOLD_SURFACE, after_reruns=True),
       *_ok(OPOS_FAR), Poll(mode="A"),
       Send("OMSTOP,0"), Until("the surface in S", mode="S", surface=True, budget_v=300.0), Wait(2.0),
       *_ok(OPOS_FAR), Poll(mode="S"),
       Start(), *_ok(_DIVE_HOLD),
       Until("under water", mode="A", submerged=True, depth_at_least=1.4, budget_v=300.0, refresh=_DIVE_HOLD),
       *_ok(_DIVE_HOLD), Wait(2.0),
       Until("under water", mode="A", submerged=True, depth_at_least=1.4, budget_v=300.0, refresh=_DIVE_HOLD, after_reruns=True),
       *_ok(OPOS_FAR), Poll(mode="A"),
       *_ok(_RISE), Until("the surface in A", mode="A", surface=True, budget_v=300.0, refresh=_RISE),
       *_ok(_RISE), Wait(2.0),
       Until("the surface in A", mode="A", surface=True, budget_v=300.0, refresh=_RISE, after_reruns=True),
       *_ok(OPOS_FAR), Poll(mode="A")),
    _c("V-71", "RH-POS-1 RH-DVL-1 RH-RD-9", "$OPOS and $ODVL at each edge of their ranges",
       "at the surface in S (a fix: the position is not applied): latitude ±90, longitude ±180, speed 0 and "
       "max_speed_kn, conductivity 0 and 100, temperature -5 and 50 are accepted, 0.1 past each refused "
       "(18); $ODVL x and y ±5 and the timeout range's ends accepted, one step past each refused (35)", "S",
       Until("the surface in S", mode="S", surface=True, budget_v=300.0),
       *_ok("OPOS,90,180,{speed_max},100,50", "OPOS,-90,-180,0,0,-5"),
       *_off("OPOS,{lat},{lon},0,35,12", (1, "90.1"), (1, "-90.1"), (2, "180.1"), (2, "-180.1"), (3, "-0.1"),
             (3, "{speed_out}"), (4, "-0.1"), (4, "100.1"), (5, "-5.1"), (5, "50.1")),
       *_ok("OPOS,{lat},{lon},0,35,12", "ODVL,5,-5,{to_lo}", "ODVL,-5,5,{to_hi}"),
       *_off("ODVL,0.5,0,{to}", (1, "5.1"), (1, "-5.1"), (2, "5.1"), (2, "-5.1"), (3, "{to_under}"), (3, "{to_over}")),
       Poll(mode="S")),
    _c("V-72", "RH-MSN-2 RH-RD-6", "$OMSTART at each edge of its fields",
       "each rh5 flag 1 and an SRP inside the mission directory start the mission, each paper-form flag "
       "1–3 starts the loaded one ($OMSTOP after each); a flag 2, paper flag 4, and a name or SRP name that "
       "is empty, absolute, with a drive letter or a '..' component are refused (30)", "S",
       *(st for body in ("OMSTART,0,1,0,0,{mission},", "OMSTART,0,0,1,0,{mission},", "OMSTART,0,0,0,1,{mission},",
                         "OMSTART,0,0,0,0,{mission},{mission}")
         for st in (*_ok(body), Send("OMSTOP,0"))),
       *(st for flag in ("1", "2", "3") for st in (Send("OMLOAD,{mission},0", expect="$ACK,2,0,0"),
                                                    *_ok(f"OMSTART,{flag}"), Send("OMSTOP,0"))),
       *_off("OMSTART,0,0,0,0,{mission},", (1, "2"), (2, "2"), (3, "2"), (4, "2"), (5, ""), (5, "/{mission}"),
             (5, "C:{mission}"), (5, "sub/../../{mission}")),
       *_off("OMSTART,0,0,0,0,{mission},{mission}", (6, "/{mission}"), (6, "C:{mission}"),
             (6, "sub/../../{mission}")),
       *_no("OMSTART,4", "OMLOAD,,0"), Poll(mode="S")),
    _c("V-73", "RH-SET-2 RH-RD-8", "$ORWSET writes at each edge",
       "a write of state 0 with no value and of state 1 with three values is accepted, four values or "
       "state 2 refused (23); SafetyAction takes srp and park, not Park or dive (23); each setting is "
       "written back as it was found", "S",
       WithSetting("Sle", "1", (*_ok("ORWSET,Sle,W,0", "ORWSET,Sle,W,1,1,2,3"),
                                *_no("ORWSET,Sle,W,1,1,2,3,4", "ORWSET,Sle,W,2,1"))),
       WithSetting("SafetyAction", "srp", (*_ok("ORWSET,SafetyAction,W,1,park"),
                                           *_no("ORWSET,SafetyAction,W,1,Park", "ORWSET,SafetyAction,W,1,dive"))),
       needs=("cmd:ORWSET",)),
    _c("V-74", "RH-LOG-1 RH-LOG-2 RH-JW-1", "$OLOGL, $OLOGD and $OJW at each edge of their counts",
       "1 and 12 labels are accepted in S, none refused (24); in the mission 1 and 12 values are accepted, "
       "none and 13 refused (25); $OJW to the first waypoint is accepted, one below refused (19)", "S",
       *_no("OLOGL"), *_ok("OLOGL,a", "OLOGL,1,2,3,4,5,6,7,8,9,10,11,12"), Start(),
       *_no("OLOGD", "OLOGD,1,2,3,4,5,6,7,8,9,10,11,12,13"), *_ok("OLOGD,1", "OLOGD,1,2,3,4,5,6,7,8,9,10,11,12"),
       *_ok("OJW,{wp_first}"), *_no("OJW,{wp_under}"), Poll(mode="N")),
    # --- rules no case above could fail (the traceability table): :mod:`.rulecases` ----------------
    *RULE_CASES,
    # --- §8 time ---------------------------------------------------------------------------------
    _c("V-62", "RH-TIM-1 RH-TIM-2", "Durations hold at the declared time scale",
       "a servo timeout of 30 s or more and a primitive timeout end within max(0.5 s, 5 %) plus the "
       "measured slack, at the declared time scale k (the servo timeout is the shortest whose end a "
       "clock 30 % fast moves by more than the precision the line allows, else the longest allowed)", "N",
       Send("OMS,90,2,20,{speed},{to_tim}"), Settle("remote"), Poll(mode="N|P"),
       Send("OMP,8080808080,00,{to}"), Settle("remote"), Poll(mode="N|P")),
)


def select_cases(patterns: Optional[list[str]], profile: Profile) -> list[Case]:
    """The cases whose clauses match any of the ``--select`` IDs or globs (all when none)."""
    if not patterns:
        return list(CASES)
    return [c for c in CASES if any(fnmatchcase(cid, p) for cid in c.clauses for p in patterns)]


def unmet_need(case: Case, profile: Profile, durations=None) -> Optional[str]:
    """Why the profile — or, given the line's :class:`~.durations.Durations`, the line at the run's
    time scale — does not let this case run, or ``None``."""
    if durations is not None:
        for need in line_needs(case):
            why = durations.unmet(need)
            if why:
                return why
    for need in case.needs:
        kind, _, arg = need.partition(":")
        if kind == "oxflt" and profile.fault_injection != "oxflt":
            return "the profile declares no $OXFLT test extension (fault_injection = \"none\")"
        if kind == "violation" and profile.trigger == "none":
            return ("the profile declares no way to raise a safety violation (violation_trigger = "
                    "\"none\", RH-SAF-5): the lockout is judged only if one happens by itself")
        if kind == "letter" and arg not in profile.osd_letters:
            return f"the profile's osd_letters lack {arg}"
        if kind == "safety_action" and profile.safety_action != arg:
            return f"the profile's safety_action is {profile.safety_action}, this case needs {arg}"
        if kind == "end_mission" and not profile.end_mission and profile.protocol != "rh5":
            return ("the profile names no end_mission (a short mission whose end a run can wait for), and "
                    f"a {profile.protocol} $OSI shows no remaining mission time to tell whether the test "
                    "mission ends soon enough (RH-MSN-4)")
        if kind == "srp_mission" and not profile.srp_mission:
            return "the profile names no srp_mission: the srp branch of SafetyAction cannot be exercised"
        if kind == "srp_field" and profile.protocol != "rh5" and profile.osi_fields < 16:
            return f"the profile's $OSI has {profile.osi_fields} fields: none shows whether the SRP runs"
        if kind == "cmd" and arg not in profile.commands:
            return f"the profile does not claim ${arg}"
        if kind in ("lockout", "ascent"):
            continue  # the line's (line_needs)
    cmds = {b.body.split(",")[0] for b in _sends(case.steps)}
    missing = sorted(c for c in cmds if c in s.__dict__ and c not in profile.commands and c != "OSD")
    if missing:
        return "the profile does not claim " + ", ".join("$" + c for c in missing)
    if case.start in ("N", "P") and "OMSTART" not in profile.commands:
        return "the case starts from a running mission, and the profile does not claim $OMSTART"
    return None


#: Duration templates (:mod:`.durations`) whose timer a case's ``Settle`` times: each must be
#: timeable on the line, else the case is NOT-TESTED before it runs.
_TIMED_KEYS = {"to": "timer:to", "to_tim": "timer:to_tim", "to_restart": "timer:to_restart", "opk_min": "timer:opk"}


def line_needs(case: Case) -> list[str]:
    """What the line must allow for ``case``: a timeable duration for every timer it sets going and
    then times (a ``Settle`` of a remote control or an ``$OPK``), and ``lockout`` where its commands
    must reach the vehicle inside a lockout (:meth:`.durations.Durations.unmet`)."""
    out = [n for n in case.needs if n in ("lockout", "ascent")]
    if any(isinstance(st, Settle) and st.timer in ("remote", "opk") for st in case.steps):
        for st in _sends(case.steps):
            for key, need in _TIMED_KEYS.items():
                if "{" + key + "}" in st.body and need not in out:
                    out.append(need)
    return out


def _sends(steps) -> list:
    out = []
    for st in steps:
        if isinstance(st, Send):
            out.append(st)
        elif isinstance(st, ClearWords):
            out.append(Send(st.queue))
        elif isinstance(st, Burst):
            out += [Send(b) for b in st.bodies]
        elif isinstance(st, WithSetting):
            out += _sends(st.steps)
    return out
