"""Typed, immutable sentence objects: one class per remote helm sentence, both directions.

Each class mirrors one rule of ``remote_helm.lark``; ``tests/test_grammar_classes.py`` checks
that every class's fields are exactly the grammar rule's fields, so the grammar stays the one
definition. Numbers are kept as :class:`decimal.Decimal` so that the text a device sent is
reproduced exactly (``10`` and ``10.0`` are the same value but different bytes); integers that
the profile defines as integers are :class:`int`. Optional fields use ``None`` for "absent"
and ``""`` (text) for "present but empty", which keeps ``format(parse(b)) == b``.

``repr`` of every object is valid Python (given ``from decimal import Decimal`` and the class).
Formatting to bytes lives in :mod:`helmcheck.grammar.codec`; this module only holds data.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from decimal import Decimal
from typing import ClassVar, Optional

__all__ = [
    "Sentence", "Command", "Reply",
    "OMS", "OMP", "OJW", "OMSTOP", "OMLOAD", "OMSTART", "OMSTARTPaper", "OPOS", "OSD", "OLOGL",
    "OLOGD", "ORWSET", "ODVL", "OPK", "OMW", "OMWClear", "OXFLT",
    "ACK", "OSI", "Compass", "GPRMC", "OPI", "DVL", "OYSI", "OCTD", "OINS",
    "COMMAND_CLASSES", "REPLY_CLASSES", "ALL_CLASSES", "Dec",
]

Dec = Decimal
_frozen = dict(frozen=True, slots=True)


class Sentence:
    """Base of every sentence. ``ID`` is the wire ID (``OMS``, ``C``); ``RULE`` the grammar rule."""

    __slots__ = ()
    ID: ClassVar[str]
    RULE: ClassVar[str]

    @classmethod
    def field_names(cls) -> tuple[str, ...]:
        names = _FIELD_NAMES.get(cls)
        if names is None:
            names = _FIELD_NAMES[cls] = tuple(f.name for f in fields(cls))  # type: ignore[arg-type]
        return names

    def as_dict(self) -> dict:
        """Field values as JSON-friendly data (Decimals become their exact text)."""
        out = {}
        for name in self.field_names():
            v = getattr(self, name)
            out[name] = v if type(v) in _PLAIN else _jsonable(v)
        return out


_FIELD_NAMES: dict[type, tuple[str, ...]] = {}
_PLAIN = frozenset({str, int, bool, type(None)})


def _jsonable(v):
    if isinstance(v, Decimal):
        return format(v, "f")
    if isinstance(v, tuple):
        return [_jsonable(x) for x in v]
    if isinstance(v, Sentence):
        return {"type": type(v).__name__, **v.as_dict()}
    return v


class Command(Sentence):
    """A sentence the backseat sends to the vehicle."""

    __slots__ = ()
    #: ACK type the vehicle answers with (RH-ACK-1); None for $OXFLT, which is never acknowledged.
    ACK_TYPE: ClassVar[Optional[int]]
    #: The command's "incorrect values" error number (RH-ACK-3).
    ERR: ClassVar[Optional[int]]


class Reply(Sentence):
    """A sentence the vehicle sends to the backseat."""

    __slots__ = ()


# --------------------------------------------------------------------------- commands


@dataclass(**_frozen)
class OMS(Command):
    """Servo: heading, depth, max pitch, speed, timeout (RH-SRV-1..4)."""

    ID: ClassVar[str] = "OMS"
    RULE: ClassVar[str] = "oms"
    ACK_TYPE: ClassVar[int] = 9
    ERR: ClassVar[int] = 20
    heading: Decimal
    depth: Decimal
    max_pitch: Decimal
    speed: Decimal
    timeout: int


@dataclass(**_frozen)
class OMP(Command):
    """Primitive: fins and motor as ten hex digits, reserved ``00``, timeout (RH-PRM-1..4)."""

    ID: ClassVar[str] = "OMP"
    RULE: ClassVar[str] = "omp"
    ACK_TYPE: ClassVar[int] = 10
    ERR: ClassVar[int] = 21
    actuators: str  #: ten hex digits as sent (case preserved): YT YB PL PR MOTOR
    reserved: str
    timeout: int

    @property
    def actuator_bytes(self) -> tuple[int, int, int, int, int]:
        a = self.actuators
        return tuple(int(a[i:i + 2], 16) for i in range(0, 10, 2))  # type: ignore[return-value]

    @property
    def motor(self) -> int:
        return int(self.actuators[8:10], 16)


@dataclass(**_frozen)
class OJW(Command):
    """Jump to waypoint n, 0-based (RH-JW-1..2)."""

    ID: ClassVar[str] = "OJW"
    RULE: ClassVar[str] = "ojw"
    ACK_TYPE: ClassVar[int] = 7
    ERR: ClassVar[int] = 19
    waypoint: int


@dataclass(**_frozen)
class OMSTOP(Command):
    """Stop the mission; the flag is always 0 (RH-MSN-3)."""

    ID: ClassVar[str] = "OMSTOP"
    RULE: ClassVar[str] = "omstop"
    ACK_TYPE: ClassVar[int] = 1
    ERR: ClassVar[int] = 28
    flag: int = 0


@dataclass(**_frozen)
class OMLOAD(Command):
    """Load a mission by name, resolved inside the mission directory (RH-MSN-1)."""

    ID: ClassVar[str] = "OMLOAD"
    RULE: ClassVar[str] = "omload"
    ACK_TYPE: ClassVar[int] = 2
    ERR: ClassVar[int] = 29
    name: str
    flag: int = 0


@dataclass(**_frozen)
class OMSTART(Command):
    """rh5 start-by-name form (RH-MSN-2, RH-RD-6). ``srp`` None = 5 fields, "" = empty 6th."""

    ID: ClassVar[str] = "OMSTART"
    RULE: ClassVar[str] = "omstart_named"
    ACK_TYPE: ClassVar[int] = 3
    ERR: ClassVar[int] = 30
    ignore_gps: int
    ignore_sounder: int
    calibrate_pressure: int
    mission_type: int
    name: str
    srp: Optional[str] = None


@dataclass(**_frozen)
class OMSTARTPaper(Command):
    """Paper form ``$OMSTART,<flag>``: starts the loaded mission (RH-MSN-2)."""

    ID: ClassVar[str] = "OMSTART"
    RULE: ClassVar[str] = "omstart_paper"
    ACK_TYPE: ClassVar[int] = 3
    ERR: ClassVar[int] = 30
    flag: int


@dataclass(**_frozen)
class OPOS(Command):
    """Position, speed, conductivity, temperature (RH-POS-1..2). ``trailing_empty``: a 6th empty field."""

    ID: ClassVar[str] = "OPOS"
    RULE: ClassVar[str] = "opos"
    ACK_TYPE: ClassVar[int] = 6
    ERR: ClassVar[int] = 18
    lat: Decimal
    lon: Decimal
    speed: Decimal
    conductivity: Optional[Decimal] = None
    temperature: Optional[Decimal] = None
    trailing_empty: bool = False


@dataclass(**_frozen)
class OSD(Command):
    """Data request: one entry per field, each "" or a letter of GCSPYDTI (RH-OSD-1..2, RH-RD-7)."""

    ID: ClassVar[str] = "OSD"
    RULE: ClassVar[str] = "osd"
    ACK_TYPE: ClassVar[int] = 8
    ERR: ClassVar[int] = 27
    letters: tuple[str, ...] = ()

    @property
    def requested(self) -> tuple[str, ...]:
        """The letters asked for, in request order, empties dropped, repeats kept."""
        return tuple(x for x in self.letters if x)


@dataclass(**_frozen)
class OLOGL(Command):
    """Log column labels, 1–12 (RH-LOG-1)."""

    ID: ClassVar[str] = "OLOGL"
    RULE: ClassVar[str] = "ologl"
    ACK_TYPE: ClassVar[int] = 5
    ERR: ClassVar[int] = 24
    labels: tuple[str, ...]


@dataclass(**_frozen)
class OLOGD(Command):
    """Log data values, 1–12, each possibly empty (RH-LOG-2)."""

    ID: ClassVar[str] = "OLOGD"
    RULE: ClassVar[str] = "ologd"
    ACK_TYPE: ClassVar[int] = 4
    ERR: ClassVar[int] = 25
    values: tuple[str, ...]


@dataclass(**_frozen)
class ORWSET(Command):
    """Read (``R``) or write (``W``, state 0|1, 0–3 values) a vehicle setting (RH-SET-1..2, RH-RD-8)."""

    ID: ClassVar[str] = "ORWSET"
    RULE: ClassVar[str] = "orwset"
    ACK_TYPE: ClassVar[int] = 12
    ERR: ClassVar[int] = 23
    setting: str
    access: str  #: "R" or "W"
    state: Optional[int] = None
    values: tuple[str, ...] = ()


@dataclass(**_frozen)
class ODVL(Command):
    """DVL velocities x (forward), y (port) in m/s for timeout seconds (RH-DVL-1)."""

    ID: ClassVar[str] = "ODVL"
    RULE: ClassVar[str] = "odvl"
    ACK_TYPE: ClassVar[int] = 15
    ERR: ClassVar[int] = 35
    x: Decimal
    y: Decimal
    timeout: int


@dataclass(**_frozen)
class OPK(Command):
    """Park at lat/lon for minutes at speed (RH-PK-1..3)."""

    ID: ClassVar[str] = "OPK"
    RULE: ClassVar[str] = "opk"
    ACK_TYPE: ClassVar[int] = 11
    ERR: ClassVar[int] = 22
    lat: Decimal
    lon: Decimal
    minutes: int
    speed: Decimal


@dataclass(**_frozen)
class OMW(Command):
    """On-the-fly waypoint (RH-OMW-1..5). ``depth2`` and ``sensors`` may be empty ("")."""

    ID: ClassVar[str] = "OMW"
    RULE: ClassVar[str] = "omw"
    ACK_TYPE: ClassVar[int] = 16
    ERR: ClassVar[int] = 36
    lat: Decimal
    lon: Decimal
    depth1: Decimal
    depth2: Optional[Decimal]
    max_pitch: Decimal
    speed: Decimal
    park_s: int
    sensors: str


@dataclass(**_frozen)
class OMWClear(Command):
    """``$OMW,Clr`` / ``CLEAR`` / ``STOP`` (any case), optionally followed by a waypoint (RH-OMW-3, RH-RD-4)."""

    ID: ClassVar[str] = "OMW"
    RULE: ClassVar[str] = "omw_clear"
    ACK_TYPE: ClassVar[int] = 16
    ERR: ClassVar[int] = 36
    keyword: str
    waypoint: Optional[OMW] = None


@dataclass(**_frozen)
class OXFLT(Command):
    """Test extension: raise safety violation ``code`` at once; never acknowledged (RH-SAF-5)."""

    ID: ClassVar[str] = "OXFLT"
    RULE: ClassVar[str] = "oxflt"
    ACK_TYPE: ClassVar[None] = None
    ERR: ClassVar[None] = None
    code: str


# --------------------------------------------------------------------------- replies


@dataclass(**_frozen)
class ACK(Reply):
    """Acknowledgement (RH-ACK-1..6); ``extra`` is the ``$ORWSET`` reply tail (RH-SET-1, RH-RD-8)."""

    ID: ClassVar[str] = "ACK"
    RULE: ClassVar[str] = "ack"
    type: int
    status: int
    err: int
    extra: tuple[str, ...] = ()


@dataclass(**_frozen)
class OSI(Reply):
    """Vehicle state (RH-OUT-1). Fields 12–21 are ``None`` when absent (older profiles)."""

    ID: ClassVar[str] = "OSI"
    RULE: ClassVar[str] = "osi"
    actuators: str
    mode: str
    next_waypoint: int
    lat: Decimal
    lon: Decimal
    speed: Decimal
    distance: Decimal
    error_state: str
    altimeter: Decimal
    park_time: int  #: seconds, written ``P<seconds>``
    declination: Decimal
    mission_name: Optional[str] = None
    remaining_time: Optional[Decimal] = None
    true_heading: Optional[Decimal] = None
    depth: Optional[Decimal] = None
    battery: Optional[str] = None  #: rh5 battery percent; rh4 SRP active (field 16)
    srp_active: Optional[str] = None  #: rh5 ``True``/``False`` (field 17)
    vehicle_name: Optional[str] = None
    reserved: tuple[str, ...] = ()  #: fields 19–21, passed through

    @property
    def field_count(self) -> int:
        # the optional fields in order, the first absent one ending the count (written out: the
        # judges read the count of every report)
        if self.mission_name is None:
            return 11
        if self.remaining_time is None:
            return 12
        if self.true_heading is None:
            return 13
        if self.depth is None:
            return 14
        if self.battery is None:
            return 15
        if self.srp_active is None:
            return 16
        if self.vehicle_name is None:
            return 17
        return 18 + len(self.reserved)


@dataclass(**_frozen)
class Compass(Reply):
    """``$C<hdg>P<pitch>R<roll>T<temp>D<depth>`` plus optional OS5000 letter fields (RH-FRM-8)."""

    ID: ClassVar[str] = "C"
    RULE: ClassVar[str] = "compass"
    heading: Decimal
    pitch: Decimal
    roll: Decimal
    temperature: Decimal
    depth: Decimal
    extra: tuple[tuple[str, Decimal], ...] = ()


@dataclass(**_frozen)
class GPRMC(Reply):
    """NMEA RMC (RH-OUT-2); 11 fields, or 12 with the NMEA 2.3 mode indicator. Empty fields are ""."""

    ID: ClassVar[str] = "GPRMC"
    RULE: ClassVar[str] = "gprmc"
    time: str
    status: str
    lat: str
    ns: str
    lon: str
    ew: str
    sog: str
    cog: str
    date: str
    magvar: str
    magvar_ew: str
    mode: Optional[str] = None


@dataclass(**_frozen)
class OPI(Reply):
    """Power (RH-OUT-2)."""

    ID: ClassVar[str] = "OPI"
    RULE: ClassVar[str] = "opi"
    percent: Decimal
    remaining_wh: Decimal
    watts: Decimal
    volts: Decimal
    amps: Decimal
    minutes_left: Decimal  #: time to full/empty, minutes
    battery_state: str  #: C charging, D discharging, F fault
    leak: int


@dataclass(**_frozen)
class DVL(Reply):
    """DVL data (RH-OUT-2)."""

    ID: ClassVar[str] = "DVL"
    RULE: ClassVar[str] = "dvl"
    vx: Decimal
    vy: Decimal
    vz: Decimal
    x_dist: Decimal
    y_dist: Decimal
    dfs: Decimal
    altitude: Decimal


@dataclass(**_frozen)
class OYSI(Reply):
    """YSI sonde values as name/value pairs; this profile's own format (RH-OUT-2 [D])."""

    ID: ClassVar[str] = "OYSI"
    RULE: ClassVar[str] = "oysi"
    readings: tuple[tuple[str, Decimal], ...]


@dataclass(**_frozen)
class OCTD(Reply):
    """CTD: conductivity mS/cm, temperature °C, depth m (RH-OUT-2 [D])."""

    ID: ClassVar[str] = "OCTD"
    RULE: ClassVar[str] = "octd"
    conductivity: Decimal
    temperature: Decimal
    depth: Decimal


@dataclass(**_frozen)
class OINS(Reply):
    """INS: lat, lon, depth, heading (RH-OUT-2 [D])."""

    ID: ClassVar[str] = "OINS"
    RULE: ClassVar[str] = "oins"
    lat: Decimal
    lon: Decimal
    depth: Decimal
    heading: Decimal


COMMAND_CLASSES: tuple[type[Command], ...] = (
    OMS, OMP, OJW, OMSTOP, OMLOAD, OMSTART, OMSTARTPaper, OPOS, OSD, OLOGL, OLOGD, ORWSET, ODVL,
    OPK, OMW, OMWClear, OXFLT,
)
REPLY_CLASSES: tuple[type[Reply], ...] = (ACK, OSI, Compass, GPRMC, OPI, DVL, OYSI, OCTD, OINS)
ALL_CLASSES: tuple[type[Sentence], ...] = COMMAND_CLASSES + REPLY_CLASSES
