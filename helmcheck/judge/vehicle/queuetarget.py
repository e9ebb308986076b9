"""The ``$OMW`` queue in arrival order, judged from where ``W`` reports say the vehicle heads (RH-OMW-2).

In ``W`` the navigation target is the first queued waypoint not yet reached, and ``$OSI`` field 7
is the distance to it (RH-OMW-2 "waypoints queue in arrival order", RH-RD-5 "field 7 is the
distance to the present navigation target"). The mirror's queue says which waypoints were queued;
it cannot see one reached (the mode stays ``W``), so :class:`QueueTarget` follows the head itself:

* a report's field 7 is compared with the distance from the position the same report gives
  (fields 4 and 5) to each queued waypoint, within :func:`allowance` — the rounding of the three
  fields as written, 2 % for how a vehicle computes a distance, and a second of way made at the
  fastest it can go for a field sampled a control tick apart from the position;
* field 7 that fits the waypoint followed so far passes RH-OMW-2 (with two or more queued: the
  order is exercised);
* field 7 that fits a later waypoint is adopted when the vehicle can have been on station at
  every waypoint before it since it was last seen heading for the one followed (at the fastest
  it can go: the profile's ``max_speed_kn`` or the speed it reports); when it cannot, the queue
  was not kept in arrival order: RH-OMW-2 fails, naming the waypoint it heads for;
* field 7 that fits no queued waypoint is not judged here (what else the report shows is the
  mirror's).

Sans-IO; fed by :mod:`.osichecks` with every judged report.
"""

from __future__ import annotations

from decimal import Decimal
from typing import Optional

from ...grammar import sentences as s
from ...model.geo import KNOT_MPS, distance_m
from .closure import osi_numbers

__all__ = ["QueueTarget", "allowance"]

_M_PER_DEG = 111_320.0


def _half_step(x: Decimal) -> float:
    """Half the last written digit of ``x`` (its rounding)."""
    exp = x.as_tuple().exponent
    return 0.5 * 10.0 ** exp if isinstance(exp, int) else 0.0


def allowance(osi: s.OSI, dist: float, mps: float) -> float:
    """How far field 7 may lie from the distance computed from the same report (module docstring)."""
    position = (_half_step(osi.lat) + _half_step(osi.lon)) * _M_PER_DEG
    return 1.0 + position + _half_step(osi.distance) + 0.02 * dist + mps * 1.0


class QueueTarget:
    """The queued waypoint a vehicle in ``W`` is seen to head for (module docstring)."""

    def __init__(self, ledger, on_station_m: float, max_speed_kn: float):
        self.ledger = ledger
        self.on_station_m = on_station_m
        self.max_speed_kn = max_speed_kn
        self.key: Optional[tuple] = None  #: the queue followed (its remote-control generation and head)
        self.index = 0  #: the queued waypoint it heads for, in the mirror's queue
        self.seen: Optional[tuple[float, float, float]] = None  #: (v, lat, lon) when last seen heading there
        self.last: Optional[tuple[float, float, float]] = None  #: (v, lat, lon) of the last report, any mode

    def report(self, osi: s.OSI, model, v_early: float, v_late: float, ev: list, case: str, book) -> None:
        """One judged ``$OSI``, made between vehicle times ``v_early`` and ``v_late``, with the
        mirror's most plausible ``model``; ``book(verdict, clauses, reason)`` books a finding."""
        lat, lon, speed, distance, _ = osi_numbers(osi)
        if lat is None or lon is None or distance is None:
            return  # a report that does not show readably where it is says nothing of the order
        before, self.last = self.last, (v_early, lat, lon)
        if osi.mode != "W" or model.mode != "W" or model.phase != "none" or not model.queue or model.queue_parking:
            self.key = None
            return
        queue = model.queue
        key = (model.control_generation, queue[0])
        here = (lat, lon)
        if key != self.key:  # a new queue: it set out from where the last report saw it
            self.key, self.index, self.seen = key, 0, before
        mps = max(self.max_speed_kn, speed or 0.0) * KNOT_MPS
        d7 = distance
        fits = [i for i, w in enumerate(queue)
                if abs(d7 - (d := distance_m(*here, float(w.lat), float(w.lon)))) <= allowance(osi, d, mps)]
        if self.index in fits:
            if len(queue) > 1:
                self.ledger.passed("RH-OMW-2", f"field 7 ({osi.distance} m) is the distance to queued waypoint "
                                               f"{self.index + 1} of {len(queue)}, in arrival order", ev, case)
            self.seen = (v_early, *here)
            return
        later = [i for i in fits if i > self.index]
        if not later:
            return
        k = later[0]
        if self.seen is None or self._can_have_reached(queue, k, v_late, mps):
            self.index, self.seen = k, (v_early, *here)
            return
        ahead = distance_m(*here, float(queue[self.index].lat), float(queue[self.index].lon))
        book("fail", ("RH-OMW-2",),
             f"in W field 7 shows {osi.distance} m, the distance to queued waypoint {k + 1} of {len(queue)}; "
             f"waypoint {self.index + 1}, queued before it, is {ahead:.0f} m away and cannot have been "
             f"reached since the vehicle was last seen heading for it: the queue is not kept in arrival order")
        self.key = None  # booked once for this queue

    def _can_have_reached(self, queue, k: int, v: float, mps: float) -> bool:
        """Every queued waypoint before ``k`` reachable (within on station) since :attr:`seen`."""
        v0, lat, lon = self.seen  # type: ignore[misc]
        path, at = 0.0, (lat, lon)
        for w in queue[self.index:k]:
            nxt = (float(w.lat), float(w.lon))
            path += max(0.0, distance_m(*at, *nxt) - self.on_station_m)
            at = nxt
        return path <= mps * max(0.0, v - v0) + self.on_station_m
