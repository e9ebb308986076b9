"""What an ``$OSI`` (and an answer) shows beyond the mirror's fields, judged against the mirror.

The mirror (:mod:`.belief`) judges mode, next waypoint, park time, error state and SRP flag.
A report carries more, and these checks use it:

* **fins and motor** (field 1): in ``M`` the commanded bytes upper-cased (RH-PRM-3); in ``S``
  reached by ``$OMSTOP`` (RH-MSN-3) or a primitive timeout from ``S`` (RH-PRM-4) neutral
  ``8080808080``;
* **the ``$OPK`` park** (RH-PK-2), judged from each ``mP`` report after an accepted ``$OPK`` —
  its minutes and the report's fields 7 and 10 alone, so the verdict does not wait on the mirror
  (:class:`_OpkPark`): field 10 below minutes×60 says when the count began (it is rounded up,
  RH-RD-5, within the RH-TIM-1 tolerance). The count must not have begun before the ``$OPK``; it
  must have begun on station: a report showing the count while field 7 is over ``on_station_m``,
  with no report on station since the ``$OPK``, fails when no moment of that interval is one at
  which the vehicle can have been on station, given every such report and the fastest it can go
  (``max_speed_kn``, or the speed it reports): a vehicle that arrived between two reports and
  drifted a little since is not failed — the profile does not say it must stay within
  ``on_station_m`` while it counts. Seen on station, it must count within
  :data:`~helmcheck.judge.timing.PLANT_REACT_S` (+ tolerance and slack);
* **on station** (field 7, the distance to the navigation target, RH-RD-5): a vehicle that
  reports itself within ``on_station_m`` of its target for longer than
  :data:`~helmcheck.judge.timing.PLANT_REACT_S` (+ RH-TIM-1 tolerance and slack) without acting
  fails the clause of the act it owes: the queued waypoint (RH-OMW-4), the mission's end at its
  last waypoint (RH-MSN-4; a waypoint of a mission of unknown length: RH-OUT-4), a mission park
  resumed after remote control that counts only once back on station (RH-INT-2);
* **the ``$OMW`` queue's order** (field 7 in ``W``, RH-OMW-2): :mod:`.queuetarget`;
* **the way made** (fields 4, 5, 6 and 7): every report's position, and field 7 in ``N``/``P`` at
  the mission's next waypoint, are kept on the mirror's candidates (``fix_seen``, ``nav_seen``)
  for the closure to tell whether an unseen waypoint reached is physically possible (RH-INT-2:
  released to the waypoint it was heading for, which it cannot have reached yet);
* **at the surface** (field 15, depth): the at-surface action must be taken at the surface
  (RH-SAF-4: checked on the report that shows it), and a vehicle at the surface in the ascent for
  longer than the same allowance without taking it fails RH-SAF-4;
* **``$OPOS``** (RH-POS-2): a candidate that applied an accepted ``$OPOS`` position keeps it as
  its latest position (``fix_seen``) and forgets the distance it last reported (``nav_seen``): it
  moved there at once (and the ``$OMW`` queue's heads forget where they were last seen,
  :meth:`~.queuetarget.QueueTarget.moved`, as the ``$OPK`` park forgets the reports that showed
  the vehicle away from its position). After an accepted ``$OPOS`` the next report's position is where the
  mirror says (moved to the given position without a GPS fix, not moved with one) — judged only
  when the two readings are far enough apart to tell; every later ``$OCTD`` shows the
  conductivity and temperature it gave;
* **``$ORWSET``** (RH-SET-1, RH-SET-2): the reply's form; a read shows what was written in this
  record (a setting never written is learnt from its first read — the vehicle's own settings are
  not assumed); ``SafetyAction`` read or written is what the mirror's models use (RH-SAF-4);
* **``$OXFLT``** (RH-SAF-5): the next report shows the code raised, with no ACK; a safety code
  shown in the lockout passes RH-SAF-1's field-8 part.
"""

from __future__ import annotations

import math
from decimal import Decimal, InvalidOperation
from typing import Optional

from ...grammar import sentences as s
from ...model.geo import KNOT_MPS, distance_m
from ...model.plant import NEUTRAL
from ...model.timers import tolerance
from ..timing import PLANT_REACT_S
from .closure import VERTICAL_MPS, osi_depth_m, osi_numbers
from .queuetarget import QueueTarget

__all__ = ["OsiChecks"]

#: Metres below which an ``$OPOS`` position cannot be told from where the vehicle already was.
_POS_DECIDABLE_M = 30.0
#: Reports away from the park position kept per ``$OPK`` (the latest; enough to time a count).
_AWAY_KEPT = 32
#: Accepted commands after which the ``mP`` reports are no longer about the ``$OPK`` park.
_ENDS_PARK = (s.OMS, s.OMP, s.OMW, s.OMWClear, s.OJW, s.OMSTOP, s.OMSTART, s.OMSTARTPaper)


class _OpkPark:
    """An accepted ``$OPK`` (RH-PK-2): its park seconds, when it was sent (vehicle seconds), the
    reports that showed the vehicle away from its position ``(earliest, latest, metres)``, the
    ``$OPOS`` positions applied since (RH-POS-2: each moved it at once), the fastest the vehicle
    can go (knots), when it was first reported on station."""

    __slots__ = ("seconds", "v0", "away", "knots", "on", "passed", "failed", "jumps")

    def __init__(self, seconds: int, v0: float):
        self.seconds, self.v0 = seconds, v0
        self.away: list[tuple[float, float, float]] = []
        self.knots = 0.0
        self.on: Optional[float] = None
        self.passed = self.failed = False
        #: (earliest, latest) vehicle seconds of each ``$OPOS`` position applied since (RH-POS-2):
        #: the vehicle was moved at once, so a report on one side says nothing of the other
        self.jumps: list[tuple[float, float]] = []

    def moved(self, early: float, late: float) -> None:
        self.jumps.append((early, late))

    def possible(self, begin: tuple[float, float], radius: float) -> bool:
        """:func:`_possible` for each stretch between the moves (:attr:`jumps`), with the reports
        of that stretch: whether the vehicle can have been on station at some moment of ``begin``."""
        mps = self.knots * KNOT_MPS
        cuts = [-math.inf] + [j for jump in self.jumps for j in jump] + [math.inf]
        for i in range(0, len(cuts), 2):
            a, b = cuts[i], cuts[i + 1]  # a stretch with no move inside it
            part = (max(begin[0], a), min(begin[1], b))
            if part[0] > part[1] + 1e-9:
                continue
            away = [x for x in self.away if a <= x[0] and x[1] <= b]
            if _possible(part, away, mps, radius):
                return True
        for early, late in self.jumps:  # at the move itself: anywhere
            if early <= begin[1] and late >= begin[0]:
                return True
        return False


def _possible(begin: tuple[float, float], away: list, mps: float, radius: float) -> bool:
    """Whether some moment of ``begin`` is one at which the vehicle can have been within
    ``radius`` of a point it was reported ``metres`` from (made between ``earliest`` and
    ``latest``), moving at most ``mps``: never closer than ``metres - radius`` of way to it."""
    lo, hi = begin
    if lo > hi + 1e-9:
        return True  # no interval to judge (the count and the $OPK disagree: judged apart)
    if mps <= 0:
        return not any(m > radius for _, _, m in away)
    cut = []
    for early, late, metres in away:
        r = (metres - radius) / mps  # the time it takes to come within radius
        if r > 0 and late - r < early + r:
            cut.append((late - r, early + r))  # on station at none of these moments
    at = lo
    for a, b in sorted(cut):
        if a >= at:  # a moment not cut (open intervals: their ends are possible)
            break
        at = max(at, b)
        if at > hi:
            return False
    return at <= hi


class OsiChecks:
    """See the module docstring; owned by a :class:`~.observer.VehicleObserver`."""

    def __init__(self, obs):
        self.o = obs
        self.oxflt: Optional[tuple[str, float]] = None
        self.ct: Optional[tuple[Decimal, Decimal]] = None
        #: the vehicle's ``$OCTD`` was seen to show what an ``$OPOS`` applied (the readings table's
        #: ``opos_ctd = reported``): from then on it is held to it
        self.ct_reported = False
        self.pos: Optional[dict] = None
        self.known: dict[str, tuple[str, ...]] = {}
        self.watch: Optional[tuple] = None  #: (key, first v on station/at surface, clause, what)
        self.park: Optional[_OpkPark] = None  #: the accepted $OPK the mP reports are judged on (RH-PK-2)
        self.shown_code = ""  #: field 8 of the last report (a code newly shown without $OXFLT: RH-SAF-5)
        #: the queued waypoint a W report heads for (RH-OMW-2)
        self.queue = QueueTarget(obs.ledger, obs.profile.on_station_m, obs.profile.max_speed_kn)

    # ------------------------------------------------------------------ answers
    def oxflt_sent(self, code: str, t: float) -> None:
        self.oxflt = (code, t)

    def recent(self) -> tuple[str, ...]:
        """Clauses of tester actions that explain an unexpected report (blame)."""
        return ("RH-SAF-5",) if self.oxflt is not None else ()

    def answered(self, p, a: s.ACK, res, ev: list) -> None:
        item = p.kind.item
        if a.status == 0:
            if isinstance(item, s.OPK):  # RH-RD-3: a new $OPK in mP replaces the park, restarts its count
                self.park = _OpkPark(item.minutes * 60, self.o.v(p.t) - self.o.slack_v())
            elif isinstance(item, _ENDS_PARK):
                self.park = None
        if a.status != 0 or not res.matched:
            return
        if isinstance(item, s.ORWSET):
            self._orwset(item, a, p, ev)
        elif isinstance(item, s.OPOS):
            self._opos(item, p)
        elif isinstance(item, s.OSD):
            self._octd(p, ev)

    def _orwset(self, item: s.ORWSET, a: s.ACK, p, ev: list) -> None:
        """RH-SET-1 (reply form), RH-SET-2 (read-back), ``SafetyAction`` for the mirror."""
        o = self.o
        x = a.extra
        if not (len(x) >= 2 and x[0] == item.setting and x[1].isdigit() and int(x[1]) == len(x) - 2):
            o.book("fail", ("RH-SET-1",), f"$ORWSET reply $ACK,12,0,0,{','.join(x)} is not "
                                          f"$ACK,12,0,0,<setting>,<n>,<state>,<values…>", ev, at=p)
            return
        o.ledger.passed("RH-SET-1", "the $ORWSET reply names the setting and counts its fields", ev, p.case)
        got = tuple(x[2:])
        if item.access == "W":
            want = (str(item.state), *item.values)
            if got == want:
                o.ledger.passed("RH-SET-2", f"{item.setting} written and answered as written", ev, p.case)
            else:
                o.book("fail", ("RH-SET-2",), f"wrote {item.setting} = {','.join(want)}; the reply shows "
                                              f"{','.join(got) or 'nothing'}", ev, at=p)
            self.known[item.setting] = want
        else:
            known = self.known.get(item.setting)
            if known is None:
                self.known[item.setting] = got
            elif got == known:
                o.ledger.passed("RH-SET-2", f"{item.setting} reads back {','.join(got)} as written", ev, p.case)
            else:
                o.book("fail", ("RH-SET-2",), f"{item.setting} was written {','.join(known)}; it reads back "
                                              f"{','.join(got) or 'nothing'}", ev, at=p)
        if item.setting == "SafetyAction" and len(got) >= 2 and got[1] in ("park", "srp"):
            for c in o.beliefs.cands:
                c.model.settings.write("SafetyAction", int(got[0]) if got[0] in ("0", "1") else 1, (got[1],))

    def _opos(self, item: s.OPOS, p) -> None:
        """Remember what an accepted ``$OPOS`` should have done (RH-POS-2)."""
        if item.conductivity not in (None, "") and item.temperature not in (None, ""):
            self.ct = (Decimal(str(item.conductivity)), Decimal(str(item.temperature)))
        o = self.o
        # A candidate that applied the position (no GPS fix) is there at once: the way it made
        # until now no longer bounds where it is, so an unseen waypoint reached is bounded from
        # the fix on (:func:`.closure.reachable`), not from the reports before it.
        v, late = o.v(p.t) - 2 * o.slack_v(), o.v(p.t_ack) + o.slack_v()
        moved = False
        for c in o.beliefs.cands:
            done = c.model.opos_records
            if done and done[-1].position_applied:
                speed = c.fix_seen[-1] if c.fix_seen is not None else 0.0
                c.fix_seen = (v, late, float(item.lat), float(item.lon), speed)
                c.nav_seen = None
                moved = True
        if moved:  # so is a queued waypoint reached (RH-OMW-2), or the $OPK position (RH-PK-2): the
            self.queue.moved()  # way it made bounds them no longer
            if self.park is not None:
                self.park.moved(v, late)
        last = o.last_osi
        rec = o.beliefs.primary.model.opos_records
        if last is None or not rec or last.lat is None or last.lon is None:
            return  # (where it was before is not known: the report before did not show it readably)
        self.pos = {"applied": rec[-1].position_applied, "lat": float(item.lat), "lon": float(item.lon),
                    "prev": (float(last.lat), float(last.lon)), "prev_t": o.last_osi_t, "t": p.t_ack,
                    "depth": osi_depth_m(last, o.profile.depth_unit)}

    def _octd(self, p, ev: list) -> None:
        if self.ct is None:
            return
        for sentence, cls, evd in p.data:
            if not isinstance(sentence, s.OCTD):
                continue
            try:
                ok = (abs(Decimal(str(sentence.conductivity)) - self.ct[0]) <= Decimal("0.05")
                      and abs(Decimal(str(sentence.temperature)) - self.ct[1]) <= Decimal("0.05"))
            except (InvalidOperation, TypeError):
                ok = False
            if ok:
                self.ct_reported = True
                self.o.ledger.passed("RH-POS-2", "$OCTD shows the conductivity and temperature $OPOS gave",
                                     [p.ev, evd], p.case)
            elif self.ct_reported:  # it reports what it applies (it did before): held to it
                self.o.book("fail", ("RH-POS-2",), f"$OCTD shows {sentence.conductivity} mS/cm, "
                                                   f"{sentence.temperature} °C; $OPOS gave {self.ct[0]}, "
                                                   f"{self.ct[1]} (always applied; this vehicle's $OCTD "
                                                   f"showed what an earlier $OPOS applied)", [p.ev, evd], at=p)
            else:  # "applied" may be used without being reported: $OCTD may be its own sensor's
                self.o.ledger.remark("RH-POS-2", "$OCTD does not show the conductivity and temperature $OPOS "
                                                 "gave: the vehicle may apply them without reporting them "
                                                 "(the reading opos_ctd = internal), so their use is not judged.")

    # ------------------------------------------------------------------ reports
    def after_osi(self, osi: s.OSI, p, t: float, ev: list, judged: bool, passes=frozenset()) -> None:
        o = self.o
        shown_before, self.shown_code = self.shown_code, osi.error_state
        self._way_made(osi, p, t)
        self._opk_park(osi, p, t, ev)
        if self.oxflt is not None:
            code, t_ox = self.oxflt
            self.oxflt = None
            if judged and osi.error_state == code:
                o.ledger.passed("RH-SAF-5", f"$OXFLT,{code} raised the violation at once, with no ACK", ev, p.case)
            elif not judged and osi.error_state in ("N", "") and o.v(t) - o.v(t_ox) < o.profile.lockout_s:
                # no state a conforming vehicle may be in explains a report with no code after it,
                # within the lockout it would have started: the violation was not raised (what else
                # the report shows is booked by the mirror)
                o.book("fail", ("RH-SAF-5",), f"the first report after $OXFLT,{code} shows no safety code "
                                              f"(field 8 {osi.error_state or 'empty'}): the violation was not raised",
                       ev, at=p)
        elif judged and shown_before == "N" and osi.error_state not in ("N", ""):
            # raised by the vehicle itself (its own rule, a sensor): judged like any other (RH-SAF-5)
            o.ledger.passed("RH-SAF-5", f"the vehicle raised {osi.error_state} by itself (no $OXFLT) and "
                                        f"field 8 shows it; the lockout is judged as for any violation", ev, p.case)
        if not judged:
            self.watch = None
            return
        m = o.beliefs.primary.model
        if osi.error_state != "N" and m.phase == "lockout":
            o.ledger.passed("RH-SAF-1", f"field 8 shows {osi.error_state} in the lockout", ev, p.case)
        self._actuators(osi, m, p, ev)
        self.queue.report(osi, m, o.v(p.t) - o.slack_v(), o.v(t) + o.slack_v(), ev, p.case,
                          lambda verdict, clauses, reason: o.book(verdict, clauses, reason, ev, at=p))
        self._position(osi, p, ev)
        self._surface_action(osi, passes, p, ev)
        if "RH-MSN-4" in passes:
            o.ledger.passed("RH-MSN-4", "S at the mission's end", ev, p.case)
        self._watch(osi, m, p, t, ev)

    def _actuators(self, osi: s.OSI, m, p, ev: list) -> None:
        o = self.o
        cand = o.beliefs.primary
        if osi.actuators is None:
            return  # field 1 not readable: judged on the next report that shows it
        if osi.mode == "M" and m.mode == "M" and m.primitive is not None:
            want = m.primitive.actuators.upper()
            if osi.actuators == want:
                o.ledger.passed("RH-PRM-3", f"field 1 shows the commanded {want}", ev, p.case)
            else:
                o.book("fail", ("RH-PRM-3",), f"in M field 1 shows {osi.actuators}; $OMP commanded {want}", ev, at=p)
        elif osi.mode == "S" and m.mode == "S" and cand.s_cause:
            if osi.actuators == NEUTRAL:
                if cand.s_cause == "RH-MSN-3":
                    o.ledger.passed("RH-MSN-3", "S with fins and motor neutral after $OMSTOP", ev, p.case)
            else:
                how = "$OMSTOP" if cand.s_cause == "RH-MSN-3" else "the primitive timeout"
                o.book("fail", (cand.s_cause,), f"S after {how} with fins and motor {osi.actuators}, not "
                                                f"neutral {NEUTRAL}", ev, at=p)
            cand.s_cause = ""

    def _position(self, osi: s.OSI, p, ev: list) -> None:
        """RH-POS-2: the first report after an accepted ``$OPOS``."""
        pos, self.pos = self.pos, None
        if pos is None:
            return
        o = self.o
        target = (pos["lat"], pos["lon"])
        prev = pos["prev"]
        lat, lon, speed, _, _ = osi_numbers(osi)
        if lat is None or lon is None:
            return  # the report does not show readably where it is
        here = (lat, lon)
        dt_v = max(0.0, o.v(o.t) - o.v(pos["prev_t"]))
        allow = max(speed or 0.0, o.profile.max_speed_kn) * KNOT_MPS * dt_v + 10.0
        apart = distance_m(*prev, *target)
        if apart < max(_POS_DECIDABLE_M, 3 * allow):
            return  # the two readings cannot be told apart
        fix, d0, d1 = o.profile.gps_fix_depth_m, pos["depth"], osi_depth_m(osi, o.profile.depth_unit)
        if d0 is not None and d1 is not None:
            # RH-RD-10: whether the vehicle had a fix when the $OPOS came is known from the reports
            # on either side of it; one that crossed the GPS-fix depth between them, or was rising
            # or sinking within the way it can make in that time of it, may have had either
            margin = VERTICAL_MPS * dt_v
            moving = abs(d1 - d0) > 0.02  # a vehicle holding its depth stays on its side of it
            if (d0 <= fix) != (d1 <= fix) or (moving and min(abs(d0 - fix), abs(d1 - fix)) <= margin):
                return
        near_target = distance_m(*here, *target) <= allow
        near_prev = distance_m(*here, *prev) <= allow
        if pos["applied"]:
            if near_target:
                o.ledger.passed("RH-POS-2", "without a GPS fix the $OPOS position was applied", ev, p.case)
            elif near_prev:
                o.book("fail", ("RH-POS-2",), f"without a GPS fix the $OPOS position {target[0]:.6f},"
                                              f"{target[1]:.6f} was not applied: the vehicle reports "
                                              f"{here[0]:.6f},{here[1]:.6f}", ev, at=p)
        else:
            if near_prev:
                o.ledger.passed("RH-POS-2", "with a GPS fix the $OPOS position was not applied", ev, p.case)
            elif near_target:
                o.book("fail", ("RH-POS-2",), f"with a GPS fix the $OPOS position was applied: the vehicle "
                                              f"reports {here[0]:.6f},{here[1]:.6f}", ev, at=p)

    def _surface_action(self, osi: s.OSI, passes, p, ev: list) -> None:
        """RH-SAF-4: the at-surface action is confirmed only at the surface."""
        if "RH-SAF-4" not in passes:
            return
        o = self.o
        depth = osi_depth_m(osi, o.profile.depth_unit)
        fix = o.profile.gps_fix_depth_m
        if depth is None or depth <= fix + 0.5:
            o.ledger.passed("RH-SAF-4", f"the at-surface action ({osi.mode}) taken at the surface", ev, p.case)
        else:
            o.book("fail", ("RH-SAF-4",), f"the at-surface action ({osi.mode}) taken at {depth:g} m, not at "
                                          f"the surface (≤ {fix:g} m)", ev, at=p)

    def _way_made(self, osi: s.OSI, p, t: float) -> None:
        """Keep the report's position, and its distance to the mission's next waypoint, on every
        candidate (module docstring; read by :mod:`.closure`)."""
        o = self.o
        # when the report can have been made — the earliest less the observer's slack once more,
        # for the report judged against it (its own time is known only to within that)
        v, late = o.v(p.t) - 2 * o.slack_v(), o.v(t) + o.slack_v()
        lat, lon, speed, distance, _ = osi_numbers(osi)
        if lat is None or lon is None:
            return  # a position not shown readably: the last one seen still bounds the way made
        speed = speed or 0.0
        nav = osi.mode in ("N", "P") and distance is not None
        for c in o.beliefs.cands:
            c.fix_seen = (v, late, lat, lon, speed)
            m = c.model
            if nav and m.mission is not None and m.mode == osi.mode and m.mission_wp == osi.next_waypoint:
                c.nav_seen = (m.mission.name, m.mission_wp, distance, v, lat, lon, speed)

    def _opk_park(self, osi: s.OSI, p, t: float, ev: list) -> None:
        """RH-PK-2 from an ``mP`` report after an accepted ``$OPK`` (module docstring)."""
        park = self.park
        if park is None:
            return
        if osi.mode != "mP":
            self.park = None  # the park is over (or never began): nothing more to judge of it
            return
        o = self.o
        prof = o.profile
        slack = o.slack_v()
        lo, hi = o.v(p.t) - slack, o.v(t) + slack  # when the report was made
        _, _, speed, d, _ = osi_numbers(osi)
        if d is None:
            return  # field 7 not readable: where the park counts is judged on the next report
        near = d <= prof.on_station_m  # RH-RD-5: field 7 as reported, inclusive
        secs, shown = park.seconds, osi.park_time
        park.knots = max(park.knots, prof.max_speed_kn, speed or 0.0)
        if not near:
            park.away.append((lo, hi, d))
            del park.away[:-_AWAY_KEPT]
        counted = secs - shown  # whole seconds field 10 has counted: it is rounded up (RH-RD-5)
        what = f"the $OPK park counts down (P{shown} of {secs} s)"
        if counted > 0:
            # the count began between these many seconds before the report: field 10 starts at
            # minutes×60 and is rounded up (RH-PK-2, RH-RD-5), so only the rate of the count has
            # RH-TIM-1's tolerance, over the part counted — not the whole park's
            least = counted - max(0.5, 0.05 * counted)
            most = counted + 1.0 + max(0.5, 0.05 * (counted + 1.0))
            if hi - least < park.v0 and not park.failed:
                park.failed = True
                o.book("fail", ("RH-PK-2",), f"{what} {counted} s, but the $OPK was accepted only "
                                             f"{max(0.0, hi - park.v0):.1f} s before the report (it counts "
                                             f"down from minutes×60 = {secs} s)", ev, at=p)
                return
            if not near and park.on is None and not park.failed:
                begin = (max(park.v0, lo - most), hi - least)
                if not park.possible(begin, prof.on_station_m):
                    park.failed = True
                    far = max(park.away, key=lambda a: a[2])
                    o.book("fail", ("RH-PK-2",), f"{what} {d:g} m from its position, not on station "
                                                 f"(≤ {prof.on_station_m:g} m): it began {counted} s before "
                                                 f"this report, when the vehicle cannot have been on station "
                                                 f"(reported {far[2]:g} m away at v={far[0]:.1f} s, at most "
                                                 f"{park.knots:g} kn)", ev, at=p)
                    return
        if near and park.on is None:
            park.on = hi  # seen on station: the count must run from here on (RH-PK-2)
        if park.on is not None and not park.failed:
            waited = lo - park.on
            allow = PLANT_REACT_S + tolerance(PLANT_REACT_S) + o.k * (o.jitter + o.res)
            ran = max(0, counted) + 1.0  # the most field 10 can have run (it is rounded up)
            if waited - ran - max(0.5, 0.05 * ran) > allow:
                park.failed = True
                o.book("fail", ("RH-PK-2",), f"on station since v={park.on:.1f} s ({d:g} m now), the $OPK "
                                             f"park has counted only {max(0, counted)} s (P{shown} of {secs} s) "
                                             f"in {waited:.1f} s of vehicle time (a vehicle counts down within "
                                             f"{allow:.1f} s of being on station)", ev, at=p)
                return
        if counted > 0 and (near or park.on is not None) and not park.passed and not park.failed:
            park.passed = True
            o.ledger.passed("RH-PK-2", f"counting down from {secs} s on station ({d:g} m from the park "
                                       f"position)", ev, p.case)

    def _watch(self, osi: s.OSI, m, p, t: float, ev: list) -> None:
        """On station or at the surface, and not acting (module docstring)."""
        o = self.o
        prof = o.profile
        key = None
        d = osi_numbers(osi)[3]
        if d is None:
            self.watch = None  # field 7 not readable: nothing is watched across this report
            return
        # RH-RD-5: on station means within on_station_m, inclusive, judged on field 7 as reported (a
        # vehicle that stopped 2.996 m away reports 3.00 and is on station; one still approaching
        # does not sit at that distance long enough to be watched)
        near = d <= prof.on_station_m
        depth = osi_depth_m(osi, prof.depth_unit)
        if m.phase == "ascent" and m.mode in ("N", "P") and depth is not None and depth <= prof.gps_fix_depth_m:
            # (the action shows only where a mission was frozen: in S it changes nothing a report
            # shows, and an $OMP accepted in the ascent holds the vehicle: the model defers the
            # surface until the primitive ends; neither is watched)
            key = ("surface", osi.mode)
            clause, what = ("RH-SAF-4",), f"at the surface ({depth:g} m) without its SafetyAction"
        elif m.phase != "none" or not near:
            key = None
        elif osi.mode == "W" and not m.queue_parking:
            key = ("W", m.control_generation)
            clause, what = ("RH-OMW-4",), f"on its queued waypoint ({d:g} m) without going on"
        elif osi.mode == "P" and m.mode == "P" and m.park_waiting:
            key = ("P", m.mission_wp)
            clause, what = ("RH-INT-2",), (f"back on station at its park's waypoint ({d:g} m) without its "
                                           f"mission park counting down the time left (P{osi.park_time})")
        elif osi.mode == "N" and m.mission is not None:
            key = ("N", osi.next_waypoint)
            last = not m.mission.is_open and m.mission_wp == m.mission.last
            clause = ("RH-MSN-4",) if last else (("RH-OUT-4", "RH-MSN-4") if m.mission.is_open else ("RH-OUT-4",))
            what = (f"{d:g} m from its last waypoint without ending the mission" if last else
                    f"{d:g} m from waypoint {osi.next_waypoint} without going on")
        if key is None:
            self.watch = None
            return
        v = o.v(p.t)
        if self.watch is None or self.watch[0] != key:
            self.watch = (key, o.v(t))
            return
        waited = v - self.watch[1]
        allow = PLANT_REACT_S + tolerance(PLANT_REACT_S) + o.k * (o.jitter + o.res) + o.beliefs.primary.extra_v
        if waited > allow:
            self.watch = None
            o.book("fail", clause, f"{what} for {waited:.1f} s of vehicle time (a vehicle acts within "
                                      f"{allow:.1f} s)", ev, at=p)

    def close(self) -> None:
        return None
