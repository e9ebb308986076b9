"""The emulated vehicle's own safety rules that trip by themselves (RH-SAF-5).

A real UVC raises a safety violation when one of its rules trips, whatever the backseat does.
The one rule a certification can plan for without a test extension is a mission's **Maximum
Operation Time**: it fires a known time after the mission starts, so a bench user can name such
a mission in the profile (``violation_trigger = "mission-rule"``, ``violation_mission``,
``violation_after_s``) and helmcheck waits for it. The emulator reads the rule from the mission
file (``max_time_s``, :mod:`.missionfile`).

:class:`OperationTimeRule` is sans-IO: the core tells it, after every model change, which mission
runs (:meth:`observe`); it says when the rule is due (:attr:`due_v`, vehicle seconds) and the
violation to raise then (:meth:`fire`: ``Stl``, time limit). A mission started again (a new
``$OMSTART``) starts the clock again; a stopped mission cancels it; the rule fires once per start.
"""

from __future__ import annotations

from typing import Any, Optional

from ..model.plant import SafetyViolation

__all__ = ["OperationTimeRule", "TIME_LIMIT_CODE"]

#: The §7 code of a time-limit violation (Maximum Operation Time).
TIME_LIMIT_CODE = "Stl"


class OperationTimeRule:
    """See the module docstring."""

    def __init__(self) -> None:
        self._mission: Any = None
        self.due_v: Optional[float] = None

    def observe(self, model: Any, v: float) -> None:
        """The model changed at vehicle time ``v``: a mission started, stopped or goes on."""
        mission = model.mission if model.running else None
        if mission is self._mission:
            return
        self._mission = mission
        limit = getattr(mission, "max_time_s", None) if mission is not None else None
        self.due_v = v + limit if limit else None

    def fire(self) -> SafetyViolation:
        """The rule tripped: the violation to tell the model (once per mission start)."""
        self.due_v = None
        return SafetyViolation(TIME_LIMIT_CODE)
