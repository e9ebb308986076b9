"""Hypothesis strategies: a valid, in-range object of every sentence class (rh5 profile)."""

from __future__ import annotations

from decimal import Decimal

from hypothesis import strategies as st

from helmcheck.grammar import sentences as S
from helmcheck.profile import SAFETY_CODES

TEXT_ALPHABET = "".join(chr(c) for c in range(0x20, 0x7F) if chr(c) not in "$*,")
text = st.text(alphabet=TEXT_ALPHABET, min_size=1, max_size=12)
name_text = st.text(alphabet="abcdefghijklmnopqrstuvwxyz0123456789_.-", min_size=1, max_size=12).filter(
    lambda s: s not in (".", "..") and ".." not in s.split("/"))


def dec(lo, hi, places=3):
    return st.decimals(min_value=Decimal(str(lo)), max_value=Decimal(str(hi)), places=places,
                       allow_nan=False, allow_infinity=False)


heading = dec(0, "359.99", 2)
lat = dec(-90, 90, 6)
lon = dec(-180, 180, 6)
speed = dec(0, "4.5", 1)
timeout = st.integers(1, 120)
any_dec = dec(-9999, 9999, 3)
hex10 = st.text(alphabet="0123456789ABCDEFabcdef", min_size=10, max_size=10)
hex10_upper = st.text(alphabet="0123456789ABCDEF", min_size=10, max_size=10)
letters = st.sampled_from("GCSPYDTI")

omw = st.builds(S.OMW, lat=lat, lon=lon, depth1=dec(-100, 100, 1),
                depth2=st.none() | dec(-100, 100, 1), max_pitch=dec(0, 45, 1), speed=speed,
                park_s=st.integers(0, 86400), sensors=st.just("") | text)

COMMANDS = {
    S.OMS: st.builds(S.OMS, heading=heading, depth=dec(0, 100, 1), max_pitch=dec(0, 45, 1),
                     speed=speed, timeout=timeout),
    S.OMP: st.builds(S.OMP, actuators=hex10, reserved=st.just("00"), timeout=timeout),
    S.OJW: st.builds(S.OJW, waypoint=st.integers(0, 999)),
    S.OMSTOP: st.builds(S.OMSTOP, flag=st.just(0)),
    S.OMLOAD: st.builds(S.OMLOAD, name=name_text, flag=st.integers(0, 9)),
    S.OMSTART: st.builds(S.OMSTART, ignore_gps=st.integers(0, 1), ignore_sounder=st.integers(0, 1),
                         calibrate_pressure=st.integers(0, 1), mission_type=st.integers(0, 1),
                         name=name_text, srp=st.none() | st.just("") | name_text),
    S.OMSTARTPaper: st.builds(S.OMSTARTPaper, flag=st.integers(0, 3)),
    S.OPOS: st.builds(S.OPOS, lat=lat, lon=lon, speed=speed,
                      conductivity=st.none() | dec(0, 100, 2), temperature=st.none() | dec(-5, 50, 2),
                      trailing_empty=st.booleans()),
    S.OSD: st.builds(S.OSD, letters=st.lists(st.just("") | letters, max_size=10).map(tuple)),
    S.OLOGL: st.builds(S.OLOGL, labels=st.lists(text, min_size=1, max_size=12).map(tuple)),
    S.OLOGD: st.builds(S.OLOGD, values=st.lists(st.just("") | text, min_size=1, max_size=12).map(tuple)),
    S.ORWSET: st.one_of(
        st.builds(S.ORWSET, setting=st.sampled_from(SAFETY_CODES + ("SafetyAction",)), access=st.just("R")),
        st.builds(S.ORWSET, setting=st.sampled_from(SAFETY_CODES), access=st.just("W"),
                  state=st.integers(0, 1), values=st.lists(text, max_size=3).map(tuple)),
        st.builds(S.ORWSET, setting=st.just("SafetyAction"), access=st.just("W"),
                  state=st.integers(0, 1), values=st.sampled_from([("park",), ("srp",)])),
    ),
    S.ODVL: st.builds(S.ODVL, x=dec(-5, 5, 3), y=dec(-5, 5, 3), timeout=timeout),
    S.OPK: st.builds(S.OPK, lat=lat, lon=lon, minutes=st.integers(1, 1440), speed=speed),
    S.OMW: omw,
    S.OMWClear: st.builds(S.OMWClear, keyword=st.sampled_from(["Clr", "CLEAR", "STOP", "clr", "Clear"]),
                          waypoint=st.none() | omw),
    S.OXFLT: st.builds(S.OXFLT, code=st.sampled_from(SAFETY_CODES)),
}

_osi_tail = st.tuples(
    st.just("") | text, dec(0, 99, 4), heading, dec(0, 100, 1), dec(0, 100, 1).map(str),
    st.sampled_from(["True", "False"]), text,
    st.lists(st.just("") | text, min_size=3, max_size=3).map(tuple),
)


def _osi(base, tail):
    mission, rem, th, depth, batt, srp, name, reserved = tail
    return S.OSI(*base, mission_name=mission, remaining_time=rem, true_heading=th, depth=depth,
                 battery=batt, srp_active=srp, vehicle_name=name, reserved=reserved)


osi = st.builds(
    _osi,
    st.tuples(hex10_upper, st.sampled_from(["S", "N", "P", "mP", "A", "M", "W"]), st.integers(0, 99),
              lat, lon, dec(0, 10, 2), dec(0, 9999, 2), st.sampled_from(("N",) + SAFETY_CODES),
              dec(0, 200, 3), st.integers(0, 86400), dec(-30, 30, 4)),
    _osi_tail,
)

REPLIES = {
    S.ACK: st.one_of(
        st.builds(S.ACK, type=st.integers(1, 17).filter(lambda t: t != 12), status=st.just(0), err=st.just(0)),
        st.builds(S.ACK, type=st.integers(1, 17).filter(lambda t: t != 12), status=st.just(1), err=st.integers(1, 53)),
        st.builds(S.ACK, type=st.just(12), status=st.just(0), err=st.just(0),
                  extra=st.lists(st.just("") | text, max_size=6).map(tuple)),
    ),
    S.OSI: osi,
    S.Compass: st.builds(S.Compass, heading=heading, pitch=dec(-90, 90, 2), roll=dec(-90, 90, 2),
                         temperature=dec(-10, 50, 1), depth=dec(0, 300, 2),
                         extra=st.lists(st.tuples(st.sampled_from(["M", "Mx", "My", "Mz", "A", "Ax", "Ay", "Az"]),
                                                  any_dec), max_size=4).map(tuple)),
    S.GPRMC: st.builds(
        S.GPRMC, time=st.sampled_from(["", "123519", "235959.00"]), status=st.sampled_from(["", "A", "V"]),
        lat=st.sampled_from(["", "4807.038", "0000.0000", "8959.9999"]), ns=st.sampled_from(["", "N", "S"]),
        lon=st.sampled_from(["", "01131.000", "17959.9"]), ew=st.sampled_from(["", "E", "W"]),
        sog=st.sampled_from(["", "0.0", "022.4"]), cog=st.sampled_from(["", "084.4", "359.9"]),
        date=st.sampled_from(["", "230394", "211126"]), magvar=st.sampled_from(["", "003.1"]),
        magvar_ew=st.sampled_from(["", "W", "E"]), mode=st.sampled_from([None, "", "A", "D", "N"])),
    S.OPI: st.builds(S.OPI, percent=dec(0, 100, 1), remaining_wh=dec(0, 2000, 1), watts=any_dec,
                     volts=dec(0, 40, 2), amps=any_dec, minutes_left=dec(0, 9999, 0),
                     battery_state=st.sampled_from("CDF"), leak=st.integers(0, 1)),
    S.DVL: st.builds(S.DVL, vx=any_dec, vy=any_dec, vz=any_dec, x_dist=any_dec, y_dist=any_dec,
                     dfs=any_dec, altitude=any_dec),
    S.OYSI: st.builds(S.OYSI, readings=st.lists(st.tuples(text, any_dec), min_size=1, max_size=5).map(tuple)),
    S.OCTD: st.builds(S.OCTD, conductivity=dec(0, 100, 3), temperature=dec(-5, 50, 3), depth=dec(0, 300, 2)),
    S.OINS: st.builds(S.OINS, lat=lat, lon=lon, depth=dec(0, 300, 2), heading=heading),
}

ALL = {**COMMANDS, **REPLIES}
any_sentence = st.one_of(*ALL.values())
