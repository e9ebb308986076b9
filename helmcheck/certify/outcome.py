"""What a certification hands back to its caller: :class:`Outcome`, the same for both roles.

``certify vehicle`` (:func:`helmcheck.certify.vehicle.runner.certify`) and ``certify backseat``
(:func:`helmcheck.certify.backseat.certifier.certify`) return one after writing the results
directory: the run verdict (a :class:`helmcheck.judge.verdict.Verdict` word), its reason, the exit
status the command line gives it, where the results are and ``results.json`` as a dict.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["Outcome"]


@dataclass
class Outcome:
    verdict: str
    reason: str
    exit_code: int
    report_dir: Path
    results: dict = field(default_factory=dict)
    #: ``--precision nominal`` stopped a vehicle run after its link check: the time scale at which
    #: this line judges timing to nominal precision (a vehicle helmcheck starts is run again at it)
    nominal_time_scale: float | None = None
    #: a vehicle run whose port vanished and did not come back in time: the command that goes on
    #: from the case the gap cut (``certify vehicle --resume DIR``)
    resume_command: str | None = None
