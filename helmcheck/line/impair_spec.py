"""What a line-fault relay does to the line: the ``--impair`` text, read into :class:`LineFaults`.

This module owns the impairment's settings — their names, units, defaults and checks (the table
:data:`ITEMS`, from which ``helmcheck relay --help`` and ``docs/line-faults.md`` are made) — and
nothing of how they are applied (that is :mod:`.impair`). Pure: no clock, no I/O.

The text is items separated by commas, ``KEY=VALUE``::

    baud=19200,<line-delay=0.6
    flip=1e-5,drop=1e-4,noise=1e-4,noise-len=2-12,stall=2s@30,cut=5s@60,seed=7
    baud=115200,rx-baud=19200

An item applies to both directions; prefixed with ``>`` it applies to the bytes going to the
vehicle only, with ``<`` to those coming from it. A prefixed item takes the place of an
unprefixed one of the same key for its direction, whatever their order; the same key twice for
the same direction is an error. ``stall`` may be given several times (each is a window); so may
``cut``, which is the line's as a whole and takes no prefix. Times are seconds (``0.6``, ``0.6s``,
``600ms``); ``T@X`` is T seconds from X seconds after the line began. Rates are probabilities
(``1e-4``, ``0.001``).

A bad item raises :class:`ImpairError`, whose message names the item and says why, on one line.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field, replace
from typing import Callable, NamedTuple

from ..grammar.wirelog import FROM_VEHICLE, TO_VEHICLE

__all__ = ["ImpairError", "Window", "DirectionFaults", "LineFaults", "Item", "ITEMS", "parse_impairment",
           "items_table"]

MAX_BAUD = 4_000_000  #: the highest rate accepted for ``baud``/``rx-baud``
DEFAULT_NOISE_LEN = (1, 8)  #: bytes in a noise burst when ``noise-len`` is not given
#: A run of bytes without LF is a line (for ``line-delay``) once the sender has been quiet this
#: long, or ``line-delay`` if that is longer.
MIN_QUIET_S = 0.1


class ImpairError(ValueError):
    """A bad ``--impair`` item; the message names it (one line)."""


class Window(NamedTuple):
    """``length`` seconds from ``at`` seconds after the line began (a stall, a cut)."""

    at: float
    length: float

    @property
    def end(self) -> float:
        return self.at + self.length

    def text(self) -> str:
        return f"{self.length:g}s@{self.at:g}"


@dataclass(frozen=True)
class DirectionFaults:
    """What the line does to the bytes going one way (:data:`ITEMS` says what each field means)."""

    baud: int = 0  #: paced at this rate, 8N1 (0: unpaced, each chunk at once)
    rx_baud: int = 0  #: the receiving UART's rate when it is not ``baud`` (0: the same)
    drop: float = 0.0
    flip: float = 0.0
    noise: float = 0.0
    noise_len: tuple[int, int] = DEFAULT_NOISE_LEN
    delay: float = 0.0
    jitter: float = 0.0
    line_delay: float = 0.0
    line_jitter: float = 0.0
    stalls: tuple[Window, ...] = ()

    @property
    def reframed(self) -> bool:
        """Is every byte re-framed by a receiver at another rate?"""
        return bool(self.rx_baud) and self.rx_baud != self.baud

    @property
    def holds_lines(self) -> bool:
        return self.line_delay > 0 or self.line_jitter > 0

    @property
    def quiet_s(self) -> float:
        """Silence that ends a line without LF (:data:`MIN_QUIET_S`)."""
        return max(self.line_delay, MIN_QUIET_S)

    @property
    def clean(self) -> bool:
        """Nothing is done to these bytes."""
        return self == DirectionFaults()


@dataclass(frozen=True)
class LineFaults:
    """Both directions' faults, the line's cuts and the seed of every random draw."""

    to_vehicle: DirectionFaults = field(default_factory=DirectionFaults)
    from_vehicle: DirectionFaults = field(default_factory=DirectionFaults)
    cuts: tuple[Window, ...] = ()
    seed: int = 0
    text: str = ""  #: the text it was read from ("" when built in code)

    def direction(self, d: str) -> DirectionFaults:
        """The faults of direction ``d`` (``>`` or ``<``)."""
        if d == TO_VEHICLE:
            return self.to_vehicle
        if d == FROM_VEHICLE:
            return self.from_vehicle
        raise ValueError(f"direction must be {TO_VEHICLE!r} or {FROM_VEHICLE!r}, not {d!r}")

    @property
    def clean(self) -> bool:
        return self.to_vehicle.clean and self.from_vehicle.clean and not self.cuts

    def with_seed(self, seed: int) -> "LineFaults":
        return replace(self, seed=int(seed))


# ---------------------------------------------------------------------- values
_TIME_RE = re.compile(r"^([0-9]*\.?[0-9]+(?:e[-+]?[0-9]+)?)(ms|s)?$", re.I)
_WINDOW_RE = re.compile(r"^([^@]+)@([^@]+)$")


def _number(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise ValueError(f"{text!r} is not a number") from None
    if not math.isfinite(v):
        raise ValueError(f"{text!r} is not a finite number")
    return v


def _rate(text: str) -> float:
    v = _number(text)
    if not 0.0 <= v <= 1.0:
        raise ValueError(f"a rate is a probability from 0 to 1, not {text}")
    return v


def _seconds(text: str) -> float:
    m = _TIME_RE.match(text.strip())
    if m is None:
        raise ValueError(f"{text!r} is not a time (seconds: 0.6, 0.6s, 600ms)")
    v = _number(m.group(1))
    return v / 1000.0 if (m.group(2) or "").lower() == "ms" else v


def _baud(text: str) -> int:
    if not text.isdigit() or not 0 < int(text) <= MAX_BAUD:
        raise ValueError(f"a baud rate is a whole number from 1 to {MAX_BAUD}, not {text!r}")
    return int(text)


def _window(text: str) -> Window:
    m = _WINDOW_RE.match(text)
    if m is None:
        raise ValueError(f"want T@X (T seconds from X seconds after the start), not {text!r}")
    length, at = _seconds(m.group(1)), _seconds(m.group(2))
    if length <= 0:
        raise ValueError(f"the length {m.group(1)!r} is not above zero")
    return Window(at, length)


def _length(text: str) -> tuple[int, int]:
    lo, sep, hi = text.partition("-")
    if not lo.isdigit() or (sep and not hi.isdigit()):
        raise ValueError(f"want N or A-B bytes, not {text!r}")
    a, b = int(lo), int(hi) if sep else int(lo)
    if not 1 <= a <= b <= 4096:
        raise ValueError(f"want 1 <= A <= B <= 4096 bytes, not {text!r}")
    return a, b


def _seed(text: str) -> int:
    if not re.fullmatch(r"[0-9]{1,19}", text):
        raise ValueError(f"a seed is a whole number, not {text!r}")
    return int(text)


# ---------------------------------------------------------------------- the items
class Item(NamedTuple):
    """One ``KEY=VALUE`` the text may hold."""

    key: str
    value: str  #: how the value is written, for the help
    field: str  #: the :class:`DirectionFaults` field (or ``cuts``, ``seed``)
    read: Callable[[str], object]
    scope: str  #: ``direction`` (prefix allowed), ``repeat`` (a window: prefix allowed, repeatable),
    #: ``line`` (the whole line's: no prefix) or ``line-repeat`` (the same, repeatable)
    meaning: str


ITEMS: tuple[Item, ...] = (
    Item("baud", "N", "baud", _baud, "direction",
         "pace the bytes as a UART sends them at N baud, 8N1: 10 bits a byte, one after another"),
    Item("rx-baud", "N", "rx_baud", _baud, "direction",
         "the receiving UART runs at N baud, not at 'baud': the bit stream sent at 'baud' is re-sampled "
         "at N (start bit, 8 data bits, stop bit), giving the garbage a wrong baud gives; needs 'baud'"),
    Item("drop", "P", "drop", _rate, "direction",
         "each byte is lost with probability P (its time on the line passes)"),
    Item("flip", "P", "flip", _rate, "direction", "each of a byte's 8 data bits is flipped with probability P"),
    Item("noise", "P", "noise", _rate, "direction",
         "before each byte, with probability P, a burst of random bytes (paced like the others)"),
    Item("noise-len", "N|A-B", "noise_len", _length, "direction",
         f"a burst's length in bytes, N or drawn from A to B (default {DEFAULT_NOISE_LEN[0]}-{DEFAULT_NOISE_LEN[1]})"),
    Item("delay", "S", "delay", _seconds, "direction", "every byte S seconds late"),
    Item("jitter", "S", "jitter", _seconds, "direction",
         "every byte a further 0 to S seconds late, drawn per byte (never out of order)"),
    Item("line-delay", "S", "line_delay", _seconds, "direction",
         "every line is held until S seconds after its last byte, then sent on (in order); a line ends "
         f"at LF, or when the sender has been quiet for S seconds (at least {MIN_QUIET_S:g} s)"),
    Item("line-jitter", "S", "line_jitter", _seconds, "direction",
         "every line a further 0 to S seconds late, drawn per line (never out of order)"),
    Item("stall", "T@X", "stalls", _window, "repeat",
         "from X seconds after the start, for T seconds, nothing passes; then everything that waited, paced"),
    Item("cut", "T@X", "cuts", _window, "line-repeat",
         "from X seconds after the start, for T seconds, the line is cut both ways and what is sent is lost; "
         "the port of one side (the backseat's unless told otherwise) disappears and comes back under the "
         "same name: a pty is closed and a new one made behind the same link; a socket's connection drops"),
    Item("seed", "N", "seed", _seed, "line", "the seed of every random draw (default 0): the same seed and "
                                            "the same bytes give the same faults"),
)
_BY_KEY = {i.key: i for i in ITEMS}


def parse_impairment(text: str, *, seed: int | None = None) -> LineFaults:
    """Read an ``--impair`` text (module docstring); ``seed`` overrides the text's.
    Raises :class:`ImpairError` naming the first bad item."""
    both: dict[str, object] = {}
    one: dict[str, dict[str, object]] = {TO_VEHICLE: {}, FROM_VEHICLE: {}}
    stalls: dict[str, list[Window]] = {"": [], TO_VEHICLE: [], FROM_VEHICLE: []}
    cuts: list[Window] = []
    line_seed, seen_seed = 0, False
    for raw in text.split(","):
        item = raw.strip()
        if not item:
            if text.strip():
                raise ImpairError(f"an empty item in {text!r} (two commas, or one at an end)")
            continue
        prefix = item[0] if item[0] in (TO_VEHICLE, FROM_VEHICLE) else ""
        key, eq, value = item[len(prefix):].partition("=")
        key = key.strip().lower()
        spec = _BY_KEY.get(key)
        if spec is None or not eq:
            known = ", ".join(i.key for i in ITEMS)
            why = "not KEY=VALUE" if spec is not None else f"unknown key {key!r}"
            raise ImpairError(f"{item!r}: {why} (keys: {known})")
        try:
            v = spec.read(value.strip())
        except ValueError as e:
            raise ImpairError(f"{item!r}: {e}") from None
        if spec.scope.startswith("line") and prefix:
            raise ImpairError(f"{item!r}: {key} is the whole line's, it takes no '>' or '<'")
        if spec.key == "cut":
            cuts.append(v)  # type: ignore[arg-type]
        elif spec.key == "seed":
            if seen_seed:
                raise ImpairError(f"{item!r}: seed given twice")
            line_seed, seen_seed = v, True  # type: ignore[assignment]
        elif spec.key == "stall":
            stalls[prefix].append(v)  # type: ignore[arg-type]
        else:
            target = one[prefix] if prefix else both
            if spec.field in target:
                where = f"for {prefix}" if prefix else "for both directions"
                raise ImpairError(f"{item!r}: {key} given twice {where}")
            target[spec.field] = v
    dirs = {}
    for d in (TO_VEHICLE, FROM_VEHICLE):
        values = {**both, **one[d]}
        wins = tuple(sorted(stalls[""] + stalls[d]))
        f = DirectionFaults(**values, stalls=wins)  # type: ignore[arg-type]
        if f.rx_baud and not f.baud:
            raise ImpairError(f"'rx-baud={f.rx_baud}' for {d}: needs baud=N too (the rate the bytes are sent at)")
        dirs[d] = f
    return LineFaults(dirs[TO_VEHICLE], dirs[FROM_VEHICLE], tuple(sorted(cuts)),
                      int(seed if seed is not None else line_seed), text.strip())


def items_table(indent: str = "  ", width: int = 96) -> str:
    """The items as plain text for ``--help``: ``KEY=VALUE  meaning``, wrapped."""
    import textwrap

    lines = []
    for i in ITEMS:
        head = f"{i.key}={i.value}"
        scope = {"direction": "", "repeat": " (repeatable)", "line": " (no > or <)",
                 "line-repeat": " (repeatable; no > or <)"}[i.scope]
        body = textwrap.wrap(i.meaning + scope, width - len(indent) - 18)
        lines.append(f"{indent}{head:<16}  {body[0]}")
        lines += [f"{indent}{'':<16}  {b}" for b in body[1:]]
    return "\n".join(lines)
