"""The readings table: every question the reference profile's words leave open, and every answer they allow.

Where §1–8b of the profile allow more than one conforming behaviour, a vehicle (or a backseat)
may take any of them. This table is the one place those questions are written down — clause,
question, the profile's own words, every reading accepted (the first is the reference model's
own), how the judge accepts each and how the emulator takes each — and everything else reads
it:

* the model (:class:`~helmcheck.model.vehicle.VehicleModel`) behaves by the readings it is given
  (``readings``: key → value, :data:`DEFAULTS` unless told otherwise) wherever a row names
  ``model`` as its ``how``;
* the vehicle judge accepts every reading: at each command a row applies to
  (:func:`alternatives`), it tries the model under each other reading too
  (:mod:`helmcheck.judge.vehicle.branches`), and a report says which the vehicle took;
* the emulator takes any reading with ``--set KEY=VALUE`` (:mod:`helmcheck.emulator.freedoms`,
  the setting named by :attr:`Reading.setting`);
* ``helmcheck profile readings`` prints it, ``helmcheck docs`` writes ``docs/readings.md`` from it,
  and ``tests/test_readings.py`` certifies the emulator under every reading of every row and fails
  when a row is missing from one of those places.

A row's ``how`` says which machinery accepts it: ``model`` (the model branches on it),
``judge`` (a judge's own rule accepts every reading; the model has no say), ``freedom`` (an
emulator freedom of timing or plant the judge allows for in its windows), ``backseat`` (the
backseat judge). Pure data and two small functions: no I/O.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

__all__ = ["Choice", "Reading", "READINGS", "DEFAULTS", "BY_KEY", "alternatives", "reading", "taken", "markdown",
           "text"]


@dataclass(frozen=True)
class Choice:
    """One conforming answer: its ``value`` (the setting's value) and what it ``means``."""

    value: str
    means: str


@dataclass(frozen=True)
class Reading:
    """One open question of the profile (module docstring)."""

    key: str  #: the setting's name (model ``readings`` key, emulator setting)
    clause: str  #: the clause (and reading) whose words leave the room
    question: str
    words: str  #: the profile's own words, quoted
    choices: tuple[Choice, ...]  #: every reading accepted; the first is the reference model's
    how: str  #: model | judge | freedom | backseat (module docstring)
    judge: str  #: how the judge accepts every reading, in one sentence
    setting: Optional[str] = None  #: the emulator setting that takes each (None: nothing to take)
    vehicle3: str = ""  #: the third-party vehicle's own choice, where its README states one
    #: the model itself behaves by this reading (``VehicleModel.readings``; the emulator takes it there)
    in_model: bool = False
    #: the vehicle clause an answer under this reading is judged on (its pass is booked there, and
    #: the report names the reading taken there)
    books: str = ""
    #: the clauses whose certification cases meet the question (the suite certifies the emulator on
    #: them under every reading); empty: no case meets it (the exploration and logs may)
    certify: tuple[str, ...] = ()

    @property
    def values(self) -> tuple[str, ...]:
        return tuple(c.value for c in self.choices)

    @property
    def default(self) -> str:
        return self.choices[0].value


READINGS: tuple[Reading, ...] = (
    Reading(
        "srp_bad_path", "RH-RD-6",
        "An SRP name that breaks the path rules (absolute, a drive letter, a '..' component): err 30 "
        "(a bad path) or err 31 (an SRP missing or unreadable)?",
        "rh5 form: … the name follows the `$OMLOAD` path rules with err 30 for a bad path and err 1 for a "
        "missing file; a given SRP name that is missing or unreadable: err 31",
        (Choice("30", "refused with 30 when the fields are checked (RH-RD-2: field syntax before look-ups)"),
         Choice("31", "refused with 31 at the file look-up: a name outside the directory is one the vehicle "
                      "cannot read (never opened); a state precondition refuses first (30)")),
        "model", "the model answers the rh5 `$OMSTART` under both; a vehicle's 30 or 31 is a pass",
        books="RH-MSN-2", in_model=True, setting="srp_bad_path", vehicle3="31", certify=("RH-MSN-2",)),
    Reading(
        "ascent_refusal_order", "RH-RD-12",
        "After the lockout, before the surface: is a malformed `$OMS`/`$OJW`/`$OPK`/`$OMW` refused with 26 "
        "(the refusal first, like the lockout's) or with its own incorrect-values error (the fields first)?",
        "RH-RD-2: lockout (err 26) first, then field syntax and ranges …; RH-RD-12: After the lockout and "
        "until the surface, only `$OMS`, `$OJW`, `$OPK` and `$OMW` stay refused (26)",
        (Choice("first", "26 whatever the fields (the refusal is the lockout's, first in RH-RD-2's order)"),
         Choice("after fields", "the command's own error when a field is bad, else 26 (the refusal is a "
                                "state precondition, after the fields)")),
        "model", "the model answers a command in the ascent under both",
        books="RH-SAF-3", in_model=True, setting="ascent_refusal_order", vehicle3="first"),
    Reading(
        "omw_pitch_speed", "RH-RD-9",
        "Are `$OMW` max pitch and speed bounded (as `$OMS`'s: [0, 45] and [0, max_speed_kn])?",
        "RH-RD-9: Ranges the paper leaves open: … `$OMW` park time integer [0,86400] s, depths [−100,100] m "
        "(no range for its pitch or speed)",
        (Choice("bounded", "pitch above 45 or speed above max_speed_kn refused (36), as `$OMS`'s"),
         Choice("unbounded", "any non-negative pitch and speed queued")),
        "model", "the model answers an `$OMW` beyond those values under both",
        books="RH-ACK-3", in_model=True, setting="omw_pitch_speed", vehicle3="bounded", certify=("RH-ACK-3",)),
    Reading(
        "stop_unloads", "RH-RD-6",
        "After `$OMSTOP` or the mission's end, is the mission still loaded (does the paper form "
        "`$OMSTART,<flag>` start it again)?",
        "RH-MSN-2: The paper form `$OMSTART,<flag>` … starts the loaded mission; RH-RD-6: `$OMSTART` paper "
        "form with no mission loaded: err 17",
        (Choice("kept", "the last mission stays loaded: the paper form starts it again"),
         Choice("unloaded", "a stopped or ended mission is no longer loaded: the paper form is refused (17) "
                            "until the next `$OMLOAD`")),
        "model", "the model answers a paper-form `$OMSTART` after a stop under both",
        books="RH-MSN-2", in_model=True, setting="stop_unloads", vehicle3="kept", certify=("RH-MSN-2",)),
    Reading(
        "resumed_park", "RH-INT-2",
        "A mission park resumed after remote control moved the vehicle off station: does its time left count "
        "from the release, or once back on station?",
        "RH-INT-2: … or a mission park (`P`) with the park time that was remaining at that moment",
        (Choice("at once", "counts from the release, wherever the vehicle is"),
         Choice("on station", "counts once back within on_station_m of the park's waypoint, which it heads for")),
        "freedom", "the mirror adopts the return on station within its window (:mod:`helmcheck.judge.vehicle.closure`)",
        books="RH-INT-2", setting="resumed_park", vehicle3="at once", certify=("RH-INT-2",)),
    Reading(
        "park_waypoint", "RH-OUT-1",
        "During a mission park (`P`), does `$OSI` field 3 show the waypoint parked on, or the one after it?",
        "RH-OUT-1: 3 next waypoint (0-based); RH-RD-5: `$OSI` field 3 shows the frozen mission waypoint in A, "
        "M, mP and W, and 0 in `S` (P is not named)",
        (Choice("parked", "the waypoint parked on; it becomes the next when the park ends"),
         Choice("next", "the next waypoint from the arrival on (the parked one is behind it)")),
        "judge", "in `P` either is taken as the mission's waypoint (:func:`helmcheck.model.observe.shown_waypoints`)",
        books="RH-OUT-4", in_model=True, setting="park_waypoint", vehicle3="parked", certify=("RH-INT-2",)),
    Reading(
        "opos_ctd", "RH-POS-2",
        "Does `$OCTD` report the conductivity and temperature an `$OPOS` applied, or the vehicle's own sensor?",
        "RH-POS-2: Conductivity and temperature are always applied (\"applied\" is not defined; the paper: "
        "they are accepted every time)",
        (Choice("reported", "`$OCTD` shows the values `$OPOS` gave"),
         Choice("internal", "they are used inside (sound speed, salinity) and `$OCTD` shows its own sensor")),
        "model", "an `$OCTD` that shows them passes; one that does not is not judged, unless the vehicle "
                 "showed an earlier `$OPOS`'s values (then it is held to it: :mod:`helmcheck.judge.vehicle.osichecks`)",
        books="RH-POS-2", in_model=True, setting="opos_ctd", vehicle3="reported", certify=("RH-POS-2",)),
    Reading(
        "process_when_idle", "RH-RD-15",
        "When replies are still going out, is a command processed at once (its `$ACK` waits behind them) "
        "or only once the line is idle (its `$ACK` goes out the instant it is processed)?",
        "RH-RD-15: Durations start when the vehicle processes the command, the instant its ACK goes out; "
        "RH-ACK-6: Commands are processed in arrival order",
        (Choice("false", "processed when due; its `$ACK` queues behind the replies before it"),
         Choice("true", "processed only once the line is idle (a serial loop that answers one line at a "
                        "time): its `$ACK` goes out at once and its durations start there")),
        "freedom", "a command's instant is bounded by its `$ACK`'s arrival less every reply byte since it "
                   "was sent, so either start of a duration lies in the window the judge allows "
                   "(:mod:`helmcheck.judge.vehicle.answers`)",
        books="RH-TIM-1", setting="process_when_idle", vehicle3="true", certify=("RH-SRV-4", "RH-ACK-6")),
    Reading(
        "omload_flag", "RH-MSN-1",
        "Which `$OMLOAD` flags does a vehicle accept?",
        "RH-MSN-1: `$OMLOAD,<name>,<flag>` (ACK 2, err 29; 1 file not found): accepted only in `S` "
        "(no range is given for the flag)",
        (Choice("any", "any flag"), Choice("0-3", "the paper's flags 0–3; any other refused (29)"),
         Choice("0", "only 0 (public client code always sends it); any other refused (29)")),
        "model", "the model answers an `$OMLOAD` under each", in_model=True, setting="omload_flag",
        books="RH-MSN-1", vehicle3="0-3", certify=("RH-MSN-1",)),
    Reading(
        "overrun", "RH-ACK-2",
        "When a backseat's requests ask for more replies than the line carries, does the vehicle queue every "
        "reply (and lag), or leave requests it cannot answer in time unanswered?",
        "RH-ACK-1: Every well-framed command of a known type gets exactly one `$ACK`; RH-ACK-2: … within the "
        "ACK window …, plus serial transmit time at the line's baud; RH-BS-4 bounds only what the backseat sends",
        (Choice("queue", "every reply waits its turn (RH-ACK-2's transmit time taken to include what is queued "
                         "ahead)"),
         Choice("drop", "a poll whose replies could not start within the ACK window goes unanswered, data and "
                        "`$ACK,8` together; commands are always answered")),
        "backseat", "the backseat judge judges each report from when it arrived; a scenario's moment that "
                    "arrived too late is not claimed (`helmcheck certify backseat` plays drop; `--overrun queue`)",
        setting="overrun"),
    Reading(
        "bs3_list", "RH-BS-3",
        "Is RH-BS-3's list of commands exhaustive, or examples of the preconditions a backseat can know "
        "(`$OLOGD` after the mission's end, `$OMSTART` while one runs)?",
        "RH-BS-3: It respects preconditions it can know: `$OLOGL` and `$ORWSET` only before starting a mission; "
        "`$OMS`, `$OJW`, `$OPK`, `$OMW` only while the vehicle reports a running mission",
        (Choice("exhaustive", "only the six commands named are judged"),
         Choice("examples", "other commands' preconditions bind the backseat too")),
        "backseat", "only the six named commands are judged (never a FAIL for one outside the list); \"before "
                    "starting a mission\" read as no mission running (RH-RD-1)"),
    Reading(
        "idle_distance", "RH-RD-5",
        "`$OSI` field 7 with no navigation target (`S`, `M` from `S`)?",
        "RH-RD-5: Field 7 is the distance to the present navigation target; with none … it is the vehicle's "
        "choice (0, or the distance to the last target) and is not judged",
        (Choice("zero", "0"), Choice("last", "the distance to the last target")),
        "judge", "field 7 is not judged there", books="RH-OUT-1", setting="idle_distance", vehicle3="last", certify=("RH-MSN-3",)),
)

BY_KEY: dict[str, Reading] = {r.key: r for r in READINGS}
#: The reference model's own reading of every row.
DEFAULTS: dict[str, str] = {r.key: r.default for r in READINGS}
#: Readings the model branches on, by the command class names they can change the answer to.
_MODEL_APPLIES: dict[str, tuple[str, ...]] = {
    "srp_bad_path": ("OMSTART",),
    "ascent_refusal_order": ("OMS", "OJW", "OPK", "OMW"),
    "omw_pitch_speed": ("OMW",),
    "stop_unloads": ("OMSTART",),
    "omload_flag": ("OMLOAD",),
}


def reading(key: str) -> Reading:
    return BY_KEY[key]


def taken(item_id: str, readings: dict) -> tuple[str, ...]:
    """``key = value`` of every reading other than the reference model's in ``readings`` that can
    change the answer to a command with sentence ID ``item_id``."""
    return tuple(f"{k} = {v}" for k, ids in _MODEL_APPLIES.items()
                 if item_id in ids and readings.get(k, DEFAULTS[k]) != DEFAULTS[k] for v in (readings[k],))


def alternatives(item_id: str, phase: str, taken: dict) -> list[tuple[str, str]]:
    """The (key, value) pairs other than ``taken``'s that may change the model's answer to a
    command with sentence ID ``item_id`` in safety ``phase`` (cheap: the judge asks at every
    command)."""
    out = []
    for key, ids in _MODEL_APPLIES.items():
        if item_id not in ids:
            continue
        if key == "ascent_refusal_order" and phase != "ascent":
            continue
        now = taken.get(key, DEFAULTS[key])
        out += [(key, v) for v in BY_KEY[key].values if v != now]
    return out


def markdown() -> str:
    """The table as a Markdown page (``docs/readings.md``, ``helmcheck docs``)."""
    out = ["# Readings: where the reference profile leaves room", "",
           "<!-- generated by `helmcheck docs` from helmcheck/model/readings.py: do not edit -->", "",
           "Where the words of the reference profile allow more than one conforming behaviour, helmcheck "
           "accepts every one of them, names the one a vehicle was seen to take in its report (a remark on "
           "the clause), and the built-in emulator can take each (`helmcheck emulate --set KEY=VALUE`): "
           "the test suite certifies it under every reading of every row. `helmcheck profile readings` "
           "prints this table.", "",
           "| clause | question | the profile's words | readings accepted (the first is the model's own) "
           "| how the judge accepts each | emulator setting | vehicle3 |",
           "|---|---|---|---|---|---|---|"]
    for r in READINGS:
        choices = "<br>".join(f"`{c.value}` — {c.means}" for c in r.choices)
        cells = [r.clause, r.question, f"“{r.words}”", choices, r.judge,
                 f"`{r.setting}`" if r.setting else "—", f"`{r.vehicle3}`" if r.vehicle3 else ""]
        out.append("| " + " | ".join(c.replace("|", "\\|").replace("\n", " ") for c in cells) + " |")
    return "\n".join(out) + "\n"


def text() -> str:
    """The table for a terminal (``helmcheck profile readings``)."""
    out = []
    for r in READINGS:
        out.append(f"{r.key} ({r.clause}): {r.question}")
        out.append(f"  the profile: \u201c{r.words}\u201d")
        for i, c in enumerate(r.choices):
            mark = " (the model's own)" if i == 0 else ""
            out.append(f"  - {c.value}{mark}: {c.means}")
        out.append(f"  judged: {r.judge}")
        if r.setting:
            out.append(f"  emulator: --set {r.setting}=VALUE" + (f"; vehicle3 takes {r.vehicle3}" if r.vehicle3 else ""))
        out.append("")
    return "\n".join(out)
