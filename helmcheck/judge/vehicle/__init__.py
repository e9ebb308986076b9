"""The vehicle observer (§1–8): one sans-IO judge of a vehicle, fed live or from a log.

* :mod:`.observer` — :class:`VehicleObserver`, the facade: wire events in, ledger findings out;
* :mod:`.lines` — what a backseat line is to a vehicle; per-line judgement of vehicle output;
* :mod:`.sent` — one backseat line as classified, and how reasons quote it;
* :mod:`.answers` — what the vehicle answered: ACK pairing, the command's effect, each ``$OSI``;
* :mod:`.deadlines` — time passing: ACK windows and give-up deadlines that run out;
* :mod:`.belief` — the mirror: the candidate states a conforming vehicle may be in;
* :mod:`.branches` — the states an answered command may have found a candidate in;
* :mod:`.brackets` — RH-TIM-1 for the mirror: how closely observations bracket a timer;
* :mod:`.candidate` — one candidate state and its bookkeeping;
* :mod:`.closure` — unseen plant events, adopted with explicit time windows;
* :mod:`.osichecks` — what a report shows beyond the mirror's fields;
* :mod:`.queuetarget` — the ``$OMW`` queue's order, from where ``W`` reports head (RH-OMW-2);
* :mod:`.blame` — which clauses a finding speaks to, and where it is booked;
* :mod:`.catalog` — what the observer knows of the vehicle's missions.
"""

from .observer import Sent, VehicleObserver

__all__ = ["VehicleObserver", "Sent"]
