"""The bench-safety interlock: what the tester refuses to send while the vehicle is on the bench.

With ``[bench_safety] in_water = false`` (the default) the tester never sends an ``$OMP`` whose
motor byte is above ``max_motor_byte``, nor an ``$OMS``/``$OPK``/``$OMW`` whose speed is above
``max_speed_kn`` — whatever a case or a hypothesis strategy asks for. The check runs on the raw
bytes at the link's one send function (:meth:`helmcheck.certify.vehicle.link.TesterLink.send`),
and it reads malformed lines too (a bad checksum or an unknown case of the ID): a faulty vehicle
might act on a line it should have discarded, so such a line must be safe as well. For the same
reason a motion command's speed is checked in **every alignment a vehicle could execute**: as
sent, and with up to two leading empty fields or a clear keyword passed over
(``$OMW,,<lat>,<lon>,…`` read from its second field), wherever the position fields are numbers.

Whatever ``in_water`` says, the tester never sends a remote-helm command the profile does not
claim (``commands``, §10): a vehicle without it would have to discard the line (RH-FRM-5), so
nothing it does with it can be judged, and a case that needs it is NOT-TESTED with that reason.
Decision (spec silent): any case of the ID counts (``$orwset`` for ``ORWSET``) — a faulty vehicle
might act on a line it should discard.
"""

from __future__ import annotations

from decimal import Decimal, InvalidOperation
from typing import Optional

from ...profile import COMMAND_IDS, Profile

__all__ = ["BenchGuard", "BenchSafetyRefused"]

#: field index (1 = first field after the ID) of the speed in each motion command
_SPEED_FIELD = {"OMS": 4, "OPK": 4, "OMW": 6}


#: How many leading empty fields (or a clear keyword, ``$OMW,CLEAR,<waypoint>``) a lenient or
#: faulty vehicle might pass over before reading a motion command's fields.
_MAX_SHIFT = 2
_CLEAR_WORDS = ("CLR", "CLEAR", "STOP")


def _skippable(field: str) -> bool:
    f = field.strip()
    return not f or f.upper() in _CLEAR_WORDS


def _executable(sid: str, f: list[str]) -> bool:
    """Could a vehicle act on these fields (``f[0]`` in the ID's place)? A waypoint needs a
    numeric latitude and longitude; ``$OMS`` a numeric heading."""
    need = 2 if sid in ("OMW", "OPK") else 1
    return len(f) > need and all(_number(x) is not None for x in f[1:need + 1])


class BenchSafetyRefused(Exception):
    """A line the interlock would not send; ``str()`` says why."""


def _number(text: str) -> Optional[Decimal]:
    try:
        v = Decimal(text.strip())
    except (InvalidOperation, ValueError):
        return None
    return v if v.is_finite() else None


class BenchGuard:
    """Checks outgoing bytes against the profile's ``[bench_safety]`` limits."""

    def __init__(self, profile: Profile):
        b = profile.bench_safety
        self.active = not b.in_water
        self.max_motor = int(b.max_motor_byte)
        self.max_speed = Decimal(str(b.max_speed_kn))
        self.unclaimed = frozenset(COMMAND_IDS) - frozenset(profile.commands)
        self.refused = 0

    def describe(self) -> dict:
        return {"enforced": self.active, "max_motor_byte": self.max_motor,
                "max_speed_kn": float(self.max_speed), "refused_lines": self.refused}

    def problem(self, raw: bytes) -> Optional[str]:
        """Why ``raw`` must not be sent, or ``None``. Every ``$`` sentence in ``raw`` is read."""
        text = raw.decode("latin-1")
        for chunk in text.split("$")[1:]:
            sid = chunk.split("*", 1)[0].split(",", 1)[0].strip().upper()
            if sid in self.unclaimed:
                return f"${sid} is not among the commands the profile claims (commands)"
            why = self._sentence(chunk) if self.active else None
            if why:
                return why
        return None

    def _sentence(self, chunk: str) -> Optional[str]:
        body = chunk.split("*", 1)[0].rstrip("\r\n")
        fields = body.split(",")
        sid = fields[0].strip().upper()
        if sid == "OMP" and len(fields) > 1:
            hexes = fields[1].strip()
            if len(hexes) >= 10:
                try:
                    motor = int(hexes[8:10], 16)
                except ValueError:
                    motor = None
                if motor is not None and motor > self.max_motor:
                    return (f"$OMP motor byte 0x{motor:02X} is above the bench limit "
                            f"0x{self.max_motor:02X} ([bench_safety] max_motor_byte)")
            return None
        idx = _SPEED_FIELD.get(sid)
        if idx is None:
            return None
        for shift in range(_MAX_SHIFT + 1):
            if shift >= len(fields):
                break
            if shift and not _skippable(fields[shift]):
                break  # only empty fields and clear keywords can be passed over
            f = fields[shift:]  # f[0] stands where the ID would
            if not _executable(sid, f) or len(f) <= idx:
                continue
            v = _number(f[idx])
            if v is not None and v > self.max_speed:
                return (f"${sid} speed {f[idx].strip()} kn is above the bench limit "
                        f"{self.max_speed} kn ([bench_safety] max_speed_kn)")
        return None

    def check(self, raw: bytes) -> None:
        why = self.problem(raw)
        if why:
            self.refused += 1
            raise BenchSafetyRefused(why)
