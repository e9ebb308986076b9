"""Aim: what the exploration goes for next on this vehicle, and the way there.

Before each *aimed* batch (:mod:`.explore`) :func:`targets` lists what the run has not reached yet
— by the clause cases or the exploration (:mod:`.modelcover`: table rows, interrupt pairs, modes,
timers run out, error codes; :mod:`.edges`: the range edges of §4–8b; the mutations of a line the
exploration has not sent; a few probes of no dimension: a setting written and read back, bad
fields in the lockout) — each as a :class:`Target`: a *way* into the state it needs and the line
or wait that *fires* it there. A way is read off the transition table: a row's source modes,
phases and guard pick the cheapest way whose state satisfies them, and for a row a timer fires one
whose state runs that timer (:data:`WAYS`: ``N`` a mission started, ``P`` its park reached, ``A@P``
a servo control over the mission park, ``ascent`` a dive, a violation and the lockout waited out,
…). Targets that need the same way and the same firing are one, worth all it reaches; targets of
one way whose firings leave the state as it is (refusals, requests) are driven as one
(:func:`_merged`). A few *tours* go the vehicle's own way through what it does with time
(:data:`_TOURS`): its mission to its park, the park interrupted a while in, released and let run
out, then the mission to its end; an ``$OPK`` park interrupted, then one reached after a
transit and let run out. Each target has a cost in vehicle seconds read from the vehicle's own
mission as its reports describe it (:class:`MissionSurvey`: how long its legs take at the speed it
reports; which waypoint parks and for how long, as the observer learnt it) and from the line
(each line's wall time at this time scale, in vehicle seconds). The list: the quick targets
first, by worth per second (:data:`_WORTH`), for a share of what is left of the batch's budget,
then those that wait take turns with the quick ones left; what does not fit in the budget is left
out. A target that waits longer than a batch's share but fits in what is left of the whole budget
(a long mission park toured to its end: a third vehicle's is 165 s) is listed alone, once a run,
for one batch after the budget (:func:`.explore._long_tour`). :mod:`.tour` drives it.

Decisions (the profile is silent): a dive for an ascent goes to 3 m at most (deep enough that the
lockout ends under water at any ascent rate below 0.15 m/s over 20 s); a park is reached by
``$OJW`` to the waypoint the vehicle was seen to park at, else by following the mission (for at
most what is left of the budget, :data:`~.tour.PARK_MAX_V` at most); queued waypoints are 8 m
apart and an ``$OPK`` park 15 m away (a leg a report sees, short at the bench speed); a row no way
of :data:`WAYS` reaches (``A`` with no mission running, a queue without one) stays uncovered, and
the coverage says so.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from types import SimpleNamespace
from typing import Optional

from ...grammar import checksum_hex
from ...model.geo import KNOT_MPS
from ...model.transitions import GUARD_ATOMS, TABLE, select
from ...profile import Profile
from .edges import Edge
from .safety import BenchGuard
from .session import frame
from .modelcover import ModelCoverage
from .steps import RAW_KINDS

__all__ = ["Target", "Way", "WAYS", "MissionSurvey", "targets", "BODIES", "edge_body"]


@dataclass(frozen=True)
class Way:
    """A way into a state: its steps (bodies to send, or ``@``-actions :mod:`.machine` runs) and
    what the state then is (mode, phase, guard atoms)."""

    steps: tuple[str, ...]
    mode: str
    phase: str = "none"
    atoms: tuple[str, ...] = ()  #: guard atoms that hold there (the others do not)
    needs: tuple[str, ...] = ()  #: commands the profile must claim
    cost_v: str = ""  #: a :class:`MissionSurvey` estimate it costs beyond its lines

    @property
    def arms(self) -> frozenset:
        """The model timers running in its state (a timer's rows are fired from a way that arms it)."""
        out = set()
        for st in self.steps:
            if st.startswith(("OMS,", "OMP,")):
                out.add("remote")
            elif st.startswith("OPK,"):
                out.add("opk")
            elif st.startswith("OMW,") and st.rstrip(",").rsplit(",", 1)[-1] not in ("0", ""):
                out.add("qpark")
            elif st == "@park":
                out.add("park")
            elif st.startswith("OXFLT"):
                out.add("lockout")
        if self.phase == "ascent":
            out.discard("lockout")
        if self.mode not in ("A", "M"):
            out.discard("remote")
        if self.mode != "mP":
            out.discard("opk")
        if self.mode != "W":
            out.discard("qpark")
        return frozenset(out)


#: The ways into the states the table's rows start from (module docstring). ``@stop``: ``$OMSTOP,0``
#: unless in ``S``; ``@mission``: the test mission started unless it runs in ``N``; ``@park``: its
#: park reached; ``@dive``: a dive until under water; ``@lockout_end``: the lockout waited out.
WAYS: dict[str, Way] = {
    "S": Way(("@stop",), "S", needs=("OMSTOP",)),
    "N": Way(("@mission",), "N", atoms=("running", "more_wps", "logging"), needs=("OMSTART",)),
    "N-last": Way(("@mission", "OJW,{wp_last}"), "N", atoms=("running", "logging"), needs=("OMSTART", "OJW")),
    "N-park": Way(("@mission", "@to_park"), "N", atoms=("running", "more_wps", "wp_parks", "logging"),
                  needs=("OMSTART", "OJW")),
    "P": Way(("@mission", "@park"), "P", atoms=("running", "mission_parking", "more_wps", "logging"),
             needs=("OMSTART",), cost_v="to_park"),
    # 15 m away: on station after a transit, so the countdown's start is seen (RH-PK-2)
    "mP": Way(("@mission", "OPK,{stn_lat},{lon},{opk_min},{speed}"), "mP", atoms=("running", "more_wps", "logging"),
              needs=("OMSTART", "OPK")),
    "mP@P": Way(("@mission", "@park", "OPK,{lat},{lon},{opk_min},{speed}"), "mP",
                atoms=("running", "mission_parking", "more_wps", "logging"), needs=("OMSTART", "OPK"),
                cost_v="to_park"),
    "A": Way(("@mission", "OMS,90,0,20,{speed},{to}"), "A", atoms=("running", "more_wps", "logging"),
             needs=("OMSTART", "OMS")),
    "A@P": Way(("@mission", "@park", "OMS,90,0,20,{speed},{to}"), "A",
               atoms=("running", "mission_parking", "more_wps", "logging"), needs=("OMSTART", "OMS"), cost_v="to_park"),
    "M@S": Way(("@stop", "OMP,8080808080,00,{to}"), "M", atoms=("logging",), needs=("OMSTOP", "OMP")),
    "M": Way(("@mission", "OMP,8080808080,00,{to}"), "M", atoms=("running", "more_wps", "logging"),
             needs=("OMSTART", "OMP")),
    "M@P": Way(("@mission", "@park", "OMP,8080808080,00,{to}"), "M",
               atoms=("running", "mission_parking", "more_wps", "logging"), needs=("OMSTART", "OMP"), cost_v="to_park"),
    "W": Way(("@mission", "OMW,{wp8_lat},{lon},0,,15,{speed},0,"), "W", atoms=("running", "more_wps", "logging"),
             needs=("OMSTART", "OMW")),
    "W2": Way(("@mission", "OMW,{wp8_lat},{lon},0,,15,{speed},0,", "OMW,{wp16_lat},{lon},0,,15,{speed},0,"), "W",
              atoms=("running", "more_wps", "queue_more", "logging"), needs=("OMSTART", "OMW")),
    "Wq": Way(("@mission", "OMW,{wp8_lat},{lon},0,,15,{speed},{qpark},"), "W",
              atoms=("running", "more_wps", "head_parks", "logging"), needs=("OMSTART", "OMW")),
    "Wq2": Way(("@mission", "OMW,{wp8_lat},{lon},0,,15,{speed},{qpark},", "OMW,{wp16_lat},{lon},0,,15,{speed},0,"),
               "W", atoms=("running", "more_wps", "head_parks", "queue_more", "logging"), needs=("OMSTART", "OMW")),
    "W@P": Way(("@mission", "@park", "OMW,{wp8_lat},{lon},0,,15,{speed},0,"), "W",
               atoms=("running", "mission_parking", "more_wps", "logging"), needs=("OMSTART", "OMW"), cost_v="to_park"),
    "Wq@P": Way(("@mission", "@park", "OMW,{wp8_lat},{lon},0,,15,{speed},{qpark},"), "W",
                atoms=("running", "mission_parking", "more_wps", "head_parks", "logging"), needs=("OMSTART", "OMW"),
                cost_v="to_park"),
    "lockout@S": Way(("@stop", "OXFLT,Sle"), "S", "lockout", atoms=("logging",), needs=("OMSTOP", "@oxflt")),
    "lockout": Way(("@mission", "OXFLT,Sle"), "N", "lockout", atoms=("running", "more_wps", "logging"),
                   needs=("OMSTART", "@oxflt")),
    "lockout@P": Way(("@mission", "@park", "OXFLT,Sle"), "P", "lockout",
                     atoms=("running", "mission_parking", "more_wps", "logging"), needs=("OMSTART", "@oxflt"),
                     cost_v="to_park"),
    "ascent": Way(("@mission", "@dive", "OXFLT,Sle", "@lockout_end"), "N", "ascent",
                  atoms=("running", "more_wps", "logging"), needs=("OMSTART", "OMS", "@oxflt"), cost_v="lockout"),
    # for the GPS fix's edges (RH-POS-2): a mission started ignoring GPS, a dive
    "N-gps": Way(("@stop", "OMSTART,1,0,0,0,{mission},"), "N", atoms=("running", "more_wps", "logging"),
                 needs=("OMSTOP", "OMSTART")),
    "N-under": Way(("@mission", "@dive"), "A", atoms=("running", "more_wps", "logging"), needs=("OMSTART", "OMS")),
}
#: Cheapest first: the way :func:`targets` takes when several reach a state.
_WAY_ORDER = tuple(WAYS)

#: A command body each event is sent as (accepted wherever its row accepts it).
BODIES = {"OMS": "OMS,90,0,20,{speed},{to}", "OMP": "OMP,8080808080,00,{to}", "OJW": "OJW,{wp_other}",
          "OPK": "OPK,{lat},{lon},{opk_min},{speed}", "OMW": "OMW,{wp8_lat},{lon},0,,15,{speed},0,",
          "OMW_CLEAR": "OMW,{kw_a}", "OMW_CLEAR_WP": "OMW,{kw_a},{wp8_lat},{lon},0,,15,{speed},0,",
          "OMSTOP": "OMSTOP,0", "OMLOAD": "OMLOAD,{mission},0", "OMSTART": "OMSTART,0,0,0,0,{mission},",
          "OPOS": "OPOS,{lat},{lon},0,,", "OSD": "OSD,S", "OLOGL": "OLOGL,a,b", "OLOGD": "OLOGD,1,2",
          "ORWSET": "ORWSET,Sle,R", "ODVL": "ODVL,0.5,0,{to}"}
#: The internal events and how a target fires them: a timer settled, the vehicle followed.
_FIRE = {"servo_timeout": "@settle:remote", "primitive_timeout": "@settle:remote", "opk_expired": "@settle:opk",
         "queue_park_expired": "@settle:qpark", "park_expired": "@settle:park", "lockout_end": "@lockout_end",
         "queue_wp_reached": "@follow", "wp_reached": "@follow", "surfaced": "@surface", "violation": "OXFLT,Sle"}
#: Bodies that raise the errors no row names (look-ups, distance): (command, error) -> (way, body).
_EXTRA = {("OMLOAD", 1): ("S", "OMLOAD,helmcheck-missing.mis,0"),
          ("OMSTART", 1): ("S", "OMSTART,0,0,0,0,helmcheck-missing.mis,"),
          ("OMSTART", 31): ("S", "OMSTART,0,0,0,0,{mission},helmcheck-missing-srp.mis"),
          ("OPK", 40): ("N", "OPK,{far_lat},{lon},{opk_min},{speed}")}
#: The line each mutation of :data:`.steps.RAW_KINDS` is made from: a request whose answer shows
#: whether the vehicle read it.
_RAW_BODY = "OSD,S"


@dataclass(frozen=True)
class Target:
    """What one aimed step goes for: ``way`` (a :data:`WAYS` key, or ``""``: wherever the vehicle
    is) then ``fire`` (bodies, ``raw:<kind>:<body>`` for a mutated line, or ``@``-actions);
    ``reaches`` the uncovered things it is expected to reach; ``cost_v`` its estimate."""

    way: str
    fire: tuple[str, ...]
    reaches: tuple[str, ...] = ()
    cost_v: float = 0.0
    writes: tuple[str, ...] = ()  #: settings it writes (put back after)
    #: its firing leaves the vehicle in the way's state (a refusal, a command that keeps the mode):
    #: targets of one way that all keep it are driven as one (:func:`_merged`)
    keeps: bool = False

    @property
    def key(self) -> tuple:
        return self.way, self.fire


@dataclass
class MissionSurvey:
    """The vehicle's own mission as its reports describe it (module docstring): per waypoint the
    longest distance to it reported in ``N``, and the highest speed reported there."""

    waypoints: int
    legs_m: dict = field(default_factory=dict)  #: waypoint -> the longest distance to it seen (m)
    speed_mps: float = 0.0  #: the highest mission speed seen

    def seen(self, osi) -> None:
        """One report (``$OSI``)."""
        if osi is None or osi.mode != "N":
            return
        try:
            wp, dist = int(osi.next_waypoint), float(osi.distance or 0)
            self.legs_m[wp] = max(self.legs_m.get(wp, 0.0), dist)
            self.speed_mps = max(self.speed_mps, float(osi.speed or 0) * KNOT_MPS)
        except (TypeError, ValueError):
            return

    def leg_v(self, wp: int) -> float:
        """Vehicle seconds a leg to ``wp`` takes (60 s when not seen: a guess)."""
        mps = max(self.speed_mps, 0.5 * KNOT_MPS)
        return self.legs_m[wp] / mps if wp in self.legs_m else 60.0

    def to_v(self, wp: Optional[int]) -> float:
        """From the mission's start to waypoint ``wp`` (the whole mission when None)."""
        last = self.waypoints - 1 if wp is None else wp
        return sum(self.leg_v(i) for i in range(last + 1))


def _ns(way: Way) -> SimpleNamespace:
    ns = SimpleNamespace(**{a: a in way.atoms for a in GUARD_ATOMS})
    return ns


def _way_for(row, claimed: set, oxflt: bool) -> Optional[str]:
    """The cheapest way into a state the row starts from (mode, phase and guard; for a row a timer
    fires, one whose state runs that timer)."""
    fire = _FIRE.get(row.event, "")
    timer = fire.split(":", 1)[1] if fire.startswith("@settle:") else ("lockout" if fire == "@lockout_end" else "")
    for name in _WAY_ORDER:
        w = WAYS[name]
        if timer and timer not in w.arms:
            continue
        if any((n == "@oxflt" and not oxflt) or (n != "@oxflt" and n not in claimed) for n in w.needs):
            continue
        if w.mode in row.sources and w.phase in row.phases and select(w.mode, w.phase, row.event, _ns(w)) is row:
            return name
    return None


def _way_cost(name: str, survey: MissionSurvey, park_wp: Optional[int], park_s: float, lockout_s: float) -> float:
    extra = WAYS[name].cost_v if name else ""
    if name and "OXFLT,Sle" in WAYS[name].steps and extra != "lockout":
        return lockout_s + (_way_cost("P", survey, park_wp, park_s, lockout_s) if "@park" in WAYS[name].steps else 0.0)
    if extra == "to_park":  # the legs up to the park (the whole mission while it is not known)
        return min(600.0, survey.to_v(park_wp if park_wp is not None else None))
    if extra == "lockout":
        return lockout_s + 15.0
    return 10.0 if name == "N-under" else 0.0


def _fire_cost(fire: tuple, survey: MissionSurvey, times: dict) -> float:
    cost = 0.0
    for f in fire:
        if f.startswith("@settle:"):
            cost += times.get(f.split(":", 1)[1], 10.0)
        elif f == "@lockout_end":
            cost += times["lockout"]
        elif f == "@follow":
            cost += times["leg"]
        elif f == "@surface":
            cost += 20.0
        elif f == "@park":
            cost += times["to_park"]
        elif f == "@dvl":
            cost += times["dvl"]
        elif f == "@into_park":
            cost += times["into_park"]
        elif f.startswith("OXFLT"):
            cost += times["lockout"]  # the next reset waits it out
    return cost


def edge_body(e: Edge, profile: Profile) -> Optional[tuple[str, str]]:
    """``(way, line)`` that puts a line at edge ``e`` where it counts (:class:`~.edges.EdgeTally`):
    every other field inside, in a state where the command with the field inside is accepted.
    The line is a template (:func:`~.interpreter.fill`), ``raw:lowerck:<body>`` for the checksum's
    case; None for an edge this does not build (it stays for the random sequences)."""
    cmd, fld, probe, kind = e.command, e.field, e.probe, e.kind
    names = {"empty": "", "absolute path": "/{mission}", "drive letter": "C:{mission}",
             "'..' component": "sub/../{mission}", "a name inside": "{mission}"}
    if kind == "checksum":
        return "", "raw:lowerck:OSD,S"
    if kind == "letter":
        return "", ("OSD,s" if e.side == "out" else f"OSD,{probe}")
    if kind == "state":
        if cmd == "OJW":
            return "N", "OJW,{wp_last}" if e.side == "in" else "OJW,{wp_bad}"
        if cmd == "OLOGD":
            return "N", "OLOGD,1,2" if e.side == "in" else "OLOGD,1,2,3"
        if cmd == "OPK":
            return "N", "OPK,{opk_in_lat},{lon},{opk_min},{speed}" if e.side == "in" else \
                "OPK,{opk_out_lat},{lon},{opk_min},{speed}"
        if cmd == "OPOS":
            # a report right after: whether the position was applied shows at once (RH-POS-2)
            return {"no mission, at the surface": ("S", "OPOS,{opos_lat},{lon},0,,|OSD,S"),
                    "a mission, at the surface": ("N", "OPOS,{opos_lat},{lon},0,,|OSD,S"),
                    "ignore-GPS start, at the surface": ("N-gps", "OPOS,{opos_lat},{lon},0,,|OSD,S"),
                    "under water": ("N-under", "OPOS,{opos_lat},{lon},0,,|OSD,S")}.get(probe)
        return None
    if kind == "width":
        return "", {"10": "OMP,8080808080,00,{to}", "9": "OMP,808080808,00,{to}",
                    "11": "OMP,80808080800,00,{to}"}.get(probe)
    if kind == "case":
        return "", "OMP,7f7f808080,00,{to}"
    if kind == "count":
        n = int(probe)
        if cmd == "OLOGL":
            return "", "OLOGL" + "".join(f",l{i}" for i in range(n))
        if cmd == "OLOGD" and n <= 2 or n > 12:  # the sequences start logging two labels
            return "N", "OLOGD" + "".join(f",{i}" for i in range(n))
        return None
    if kind == "name":
        name = names.get(probe)
        if name is None:
            return None
        if cmd == "OMLOAD":
            return "S", f"OMLOAD,{name},0"
        if fld == "srp":
            return "S", f"OMSTART,0,0,0,0,{{mission}},{name}"
        return "S", f"OMSTART,0,0,0,0,{name},"
    fields = {"OMS": ("N", "OMS", ["90", "0", "20", "{speed}", "{to}"],
                      ["heading", "depth", "max_pitch", "speed", "timeout"]),
              "OMP": ("", "OMP", ["8080808080", "00", "{to}"], ["actuators", "reserved", "timeout"]),
              "OJW": ("N", "OJW", ["{wp_other}"], ["waypoint"]),
              "OMSTOP": ("", "OMSTOP", ["0"], ["flag"]),
              "OMLOAD": ("S", "OMLOAD", ["{mission}", "0"], ["name", "flag"]),
              "OPOS": ("", "OPOS", ["{lat}", "{lon}", "0", "35", "12"],
                       ["lat", "lon", "speed", "conductivity", "temperature"]),
              "ODVL": ("", "ODVL", ["0.5", "0", "{to}"], ["x", "y", "timeout"]),
              "OPK": ("N", "OPK", ["{stn_lat}", "{lon}", "{opk_min}", "{speed}"], ["lat", "lon", "minutes", "speed"]),
              "OMW": ("N", "OMW", ["{stn_lat}", "{lon}", "0", "", "15", "{speed}", "0", ""],
                      ["lat", "lon", "depth1", "depth2", "max_pitch", "speed", "park_s", "sensors"])}
    if cmd == "OMSTART":
        if fld == "flag":
            return "S", f"OMSTART,{probe}"
        order = ["ignore_gps", "ignore_sounder", "calibrate_pressure", "mission_type"]
        if fld not in order:
            return None
        vals = ["0", "0", "0", "0"]
        vals[order.index(fld)] = probe
        return "S", "OMSTART," + ",".join(vals) + ",{mission},"
    if cmd == "OMW" and fld == "keyword":
        return "N", f"OMW,{probe}"
    if cmd == "ORWSET":
        if fld == "state":
            return "S", f"ORWSET,Sle,W,{probe},1"
        return None  # SafetyAction's values: written only where the run can put them back (cases)
    got = fields.get(cmd)
    if got is None or fld not in got[3]:
        return None
    way, ident, vals, order = got
    vals = list(vals)
    vals[order.index(fld)] = probe
    return way, ident + "," + ",".join(vals)


def _raw_lowercase_ok(body: str) -> bool:
    return any(c in "ABCDEF" for c in checksum_hex(body))


def targets(cover: ModelCoverage, edges, profile: Profile, survey: MissionSurvey, *, park_wp: Optional[int],
            park_s: float, durations: dict, k: float, line_wall_s: float, left_v: float,
            lines_sent: set, limit: int = 96, whole_v: Optional[float] = None) -> list[Target]:
    """What the next aimed batch goes for (module docstring), best first: at most ``limit``
    targets that fit in ``left_v`` vehicle seconds — or, when ``whole_v`` (what is left of the
    whole budget) is given and a target that waits needs more than ``left_v`` but fits in
    ``whole_v``, the richest such target alone (a *long* batch: the vehicle's own mission toured
    to its park's end; the caller gives it the time it needs). ``edges``: the run's
    :class:`~.edges.EdgeTally`; ``durations``: the durations' template values (``to``,
    ``opk_s``, ``qpark``); ``lines_sent``: the mutation kinds already sent."""
    claimed = set(profile.commands)
    oxflt = profile.fault_injection == "oxflt"
    guard = BenchGuard(profile)
    un = cover.uncovered()
    to = float(durations.get("to", 10))
    times = {"remote": to + 2, "opk": float(durations.get("opk_s", 60)) + 30.0,
             "qpark": float(durations.get("qpark", 30)) + 30.0, "park": park_s + 5.0,
             "lockout": profile.lockout_s + 2.0, "dvl": to + 2, "leg": min(120.0, max(survey.leg_v(i) for i in
                                                                                       range(survey.waypoints)))}
    times["to_park"] = _way_cost("P", survey, park_wp, park_s, profile.lockout_s)
    times["into_park"] = INTO_PARK_V
    found: dict[tuple, Target] = {}

    def add(way: str, fire: tuple, what: str, writes: tuple = (), keeps: bool = False) -> None:
        if not oxflt and any("OXFLT" in f for f in (*(WAYS[way].steps if way else ()), *fire)):
            return  # no $OXFLT extension declared (RH-SAF-5): a violation is the vehicle's own to raise
        key = (way, fire)
        t = found.get(key)
        if t is None:
            cost = _way_cost(way, survey, park_wp, park_s, profile.lockout_s) + _fire_cost(fire, survey, times)
            found[key] = Target(way, fire, (what,), cost, writes, keeps)
        elif what not in t.reaches:
            found[key] = Target(way, fire, t.reaches + (what,), t.cost_v, t.writes, t.keeps and keeps)

    rows = {r.id: r for r in TABLE}
    for rid in sorted(un["rows"]):
        row = rows[rid]
        way = _way_for(row, claimed, oxflt)
        if way is None:
            continue
        if row.event not in _FIRE:
            add(way, (BODIES[row.event],), f"row {rid}", keeps=row.error is not None or row.target == "=")
            continue
        fire: tuple = (_FIRE[row.event],)
        if row.event == "park_expired":
            if park_wp is None:
                continue  # the park is learnt first (any way to P shows it)
            if "OMS" in claimed and "OMSTART" in claimed:  # interrupted, released, then to its end (RH-INT-2)
                way, fire = "P", ("@into_park", "OMS,90,0,20,{speed},{to}", "@settle:remote", "@settle:park")
        elif row.event == "wp_reached":
            if "wp_parks" in row.guard_text:
                way, fire = "N", ("@park",)  # the mission followed to its park (and the park learnt)
            elif "more_wps" not in row.guard_text and "OJW" in claimed:
                way = "N-last"  # the mission's last waypoint, then its end (RH-MSN-4)
        add(way, fire, f"row {rid}")
    for mode, event in sorted(un["interrupt_pairs"]):
        way = {"P": "P", "mP": "mP", "A": "A", "M": "M", "W": "W"}[mode]
        if all(n in claimed or n == "@oxflt" and oxflt for n in WAYS[way].needs):
            add(way, (BODIES[event],), f"{event} in {mode}")
    for name in sorted(un["timers"]):
        way, fire = {"remote": ("A", "@settle:remote"), "opk": ("mP", "@settle:opk"), "park": ("P", "@settle:park"),
                     "qpark": ("Wq", "@settle:qpark"), "lockout": ("lockout", "@lockout_end"),
                     "dvl": ("", "@dvl")}[name]
        if name == "park" and "OMS" in claimed:  # as the park_expired row (above)
            way, fire = "P", ("@into_park", "OMS,90,0,20,{speed},{to}", "@settle:remote", "@settle:park")
        if name == "park" and park_wp is None:
            continue
        if name == "remote" and "OMS" not in claimed:
            way = "M"
        if way and not all(n in claimed or n == "@oxflt" and oxflt for n in WAYS[way].needs):
            continue
        add(way, fire if isinstance(fire, tuple) else (fire,), f"timer {name}")
    for mode in sorted(un["modes"]):
        way = {"S": "S", "N": "N", "P": "P", "mP": "mP", "A": "A", "M": "M@S", "W": "W", "lockout": "lockout@S",
               "ascent": "ascent"}.get(mode)
        if way and all(n in claimed or n == "@oxflt" and oxflt for n in WAYS[way].needs):
            add(way, ("@surface",) if mode == "ascent" else ("OSD,S",), f"mode {mode}")
    for ev, code in sorted(un["error_codes"]):
        if code == 26 and ev in BODIES:
            add("lockout", (BODIES[ev],), f"{ev} err 26", keeps=True)
        elif (ev, code) in _EXTRA:
            way, body = _EXTRA[(ev, code)]
            add(way, (body,), f"{ev} err {code}", keeps=True)
    for e in edges.edges:
        if e.id in edges.reached or e.id in edges.held:
            continue
        got = edge_body(e, profile)
        if got is None or got[1] is None or (got[0] and not all(n in claimed or n == "@oxflt" and oxflt
                                                                for n in WAYS[got[0]].needs)):
            continue
        way, body = got
        fire = tuple(body.split("|"))
        if any(guard.problem(frame(re.sub(r"{\w+}", "0", f))) for f in fire if f[:1] == "O"):
            continue  # above the bench-safety limits: never sent (the random sequences' try says so)
        writes = ("Sle",) if body.startswith("ORWSET,Sle,W") else ()
        add(way, fire, f"edge {e.id}", writes, keeps=e.side == "out" or e.command in _KEEP_MODE)
    for kind in RAW_KINDS:
        if kind not in lines_sent and kind != "unknown":
            add("", (f"raw:{kind}:{_RAW_BODY}",), f"line {kind}", keeps=True)
    for name, (way, fire, reaches) in _TOURS.items():
        probe = f"probe {name}"
        left = tuple(r for r in reaches if _open(r, un)) + (() if probe in lines_sent else (probe,))
        sends = {b.split(",", 1)[0] for f in fire for b in f.replace("burst:", "").split("\x1f") if b[:1] == "O"}
        if (len(left) > 1 or left == (probe,)) and sends <= claimed | {"OXFLT"} \
                and all(n in claimed or n == "@oxflt" and oxflt for n in WAYS[way].needs):
            for r in left:
                add(way, fire, r)
    per_line = max(line_wall_s * k, 0.05)
    in_lockout = max(1, int((profile.lockout_s - 4.0) / per_line))
    found = {t.key: t for t in _merged(list(found.values()), in_lockout)}
    long = [t for t in found.values() if left_v < t.cost_v <= (whole_v or 0.0) and t.cost_v >= DEEP_V]
    if long:  # a target no batch's share fits goes first, in a batch of its own (:func:`.explore.explore`)
        return [max(long, key=lambda t: (_worth(t), -t.cost_v, t.way, t.fire))]
    out = [t for t in found.values() if t.cost_v <= left_v]
    out.sort(key=lambda t: (-_worth(t) / _cost(t, per_line), t.way, t.fire))
    # the quick targets first, for QUICK_SHARE of what is left of the budget; then those that wait
    # (a timer, a park, the mission's legs: the richest first) take turns with the quick ones left,
    # one for every DEEP_EVERY — ordered by worth per second alone, the quick ones would take the
    # whole budget and no park, queue or mission end would ever be reached
    deep = sorted((t for t in out if t.cost_v >= DEEP_V), key=lambda t: -_worth(t))
    quick = [t for t in out if t.cost_v < DEEP_V]
    mixed, spent = [], 0.0
    while quick and spent + _cost(quick[0], per_line) <= QUICK_SHARE * left_v:
        spent += _cost(quick[0], per_line)
        mixed.append(quick.pop(0))
    while deep or quick:
        if deep:
            mixed.append(deep.pop(0))
        mixed += quick[:DEEP_EVERY]
        del quick[:DEEP_EVERY]
    return mixed[:limit]


def _cost(t: Target, per_line: float) -> float:
    """A target's vehicle seconds with its lines (the way's, the firing's and a report after)."""
    lines = len(WAYS[t.way].steps) if t.way else 0
    return t.cost_v + per_line * (lines + len(t.fire) + 2)


#: How far into a mission park it is interrupted (vehicle seconds; less for a shorter park): far
#: enough that what is left of it is told from the whole park (RH-INT-2, RH-TIM-1's tolerance)
INTO_PARK_V = 30.0
#: A target that costs this many vehicle seconds or more waits for something (:func:`targets`
#: gives such targets a turn for every DEEP_EVERY quick ones).
DEEP_V = 20.0
DEEP_EVERY = 4
#: The share of what is left of the budget the quick targets have first.
QUICK_SHARE = 0.6
#: Tours of the vehicle's own mission and of the remote controls' parks, each one target worth all
#: it reaches on the way (module docstring): the mission to its park, the park interrupted and
#: released, let run out, then the mission to its end (RH-INT-2, RH-RD-5, RH-MSN-4); an ``$OPK``
#: park interrupted and released, then one reached after a transit and let run out (RH-INT-3,
#: RH-PK-2); a setting written and read back (RH-SET-2); the lockout's refusals of lines with bad
#: fields (RH-RD-2: 26 first).
_TOURS = {
    "mission": ("P", ("@into_park", "OMS,90,0,20,{speed},{to}", "@settle:remote", "@settle:park", "OJW,{wp_last}",
                      "@follow"),
                ("row 82", "row 83", "OMS in P", "row 64", "timer remote", "timer park", "row 85", "row 84",
                 "row 86")),
    "opk": ("mP", ("OMS,90,0,20,{speed},{to}", "@settle:remote", "OPK,{stn_lat},{lon},{opk_min},{speed}",
                   "@settle:opk"),
            ("OMS in mP", "row 65", "timer remote", "row 71", "timer opk")),
    "settings": ("S", ("@roundtrip",), ("probe settings",)),
    "lockout-order": ("lockout", ("burst:OMS,360,0,20,0,5\x1fOMP,808080808,00,5\x1fOJW,-1\x1fOPK,91,{lon},1,0"
                                  "\x1fOMW,91,{lon},0,,15,0,0,\x1fOPOS,91,{lon},0,,\x1fODVL,9,0,5\x1fOLOGD,1,2,3,4,5,6,7,"
                                  "8,9,10,11,12,13",),
                      ("OMS err 26", "OMP err 26", "OJW err 26", "OPK err 26")),
}


def _open(what: str, un: dict) -> bool:
    """Whether ``what`` (a target's reach: ``row 85``, ``timer park``, ``OMS in P``, ``OMS err 26``)
    is still uncovered."""
    kind, _, rest = what.partition(" ")
    if kind == "row":
        return int(rest) in un["rows"]
    if kind == "timer":
        return rest in un["timers"]
    if " in " in what:
        ev, _, mode = what.partition(" in ")
        return (mode, ev) in un["interrupt_pairs"]
    if " err " in what:
        ev, _, code = what.partition(" err ")
        return (ev, int(code)) in un["error_codes"]
    return False


#: Commands whose acceptance keeps the vehicle's mode (their range edges can be driven together).
_KEEP_MODE = ("OSD", "OLOGL", "OLOGD", "OPOS", "ODVL", "ORWSET", "OMLOAD")
#: Targets of one way driven as one, at most (:func:`_merged`).
MERGE_MAX = 8


def _merged(found: list[Target], in_lockout: int) -> list[Target]:
    """Targets of one way whose firings all keep the way's state, as one target each
    :data:`MERGE_MAX` of them (in the lockout: as many as the lockout lasts for, ``in_lockout``
    lines, written as one burst so that all arrive inside it); the others as they are."""
    groups: dict[str, list[Target]] = {}
    out = []
    for t in found:
        if t.keeps and all(not f.startswith("@") for f in t.fire):
            groups.setdefault(t.way, []).append(t)
        else:
            out.append(t)
    for way, ts in groups.items():
        locked = WAYS[way].phase == "lockout" if way else False
        size = min(in_lockout, 40) if locked else MERGE_MAX
        for i in range(0, len(ts), size):
            part = ts[i:i + size]
            fire = tuple(f for t in part for f in t.fire)
            if locked:
                fire = ("burst:" + "\x1f".join(fire),)
            out.append(Target(way, fire, tuple(r for t in part for r in t.reaches), max(t.cost_v for t in part),
                              tuple(w for t in part for w in t.writes), True))
    return out


#: What each kind of thing a target reaches is worth (:func:`targets` orders by worth per vehicle
#: second): the model's transitions and timers first, then modes and mutations of a line (each its
#: own framing rule), range edges (each a bound a vehicle may get wrong), then interrupt pairs and
#: error codes (a pair's transition is counted as a row already).
_WORTH = {"row": 3.0, "timer": 3.0, "mode": 2.0, "line": 2.0, "edge": 1.5, "probe": 2.0}


def _worth(t: Target) -> float:
    return sum(_WORTH.get(r.split(" ", 1)[0], 1.0) for r in t.reaches)
