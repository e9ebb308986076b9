"""The interpreter of the clause cases: steps (:mod:`.steps`) into session calls (:mod:`.session`).

:func:`run_case` writes the case's note (``case V-22 RH-INT-2: …``, so every finding inside it
is booked on the clauses it is about), does the verified reset to its start state, runs its
steps and closes it (``case V-22 end``). It returns the case's outcome for the report's case
list — the *clause* verdicts are the observer's, in the ledger.

Things the tester knows and the wire does not are written to the log as notes, so an offline
check reaches the same verdicts: a case the profile does not let run (``not tested …``), a step
the bench-safety interlock refused (``not tested <clause>: …`` — a clause is never passed by a
step that was not sent), a state the case needed and the vehicle — conformingly — was not in
(``inconclusive …``), a case whose expectation disagrees with the model (the tester's fault,
``inconclusive``).
"""

from __future__ import annotations

from decimal import Decimal
from typing import Optional

from ...grammar import checksum_hex
from ...grammar import sentences as s
from ...profile import Profile
from .catalogue import unmet_need
from .edges import edge_list, edge_values, north_of, opk_edge_m
from .flow import CaseStop
from .safety import BenchSafetyRefused
from .session import Session, frame
from .steps import (Burst, Case, ClearWords, Fault, MissionEnd, Octd, Poll, Raw, Send, SetRoundTrip, Settle, Start,
                    Until, Wait, WithSetting, Quiet)

__all__ = ["run_case", "run_step", "raw_line", "context", "fill"]


# ============================================================================ templates

def context(session: Session) -> dict:
    p = session.profile
    lat, lon = session.here()
    bench = p.bench_safety
    speed = Decimal(str(min(2.0, p.max_speed_kn, bench.max_speed_kn if not bench.in_water else 99)))
    motor = min(0x90, p.bench_safety.max_motor_byte if not bench.in_water else 0x90)
    motor = max(0x80, motor)
    nwp = p.mission_waypoints
    base = p.waypoint_base
    ctx = {"mission": p.mission, "speed": f"{speed.normalize():f}", "motor": f"{motor:02X}",
           "wp_last": str(nwp - 1 + base), "wp_bad": str(nwp + base),
           "depth_over": f"{p.max_depth + 1:g}", "speed_over": f"{p.max_speed_kn + 0.5:g}",
           # deep enough that an ascent after a lockout takes a while, within any depth range
           "dive_depth": f"{min(p.max_depth / 2, 10.0 if p.depth_unit == 'm' else 33.0):g}"}
    ctx.update(session.durations().context())
    ctx.update(edge_values(p), opk_in_m=opk_edge_m(p, "in"), opk_out_m=opk_edge_m(p, "out"))
    kws = (list(p.omw_clear_keywords) or ["Clr"]) * 3  # the profile's $OMW keywords, first three (RH-OMW-3)
    ctx.update(kw_a=kws[0], kw_b=kws[1], kw_c=kws[2])
    _position(ctx, lat, lon)
    _other(session, ctx)
    return ctx


def _position(ctx: dict, lat: str, lon: str) -> None:
    opos = float(ctx.get("opos_m", 110.0)) / 111320.0  # an $OPOS the next report tells apart (RH-POS-2)
    ctx.update(lat=lat, lon=lon, near_lat=f"{float(lat) + 0.001:.6f}", near_lon=f"{float(lon) + 0.001:.6f}",
               opos_lat=f"{float(lat) + opos:.6f}",
               far_lat=f"{float(lat) + 1.0:.6f}", km_lat=f"{float(lat) + 0.01:.6f}",  # 1.1 km north
               stn_lat=f"{float(lat) + 15.0 / 111320.0:.6f}")  # 15 m north
    if "opk_in_m" in ctx:  # the $OPK 10-mile edge, from where the vehicle last reported (.edges)
        ctx.update(opk_in_lat=north_of(float(lat), ctx["opk_in_m"]), opk_out_lat=north_of(float(lat), ctx["opk_out_m"]))


def _other(session: Session, ctx: dict) -> None:
    """``{wp_other}``: a waypoint of the test mission that is not its (learnt) park waypoint."""
    p = session.profile
    entry = session.obs.missions.entry(p.mission)
    park = entry.park_waypoint if entry is not None else None
    n = max(1, p.mission_waypoints)
    other = 1 % n if park is None else (park + 1) % n
    ctx["wp_other"] = str(other + p.waypoint_base)


def _here(session: Session, ctx: dict) -> None:
    _position(ctx, *session.here())
    _other(session, ctx)


#: Commands only the lockout refuses once a mission runs (RH-SAF-1: err 26; afterwards refused for
#: the state, 23/24, changing nothing): the probes that show a lockout's end, first claimed first.
LOCKOUT_PROBES = ("ORWSET,Sle,R", "OLOGL,probe")


def _claimed_probe(session: Session, probe: Optional[str]) -> Optional[str]:
    """``probe``, or another lockout probe when the profile does not claim its command (a command
    the profile does not claim is never sent); None when it claims none."""
    if not probe:
        return None
    claimed = session.profile.commands
    for text in (probe,) + tuple(p for p in LOCKOUT_PROBES if p != probe):
        if text.split(",", 1)[0] in claimed:
            return text
    return None


def fill(text: str, ctx: dict) -> str:
    return text.format(**ctx) if "{" in text else text


def number(value, ctx: dict) -> Optional[float]:
    """A step's number, or the number a template in it names (``"{gap}"``)."""
    if value is None or isinstance(value, (int, float)):
        return value
    return float(fill(value, ctx))


def raw_line(kind: str, body: str, profile: Profile) -> bytes:
    """One negative (or boundary) line derived from ``body`` (:data:`.steps.RAW_KINDS`)."""
    good = frame(body)
    if kind == "badck":
        ck = int(checksum_hex(body), 16) ^ 0x5A
        return b"$" + body.encode() + b"*" + f"{ck:02X}".encode() + b"\r\n"
    if kind == "zerock":
        return frame(zero_padded(body, profile))
    if kind == "lowerck":
        pad = body
        while body.startswith("OSD") and not any(c in "ABCDEF" for c in checksum_hex(pad)) and len(pad) < 60:
            pad += ","  # $OSD takes empty fields (RH-RD-7): find a checksum with a hex letter
        if not any(c in "ABCDEF" for c in checksum_hex(pad)):
            pad = body + ("," if body.startswith("OSD") else "")
        return frame(pad, lowercase=True)
    if kind == "nock":
        return b"$" + body.encode() + b"\r\n"
    if kind == "shortck":
        return b"$" + body.encode() + b"*" + checksum_hex(body)[:1].encode() + b"\r\n"
    if kind == "longck":  # the right two digits and one more
        return b"$" + body.encode() + b"*" + checksum_hex(body).encode() + b"0\r\n"
    if kind == "hexck":
        return b"$" + body.encode() + b"*GZ\r\n"
    if kind == "twostar":
        b2 = body + "*"
        return b"$" + b2.encode() + b"*" + checksum_hex(b2).encode() + b"\r\n"
    if kind == "unknown":
        return good
    if kind == "lowerid":
        return frame(body.lower())
    if kind in ("exact256", "overlong"):
        want = profile.max_line_bytes + (1 if kind == "overlong" else 0)
        pad = body
        while len(frame(pad)) < want:
            pad += ","
        line = frame(pad)
        if len(line) > want:  # cannot hit the size exactly with commas only (never happens)
            line = line[:want - 2] + b"\r\n"
        return line
    if kind == "noise":
        return b"\x00\xffnoise,junk*7F" + good
    if kind == "torn":
        return b"$" + body.encode() + b"," + frame("OSD,S")
    if kind == "barelf":
        return frame(body, terminator="\n")
    raise ValueError(f"unknown raw line kind {kind!r}")


def zero_padded(body: str, profile: Profile) -> str:
    """``body`` (an ``$OSD`` request) made into one whose checksum is under 0x10, so that it is
    written with a leading zero (RH-FRM-2: "two hex digits, zero-padded"): letters the vehicle
    serves and empty fields are added (RH-RD-7: any number of fields, a repeated letter served
    twice), fewest first. Another body, or none found, is returned as it is."""
    if not body.startswith("OSD"):
        return body
    letters = [c for c in "SGCP" if c in profile.osd_letters] or ["S"]
    tails = [""]
    for _ in range(4):
        for tail in tails:
            if int(checksum_hex(body + tail), 16) < 0x10:
                return body + tail
        tails = [tail + "," + x for tail in tails for x in ["", *letters]]
    return body


# ============================================================================ steps

def _not_reached(session: Session, what: str) -> CaseStop:
    reason = f"{session.case}: {what} (as a conforming vehicle may); the case could not exercise its clause"
    session.tester("inconclusive", session.case_clauses[:1], reason)
    return CaseStop("inconclusive", reason)


def _condition(session: Session, osi: s.OSI, mode: Optional[str], mode_not: Optional[str] = None,
               park_below: Optional[int] = None, submerged: Optional[bool] = None) -> bool:
    ok = True
    if mode is not None and osi.mode not in mode.split("|"):
        ok = False
    if mode_not is not None and osi.mode == mode_not:
        ok = False
    if park_below is not None and not osi.park_time < park_below:
        ok = False
    if submerged is not None:
        under = osi.depth is not None and float(osi.depth) > session.profile.gps_fix_depth_m
        ok = ok and under == submerged
    return ok


def _check_expect(session: Session, sent, text: str) -> None:
    """The case's ``expect`` words must agree with the model (else it is the case's fault)."""
    if not text.startswith("$ACK,") or sent is None or sent.ack is None or sent.reading:
        return  # (an answer under another reading of the profile is the vehicle's own choice)
    want = text[5:].split(",")
    model = next((r for r in sent.expected if isinstance(r, s.ACK)), None)
    if model is None:
        return
    got = [str(model.type), str(model.status), str(model.err)]
    if want[:3] != got:
        reason = (f"{session.case}: the case needs the answer $ACK,{','.join(want[:3])} here, but in the state "
                  f"the vehicle reported a conforming vehicle answers $ACK,{','.join(got)}: the case could not "
                  f"exercise its clause (not a finding about the vehicle)")
        session.tester("inconclusive", session.case_clauses[:1], reason)
        raise CaseStop("inconclusive", reason)


def run_step(session: Session, st, ctx: dict) -> None:
    """Carry out one step of a case."""
    if isinstance(st, Send):
        sent = session.exchange(frame(fill(st.body, ctx)))
        _check_expect(session, sent, st.expect)
    elif isinstance(st, Raw):
        session.exchange(raw_line(st.kind, fill(st.body, ctx), session.profile))
    elif isinstance(st, Poll):
        osi = session.poll()
        _here(session, ctx)
        if not _condition(session, osi, st.mode, st.mode_not, number(st.park_below, ctx), st.submerged):
            if st.submerged is not None:
                raise _not_reached(session, f"the vehicle reports depth {osi.depth} m where the case needs it "
                                            f"{'under water' if st.submerged else 'at the surface'}")
            want = st.mode or (f"not {st.mode_not}" if st.mode_not else f"P below {st.park_below}")
            raise _not_reached(session, f"the vehicle reports {osi.mode} P{osi.park_time} where the case "
                                        f"needs {want}")
    elif isinstance(st, Wait):
        session.wait(number(st.vehicle_s, ctx), frame(fill(st.probe, ctx)) if st.probe else None)
    elif isinstance(st, Settle):
        probe = _claimed_probe(session, st.probe)
        session.settle(st.timer, frame(fill(probe, ctx)) if probe else None, session.case_clauses[0])
        _here(session, ctx)
    elif isinstance(st, Until):
        if st.after_reruns and session.reruns_total == ctx.get("_reruns_confirmed"):
            return  # nothing was made again since the last Until confirmed the state
        _until(session, st, ctx)
        ctx["_reruns_confirmed"] = session.reruns_total
        _here(session, ctx)
    elif isinstance(st, Fault):
        _violation(session, st, ctx)
        ctx["raised"] = True
    elif isinstance(st, Start):
        p = session.profile
        name = getattr(p, st.which) or (p.mission if st.which == "end_mission" else "")
        if st.which == "mission" and session.mission_override:
            name = session.mission_override
        session.start_mission(name, p.srp_mission if st.srp else "", st.ignore_gps)
        _here(session, ctx)
    elif isinstance(st, MissionEnd):
        _mission_end(session, st)
        _here(session, ctx)
    elif isinstance(st, WithSetting):
        _with_setting(session, st, ctx)
    elif isinstance(st, Burst):
        sents = session.burst([frame(fill(b, ctx)) for b in st.bodies])
        for sent, text in zip(sents, st.expect):
            _check_expect(session, sent, text)
    elif isinstance(st, ClearWords):
        _clear_words(session, st, ctx)
    elif isinstance(st, SetRoundTrip):
        _set_round_trip(session, st)
    elif isinstance(st, Quiet):
        session.quiet(st.wall_s, st.reopen)
    elif isinstance(st, Octd):
        if "T" in session.profile.osd_letters:
            session.exchange(frame("OSD,T"))
    else:  # pragma: no cover
        raise TypeError(st)


def _clear_words(session: Session, st: ClearWords, ctx: dict) -> None:
    """Each keyword edge of :func:`.edges.edge_list`: the accepted spellings in ``W``, each followed
    by a report (the queue cleared, the mission resumed: RH-OMW-3, RH-RD-4), then the refused ones."""
    words = [e for e in edge_list(session.profile) if e.command == "OMW" and e.field == "keyword"]
    for e in words:
        if e.side == "in":
            run_step(session, Send(st.queue, expect="$ACK,16,0,0"), ctx)
            run_step(session, Send(f"OMW,{e.probe}", expect="$ACK,16,0,0"), ctx)
            run_step(session, Poll(mode="N|P"), ctx)
    for e in words:
        if e.side == "out":
            run_step(session, Send(f"OMW,{e.probe}", expect="$ACK,16,1,36"), ctx)


def _until(session: Session, st: Until, ctx: dict) -> None:
    fix = session.profile.gps_fix_depth_m
    srp = None if st.srp_active is None else ("True" if st.srp_active else "False")
    at_least = number(st.depth_at_least, ctx)
    park_below = number(st.park_below, ctx)
    # the vehicle's own rule (violation_trigger = mission-rule) trips when it will, whatever the case
    # is doing (a servo dive, a park): once it shows, the case goes on from there (the Fault step)
    rule = (session.profile.trigger == "mission-rule" and "violation" in session.case_needs
            and not ctx.get("raised"))

    def pred(o: s.OSI) -> bool:
        if rule and o.error_state not in ("N", ""):
            ctx["tripped"] = o.error_state
            return True
        flag = o.srp_active if session.profile.protocol == "rh5" else o.battery
        need = None if at_least is None else min(at_least, session.profile.max_depth / 4)
        deep = need is None or (o.depth is not None and float(o.depth) >= need)
        return (deep and _condition(session, o, st.mode, None, park_below, st.submerged)
                and (not st.surface or (o.depth is not None and float(o.depth) <= fix))
                and (srp is None or flag == srp))
    refresh = None
    if st.refresh:
        body = fill(st.refresh, ctx)
        timeout = float(body.rsplit(",", 1)[1])  # a control's timeout is its last field ($OMS, $OMP)
        refresh = (frame(body), timeout / 2)
    session.until(st.what, pred, st.budget_v, session.case_clauses[0], refresh=refresh)


#: Wall seconds the test mission's end is waited for when the profile names no end_mission.
TEST_MISSION_END_WALL_S = 120.0


def _mission_end(session: Session, st: MissionEnd) -> None:
    """Poll until ``S`` (the observer judges the end, RH-MSN-4); a vehicle that reports more time
    left than the cap allows (``$OSI`` field 13, rh5) is not waited for: INCONCLUSIVE at once.
    Without an ``end_mission`` the test mission is waited for when the vehicle reports a time left
    that ends within :data:`TEST_MISSION_END_WALL_S` of wall time; else NOT-TESTED at once (a
    long mission is the profile's to know, not a finding)."""
    name = session.profile.end_mission or session.profile.mission
    fallback = not session.profile.end_mission
    v0 = session.obs.v(session.now())
    cap = min(st.cap_v, TEST_MISSION_END_WALL_S * session.k) if fallback else st.cap_v

    def pred(o: s.OSI) -> bool:
        if o.mode == "S":
            return True
        left = float(o.remaining_time) * 3600.0 if (session.profile.protocol == "rh5" and
                                                     o.remaining_time is not None) else 0.0
        spent = session.obs.v(session.now()) - v0
        if fallback and not left and o.mode in ("N", "P"):
            reason = (f"{session.case}: the profile names no end_mission and the vehicle reports no time left for "
                      f"its test mission {name}: its end cannot be waited for; name a short end_mission")
            session.tester("not-tested", session.case_clauses[:1], reason)
            raise CaseStop("not-tested", reason)
        if left and spent + left > cap:
            if fallback:
                reason = (f"{session.case}: the profile names no end_mission, and the vehicle reports about "
                          f"{left:.0f} s of its test mission {name} left, more than {cap:g} s of vehicle time "
                          f"({TEST_MISSION_END_WALL_S:g} s of wall time at ×{session.k:g}): name a short "
                          f"end_mission to judge RH-MSN-4")
                session.tester("not-tested", session.case_clauses[:1], reason)
                raise CaseStop("not-tested", reason)
            reason = (f"{session.case}: the vehicle reports about {left:.0f} s of {name} left {spent:.0f} s after "
                      f"its start, past the cap of {st.cap_v:g} s; a shorter end_mission would be judged")
            session.tester("inconclusive", session.case_clauses[:1], reason)
            raise CaseStop("inconclusive", reason)
        return False
    session.until(f"the end of {name} (S)", pred, cap, session.case_clauses[0])


def _with_setting(session: Session, st: WithSetting, ctx: dict) -> None:
    """Read ``setting`` in ``S``, write it, run the steps; always write back what was read."""
    read = session.exchange(frame(f"ORWSET,{st.setting},R"))
    if read is None or not read.accepted or len(read.ack.extra) < 3:
        raise _not_reached(session, f"reading {st.setting} in S gave no value to restore afterwards")
    orig = list(read.ack.extra[2:])
    w = session.exchange(frame(f"ORWSET,{st.setting},W,1,{st.value}"))
    if w is None or not w.accepted:
        raise _not_reached(session, f"writing {st.setting} = {st.value} in S was refused")
    try:
        for sub in st.steps:
            run_step(session, sub, ctx)
    finally:
        _restore(session, st.setting, orig)


def _restore(session: Session, setting: str, orig: list) -> None:
    """Stop the mission (verified reset) and write ``orig`` back; verified by a read."""
    with session.not_stopping():
        session.reset(mission=False)
        session.exchange(frame(f"ORWSET,{setting},W,{','.join(orig)}"))
        back = session.exchange(frame(f"ORWSET,{setting},R"))
        if back is None or back.ack is None or list(back.ack.extra[2:]) != orig:
            session.note(f"restore: {setting} could not be verified as {','.join(orig)}")


def _set_round_trip(session: Session, st: SetRoundTrip) -> None:
    """RH-SET-2: read, write a changed state and value, read back (the observer compares);
    the original is always written back."""
    read = session.exchange(frame(f"ORWSET,{st.setting},R"))
    if read is None or not read.accepted or len(read.ack.extra) < 3:
        raise _not_reached(session, f"reading {st.setting} gave no value to restore afterwards")
    orig = list(read.ack.extra[2:])
    new_state = "0" if orig[0] == "1" else "1"
    try:
        session.exchange(frame(f"ORWSET,{st.setting},W,{new_state},7"))
        session.exchange(frame(f"ORWSET,{st.setting},R"))
    finally:
        with session.not_stopping():
            session.exchange(frame(f"ORWSET,{st.setting},W,{','.join(orig)}"))


#: Wall seconds an operator gets to trip a sensor once told (``violation_trigger = "operator"``).
OPERATOR_WAIT_S = 120.0


def _violation(session: Session, st: Fault, ctx: dict) -> None:
    """RH-SAF-5: raise a safety violation the way the profile says (``violation_trigger``).

    ``oxflt``: send ``$OXFLT,<code>`` (no ACK). ``mission-rule``: the case runs the profile's
    ``violation_mission``; wait until ``$OSI`` field 8 shows a code, at most ``violation_after_s``
    after the mission's start plus a quarter of it (at least 10 s) for the rule's own timing.
    ``operator``: tell the person at the terminal to trip a sensor now and wait for the code, at
    most :data:`OPERATOR_WAIT_S` of wall time. The observer adopts the violation wherever it falls
    between two reports; the code shown need not be ``st.code``.
    """
    p = session.profile
    trig = p.trigger
    then = [frame(fill(body, ctx)) for body in st.then]
    if trig == "oxflt" or "oxflt" in session.case_needs:
        # with a line after it in the same write: its answer bounds when the violation began
        # (the judge's window), whatever the vehicle's latency
        session.burst([frame(f"OXFLT,{st.code}"), *(then or [frame("OSD,S")])])
        return
    _raised(session, st, trig)
    if then:
        session.burst(then)


def _raised(session: Session, st: Fault, trig: str) -> None:
    """Wait for a violation the vehicle raises itself (``mission-rule``, ``operator``)."""
    p = session.profile
    shown = lambda o: o.error_state not in ("N", "")  # noqa: E731
    if trig == "mission-rule":
        started = session.mission_started_at if session.mission_started_at is not None else session.now()
        elapsed_v = (session.now() - started) * session.k
        budget_v = max(0.0, p.violation_after_s - elapsed_v) + max(10.0, 0.25 * p.violation_after_s)
        session.until(f"the safety code of {p.violation_mission}'s own rule (violation_after_s = "
                      f"{p.violation_after_s:g} s after its start)", shown, budget_v, session.case_clauses[0])
        return
    if trig == "operator":
        if session.operator is None:  # run_case checks first; kept for exploration and replays
            raise CaseStop("not-tested", "violation_trigger = \"operator\" and nobody at a terminal")
        session.operator(f"{session.case}: trip a safety sensor on the vehicle NOW (e.g. the leak sensor). "
                         f"helmcheck waits up to {OPERATOR_WAIT_S:.0f} s for $OSI field 8 to show its code.")
        osi = session.until("the safety code of the sensor the operator trips", shown,
                            OPERATOR_WAIT_S * session.k, session.case_clauses[0])
        session.operator(f"{session.case}: seen {osi.error_state} — thank you; leave the vehicle alone now.")
        return
    raise CaseStop("not-tested", "the profile declares no way to raise a safety violation")


# ============================================================================ cases

def run_case(session: Session, case: Case) -> tuple[str, str]:
    """Run one case: its outcome for the report's case list, and why."""
    why = unmet_need(case, session.profile, session.durations(fresh=True))
    if why:
        session.tester("not-tested", case.clauses, f"{case.id}: {why}")
        return "not-tested", why
    if "violation" in case.needs and session.profile.trigger == "operator" and session.operator is None:
        why = ("violation_trigger = \"operator\" needs a person at a terminal to trip a sensor when told, "
               "and helmcheck runs without one (standard input and error are not a terminal)")
        session.tester("not-tested", case.clauses, f"{case.id}: {why}")
        return "not-tested", why
    session.begin_case(case.id, case.clauses, case.title)
    rule = "violation" in case.needs and session.profile.trigger == "mission-rule"
    session.mission_override = session.profile.violation_mission if rule else None
    session.case_needs = case.needs
    try:
        session.reset(mission=case.start in ("N", "P"), park=case.start == "P")
        ctx = context(session)
        for st in case.steps:
            try:
                run_step(session, st, ctx)
            except BenchSafetyRefused as e:
                session.tester("not-tested", case.clauses[:1],
                               f"{case.id}: a step was not sent: {e} — the clause is not exercised by it")
        got = session.failures()
        if got:
            return "fail", f"{got[0][0]}: {got[0][1]}"
        return "done", f"{case.id}: {case.title.lower()} — ran to the end; the clause verdicts are the observer's"
    except CaseStop as e:
        return e.outcome, e.reason
    finally:
        session.mission_override = None
        session.case_needs = ()
        session.end_case()
