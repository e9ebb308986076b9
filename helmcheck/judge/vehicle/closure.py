"""Unseen plant events: adopted when, and only when, nothing else explains what the vehicle says.

What the vehicle physically does is not on the wire: a mission waypoint reached, on station at
an ``$OPK`` position or a queued ``$OMW`` waypoint, the surface after a lockout, a safety rule
tripping by itself (RH-SAF-5), the end of a mission of unknown length. The observer adopts such
an event for a candidate state only when a report cannot be explained without it, and places it
in an explicit **time window**: it happened after ``tp`` (the last observation that showed it had
not, or the model's last input) and before the report that reveals it — or at ``tp`` exactly,
where the emulator's own log has a plant note of that waypoint reached
(:attr:`~.candidate.Candidate.noted`). The event is applied at the window's start and the
window's width is carried as extra slack on every timer it started (:class:`~.candidate.Candidate`),
so any moment in the window is accepted.

:func:`explain_osi` tries, in order of plausibility (fewest events first), the events that fit
the candidate's mode, and keeps the first that explains the ``$OSI``:

=====================  ===================================================================
``surface``            in the ascent (or a lockout that ends in the window), the ``$OSI``
                       depth is at the surface: the at-surface action runs (RH-SAF-4)
``violation``          field 8 shows a safety code the candidate lacks (RH-SAF-1, RH-SAF-5);
                       with ``surface`` after it when the window also covers the lockout; after
                       any of the motion events below when the way made before it is unseen too
``waypoint`` ×n        mode ``N``: the next mission waypoint(s) reached, up to
                       :data:`MAX_WAYPOINTS` (legs of any length)
``mission park``       a mission park at a waypoint whose park time is not known yet, maybe
                       after waypoints passed (learnt when none passed)
``mission end``        ``S`` where only the end of a mission of unknown length explains it
``on station``         ``mP``: the ``$OPK`` countdown starts; ``W``: the queued waypoint is
                       reached (×n for the queue); ``P``: a mission park resumed after remote
                       control, held until back on station (RH-INT-2), counts from then
``resumed park held``  ``P``: a mission park resumed after remote control counts only once
                       back on station at its waypoint (RH-INT-2's other reading)
=====================  ===================================================================

:func:`explain_reply` does the same for an ``$ACK`` the candidate cannot explain, with the events
that change an answer: a violation (an unexpected err 26; its code is learnt from the next
``$OSI``), the mission's end (a command refused for want of a running mission), the surface (a
command the ascent refuses accepted). Mission names the observer knows nothing about are learnt
from the vehicle's answer; the answer is then adopted but not judged (``mission_dependent``).

A report's numbers, which these and the report checks (:mod:`.osichecks`) read, are worked out
here once per report (:func:`osi_numbers`, :func:`osi_depth_m`).
"""

from __future__ import annotations

from typing import Callable, Optional

from ...grammar import sentences as s
from ...grammar.errors import SentenceError
from ...model.geo import KNOT_MPS
from ...model.plant import OnStation, QueueWaypointReached, SafetyViolation, WaypointReached
from ...profile import SAFETY_CODES
from .candidate import Candidate
from .catalog import UnknownMission, _LearntOpen

__all__ = ["explain_osi", "explain_reply", "same_replies", "reply_keys", "MAX_WAYPOINTS", "osi_depth_m",
           "osi_numbers", "reachable"]

#: The most mission (or queue) waypoints the observer assumes passed between two reports.
MAX_WAYPOINTS = 8
#: The trials of one mission waypoint reached, what it holds learnt: the event a plant note gives
#: the moment of when the observer left it to the reports (:attr:`~.candidate.Candidate.noted`).
_NOTED = ("mission waypoint reached", "a mission park", "the mission's end")
_FT = 0.3048
_SAFETY = frozenset(SAFETY_CODES)


def _key(r) -> tuple:
    if isinstance(r, str):
        return (r,)
    if isinstance(r, s.ACK):
        return ("ACK", r.type, r.status, r.err)
    return (type(r).__name__,)


def reply_keys(replies: list) -> list[tuple]:
    """What is judged of a reply list: ACK type/status/err, data sentence kinds."""
    return [_key(r) for r in replies]


def same_replies(want: list, got: list) -> bool:
    """Two reply lists agree on what is judged (:func:`reply_keys`)."""
    return reply_keys(want) == reply_keys(got)


#: The fastest a vehicle rises or sinks (m/s): what bounds a surface, or a GPS-fix depth, that no
#: report showed (RH-RD-10).
VERTICAL_MPS = 1.0


def osi_depth_m(osi: s.OSI, depth_unit: str) -> Optional[float]:
    d = osi_numbers(osi)[4]
    if d is None:
        return None
    return d * _FT if depth_unit == "ft" else d


def osi_numbers(osi: s.OSI) -> tuple:
    """``(lat, lon, speed, field 7, depth or None)`` of a report as floats, worked out once per
    report however many checks read them (``float`` of a ``Decimal`` formats and parses it).
    A field the report does not show readably (``None``: a bad field, :mod:`.lines`) is None."""
    hit = _NUMBERS[0]
    if hit[0] is osi:
        return hit[1]
    lat, lon, speed, distance, depth = osi.lat, osi.lon, osi.speed, osi.distance, osi.depth
    got = (None if lat is None else float(lat), None if lon is None else float(lon),
           None if speed is None else float(speed), None if distance is None else float(distance),
           None if depth is None else float(depth))
    _NUMBERS[0] = (osi, got)  # one item, replaced whole: the latest report
    return got


_NUMBERS: list = [(None, ())]


# =============================================================================== $OSI

def explain_osi(c: Candidate, osi: s.OSI, v: float, slack_v: float, tp: float, catalog,
                fix_depth: float, depth_unit: str) -> Optional[Candidate]:
    """A copy of ``c`` with the unseen events that explain ``osi`` (module docstring), or None."""
    m = c.model
    # the events happened after the last observation that showed they had not (``seen``), but the
    # model runs forward only: they are applied once the commands since then (whose answers did
    # not depend on them) have been, and the window from ``seen`` is carried as their uncertainty
    # — the commands of a slow line can fill much of it
    seen = min(tp, v)
    tp = max(tp, m.now if m.now is not None else tp)
    tp = min(tp, v)
    gap = max(0.0, v - seen)
    depth = osi_depth_m(osi, depth_unit)
    at_surface = depth is not None and depth <= fix_depth

    def ok(trial: Optional[Candidate], early: float = 0.0) -> bool:
        return trial is not None and not trial.check(osi, v, slack_v + gap + early)

    def run(name: str, build: Callable[[Candidate], Optional[Candidate]], n: int = 1,
            learn: Optional[Callable[[], None]] = None) -> Optional[Candidate]:
        # a countdown the last report showed full (field 10 is rounded up, RH-RD-5) may have begun
        # up to a second before that report: the window of an on-station event reaches back as far
        early = 1.0 if name.startswith("on station") else 0.0
        trial = build(c.clone())
        if ok(trial, early):
            if learn is not None:
                learn()
            if n == 1 and c.noted == tp and name.startswith(_NOTED):
                # the emulator's own note says when: the waypoint was reached then, at the window's start
                return trial.adopted(f"{name} at v={tp:.1f} (the plant's note)", tp, tp, n)  # type: ignore[union-attr]
            return trial.adopted(f"{name} between v={seen - early:.1f} and v={v:.1f}", seen - early, v, n)  # type: ignore[union-attr]
        return None

    def surfaced(t: Candidate) -> Candidate:
        t.model.advance(tp)
        t.model.update_plant(t.model.snapshot.with_(depth_m=depth))
        return t

    def violation(t: Candidate, then_surface: bool = False) -> Candidate:
        t.model.plant(SafetyViolation(osi.error_state), tp)
        if then_surface:
            t.model.update_plant(t.model.snapshot.with_(depth_m=depth))
        return t

    trials: list = []
    if at_surface and m.phase in ("ascent", "lockout"):
        trials.append(("the surface", surfaced, 1, None))
    if osi.error_state in _SAFETY and osi.error_state != m.error_state:
        if c.code_unknown and m.phase != "none":
            t = c.clone()
            t.model.error_state = osi.error_state
            t.code_unknown = False
            if ok(t):
                return t
        trials.append((f"safety violation {osi.error_state}", violation, 1, None))
        if at_surface:
            trials.append((f"safety violation {osi.error_state} and the surface",
                           lambda t: violation(t, True), 2, None))
    if m.phase == "none":
        motion = _motion_trials(c, osi, tp, gap, catalog, v)
        trials += motion
        if osi.error_state in _SAFETY and osi.error_state != m.error_state:
            # the way made first, then a violation the vehicle raised by itself (RH-SAF-5) — the
            # lockout shows the mission mode the way left it in (RH-RD-11), the surface after it
            for name, build, n, learn in motion:
                trials.append((f"{name}, then safety violation {osi.error_state}", _then(build, violation),
                               n + 1, learn))
                if at_surface:
                    trials.append((f"{name}, then safety violation {osi.error_state} and the surface",
                                   _then(build, lambda t: violation(t, True)), n + 2, learn))
    due = m.timers.due
    if m.phase == "none" and due is not None and tp <= due <= v:
        # a timer ran out between the reports (a release to the mission, RH-INT-2), and the way made
        # after it is unseen too: the same motion, from the state after the timer
        after = c.clone()
        after.model.advance(due)
        after.drain()
        if after.model.mode != m.mode:
            for name, build, n, learn in _motion_trials(after, osi, due, gap, catalog, v):
                trials.append((f"{name} after the {after.model.mode} the timer left it in",
                               _then(_advance(due), build), n, learn))
    for name, build, n, learn in trials:
        got = run(name, build, n, learn)
        if got is not None:
            return got
    return None


def _advance(t_due: float) -> Callable[[Candidate], Candidate]:
    def build(t: Candidate) -> Candidate:
        t.model.advance(t_due)
        return t
    return build


def _then(first: Callable[[Candidate], Optional[Candidate]],
          second: Callable[[Candidate], Candidate]) -> Callable[[Candidate], Optional[Candidate]]:
    """A trial's build followed by another's on the same copy (None when the first finds nothing)."""
    def build(t: Candidate) -> Optional[Candidate]:
        got = first(t)
        return second(got) if got is not None else None
    return build


def _motion_trials(c: Candidate, osi: s.OSI, tp: float, gap: float, catalog, v: float) -> list:
    """The plant events that fit ``c``'s mode, each only where it is physically possible.

    Nothing moves faster than the profile's ``max_speed_kn`` (or the speed the vehicle itself
    reports, if higher), and "there" means within ``on_station_m`` (RH-RD-5):

    * a mission waypoint is reached (mode ``N``; every trial that passes the next waypoint ``k``,
      the learnt parks and mission ends included) only if the vehicle can have come within
      ``on_station_m`` of ``k`` by the report: from the last report of its distance to ``k``
      (field 7 in ``N`` or ``P`` at ``k``, :attr:`~.candidate.Candidate.nav_seen`) — and, from
      the last position reported after it (under remote control, when the mission is frozen,
      RH-RD-5), less the way it has made since; with the vehicle's mission files (a catalogue
      that learns nothing), from the last position reported, to ``k`` as the file places it.
      Nothing of that reported: no evidence, adoptable;
    * the ``$OPK`` countdown starts on station (RH-PK-2) only if the report showing it can be on
      station when its count began: field 7 at most ``on_station_m`` plus the way the vehicle can
      have drifted in the time field 10 has counted (rounded up, RH-RD-5, and the RH-TIM-1
      tolerance of the park) — the profile does not say it must stay on station while it counts.
      (What earlier reports show of where it was is judged by :mod:`.osichecks`, RH-PK-2.)
    """
    m = c.model
    out: list = []

    def can_reach(k: int) -> bool:
        return reachable(c, k, v, catalog, osi_numbers(osi)[2] or 0.0)

    if m.mode == "N" and m.mission is not None:
        k = m.mission_wp

        def waypoints(n: int):
            def build(t: Candidate) -> Optional[Candidate]:
                for _ in range(n):
                    if t.model.mode != "N":
                        return None
                    t.model.plant(WaypointReached(), tp)
                return t
            return build
        for n in range(1, MAX_WAYPOINTS + 1):
            out.append(("mission waypoint reached" if n == 1 else f"{n} mission waypoints reached",
                        waypoints(n), n, None))
        out += _park_and_end(c, osi, tp, gap, catalog)
        if not can_reach(k):
            def not_past(build):
                def guarded(t: Candidate) -> Optional[Candidate]:
                    before = t.model
                    got = build(t)
                    if got is None or got.model is not before:
                        return got  # not from here (a park's end taken from the checkpoint)
                    return got if (got.model.mode, got.model.mission_wp) == ("N", k) else None
                return guarded
            out = [(name, not_past(build), n, learn) for name, build, n, learn in out]
    elif m.mode == "P" and m.mission is not None and osi.mode == "S":
        out += _park_and_end(c, osi, tp, gap, catalog)
    elif m.mode == "P" and osi.mode == "P" and m.mission is not None and c.resumed:
        out += _resumed_park(c, osi, tp)
    elif m.mode == "mP":
        from ...model.timers import tolerance
        prof = m.profile
        _, _, speed, distance, _ = osi_numbers(osi)  # (an unread field 7 is no evidence of where it is)
        knots = max([prof.max_speed_kn, speed or 0.0] + [x[-1] for x in (c.nav_seen, c.fix_seen) if x is not None])
        vmax = knots * KNOT_MPS  # m/s
        counted = max(0.0, m.opk_seconds - osi.park_time) + 1.0 + tolerance(m.opk_seconds)
        if distance is None or distance <= prof.on_station_m + vmax * counted:
            def on_station(t: Candidate) -> Candidate:
                t.model.plant(OnStation(), tp)
                return t
            out.append(("on station at the $OPK position", on_station, 1, None))
    elif m.mode == "W":
        def queue(n: int):
            def build(t: Candidate) -> Optional[Candidate]:
                for _ in range(n):
                    if t.model.mode != "W" or t.model.queue_parking:
                        return None
                    t.model.plant(QueueWaypointReached(), tp)
                return t
            return build
        for n in range(1, min(len(m.queue), MAX_WAYPOINTS) + 1):
            out.append(("queued waypoint reached" if n == 1 else f"{n} queued waypoints reached",
                        queue(n), n, None))
        whole = len(m.queue)
        if m.mission is not None and 0 < whole <= MAX_WAYPOINTS and can_reach(m.mission_wp):
            # the queue done, the mission resumed (RH-OMW-4, RH-INT-2) and its next waypoint reached
            # too between two reports (a slow line leaves long gaps between them)
            def then_mission(j: int):
                def build(t: Candidate) -> Optional[Candidate]:
                    got = queue(whole)(t)
                    for _ in range(j):
                        if got is None or got.model.mode != "N":
                            return None
                        got.model.plant(WaypointReached(), tp)
                    return got
                return build
            for j in (1, 2):
                out.append((f"the queue done, then {j} mission waypoint(s) reached", then_mission(j), whole + j,
                            None))
    return out


def _resumed_park(c: Candidate, osi: s.OSI, tp: float) -> list:
    """A mission park resumed after remote control (RH-INT-2) that counts only once back on
    station at its waypoint — the reading the profile leaves beside counting at once
    (:meth:`~helmcheck.model.vehicle.VehicleModel.await_park_station`): the count held at the time
    left (where the report shows it, within what the observer knows of that time:
    :attr:`~.candidate.Candidate.left_known`); then on station there, as for the ``$OPK`` park
    (field 7 at most ``on_station_m`` plus the way it can have drifted while its count ran)."""
    from ...model.timers import tolerance
    m = c.model
    out: list = []
    shown = float(osi.park_time)
    if not m.park_waiting and m.timers.armed("park"):
        def hold(t: Candidate) -> Optional[Candidate]:
            if not t.model.await_park_station():
                return None
            left, u = t.model.park_left or 0.0, c.left_known
            if left < shown - 1.0 - u or left > shown + u:
                return None  # not the time that was left (RH-INT-2)
            t.model.park_left = min(max(left, shown - 1.0 + 1e-6), shown)  # field 10 rounded up
            t.left_known = 0.0
            return t
        out.append(("the resumed mission park waiting to be back on station", hold, 1, None))
    elif m.park_waiting:
        prof = m.profile
        left = m.park_left or 0.0
        knots = max([prof.max_speed_kn, float(osi.speed)] + [x[-1] for x in (c.nav_seen, c.fix_seen) if x is not None])
        counted = max(0.0, left - shown) + 1.0 + tolerance(left)
        if float(osi.distance) <= prof.on_station_m + knots * KNOT_MPS * counted:
            def on_station(t: Candidate) -> Candidate:
                t.model.plant(OnStation(), tp)
                return t
            out.append(("on station at the mission park's waypoint", on_station, 1, None))
    return out


def reachable(c: Candidate, k: int, v: float, catalog, speed_kn: float = 0.0) -> bool:
    """Can the vehicle of candidate ``c`` have come within ``on_station_m`` of mission waypoint
    ``k`` by vehicle time ``v`` (:func:`_motion_trials`' first rule)? Nothing moves faster than
    the profile's ``max_speed_kn`` or the fastest speed reported (``speed_kn``, the last reports'
    own); no distance reported is no evidence (True)."""
    from ...model.geo import distance_m
    from ...model.timers import tolerance

    m = c.model
    prof = m.profile
    run, nav, fix = m.mission, c.nav_seen, c.fix_seen
    if run is None:
        return True
    knots = max([prof.max_speed_kn, speed_kn] + [x[-1] for x in (nav, fix) if x is not None])
    vmax = knots * KNOT_MPS  # m/s
    need = []  # (since when, metres it still had to make at least to be on station at k)
    if nav is not None and nav[0] == run.name and nav[1] == k:
        _, _, d, t0, lat, lon, _ = nav
        need.append((t0, d - prof.on_station_m))
        if fix is not None and fix[0] > t0:  # the way made since (under remote control, say)
            need.append((fix[0], d - distance_m(lat, lon, fix[2], fix[3]) - prof.on_station_m))
    if fix is not None and not getattr(catalog, "learns", True) and not run.is_open:
        w = run.waypoints[k]
        need.append((fix[0], distance_m(fix[2], fix[3], w.lat, w.lon) - prof.on_station_m))
    for since, metres in need:
        left = max(0.0, v - since)
        if metres > vmax * (left + tolerance(left)):
            return False
    return True


def _park_and_end(c: Candidate, osi: s.OSI, tp: float, gap: float, catalog) -> list:
    """Learning a mission park, or the end of a mission of unknown length (RH-RD-5, RH-MSN-4)."""
    m = c.model
    run = m.mission
    entry = catalog.entry(run.name) if run is not None else None
    if entry is None:
        return []
    out: list = []
    wp = m.mission_wp

    def swap(t: Candidate, mission) -> None:
        tm = t.model
        for attr in ("mission", "loaded", "srp_mission"):
            if getattr(tm, attr) is run:
                setattr(tm, attr, mission)

    at, j = osi.next_waypoint, osi.next_waypoint - wp
    if (m.mode == "N" and osi.mode == "P" and 0 <= j < MAX_WAYPOINTS and not entry.park_known(at)
            and (run.is_open or at <= run.last)):
        # the park at the report's waypoint, reached after j waypoints passed (RH-OUT-4, RH-RD-5);
        # its length is learnt only when nothing but the park fills the window (j = 0): after
        # travel, the window bounds when it ends (what this candidate uses), not how long it is
        seconds = osi.park_time + gap

        def learn_p():
            entry.learn_park(at, seconds, osi.park_time - 1.0)

        def build_p(t: Candidate) -> Optional[Candidate]:
            swap(t, _with_park(run, at, seconds))
            for _ in range(j + 1):
                if t.model.mode != "N":
                    return None
                t.model.plant(WaypointReached(), tp)
            return t
        name = "a mission park (learnt)" if not j else f"{j} mission waypoint(s) reached, then a mission park"
        out.append((name, build_p, j + 1, None if j else learn_p))
    bounds = entry.park_bounds(osi.next_waypoint) if m.mode == "N" and osi.mode == "P" else None
    if bounds is not None and osi.next_waypoint == wp and bounds[1] - bounds[0] > 1e-6:
        # a park known only within an interval (first seen after it began), seen again from
        # closer to its start — a mission restarted on station there (RH-MSN-2, RH-RD-5): the
        # length this report allows, where it agrees with what was seen before, narrows it
        lo, hi = osi.park_time - 1.0, osi.park_time + gap
        if lo <= bounds[1] + 1e-6 and hi >= bounds[0] - 1e-6:
            refined = max(bounds[0], min(bounds[1], hi))

            def learn_r():
                entry.refine_park(wp, lo, hi)

            def build_r(t: Candidate) -> Optional[Candidate]:
                swap(t, _with_park(run, wp, refined))
                t.model.plant(WaypointReached(), tp)
                return t if t.model.mode == "P" else None
            out.append(("a mission park (its length narrowed)", build_r, 1, learn_r))
    if m.mode == "N" and not entry.park_known(wp):
        if osi.mode == "N" and osi.next_waypoint == wp + 1:
            def learn_0():
                entry.learn_park(wp, 0.0)

            def build_0(t: Candidate) -> Candidate:
                swap(t, _with_park(run, wp, 0.0))
                t.model.plant(WaypointReached(wp), tp)
                return t
            out.append(("mission waypoint reached (no park)", build_0, 1, learn_0))
    if osi.mode == "S" and run.is_open:
        base = m.checkpoint
        if base is not None and base.mode == "P" and base.mission is run and m.mode == "N":
            last = base.mission_wp
            origin = "checkpoint"
        else:
            last = wp
            origin = m.mode

        def learn_end():
            entry.learn_end(last)

        def build_end(t: Candidate) -> Optional[Candidate]:
            if origin == "checkpoint":
                t.model = base.clone()
                t.model.trace = []
            swap(t, entry.finite(last + 1))
            if t.model.mode == "N":
                t.model.plant(WaypointReached(last), tp)
            return t
        out.append(("the mission's end (its length learnt)", build_end, 1, learn_end))
    return out


def _with_park(run, wp: int, seconds: float):
    """``run`` with a park of ``seconds`` at waypoint ``wp`` (a candidate's trial copy)."""
    from ...model.missions import Mission, Waypoint
    wps = run.waypoints
    if run.is_open:
        parks = dict(getattr(wps, "parks", {}))
        parks[wp] = seconds
        return Mission(run.name, _LearntOpen(parks))
    lst = list(wps)
    w = lst[wp]
    lst[wp] = Waypoint(w.lat, w.lon, w.depth, w.speed, seconds)
    return Mission(run.name, tuple(lst))


# =============================================================================== $ACK

def explain_reply(c: Candidate, item, v: float, observed: list, tp: float, catalog,
                  fix_depth: float, reported_depth: Optional[float] = None) -> Optional[tuple[Candidate, list, bool]]:
    """``(candidate, replies, mission_dependent)`` with unseen events (or a mission name learnt
    from the vehicle's answer) that explain ``observed`` for ``item`` at ``v``; else None."""
    m = c.model
    tp = min(max(tp, m.now if m.now is not None else tp), v)
    ack = next((r for r in observed if isinstance(r, s.ACK)), None)
    if ack is None:
        return None

    def attempt(name: str, prepare: Callable[[Candidate], Optional[Candidate]], n: int = 1):
        t = prepare(c.clone())
        if t is None:
            return None
        replies = t.model.receive(item, v)
        if same_replies(replies, observed):
            return t.adopted(f"{name} between v={tp:.1f} and v={v:.1f}", tp, v, n), replies
        return None

    trials: list = []
    if ack.err == 26 and m.phase == "none":
        def violated(t: Candidate) -> Candidate:
            t.model.plant(SafetyViolation("Sop"), tp)
            t.code_unknown = True  # learnt from the next $OSI field 8
            return t
        trials.append(("a safety violation (code not yet shown)", violated))
    if m.phase in ("ascent", "lockout") and ack.err != 26:
        def surfaced(t: Candidate, holding: bool = False) -> Candidate:
            t.model.advance(tp)
            t.model.update_plant(t.model.snapshot.with_(depth_m=0.0))
            if holding and t.model.phase == "ascent" and t.model.mode == "M":
                t.model.phase = "none"
            return t
        trials.append(("the surface", surfaced))
        if m.mode == "M" and reported_depth is not None and reported_depth <= fix_depth:
            # Decision (RH-SAF-3 ends the refusals "until the vehicle is at the surface"; RH-RD-12
            # is silent on a surface reached while $OMP holds depth, which the model defers to the
            # primitive's end): a vehicle the last report showed at the surface that ends the
            # episode there, mode M kept, conforms too
            trials.append(("the surface while $OMP held depth", lambda t: surfaced(t, holding=True)))
    if m.mission is not None and m.mode in ("N", "P") and m.phase == "none":
        def ended(t: Candidate) -> Optional[Candidate]:
            tm = t.model
            run = tm.mission
            entry = catalog.entry(run.name)
            if run.is_open and entry is not None:
                finite = entry.finite(tm.mission_wp + 1)
                for attr in ("mission", "loaded"):
                    if getattr(tm, attr) is run:
                        setattr(tm, attr, finite)
            elif tm.mission_wp != tm.mission.last:
                return None
            if tm.mode == "P":
                tm.advance(tp)
                return t if tm.mode == "S" else None
            tm.plant(WaypointReached(tm.mission_wp), tp)
            return t if tm.mode == "S" else None
        trials.append(("the mission's end", ended))
    for name, prep in trials:
        got = attempt(name, prep)
        if got is not None:
            return got[0], got[1], False
    got = _learn_name(c, item, v, observed, catalog)
    if got is not None:
        return got[0], got[1], True
    return None


def _learn_name(c: Candidate, item, v: float, observed: list, catalog):
    """An ``$OMSTART``/``$OMLOAD`` naming a mission the observer knows nothing about: follow the
    vehicle's answer (its mission files decide; the answer is not judged)."""
    if isinstance(item, SentenceError) or not isinstance(item, (s.OMSTART, s.OMLOAD)):
        return None
    names = [item.name] + ([item.srp] if isinstance(item, s.OMSTART) and item.srp else [])
    unknown = [n for n in names if isinstance(catalog.lookup(n), UnknownMission)]
    if not unknown:
        return None
    ack = observed[-1]
    if ack.status == 0:
        for n in unknown:
            catalog.learn_present(n)
    t = c.clone()
    replies = t.model.receive(item, v)  # adopted either way: the files decide, not the observer
    return t, replies
