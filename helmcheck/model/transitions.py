"""The transition table: the one source of truth for modes, lockout phases and preconditions.

Theory of operation
-------------------
The vehicle's control state is a pair *(mode, phase)*:

* **mode** — the ``$OSI`` field 2 letter: ``S N P mP A M W`` (RH-OUT-1, §3).
* **phase** — the safety episode (RH-SAF-1..4, RH-RD-11..13): ``none``; ``lockout`` (every
  command but ``$OSD`` refused with err 26 for ``lockout_s``); ``ascent`` (after the lockout,
  until the surface: only ``$OMS $OJW $OPK $OMW`` stay refused, ``$OMP`` is released). The
  *at-surface action* is the ``surfaced`` transition ``ascent → none`` (RH-SAF-4).

Every way the pair can change, and every way a command can be refused for the state it meets,
is one :class:`Row` of :data:`TABLE`: *(source modes, event, guard, target mode, error, clauses,
phases, phase target)*. For an input the **first** row, in table order, whose source modes and
phases contain the present pair and whose guard holds, decides:

* ``error`` set → the command is rejected with that error number and nothing changes;
* otherwise the mode becomes ``target`` (``=`` keeps it) and the phase ``phase_to`` (``None``
  keeps it); the model's handler for the event does the data part (set-points, queue, timers).

Guards are conjunctions of named atoms read as attributes of a context object (the
:class:`~helmcheck.model.vehicle.VehicleModel`, or any object with the same boolean
attributes); ``!atom`` negates. The atoms are listed in :data:`GUARD_ATOMS`.

Built from this table, and nowhere else: the fast dispatch index :data:`INDEX` (used by the
model on every input), the python-statemachine statechart (:mod:`helmcheck.model.chart`, used
for validation and verified by a test to pick the same row as :func:`select` for every mode,
phase, event and guard valuation) and the generated docs (``docs/model/``).

What is *not* in the table (the model's handlers do it, after the row accepted the command,
each rejecting with the command's error and no state change): field syntax and ranges
(:mod:`helmcheck.model.validate`, checked between the lockout rows and the precondition rows,
RH-RD-2), ``$OJW`` index against the running mission, ``$OLOGD`` value count against the
labels, ``$OMSTART`` with no mission loaded (17), mission file look-ups (1, 3, 31) and the
``$OPK`` distance (40). Timers that change no mode (``$ODVL``, the start of a park countdown)
are not transitions either.

Decisions (spec open)
---------------------
* A remote control and a safety violation freeze the mission (RH-RD-5): a violation shows the
  frozen mission mode (``N``/``P``) or ``S`` (RH-RD-11), the same targets as a release.
* ``$OMSTART`` accepted during the ascent (no mission running) ends the episode like
  ``$OMSTOP`` does (RH-RD-12, RH-RD-13).
* While ``$OMP`` holds depth during the ascent, reaching the surface is deferred: ``surfaced``
  has no row from ``M``; the model fires it when the primitive times out at the surface.
* A mission waypoint that has park time parks before the mission goes on — also the last
  one: the mission ends when the last waypoint is reached *and parked* (RH-MSN-4, like RH-OMW-4).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Iterable, Optional

__all__ = [
    "MODES", "REMOTE_MODES", "PHASES", "STAY", "COMMAND_EVENTS", "INTERNAL_EVENTS", "EVENTS",
    "GUARD_ATOMS", "ACK_TYPES", "ERRORS", "EVENT_OF_ACK_TYPE", "Row", "TABLE", "INDEX", "select",
    "rows_for",
]

MODES = ("S", "N", "P", "mP", "A", "M", "W")
#: Modes in which remote-helm control is active (RH-INT-1).
REMOTE_MODES = ("mP", "A", "M", "W")
PHASES = ("none", "lockout", "ascent")
NORMAL = ("none", "ascent")
ALL_PHASES = PHASES
STAY = "="

#: Command events: one per command kind. ``$OMW,Clr`` alone and ``CLEAR,<waypoint>`` are
#: separate events because RH-RD-4 gives them different targets.
COMMAND_EVENTS = ("OMS", "OMP", "OJW", "OPK", "OMW", "OMW_CLEAR", "OMW_CLEAR_WP", "OMSTOP",
                  "OMLOAD", "OMSTART", "OPOS", "OSD", "OLOGL", "OLOGD", "ORWSET", "ODVL")
#: Events from time (``advance``) and from the plant (``plant``).
INTERNAL_EVENTS = ("violation", "servo_timeout", "primitive_timeout", "opk_expired",
                   "queue_wp_reached", "queue_park_expired", "wp_reached", "park_expired",
                   "lockout_end", "surfaced")
EVENTS = COMMAND_EVENTS + INTERNAL_EVENTS

#: ACK type of each command event (RH-ACK-1, §2).
ACK_TYPES = {"OMSTOP": 1, "OMLOAD": 2, "OMSTART": 3, "OLOGD": 4, "OLOGL": 5, "OPOS": 6, "OJW": 7,
             "OSD": 8, "OMS": 9, "OMP": 10, "OPK": 11, "ORWSET": 12, "ODVL": 15, "OMW": 16,
             "OMW_CLEAR": 16, "OMW_CLEAR_WP": 16}
#: Each command's "incorrect values" error (RH-ACK-3), also used for a failed precondition (RH-ACK-4).
ERRORS = {"OPOS": 18, "OJW": 19, "OMS": 20, "OMP": 21, "OPK": 22, "ORWSET": 23, "OLOGL": 24,
          "OLOGD": 25, "OSD": 27, "OMSTOP": 28, "OMLOAD": 29, "OMSTART": 30, "ODVL": 35, "OMW": 36,
          "OMW_CLEAR": 36, "OMW_CLEAR_WP": 36}
#: The event a malformed command of a given ACK type is judged as (for the lockout rows).
EVENT_OF_ACK_TYPE = {t: e for e, t in ACK_TYPES.items() if e not in ("OMW_CLEAR", "OMW_CLEAR_WP")}

#: Guard atoms: boolean attributes of the context (the model) the table's guards read.
GUARD_ATOMS = {
    "running": "a mission is running (RH-RD-1)",
    "mission_parking": "the (frozen) mission behaviour is a mission park P (RH-INT-2)",
    "wp_parks": "the mission waypoint just reached has park time (RH-RD-5)",
    "more_wps": "the mission's next waypoint is not its last (RH-MSN-4)",
    "head_parks": "the queued waypoint just reached has park time (RH-OMW-4)",
    "queue_more": "more than one waypoint is queued (RH-OMW-4)",
    "logging": "an $OLOGL was accepted (RH-LOG-2)",
    "srp_ready": "SafetyAction is srp and an SRP mission was given at start (RH-SAF-4, RH-RD-12)",
}


@dataclass(frozen=True, slots=True)
class Row:
    """One transition (or refusal) of the vehicle. See the module docstring for the semantics."""

    id: int
    sources: tuple[str, ...]
    event: str
    guard: tuple[str, ...]
    target: str
    error: Optional[int]
    clauses: tuple[str, ...]
    phases: tuple[str, ...]
    phase_to: Optional[str]
    checks: tuple[tuple[str, bool], ...] = field(repr=False, compare=False, default=())

    @property
    def accepted(self) -> bool:
        return self.error is None

    def holds(self, ctx: Any) -> bool:
        """True when every guard atom has its wanted value on ``ctx``."""
        for atom, want in self.checks:
            if bool(getattr(ctx, atom)) is not want:
                return False
        return True

    @property
    def guard_text(self) -> str:
        return " and ".join(g.replace("!", "not ") for g in self.guard)


def _build() -> tuple[Row, ...]:
    rows: list[Row] = []

    def row(sources: Iterable[str], event: str, target: str, clauses: Iterable[str], *,
            guard: Iterable[str] = (), error: Optional[int] = None,
            phases: Iterable[str] = NORMAL, phase_to: Optional[str] = None) -> None:
        guard = tuple(guard)
        for g in guard:
            assert g.lstrip("!") in GUARD_ATOMS, g
        checks = tuple((g.lstrip("!"), not g.startswith("!")) for g in guard)
        rows.append(Row(len(rows), tuple(sources), event, guard, target, error, tuple(clauses),
                        tuple(phases), phase_to, checks))

    def resume(sources, event, clauses, *, phases=NORMAL, phase_to=None, otherwise="S",
               otherwise_error=None, otherwise_sources=None):
        """RH-INT-2: release remote control to the mission behaviour frozen at takeover."""
        row(sources, event, "P", (*clauses, "RH-INT-2"), guard=("running", "mission_parking"),
            phases=phases, phase_to=phase_to)
        row(sources, event, "N", (*clauses, "RH-INT-2"), guard=("running",), phases=phases,
            phase_to=phase_to)
        row(otherwise_sources or sources, event, otherwise if otherwise_error is None else STAY,
            (*clauses, "RH-INT-2") if otherwise_error is None else (*clauses, "RH-ACK-4"),
            error=otherwise_error, phases=phases, phase_to=None if otherwise_error else phase_to)

    everywhere = MODES
    # -- the safety lockout comes first (RH-RD-2): everything but $OSD is refused with 26
    for ev in COMMAND_EVENTS:
        if ev != "OSD":
            row(everywhere, ev, STAY, ("RH-SAF-1", "RH-SAF-2", "RH-RD-2"), error=26,
                phases=("lockout",))
    for ev in ("OMS", "OJW", "OPK", "OMW", "OMW_CLEAR", "OMW_CLEAR_WP"):
        row(everywhere, ev, STAY, ("RH-SAF-3", "RH-RD-12"), error=26, phases=("ascent",))

    # -- servo (RH-SRV-*)
    row(("N", "P", "mP", "W"), "OMS", "A", ("RH-SRV-1", "RH-SRV-3", "RH-INT-1"))
    row(("A",), "OMS", "A", ("RH-SRV-3", "RH-RD-3"))
    row(("M",), "OMS", "A", ("RH-SRV-1", "RH-INT-1", "RH-RD-1"), guard=("running",))
    row(("S", "M"), "OMS", STAY, ("RH-SRV-1", "RH-ACK-4"), error=20)
    # -- primitive (RH-PRM-*)
    row(("S", "N", "P", "mP", "A", "W"), "OMP", "M", ("RH-PRM-1", "RH-PRM-3", "RH-INT-1"),
        phases=("none",))
    row(("S", "N", "P", "mP", "A", "W"), "OMP", "M", ("RH-SAF-3", "RH-PRM-3", "RH-RD-12"),
        phases=("ascent",))
    row(("M",), "OMP", "M", ("RH-PRM-3", "RH-RD-3"))
    # -- jump (RH-JW-*)
    row(("N", "P", "mP", "A", "W"), "OJW", "N", ("RH-JW-1", "RH-JW-2"))
    row(("M",), "OJW", "N", ("RH-JW-2", "RH-RD-1"), guard=("running",))
    row(("S", "M"), "OJW", STAY, ("RH-JW-1", "RH-ACK-4"), error=19)
    # -- park (RH-PK-*)
    row(("N", "P", "A", "W"), "OPK", "mP", ("RH-PK-1", "RH-PK-2", "RH-INT-1"))
    row(("mP",), "OPK", "mP", ("RH-PK-2", "RH-RD-3"))
    row(("M",), "OPK", "mP", ("RH-PK-1", "RH-INT-1", "RH-RD-1"), guard=("running",))
    row(("S", "M"), "OPK", STAY, ("RH-PK-1", "RH-ACK-4"), error=22)
    # -- on-the-fly waypoints (RH-OMW-*)
    row(("N", "P", "mP", "A"), "OMW", "W", ("RH-OMW-1", "RH-OMW-2", "RH-OMW-5", "RH-INT-1"))
    row(("W",), "OMW", "W", ("RH-OMW-2", "RH-RD-3"))
    row(("M",), "OMW", "W", ("RH-OMW-1", "RH-OMW-5", "RH-RD-1"), guard=("running",))
    row(("S", "M"), "OMW", STAY, ("RH-OMW-1", "RH-ACK-4"), error=36)
    row(("N", "P"), "OMW_CLEAR", STAY, ("RH-OMW-3", "RH-RD-4"))
    resume(("mP", "A", "W", "M"), "OMW_CLEAR", ("RH-OMW-3", "RH-RD-4"), otherwise_error=36,
           otherwise_sources=("S", "mP", "A", "M", "W"))
    row(("N", "P", "mP", "A", "W"), "OMW_CLEAR_WP", "W", ("RH-OMW-3", "RH-RD-4", "RH-INT-1"))
    row(("M",), "OMW_CLEAR_WP", "W", ("RH-OMW-3", "RH-RD-4", "RH-RD-1"), guard=("running",))
    row(("S", "M"), "OMW_CLEAR_WP", STAY, ("RH-OMW-1", "RH-ACK-4"), error=36)
    # -- mission commands (RH-MSN-*)
    row(everywhere, "OMSTOP", "S", ("RH-MSN-3", "RH-RD-12", "RH-RD-13"), phase_to="none")
    row(("S", "M"), "OMLOAD", STAY, ("RH-MSN-1", "RH-RD-1"), guard=("!running",))
    row(everywhere, "OMLOAD", STAY, ("RH-MSN-1", "RH-ACK-4"), error=29)
    row(("S", "M"), "OMSTART", "N", ("RH-MSN-2", "RH-RD-1", "RH-RD-6", "RH-RD-13"),
        guard=("!running",), phase_to="none")
    row(everywhere, "OMSTART", STAY, ("RH-MSN-2", "RH-ACK-4"), error=30)
    # -- read/write commands (RH-POS, RH-OSD, RH-LOG, RH-SET, RH-DVL)
    row(everywhere, "OPOS", STAY, ("RH-POS-1", "RH-POS-2"))
    row(everywhere, "OSD", STAY, ("RH-OSD-1", "RH-ACK-5"), phases=ALL_PHASES)
    row(("S", "M"), "OLOGL", STAY, ("RH-LOG-1", "RH-RD-1"), guard=("!running",))
    row(everywhere, "OLOGL", STAY, ("RH-LOG-1", "RH-ACK-4"), error=24)
    row(("N", "P", "mP", "A", "M", "W"), "OLOGD", STAY, ("RH-LOG-2",), guard=("running", "logging"))
    row(everywhere, "OLOGD", STAY, ("RH-LOG-2", "RH-ACK-4"), error=25)
    row(("S", "M"), "ORWSET", STAY, ("RH-SET-1", "RH-SET-2", "RH-RD-8"), guard=("!running",))
    row(everywhere, "ORWSET", STAY, ("RH-SET-1", "RH-ACK-4"), error=23)
    row(everywhere, "ODVL", STAY, ("RH-DVL-1",))

    # -- time and plant events
    row(("S", "N", "P"), "violation", STAY, ("RH-SAF-1", "RH-RD-11"), phases=ALL_PHASES,
        phase_to="lockout")
    resume(REMOTE_MODES, "violation", ("RH-SAF-1", "RH-RD-11"), phases=ALL_PHASES,
           phase_to="lockout")
    resume(("A",), "servo_timeout", ("RH-SRV-4",))
    resume(("M",), "primitive_timeout", ("RH-PRM-4", "RH-RD-12"))
    resume(("mP",), "opk_expired", ("RH-PK-3", "RH-INT-3"))
    row(("W",), "queue_wp_reached", "W", ("RH-OMW-4",), guard=("head_parks",), phases=("none",))
    row(("W",), "queue_wp_reached", "W", ("RH-OMW-2", "RH-OMW-4"), guard=("queue_more",),
        phases=("none",))
    resume(("W",), "queue_wp_reached", ("RH-OMW-4",), phases=("none",))
    row(("W",), "queue_park_expired", "W", ("RH-OMW-4",), guard=("queue_more",), phases=("none",))
    resume(("W",), "queue_park_expired", ("RH-OMW-4",), phases=("none",))
    row(("N",), "wp_reached", "P", ("RH-RD-5",), guard=("wp_parks",), phases=("none",))
    row(("N",), "wp_reached", "N", ("RH-OUT-4",), guard=("more_wps",), phases=("none",))
    row(("N",), "wp_reached", "S", ("RH-MSN-4",), phases=("none",))
    row(("P",), "park_expired", "N", ("RH-RD-5",), guard=("more_wps",), phases=("none",))
    row(("P",), "park_expired", "S", ("RH-MSN-4",), phases=("none",))
    row(everywhere, "lockout_end", STAY, ("RH-SAF-1", "RH-SAF-3", "RH-RD-12"), phases=("lockout",),
        phase_to="ascent")
    row(("S",), "surfaced", "S", ("RH-SAF-4", "RH-RD-12"), phases=("ascent",), phase_to="none")
    row(("N", "P"), "surfaced", "N", ("RH-SAF-4",), guard=("srp_ready",), phases=("ascent",),
        phase_to="none")
    row(("N", "P"), "surfaced", "P", ("RH-SAF-4", "RH-RD-12"), phases=("ascent",),
        phase_to="none")
    return tuple(rows)


TABLE: tuple[Row, ...] = _build()


def _index(table: tuple[Row, ...]) -> dict[tuple[str, str, str], tuple[Row, ...]]:
    index: dict[tuple[str, str, str], list[Row]] = {}
    for r in table:
        for m in r.sources:
            for ph in r.phases:
                index.setdefault((m, ph, r.event), []).append(r)
    return {k: tuple(v) for k, v in index.items()}


#: (mode, phase, event) → candidate rows in table order: the fast dispatch.
INDEX: dict[tuple[str, str, str], tuple[Row, ...]] = _index(TABLE)


def rows_for(mode: str, phase: str, event: str) -> tuple[Row, ...]:
    """The candidate rows for a state and an event, in table order."""
    return INDEX.get((mode, phase, event), ())


def select(mode: str, phase: str, event: str, ctx: Any) -> Optional[Row]:
    """The row that decides ``event`` in ``(mode, phase)``: the first whose guard holds on ``ctx``.

    ``None`` means the event does not apply (only possible for time and plant events: every
    command has a row in every state, which ``tests/test_model_table.py`` checks).
    """
    for r in INDEX.get((mode, phase, event), ()):
        if r.holds(ctx):
            return r
    return None
