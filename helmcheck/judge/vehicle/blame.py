"""Which clauses an observation speaks to, and where a finding is booked.

Every finding names an ordered tuple of *candidate* clauses, the most specific first:

* an answered command — :func:`command_clauses`: a malformed command's field clause and RH-ACK-3
  (``$OSD`` letters: RH-OSD-2); a command the table refuses: the refusing row's clauses (the
  precondition and RH-ACK-4, or the lockout's RH-SAF-1/RH-SAF-3); an accepted one: its row's
  clauses (RH-INT-1 first when it takes over from another remote control). A value out of range is booked on the clause that sets the range, whether the
  grammar (a field's form: ``$OMP`` field 1 not ten hex digits, a timeout that is not an integer)
  or the range check (``$OMP`` field 2 not ``00``, a timeout of 0) finds it: :data:`FIELD_CLAUSE`
  names that clause for each field whose form or range a vehicle clause sets, also where a reading
  spells the range out (``RH-RD-6``: the rh5 ``$OMSTART`` flags are RH-MSN-2's, its names follow
  RH-MSN-1's path rules); a field count, or a field whose range only a reading sets
  (``RH-RD-9``: ``$OPOS`` speed, ``$ODVL`` x/y, the ``$OMW`` fields), is RH-ACK-3's — but a count a
  clause states itself (``$OLOGL``'s 1–12 labels, ``$OLOGD``'s 12 values: :data:`COUNT_CLAUSE`) is
  that clause's. Readings (``RH-RD-*``) are never booked: they say how a clause
  is read, not what a vehicle must do;
* an ``$OSI`` no conforming state explains — RH-OUT-4 and the clauses of what changed since the
  last confirmed report (a timer's row, an accepted command's row); RH-TIM-1/2 follow when a
  duration was being timed around the report;
* a command refused, as it should be, with the wrong error number: RH-ACK-4 for a refused
  precondition, else RH-ACK-3 — but a mission name the path rules reject, answered with a
  look-up's error (1, 3, 31), is RH-MSN-1's (:func:`looked_up`: the name was looked up, not
  rejected);
* a line the vehicle must discard but answered — the discard's own clause (RH-FRM-2/4/5/6/7),
  whatever else is wrong with the answer;
* a command refused where a conforming vehicle accepts it, where a clause names that very
  behaviour — :func:`stated_by`, booked on those clauses alone (not on the case's subject or the
  accepting row's first clause, which the refusal does not speak to): a command the phase's
  refusal of every other command spares (:func:`phase_exceptions`, derived from the transition
  table: ``$OSD`` in the lockout is RH-SAF-1's "except ``$OSD``", and RH-OSD-1's, whose row lists
  the lockout); a command refused with its own "incorrect values" error, written in a form of a
  field the profile names beside the plain one (:data:`FORMS`: ``$OMP`` hex digits in lower case,
  RH-PRM-2 "hex case is free on input"; an empty ``$OMW`` depth 2, RH-OMW-3; …).

:func:`targets` books a finding: inside a clause case (its ``case …`` note) on the candidates the
case is about, if any (a failure inside a case belongs to its subject, not to a neighbour it
touched); otherwise on the first candidate (and, when that is the generic RH-OUT-4, on the first
specific cause as well), with three refinements of that first cause:

* a clause that says only when, or with which values, a command is accepted
  (:data:`ACCEPTANCE`: RH-SRV-1/2, RH-PRM-1/2, RH-JW-1, RH-PK-1, RH-OMW-1) was settled by the
  command's ``$ACK``: a report after it is about the state the command leads to, so the next
  cause is taken (RH-PK-2 "mode becomes mP", not RH-PK-1);
* a release (:data:`RELEASES`): a timer or command that ends remote control says *that* control
  ends, RH-INT-2 says *what* the vehicle resumes — the waypoint it was heading for, the park time
  left. A report no conforming state explains after one may be wrong in either, and the report
  says which (:meth:`.belief.Beliefs.osi` orders the candidates): still in the remote mode the
  release ends — the trigger's clause alone; released into the right mode but toward another
  waypoint or with another park time left — RH-INT-2 alone. Where the candidates still name both
  (released into another mode, which breaks both where the trigger's clause says the mission
  resumes, RH-PK-3 and RH-OMW-4; a wrong error state or SRP flag as well), both are booked;
* a report whose only specific cause is a clause its own check judges on that same report
  (:data:`REPORT_JUDGED`: the ``$OPK`` countdown, RH-PK-2, judged from fields 7 and 10 by
  :mod:`.osichecks`) is booked on RH-OUT-4 alone: the own check books the clause, with the
  reason the report gives (where the vehicle was, what it counted).

:data:`OWN_EVIDENCE` lists the clauses a row's confirmation does not pass by itself, because
their text asks for more than the mode the row leads to; each passes only on its own
observation (named beside it).
"""

from __future__ import annotations

from functools import lru_cache
from typing import Iterable, Optional

from ...clauses import catalogue
from ...grammar import sentences as s
from ...grammar.errors import SentenceError
from ...model.transitions import COMMAND_EVENTS, MODES, PHASES, TABLE

__all__ = ["command_clauses", "looked_up", "targets", "vehicle_clause", "OWN_EVIDENCE", "FIELD_CLAUSE", "COUNT_CLAUSE", "CHECK_CLAUSE",
           "passable",
           "stated_by", "phase_exceptions", "FORMS"]

#: clause → the observation that passes it (instead of a row's confirmation).
OWN_EVIDENCE = {
    "RH-PK-2": "an $OSI in mP counting down while on station",
    "RH-PRM-3": "an $OSI in M showing the commanded fins and motor",
    "RH-SRV-4": "the RH-TIM-1 bracket of the servo timeout",
    "RH-PRM-4": "the RH-TIM-1 bracket of the primitive timeout (and neutral fins and motor from S)",
    "RH-PK-3": "the RH-TIM-1 bracket of the $OPK park",
    "RH-SAF-1": "an err 26 in the lockout, the code in field 8, the lockout's RH-TIM-1 bracket",
    "RH-SAF-2": "an $OSI after the lockout, confirming refused commands had no effect",
    "RH-SAF-4": "the at-surface action confirmed at the surface",
    "RH-INT-3": "a release after an interrupted $OPK park, to the mission",
    "RH-OMW-5": "a release after an interrupted queue, to the mission",
    "RH-MSN-3": "an $OSI in S with neutral fins and motor after $OMSTOP",
    "RH-MSN-4": "an $OSI in S at the mission's end",
    "RH-POS-2": "the $OSI position and $OCTD values after $OPOS",
    "RH-SET-2": "an $ORWSET reply showing what was written",
    "RH-OSD-1": "the data sentences of an $OSD, in request order",
    "RH-TIM-1": "an RH-TIM-1 bracket", "RH-TIM-2": "an RH-TIM-1 bracket at the declared time scale",
}

#: (sentence ID, field) → the vehicle clause that sets the field's form or range (§4–6, as the
#: range checks of :mod:`helmcheck.grammar.ranges` name it): a value the grammar cannot read there
#: (nine hex digits, ``1.5`` for an integer timeout) breaks that clause, not only RH-ACK-3.
FIELD_CLAUSE = {
    **{("OMS", f): "RH-SRV-2" for f in ("heading", "depth", "max_pitch", "speed", "timeout")},
    **{("OMP", f): "RH-PRM-2" for f in ("actuators", "reserved", "timeout")},
    ("OJW", "waypoint"): "RH-JW-1",
    **{("OPK", f): "RH-PK-1" for f in ("lat", "lon", "minutes", "speed")},
    ("OPOS", "lat"): "RH-POS-1", ("OPOS", "lon"): "RH-POS-1",
    ("ODVL", "timeout"): "RH-DVL-1",
    ("OMSTOP", "flag"): "RH-MSN-3",
    # the rh5 ``$OMSTART`` (RH-RD-6 reads RH-MSN-2): its flags are RH-MSN-2's; its mission and SRP
    # names follow "the $OMLOAD path rules", which are RH-MSN-1's text (nothing outside the
    # mission directory is opened), so a name that breaks them is RH-MSN-1's
    **{("OMSTART", f): "RH-MSN-2" for f in ("ignore_gps", "ignore_sounder", "calibrate_pressure", "mission_type")},
    ("OMSTART", "name"): "RH-MSN-1", ("OMSTART", "srp"): "RH-MSN-1",
}

#: Command event → the clause that states the check a conforming vehicle refuses it by in a state
#: its row accepts it in: ``$OJW`` n in [0, waypoints−1] (RH-JW-1, also under remote control,
#: whose row is RH-JW-2's), the ``$OPK`` 10 miles (RH-PK-1, also in ``mP``, whose row is RH-PK-2's),
#: ``$OLOGD``'s values against the labels (RH-LOG-2).
CHECK_CLAUSE = {"OJW": "RH-JW-1", "OPK": "RH-PK-1", "OLOGD": "RH-LOG-2"}

#: Sentence ID → the vehicle clause that states how many fields it takes, where one does beyond
#: RH-ACK-3's "the wrong number of fields": ``$OLOGL`` 1–12 labels, none empty (RH-LOG-1, RH-RD-9),
#: ``$OLOGD`` at most 12 values (RH-LOG-2's ``<d1>…<d12>``). A count the grammar refuses there breaks
#: that clause (the traceability table, ``helmcheck/spec/rules.toml``), RH-ACK-3 related.
COUNT_CLAUSE = {"OLOGL": "RH-LOG-1", "OLOGD": "RH-LOG-2"}

_KNOWN = None


def vehicle_clause(cid: str) -> bool:
    """A clause a vehicle is judged on (§1–8; not a §8b reading, not §9)."""
    global _KNOWN
    if _KNOWN is None:
        _KNOWN = {c for c, v in catalogue().items() if v.role == "vehicle"}
    return cid in _KNOWN


def passable(clauses: Iterable[str]) -> tuple[str, ...]:
    """The clauses a confirmation passes: vehicle clauses without their own evidence."""
    if isinstance(clauses, tuple):
        return _passable(clauses)
    if not clauses:
        return ()
    return tuple(c for c in clauses if vehicle_clause(c) and c not in OWN_EVIDENCE)


@lru_cache(maxsize=1024)
def _passable(clauses: tuple[str, ...]) -> tuple[str, ...]:
    return tuple(c for c in clauses if vehicle_clause(c) and c not in OWN_EVIDENCE)


@lru_cache(maxsize=1024)
def _dedupe(xs: tuple[str, ...]) -> tuple[str, ...]:
    return tuple(dict.fromkeys(x for x in xs if vehicle_clause(x)))


def command_clauses(item, expected_ack: Optional[s.ACK], row, before_mode: str = "",
                    before_phase: str = "") -> tuple[str, ...]:
    """The clauses an answered command speaks to, most specific first (module docstring).
    ``before_mode``: the mode the command met; a command a conforming vehicle accepts there that
    takes over from another remote control speaks first to RH-INT-1 (any remote command interrupts
    any other), whatever else its row names. ``before_phase``: the safety phase it met (a refusal
    owed in the ascent after the lockout is RH-SAF-3's, not the lockout's)."""
    if isinstance(item, SentenceError):
        if expected_ack is not None and expected_ack.err == 26:
            if row is None:
                return ("RH-SAF-3",) if before_phase == "ascent" else ("RH-SAF-1",)
            return _dedupe(row.clauses)
        first = "RH-OSD-2" if item.sentence_id == "OSD" else item.clause
        if (first == "RH-ACK-3" or first.startswith("RH-RD-")) and item.field:
            # a field's form or range (set by a clause, or by a reading of one): the clause that sets it
            first = FIELD_CLAUSE.get((item.sentence_id, item.field), first)
        elif first == "RH-ACK-3" and not item.field:
            # a count a clause states (1–12 labels, at most 12 values): that clause's (COUNT_CLAUSE)
            first = COUNT_CLAUSE.get(item.sentence_id, first)
        return _dedupe((first, "RH-ACK-3")) or ("RH-ACK-3",)
    if row is None:
        return ("RH-ACK-1",)
    out = _dedupe(row.clauses)
    if (before_mode in _REMOTE and "RH-INT-1" in out and row.error is None and row.target != before_mode
            and (expected_ack is None or expected_ack.status == 0)):
        out = ("RH-INT-1",) + tuple(c for c in out if c != "RH-INT-1")
    if expected_ack is not None and expected_ack.status == 1 and row.error is None:
        # accepted by the table, refused by a data check (index, count, file, distance): the
        # clause that states the check (CHECK_CLAUSE), else the row's own (RH-MSN-1/2)
        own = CHECK_CLAUSE.get(row.event)
        out = (own,) if own else out[:1]
    return out or ("RH-ACK-1",)


#: The forms of a command's fields the profile names beside the plain one, and the clause that
#: names each: (sentence ID, field) → (clause, whether a field's value is in that form). A vehicle
#: that refuses a command written so, with the command's own "incorrect values" error, breaks that
#: clause (:func:`stated_by`).
FORMS = {
    ("OMP", "actuators"): ("RH-PRM-2", lambda v: v != v.upper()),  # "hex case is free on input"
    ("OMW", "keyword"): ("RH-OMW-3", lambda v: v != "Clr"),  # CLEAR and STOP, any case (RH-RD-4)
    ("OMW", "depth2"): ("RH-OMW-3", lambda v: v is None),  # "depth2 may be empty"
    ("OPOS", "conductivity"): ("RH-POS-1", lambda v: v is None),  # "… may be empty"
    ("OPOS", "temperature"): ("RH-POS-1", lambda v: v is None),
    ("OPOS", "trailing_empty"): ("RH-POS-1", bool),  # "a sixth empty field is tolerated"
    ("OSD", "letters"): ("RH-OSD-1", lambda v: "" in v),  # "the positional form … accepted"
}


def _forms(item) -> list[str]:
    out = []
    for name in item.field_names():
        value = getattr(item, name)
        if isinstance(value, s.Command):  # ``$OMW,CLEAR,<waypoint>``: its waypoint's fields too
            out += _forms(value)
            continue
        form = FORMS.get((item.ID, name))
        if form is not None and form[1](value):
            out.append(form[0])
    return out


@lru_cache(maxsize=1)
def phase_exceptions() -> dict[tuple[str, str], tuple[str, ...]]:
    """(command event, phase) → the clauses that say the event is answered in a phase whose rule
    refuses every other command, derived from the transition table: where the rows that refuse a
    command in every mode of a phase all name one clause, and refuse more commands than they
    spare, that clause states the rule with its exceptions ("every remote-helm command except
    ``$OSD``", RH-SAF-1); an exception's own row names the phase among its phases, and its first
    clause says so too (RH-OSD-1, "including the safety lockout")."""
    out: dict = {}
    for phase in PHASES:
        refused = [r for r in TABLE if r.error is not None and phase in r.phases and r.event in COMMAND_EVENTS
                   and set(r.sources) == set(MODES) and not r.guard]
        clauses = {r.clauses[0] for r in refused}
        events = {r.event for r in refused}
        spared = [e for e in COMMAND_EVENTS if e not in events]
        if len(clauses) != 1 or len(spared) >= len(events):
            continue
        (rule,) = clauses
        for ev in spared:
            own = next((r for r in TABLE if r.event == ev and phase in r.phases and r.error is None), None)
            out[(ev, phase)] = (rule,) + ((own.clauses[0],) if own is not None and own.clauses[0] != rule else ())
    return out


def stated_by(item, err: int, row, phase: str) -> tuple[str, ...]:
    """The clauses that name the behaviour a vehicle broke by refusing ``item`` (with ``err``) in
    ``phase``, where a conforming vehicle takes ``row`` and accepts it; () when none does beyond
    the row's own (module docstring)."""
    out: list[str] = []
    if row is not None:
        out += phase_exceptions().get((row.event, phase), ())
    if isinstance(item, s.Command) and err == item.ERR:
        out += _forms(item)
    return _dedupe(tuple(out))


#: The answers of a mission look-up (RH-MSN-1/2, RH-RD-6): 1 not found, 3 does not parse, 31 the SRP.
LOOKUP_ERRORS = frozenset({1, 3, 31})


def looked_up(item, err: int) -> Optional[str]:
    """RH-MSN-1 when a mission or SRP name that its path rules reject (an absolute path, a drive
    letter, a ``..`` component) is refused with a look-up's error (:data:`LOOKUP_ERRORS`) instead
    of the rejection's 29 (``$OMLOAD``) or 30 (``$OMSTART``, RH-RD-6): the vehicle looked the
    name up rather than rejecting it, which is RH-MSN-1's rule broken, not only a wrong number
    (RH-ACK-3, as any other refusal with the wrong error is). None otherwise."""
    if (isinstance(item, SentenceError) and item.sentence_id in ("OMLOAD", "OMSTART")
            and item.field in ("name", "srp") and err in LOOKUP_ERRORS):
        return "RH-MSN-1"
    return None


#: The remote-control modes (RH-INT-1).
_REMOTE = frozenset({"mP", "A", "M", "W"})
#: Clauses that say only "the report must be consistent": outside a case, a finding on one of
#: them is booked on its first specific cause too (what the vehicle did wrong to get there).
GENERIC = frozenset({"RH-OUT-4"})
#: The clauses of what ends remote control whose text hands what follows to RH-INT-2 (the servo
#: and primitive timeouts, the ``$OPK`` time up, ``$OMW,Clr`` and the queue done).
RELEASES = frozenset({"RH-SRV-4", "RH-PRM-4", "RH-PK-3", "RH-OMW-3", "RH-OMW-4"})
#: Clauses a report's own check judges on every report they speak to (module docstring).
REPORT_JUDGED = frozenset({"RH-PK-2"})
#: Clauses that say only when, or with which values, a command is accepted (module docstring).
ACCEPTANCE = frozenset({"RH-SRV-1", "RH-SRV-2", "RH-PRM-1", "RH-PRM-2", "RH-JW-1", "RH-PK-1", "RH-OMW-1"})
#: Named when a duration was being timed around a report: no cause by themselves.
_TIMING = frozenset({"RH-TIM-1", "RH-TIM-2"})


def targets(candidates: tuple[str, ...], case_clauses: tuple[str, ...], stated: tuple[str, ...] = ()) -> tuple[str, ...]:
    """Where a finding is booked (module docstring): on ``stated`` (:func:`stated_by`) when given."""
    if stated:
        return stated
    if case_clauses:
        inside = tuple(c for c in candidates if c in case_clauses)
        if inside:
            return inside
    if candidates and candidates[0] in GENERIC and len(candidates) > 1:
        specific = [c for c in candidates[1:] if c not in _TIMING and c not in GENERIC]
        if specific and all(c in REPORT_JUDGED for c in specific):
            return candidates[:1]
        first = candidates[1]
        if first in ACCEPTANCE:
            first = next((c for c in specific if c not in ACCEPTANCE), first)
        if first in RELEASES and "RH-INT-2" in candidates[2:]:
            return (candidates[0], first, "RH-INT-2")
        return (candidates[0], first)
    return candidates[:1]
