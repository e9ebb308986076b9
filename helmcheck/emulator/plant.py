"""Plant dynamics: what the emulated vehicle physically does while the model decides.

This module owns the emulator's physics; the protocol behaviour is the model's alone. Each
step reads the model's state (mode, safety phase, mission waypoint, set-points) read-only,
moves the vehicle, and returns the plant events the model must hear
(:mod:`helmcheck.model.plant`): a mission waypoint reached (mode ``N``, RH-MSN-4, RH-RD-5), on
station at the ``$OPK`` position (RH-PK-2), a queued ``$OMW`` waypoint reached (RH-OMW-4), at
the surface / submerged (RH-RD-10, RH-SAF-4). :meth:`Plant.snapshot` gives the measured values
the data sentences report (RH-OUT-1..3).

Where to go is the model's answer, never recomputed here: a goal position is the model's
``navigation_target()`` (what ``$OSI`` field 7 measures, RH-RD-5), and a new remote-control goal
(a replacing ``$OPK``, a change of the ``$OMW`` queue) is told by the model's
``control_generation``, so an arrival there is reported again.

Kinematics (a simple, deterministic vehicle; all times are *vehicle* seconds):

* Heading (magnetic, RH-RD-14) slews toward its target at ``turn_rate_dps``; the vehicle
  moves along its true heading (magnetic + declination). While turning hard it slows down
  (speed × cos of the heading error, at least 20 %), so it cannot orbit a close target.
* A target position is reached within ``on_station_m`` (3 m, RH-RD-5).
* Depth changes at ``speed × sin(max pitch)``: the mission uses ``default_max_pitch_deg``,
  ``$OMS``/``$OMW`` their own max pitch (RH-SRV-2). With no way on, the vehicle rises slowly
  (positive buoyancy) and cannot dive.
* Modes: ``S`` holds position and floats to the surface; ``N`` goes to the mission's next
  waypoint at its depth and speed; ``P`` holds (at the surface after a safety episode); ``mP``
  goes to the ``$OPK`` position and holds; ``A`` follows the ``$OMS`` heading, depth and speed;
  ``W`` goes to the first queued waypoint (negative depth = height above the bottom) and holds
  while parked on it; ``M`` obeys the ``$OMP`` bytes: motor above 0x80 drives ahead (0xFF = the
  profile's ``max_speed_kn``), yaw fins turn (0xFF = full turn rate to starboard), pitch fins
  pitch (0xFF = 30° nose down).
* Safety episode (RH-RD-11, RH-RD-12): during the lockout the vehicle stops and holds its
  depth; afterwards it rises at ``ascent_mps`` to the surface (an ``$OMP`` accepted during the
  ascent holds the depth while the motor and fins act horizontally).
* Battery: ``capacity_wh`` drained by a hotel load plus a propulsion load growing with the
  square of the speed.
* ``speed_factor`` scales every commanded speed into the speed made good (a freedom of the
  vehicle, :mod:`.freedoms`; 1 by default).

The ``$ODVL`` velocities are accepted and timed by the model but do not move the plant; the
plant's position is ground truth, corrected only by an ``$OPOS`` the model applied (RH-POS-2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Optional

from ..model.geo import EARTH_RADIUS_M, KNOT_MPS, distance_m
from ..model.plant import (AtSurface, OnStation, PlantEvent, PlantSnapshot, QueueWaypointReached,
                            Submerged, WaypointReached)
from ..profile import Profile

__all__ = ["PlantParams", "Plant", "Target"]

_FT = 0.3048


@dataclass(frozen=True)
class PlantParams:
    """Tunable physics. Defaults give an Iver3-like vehicle."""

    home_lat: float = 41.52
    home_lon: float = -71.32
    declination: float = -14.5
    turn_rate_dps: float = 15.0
    default_max_pitch_deg: float = 20.0
    buoyancy_rise_mps: float = 0.1
    ascent_mps: float = 0.3
    water_depth_m: float = 40.0
    dt: float = 0.2  #: integration step while moving
    capacity_wh: float = 1200.0
    hotel_w: float = 20.0
    propulsion_w_per_kn2: float = 8.0
    primitive_pitch_deg: float = 30.0
    start_battery_pct: float = 95.0
    start_heading: float = 90.0  #: magnetic, degrees
    speed_factor: float = 1.0  #: speed made good ÷ commanded speed (:mod:`.freedoms`)


@dataclass
class Target:
    """What the plant steers for in the present model state."""

    kind: str  #: "hold", "goto", "course", "primitive"
    depth: Optional[float] = None  #: metres; None = hold the present depth
    speed_kn: float = 0.0
    max_pitch: float = 20.0
    lat: float = 0.0
    lon: float = 0.0
    heading: Optional[float] = None  #: magnetic set-point (course)
    arrive: Optional[str] = None  #: "wp", "station", "queue": the event on arrival
    key: Any = None  #: identity of the goal, so each arrival is reported once
    rise_mps: Optional[float] = None  #: fixed vertical rate (safety ascent)
    turn_dps: float = 0.0  #: primitive turn rate


@dataclass
class Plant:
    """Vehicle state and its integration. See the module docstring."""

    profile: Profile
    params: PlantParams = field(default_factory=PlantParams)
    lat: float = 0.0
    lon: float = 0.0
    depth: float = 0.0
    heading: float = 0.0  #: magnetic
    speed_kn: float = 0.0
    pitch: float = 0.0
    x_dist: float = 0.0
    energy_wh: float = 0.0
    watts: float = 0.0
    actuators: str = "8080808080"
    _goal_key: Any = None
    _arrived: bool = False
    _remaining_cache: Any = None
    consumed: float = 0.0  #: vehicle seconds the last :meth:`step` integrated

    def __post_init__(self) -> None:
        p = self.params
        if not (self.lat or self.lon):
            self.lat, self.lon = p.home_lat, p.home_lon
        if not self.heading:
            self.heading = p.start_heading % 360.0
        if not self.energy_wh:
            self.energy_wh = p.capacity_wh * p.start_battery_pct / 100.0
        self.watts = p.hotel_w

    # ------------------------------------------------------------------ targets
    def _depth_m(self, value: float) -> float:
        return value * _FT if self.profile.depth_unit == "ft" else value

    def target(self, m: Any) -> Target:
        """What to steer for, read from the model ``m`` (a VehicleModel), read-only."""
        t = self._target(m)
        f = self.params.speed_factor
        if f != 1.0 and t.speed_kn:
            t.speed_kn *= f
        return t

    def _target(self, m: Any) -> Target:
        phase = m.phase
        mode = m.mode
        if phase == "lockout":
            return Target("hold")
        if phase == "ascent":
            if mode == "M" and m.primitive is not None:
                return self._primitive(m.primitive, hold_depth=True)
            return Target("hold", depth=0.0, rise_mps=self.params.ascent_mps)
        if mode == "S":
            return Target("hold", depth=0.0)
        if mode == "N" and m.mission is not None:
            i = m.mission_wp
            w = m.mission.waypoints[i]
            lat, lon = m.navigation_target()
            return Target("goto", depth=w.depth, speed_kn=w.speed, lat=lat, lon=lon,
                          max_pitch=self.params.default_max_pitch_deg, arrive="wp",
                          key=("wp", m.mission, i))
        if mode == "P":
            if m.park_waiting and m.mission is not None:  # back to the park's waypoint first (RH-INT-2)
                w = m.mission.waypoints[m.mission_wp]
                lat, lon = m.navigation_target()
                return Target("goto", depth=w.depth, speed_kn=w.speed, lat=lat, lon=lon,
                              max_pitch=self.params.default_max_pitch_deg, arrive="station",
                              key=("park", m.mission, m.mission_wp, m.control_generation))
            return Target("hold", depth=0.0 if m.error_state != "N" else None)
        if mode == "mP" and m.opk is not None:
            if m.opk_counting:
                return Target("hold")
            lat, lon = m.navigation_target()
            return Target("goto", speed_kn=float(m.opk.speed), lat=lat, lon=lon,
                          max_pitch=self.params.default_max_pitch_deg, arrive="station",
                          key=("opk", m.control_generation))
        if mode == "A" and m.servo is not None:
            c = m.servo
            return Target("course", depth=self._depth_m(float(c.depth)), speed_kn=float(c.speed),
                          max_pitch=float(c.max_pitch), heading=float(c.heading) % 360.0)
        if mode == "M" and m.primitive is not None:
            return self._primitive(m.primitive, hold_depth=False)
        if mode == "W" and m.queue:
            if m.queue_parking:
                return Target("hold")
            c = m.queue[0]
            d = self._depth_m(float(c.depth1))
            depth = d if d >= 0 else max(0.0, self.params.water_depth_m + d)
            lat, lon = m.navigation_target()
            return Target("goto", depth=depth, speed_kn=float(c.speed), lat=lat, lon=lon,
                          max_pitch=float(c.max_pitch), arrive="queue",
                          key=("queue", m.control_generation))
        return Target("hold")

    def _primitive(self, c: Any, hold_depth: bool) -> Target:
        b = c.actuator_bytes
        yaw = ((b[0] + b[1]) / 2.0 - 128.0) / 127.0
        pitch_cmd = ((b[2] + b[3]) / 2.0 - 128.0) / 127.0
        motor = max(0.0, (b[4] - 128.0) / 127.0)
        speed = motor * self.profile.max_speed_kn
        pitch = pitch_cmd * self.params.primitive_pitch_deg
        if hold_depth:
            depth: Optional[float] = None
        elif pitch > 0:
            depth = max(0.0, self.params.water_depth_m - 1.0)
        elif pitch < 0:
            depth = 0.0
        else:
            depth = None
        return Target("primitive", depth=depth, speed_kn=speed, max_pitch=abs(pitch),
                      turn_dps=yaw * self.params.turn_rate_dps)

    # ------------------------------------------------------------------ dynamics
    def _vertical_rate(self, t: Target) -> float:
        """Metres per second the depth may change by toward ``t.depth``."""
        if t.rise_mps is not None:
            return t.rise_mps
        speed = t.speed_kn * KNOT_MPS
        return speed * math.sin(math.radians(min(max(t.max_pitch, 0.0), 89.0)))

    def _depth_step(self, t: Target, dt: float) -> None:
        if t.depth is None:
            self.pitch = 0.0
            return
        err = t.depth - self.depth
        if abs(err) < 1e-9:
            self.pitch = 0.0
            return
        rate = self._vertical_rate(t)
        if err > 0:  # dive: needs way on
            move = min(err, rate * dt)
            self.pitch = -t.max_pitch if move > 0 else 0.0
        else:  # rise: at least the buoyancy
            move = max(err, -max(rate, self.params.buoyancy_rise_mps) * dt)
            self.pitch = t.max_pitch if rate > 0 and t.rise_mps is None else 0.0
        self.depth = max(0.0, self.depth + move)

    def _move(self, dist_m: float) -> None:
        if dist_m <= 0:
            return
        true = math.radians((self.heading + self.params.declination) % 360.0)
        dn = dist_m * math.cos(true)
        de = dist_m * math.sin(true)
        self.lat += math.degrees(dn / EARTH_RADIUS_M)
        coslat = max(1e-6, math.cos(math.radians(self.lat)))
        self.lon += math.degrees(de / (EARTH_RADIUS_M * coslat))
        if self.lon > 180.0:
            self.lon -= 360.0
        elif self.lon < -180.0:
            self.lon += 360.0
        self.lat = max(-89.9, min(89.9, self.lat))
        self.x_dist += dist_m

    def _bearing_mag(self, lat: float, lon: float) -> float:
        p1, p2 = math.radians(self.lat), math.radians(lat)
        dl = math.radians(lon - self.lon)
        y = math.sin(dl) * math.cos(p2)
        x = math.cos(p1) * math.sin(p2) - math.sin(p1) * math.cos(p2) * math.cos(dl)
        true = math.degrees(math.atan2(y, x)) % 360.0
        return (true - self.params.declination) % 360.0

    def _slew(self, want: float, dt: float) -> float:
        """Turn toward ``want`` (magnetic); returns the remaining error in degrees."""
        err = (want - self.heading + 540.0) % 360.0 - 180.0
        step = self.params.turn_rate_dps * dt
        if abs(err) <= step:
            self.heading = want % 360.0
            return 0.0
        self.heading = (self.heading + math.copysign(step, err)) % 360.0
        return err - math.copysign(step, err)

    def _drain(self, dt: float) -> None:
        p = self.params
        self.watts = p.hotel_w + p.propulsion_w_per_kn2 * self.speed_kn ** 2
        self.energy_wh = max(0.0, self.energy_wh - self.watts * dt / 3600.0)

    def _at_rest(self, t: Target) -> bool:
        if t.kind == "hold" or (t.kind == "goto" and self._arrived):
            return t.depth is None or abs(t.depth - self.depth) < 1e-9
        return False

    def sync(self, m: Any) -> Target:
        """Re-read the model's goal; a new goal may be reached (and reported) again."""
        t = self.target(m)
        if t.key != self._goal_key:
            self._goal_key = t.key
            self._arrived = False
        return t

    def step(self, m: Any, dt: float) -> list[PlantEvent]:
        """Advance ``dt`` vehicle seconds under the model ``m``; the plant events that happened.

        Integrates in sub-steps of ``params.dt`` while moving, in one go while at rest. Stops
        early at the first event (the caller tells the model and calls again for the rest);
        :attr:`consumed` says how much of ``dt`` was used.
        """
        self.consumed = 0.0
        events: list[PlantEvent] = []
        t = self.sync(m)
        if self._at_rest(t):
            self.speed_kn = 0.0
            self.pitch = 0.0
            self._actuators(t, 0.0)
            self._drain(dt)
            self.consumed = dt
            return events
        fix = self.profile.gps_fix_depth_m
        left = dt
        while left > 1e-12:
            h = min(self.params.dt, left)
            was_surface = self.depth <= fix
            err = self._horizontal(t, h)
            self._depth_step(t, h)
            self._drain(h)
            self._actuators(t, err)
            left -= h
            self.consumed += h
            if t.arrive is not None and not self._arrived:
                if distance_m(self.lat, self.lon, t.lat, t.lon) <= self.profile.on_station_m:
                    self._arrived = True
                    events.append(_ARRIVE[t.arrive](t))
            now_surface = self.depth <= fix
            if now_surface != was_surface:
                events.append(AtSurface() if now_surface else Submerged(self.depth))
            if events:
                break
        return events

    def _horizontal(self, t: Target, h: float) -> float:
        """Heading and position over ``h`` seconds; returns the heading error left (degrees)."""
        if t.kind == "hold":
            self.speed_kn = 0.0
            return 0.0
        if t.kind == "primitive":
            self.heading = (self.heading + t.turn_dps * h) % 360.0
            self.speed_kn = t.speed_kn
            self._move(t.speed_kn * KNOT_MPS * h)
            return 0.0
        if t.kind == "course":
            err = self._slew(t.heading, h)  # type: ignore[arg-type]
            self.speed_kn = t.speed_kn
            self._move(t.speed_kn * KNOT_MPS * h)
            return err
        # goto
        if self._arrived:
            self.speed_kn = 0.0
            return 0.0
        dist = distance_m(self.lat, self.lon, t.lat, t.lon)
        err = self._slew(self._bearing_mag(t.lat, t.lon), h)
        factor = max(0.2, math.cos(math.radians(min(abs(err), 90.0))))
        self.speed_kn = t.speed_kn * factor
        self._move(min(dist, self.speed_kn * KNOT_MPS * h))
        return err

    def _actuators(self, t: Target, heading_err: float) -> None:
        """Autopilot fins and motor for ``$OSI`` field 1 in N, P, mP, A, W (0x80 = neutral)."""
        yaw = 0x80 + int(round(max(-1.0, min(1.0, heading_err / 45.0)) * 0x30))
        pitch = 0x80 + int(round(max(-1.0, min(1.0, -self.pitch / 30.0)) * 0x30))
        top = max(self.profile.max_speed_kn, 0.1)
        motor = 0x80 + int(round(min(1.0, self.speed_kn / top) * 0x7F))
        self.actuators = f"{yaw:02X}{yaw:02X}{pitch:02X}{pitch:02X}{motor:02X}"

    # ------------------------------------------------------------------ scheduling
    def next_event_in(self, m: Any) -> Optional[float]:
        """A lower bound on the vehicle seconds until the next plant event, or ``None``."""
        t = self.sync(m)
        if self._at_rest(t):
            return None
        best: Optional[float] = None
        if t.arrive is not None and not self._arrived and t.speed_kn > 0:
            d = distance_m(self.lat, self.lon, t.lat, t.lon) - self.profile.on_station_m
            best = max(0.0, d) / (t.speed_kn * KNOT_MPS)
        if t.depth is not None:
            fix = self.profile.gps_fix_depth_m
            crossing = (self.depth > fix >= t.depth) or (self.depth <= fix < t.depth)
            if crossing:
                rate = self._vertical_rate(t)
                if self.depth > t.depth:
                    rate = max(rate, self.params.buoyancy_rise_mps)
                if rate > 0:
                    dt = max(0.0, abs(self.depth - fix)) / rate
                    best = dt if best is None else min(best, dt)
        return best

    # ------------------------------------------------------------------ observation
    def apply_fix(self, snap: PlantSnapshot) -> None:
        """Adopt a position the model applied from ``$OPOS`` (RH-POS-2)."""
        self.lat, self.lon = snap.lat, snap.lon

    def snapshot(self, m: Any, now: float, utc0: float, extra: Optional[PlantSnapshot] = None) -> PlantSnapshot:
        """The measured values at vehicle time ``now`` (RH-OUT-1..3)."""
        p = self.params
        base = extra if extra is not None else PlantSnapshot()
        pct = 100.0 * self.energy_wh / p.capacity_wh if p.capacity_wh else 0.0
        volts = 24.0 + 5.0 * pct / 100.0
        watts = self.watts
        speed_ms = self.speed_kn * KNOT_MPS
        return base.with_(
            lat=self.lat, lon=self.lon, speed_kn=self.speed_kn, depth_m=self.depth,
            heading=self.heading % 360.0, declination=p.declination, pitch=self.pitch, roll=0.0,
            altitude_m=max(0.0, p.water_depth_m - self.depth), battery_pct=pct,
            remaining_wh=self.energy_wh, watts=watts, volts=volts, amps=-watts / volts,
            minutes=self.energy_wh / watts * 60.0 if watts > 0 else 0.0, battery_state="D",
            vx=speed_ms, vy=0.0, vz=0.0, x_dist=self.x_dist, y_dist=0.0,
            utc=utc0 + now, actuators=self.actuators,
            remaining_mission_h=self.remaining_mission_h(m, now))

    def remaining_mission_h(self, m: Any, now: float) -> float:
        """Hours left in the running mission at mission speeds, parks included (``$OSI`` field 13)."""
        mission = m.mission
        if mission is None:
            return 0.0
        c = self._remaining_cache
        if c is None or c[0] is not mission:
            wps = mission.waypoints
            suffix = [0.0] * (len(wps) + 1)  # seconds from arriving at wp i to the end
            for i in range(len(wps) - 1, -1, -1):
                leg = 0.0
                if i + 1 < len(wps):
                    a, b = wps[i], wps[i + 1]
                    leg = distance_m(a.lat, a.lon, b.lat, b.lon) / max(b.speed * KNOT_MPS, 1e-6)
                suffix[i] = wps[i].park_s + leg + suffix[i + 1]
            c = self._remaining_cache = (mission, suffix)
        suffix = c[1]
        i = m.mission_wp
        w = mission.waypoints[i]
        if m.mission_mode == "P":
            left = m.park_left if m.park_left is not None else (m.park_remaining(now) or 0.0)
            secs = left + suffix[i] - w.park_s
        else:
            secs = distance_m(self.lat, self.lon, w.lat, w.lon) / max(w.speed * KNOT_MPS, 1e-6) + suffix[i]
        return max(0.0, secs) / 3600.0


_ARRIVE = {
    "wp": lambda t: WaypointReached(t.key[2]),
    "station": lambda t: OnStation(),
    "queue": lambda t: QueueWaypointReached(),
}
