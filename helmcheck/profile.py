"""The profile (ICS): what an implementation under test claims, and every ``[D]`` decision.

Reference profile §10 fixes the public key names; every ``[D]`` decision of §1–8b is a key here,
never a constant in code. A key left out takes the ``rh5`` default. ``load_profile(path)`` reads
a TOML file and rejects unknown keys and bad values with a :class:`ProfileError` that names the
file, the key and what was wrong.

Keys beyond §10 (each a ``[D]`` of the profile, documented in the README):

- ``max_line_bytes`` (RH-FRM-6), ``lowercase_checksum_in`` (RH-FRM-3),
- ``waypoint_base`` (RH-JW-1), ``omw_clear_keywords`` (RH-OMW-3, RH-RD-4),
- ``safety_action`` (RH-SAF-4 default ``SafetyAction``), ``on_station_m`` (RH-RD-5),
- ``gps_fix_depth_m`` (RH-RD-10), ``opk_max_distance_m`` (RH-PK-1, RH-RD-9),
- ``vehicle_name``: the name the emulator reports in ``$OSI`` field 18,
- ``end_mission`` (RH-MSN-4): a short mission present on the vehicle whose end a run can wait
  for (default ``short.mis``, shipped by the emulator); ``""`` = none, RH-MSN-4 NOT-TESTED,
- ``srp_mission`` (RH-SAF-4, RH-RD-6): an SRP mission present on the vehicle, given at start so
  that ``SafetyAction = srp`` can be exercised (default ``srp.mis``, shipped by the emulator);
  ``""`` = none, the ``srp`` branch NOT-TESTED,
- ``vehicle_serial``, ``uvc_version``: what the implementation under test is (identity in the
  report; never judged).

§10 keys with rules of their own:

- ``violation_trigger`` (RH-SAF-5): how the tester gets a safety violation to judge §7. Left
  out, it is ``oxflt`` when ``fault_injection = "oxflt"`` and ``none`` otherwise
  (:attr:`Profile.trigger`); ``oxflt`` needs ``fault_injection = "oxflt"`` and
  ``mission-rule`` needs ``violation_mission`` and a positive ``violation_after_s``.
- ``reaction_s`` (RH-BS-3/5): the time a backseat gets to act on a state report.

Every number must be finite; durations that divide or bound a wait must be positive.
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

__all__ = ["Profile", "BenchSafety", "ProfileError", "load_profile", "profile_from_dict", "DEFAULT", "PROTOCOLS",
           "OSI_FIELD_RANGE", "COMMAND_IDS", "SAFETY_CODES"]

PROTOCOLS = ("rh5", "rh4", "rh3", "paper")
#: Allowed $OSI field counts per protocol (RH-OUT-1; public-evidence §2.2.1).
OSI_FIELD_RANGE = {"rh5": (21, 21), "rh4": (11, 17), "rh3": (11, 17), "paper": (11, 17)}
COMMAND_IDS = ("OMS", "OMP", "OJW", "OMSTOP", "OMLOAD", "OMSTART", "OPOS", "OSD", "OLOGL",
               "OLOGD", "ORWSET", "ODVL", "OPK", "OMW")
#: Safety codes of §7, in profile order.
SAFETY_CODES = ("Sop", "Stl", "Sle", "Sfp", "Sed", "Sup", "Stf", "Srp", "Snd", "Snc", "Spw", "Sti")


class ProfileError(ValueError):
    """A profile file or value that cannot be used; the message names file, key and problem."""


@dataclass(frozen=True)
class BenchSafety:
    """Limits the tester enforces while the vehicle is out of the water (issue: certify vehicle)."""

    in_water: bool = False
    max_motor_byte: int = 0x90
    max_speed_kn: float = 0.5


@dataclass(frozen=True)
class Profile:
    """A conformance profile. Field names are the TOML keys (§10)."""

    protocol: str = "rh5"
    depth_unit: str = "m"
    ack_window_s: float = 1.0
    lockout_s: float = 20.0
    timeout_range: tuple[int, int] = (1, 120)
    max_depth_m: float = 100.0
    max_speed_kn: float = 4.5
    osi_fields: int = 21
    osd_letters: str = "GCSPYDTI"
    commands: tuple[str, ...] = COMMAND_IDS
    mission: str = "conformance.mis"
    mission_waypoints: int = 4
    fault_injection: str = "none"
    violation_trigger: str = ""  #: "" = derived from fault_injection (see :attr:`trigger`)
    violation_mission: str = ""
    violation_after_s: float = 0.0
    reaction_s: float = 0.25
    time_scale: float = 1.0
    baud: int = 19200
    bench_safety: BenchSafety = field(default_factory=BenchSafety)
    # [D] keys beyond the §10 example
    max_line_bytes: int = 256
    lowercase_checksum_in: bool = True
    waypoint_base: int = 0
    omw_clear_keywords: tuple[str, ...] = ("Clr", "CLEAR", "STOP")
    safety_action: str = "park"
    on_station_m: float = 3.0
    gps_fix_depth_m: float = 0.25
    opk_max_distance_m: float = 16093.0
    vehicle_name: str = "IVER3-EMU"
    end_mission: str = "short.mis"
    srp_mission: str = "srp.mis"
    vehicle_serial: str = ""
    uvc_version: str = ""
    name: str = "rh5"  #: where the profile came from (file name or "rh5"); not a TOML key

    @property
    def max_depth(self) -> float:
        """The depth ceiling in the profile's depth unit (RH-SRV-2; feet for rh4 and older)."""
        return self.max_depth_m if self.depth_unit == "m" else self.max_depth_m / 0.3048

    @property
    def trigger(self) -> str:
        """RH-SAF-5: how a violation is raised for §7 — ``oxflt``, ``mission-rule``,
        ``operator`` or ``none``. Left out of the file, ``oxflt`` when the vehicle declares
        ``fault_injection = "oxflt"``, else ``none``."""
        if self.violation_trigger:
            return self.violation_trigger
        return "oxflt" if self.fault_injection == "oxflt" else "none"

    def replace(self, **changes: Any) -> "Profile":
        return dataclasses.replace(self, **changes)

    def as_dict(self) -> dict[str, Any]:
        d = dataclasses.asdict(self)
        d["timeout_range"] = list(self.timeout_range)
        d["commands"] = list(self.commands)
        d["omw_clear_keywords"] = list(self.omw_clear_keywords)
        return d


DEFAULT = Profile()

_CHOICES = {
    "protocol": PROTOCOLS,
    "depth_unit": ("m", "ft"),
    "fault_injection": ("none", "oxflt"),
    "safety_action": ("park", "srp"),
    "violation_trigger": ("", "none", "oxflt", "mission-rule", "operator"),  # "": derived (Profile.trigger)
}
#: Keys whose value must be > 0 (they divide a duration or bound a wait).
_POSITIVE = ("time_scale", "lockout_s", "ack_window_s", "on_station_m", "max_depth_m")
#: Upper bounds beyond which a value has no meaning on the wire.
_AT_MOST = {"ack_window_s": 60.0, "lockout_s": 3600.0, "time_scale": 1000.0, "max_depth_m": 11000.0,
            "max_speed_kn": 50.0, "reaction_s": 10.0, "gps_fix_depth_m": 100.0, "on_station_m": 10000.0,
            "opk_max_distance_m": 100000.0, "violation_after_s": 86400.0, "max_line_bytes": 65536,
            "mission_waypoints": 100000, "osi_fields": 64}
_BAUDS = (9600, 19200, 38400, 57600, 115200)


def _check(where: str, key: str, value: Any, default: Any) -> Any:
    def bad(why: str) -> ProfileError:
        return ProfileError(f"{where}: key {key!r}: {why} (got {value!r})")

    if key in _CHOICES:
        if value not in _CHOICES[key]:
            raise bad("must be one of " + ", ".join(map(repr, _CHOICES[key])))
        return value
    if isinstance(default, bool):
        if not isinstance(value, bool):
            raise bad("must be true or false")
        return value
    if isinstance(default, int):
        if isinstance(value, bool) or not isinstance(value, int):
            raise bad("must be an integer")
        if value < 0:
            raise bad("must not be negative")
        if key == "baud" and value not in _BAUDS:
            raise bad("must be one of " + ", ".join(map(str, _BAUDS)))
        if key == "max_line_bytes" and value < 16:
            raise bad("must be at least 16")
        if key == "waypoint_base" and value not in (0, 1):
            raise bad("must be 0 or 1")
        if key == "mission_waypoints" and value < 1:
            raise bad("must be at least 1")
        limit = _AT_MOST.get(key)
        if limit is not None and value > limit:
            raise bad(f"must be at most {limit:g}")
        return value
    if isinstance(default, float):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise bad("must be a number")
        if not math.isfinite(value):
            raise bad("must be a finite number")
        if value < 0 or (key.rpartition(".")[2] in _POSITIVE and value <= 0):
            raise bad("must be positive")
        limit = _AT_MOST.get(key)
        if limit is not None and value > limit:
            raise bad(f"must be at most {limit:g}")
        return float(value)
    if isinstance(default, str):
        if not isinstance(value, str):
            raise bad("must be a string")
        if key == "osd_letters" and (not value or any(c not in "GCSPYDTI" for c in value)):
            raise bad("must be letters of GCSPYDTI")
        return value
    if key == "timeout_range":
        if (not isinstance(value, list) or len(value) != 2
                or not all(isinstance(x, int) and not isinstance(x, bool) for x in value)
                or not 0 <= value[0] <= value[1]):
            raise bad("must be [low, high] integers with 0 <= low <= high")
        return tuple(value)
    if key in ("commands", "omw_clear_keywords"):
        if not isinstance(value, list) or not all(isinstance(x, str) for x in value):
            raise bad("must be a list of strings")
        if key == "commands":
            unknown = [c for c in value if c not in COMMAND_IDS]
            if unknown:
                raise bad(f"unknown command {unknown[0]!r}; known: {', '.join(COMMAND_IDS)}")
        return tuple(value)
    raise bad("is not supported")  # pragma: no cover - every key is handled above


def _bench(where: str, value: Any) -> BenchSafety:
    if not isinstance(value, dict):
        raise ProfileError(f"{where}: [bench_safety] must be a table")
    known = {f.name: f.default for f in dataclasses.fields(BenchSafety)}
    out = {}
    for k, v in value.items():
        if k not in known:
            raise ProfileError(f"{where}: unknown key 'bench_safety.{k}'; known: {', '.join(known)}")
        out[k] = _check(where, f"bench_safety.{k}", v, known[k])
    if not 0 <= out.get("max_motor_byte", 0x90) <= 255:
        raise ProfileError(f"{where}: key 'bench_safety.max_motor_byte' must be 0..255")
    return BenchSafety(**out)


def profile_from_dict(data: dict[str, Any], where: str = "<profile>") -> Profile:
    """Build a profile from parsed TOML data, validating every key."""
    known = {f.name: f.default for f in dataclasses.fields(Profile) if f.name != "name"}
    kwargs: dict[str, Any] = {}
    for key, value in data.items():
        if key == "bench_safety":
            kwargs[key] = _bench(where, value)
            continue
        if key not in known:
            raise ProfileError(f"{where}: unknown key {key!r}; known keys: {', '.join(sorted(known))}")
        kwargs[key] = _check(where, key, value, known[key])
    protocol = kwargs.get("protocol", "rh5")
    lo, hi = OSI_FIELD_RANGE[protocol]
    if "osi_fields" in kwargs:
        if not lo <= kwargs["osi_fields"] <= hi:
            raise ProfileError(f"{where}: key 'osi_fields': protocol {protocol} has {lo}..{hi} $OSI fields "
                               f"(got {kwargs['osi_fields']})")
    elif protocol != "rh5":
        kwargs["osi_fields"] = hi
    if "depth_unit" not in kwargs and protocol != "rh5":
        kwargs["depth_unit"] = "ft"
    _check_trigger(where, kwargs)
    return Profile(name=where, **kwargs)


def _check_trigger(where: str, kw: dict[str, Any]) -> None:
    """RH-SAF-5: the violation trigger must be usable with the rest of the profile."""
    trig = kw.get("violation_trigger", "")
    if trig == "oxflt" and kw.get("fault_injection", "none") != "oxflt":
        raise ProfileError(f"{where}: key 'violation_trigger': 'oxflt' needs fault_injection = \"oxflt\" "
                           f"(the vehicle must accept the $OXFLT test extension)")
    if trig == "mission-rule":
        if not kw.get("violation_mission"):
            raise ProfileError(f"{where}: key 'violation_trigger': 'mission-rule' needs violation_mission, "
                               f"a mission on the vehicle whose own safety rule trips")
        if not kw.get("violation_after_s", 0.0) > 0:
            raise ProfileError(f"{where}: key 'violation_trigger': 'mission-rule' needs violation_after_s > 0, "
                               f"the vehicle seconds after its start at which the rule trips")


def load_profile(path: str | Path | None) -> Profile:
    """Read a TOML profile; ``None`` gives the ``rh5`` defaults."""
    if path is None:
        return DEFAULT
    p = Path(path)
    try:
        raw = p.read_bytes()
    except OSError as e:
        raise ProfileError(f"{p}: cannot read profile: {e.strerror or e}") from None
    try:
        data = tomllib.loads(raw.decode("utf-8"))
    except UnicodeDecodeError as e:
        raise ProfileError(f"{p}: not UTF-8 text at byte {e.start}") from None
    except tomllib.TOMLDecodeError as e:
        raise ProfileError(f"{p}: not valid TOML: {e}") from None
    return profile_from_dict(data, where=str(p))
