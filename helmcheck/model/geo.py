"""Small geodesy helpers: great-circle distance (``$OPK`` 10-mile rule, ``$OSI`` field 7), and
the knot in metres per second (speeds are in knots: ``$OMS``, ``$OPK``, ``$OMW``, ``$OSI`` field 6).

Distances use the haversine formula on a sphere of radius 6 371 008.8 m (the IUGG mean
radius); over the 16 km of the ``$OPK`` limit (RH-PK-1, RH-RD-9) it differs from the ellipsoid
by well under 0.5 %, far less than any plausible test margin.
"""

from __future__ import annotations

import math

__all__ = ["distance_m", "EARTH_RADIUS_M", "KNOT_MPS"]

EARTH_RADIUS_M = 6_371_008.8
KNOT_MPS = 1852.0 / 3600.0  #: metres per second in one knot


def distance_m(lat1: float, lon1: float, lat2: float, lon2: float) -> float:
    """Great-circle distance in metres between two points in signed decimal degrees."""
    p1, p2 = math.radians(lat1), math.radians(lat2)
    dp = p2 - p1
    dl = math.radians(lon2 - lon1)
    a = math.sin(dp / 2) ** 2 + math.cos(p1) * math.cos(p2) * math.sin(dl / 2) ** 2
    return 2 * EARTH_RADIUS_M * math.asin(min(1.0, math.sqrt(a)))
