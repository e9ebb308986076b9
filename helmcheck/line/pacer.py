"""The line pacer (:class:`LinePacer`): how long bytes take on a UART at a baud rate.

:class:`LinePacer` is the sans-IO model of the line's capacity: 10 bits per byte (8N1,
:func:`helmcheck.grammar.wirelog.transmit_time`) at the baud rate, so a sender can pace its output
as a real UART would (RH-ACK-2's "serial transmit time", RH-BS-4's line budget). Pacing is wall
time; it never scales with a time scale (RH-TIM-2).
"""

from __future__ import annotations

from ..grammar.wirelog import transmit_time


class LinePacer:
    """Sans-IO model of a UART's capacity: a byte takes the 8N1 :func:`transmit_time` at ``baud``.

    ``reserve(n, now)`` books ``n`` bytes onto the line and returns when they may start; the
    line is then busy until :attr:`free_at`. ``baud = 0`` means unpaced (everything at once)."""

    __slots__ = ("baud", "free_at", "_per_byte")

    def __init__(self, baud: int):
        self.baud = baud
        self.free_at = 0.0
        self._per_byte = transmit_time(1, baud)

    def transmit_time(self, n: int) -> float:
        return n * self._per_byte

    def start_time(self, now: float) -> float:
        """When the next byte booked now may start."""
        return now if self.free_at <= now else self.free_at

    def reserve(self, n: int, now: float) -> float:
        start = self.start_time(now)
        self.free_at = start + n * self._per_byte
        return start

    def reset(self, now: float) -> None:
        self.free_at = now
