"""The profile (ICS): what an implementation under test claims, and every ``[D]`` decision.

Reference profile §10 fixes the public key names; every ``[D]`` decision of §1–8b is a key here,
never a constant in code. A key left out takes the ``rh5`` default. ``load_profile(path)`` reads
a TOML file and rejects unknown keys and bad values with a :class:`ProfileError` that names the
file, the key and what was wrong (an unknown key with the closest known ones,
:mod:`helmcheck.spelling`; ``helmcheck profile keys`` lists them all).

Each field's documentation is its metadata (:func:`_key`: what it is, its clauses, whether a
real vehicle's file must fill it in, and a safe starting value); ``helmcheck profile init``
writes a commented file from it (:mod:`helmcheck.profile_template`). Keys beyond §10 (each a
``[D]`` of the profile, documented in the README):

- ``max_line_bytes`` (RH-FRM-6), ``lowercase_checksum_in`` (RH-FRM-3),
- ``waypoint_base`` (RH-JW-1), ``omw_clear_keywords`` (RH-OMW-3, RH-RD-4),
- ``safety_action`` (RH-SAF-4 default ``SafetyAction``), ``on_station_m`` (RH-RD-5),
- ``gps_fix_depth_m`` (RH-RD-10), ``opk_max_distance_m`` (RH-PK-1, RH-RD-9),
- ``vehicle_name``: the name the emulator reports in ``$OSI`` field 18,
- ``end_mission`` (RH-MSN-4): a short mission present on the vehicle whose end a run can wait
  for; default ``""`` = none, RH-MSN-4 NOT-TESTED,
- ``srp_mission`` (RH-SAF-4, RH-RD-6): an SRP mission present on the vehicle, given at start so
  that ``SafetyAction = srp`` can be exercised; default ``""`` = none, the ``srp`` branch
  NOT-TESTED. (A real vehicle is not assumed to hold any mission but the test mission; the
  built-in emulator's profile, :func:`emulator_profile`, names the ones it ships.)
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
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .spelling import did_you_mean

__all__ = ["Profile", "BenchSafety", "ProfileError", "load_profile", "profile_from_dict", "DEFAULT", "PROTOCOLS",
           "OSI_FIELD_RANGE", "COMMAND_IDS", "SAFETY_CODES", "emulator_profile", "EMULATOR_PROFILE",
           "profile_keys", "key_rule"]

PROTOCOLS = ("rh5", "rh4", "rh3", "paper")
#: Allowed $OSI field counts per protocol (RH-OUT-1; public-evidence §2.2.1).
OSI_FIELD_RANGE = {"rh5": (21, 21), "rh4": (11, 17), "rh3": (11, 17), "paper": (11, 17)}
COMMAND_IDS = ("OMS", "OMP", "OJW", "OMSTOP", "OMLOAD", "OMSTART", "OPOS", "OSD", "OLOGL",
               "OLOGD", "ORWSET", "ODVL", "OPK", "OMW")
#: Safety codes of §7, in profile order.
SAFETY_CODES = ("Sop", "Stl", "Sle", "Sfp", "Sed", "Sup", "Stf", "Srp", "Snd", "Snc", "Spw", "Sti")


class ProfileError(ValueError):
    """A profile file or value that cannot be used; the message names file, key and problem."""


_MISSING = object()


def _key(default: Any = _MISSING, doc: str = "", *, group: str, clause: str = "", fill: str = "",
         real: Any = _MISSING, factory: Any = None, hexa: bool = False) -> Any:
    """A profile key: its default and its documentation, the one source ``helmcheck profile init``
    writes a commented file from (:mod:`helmcheck.profile_template`).

    *doc* says what the key is; *clause* the clauses it serves; *group* the template section;
    *fill* (non-empty) marks a key a real vehicle's file must be given a value for, and says
    which; *real* is the value a new file for a real vehicle starts with when it is not the
    default (a safe one: nothing raised, nothing assumed on the vehicle); *hexa* writes an
    integer in hexadecimal."""
    meta = {"doc": doc, "group": group, "clause": clause, "fill": fill, "hex": hexa}
    if real is not _MISSING:
        meta["real"] = real
    if factory is not None:
        return field(default_factory=factory, metadata=meta)
    return field(default=default, metadata=meta)


@dataclass(frozen=True)
class BenchSafety:
    """Limits the tester enforces while the vehicle is out of the water (issue: certify vehicle)."""

    in_water: bool = _key(False, "true only when the vehicle is in the water: then no bench limit is enforced",
                          group="safety")
    max_motor_byte: int = _key(0x90, "$OMP motor byte ceiling on the bench (0x80 = stop)", group="safety",
                               hexa=True)
    max_speed_kn: float = _key(0.5, "$OMS / $OPK / $OMW speed ceiling on the bench, knots", group="safety")


@dataclass(frozen=True)
class Profile:
    """A conformance profile. Field names are the TOML keys (§10); each field's metadata is its
    documentation (:func:`_key`)."""

    protocol: str = _key("rh5", "protocol generation the vehicle speaks", group="protocol", clause="RH-OUT-1")
    depth_unit: str = _key("m", "depth unit of the vehicle's sentences; rh4 and older: ft", group="protocol",
                           clause="§4")
    ack_window_s: float = _key(1.0, "wall seconds within which every $ACK must come", group="protocol",
                               clause="RH-ACK-2")
    lockout_s: float = _key(20.0, "safety lockout after a violation, vehicle seconds", group="protocol",
                            clause="RH-SAF-1")
    timeout_range: tuple[int, int] = _key((1, 120), "[low, high] timeout seconds for $OMS / $OMP / $ODVL",
                                          group="protocol", clause="RH-SRV-2, RH-PRM-2, RH-DVL-1")
    max_depth_m: float = _key(100.0, "the vehicle's depth ceiling, metres", group="protocol", clause="RH-SRV-2")
    max_speed_kn: float = _key(4.5, "the vehicle's speed ceiling, knots", group="protocol", clause="RH-SRV-2")
    osi_fields: int = _key(21, "$OSI field count: rh5 21, rh4/rh3/paper 11 to 17", group="protocol",
                           clause="RH-OUT-1")
    osd_letters: str = _key("GCSPYDTI", "the $OSD letters the vehicle serves; G gives $GPRMC, whose time is "
                            "also read to check the time scale", group="protocol", clause="RH-OSD-1, RH-OSD-2",
                            fill="leave out the letters of sensors the vehicle lacks")
    commands: tuple[str, ...] = _key(COMMAND_IDS, "the commands the vehicle claims; one left out is an "
                                     "unknown ID to it", group="protocol", clause="RH-FRM-5",
                                     fill="leave out commands the vehicle does not implement")
    mission: str = _key("conformance.mis", "the test mission, present on the vehicle and started by name: "
                        "at least 4 waypoints, a mission park on one of the first", group="missions", clause="§10",
                        fill="the name of the test mission on the vehicle")
    mission_waypoints: int = _key(4, "waypoints in the test mission", group="missions", clause="§10",
                                  fill="the test mission's waypoint count")
    fault_injection: str = _key("none", "whether the vehicle accepts the $OXFLT test extension (oxflt), which "
                                "raises a safety violation at once", group="safety", clause="RH-SAF-5")
    violation_trigger: str = _key("", "how the tester gets a safety violation to judge §7: none (§7 NOT-TESTED), "
                                  "oxflt (needs fault_injection = \"oxflt\"), mission-rule (violation_mission trips "
                                  "its own rule violation_after_s after its start), operator (someone trips a "
                                  "sensor on the bench); left out: oxflt with fault_injection = \"oxflt\", else none",
                                  group="safety", clause="RH-SAF-5", real="none")
    violation_mission: str = _key("", "for violation_trigger mission-rule: a mission on the vehicle whose own "
                                  "safety rule trips",
                                  group="safety", clause="RH-SAF-5")
    violation_after_s: float = _key(0.0, "for violation_trigger mission-rule: vehicle seconds after the start of "
                                    "violation_mission at which its rule trips",
                                    group="safety", clause="RH-SAF-5")
    reaction_s: float = _key(0.25, "backseat judging: time a backseat gets to act on a state report",
                             group="backseat", clause="RH-BS-3, RH-BS-5")
    time_scale: float = _key(1.0, "how many times faster than wall time the vehicle's clock runs: above 1 "
                             "only for emulators; --time-scale overrides it", group="link", clause="RH-TIM-2")
    baud: int = _key(19200, "line rate, 8N1; --baud overrides it", group="link", clause="RH-FRM-9",
                     fill="the serial line's baud rate")
    bench_safety: BenchSafety = _key(doc="enforced by the tester while the vehicle is out of the water",
                                     group="safety", factory=BenchSafety)
    # [D] keys beyond the §10 example
    max_line_bytes: int = _key(256, "longest line, bytes, CR LF included", group="protocol", clause="RH-FRM-6")
    lowercase_checksum_in: bool = _key(True, "the vehicle accepts lower-case checksum hex", group="protocol",
                                       clause="RH-FRM-3")
    waypoint_base: int = _key(0, "number of the first waypoint", group="protocol", clause="RH-JW-1")
    omw_clear_keywords: tuple[str, ...] = _key(("Clr", "CLEAR", "STOP"), "$OMW keywords that clear the queue",
                                               group="protocol", clause="RH-OMW-3, RH-RD-4")
    safety_action: str = _key("park", "the vehicle's SafetyAction setting at the surface after a violation",
                              group="safety", clause="RH-SAF-4")
    on_station_m: float = _key(3.0, "metres within which the vehicle is on station", group="protocol",
                               clause="RH-RD-5")
    gps_fix_depth_m: float = _key(0.25, "depth at or above which the vehicle is at the surface, metres",
                                  group="protocol", clause="RH-RD-10")
    opk_max_distance_m: float = _key(16093.0, "farthest $OPK position accepted, metres", group="protocol",
                                     clause="RH-PK-1, RH-RD-9")
    vehicle_name: str = _key("IVER3-EMU", "the vehicle's name, as it reports in $OSI field 18 (identity in "
                             "the report; the emulator reports this one)", group="identity",
                             fill="the vehicle's name", real="")
    end_mission: str = _key("", "a short mission present on the vehicle whose end a run can wait for; \"\" = "
                            "none, RH-MSN-4 NOT-TESTED", group="missions", clause="RH-MSN-4",
                            fill="a short mission on the vehicle, or \"\"")
    srp_mission: str = _key("", "an SRP mission present on the vehicle, given at start so that SafetyAction "
                            "srp is exercised; \"\" = none, that branch NOT-TESTED", group="missions",
                            clause="RH-SAF-4, RH-RD-6", fill="an SRP mission on the vehicle, or \"\"")
    vehicle_serial: str = _key("", "the vehicle's serial number (identity in the report; never judged)",
                               group="identity", fill="the vehicle's serial number")
    uvc_version: str = _key("", "the UVC software version (identity in the report; never judged)",
                            group="identity", fill="the UVC version the vehicle runs")
    name: str = field(default="rh5", metadata={"not_a_key": True})  #: where the profile came from; not a TOML key

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


def key_rule(key: str) -> str:
    """The values ``key`` (``bench_safety.max_motor_byte`` for the table's) may take, in words,
    from the same tables :func:`profile_from_dict` checks them with (for documentation)."""
    name = key.rpartition(".")[2]
    if key in _CHOICES:
        return "one of " + " | ".join(repr(c).replace("'", '"') for c in _CHOICES[key] if c)
    if key == "baud":
        return "one of " + " | ".join(map(str, _BAUDS))
    if key == "waypoint_base":
        return "0 or 1"
    if key == "osd_letters":
        return "letters of GCSPYDTI"
    if key == "commands":
        return "any of " + ", ".join(COMMAND_IDS)
    if key == "timeout_range":
        return "[low, high] integers, 0 <= low <= high"
    if key == "bench_safety.max_motor_byte":
        return "0x00..0xFF"
    low = {"max_line_bytes": "at least 16", "mission_waypoints": "at least 1"}.get(key)
    if low is None:
        owner = BenchSafety if key.startswith("bench_safety.") else Profile
        default = next((f.default for f in dataclasses.fields(owner) if f.name == name), None)
        number = isinstance(default, (int, float)) and not isinstance(default, bool)
        low = "> 0" if name in _POSITIVE else (">= 0" if number else "")
    limit = _AT_MOST.get(key)
    parts = [low] if low else []
    if limit is not None:
        parts.append(f"at most {limit:g}")
    return ", ".join(parts)


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
                raise bad(f"unknown command {unknown[0]!r}{did_you_mean(unknown[0], COMMAND_IDS)}; "
                          f"known: {', '.join(COMMAND_IDS)}")
        return tuple(value)
    raise bad("is not supported")  # pragma: no cover - every key is handled above


def _bench(where: str, value: Any) -> BenchSafety:
    if not isinstance(value, dict):
        raise ProfileError(f"{where}: [bench_safety] must be a table")
    known = {f.name: f.default for f in dataclasses.fields(BenchSafety)}
    out = {}
    for k, v in value.items():
        if k not in known:
            raise ProfileError(f"{where}: unknown key 'bench_safety.{k}'{did_you_mean(k, known)}; "
                               f"[bench_safety] has {', '.join(known)}")
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
        if key == EMULATOR_TABLE:
            if not isinstance(value, dict):
                raise ProfileError(f"{where}: [{EMULATOR_TABLE}] must be a table")
            continue  # the emulator's own choices (helmcheck emulate reads them); not part of the claim
        if key not in known:
            raise ProfileError(f"{where}: unknown key {key!r}{did_you_mean(key, [*known, EMULATOR_TABLE])}; "
                               f"every key: helmcheck profile keys")
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


#: The table of a profile file that holds ``helmcheck emulate``'s own settings, the freedoms the
#: profile leaves a vehicle (:mod:`helmcheck.emulator.freedoms`). Only the emulator
#: reads it (:func:`load_emulator_table`); a profile never carries it, so a tester never learns it.
EMULATOR_TABLE = "emulator"


def load_emulator_table(path: str | Path | None) -> dict[str, Any]:
    """The ``[emulator]`` table of the profile file at ``path`` (``{}`` when none); call after
    :func:`load_profile` has accepted the file."""
    import tomllib

    if path is None:
        return {}
    data = tomllib.loads(Path(path).read_bytes().decode("utf-8"))
    table = data.get(EMULATOR_TABLE, {})
    return table if isinstance(table, dict) else {}


#: The built-in emulator's profile, package data (``helmcheck/profiles/emulator.toml``).
EMULATOR_PROFILE = "profiles/emulator.toml"


def emulator_profile() -> Profile:
    """What ``helmcheck emulate`` claims (its ``$OXFLT`` extension and the missions it ships):
    the profile every certification of the built-in emulator uses (``make demo``, the tests)."""
    import tomllib
    from importlib import resources

    text = resources.files("helmcheck").joinpath(EMULATOR_PROFILE).read_text(encoding="utf-8")
    return profile_from_dict(tomllib.loads(text), where=f"helmcheck/{EMULATOR_PROFILE}")


def profile_keys() -> list[dataclasses.Field]:
    """The TOML keys of a profile, in file order (every :class:`Profile` field but ``name``)."""
    return [f for f in dataclasses.fields(Profile) if not f.metadata.get("not_a_key")]


def load_profile(path: str | Path | None) -> Profile:
    """Read a TOML profile; ``None`` gives the ``rh5`` defaults."""
    if path is None:
        return DEFAULT
    import tomllib  # only when there is a file to read

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
