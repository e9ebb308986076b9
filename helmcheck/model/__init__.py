"""The reference vehicle model: a sans-IO state machine of a conforming Iver3 UVC (§2–8).

Modules, one concern each:

* :mod:`~helmcheck.model.transitions` — the transition table (the one source of truth) and its
  fast dispatch index; :mod:`~helmcheck.model.chart` — the python-statemachine statechart built
  from it; :mod:`~helmcheck.model.docs` — generated Graphviz/Markdown docs.
* :mod:`~helmcheck.model.vehicle` — :class:`VehicleModel` (``receive``/``advance``/``plant``);
  :mod:`~helmcheck.model.status` — what its state reads as (``$OSI``, data sentences, field 7);
  :mod:`~helmcheck.model.effects` — the state changes its handlers share;
  :mod:`~helmcheck.model.handlers` — what each accepted event does to the data;
  :mod:`~helmcheck.model.records` — logged rows and ``$OPOS`` outcomes.
* :mod:`~helmcheck.model.validate` — field ranges; :mod:`~helmcheck.model.settings` — the
  ``$ORWSET`` store; :mod:`~helmcheck.model.data` — data sentences; :mod:`~helmcheck.model.timers`.
* :mod:`~helmcheck.model.missions` — missions and the catalogue protocol;
  :mod:`~helmcheck.model.plant` — plant snapshot and plant events; :mod:`~helmcheck.model.events`
  — events the model reports.
* :mod:`~helmcheck.model.observe` — what a conforming vehicle may report at a time (RH-TIM-1).
* :mod:`~helmcheck.model.readings` — the readings table: the profile's open questions and every
  answer they allow (the model answers by its ``readings``; the judge accepts them all).
* :mod:`~helmcheck.model.testing` — a test mission, a catalogue and command builders;
  :mod:`~helmcheck.model.coverage` — which clauses a body of tests names;
  :mod:`~helmcheck.model.geo` — great-circle distance.
"""

from .events import ModelEvent
from .missions import (BadMission, InMemoryCatalog, Mission, MissionCatalog, MissingMission, Waypoint,
                       mission_name_problem)
from .observe import Acceptable, Expectation, expectation
from .plant import (AtSurface, OnStation, PlantEvent, PlantSnapshot, QueueWaypointReached, SafetyViolation,
                    Submerged, WaypointReached)
from .transitions import MODES, PHASES, TABLE, Row, select
from .vehicle import LogRow, OposRecord, VehicleModel

__all__ = [
    "VehicleModel", "LogRow", "OposRecord", "ModelEvent",
    "Mission", "Waypoint", "MissingMission", "BadMission", "MissionCatalog", "InMemoryCatalog",
    "mission_name_problem",
    "PlantSnapshot", "PlantEvent", "WaypointReached", "OnStation", "QueueWaypointReached", "AtSurface",
    "Submerged", "SafetyViolation",
    "Expectation", "Acceptable", "expectation",
    "MODES", "PHASES", "TABLE", "Row", "select",
]
