"""Model coverage: how much of the reference model a run's lines reached on this vehicle.

Six dimensions, each with a universe taken from the model's tables and the profile (commands it
does not claim, and a violation when it declares no way to raise one, are left out):

* **modes** — each ``$OSI`` mode (``S N P mP A M W``) the model was in after a line or a report,
  and the safety phases (``lockout``, ``ascent``) as their own entries;
* **rows** (the *transitions*) — the rows of :data:`helmcheck.model.transitions.TABLE` met: a
  command's row is the one it meets in the state the model was in when it was sent, counted when
  the model's answer agrees with the row (accepted, or refused with the row's own error); a row
  fired by time is counted when a model timer ran out between two observations (the row it
  selects in the state before); a row fired by the plant when the model shows it applied: the
  waypoint, the queue or the phase it changes, between two observations with no command between
  them that changes the mode; a violation's when the model entered the lockout;
* **interrupt pairs** — each control mode (``mP A M W`` and the mission park ``P``) met by each
  command that changes control (RH-INT-1..3), counted when the model accepts it there;
* **timers** — each model timer (``remote`` for ``$OMS``/``$OMP``, ``opk``, ``park``, ``qpark``,
  ``lockout``, ``dvl``) that ran out;
* **boundaries** — each model timer seen by a report just *before* its deadline and again *after*
  it, within RH-TIM-1's tolerance (the exploration's own brackets, :meth:`ModelCoverage.boundary`);
* **error codes** — each (command, error) pair the model answers: the command's own code
  (:data:`~helmcheck.model.transitions.ERRORS`), 26 in the lockout, and the look-ups (1, 17, 31)
  and the ``$OPK`` distance (40).

The session feeds it every line and report of the run (:meth:`ModelCoverage.before`,
:meth:`ModelCoverage.command`, :meth:`ModelCoverage.report`), each counted for its
:attr:`~ModelCoverage.source`: ``"cases"`` while the clause cases run, ``"explore"`` while the
exploration does, nothing otherwise (a re-drive, a restore). :meth:`ModelCoverage.summary` is what
``results.json`` keeps (``stats.explore.model_coverage``): the exploration's own reach per
dimension, with what stayed uncovered and how much the cases and the exploration reached together
(``with_cases``); the exploration aims at what neither reached yet (:mod:`.aim`).

The traceability table (which rule of which clause the lines exercised) plugs in through
:func:`register_rules`: a provider given the keys the exploration reached (:meth:`ModelCoverage.keys`:
``row:21``, ``mode:mP``, ``pair:OMS@P``, ``timer:opk``, ``boundary:park/after``, ``error:OMS/20``,
``edge:<id>``) returns the rules it exercised and those it did not, and the summary then carries
a ``rules`` dimension like the others. Without one there is no such dimension.
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import Callable, Iterable, Optional

from ...grammar import decode
from ...model.transitions import (ERRORS, EVENT_OF_ACK_TYPE, GUARD_ATOMS, INTERNAL_EVENTS, MODES, TABLE,
                                  select)
from ...model.vehicle import VehicleModel
from ...profile import Profile
from ...reports.scope import model_coverage, reach_text

__all__ = ["ModelCoverage", "CONTROL_MODES", "INTERRUPTING", "TIMERS", "register_rules",
           "rules_provider", "TIMER_EVENTS"]

#: Modes an interrupt can meet: the remote controls and the mission park (RH-INT-1..3).
CONTROL_MODES = ("mP", "A", "M", "W", "P")
#: Command events that take or give up control.
INTERRUPTING = ("OMS", "OMP", "OJW", "OPK", "OMW", "OMW_CLEAR", "OMSTOP")
#: The model's timers (:mod:`helmcheck.model.timers`) and the commands that arm them.
TIMERS = {"remote": ("OMS", "OMP"), "opk": ("OPK",), "park": ("OMSTART",), "qpark": ("OMW",),
          "lockout": (), "dvl": ("ODVL",)}
#: The table event a timer running out fires, by the mode it runs out in (``dvl`` fires none).
TIMER_EVENTS = {"remote": {"A": "servo_timeout", "M": "primitive_timeout"}, "opk": "opk_expired",
                "park": "park_expired", "qpark": "queue_park_expired", "lockout": "lockout_end"}
#: The modes each needs a claimed command to be entered.
_MODE_NEEDS = {"N": "OMSTART", "P": "OMSTART", "mP": "OPK", "A": "OMS", "M": "OMP", "W": "OMW"}
#: Errors beyond each command's own that the model answers: look-ups, distance, no mission.
_EXTRA_ERRORS = {"OMLOAD": (1,), "OMSTART": (1, 17, 31), "OPK": (40,)}
#: Event → the command the profile must claim for it.
_COMMAND_OF = {"OMW_CLEAR": "OMW", "OMW_CLEAR_WP": "OMW"}
_SOURCES = ("cases", "explore")

#: The traceability table's provider (:func:`register_rules`), or None.
_RULES: Optional[Callable[[frozenset], tuple[Iterable[str], Iterable[str]]]] = None


def register_rules(provider: Optional[Callable[[frozenset], tuple[Iterable[str], Iterable[str]]]]) -> None:
    """Plug the traceability table in: ``provider(keys)`` gets the keys a run's exploration reached
    (:meth:`ModelCoverage.keys`) and returns ``(exercised, not_exercised)``, rule IDs; the summary
    then has a ``rules`` dimension. ``None`` unplugs it."""
    global _RULES
    _RULES = provider


def rules_provider():
    """The provider :func:`register_rules` plugged in, or None."""
    return _RULES


def _snapshot(model: VehicleModel) -> SimpleNamespace:
    """What the counting needs of a model state later: its mode and phase, the guard atoms the
    table reads, the timers' deadlines, the mission waypoint and queue, and the row it last applied
    (a copy, not the live model)."""
    if model.applied is None:  # from here on the model counts the rows it applies (never judged on)
        model.applied = {}
    snap = SimpleNamespace(mode=model.mode, phase=model.phase, now=model.now, last_row=model.last_row,
                           error_state=model.error_state, wp=model.mission_wp, queue=len(model.queue),
                           applied=dict(model.applied),
                           timers={n: model.timers.deadline(n) for n in model.timers.names()})
    for atom in GUARD_ATOMS:
        setattr(snap, atom, bool(getattr(model, atom, False)))
    return snap


#: The plant's events, and what shows each happened between two observations.
_PLANT = ("queue_wp_reached", "wp_reached", "surfaced")


def _plant_row(last: SimpleNamespace, now: SimpleNamespace):
    """The row a plant event applied between two observations with no command between them that
    changed the mode, read off the difference: a waypoint of the queue reached (the queue shorter),
    of the mission (the next one, or another mode), the surface (the ascent over)."""
    for ev in _PLANT:
        row = select(last.mode, last.phase, ev, last)
        if row is None:
            continue
        target = last.mode if row.target == "=" else row.target
        if ev == "surfaced":
            if last.phase == "ascent" and now.phase == "none" and now.mode == target:
                return row
        elif ev == "queue_wp_reached":
            if now.queue < last.queue and now.mode == target and now.phase == last.phase:
                return row
        elif now.mode == target and now.phase == last.phase and (now.mode != last.mode or now.wp != last.wp):
            return row
    return None


class _Reach:
    """What one source reached, per dimension."""

    def __init__(self):
        self.modes: set = set()
        self.rows: set = set()
        self.pairs: set = set()
        self.timers: set = set()
        self.bounds: set = set()
        self.errors: set = set()
        self.edges: set = set()


class ModelCoverage:
    """What a run's lines met of the model (module docstring)."""

    def __init__(self, profile: Profile):
        self.profile = profile
        claimed = set(profile.commands)
        violation = profile.trigger != "none"
        self.violation = violation

        def reachable_event(ev: str) -> bool:
            if ev in INTERNAL_EVENTS:
                return violation or ev not in ("violation", "lockout_end", "surfaced")
            return _COMMAND_OF.get(ev, ev) in claimed

        self.modes_all = {m for m in MODES if _MODE_NEEDS.get(m, "OMSTOP") in claimed or m == "S"}
        if violation:
            self.modes_all |= {"lockout", "ascent"}
        self.rows_all = {r.id for r in TABLE if reachable_event(r.event)
                         and (violation or not set(r.phases) <= {"lockout", "ascent"})}
        self.pairs_all = {(m, e) for m in CONTROL_MODES for e in INTERRUPTING if reachable_event(e)
                          and (m == "P" or _MODE_NEEDS[m] in claimed)}
        self.timers_all = {t for t, cmds in TIMERS.items()
                           if (all(_COMMAND_OF.get(c, c) in claimed for c in cmds) if cmds else violation)}
        self.bounds_all = {(t, side) for t in self.timers_all for side in ("before", "after")}
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
        #: what each source reached; :attr:`rows` and the others are the exploration's own
        self.reach = {s: _Reach() for s in _SOURCES}
        mine = self.reach["explore"]
        self.modes, self.rows, self.pairs = mine.modes, mine.rows, mine.pairs
        self.timers, self.bounds, self.errors = mine.timers, mine.bounds, mine.errors
        #: ``"cases"``, ``"explore"`` or None: what the lines fed now count for (module docstring)
        self.source: Optional[str] = None
        self._last: Optional[SimpleNamespace] = None  #: the model at the last observation

    # ------------------------------------------------------------------ feeding
    def _got(self) -> Optional[_Reach]:
        return self.reach.get(self.source) if self.source else None

    def before(self, model: VehicleModel, raw: bytes) -> Optional[tuple]:
        """What a line meets in ``model`` (the observer's state before it is sent): (event, row,
        mode) or None for a line the table has no event for. What changed since the last
        observation by time (a timer that ran out) is counted first."""
        self._observe(model)
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

    def command(self, met: Optional[tuple], expected: list, model: Optional[VehicleModel] = None) -> None:
        """Count what a sent command met (:meth:`before`), given the model's answer to it (and the
        model after it: what time changed meanwhile and, after a command that changes no mode —
        a request such as the poll, a refusal —, what the plant did)."""
        got = self._got()
        event, row, mode = met if met is not None else (None, None, None)
        ack = next((r for r in expected if type(r).__name__ == "ACK"), None)
        err = (int(ack.err) if int(ack.status) else None) if ack is not None else None
        if model is not None:
            keeps = ack is not None and (err is not None or (row is not None and row.target == "="))
            self._observe(model, plant=keeps)
        if met is None or got is None or ack is None:
            return
        if err is not None:
            got.errors.add((event if event not in ("OMW_CLEAR", "OMW_CLEAR_WP") else "OMW", err))
        if row is not None and (row.error == err if err is not None else row.error is None):
            got.rows.add(row.id)
        if err is None and mode in CONTROL_MODES and event in INTERRUPTING:
            got.pairs.add((mode, event))

    def report(self, model: VehicleModel) -> None:
        """After a report: a row time or the plant applied, the mode it shows."""
        self._observe(model)

    def _observe(self, model: VehicleModel, plant: bool = True) -> None:
        """Count what changed since the last observation: timers that ran out (and the row each
        fired in the state before), a violation, a row the plant applied (``plant``: no command
        between that changed the mode), the mode now."""
        now = _snapshot(model)
        last, self._last = self._last, now
        got = self._got()
        if got is None:
            return
        got.modes.add(now.mode)
        if now.phase != "none":
            got.modes.add(now.phase)
        if last is None:
            return
        fired = False
        if now.now is not None:
            for name, due in last.timers.items():
                if due is not None and due <= now.now + 1e-9 and now.timers.get(name) != due:
                    got.timers.add(name)
                    ev = TIMER_EVENTS.get(name)
                    ev = ev.get(last.mode) if isinstance(ev, dict) else ev
                    row = select(last.mode, last.phase, ev, last) if ev else None
                    if row is not None:
                        got.rows.add(row.id)
                        fired = True
        grew = [rid for rid, n in now.applied.items() if n > last.applied.get(rid, 0)]
        if grew or now.applied:  # the rows the model applied since (module docstring)
            got.rows.update(grew)
            return
        if now.phase == "lockout" and (last.phase != "lockout" or now.error_state != last.error_state):
            row = select(last.mode, last.phase, "violation", last)
            if row is not None:
                got.rows.add(row.id)
            return
        row = now.last_row
        if row is not None and row is not last.last_row and row.event in _PLANT:
            got.rows.add(row.id)
        elif plant and not fired:
            row = _plant_row(last, now)
            if row is not None:
                got.rows.add(row.id)

    def boundary(self, timer: str, side: str) -> None:
        got = self._got()
        if got is not None:
            got.bounds.add((timer, side))

    # ------------------------------------------------------------------ what is left
    def _dims(self, reach: _Reach) -> dict:
        return {"modes": (reach.modes, self.modes_all), "rows": (reach.rows, self.rows_all),
                "interrupt_pairs": (reach.pairs, self.pairs_all), "timers": (reach.timers, self.timers_all),
                "boundaries": (reach.bounds, self.bounds_all), "error_codes": (reach.errors, self.errors_all)}

    def uncovered(self, with_cases: bool = True) -> dict[str, set]:
        """Per dimension, what is not reached yet (by the exploration and, ``with_cases``, the cases)."""
        ex = self._dims(self.reach["explore"])
        cs = self._dims(self.reach["cases"])
        return {k: u - got - (cs[k][0] if with_cases else set()) for k, (got, u) in ex.items()}

    def keys(self) -> frozenset:
        """What the exploration reached, as keys (module docstring: the traceability table's input)."""
        r = self.reach["explore"]
        return frozenset([f"mode:{m}" for m in r.modes] + [f"row:{i}" for i in r.rows]
                         + [f"pair:{e}@{m}" for m, e in r.pairs] + [f"timer:{t}" for t in r.timers]
                         + [f"boundary:{t}/{s}" for t, s in r.bounds] + [f"error:{e}/{c}" for e, c in r.errors]
                         + [f"edge:{x}" for x in r.edges])

    # ------------------------------------------------------------------ results
    def summary(self) -> dict:
        rows = {r.id: r for r in TABLE}
        names = {
            "modes": str,
            "rows": lambda i: (f"row {i}: {'/'.join(rows[i].sources)} {rows[i].event}"
                               + (f" [{rows[i].guard_text}]" if rows[i].guard else "")
                               + (f" -> err {rows[i].error}" if rows[i].error else f" -> {rows[i].target}")),
            "interrupt_pairs": lambda p: f"{p[1]} in {p[0]}",
            "timers": str,
            "boundaries": lambda b: f"{b[0]} {b[1]}",
            "error_codes": lambda e: f"{e[0]} err {e[1]}",
        }
        order = {m: i for i, m in enumerate(MODES + ("lockout", "ascent"))}
        cases = self._dims(self.reach["cases"])
        out = {}
        for key, (got, universe) in self._dims(self.reach["explore"]).items():
            hit = got & universe
            missing = sorted(universe - got, key=lambda x: order.get(x, 99) if key == "modes" else x)
            both = (got | cases[key][0]) & universe
            out[key] = {"covered": len(hit), "of": len(universe),
                        "percent": round(100.0 * len(hit) / len(universe), 1) if universe else 100.0,
                        "uncovered": [names[key](x) for x in missing], "with_cases": len(both)}
        if _RULES is not None:
            hit, miss = (sorted(set(x)) for x in _RULES(self.keys()))
            n = len(hit) + len(miss)
            out["rules"] = {"covered": len(hit), "of": n, "percent": round(100.0 * len(hit) / n, 1) if n else 100.0,
                            "uncovered": miss, "with_cases": len(hit)}
        return out

    def line(self) -> str:
        """One line for the log and the console."""
        return "model coverage: " + reach_text(model_coverage({"stats": {"explore": {"model_coverage": self.summary()}}}),
                                               with_cases=True)
