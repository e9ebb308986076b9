"""The oracle: the reference model mirrored from what the tester sent and saw (RH-OUT-4, RH-TIM-1).

:class:`Mirror` holds a :class:`~helmcheck.model.vehicle.VehicleModel` fed with every command
the vehicle read, at the vehicle time its ACK came back (RH-RD-15; vehicle time is wall time ×
the declared time scale k, RH-TIM-2). It answers two questions:

* :meth:`Mirror.receive` — which replies a conforming vehicle sends for a command. When the
  command lands within the RH-TIM-1 tolerance of a model timer, both sides of the race are
  acceptable: the mirror tries the state before and after the timer and keeps the one the
  vehicle's ACK shows.
* :meth:`Mirror.check_osi` — whether an ``$OSI`` is one a conforming vehicle may report at that
  moment (:func:`helmcheck.model.observe.expectation`, widened by the observer's slack: the
  poll's round trip, the ACK latency of the commands that armed the timers, scheduling jitter).

What the tester cannot see is the plant (motion). The model needs plant events (a mission
waypoint reached, on station at an ``$OPK`` position, a queued waypoint reached, the surface);
the mirror *adopts* one when, and only when, the vehicle's ``$OSI`` is explained by it and not
without it, at the earliest moment it can have happened (the previous poll). It also learns a
mission's park times from the first mission park it sees: the tester knows the test mission
only by name and waypoint count (profile ``mission``, ``mission_waypoints``), and the short
mission and the SRP mission (profile ``end_mission``, ``srp_mission``) only by name
(:class:`StubCatalog`). Those two are open-length missions until the vehicle shows their end:
an ``S`` that only "the last waypoint was the present one" explains is adopted as the end
(RH-MSN-4), judged with the same RH-OUT-4 tolerance (a mission park still running is not an end).

Decision (spec open): an ``$OPK`` countdown starts when the vehicle shows it counting (the
tester cannot see "on station"); the uncertainty this adds is part of the slack.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

from ...grammar import sentences as s
from ...model.missions import Mission, MissingMission, OpenWaypoints, Waypoint, normalise_name
from ...model.plant import OnStation, QueueWaypointReached, WaypointReached
from ...model.timers import tolerance
from ...model.vehicle import VehicleModel
from ...profile import Profile

__all__ = ["Mirror", "StubCatalog", "StubMission", "same_replies", "JITTER_S"]

#: Wall seconds of scheduling jitter the observer allows on top of what it measures.
JITTER_S = 0.03
_FT = 0.3048


@dataclass
class StubMission:
    """One mission as the tester knows it: by name, with its waypoint count when known.

    Waypoint positions are unknown (the model does not need them to judge); park times are
    learnt from observation (``None`` = not seen yet, taken as 0 until then). A mission of
    unknown length (``waypoints`` None) is an open-length mission
    (:meth:`~helmcheck.model.missions.Mission.open`) until its end is seen (RH-MSN-4):
    :meth:`ended_at` then gives it its length.
    """

    name: str
    waypoints: Optional[int] = None
    parks: dict = field(default_factory=dict)
    _cache: Optional[Mission] = None

    def mission(self) -> Mission:
        if self._cache is None:
            if self.waypoints is None:
                self._cache = Mission(self.name, _LearntOpenWaypoints(self.parks))
            else:
                self._cache = self._finite(self.waypoints)
        return self._cache

    def _finite(self, n: int) -> Mission:
        wps = tuple(Waypoint(41.52 + 0.002 * (i + 1), -71.32, 2.0, 2.0, float(self.parks.get(i) or 0.0))
                    for i in range(n))
        return Mission(self.name, wps)

    def ended_at(self, last: int) -> Mission:
        """The mission with ``last`` as its last waypoint (nothing is learnt yet)."""
        return self._finite(last + 1)

    def learn_end(self, last: int) -> None:
        """RH-MSN-4: the vehicle showed the end after waypoint ``last``."""
        if self.waypoints is None:
            self.waypoints = last + 1
            self._cache = None

    def learn_park(self, index: int, seconds: float) -> None:
        if self.parks.get(index) is None:
            self.parks[index] = max(0.0, float(seconds))
            self._cache = None

    @property
    def park_waypoint(self) -> Optional[int]:
        """The first waypoint seen to have a mission park."""
        for i in sorted(self.parks):
            if self.parks[i]:
                return i
        return None


class _LearntOpenWaypoints(OpenWaypoints):
    """Open-length waypoints (:class:`~helmcheck.model.missions.OpenWaypoints`) with the park
    times learnt so far."""

    __slots__ = ("parks",)

    def __init__(self, parks: dict):
        self.parks = dict(parks)

    def __getitem__(self, i: int) -> Waypoint:
        park = self.parks.get(i)
        return Waypoint(0.0, 0.0, park_s=float(park)) if park else self._WP


class StubCatalog:
    """The vehicle's missions as the tester knows them, by name (profile ``mission``,
    ``end_mission``, ``srp_mission``).

    The test mission has the profile's ``mission_waypoints``; the others are of unknown length
    (:class:`StubMission`). ``name``, ``waypoints``, ``parks``, :meth:`mission`,
    :meth:`learn_park` and :attr:`park_waypoint` speak of the test mission.
    """

    def __init__(self, name: str, waypoints: int, others: tuple = ()):
        self.main = StubMission(name, max(1, waypoints))
        self.entries = {name: self.main}
        for other in others:
            if other and other not in self.entries:
                self.entries[other] = StubMission(other)

    @classmethod
    def for_profile(cls, profile: Profile) -> "StubCatalog":
        others = tuple(normalise_name(n) for n in (profile.end_mission, profile.srp_mission) if n)
        return cls(normalise_name(profile.mission), profile.mission_waypoints, others)

    @property
    def name(self) -> str:
        return self.main.name

    @property
    def waypoints(self) -> int:
        return self.main.waypoints  # type: ignore[return-value]

    @property
    def parks(self) -> dict:
        return self.main.parks

    @property
    def park_waypoint(self) -> Optional[int]:
        return self.main.park_waypoint

    def mission(self) -> Mission:
        return self.main.mission()

    def learn_park(self, index: int, seconds: float) -> None:
        self.main.learn_park(index, seconds)

    def entry(self, name: str) -> Optional[StubMission]:
        """The stub of the mission called ``name``, or ``None``."""
        return self.entries.get(normalise_name(name))

    def lookup(self, name: str):
        e = self.entry(name)
        return e.mission() if e is not None else MissingMission(name)


def _key(r: s.Reply) -> tuple:
    if isinstance(r, s.ACK):
        return ("ACK", r.type, r.status, r.err)
    return (type(r).__name__,)


def same_replies(want: list, got: list) -> bool:
    """Do two reply lists agree on what is judged: ACK type/status/err, data sentence kinds."""
    return [_key(r) for r in want] == [_key(r) for r in got]


class Mirror:
    """The model mirrored from the wire. See the module docstring."""

    def __init__(self, profile: Profile, time_scale: float):
        self.profile = profile
        self.k = float(time_scale)
        self.stub = StubCatalog.for_profile(profile)
        self.model = VehicleModel(profile, self.stub)
        self.cmd_latency = 0.0  #: wall seconds: largest ACK latency since the last reset
        self.plant_slack = 0.0  #: vehicle seconds of uncertainty from adopted plant events
        self.last_obs: Optional[float] = None  #: wall time of the last judged $OSI
        self.adopted: list[str] = []
        self.alts: list[VehicleModel] = []  #: other states the vehicle may be in (see receive)

    # ------------------------------------------------------------------ housekeeping
    def v(self, t: float) -> float:
        """Vehicle seconds at link time ``t`` (RH-TIM-2)."""
        return self.k * t

    def fresh(self) -> None:
        """Forget everything but what was learnt about the mission (after a verified reset)."""
        old = self.model
        self.alts = []
        self.model = VehicleModel(self.profile, self.stub)
        # what a vehicle keeps across $OMSTOP: settings, log labels, the loaded mission
        self.model.settings = old.settings
        self.model.log_labels = old.log_labels
        self.model.loaded = old.loaded
        self.settle()

    def settle(self) -> None:
        self.cmd_latency = 0.0
        self.plant_slack = 0.0
        self.last_obs = None

    @property
    def mode(self) -> str:
        return self.model.mode

    def slack(self, wall: float) -> float:
        """Vehicle seconds of observer uncertainty for an observation with ``wall`` s of its own."""
        return self.k * (wall + self.cmd_latency + JITTER_S) + self.plant_slack

    def deadline(self, name: Optional[str] = None) -> Optional[tuple[float, float, str]]:
        """(vehicle deadline, duration, timer name) of the named (or the next) model timer."""
        return self.model.timer(name)

    # ------------------------------------------------------------------ commands
    def receive(self, item, t_ack: float, latency: float, observed: Optional[list] = None) -> list:
        """Feed ``item`` at link time ``t_ack``; returns the replies a conforming vehicle sends.

        ``observed`` (the vehicle's replies) picks the side of a timer race (RH-TIM-1); when
        neither side explains it, the nominal replies are returned and the mirror keeps them.
        """
        self.cmd_latency = max(self.cmd_latency, latency)
        vt = self.v(t_ack)
        m = self.model
        candidates = [(m.clone(), vt)]
        dl = self.deadline()
        if dl is not None:
            due, dur, _ = dl
            win = tolerance(dur, self.slack(latency))
            if abs(due - vt) <= win:
                before = min(vt, due - 1e-6)
                if m.now is None or before >= m.now:
                    candidates.append((m.clone(), before))
                candidates.append((m.clone(), max(vt, due + 1e-6)))
        if m.phase != "none":  # the vehicle may have reached the surface since it was last seen
            c = m.clone()
            c.advance(vt)
            if c.phase == "ascent":
                c.update_plant(c.snapshot.with_(depth_m=0.0))
                candidates.append((c, vt))
        results = []
        chosen = None
        for c, at in candidates:
            c.advance(at)
            c.update_plant(c.snapshot)  # a vehicle that is at the surface when its ascent starts acts at once
            replies = c.receive(item, at)
            if observed is None or same_replies(replies, observed):
                chosen = (c, replies)
                break
            results.append((c, replies))
        alts = self._alternatives(item, vt, observed)
        if chosen is None:
            if alts:  # only an unseen plant event explains the answer
                chosen, alts = alts[0], alts[1:]
            else:
                chosen = results[0]
        c, replies = chosen
        self._adopt(c, item)
        self.alts = [a for a, _ in alts][:4]
        return replies

    def _alternatives(self, item, vt: float, observed: Optional[list]) -> list:
        """States in which a plant event the tester could not see happened just before ``item``.

        They stay candidates (:attr:`alts`) until an ``$OSI`` tells them apart from the nominal:
        earlier candidates are carried through this command too (an ``$OSD`` poll between the
        command and the ``$OSI`` that settles it must not drop them).
        """
        out = []
        for base in self.alts:
            c = base.clone()
            c.advance(vt)
            replies = c.receive(item, vt)
            if observed is None or same_replies(replies, observed):
                out.append((c, replies))
        for base in [self.model] + list(self.alts):
            evs = []
            if base.mode == "N" and base.mission is not None:
                evs.append(WaypointReached())
            if base.mode in ("mP", "W"):
                evs.append(OnStation())
            for e in evs:
                c = base.clone()
                c.advance(vt)
                c.plant(e, vt)
                replies = c.receive(item, vt)
                if observed is None or same_replies(replies, observed):
                    if isinstance(item, s.OPK) and c.mode == "mP" and c.opk_counting:
                        c.await_on_station()
                    out.append((c, replies))
        return out

    def _adopt(self, c: VehicleModel, item) -> None:
        if isinstance(item, s.OPK) and c.mode == "mP" and c.opk_counting:
            c.await_on_station()  # countdown adopted when the vehicle shows it (module doc)
        self.model = c

    # ------------------------------------------------------------------ observations
    def _plant_from(self, m: VehicleModel, osi: s.OSI) -> None:
        snap = m.snapshot
        changes = {"lat": float(osi.lat), "lon": float(osi.lon), "speed_kn": float(osi.speed)}
        if osi.depth is not None:
            d = float(osi.depth)
            changes["depth_m"] = d * _FT if self.profile.depth_unit == "ft" else d
        m.update_plant(snap.with_(**changes))

    def expectation(self, t: float, wall_slack: float):
        return self.model.expectation(self.v(t), self.slack(wall_slack))

    def check_osi(self, osi: s.OSI, t: float, wall_slack: float) -> tuple[list, object]:
        """Judge an ``$OSI`` seen at link time ``t``: ``([], exp)`` or ``([(clause, msg)…], exp)``."""
        vt = self.v(t)
        slack = self.slack(wall_slack)
        self._countdown_seen(osi, vt, wall_slack)
        exp = self.model.expectation(vt, slack)
        problems = exp.check(osi)
        prev = self.last_obs
        if problems:
            adopted = self._closure(osi, t, wall_slack, prev)
            if adopted is None:
                for alt in self.alts:
                    if not alt.expectation(vt, slack).check(osi):
                        self.model = alt
                        self.adopted.append("unseen plant event before the last command")
                        adopted = "alternative"
                        break
            if adopted is not None:
                problems = []
        self.alts = []
        if not problems:
            self.last_obs = t
            if self.model.phase != "ascent":
                self._plant_from(self.model, osi)
        return problems, exp

    def _countdown_seen(self, osi: s.OSI, vt: float, wall_slack: float) -> None:
        """An ``$OPK`` park shown counting: adopt "on station" at the start the display implies."""
        m = self.model
        if not (m.mode == "mP" and osi.mode == "mP" and m.phase == "none" and not m.opk_counting
                and 0 < osi.park_time < m.opk_seconds):
            return
        start = vt - (m.opk_seconds - osi.park_time) - 0.5
        c = m.clone()
        c.plant(OnStation(), max(start, m.now if m.now is not None else start))
        self.model = c
        self.plant_slack = max(self.plant_slack, 1.0 + self.k * wall_slack)
        self.adopted.append(f"on station (countdown shown) at v={start:.1f}")

    def _closure(self, osi: s.OSI, t: float, wall_slack: float, prev: Optional[float]) -> Optional[str]:
        """Adopt the plant event that explains ``osi`` (module docstring); its name or ``None``."""
        m = self.model
        vt = self.v(t)
        tp_wall = prev if prev is not None else t
        tp = max(m.now if m.now is not None else 0.0, self.v(tp_wall))
        gap = max(0.0, vt - tp)

        learnt: list = []  #: what a build would teach the stubs, applied only if it explains osi

        def trial(name: str, build) -> Optional[str]:
            learnt.clear()
            c = build()
            if c is None:
                return None
            slack = self.slack(wall_slack) + gap
            if not c.expectation(vt, slack).check(osi):
                self.model = c
                self.plant_slack = max(self.plant_slack, gap)
                self.adopted.append(f"{name} at v={tp:.1f}")
                for learn in learnt:
                    learn()
                return name
            return None

        def surfaced():
            c = m.clone()
            c.advance(vt)
            self._plant_from(c, osi)
            c.drop_checkpoint()
            return c

        def events(*evs):
            def build():
                c = m.clone()
                for e in evs:
                    c.plant(e, tp)
                return c
            return build

        def swap(c: VehicleModel, old: Mission, mission: Mission) -> VehicleModel:
            """``c`` with the stub mission ``old`` replaced by what was learnt about it."""
            if c.mission is old:
                c.mission = mission
            if c.loaded is old:
                c.loaded = mission
            if c.srp_mission is old:
                c.srp_mission = mission
            return c

        def learn_park():
            wp = m.mission_wp
            entry = self.stub.entry(m.mission.name) if m.mission is not None else None
            if entry is None or m.mode != "N" or entry.parks.get(wp) is not None:
                return None
            if osi.mode == "P" and osi.next_waypoint == wp:
                entry.learn_park(wp, osi.park_time + gap)
            elif osi.mode == "N" and osi.next_waypoint == wp + 1:
                entry.learn_park(wp, 0.0)
            else:
                return None
            c = swap(m.clone(), m.mission, entry.mission())  # type: ignore[arg-type]
            c.plant(WaypointReached(wp), tp)
            return c

        def mission_end():
            """RH-MSN-4 for a mission of unknown length: ``S`` where its end explains it.

            The last waypoint is the one the model is at: reached now (``N``), or parked on and
            its park run out (``P``, or ``N`` just after that park ran out: the checkpoint).
            """
            run = m.mission
            if osi.mode != "S" or m.phase != "none" or run is None or not run.is_open:
                return None
            entry = self.stub.entry(run.name)
            if entry is None:
                return None
            base = m.checkpoint
            if base is not None and base.mode == "P" and base.mission is run and m.mode == "N":
                last = base.mission_wp
                c = swap(base.clone(), run, entry.ended_at(last))
            elif m.mode == "P":
                last = m.mission_wp
                c = swap(m.clone(), run, entry.ended_at(last))
            elif m.mode == "N":
                last = m.mission_wp
                c = swap(m.clone(), run, entry.ended_at(last))
                c.plant(WaypointReached(last), tp)
            else:
                return None
            learnt.append(lambda: entry.learn_end(last))
            return c

        for name, build in (("surface/depth", surfaced), ("waypoint reached", events(WaypointReached())),
                            ("learnt mission park", learn_park), ("mission end", mission_end),
                            ("on station", events(OnStation())),
                            ("queue waypoint reached", events(QueueWaypointReached())),
                            ("two waypoints reached", events(WaypointReached(), WaypointReached()))):
            got = trial(name, build)
            if got:
                return got
        return None
