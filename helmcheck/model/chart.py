"""The vehicle as a python-statemachine statechart, generated from the transition table.

:func:`build_chart` turns :data:`~helmcheck.model.transitions.TABLE` into a ``StateChart``
class with the library's documented factory (``statemachine.io.create_machine_class_from_definition``):
one parallel state ``vehicle`` with two regions,

* ``mode``: ``S N P mP A M W`` (initial ``S``), and
* ``safety``: ``none lockout ascent`` (initial ``none``).

Each table row becomes one transition in *each* region, added in table order: in ``mode`` from
every source mode (guard: the row's phases contain the active ``safety`` state, and its guard
atoms), in ``safety`` from every listed phase (guard: the row's source modes contain the active
``mode`` state, and its guard atoms). A region leaves its state unchanged with a *targetless*
transition (refusals, ``=`` targets, rows that keep the phase). Since SCXML picks, per region,
the first enabled transition in document order, both regions pick the row
:func:`~helmcheck.model.transitions.select` picks; every transition's action records
``(region, row id)`` in ``ctx.fired`` so a test can check exactly that.

Guard atoms are read from the ``ctx`` keyword argument of ``send`` (any object with the
boolean attributes of :data:`~helmcheck.model.transitions.GUARD_ATOMS`).

The table is the one source of behaviour; the chart is that table as a statechart (for the
generated diagrams and for validation). The model dispatches through the table's index, because
the library's ``send`` costs about 0.2 ms, too slow for the ≥50 000 commands/s the model must
take. ``tests/test_model_table.py`` checks that chart and index agree for every mode, phase,
event and guard valuation.
"""

from __future__ import annotations

from functools import lru_cache
from typing import Any, Callable, Optional

from statemachine.io import create_machine_class_from_definition

from .transitions import MODES, PHASES, STAY, TABLE, Row

__all__ = ["build_chart", "VehicleChart", "chart_step", "ChartResult"]


def _atom(atom: str, want: bool) -> Callable[..., bool]:
    def cond(ctx: Any) -> bool:
        return bool(getattr(ctx, atom)) is want
    cond.__name__ = ("" if want else "not_") + atom
    return cond


def _active_in(states: tuple[str, ...]) -> Callable[..., bool]:
    wanted = frozenset(states)

    def cond(machine: Any) -> bool:
        return not wanted.isdisjoint(machine.configuration_values)
    cond.__name__ = "in_" + "_".join(states)
    return cond


def _record(region: str, row_id: int) -> Callable[..., None]:
    def on(ctx: Any) -> None:
        ctx.fired.append((region, row_id))
    on.__name__ = f"row_{row_id}_{region}"
    return on


def _transitions(row: Row, region: str) -> dict:
    guards = [_atom(a, w) for a, w in row.checks]
    if region == "mode":
        target = None if row.error is not None or row.target == STAY else row.target
        cond = [_active_in(row.phases), *guards]
    else:
        target = None if row.error is not None else row.phase_to
        cond = [_active_in(row.sources), *guards]
    return {"target": target, "cond": cond, "on": [_record(region, row.id)]}


def definition(table: tuple[Row, ...] = TABLE) -> dict:
    """The statechart as the factory's dict schema."""
    modes: dict[str, dict] = {m: {"on": {}} for m in MODES}
    phases: dict[str, dict] = {p: {"on": {}} for p in PHASES}
    modes["S"]["initial"] = True
    phases["none"]["initial"] = True
    for row in table:
        for m in row.sources:
            modes[m]["on"].setdefault(row.event, []).append(_transitions(row, "mode"))
        for p in row.phases:
            phases[p]["on"].setdefault(row.event, []).append(_transitions(row, "safety"))
    return {"vehicle": {"parallel": True, "states": {
        "mode": {"states": modes}, "safety": {"states": phases}}}}


@lru_cache(maxsize=1)
def build_chart() -> type:
    """The ``StateChart`` class of the vehicle, built from the table (cached)."""
    return create_machine_class_from_definition(
        "VehicleChart", definition(), validate_disconnected_states=False,
        validate_trap_states=False, validate_final_reachability=False)


def VehicleChart() -> Any:
    """A fresh instance of the chart (configuration ``{S, none}``)."""
    return build_chart()()


class ChartResult:
    """What the chart did for one event: the rows each region fired, and the new state."""

    __slots__ = ("mode_row", "safety_row", "mode", "phase")

    def __init__(self, mode_row: Optional[int], safety_row: Optional[int], mode: str, phase: str):
        self.mode_row, self.safety_row, self.mode, self.phase = mode_row, safety_row, mode, phase

    def __repr__(self) -> str:
        return (f"ChartResult(mode_row={self.mode_row}, safety_row={self.safety_row}, "
                f"mode={self.mode!r}, phase={self.phase!r})")


def chart_step(chart: Any, mode: str, phase: str, event: str, ctx: Any) -> ChartResult:
    """Put ``chart`` in ``(mode, phase)``, send ``event`` with ``ctx``, report what happened.

    ``ctx`` gets a fresh ``fired`` list.
    """
    chart.current_state_value = {"vehicle", "mode", "safety", mode, phase}
    ctx.fired = []
    chart.send(event, ctx=ctx)
    by_region = dict(ctx.fired)
    values = chart.configuration_values
    new_mode = next(m for m in MODES if m in values)
    new_phase = next(p for p in PHASES if p in values)
    return ChartResult(by_region.get("mode"), by_region.get("safety"), new_mode, new_phase)
