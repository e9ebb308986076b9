"""The clause cases that probe a rule no earlier case could fail (the traceability table, ``helmcheck/spec/rules.toml``).

Each case here does the thing a rule forbids, in the history the rule names, so that a vehicle
breaking exactly that rule answers differently from the model:

* a condition the other cases always satisfy — "only while a mission is running" after the
  mission was stopped, and in an ``M`` entered from ``S`` (RH-RD-1); "no *accepted* ``$OMS``"
  with a refused one sent into the timeout (RH-SRV-4); "after an *accepted* ``$OLOGL``" with a
  refused one after it (RH-LOG-2: the labels are the accepted one's);
* the order of the checks (RH-RD-2): a failed precondition met with a file that is not there, or
  a park too far away, answers the precondition's error, not the later check's; a command with bad
  fields in the lockout answers 26;
* a path rule's variant the others do not send (a ``..`` that resolves inside the directory, a
  backslash, a lower-case drive letter: RH-MSN-1), a keyword that ends every kind of remote control
  (RH-RD-4), the SRP flag of a type-1 start and a missing SRP file (RH-RD-6), a malformed checksum
  of three digits or of non-hex letters (RH-FRM-4);
* a line that goes quiet and comes back — the tester silent for a while, its end of the link
  closed and opened again where the port's name allows (a client reconnecting) — and the first
  command after it (RH-ACK-1);

and :data:`RULE_CASES` is appended to :data:`.catalogue.CASES`. Case IDs start at V-80 so that
cases added to the catalogue meanwhile keep theirs. The steps are the same vocabulary
(:mod:`.steps`); nothing here judges.
"""

from __future__ import annotations

from .steps import Case, Fault, Poll, Quiet, Raw, Send, Settle, Start, Until, Wait

__all__ = ["RULE_CASES"]

OMS = "OMS,90,2,20,{speed},{to}"
OMS_RESTART = "OMS,90,2,20,{speed},{to_restart}"
FAR_OMW = "OMW,{near_lat},{lon},2,,15,{speed},0,"
OMP_LONG = "OMP,8080808080,00,{to_long}"


def _c(id_, clauses, title, expectation, start, *steps, needs=()):
    return Case(id_, tuple(clauses.split()), title, expectation, start, tuple(steps), tuple(needs))


RULE_CASES: tuple[Case, ...] = (
    _c("V-80", "RH-SRV-1 RH-JW-1 RH-PK-1 RH-OMW-1 RH-LOG-2 RH-MSN-3", "A mission stopped is no mission running",
       "a waypoint queued (W), then $OMSTOP: S; then $OMS, $OJW, $OPK, $OMW and $OLOGD, each allowed only while a "
       "mission runs, are refused with their own error (RH-RD-1: running since an accepted $OMSTART, until "
       "$OMSTOP); the mission started again is not in W (the queue was cleared)", "N",
       Send(FAR_OMW, expect="$ACK,16,0,0"), Send("OMSTOP,0", expect="$ACK,1,0,0"), Poll(mode="S"),
       Send(OMS, expect="$ACK,9,1,20"), Send("OJW,0", expect="$ACK,7,1,19"),
       Send("OPK,{lat},{lon},1,{speed}", expect="$ACK,11,1,22"), Send(FAR_OMW, expect="$ACK,16,1,36"),
       Send("OLOGD,1", expect="$ACK,4,1,25"), Start(), Poll(mode_not="W")),
    _c("V-81", "RH-SRV-1 RH-JW-1 RH-PK-1 RH-OMW-1 RH-LOG-1 RH-SET-1 RH-MSN-2",
       "An M entered from S is no mission running",
       "$OMP from S (M); $OMS, $OJW, $OPK, $OMW are refused with their own error, $OLOGL and an $ORWSET read "
       "are accepted (RH-RD-1: \"accepted only in S\" means no mission running); $OMSTART is accepted there "
       "and ends the primitive control", "S",
       # each refused command right after an $OMP that holds M (RH-RD-3 restarts it): M on the slowest line too
       Send(OMP_LONG, expect="$ACK,10,0,0"), Poll(mode="M"), Send(OMS, expect="$ACK,9,1,20"),
       Send(OMP_LONG), Send("OJW,0", expect="$ACK,7,1,19"),
       Send(OMP_LONG), Send("OPK,{lat},{lon},1,{speed}", expect="$ACK,11,1,22"),
       Send(OMP_LONG), Send(FAR_OMW, expect="$ACK,16,1,36"),
       Send(OMP_LONG), Send("OLOGL,a,b", expect="$ACK,5,0,0"),
       Send(OMP_LONG), Send("ORWSET,Sle,R", expect="$ACK,12,0,0"), Poll(mode="M"),
       Send("OMSTART,0,0,0,0,{mission},", expect="$ACK,3,0,0"), Poll(mode_not="M")),
    _c("V-82", "RH-ACK-4 RH-PK-1 RH-MSN-1 RH-MSN-2", "Checks in their order",
       "RH-RD-2: an $OPK ~111 km away in S is refused for the state (22), not the distance (40); a start whose "
       "SRP file is missing is 31 (RH-RD-6); while a mission runs an $OMLOAD or $OMSTART of a file that is not "
       "there is refused for the state (29, 30), not the look-up (1); an $OPK ~111 km away with minutes 0 is "
       "refused for its field (22), not the distance", "S",
       Send("OPK,{far_lat},{lon},1,{speed}", expect="$ACK,11,1,22"),
       Send("OMSTART,0,0,0,0,{mission},helmcheck-missing.mis", expect="$ACK,3,1,31"), Start(),
       Send("OMLOAD,helmcheck-missing.mis,0", expect="$ACK,2,1,29"),
       Send("OMSTART,0,0,0,0,helmcheck-missing.mis,", expect="$ACK,3,1,30"),
       Send("OPK,{far_lat},{lon},0,{speed}", expect="$ACK,11,1,22"), Poll(mode="N|P")),
    _c("V-83", "RH-MSN-1", "The path rules hold wherever a name resolves",
       "a '..' component that resolves inside the mission directory, a '..' between backslashes, a name "
       "starting with a backslash and a lower-case drive letter are refused (29; $OMSTART 30)", "S",
       Send("OMLOAD,sub/../{mission},0", expect="$ACK,2,1,29"),
       Send("OMLOAD,sub\\..\\{mission},0", expect="$ACK,2,1,29"),
       Send("OMLOAD,\\{mission},0", expect="$ACK,2,1,29"), Send("OMLOAD,c:{mission},0", expect="$ACK,2,1,29"),
       Send("OMSTART,0,0,0,0,sub/../{mission},", expect="$ACK,3,1,30"), Poll(mode="S")),
    _c("V-84", "RH-OMW-3", "An $OMW keyword ends every remote control",
       "the keyword alone ends A, M and mP as it ends W, and the mission resumes (RH-RD-4); CLEAR with a "
       "waypoint clears the queue, then queues that waypoint (W)", "N",
       Send(OMS), Poll(mode="A"), Send("OMW,{kw_a}", expect="$ACK,16,0,0"), Poll(mode="N|P"),
       Send(OMP_LONG), Send("OMW,{kw_b}", expect="$ACK,16,0,0"), Poll(mode="N|P"),
       Send("OPK,{lat},{lon},5,{speed}"), Send("OMW,{kw_c}", expect="$ACK,16,0,0"), Poll(mode="N|P"),
       Send(FAR_OMW), Send("OMW,CLEAR,{near_lat},{near_lon},2,,15,{speed},0,", expect="$ACK,16,0,0"),
       Poll(mode="W"), Send("OMW,{kw_a}"), Poll(mode="N|P")),
    _c("V-85", "RH-SAF-1", "In the lockout the refusal comes first",
       "commands with bad fields written right after the violation are refused with 26, not their own error "
       "(RH-RD-2: the lockout first); $OSD is still served", "N",
       Fault("Sle", then=("OMS,400,2,20,{speed},10", "OJW,x", "OMP,8080,00,5", "OSD,S")),
       Settle("lockout", probe="ORWSET,Sle,R"), needs=("violation", "lockout")),
    _c("V-86", "RH-SRV-4", "A refused $OMS does not restart the servo timeout",
       "an $OMS refused (heading 360) well into the timeout leaves the first timeout running: control is "
       "released when it ends (\"no accepted $OMS\"), not a whole timeout after the refused one", "N",
       Send(OMS_RESTART), Poll(mode="A"), Wait("{gap}"),
       Send("OMS,360,2,20,{speed},{to_restart}", expect="$ACK,9,1,20"), Settle("remote"), Poll(mode="N|P")),
    _c("V-87", "RH-JW-1 RH-PK-1 RH-LOG-1 RH-LOG-2", "Integers are integers, labels are not empty",
       "an $OLOGL of one label is accepted, one with an empty label refused (24, RH-RD-9); in the mission two "
       "values are refused (25): the labels are the accepted $OLOGL's, not the refused one's; an $OJW to "
       "waypoint 1.5 (19) and an $OPK of 1.5 minutes (22) are refused", "S",
       Send("OLOGL,a", expect="$ACK,5,0,0"), Send("OLOGL,a,,b", expect="$ACK,5,1,24"), Start(),
       Send("OLOGD,1,2", expect="$ACK,4,1,25"), Send("OJW,1.5", expect="$ACK,7,1,19"),
       Send("OPK,{lat},{lon},1.5,{speed}", expect="$ACK,11,1,22"), Poll(mode="N|P")),
    _c("V-88", "RH-MSN-2", "Mission type 1 runs as an SRP",
       "the rh5 $OMSTART with mission type 1 starts the mission with $OSI field 17 True (RH-RD-6)", "S",
       Send("OMSTART,0,0,0,1,{mission},", expect="$ACK,3,0,0"),
       Until("the SRP flag", mode="N|P", srp_active=True, budget_v=30.0), needs=("srp_field",)),
    _c("V-89", "RH-FRM-4 RH-FRM-5", "A checksum of three digits or of letters, a lower-case $osd",
       "a line whose checksum has three hex digits, or two characters that are not hex, is discarded (no ACK, "
       "the mode stays); `$osd` is an unknown ID (RH-RD-16): no answer", "N",
       Raw("longck", "OMSTOP,0"), Raw("hexck", "OMSTOP,0"), Poll(mode="N|P"), Raw("lowerid", "OSD,S"), Poll()),
    _c("V-90", "RH-ACK-1 RH-ACK-2", "The first command after a quiet line",
       "nothing is sent for 4 s, then the link is closed and opened again where the port's name allows it (a "
       "client reconnecting); the first command after it, and the next, each get their $ACK in the window",
       "S", Quiet(4.0, reopen=True), Send("OSD,S"), Send("OPOS,{lat},{lon},0,,", expect="$ACK,6,0,0"), Poll(mode="S")),
)
