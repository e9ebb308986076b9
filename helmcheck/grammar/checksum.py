"""The NMEA checksum (RH-FRM-2): XOR of every byte strictly between ``$`` and ``*``."""

from __future__ import annotations

__all__ = ["checksum", "checksum_hex"]


def checksum(body: bytes | str) -> int:
    """XOR of the bytes of ``body`` (the text between ``$`` and ``*``), 0..255."""
    if isinstance(body, str):
        body = body.encode("latin-1")
    n = len(body)
    if n == 0:
        return 0
    # Fold the bytes as one big integer: XOR-ing halves keeps the per-byte XOR. This runs in
    # O(log n) big-integer steps instead of a Python loop per byte.
    width = 1
    while width < n:
        width <<= 1
    x = int.from_bytes(body, "big")
    bits = width * 8
    while bits > 8:
        bits >>= 1
        x = (x >> bits) ^ (x & ((1 << bits) - 1))
    return x


def checksum_hex(body: bytes | str) -> str:
    """The checksum as two upper-case, zero-padded hex digits, as a vehicle writes it (RH-FRM-3)."""
    return "%02X" % checksum(body)
