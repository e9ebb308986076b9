"""The ``$OMW`` queue in arrival order, judged from where ``W`` reports say the vehicle heads (RH-OMW-2).

In ``W`` the navigation target is the first queued waypoint not yet reached, and ``$OSI`` field 7
is the distance to it (RH-OMW-2 "waypoints queue in arrival order", RH-RD-5 "field 7 is the
distance to the present navigation target"). The mirror's queue says which waypoints were queued;
it cannot see one reached (the mode stays ``W``), so :class:`QueueTarget` follows the head itself,
as the set of queued waypoints the vehicle *may* be heading for — each with the latest report at
which it may have been (its position and time) — never as one guess:

* a report's field 7 is compared with the distance from the position the same report gives
  (fields 4 and 5) to each queued waypoint, within :func:`allowance` — the rounding of the three
  fields as written, 2 % for how a vehicle computes a distance, and a second of way made at the
  fastest it can go for a field sampled a control tick apart from the position. A conforming
  vehicle's field 7 fits the waypoint it heads for; it may fit others too (a distance is no
  name: two waypoints can be as far from the vehicle);
* a waypoint that fits is one the vehicle may head for now if it may already have been heading
  for it, or if, from a report at which it may have been heading for an earlier one, it can have
  been on station at every waypoint in between since (at the fastest it can go: the profile's
  ``max_speed_kn`` or the speed it reports). Those are the heads from now on; where there is just
  one and two or more are queued, the order is exercised: RH-OMW-2 passes;
* field 7 that fits a later waypoint but none the vehicle may head for is evidence that excludes
  every conforming explanation: the queue was not kept in arrival order, RH-OMW-2 fails, naming
  the waypoint it heads for (once per queue);
* field 7 that fits no queued waypoint, or only waypoints before every head, is not judged here
  (what else the report shows is the mirror's), and changes nothing; nor is a report while the
  vehicle parks on a queued waypoint, or as the park ends (within its RH-TIM-1 tolerance the
  report may show its last moment, field 7 still the parked waypoint's distance);
* an ``$OPOS`` position applied (RH-POS-2, no GPS fix) moves the vehicle at once: the heads
  forget where they were last seen (:meth:`QueueTarget.moved`);
* the queue the mirror holds grows at its end (``$OMW`` in ``W`` appends, RH-RD-3) and loses its
  head when the mirror adopts a waypoint reached or a park on it ends: the heads follow, shifted
  (a vehicle that may have been heading for a waypoint now gone heads for the first left); a queue that is not
  such a continuation (control ended and a new queue began) sets out from where the last report
  saw the vehicle, heading for its first waypoint.

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
    """The queued waypoints a vehicle in ``W`` may be heading for (module docstring)."""

    def __init__(self, ledger, on_station_m: float, max_speed_kn: float):
        self.ledger = ledger
        self.on_station_m = on_station_m
        self.max_speed_kn = max_speed_kn
        self.queue: tuple = ()  #: the mirror's queue as last followed (empty: none followed)
        #: index in :attr:`queue` → (v, lat, lon) of the latest report at which the vehicle may have
        #: been heading for it (None: no report before the queue began)
        self.heads: dict[int, Optional[tuple[float, float, float]]] = {}
        self.booked = False  #: RH-OMW-2 failed for this queue (booked once)
        self.last: Optional[tuple[float, float, float]] = None  #: (v, lat, lon) of the last report, any mode

    def report(self, osi: s.OSI, model, v_early: float, v_late: float, ev: list, case: str, book) -> None:
        """One judged ``$OSI``, made between vehicle times ``v_early`` and ``v_late``, with the
        mirror's most plausible ``model``; ``book(verdict, clauses, reason)`` books a finding."""
        lat, lon, speed, distance, _ = osi_numbers(osi)
        if lat is None or lon is None or distance is None:
            return  # a report that does not show readably where it is says nothing of the order
        before, self.last = self.last, (v_early, lat, lon)
        if osi.mode != "W" or model.mode != "W" or model.phase != "none" or not model.queue:
            self.queue, self.heads = (), {}
            return
        queue = tuple(model.queue)
        self._follow(queue, before)
        cp = model.checkpoint
        if (model.queue_parking or osi.park_time > 0
                or (cp is not None and cp.mode == "W" and cp.queue_parking)):
            # parked on the head (as the mirror or the report says: the mirror may have ended the
            # park a little before the vehicle, within RH-TIM-1's tolerance), or the park ended
            # within the report's uncertainty: where it heads next is for the reports after it
            return
        here = (lat, lon)
        mps = max(self.max_speed_kn, speed or 0.0) * KNOT_MPS
        d7 = distance
        fits = [i for i, w in enumerate(queue)
                if abs(d7 - (d := distance_m(*here, float(w.lat), float(w.lon)))) <= allowance(osi, d, mps)]
        if not fits:
            return
        now = (v_early, *here)
        heads = {k: now for k in fits if self._possible(k, v_late, mps)}
        if heads:
            self.heads = heads
            if len(heads) == 1 and len(queue) > 1:
                k = next(iter(heads))
                self.ledger.passed("RH-OMW-2", f"field 7 ({osi.distance} m) is the distance to queued waypoint "
                                               f"{k + 1} of {len(queue)}, in arrival order", ev, case)
            return
        first = min(self.heads)
        later = [k for k in fits if k > first]
        if not later or self.booked:
            return
        k = later[0]
        j = max(h for h in self.heads if h < k)
        ahead = distance_m(*here, float(queue[j].lat), float(queue[j].lon))
        book("fail", ("RH-OMW-2",),
             f"in W field 7 shows {osi.distance} m, the distance to queued waypoint {k + 1} of {len(queue)}; "
             f"waypoint {j + 1}, queued before it, is {ahead:.0f} m away and cannot have been reached "
             f"since the vehicle was last seen heading for it, and no waypoint it may be heading for is "
             f"that far: the queue is not kept in arrival order")
        self.booked = True
        self.heads = {k: now for k in fits}  # followed from what it shows

    def moved(self) -> None:
        """An ``$OPOS`` position was applied (RH-POS-2): the vehicle is there at once, so the way
        it can have made since a head was last seen no longer bounds which waypoints it has
        reached; every later waypoint may be reached by the next report."""
        self.heads = {j: None for j in self.heads}
        if self.last is not None:
            self.last = None  # nor does the report before it say where a new queue sets out from

    def _follow(self, queue: tuple, before) -> None:
        """The heads of :attr:`queue` carried over to ``queue`` (module docstring)."""
        old = self.queue
        self.queue = queue
        if old == queue and self.heads:
            return
        n = next((n for n in range(len(old)) if queue[:len(old) - n] == old[n:]), None) if old else None
        if n is not None:
            heads = {j - n: at for j, at in self.heads.items() if j >= n}
            passed = [at for j, at in self.heads.items() if j < n]
            if passed:  # heading for one the mirror now has reached: heading for the next since
                heads.setdefault(0, None if None in passed else min(passed))
            self.heads = heads or {0: before}
            return
        self.heads, self.booked = {0: before}, False

    def _possible(self, k: int, v: float, mps: float) -> bool:
        """May the vehicle head for queued waypoint ``k`` at ``v``: it may have been already, or
        it can have been on station at every waypoint from a head before ``k`` to ``k`` since the
        report that head was last possible at."""
        if k in self.heads:
            return True
        for j, at in self.heads.items():
            if j < k and (at is None or self._reachable(j, k, at, v, mps)):
                return True
        return False

    def _reachable(self, j: int, k: int, at: tuple, v: float, mps: float) -> bool:
        v0, lat, lon = at
        path, here = 0.0, (lat, lon)
        for w in self.queue[j:k]:
            nxt = (float(w.lat), float(w.lon))
            path += max(0.0, distance_m(*here, *nxt) - self.on_station_m)
            here = nxt
        return path <= mps * max(0.0, v - v0) + self.on_station_m
