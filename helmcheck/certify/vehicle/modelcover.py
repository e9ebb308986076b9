"""Model coverage: how much of the reference model an exploration exercised.

Four dimensions, each with a universe taken from the model's tables and the profile (commands
it does not claim, and a violation when it declares no way to raise one, are left out):

* **rows** — the rows of :data:`helmcheck.model.transitions.TABLE` met: a command's row is the
  one it meets in the state the model was in when it was sent, counted when the model's answer
  agrees with the row (accepted, or refused with the row's own error); a row fired by time or
  the plant is counted when the model shows it applied after a report;
* **interrupt pairs** — each control mode (``mP A M W`` and the mission park ``P``) met by each
  command that changes control (RH-INT-1..3), counted when the model accepts it there;
* **boundaries** — each model timer (``remote`` for ``$OMS``/``$OMP``, ``opk``, ``park``,
  ``qpark``, ``lockout``, ``dvl``) seen by a report just *before* its deadline and again *after*
  it, within RH-TIM-1's tolerance;
* **error codes** — each (command, error) pair the model answers: the command's own code
  (:data:`~helmcheck.model.transitions.ERRORS`), 26 in the lockout, and the look-ups (1, 17, 31)
  and the ``$OPK`` distance (40).

The exploration feeds it (:meth:`ModelCoverage.command`, :meth:`ModelCoverage.report`,
:meth:`ModelCoverage.boundary`); :meth:`ModelCoverage.summary` is what ``results.json`` keeps
(``stats.explore.model_coverage``) and the report shows beside the clause coverage.
"""

from __future__ import annotations

from typing import Optional

from ...grammar import decode
from ...model.transitions import ERRORS, EVENT_OF_ACK_TYPE, INTERNAL_EVENTS, TABLE
from ...model.vehicle import VehicleModel
from ...profile import Profile

__all__ = ["ModelCoverage", "CONTROL_MODES", "INTERRUPTING", "TIMERS"]

#: Modes an interrupt can meet: the remote controls and the mission park (RH-INT-1..3).
CONTROL_MODES = ("mP", "A", "M", "W", "P")
#: Command events that take or give up control.
INTERRUPTING = ("OMS", "OMP", "OJW", "OPK", "OMW", "OMW_CLEAR", "OMSTOP")
#: The model's timers (:mod:`helmcheck.model.timers`) and the commands that arm them.
TIMERS = {"remote": ("OMS", "OMP"), "opk": ("OPK",), "park": ("OMSTART",), "qpark": ("OMW",),
          "lockout": (), "dvl": ("ODVL",)}
#: Errors beyond each command's own that the model answers: look-ups, distance, no mission.
_EXTRA_ERRORS = {"OMLOAD": (1,), "OMSTART": (1, 17, 31), "OPK": (40,)}
#: Event → the command the profile must claim for it.
_COMMAND_OF = {"OMW_CLEAR": "OMW", "OMW_CLEAR_WP": "OMW"}


class ModelCoverage:
    """What the exploration met of the model (module docstring)."""

    def __init__(self, profile: Profile):
        self.profile = profile
        claimed = set(profile.commands)
        violation = profile.trigger != "none"

        def reachable_event(ev: str) -> bool:
            if ev in INTERNAL_EVENTS:
                return violation or ev not in ("violation", "lockout_end", "surfaced")
            return _COMMAND_OF.get(ev, ev) in claimed

        self.rows_all = {r.id for r in TABLE if reachable_event(r.event)
                         and (violation or not set(r.phases) <= {"lockout", "ascent"})}
        self.pairs_all = {(m, e) for m in CONTROL_MODES for e in INTERRUPTING if reachable_event(e)}
        self.bounds_all = {(t, side) for t, cmds in TIMERS.items()
                           if (all(_COMMAND_OF.get(c, c) in claimed for c in cmds) if cmds else violation)
                           for side in ("before", "after")}
        errs = set()
        for ev, code in ERRORS.items():
            if reachable_event(ev) and ev not in ("OMW_CLEAR", "OMW_CLEAR_WP"):
                errs.add((ev, code))
                if violation and ev != "OSD":
                    errs.add((ev, 26))
        for ev, codes in _EXTRA_ERRORS.items():
            if reachable_event(ev):
                errs.update((ev, c) for c in codes)
        self.errors_all = errs
        self.rows: set = set()
        self.pairs: set = set()
        self.bounds: set = set()
        self.errors: set = set()

    # ------------------------------------------------------------------ feeding
    def before(self, model: VehicleModel, raw: bytes) -> Optional[tuple]:
        """What a line meets in ``model`` (the observer's state before it is sent): (event, row,
        mode) or None for a line the table has no event for."""
        d = decode(raw, self.profile)
        item = d.sentence
        if item is None:  # refused for its fields: the command's own error, no row
            ack_type = getattr(d.error, "ack_type", None)
            event = EVENT_OF_ACK_TYPE.get(ack_type) if ack_type is not None else None
            return None if event is None else (event, None, model.mode)
        event = VehicleModel.event_of(item)
        if event is None:
            return None
        return event, model.row_for(item), model.mode

    def command(self, met: Optional[tuple], expected: list) -> None:
        """Count what a sent command met (:meth:`before`), given the model's answer to it."""
        if met is None:
            return
        event, row, mode = met
        ack = next((r for r in expected if type(r).__name__ == "ACK"), None)
        if ack is None:
            return
        err = int(ack.err) if int(ack.status) else None
        if err is not None:
            self.errors.add((event if event not in ("OMW_CLEAR", "OMW_CLEAR_WP") else "OMW", err))
        if row is not None and (row.error == err if err is not None else row.error is None):
            self.rows.add(row.id)
        if err is None and mode in CONTROL_MODES and event in INTERRUPTING:
            self.pairs.add((mode, event))

    def report(self, model: VehicleModel) -> None:
        """After a report: a row time or the plant applied."""
        row = model.last_row
        if row is not None and row.event in INTERNAL_EVENTS:
            self.rows.add(row.id)

    def boundary(self, timer: str, side: str) -> None:
        self.bounds.add((timer, side))

    # ------------------------------------------------------------------ results
    def summary(self) -> dict:
        def dim(got: set, universe: set, name) -> dict:
            hit = got & universe
            missing = sorted(universe - got)  # by value: row 2 before row 10
            return {"covered": len(hit), "of": len(universe),
                    "percent": round(100.0 * len(hit) / len(universe), 1) if universe else 100.0,
                    "uncovered": [name(x) for x in missing]}
        rows = {r.id: r for r in TABLE}
        return {
            "rows": dim(self.rows, self.rows_all,
                        lambda i: f"row {i}: {'/'.join(rows[i].sources)} {rows[i].event}"
                                  + (f" [{rows[i].guard_text}]" if rows[i].guard else "")
                                  + (f" -> err {rows[i].error}" if rows[i].error else f" -> {rows[i].target}")),
            "interrupt_pairs": dim(self.pairs, self.pairs_all, lambda p: f"{p[1]} in {p[0]}"),
            "boundaries": dim(self.bounds, self.bounds_all, lambda b: f"{b[0]} {b[1]}"),
            "error_codes": dim(self.errors, self.errors_all, lambda e: f"{e[0]} err {e[1]}"),
        }

    def line(self) -> str:
        """One line for the log and the console."""
        s = self.summary()
        return ("model coverage: " + ", ".join(f"{k.replace('_', ' ')} {v['covered']}/{v['of']}"
                                               for k, v in s.items()))
