"""The NMEA checksum (RH-FRM-2): XOR of every byte strictly between ``$`` and ``*``."""

from __future__ import annotations

__all__ = ["checksum", "checksum_hex"]


def _shifts(n: int) -> tuple[int, ...]:
    width = 1
    while width < n:
        width <<= 1
    out = []
    while width > 1:
        width >>= 1
        out.append(width * 8)
    return tuple(out)


#: For a body of n bytes, the bit shifts that fold it onto its lowest byte.
_SHIFTS = tuple(_shifts(n) for n in range(1025))


def checksum(body: bytes | str) -> int:
    """XOR of the bytes of ``body`` (the text between ``$`` and ``*``), 0..255."""
    if isinstance(body, str):
        body = body.encode("latin-1")
    n = len(body)
    if n <= 16:
        x = 0
        for c in body:
            x ^= c
        return x
    # Fold the bytes as one big integer: x ^= x >> half, halving down to one byte, leaves the
    # XOR of every byte in the lowest byte. O(log n) integer steps instead of one per byte;
    # written out for bodies of up to 128 bytes (nearly every line), which saves the loop.
    x = int.from_bytes(body, "big")
    if n > 128:
        for k in _SHIFTS[n] if n < 1025 else _shifts(n):
            x ^= x >> k
        return x & 0xFF
    x ^= x >> 512
    x ^= x >> 256
    x ^= x >> 128
    x ^= x >> 64
    x ^= x >> 32
    x ^= x >> 16
    x ^= x >> 8
    return x & 0xFF


def checksum_hex(body: bytes | str) -> str:
    """The checksum as two upper-case, zero-padded hex digits, as a vehicle writes it (RH-FRM-3)."""
    return "%02X" % checksum(body)
