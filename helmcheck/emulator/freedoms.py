"""The emulator's settings for the freedoms the reference profile leaves a conforming vehicle.

The reference model (:mod:`helmcheck.model`) makes one choice wherever the profile leaves room.
A vehicle we did not write may make another and still conform, so the emulator can be told to
choose differently; the test suite then certifies it with those choices
(``tests/test_emulator_freedoms.py``) and every conforming choice must PASS. ``docs/freedoms.md``
lists each freedom with the clause that leaves the room, its bound and the setting here.

:class:`EmulatorSettings` holds the choices; the defaults are the reference emulator's own
behaviour, exactly. They come from the ``[emulator]`` table of the profile file given to
``helmcheck emulate --profile`` and from ``helmcheck emulate --set KEY=VALUE`` (a TOML value),
read by :func:`settings_from_dict`. The tester never reads this table: ``certify vehicle`` must
not learn the vehicle's choices.

Settings (wall seconds where the line is concerned, vehicle seconds otherwise; RH-TIM-2):

* the line (RH-ACK-2): ``reply_delay_s`` ``[lo, hi]`` — each command is processed (its ACK goes
  out, RH-RD-15) a delay drawn uniformly from ``[lo, hi]`` after it arrived, in arrival order
  (RH-ACK-6); ``pacing`` ``"baud"`` (each sentence waits for the previous one's transmit time) or
  ``"burst"`` (everything at once); ``process_when_idle`` — a line (a poll too) is processed only
  once the replies before it have left the line, so its ACK goes out the instant it is processed
  and its durations start there (a serial loop that answers one line at a time);
  ``burst_interval_s`` — with ``"burst"``, a serial loop that
  turns every this many wall seconds: the lines that arrived are processed at its next turn and
  their replies written at once (the instant the ACK goes out is the instant of processing,
  RH-RD-15); ``seed`` for the draws. ``$OXFLT`` raises its violation at once (RH-SAF-5): it
  waits only for the lines that came before it. ``overrun`` — what the vehicle does when requests
  ask for more replies than the line carries (the profile leaves it open): ``"queue"`` (every reply
  waits its turn: queue and lag) or ``"drop"`` (a poll whose replies could not start within the
  ACK window is not answered, its replies dropped whole; commands are always answered; :mod:`.outbox`).
* the clock (RH-TIM-1): ``control_tick_s`` — the control loop runs every this many vehicle
  seconds: timer expiries and plant events take effect on the next tick, sensors are sampled on
  ticks; ``timer_factor`` and ``timer_offset_s`` — every protocol duration the vehicle times
  (``$OMS``/``$OMP``/``$ODVL`` timeouts, parks, the lockout) really lasts
  ``duration × factor + offset`` (:class:`SkewedTimers`); its ``$OSI`` park countdown runs on
  the same clock.
* the profile's open questions (the readings table, :mod:`helmcheck.model.readings`, where each
  is explained; every row with a setting is one here): ``srp_bad_path``, ``ascent_refusal_order``,
  ``omw_pitch_speed``, ``stop_unloads`` (the model answers by them), ``resumed_park`` and ``idle_distance`` (below);
* the mission: ``resumed_park`` — a mission park resumed after remote control (RH-INT-2) counts
  ``"at once"`` from the release, wherever the vehicle is (the reference model), or, ``"on
  station"``, only once the vehicle is back within ``on_station_m`` of the park's waypoint, which
  it heads for (the paper: "the vehicle will park for the remaining time").
* the plant: ``speed_factor`` (speed made good ÷ commanded), ``turn_rate_dps``,
  ``dive_pitch_deg`` (pitch of the mission's dives), ``ascent_mps`` (the ascent after a
  lockout), ``buoyancy_rise_mps``, ``water_depth_m``, ``start_lat``/``start_lon``/
  ``start_heading``, ``declination``, ``start_battery_pct``.
* what it reports: ``decimals`` — a table of field name → decimal places for every number of
  that name in a data sentence (``lat``, ``lon``, ``speed``, ``distance``, ``altimeter``,
  ``declination``, ``remaining_time``, ``true_heading``, ``depth``, ``battery``, ``heading``,
  ``pitch``, ``roll``, ``temperature``, ``conductivity``, …); ``idle_distance`` — ``$OSI`` field 7
  with no navigation target (RH-RD-5): ``"zero"`` or ``"last"`` (the distance to the last
  target); ``osi_reserved`` — ``$OSI`` fields 19–21; ``compass_extra`` — further OS5000 letter
  fields after ``$C``'s ``D`` (RH-FRM-8); ``gprmc_time_decimals`` — decimals of the ``$GPRMC``
  time (0–3); ``factory_settings`` — the ``$ORWSET`` safety-rule settings the vehicle starts
  with (``{Sle = [1, "30"], …}``: state, then 0–3 values; RH-SET-2).

:func:`nonconforming` says which settings leave the bounds the profile allows (the emulator
still runs with them: the tests use such vehicles to show the judge fails them).
"""

from __future__ import annotations

import dataclasses
import math
import random
from dataclasses import dataclass, field
from decimal import Decimal
from typing import Any, Optional

from ..grammar import sentences as s
from ..grammar.wirelog import transmit_time
from ..model.readings import BY_KEY as READINGS_BY_KEY, DEFAULTS as READING_DEFAULTS, READINGS
from ..model.timers import Timers, tolerance
from ..profile import SAFETY_CODES, Profile

__all__ = ["EmulatorSettings", "SettingsError", "settings_from_dict", "parse_assignment", "nonconforming",
           "SkewedTimers", "ReplyShaper", "ReplyDelay", "DEFAULT_SETTINGS", "DECIMAL_FIELDS", "skew_allowance",
           "model_readings", "MODEL_READINGS"]

#: Field names ``decimals`` may name: every Decimal field of a data sentence, and ``battery``.
DECIMAL_FIELDS = ("lat", "lon", "speed", "distance", "altimeter", "declination", "remaining_time",
                  "true_heading", "depth", "battery", "heading", "pitch", "roll", "temperature",
                  "percent", "remaining_wh", "watts", "volts", "amps", "minutes_left", "vx", "vy", "vz",
                  "x_dist", "y_dist", "dfs", "altitude", "conductivity")
_HEADINGS = ("heading", "true_heading")


class SettingsError(ValueError):
    """An ``[emulator]`` setting that cannot be used; the message names it."""


def _reading_doc(key: str) -> str:
    r = READINGS_BY_KEY[key]
    return f"{r.question} " + "; ".join(f"{c.value}: {c.means}" for c in r.choices)


def _s(default: Any, doc: str, clause: str = "", *, factory: Any = None) -> Any:
    meta = {"doc": doc, "clause": clause}
    if factory is not None:
        return field(default_factory=factory, metadata=meta)
    return field(default=default, metadata=meta)


@dataclass(frozen=True)
class EmulatorSettings:
    """The emulator's choices where the profile leaves room (module docstring). The defaults
    are the reference emulator's own behaviour."""

    # --- the line
    reply_delay_s: tuple[float, float] = _s((0.0, 0.0), "wall seconds [lo, hi] from a command's arrival to "
                                            "its processing (its ACK going out)", "RH-ACK-2, RH-RD-15")
    pacing: str = _s("baud", "baud: one sentence after another at the line rate; burst: all at once",
                     "RH-ACK-2, RH-FRM-9")
    burst_interval_s: float = _s(0.0, "with pacing burst: the serial loop's period, wall seconds (lines are "
                                 "processed at its next turn, replies written at once)", "RH-ACK-2, RH-RD-15")
    seed: int = _s(0, "seed of the reply-delay draws")
    process_when_idle: bool = _s(False, "a line is processed (its state change and replies together) only once "
                                 "the replies before it have left the line, so its ACK goes out the instant "
                                 "it is processed and every duration starts there", "RH-ACK-6, RH-RD-15")
    overrun: str = _s("queue", "requests asking for more replies than the line carries: queue (every reply waits "
                      "its turn) or drop (a poll whose replies could not start within the ACK window is "
                      "not answered; commands always are)", "RH-ACK-1, RH-ACK-2, RH-BS-4")
    # --- the clock
    control_tick_s: float = _s(0.0, "vehicle seconds between control-loop ticks (0: continuous)", "RH-TIM-1")
    timer_factor: float = _s(1.0, "every timed duration lasts duration × factor + offset", "RH-TIM-1")
    timer_offset_s: float = _s(0.0, "vehicle seconds added to every timed duration", "RH-TIM-1")
    # --- the mission
    resumed_park: str = _s("at once", "a mission park resumed after remote control counts from the release "
                           "(at once) or once back on station at its waypoint (on station)", "RH-INT-2")
    # --- the plant
    speed_factor: float = _s(1.0, "speed made good ÷ commanded speed")
    turn_rate_dps: float = _s(15.0, "turn rate, degrees per vehicle second")
    dive_pitch_deg: float = _s(20.0, "pitch of the mission's dives and climbs, degrees")
    ascent_mps: float = _s(0.3, "ascent rate after a lockout, m/s", "RH-SAF-3, RH-SAF-4, RH-RD-12")
    buoyancy_rise_mps: float = _s(0.1, "rise rate with no way on, m/s")
    water_depth_m: float = _s(40.0, "water depth, m (the altimeter)")
    start_lat: float = _s(41.52, "start latitude, degrees")
    start_lon: float = _s(-71.32, "start longitude, degrees")
    start_heading: float = _s(90.0, "start magnetic heading, degrees")
    declination: float = _s(-14.5, "magnetic declination, degrees ($OSI field 11)", "RH-RD-14")
    start_battery_pct: float = _s(95.0, "battery at start, percent ($OSI field 16, $OPI)")
    # --- what it reports
    decimals: tuple[tuple[str, int], ...] = _s((), "field name → decimal places in data sentences", "§4, RH-OUT-1")
    idle_distance: str = _s("zero", "$OSI field 7 with no navigation target: zero or last", "RH-RD-5")
    osi_reserved: tuple[str, ...] = _s(("0.0", "False", "False"), "$OSI fields 19–21", "RH-OUT-1")
    compass_extra: tuple[str, ...] = _s((), "OS5000 letter fields after $C's D (Mx My Mz A Ax Ay Az M)",
                                        "RH-FRM-8")
    gprmc_time_decimals: int = _s(2, "decimals of the $GPRMC time", "RH-OUT-2")
    factory_settings: tuple[tuple[str, int, tuple[str, ...]], ...] = _s(
        (), "$ORWSET safety-rule settings at start: name → [state, values…]", "RH-SET-2")
    # --- the profile's open questions the model answers (the readings table, helmcheck.model.readings)
    srp_bad_path: str = _s(READING_DEFAULTS["srp_bad_path"], _reading_doc("srp_bad_path"), "RH-RD-6")
    ascent_refusal_order: str = _s(READING_DEFAULTS["ascent_refusal_order"], _reading_doc("ascent_refusal_order"),
                                   "RH-RD-12")
    omw_pitch_speed: str = _s(READING_DEFAULTS["omw_pitch_speed"], _reading_doc("omw_pitch_speed"), "RH-RD-9")
    stop_unloads: str = _s(READING_DEFAULTS["stop_unloads"], _reading_doc("stop_unloads"), "RH-RD-6")
    opos_ctd: str = _s(READING_DEFAULTS["opos_ctd"], _reading_doc("opos_ctd"), "RH-POS-2")
    park_waypoint: str = _s(READING_DEFAULTS["park_waypoint"], _reading_doc("park_waypoint"), "RH-OUT-1")
    omload_flag: str = _s(READING_DEFAULTS["omload_flag"], _reading_doc("omload_flag"), "RH-MSN-1")

    @property
    def is_default(self) -> bool:
        return self == DEFAULT_SETTINGS

    def decimals_map(self) -> dict[str, int]:
        return dict(self.decimals)

    def replace(self, **changes: Any) -> "EmulatorSettings":
        return dataclasses.replace(self, **changes)

    def as_dict(self) -> dict[str, Any]:
        """TOML-friendly values (``--set`` and the ``[emulator]`` table take these back)."""
        out: dict[str, Any] = {}
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            if f.name == "decimals":
                v = dict(v)
            elif f.name == "factory_settings":
                v = {name: [state, *vals] for name, state, vals in v}
            elif isinstance(v, tuple):
                v = list(v)
            out[f.name] = v
        return out

    def assignments(self) -> list[str]:
        """``--set KEY=VALUE`` arguments giving these settings (only those not at their default)."""
        from ..profile_toml import toml_value

        out = []
        for name, v in self.as_dict().items():
            if v == DEFAULT_SETTINGS.as_dict()[name]:
                continue
            if isinstance(v, dict):
                for k, x in v.items():
                    out.append(f"{name}.{k}={toml_value(x)}")
            else:
                out.append(f"{name}={toml_value(v)}")
        return out


DEFAULT_SETTINGS = EmulatorSettings()

#: settings that take one of a few words: the readings table's (every reading of its rows) and the line's
_CHOICES = {"pacing": ("baud", "burst"), "overrun": ("queue", "drop"), **{r.setting: r.values for r in READINGS
                                            if r.setting and isinstance(getattr(DEFAULT_SETTINGS, r.setting), str)}}
#: the readings the model itself answers by (the rest the emulator or the judge takes care of)
MODEL_READINGS = tuple(r.key for r in READINGS if r.in_model)


def model_readings(st: "EmulatorSettings") -> dict[str, str]:
    """The model's ``readings`` for these settings (:mod:`helmcheck.model.readings`)."""
    return {**READING_DEFAULTS, **{k: getattr(st, k) for k in MODEL_READINGS}}
_POSITIVE = ("timer_factor", "speed_factor", "turn_rate_dps", "dive_pitch_deg", "ascent_mps",
             "buoyancy_rise_mps", "water_depth_m")
_COMPASS_LETTERS = ("M", "Mx", "My", "Mz", "A", "Ax", "Ay", "Az")


def _number(where: str, key: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise SettingsError(f"{where}: emulator setting {key!r} must be a finite number (got {value!r})")
    return float(value)


def settings_from_dict(data: dict[str, Any], where: str = "[emulator]",
                       base: EmulatorSettings = DEFAULT_SETTINGS) -> EmulatorSettings:
    """Settings from an ``[emulator]`` table (parsed TOML); keys left out keep ``base``'s."""
    if not isinstance(data, dict):
        raise SettingsError(f"{where}: [emulator] must be a table")
    known = {f.name for f in dataclasses.fields(EmulatorSettings)}
    kw: dict[str, Any] = {}
    for key, value in data.items():
        if key not in known:
            raise SettingsError(f"{where}: unknown emulator setting {key!r}; known: {', '.join(sorted(known))}")

        def bad(why: str) -> SettingsError:
            return SettingsError(f"{where}: emulator setting {key!r}: {why} (got {value!r})")

        if key in _CHOICES:
            if isinstance(value, int) and not isinstance(value, bool):
                value = str(value)  # an error number as a word (--set srp_bad_path=31)
            if value not in _CHOICES[key]:
                raise bad("must be one of " + ", ".join(map(repr, _CHOICES[key])))
            kw[key] = value
        elif key == "reply_delay_s":
            if isinstance(value, (int, float)) and not isinstance(value, bool):
                value = [value, value]
            if not isinstance(value, list) or len(value) != 2:
                raise bad("must be a number or [lo, hi]")
            lo, hi = (_number(where, key, x) for x in value)
            if not 0 <= lo <= hi:
                raise bad("must be 0 <= lo <= hi")
            kw[key] = (lo, hi)
        elif key == "process_when_idle":
            if not isinstance(value, bool):
                raise bad("must be true or false")
            kw[key] = value
        elif key in ("seed", "gprmc_time_decimals"):
            if isinstance(value, bool) or not isinstance(value, int) or value < 0:
                raise bad("must be a non-negative integer")
            if key == "gprmc_time_decimals" and value > 3:
                raise bad("must be 0..3")
            kw[key] = value
        elif key == "decimals":
            if not isinstance(value, dict):
                raise bad("must be a table of field name = places")
            merged = dict(base.decimals)
            for name, places in value.items():
                if name not in DECIMAL_FIELDS:
                    raise bad(f"unknown field {name!r}; known: {', '.join(DECIMAL_FIELDS)}")
                if isinstance(places, bool) or not isinstance(places, int) or not 0 <= places <= 12:
                    raise bad(f"{name}: places must be an integer 0..12")
                merged[name] = places
            kw[key] = tuple(sorted(merged.items()))
        elif key in ("osi_reserved", "compass_extra"):
            if not isinstance(value, list) or not all(isinstance(x, str) for x in value):
                raise bad("must be a list of strings")
            if key == "osi_reserved":
                if len(value) != 3 or any(c in x for x in value for c in ",*$\r\n"):
                    raise bad("must be three fields without , * $ or line ends")
            elif any(x not in _COMPASS_LETTERS for x in value):
                raise bad(f"letters must be of {', '.join(_COMPASS_LETTERS)}")
            kw[key] = tuple(value)
        elif key == "factory_settings":
            if not isinstance(value, dict):
                raise bad("must be a table of safety code = [state, values…]")
            merged = {n: (st, vals) for n, st, vals in base.factory_settings}
            for name, spec in value.items():
                if name not in SAFETY_CODES:
                    raise bad(f"{name!r} is not a safety code (SafetyAction is the profile's safety_action)")
                if (not isinstance(spec, list) or not 1 <= len(spec) <= 4 or spec[0] not in (0, 1)
                        or isinstance(spec[0], bool) or not all(isinstance(x, str) and x and "," not in x
                                                                for x in spec[1:])):
                    raise bad(f"{name}: must be [state 0|1, up to 3 non-empty values]")
                merged[name] = (spec[0], tuple(spec[1:]))
            kw[key] = tuple((n, st, vals) for n, (st, vals) in sorted(merged.items()))
        else:
            x = _number(where, key, value)
            if key in _POSITIVE and x <= 0:
                raise bad("must be positive")
            if key in ("burst_interval_s", "control_tick_s", "start_battery_pct") and x < 0:
                raise bad("must not be negative")
            if key == "start_battery_pct" and x > 100:
                raise bad("must be at most 100")
            if key == "start_lat" and not -89 <= x <= 89:
                raise bad("must be within [-89, 89]")
            if key == "start_lon" and not -180 <= x <= 180:
                raise bad("must be within [-180, 180]")
            kw[key] = x
    return dataclasses.replace(base, **kw)


def parse_assignment(text: str) -> dict[str, Any]:
    """``KEY=VALUE`` (VALUE a TOML value; a bare word is a string; ``a.b=V`` sets key ``b`` of the
    table ``a``) as a one-entry ``[emulator]`` table."""
    import tomllib

    key, sep, raw = text.partition("=")
    key = key.strip()
    if not sep or not key:
        raise SettingsError(f"--set {text!r}: expected KEY=VALUE")
    raw = raw.strip()
    try:
        value = tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw
    head, dot, sub = key.partition(".")
    if dot:
        return {head: {sub: value}}
    return {key: value}


def skew_allowance(duration: float) -> float:
    """RH-TIM-1: how far a conforming vehicle's duration may be from ``duration`` (vehicle s)."""
    return tolerance(duration)


#: Durations a vehicle under the rh5 defaults times (vehicle seconds): the shortest timeout,
#: the 10 s point where 5 % overtakes 0.5 s, the lockout, the longest park.
_PROBE_DURATIONS = (1.0, 10.0, 20.0, 120.0, 86400.0)


def nonconforming(st: EmulatorSettings, profile: Profile, replies_bytes: int = 600) -> list[str]:
    """Why these settings leave the bounds a conforming vehicle keeps (empty: they do not)."""
    out = []
    baud = profile.baud
    tx = transmit_time(replies_bytes, baud)
    late = st.reply_delay_s[1] + (st.burst_interval_s if st.pacing == "burst" else 0.0)
    if late + tx > profile.ack_window_s:
        out.append(f"reply_delay_s/burst_interval_s: replies up to {late:g} s after the command, plus "
                   f"{tx:.3f} s on the line, exceed the ACK window {profile.ack_window_s:g} s (RH-ACK-2)")
    for d in _PROBE_DURATIONS + (profile.lockout_s,):
        off = d * (st.timer_factor - 1.0) + st.timer_offset_s
        worst = max(abs(off), abs(off + st.control_tick_s))  # a tick only ever makes it later
        if worst > skew_allowance(d) + 1e-9:
            out.append(f"timer_factor/timer_offset_s/control_tick_s: a {d:g} s duration ends {off:+.3f} s "
                       f"off (+ up to {st.control_tick_s:g} s for the tick), beyond RH-TIM-1's "
                       f"{skew_allowance(d):g} s")
            break
    return out


class SkewedTimers(Timers):
    """:class:`~helmcheck.model.timers.Timers` whose durations last ``duration × factor + offset``
    (a vehicle clock that runs slow or fast, or a fixed latency on every expiry). What the
    vehicle displays (:meth:`remaining`, ``$OSI`` field 10) counts down linearly over the real
    length, so it shows 0 when the timer expires."""

    __slots__ = ("factor", "offset")

    def __init__(self, factor: float = 1.0, offset: float = 0.0) -> None:
        super().__init__()
        self.factor = factor
        self.offset = offset

    def copy(self) -> "SkewedTimers":
        new = SkewedTimers.__new__(SkewedTimers)
        new._t = self._t
        new.skew = self.skew
        new.due = self.due
        new._next = self._next
        new.factor = self.factor
        new.offset = self.offset
        return new

    def _length(self, dur: float) -> float:
        return max(0.0, dur * self.factor + self.offset)

    def deadline(self, name: str) -> Optional[float]:
        t = self._t.get(name)
        if t is None:
            return None
        start, dur = t
        return start + self._length(dur)

    def remaining(self, name: str, now: float, clip: bool = True) -> Optional[float]:
        t = self._t.get(name)
        if t is None:
            return None
        start, dur = t
        length = self._length(dur)
        if length <= 0:
            return 0.0
        left = dur * (start + length - now) / length
        return left if not clip or left > 0.0 else 0.0


def _quantize(value: Decimal, places: int, heading: bool = False) -> Decimal:
    x = float(value)
    text = f"{x:.{places}f}"
    if heading and float(text) >= 360.0:
        text = f"{0.0:.{places}f}"
    if text.startswith("-") and float(text) == 0.0:
        text = text[1:]
    return Decimal(text)


class ReplyShaper:
    """Rewrites the replies the model produced into this vehicle's own spelling of them: decimals,
    ``$OSI`` field 7 with no target, fields 19–21, ``$C`` extras, the ``$GPRMC`` time. Values are
    the model's; only what the profile leaves free changes. ``idle_distance = "last"`` needs the
    last navigation target's distance, which the core passes in."""

    def __init__(self, st: EmulatorSettings):
        self.st = st
        self.places = st.decimals_map()
        self.active = (bool(self.places) or st.idle_distance != "zero" or st.compass_extra != ()
                       or st.gprmc_time_decimals != 2
                       or st.osi_reserved != DEFAULT_SETTINGS.osi_reserved)

    def shape(self, reply: s.Reply, idle_distance: Optional[float] = None, utc: Optional[float] = None) -> s.Reply:
        if not self.active or isinstance(reply, (s.ACK, str)):
            return reply
        changes: dict[str, Any] = {}
        if isinstance(reply, s.OSI):
            if idle_distance is not None and self.st.idle_distance == "last":
                changes["distance"] = Decimal(f"{idle_distance:.2f}")
            if reply.reserved:
                changes["reserved"] = self.st.osi_reserved[:len(reply.reserved)]
            if "battery" in self.places and reply.battery is not None:
                try:
                    changes["battery"] = f"{float(reply.battery):.{self.places['battery']}f}"
                except ValueError:
                    pass
        if isinstance(reply, s.Compass) and self.st.compass_extra:
            changes["extra"] = tuple((k, Decimal("0.0")) for k in self.st.compass_extra)
        if isinstance(reply, s.GPRMC) and self.st.gprmc_time_decimals != 2:
            hhmmss, _, frac = reply.time.partition(".")
            n = self.st.gprmc_time_decimals
            if n == 3 and utc is not None:
                frac = f"{int(utc * 1000) % 1000:03d}"  # the clock's own milliseconds
            changes["time"] = hhmmss + ("." + (frac + "000")[:n] if n else "")
        if self.places:
            for name in reply.field_names():
                places = self.places.get(name)
                if places is None or name == "battery":
                    continue
                v = changes.get(name, getattr(reply, name))
                if isinstance(v, Decimal):
                    changes[name] = _quantize(v, places, heading=name in _HEADINGS)
        return dataclasses.replace(reply, **changes) if changes else reply


class ReplyDelay:
    """Draws each command's processing delay (wall seconds) from ``reply_delay_s``."""

    def __init__(self, st: EmulatorSettings):
        self.lo, self.hi = st.reply_delay_s
        self._rng = random.Random(st.seed)

    @property
    def active(self) -> bool:
        return self.hi > 0

    def draw(self) -> float:
        if self.lo == self.hi:
            return self.lo
        return self._rng.uniform(self.lo, self.hi)
