"""What an ``$OSI`` (and an answer) shows beyond the mirror's fields, judged against the mirror.

The mirror (:mod:`.belief`) judges mode, next waypoint, park time, error state and SRP flag.
A report carries more, and these checks use it:

* **fins and motor** (field 1): in ``M`` the commanded bytes upper-cased (RH-PRM-3); in ``S``
  reached by ``$OMSTOP`` (RH-MSN-3) or a primitive timeout from ``S`` (RH-PRM-4) neutral
  ``8080808080``;
* **on station** (field 7, the distance to the navigation target, RH-RD-5): a vehicle counting
  an ``$OPK`` park down must be on station (RH-PK-2: checked on the first report that shows the
  count, allowing the distance it may have moved since the count began); a vehicle that reports
  itself within ``on_station_m`` of its target for longer than :data:`~helmcheck.judge.timing.
  PLANT_REACT_S` (+ RH-TIM-1 tolerance and slack) without acting fails the clause of the act it
  owes: the ``$OPK`` count (RH-PK-2), the queued waypoint (RH-OMW-4), the mission's end at its
  last waypoint (RH-MSN-4; a waypoint of a mission of unknown length: RH-OUT-4);
* **at the surface** (field 15, depth): the at-surface action must be taken at the surface
  (RH-SAF-4: checked on the report that shows it), and a vehicle at the surface in the ascent for
  longer than the same allowance without taking it fails RH-SAF-4;
* **``$OPOS``** (RH-POS-2): after an accepted ``$OPOS`` the next report's position is where the
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

from decimal import Decimal, InvalidOperation
from typing import Optional

from ...grammar import sentences as s
from ...model.geo import distance_m
from ...model.plant import NEUTRAL
from ...model.timers import tolerance
from ..timing import JITTER_S, PLANT_REACT_S
from .closure import osi_depth_m

__all__ = ["OsiChecks"]

_KN = 1852.0 / 3600.0
#: Metres below which an ``$OPOS`` position cannot be told from where the vehicle already was.
_POS_DECIDABLE_M = 30.0


class OsiChecks:
    """See the module docstring; owned by a :class:`~.observer.VehicleObserver`."""

    def __init__(self, obs):
        self.o = obs
        self.oxflt: Optional[tuple[str, float]] = None
        self.ct: Optional[tuple[Decimal, Decimal]] = None
        self.pos: Optional[dict] = None
        self.known: dict[str, tuple[str, ...]] = {}
        self.watch: Optional[tuple] = None  #: (key, first v on station/at surface, clause, what)
        self.counting_checked = False

    # ------------------------------------------------------------------ answers
    def oxflt_sent(self, code: str, t: float) -> None:
        self.oxflt = (code, t)

    def recent(self) -> tuple[str, ...]:
        """Clauses of tester actions that explain an unexpected report (blame)."""
        return ("RH-SAF-5",) if self.oxflt is not None else ()

    def answered(self, p, a: s.ACK, res, ev: list) -> None:
        item = p.kind.item
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
        last = o.last_osi
        rec = o.beliefs.primary.model.opos_records
        if last is None or not rec:
            return
        self.pos = {"applied": rec[-1].position_applied, "lat": float(item.lat), "lon": float(item.lon),
                    "prev": (float(last.lat), float(last.lon)), "prev_t": o.last_osi_t, "t": p.t_ack}

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
                self.o.ledger.passed("RH-POS-2", "$OCTD shows the conductivity and temperature $OPOS gave",
                                     [p.ev, evd], p.case)
            else:
                self.o.book("fail", ("RH-POS-2",), f"$OCTD shows {sentence.conductivity} mS/cm, "
                                                   f"{sentence.temperature} °C; $OPOS gave {self.ct[0]}, "
                                                   f"{self.ct[1]} (always applied)", [p.ev, evd], at=p)

    # ------------------------------------------------------------------ reports
    def after_osi(self, osi: s.OSI, p, t: float, ev: list, judged: bool, passes=frozenset()) -> None:
        o = self.o
        if self.oxflt is not None:
            code, _ = self.oxflt
            self.oxflt = None
            if judged and osi.error_state == code:
                o.ledger.passed("RH-SAF-5", f"$OXFLT,{code} raised the violation at once, with no ACK", ev, p.case)
        if not judged:
            self.watch = None
            return
        m = o.beliefs.primary.model
        if osi.error_state != "N" and m.phase == "lockout":
            o.ledger.passed("RH-SAF-1", f"field 8 shows {osi.error_state} in the lockout", ev, p.case)
        self._actuators(osi, m, p, ev)
        self._position(osi, p, ev)
        self._surface_action(osi, passes, p, ev)
        if "RH-MSN-4" in passes:
            o.ledger.passed("RH-MSN-4", "S at the mission's end", ev, p.case)
        self._counting(osi, m, p, ev)
        self._watch(osi, m, p, t, ev)

    def _actuators(self, osi: s.OSI, m, p, ev: list) -> None:
        o = self.o
        cand = o.beliefs.primary
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
        here = (float(osi.lat), float(osi.lon))
        dt_v = max(0.0, o.v(o.t) - o.v(pos["prev_t"]))
        allow = max(float(osi.speed), o.profile.max_speed_kn) * _KN * dt_v + 10.0
        apart = distance_m(*prev, *target)
        if apart < max(_POS_DECIDABLE_M, 3 * allow):
            return  # the two readings cannot be told apart
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

    def _counting(self, osi: s.OSI, m, p, ev: list) -> None:
        """RH-PK-2: an ``$OPK`` count shown for the first time must be shown on station."""
        o = self.o
        if not (m.mode == "mP" and osi.mode == "mP" and m.opk_counting):
            self.counting_checked = False
            return
        if self.counting_checked or osi.park_time >= m.opk_seconds:
            return
        self.counting_checked = True
        d = float(osi.distance)
        since = max(0.0, (m.opk_seconds - osi.park_time) + 1.0)
        allow = o.profile.on_station_m + float(osi.speed) * _KN * since + 1.0
        if d <= allow:
            o.ledger.passed("RH-PK-2", f"counting down from {m.opk_seconds} s on station ({d:g} m from the "
                                       f"park position)", ev, p.case)
        else:
            o.book("fail", ("RH-PK-2",), f"the $OPK park counts down (P{osi.park_time}) {d:g} m from its "
                                         f"position, not on station (≤ {o.profile.on_station_m:g} m)", ev, at=p)

    def _watch(self, osi: s.OSI, m, p, t: float, ev: list) -> None:
        """On station or at the surface, and not acting (module docstring)."""
        o = self.o
        prof = o.profile
        key = None
        d = float(osi.distance)
        # RH-RD-5: on station means within on_station_m, inclusive, judged on field 7 as reported (a
        # vehicle that stopped 2.996 m away reports 3.00 and is on station; one still approaching
        # does not sit at that distance long enough to be watched)
        near = d <= prof.on_station_m
        depth = osi_depth_m(osi, prof.depth_unit)
        if m.phase == "ascent" and depth is not None and depth <= prof.gps_fix_depth_m:
            key = ("surface", osi.mode)
            clause, what = ("RH-SAF-4",), f"at the surface ({depth:g} m) without its SafetyAction"
        elif m.phase != "none" or not near:
            key = None
        elif osi.mode == "mP" and not m.opk_counting and osi.park_time >= m.opk_seconds:
            key = ("mP", m.control_generation)
            clause, what = ("RH-PK-2",), f"on station ({d:g} m) without counting its $OPK park down"
        elif osi.mode == "W" and not m.queue_parking:
            key = ("W", m.control_generation)
            clause, what = ("RH-OMW-4",), f"on its queued waypoint ({d:g} m) without going on"
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
        allow = PLANT_REACT_S + tolerance(PLANT_REACT_S) + o.k * (JITTER_S + o.res) + o.beliefs.primary.extra_v
        if waited > allow:
            self.watch = None
            o.book("fail", clause, f"{what} for {waited:.1f} s of vehicle time (a vehicle acts within "
                                      f"{allow:.1f} s)", ev, at=p)

    def close(self) -> None:
        return None
