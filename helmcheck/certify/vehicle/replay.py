"""Version-independent replay files: write one, read one, re-drive it against a vehicle.

A replay file is JSON::

    {"format": "helmcheck-replay", "version": 2, "clause": "RH-SRV-4", "reason": "...",
     "time_scale": 20.0, "profile": {...}, "start": "verified-reset", "lazy_silence": true,
     "steps": [{"send": "$OMSTOP,0*hh\\r\\n", "t": 0.0}, {"expect": "$ACK,1,0,0"}, ...,
               {"send": "$OMS,90,2,20,0.5,5*hh\\r\\n", "t": 0.412}, {"expect": "$ACK,9,0,0"},
               {"wait": 6.0}, {"send": "$OSD,S*27\\r\\n", "t": 0.731}, ...]}

``send`` is the exact bytes, escaped as in the wire log (``\\r``, ``\\n``, ``\\xNN``), and ``t``
when it was sent (wall seconds from the first step, at the recorded time scale); ``wait`` is
vehicle seconds (divided by the time scale when re-driven, RH-TIM-2); ``expect`` says in words
what the model expected then (for people, and to say where a re-drive went another way; the
re-drive asks the model afresh). ``origin`` (optional): the vehicle's position (lat, lon) when
the steps began; a re-drive moves every position the steps send by the difference to where the
vehicle is when it begins them (:mod:`.relocate`), so that they ask, relative to the vehicle, what
they asked when recorded. ``lazy_silence``: the sequence did not sit out the ACK window of
a line the vehicle must discard (the exploration's pace); the re-drive keeps that pace and lets
the observer settle every line before its verdict. Nothing in it depends on a hypothesis version.

The steps are the *whole* sequence from the verified reset that began it (the exploration records
from there, and ends every sequence with a verified reset of its own, so a lockout or a park a
sequence set going is judged inside it): whatever state the failure needs, the steps build it.
:func:`redrive` first brings the vehicle to that reset (``$OMSTOP,0`` until accepted, waiting out
a lockout left by whatever ran before, then ``S`` seen, at the surface when it gets there within
two minutes of vehicle time: :meth:`.session.Session.outwait_surface`; and, when the replay says
where the steps began, driven back there when the vehicle is more than 1 m off, and the mission's
first waypoint surveyed from there, :func:`_return`; when that reset does not end in ``S`` — also
for a failure on a clause the re-drive ignores — the steps are not sent: INCONCLUSIVE, or the
reset's own failure), then sends the steps at their recorded
pace (each line at its recorded offset, scaled to the present time scale, from the last line that
set a timer going — or as soon as the line before it is settled, when that is later — so that a
line that polled across a timer's end, or into the window after it, still does, however slowly
the vehicle answered the lines between this time), judging every reply
with the present model, and says whether it still fails — and at which step, or at which step the
vehicle first went another way than when it was recorded.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import NamedTuple, Optional

from ...grammar.wirelog import unescape
from ...profile import Profile
from ...reports.atomic import write_text_atomic
from .relocate import shift_line

__all__ = ["save_replay", "load_replay", "redrive", "Redrive", "ReplayError", "FORMAT"]

FORMAT = "helmcheck-replay"
#: Vehicle seconds a re-drive goes on polling after its last step (plus twice the observer's own
#: slack): the RH-TIM-1 tolerance of a 30 s timer, and then some.
LINGER_V = 3.0
#: How a re-drive's reason begins when the vehicle failed before the steps: not a reproduction of
#: the steps' failure (its :class:`Redrive` says ``ran=False``; the exploration does not count it,
#: :func:`.explore.counts`).
IN_RESET = "already in the verified reset before the steps"
#: A re-drive that finds the vehicle further than this from where the steps began drives it back
#: there first, for at most this long in vehicle time (:func:`_return`).
RETURN_BEYOND_M = 1.0
RETURN_WITHIN_V = 600.0
#: Where the drive back stops: this near the origin (:func:`_return`).
ON_ORIGIN_M = 0.5
#: The longest a re-drive polls on after its last step while the vehicle travels (:func:`_arrive`).
ARRIVE_WITHIN_V = 60.0


class ReplayError(ValueError):
    """A replay file that cannot be used; names the file."""


class Redrive(NamedTuple):
    """What a re-drive says: ``verdict`` (``fail`` / ``pass`` / ``inconclusive``), its ``reason``
    and the ``clause`` a failure was booked on; ``faithful``: the steps ran and the model expected
    every answer up to the verdict as it did when they were recorded (the vehicle went the
    recorded way). A pass that is not faithful says nothing of the recorded failure: the steps
    did not lead where they led then (:func:`.explore._confirm` does not count it). ``ran``: the
    steps were sent (not after a verified reset that failed, nor one refused by bench safety)."""

    verdict: str
    reason: str
    clause: Optional[str]
    faithful: bool
    ran: bool = True


def save_replay(path: Path, clause: str, reason: str, steps: list, time_scale: float, profile: Profile,
                lazy_silence: bool = True, origin: Optional[tuple] = None) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    t0 = next((float(s["t"]) for s in steps if "t" in s), 0.0)
    out = []
    for s in steps:
        s = dict(s)
        if "t" in s:
            s["t"] = round(float(s["t"]) - t0, 6)
        out.append(s)
    doc = {"format": FORMAT, "version": 2, "clause": clause, "reason": reason, "time_scale": time_scale,
           "profile": profile.as_dict(), "start": "verified-reset", "lazy_silence": lazy_silence}
    if origin is not None:
        doc["origin"] = [round(float(origin[0]), 6), round(float(origin[1]), 6)]
    doc["steps"] = out
    write_text_atomic(path, json.dumps(doc, indent=1) + "\n")
    return path


def load_replay(path: Path) -> dict:
    try:
        doc = json.loads(Path(path).read_text(encoding="utf-8"))
    except OSError as e:
        raise ReplayError(f"{path}: cannot read: {e.strerror or e}") from None
    except ValueError as e:
        raise ReplayError(f"{path}: not JSON: {e}") from None
    if not isinstance(doc, dict) or doc.get("format") != FORMAT or not isinstance(doc.get("steps"), list):
        raise ReplayError(f"{path}: not a helmcheck replay file (want format {FORMAT!r} and a steps list)")
    origin = doc.get("origin")
    if origin is not None and not (isinstance(origin, list) and len(origin) == 2
                                   and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in origin)):
        raise ReplayError(f"{path}: origin must be [lat, lon], two numbers (got {origin!r})")
    for i, st in enumerate(doc["steps"]):
        if not isinstance(st, dict) or sum(k in st for k in ("send", "wait", "expect")) != 1:
            raise ReplayError(f"{path}: step {i} needs exactly one of send, wait, expect")
    return doc


def redrive(doc: dict, session, time_scale: Optional[float] = None) -> Redrive:
    """Re-drive the steps on ``session``: a :class:`Redrive`.

    First the verified reset the sequence began from (module docstring), then the steps at their
    recorded pace; the session's observer judges every reply, as in any run. The reason names the
    step a failure came at, and the first step whose answer the model expected otherwise than
    when it was recorded (where the vehicle's state went another way)."""
    from .flow import CaseStop

    try:  # what an earlier drive left unanswered or running (it stopped at its failure) is its own
        with session.not_stopping():
            session.finish()
            session.outwait_lockout()
    except CaseStop:
        pass
    session.mark = session.ledger.mark()
    reset_failed = None
    try:
        with session.not_stopping():
            session.reset(mission=False)
            session.outwait_surface()
            if _return(doc, session):
                session.reset(mission=False)
                session.outwait_surface()
    except CaseStop as f:
        # the steps were recorded from a verified reset (RH-MSN-3: S): from anywhere else they
        # ask something else (a vehicle left in A by a fault the run already found, whose
        # $OMSTOP,0 does not end it, answers the steps' first $OMLOAD as one in A): not run
        reset_failed = f.reason
    got = [f for f in session.failures() if f[0] not in session.ignore]
    if got:  # a vehicle that breaks the profile in every reply already does in the reset
        return Redrive("fail", f"{IN_RESET}: {got[0][0]}: {got[0][1]}", got[0][0], False, ran=False)
    if reset_failed is not None:
        return Redrive("inconclusive", f"the verified reset before the steps failed: {reset_failed}", None, False,
                       ran=False)
    session.mark = session.ledger.mark()
    shift = _shift(doc, session)
    # the line pace the sequence was recorded at: an exploration does not sit out the window of a
    # line the vehicle must discard (the observer settles it later, :meth:`Session.finish`)
    lazy, session.lazy_silence = session.lazy_silence, bool(doc.get("lazy_silence", False))
    try:
        return _steps(doc, session, time_scale, shift)
    finally:
        session.lazy_silence = lazy


def _return(doc: dict, session) -> bool:
    """Bring the vehicle back to the replay's ``origin`` and let the judge see where the mission's
    first waypoint is from there; True when it sent anything (the caller resets again).

    The steps may depend on where the vehicle is against the mission's waypoints, which no shift
    of the steps' own positions moves: a release toward waypoint 0 from 9 m away is wrong, and
    from 6 m the vehicle may have got on station (within 3 m, RH-RD-5) inside RH-TIM-1's tolerance.
    And the judge can tell only what the reports showed: a vehicle whose mission files it does not
    have is judged against the distances the reports gave (RH-RD-5's field 7), and a run's earlier
    sequences had shown them where a fresh vehicle has not. So, with ``$OMSTART`` and ``$OMW``
    claimed and a test mission named, said in the log:

    * **Drive back**, when the vehicle is more than :data:`RETURN_BEYOND_M` from the origin and
      the bench speed covers the distance within :data:`RETURN_WITHIN_V` vehicle seconds (else the
      steps' positions are moved instead, :func:`_shift`, and the survey is made where the vehicle
      is): the test mission started and one
      ``$OMW`` at the surface (depth 0, no park, the bench speed), followed while it gets nearer.
      The ``$OMW`` aims past the origin by the on-station distance, on the line the vehicle comes
      along, so that it passes about over the origin rather than counting the waypoint reached up
      to ``on_station_m`` short of it; the drive ends within :data:`ON_ORIGIN_M` of the origin, past
      its nearest point, or with the queue, and the queue is cleared.
    * **Survey**: the mission running (started here, or resumed by the cleared queue), one
      ``$OSD`` reports the distance to its first waypoint from the origin, then ``$OMSTOP`` at
      once, before the mission takes the vehicle on."""
    from ...model.geo import KNOT_MPS, distance_m
    from .generate import bench_speed
    from .session import frame
    origin = doc.get("origin")
    p = session.profile
    if origin is None or not {"OMSTART", "OMW"} <= set(p.commands) or not p.mission:
        return False
    o_lat, o_lon = float(origin[0]), float(origin[1])
    lat, lon = map(float, session.here())
    apart = distance_m(lat, lon, o_lat, o_lon)
    drive = apart > RETURN_BEYOND_M
    if drive and apart > bench_speed(p) * KNOT_MPS * RETURN_WITHIN_V:
        drive = False
        session.note(f"replay: the vehicle is {apart:.0f} m from where the steps began, too far to drive back "
                     f"within {RETURN_WITHIN_V:g} s at the bench speed; the steps' positions are moved instead, "
                     f"and the mission's first waypoint surveyed from where it is ($OMSTART, $OSD, $OMSTOP)")
    else:
        session.note(f"replay: the vehicle is {apart:.0f} m from where the steps began; "
                     + ("driven back there first ($OMSTART, then $OMW to it), " if drive else "")
                     + "the mission's first waypoint surveyed from there ($OMSTART, $OSD, $OMSTOP)")
    sent = session.exchange(frame(f"OMSTART,0,0,0,0,{p.mission},"))
    if sent is None or not sent.accepted:
        return True
    if drive:
        past = p.on_station_m / apart  # the aim: beyond the origin, on the line from here
        aim = (o_lat + (o_lat - lat) * past, o_lon + (o_lon - lon) * past)
        session.exchange(frame(f"OMW,{aim[0]:.6f},{aim[1]:.6f},0,,15,{bench_speed(p):g},0,"))
        end, window = session.now() + RETURN_WITHIN_V / session.k, session.now() + 60.0 / session.k
        best, near = apart + p.on_station_m, apart
        while session.now() < end:
            osi = session.poll()
            if osi.lat is None or osi.lon is None:
                break  # the report does not show readably where it is
            here = distance_m(float(osi.lat), float(osi.lon), o_lat, o_lon)
            # done: the queue ended, on the origin, or past the nearest point of the way to the aim
            if osi.mode != "W" or here <= ON_ORIGIN_M or (here < p.on_station_m and here > near):
                break
            near = min(near, here)
            left = distance_m(float(osi.lat), float(osi.lon), *aim)
            if session.now() > window:  # a minute of vehicle time and no nearer: it does not move
                if left > best - 1.0:
                    break
                best, window = left, session.now() + 60.0 / session.k
            session.link.sleep(max(session.poll_gap, 0.05))
        if session.obs.last_osi is not None and session.obs.last_osi.mode == "W" and p.omw_clear_keywords:
            session.exchange(frame(f"OMW,{p.omw_clear_keywords[0]}"))
    session.poll()
    if "OMSTOP" in p.commands:
        session.exchange(frame("OMSTOP,0"))
    return True


def _arrive(session) -> None:
    """After the last step: while the vehicle still follows a queue (``W``, RH-OMW-2/4) or travels
    to its ``$OPK`` park (``mP`` not yet on station, RH-PK-2), poll on until it is done, for at most
    :data:`ARRIVE_WITHIN_V` vehicle seconds, judging every report (:meth:`.session.Session.check`).
    A vehicle that begins a little off where the recording's did (within :data:`ON_ORIGIN_M` of the
    drive back, or a shift) takes a little longer to get where the recorded failure showed."""
    on = session.profile.on_station_m
    session.poll_while(lambda osi: osi.mode == "W" or (osi.mode == "mP" and float(osi.distance or 0) > on),
                       ARRIVE_WITHIN_V, judge=True)


def _shift(doc: dict, session) -> tuple[float, float]:
    """How far the steps' positions move: from the replay's ``origin`` to where the vehicle is now
    (:mod:`.relocate`); nothing for a replay without one. Said in the log when it is not nothing."""
    origin = doc.get("origin")
    if origin is None:
        return 0.0, 0.0
    lat, lon = session.here()
    dlat, dlon = round(float(lat) - float(origin[0]), 6), round(float(lon) - float(origin[1]), 6)
    if dlat or dlon:
        session.note(f"replay: the steps' positions moved {dlat:+.6f}, {dlon:+.6f} degrees, from where they "
                     f"were recorded ({origin[0]}, {origin[1]}) to where this vehicle begins ({lat}, {lon})")
    return dlat, dlon


def _armed(session) -> frozenset:
    """The timers the observer's mirror runs, each as (name, start, duration): a line that adds
    one set it going (or restarted it)."""
    timers = session.obs.state().timers
    return frozenset((n, round(timers.deadline(n) - timers.duration(n), 6), timers.duration(n))
                     for n in timers.names())


def _steps(doc: dict, session, time_scale: Optional[float], shift=(0.0, 0.0)) -> Redrive:
    from .flow import CaseStop
    from .safety import BenchSafetyRefused
    from .session import _brief

    steps = doc["steps"]
    k_rec = float(doc.get("time_scale") or session.k)
    pace = k_rec / float(time_scale or session.k)
    where = {"i": -1, "send": ""}
    diverged: list = []
    # each line at its recorded offset (scaled to the present time scale) from the last line that
    # set a timer going, or as soon as the line before it is settled when that is later: a line
    # that polled across a timer's end or into the window after it (an ascent, a park) still
    # does, however slowly the lines between were answered this time; a delay before a timer's
    # line shifts it and what follows it
    anchor_t, anchor_at = next((float(st["t"]) for st in steps if "t" in st), 0.0), session.now()
    last = None
    try:
        for i, st in enumerate(steps):
            where["i"] = i
            if "send" in st:
                where["send"] = st["send"]
                at = None
                if "t" in st:
                    session.link.sleep(max(0.0, anchor_at + (float(st["t"]) - anchor_t) * pace - session.now()))
                    at = session.now()
                raw = shift_line(unescape(st["send"]), *shift)
                armed = _armed(session)
                try:
                    last = session.exchange(raw)
                except BenchSafetyRefused as e:
                    return Redrive("inconclusive", f"step {i + 1} was not sent: {e}", None, False, ran=False)
                if at is not None and _armed(session) - armed:
                    anchor_t, anchor_at = float(st["t"]), at
            elif "wait" in st:
                session.wait(float(st["wait"]))
            elif "expect" in st and last is not None and not diverged:
                now = _brief(last.expected)
                if now != st["expect"]:
                    diverged.append(f"step {i} ({where['send'].strip()}) went another way: recorded "
                                    f"{st['expect']}, now {now}")
        where["send"] = ""
        # a line the vehicle left unanswered, and a transition that comes late by more than its
        # tolerance, are judged before the verdict
        session.finish(LINGER_V + 2 * session.obs.slack_v())
        _arrive(session)
    except CaseStop as f:
        at = f"step {where['i'] + 1} of {len(steps)} ({where['send'].strip() or 'a wait'})"
        why = f"at {at}: {f.reason}" + (f"; first, {diverged[0]}" if diverged else "")
        return Redrive("fail" if f.outcome == "fail" else "inconclusive", why, f.clause, not diverged)
    if diverged:
        return Redrive("pass", f"all {len(steps)} steps agreed with the model, but {diverged[0]}", None, False)
    return Redrive("pass", f"all {len(steps)} steps agreed with the model", None, True)
