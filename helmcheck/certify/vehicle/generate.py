"""What the exploration draws: command lines aimed at the model's rows, errors and edges.

The strategies here are built from the profile and the model's own tables, never from one
vehicle's habits:

* :func:`commands` — every command the profile claims, each field drawn from the edges of its
  range (:mod:`helmcheck.grammar.ranges`: the lowest and highest value accepted, and the first
  value past each), the forms the grammar reads (``$OMW`` keywords in any case, ``CLEAR,<wp>``,
  the paper and rh5 ``$OMSTART``), mission names that must be refused (an absolute path, a drive
  letter, a ``..`` component, a file that is not there), ``$OJW`` indices around the mission's
  length, ``$OSD`` letter lists (the profile's letters in any order, unknown and lower-case ones),
  ``$OLOGL``/``$OLOGD`` value counts around the labels, ``$ORWSET`` reads and bad writes — so
  every error code of every command (:data:`helmcheck.model.transitions.ERRORS`, err 1, 17, 26,
  40) is one draw away;
* :func:`control_commands` — the four remote controls (RH-INT-1), drawn more often, with
  timeouts, ``$OPK`` minutes and queued-waypoint parks the observer can time on the line at the
  time scale (:func:`timeouts`; the ``{opk_min}`` and ``{qpark}`` templates, filled from the run's
  :mod:`.durations` when a line is sent): an accepted duration shorter than that is never drawn,
  so no observation is booked that the observer could not time;
* :func:`invalid_lines` — one mutation of a valid line (:data:`.steps.RAW_KINDS`, every kind)
  or an unknown ID.

Positions are drawn near the vehicle, ~110 km away, and past the ±90°/±180° edges (refused); the
in-range edges themselves (a pole, the antimeridian) are left out on purpose: a plant at the pole
has no heading and no longitude, which tests the simulator, not the protocol.

Bodies carry templates (``{lat}``, ``{mission}``, ``{wp_last}`` …: :mod:`.steps`) filled from
the vehicle's last report when sent. Speeds and the motor byte stay within ``[bench_safety]``
(the link refuses anything above it anyway, :mod:`.safety`), so the edge past ``max_speed_kn``
is drawn only where the bench allows it.
"""

from __future__ import annotations

from typing import Optional

from hypothesis import strategies as st

from ...profile import Profile
from .steps import RAW_KINDS

__all__ = ["commands", "FAMILIES", "EXPLORE_WRITES", "control_commands", "invalid_lines", "timeouts", "valid_commands", "osd_requests",
           "TIMEOUT_CHOICES", "bench_speed", "bench_motor"]

#: Remote-control timeouts the exploration draws from (seconds), before :func:`timeouts` keeps those
#: the observer can time on the line at the time scale.
TIMEOUT_CHOICES = (2, 3, 5, 8, 12, 20, 30, 45, 60, 90)


def timeouts(shortest: Optional[int], timeout_range=(1, 120)):
    """The timeouts an exploration sends: the shortest the observer can time on this line at this
    time scale (``shortest``, :attr:`.durations.Durations.to`) and the longer of
    :data:`TIMEOUT_CHOICES`, within the profile's ``timeout_range`` — at most five. ``None`` (no
    timeout the profile allows can be timed here): nothing is drawn (a control with a timeout is
    left out of the exploration rather than booked where it cannot be timed)."""
    lo, hi = int(timeout_range[0]), int(timeout_range[1])
    if shortest is None:
        return st.nothing()
    shortest = int(shortest)
    keep = sorted({shortest} | {d for d in TIMEOUT_CHOICES if max(lo, shortest) <= d <= hi})
    return st.sampled_from(keep[:5])


def bench_speed(p: Profile) -> float:
    bench = p.bench_safety
    return min(2.0, p.max_speed_kn, bench.max_speed_kn if not bench.in_water else 99.0)


def bench_motor(p: Profile) -> int:
    bench = p.bench_safety
    return max(0x80, min(0x90, bench.max_motor_byte) if not bench.in_water else 0x90)


def _num(lo: float, hi: float, places: int = 1):
    return st.integers(int(lo * 10 ** places), int(hi * 10 ** places)).map(lambda n: f"{n / 10 ** places:g}")


def _edges(lo: float, hi: float, inside, step: float = 1.0, hi_open: bool = False):
    """A value at an edge of ``[lo, hi]`` (``hi_open``: ``[lo, hi)``), one past an edge, or one from
    ``inside``."""
    top = hi - (0.1 if hi_open else 0.0)
    over = hi if hi_open else hi + step
    return st.one_of(st.sampled_from([f"{lo:g}", f"{top:g}", f"{lo - step:g}", f"{over:g}"]), inside)


def _timeouts_edges(p: Profile, tos):
    lo, hi = int(p.timeout_range[0]), int(p.timeout_range[1])
    # the accepted edges are sent only when they can be timed (tos); the refused ones always
    return st.one_of(tos, tos, tos, st.sampled_from([str(lo - 1), str(hi + 1)]))


def _oms(p: Profile, spd, tos):
    return st.builds(lambda h, d, pt, v, t: f"OMS,{h},{d},{pt},{v},{t}",
                     _edges(0, 360, _num(0, 359), hi_open=True), _edges(0, p.max_depth, _num(0, 4)),
                     _edges(0, 45, _num(0, 45, 0)), spd, _timeouts_edges(p, tos))


def _omp(p: Profile, motor: int, tos):
    hexb = st.integers(0x60, 0xA0).map(lambda b: f"{b:02X}")
    mot = st.integers(0x80, max(0x80, motor)).map(lambda b: f"{b:02X}")
    # one field off at a time: the timeout's edges with good bytes, bad bytes with a timeout the
    # vehicle accepts (else the timeout alone explains the refusal, and a vehicle that reads nine
    # hex digits as ten is not told apart from one that refuses them, RH-PRM-2)
    good = st.builds(lambda a, b, m, t: f"OMP,{a}{a}{b}{b}{m},00,{t}", hexb, hexb, mot, _timeouts_edges(p, tos))
    bad = st.builds(lambda form, t: form.format(t=t),
                    st.sampled_from(["OMP,808080808,00,{t}", "OMP,80808080800,00,{t}", "OMP,8080G08080,00,{t}",
                                     "OMP,8080808080,01,{t}", "OMP,8080808080,10,{t}", "OMP,8080808080,00",
                                     "OMP,8080,00,{t}"]),
                    tos)
    return st.one_of(good, bad)


def _ojw(p: Profile):
    b = p.waypoint_base
    last = p.mission_waypoints - 1 + b
    return st.sampled_from([b - 1, b, last, last + 1, "x"]).map(lambda n: f"OJW,{n}")


def _opk(spd):
    where = st.sampled_from(["{lat},{lon}", "{stn_lat},{lon}", "{far_lat},{lon}", "91,{lon}"])
    return st.builds(lambda w, m, v: f"OPK,{w},{m},{v}", where,
                     st.sampled_from(["0", "{opk_min}", "{opk_min}", "1440", "1441"]), spd)


def _omw(p: Profile, spd):
    park = st.sampled_from(["0", "0", "{qpark}", "86400", "86401"])
    depth = st.sampled_from(["2", "2", "0", "100", "101"])
    where = st.sampled_from(["{near_lat},{lon}", "{near_lat},{near_lon}", "{stn_lat},{lon}", "91,{lon}"])
    full = st.builds(lambda w, d, v, k: f"OMW,{w},{d},,15,{v},{k},", where, depth, spd, park)
    words = list(p.omw_clear_keywords) + [w.lower() for w in p.omw_clear_keywords] + ["Clear", "Clr2"]
    clear = st.sampled_from(words).map(lambda w: f"OMW,{w}")
    clear_wp = st.builds(lambda v: f"OMW,CLEAR,{{near_lat}},{{lon}},2,,15,{v},0,", spd)
    return st.one_of(full, full, clear, clear_wp)


def _mission_names():
    """The test mission, and names a vehicle must refuse: not there, an absolute path, a drive
    letter, a ``..`` component (RH-MSN-1, RH-RD-6), empty."""
    return st.sampled_from(["{mission}", "{mission}", "helmcheck-missing.mis", "../{mission}", "/{mission}",
                            "C:{mission}", "sub/../../{mission}", "..\\{mission}", ""])


def osd_requests(p: Profile):
    """``$OSD`` bodies: the profile's letters in any order and number (RH-OSD-1, RH-RD-7), the
    positional form, an unknown or a lower-case letter (RH-OSD-2)."""
    letters = p.osd_letters or "S"
    served = st.lists(st.sampled_from(letters), min_size=1, max_size=4).map(lambda ls: "OSD," + ",".join(ls))
    odd = st.sampled_from(["OSD,S,Q", "OSD,s", "OSD,X", "OSD,G,C,S,P,,,,", "OSD,S,,S", "OSD"])
    return st.one_of(served, served, odd)


def _log():
    labels = st.integers(1, 3)
    ologl = labels.map(lambda n: "OLOGL," + ",".join("abc"[:n]))
    ologd = st.integers(0, 4).map(lambda n: "OLOGD" + "".join(f",{i + 1}" for i in range(n)))
    return st.one_of(ologl, ologd)


#: The settings the exploration writes (``$ORWSET``): the run reads them first and writes back what
#: it found (:mod:`.restore`).
EXPLORE_WRITES = ("Sle", "Sop", "Sed")


def _orwset():
    """Reads of the settings, writes of a state and a value then read back by a later draw (RH-SET-2;
    the run writes back what it found, :mod:`.restore`), and lines a vehicle must refuse."""
    write = st.builds(lambda name, state, value: f"ORWSET,{name},W,{state},{value}",
                      st.sampled_from(EXPLORE_WRITES), st.sampled_from(["0", "1"]), st.integers(1, 9))
    return st.one_of(write, st.sampled_from([
        "ORWSET,Sle,R", "ORWSET,Sop,R", "ORWSET,Sed,R", "ORWSET,SafetyAction,R", "ORWSET,Bogus,R",
        "ORWSET,Sle,W,2,5", "ORWSET,SafetyAction,W,1,dive", "ORWSET", "ORWSET,Sle,R,1"]))


def _opos(spd):
    return st.builds(lambda w, v, c: f"OPOS,{w},{v},{c}",
                     st.sampled_from(["{lat},{lon}", "{near_lat},{lon}", "91,{lon}", "{lat},181"]),
                     spd, st.sampled_from([",", "35,12", "101,12", "35,51"]))


def _odvl(tos):
    return st.builds(lambda x, y, t: f"ODVL,{x},{y},{t}", st.sampled_from(["0.5", "5", "-5", "5.1"]),
                     st.sampled_from(["0", "-5.1"]), st.one_of(tos, st.sampled_from(["0", "121"])))


def _start_stop():
    return st.one_of(
        st.sampled_from(["OMSTOP,0", "OMSTOP,0", "OMSTOP,1"]),
        st.builds(lambda f, n: f"OMSTART,{f},0,0,0,{n},", st.sampled_from(["0", "0", "1", "2"]), _mission_names()),
        st.builds(lambda n, f: f"OMLOAD,{n},{f}", _mission_names(), st.sampled_from(["0", "0", "1"])),
        st.just("OMSTART,0"),
    )


def _one_off(fmt: str, inside: list, edges: list[list[str]]):
    """Bodies with every field inside its range but one, which is at an edge or one past it: the
    field a vehicle gets wrong is then the one the refusal (or acceptance) is about."""
    def build(i: int):
        parts = [st.sampled_from(edges[j]) if j == i else inside[j] for j in range(len(inside))]
        return st.tuples(*parts).map(lambda vals: fmt.format(*vals))
    return st.integers(0, len(inside) - 1).flatmap(build)


def one_field_off(p: Profile, tos) -> st.SearchStrategy[str]:
    """For each claimed command with ranged fields, a body with one field at an edge of its range
    or one past it and the rest inside (:func:`_one_off`; ``$OMP``'s bytes: a digit short or over,
    a letter past F, lower case); ``$OSD`` with every letter the profile
    serves; ``$OMLOAD`` and ``$OMSTART`` with every name a vehicle must refuse (RH-MSN-1); ``$OPOS``
    a kilometre away (far enough that a report soon after tells whether it was
    applied, RH-POS-2). Speeds stay within bench safety, so only their lower edge is drawn."""
    spd = _num(0, bench_speed(p))
    lo, hi = int(p.timeout_range[0]), int(p.timeout_range[1])
    t_edges = [str(lo - 1), str(hi + 1)]
    md = p.max_depth
    b = p.waypoint_base
    last = p.mission_waypoints - 1 + b
    mot = st.integers(0x80, max(0x80, bench_motor(p))).map(lambda m: f"{m:02X}")
    per = {
        "OMS": _one_off("OMS,{},{},{},{},{}", [_num(0, 359), _num(0, min(4.0, md)), _num(0, 45, 0), spd, tos],
                        [["0", "359.9", "-1", "360", "360.5"], ["0", f"{md:g}", "-1", f"{md + 1:g}", f"{md + 0.5:g}"],
                         ["0", "45", "-1", "46"], ["0"], t_edges]),
        # the bytes: nine and eleven hex digits, a letter past F, fins in lower case (accepted)
        "OMP": _one_off("OMP,{},{},{}", [mot.map(lambda m: f"80808080{m}"), st.just("00"), tos],
                        [["808080808", "80808080800", "8080G08080", "7f7f808080"], ["01", "10"], t_edges]),
        "OJW": st.sampled_from([b - 1, b, last, last + 1, last + 1, b + 1 if last > b else b]).map(
            lambda n: f"OJW,{n}"),
        "OPK": _one_off("OPK,{},{},{},{}", [st.just("{lat}"), st.just("{lon}"), st.just("{opk_min}"), spd],
                        [["{stn_lat}", "{far_lat}", "91", "-91"], ["181", "-181"], ["0", "1440", "1441"], ["0"]]),
        "OMW": _one_off("OMW,{},{},{},,15,{},{},", [st.just("{near_lat}"), st.just("{lon}"), st.just("2"), spd,
                                                   st.sampled_from(["0", "{qpark}"])],
                        [["91", "-91"], ["181"], ["-100", "100", "-101", "101"], ["0"], ["86400", "86401"]]),
        "ODVL": _one_off("ODVL,{},{},{}", [st.just("0.5"), st.just("0"), tos],
                         [["5", "-5", "5.1", "-5.1"], ["5", "-5", "5.1", "-5.1"], ["0", str(hi), str(hi + 1)]]),
        "OPOS": _one_off("OPOS,{},{},{},{},{}", [st.just("{km_lat}"), st.just("{lon}"), spd, st.just("35"),
                                                 st.just("12")],
                         [["91", "{lat}"], ["181"], ["0"], ["0", "100", "-1", "101"], ["-5", "50", "-6", "51"]]),
        "OSD": st.permutations(list(p.osd_letters or "S")).map(lambda ls: "OSD," + ",".join(ls)),
        "OMLOAD": st.builds(lambda n, f: f"OMLOAD,{n},{f}", _mission_names(), st.sampled_from(["0", "1"])),
        "OMSTART": _mission_names().map(lambda n: f"OMSTART,0,0,0,0,{n},"),
    }
    claimed = [v for k, v in per.items() if k in p.commands]
    return st.one_of(*claimed) if claimed else st.just("OSD,S")


#: The families :func:`commands` draws from, each a rule of the exploration: the commands that
#: move the vehicle, those that steer its mission, and those that read or write data.
FAMILIES = {"motion": ("OMS", "OMP", "ODVL"), "navigation": ("OJW", "OPK", "OMW"),
            "mission": ("OMSTOP", "OMLOAD", "OMSTART"), "data": ("OSD", "OPOS", "OLOGL", "ORWSET")}


def commands(p: Profile, tos, family: str = "") -> st.SearchStrategy[str]:
    """Bodies of every command the profile claims (of one :data:`FAMILIES` family, when given), at
    its edges (module docstring)."""
    spd = st.one_of(_num(0, bench_speed(p)), st.just("0"))
    per = {"OMS": lambda: _oms(p, spd, tos), "OMP": lambda: _omp(p, bench_motor(p), tos),
           "OJW": lambda: _ojw(p), "OPK": lambda: _opk(spd), "OMW": lambda: _omw(p, spd),
           "OSD": lambda: osd_requests(p), "OLOGL": _log, "ORWSET": _orwset, "OPOS": lambda: _opos(spd),
           "ODVL": lambda: _odvl(tos), "OMSTOP": _start_stop}
    names = FAMILIES.get(family) or tuple(per)
    claimed = [per[c]() for c in names if c in per and c in p.commands]
    return st.one_of(*claimed) if claimed else st.just("OSD,S")


def valid_commands(nwp: int, speed: float, motor: int, oxflt: bool, tos=timeouts(10)):
    """Bodies of well-formed commands a vehicle accepts somewhere, bench-safe (the older, plain
    vocabulary: kept for drivers that want only well-formed lines)."""
    spd = _num(0, speed)
    hexb = st.integers(0x60, 0xA0).map(lambda b: f"{b:02X}")
    mot = st.integers(0x80, max(0x80, motor)).map(lambda b: f"{b:02X}")
    return st.one_of(
        st.builds(lambda h, d, pt, v, t: f"OMS,{h},{d},{pt},{v},{t}", _num(0, 359), _num(0, 4), _num(0, 45, 0),
                  spd, tos),
        st.builds(lambda a, b, m, t: f"OMP,{a}{a}{b}{b}{m},00,{t}", hexb, hexb, mot, tos),
        st.builds(lambda n: f"OJW,{n}", st.integers(0, nwp)),
        st.builds(lambda v: f"OPK,{{lat}},{{lon}},{{opk_min}},{v}", spd),
        st.builds(lambda v, pk: f"OMW,{{near_lat}},{{lon}},2,,15,{v},{pk},", spd, st.sampled_from(["0", "{qpark}"])),
        st.sampled_from(["OMW,Clr", "OMW,CLEAR", "OMW,stop", "OMSTOP,0", "OMSTART,0,0,0,0,{mission},",
                         "OMLOAD,{mission},0", "OMSTART,0", "OLOGD,1,2", "ORWSET,Sle,R", "OLOGL,x,y",
                         "OPOS,{lat},{lon},0.5,,", "ODVL,0.5,0,3", "OSD,G,C,S,P,,,,", "OSD,S,S", "OSD,S,Q"]),
    )


def control_commands(speed: float, motor: int, tos=timeouts(10)):
    """The remote-control commands (RH-INT-1), drawn more often than the rest."""
    spd = _num(0, speed)
    mot = st.integers(0x80, max(0x80, motor)).map(lambda b: f"{b:02X}")
    return st.one_of(
        st.builds(lambda v, t: f"OMS,90,2,20,{v},{t}", spd, tos),
        st.builds(lambda m, t: f"OMP,80808080{m},00,{t}", mot, tos),
        st.builds(lambda v: f"OPK,{{lat}},{{lon}},{{opk_min}},{v}", spd),
        st.builds(lambda v, pk: f"OMW,{{near_lat}},{{lon}},2,,15,{v},{pk},", spd,
                  st.sampled_from(["0", "0", "{qpark}"])),
    )


#: Bodies a mutation is applied to: a request, a state change, a remote control.
_MUTATED = ("OMSTOP,0", "OMS,90,2,20,0,{to}", "OJW,{wp_other}", "OSD,S", "OSD,G,S", "OPOS,{lat},{lon},0,,")


def invalid_lines(group: str = ""):
    """(kind, body) pairs. ``framing``: one mutation of a valid line (every :data:`.steps.RAW_KINDS`
    kind but ``unknown``, each as likely); ``refused``: a line the grammar frames whose field count or
    values the command refuses (kind ``frame``) or whose ID is unknown (kind ``unknown``). Without a
    group, either."""
    framing = st.tuples(st.sampled_from(sorted(k for k in RAW_KINDS if k != "unknown")), st.sampled_from(_MUTATED))
    refused = st.one_of(
        st.tuples(st.just("frame"), st.sampled_from(["OMS,400,2,20,0,5", "OMS,90,2,20,0,0", "OMP,80808080,00,5",
                                                      "OJW,-1", "OPK,{lat},{lon},0,0", "ODVL,9,0,3",
                                                      "OMSTOP,2", "OMW,,1,2,3", "OSD,x", "OMS,90,2,20"])),
        st.tuples(st.just("unknown"), st.sampled_from(["OXYZ,1", "OHELLO", "OMSTOPX,0", "XOSD,S"])),
    )
    if group:
        return {"framing": framing, "refused": refused}[group]
    return st.one_of(framing, refused)
