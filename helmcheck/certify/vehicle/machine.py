"""The exploration's state machine: its rules and episodes (:func:`machine`).

The rules draw from :mod:`.generate` and walk the model's map (:mod:`.explore` says how, and
what a sequence starts and ends with): single commands by family, the four remote controls,
lines the vehicle must read as written, refuse or discard, bursts, protocol time passing, a
report landed just before a model timer's deadline and polled across it, the mission park, and
the episodes — a control interrupted and released, the mission park interrupted, a control
bracketed at its timeout (refreshed halfway when drawn), a whole safety episode. Preconditions
read only what the sequence has sent, never the live vehicle, so hypothesis draws the same data
when it replays one; a rule whose state the vehicle is not in does nothing. The session counts
every line's model coverage (:mod:`.modelcover`).
"""

from __future__ import annotations

from typing import Optional

from hypothesis import strategies as st
from hypothesis.stateful import RuleBasedStateMachine, initialize, precondition, rule

from ...model.timers import tolerance
from ...judge.vehicle.blame import GENERIC
from .flow import CaseStop, LinkLost
from .generate import (EXPLORE_WRITES, bench_motor, bench_speed, commands, control_commands, invalid_lines,
                       one_field_off)
from .interpreter import _here, context, fill, raw_line
from .safety import BenchSafetyRefused
from .session import frame
from .steps import SetRoundTrip
from .tour import PARK_WITHIN_V, _reach_park, aimed

__all__ = ["machine", "VehicleFailure", "HORIZON_V", "PARK_WITHIN_V", "QUEUE_WITHIN_V"]


def _raw(kind: str, body: str, profile) -> bytes:
    """The line of one drawn mutation: a framed body as it is, or :func:`.interpreter.raw_line`'s."""
    return frame(body) if kind == "frame" else raw_line(kind, body, profile)


class VehicleFailure(AssertionError):
    """An example failed: the observer booked a failure about the vehicle (the reason)."""


#: Vehicle seconds ahead within which a timer's deadline is waited for (:meth:`boundary`).
HORIZON_V = 25.0
#: The longest a sequence follows its queue of waypoints (:meth:`queue`).
QUEUE_WITHIN_V = 120.0


#: Commands that may set a timer going (a remote control's timeout, a park, RH-RD-15).
_ARMING = frozenset({"OMS", "OMP", "OPK", "OMW", "ODVL", "OJW", "OMSTART"})


def machine(state, p, tos, deep: bool = True, aim: Optional[list] = None):
    """The ``RuleBasedStateMachine`` class of one exploration: ``state`` is shared by its
    instances (the exploration's budget, counts, coverage and smallest failure). ``deep=False``:
    the rules that wait for protocol time (timers, parks, the lockout) are off and the mission
    park is no start — cheap sequences, many lines each, for the one-step paths of the model
    (every command and error code in ``S`` and ``N``, every mutation of a line)."""
    session = state.run.session
    cov = state.coverage
    obs = session.obs
    speed, motor = bench_speed(p), bench_motor(p)
    oxflt = p.fault_injection == "oxflt"
    claimed = set(p.commands)
    short = st.sampled_from(list(tos.elements)[:2]) if hasattr(tos, "elements") else tos  # episodes wait these out
    # a steer that lasts (:meth:`steer_then_read`)
    hi_to = max(tos.elements) if hasattr(tos, "elements") else int(p.timeout_range[1])

    def send(raw: bytes):
        """One line, exchanged (the session counts its model coverage)."""
        return session.exchange(raw)

    def mode() -> str:
        return obs.state().mode

    class Base(RuleBasedStateMachine):
        def __init__(self):
            super().__init__()
            self.active = not state.batch_spent
            self.ctx: dict = {}
            self.failed = False
            # what this example has sent, for the preconditions: they read only the machine's own
            # record, never the live vehicle, so hypothesis draws the same data when it replays
            # (the rules themselves look at the vehicle and do nothing where it is elsewhere)
            self.mission = False
            self.timed = False
            self.faults = 0
            self.wrote: set = set()  #: settings written (put back at the end: :meth:`_put_back`)
            if self.active:
                state.executions += 1
                if state.progress is not None:
                    try:
                        state.show_progress()
                    except Exception as e:  # noqa: BLE001 - a tester error: kept, raised by explore()
                        state.tester_error(e)
                        self.active = False
            elif state.spent:  # not a shrink candidate past its batch's cap (explore.SHRINK_SHARE)
                state.skipped += 1

        def _guard(self, fn):
            if not self.active or state.batch_spent:  # the budget ends the sequence here too
                return
            try:
                state.steps += 1
                fn()
                session.check()
                state.show_progress()
            except CaseStop as f:
                if f.outcome == "fail":
                    self._failed(f)
                    raise VehicleFailure(f.reason) from None
                return
            except BenchSafetyRefused:
                return
            except LinkLost as e:
                state.lost = str(e)
                self.active = False
            except Exception as e:  # noqa: BLE001 - a tester error: kept, raised by explore()
                state.tester_error(e)
                self.active = False

        def _failed(self, f: CaseStop) -> None:
            self.failed = True
            state.failures += 1
            trace = list(session.trace or [])
            cid = f.clause or f.reason.split(":", 1)[0]
            # the clauses the same observation was booked on (the generic RH-OUT-4 and the cause
            # it names, blame.targets): the finding is the specific one's, and all go together
            said = f.reason.split(": ", 1)[-1]
            also = tuple(dict.fromkeys([cid] + [c for c, r in session.failures() if r == said]))
            cid = next((c for c in also if c not in GENERIC), cid)
            best = state.found.get(cid)
            if best is None or len(trace) < len(best["steps"]):
                state.found[cid] = {"clause": cid, "also": also, "reason": f.reason, "steps": trace,
                                    "origin": session.trace_origin}
            state.shrink_from()

        @initialize(start=st.sampled_from(["S", "S", "S", "N", "N", "N", "N", "P"]))
        def start(self, start):
            """From a verified reset: the replay of a failure begins here (:mod:`.replay`)."""
            if start == "P" and not deep:
                start = "N"
            if aim is not None:  # an aimed tour takes its own ways from S (:mod:`.tour`)
                start = "S"
            self.mission = start != "S"
            self.timed = start == "P"
            if not self.active:
                return
            # the verified reset, not recorded: a replay begins with one of its own (.replay); what
            # the vehicle does wrong in it was set going before this sequence (whose closing reset
            # finds it, unless that sequence had already failed): it is no finding of this one
            before = session.ledger.mark()
            try:
                with session.not_stopping():
                    # a lockout the mirror still counts (the vehicle's ended sooner: a finding of
                    # the sequence that raised it) is waited out, so this one starts from the same
                    # state on any vehicle
                    session.outwait_lockout()
                    session.reset(mission=False)
                    session.outwait_surface()  # a dive or safety episode before: the GPS fix back (RH-POS-2)
                    cust = session.custodian  # the settings as the run found them (a failed sequence left its own)
                    for rec in (cust.records.values() if cust is not None else ()):
                        if rec.written and rec.before is not None:
                            session.exchange(frame(f"ORWSET,{rec.name},W,{','.join(rec.before)}"))
            except CaseStop:
                pass
            except LinkLost as e:
                state.lost = str(e)
                self.active = False
                return
            # a clause the reset already shows violated is carried over from an earlier sequence
            # (whose own closing reset found it): this one does not stop at it, its replay could
            # not show it on a fresh vehicle
            session.ignore = state.ignored | {c for c, _ in session.ledger.failures_since(before)}
            session.trace, session.trace_origin = [], None

            def go():
                session.mark = session.ledger.mark()
                self.ctx = context(session)  # a rule after a failed start still has its fields
                # the steps' positions are relative to here (a replay moves them: .relocate)
                session.trace_origin = (float(self.ctx["lat"]), float(self.ctx["lon"]))
                if "OLOGL" in claimed:
                    send(frame("OLOGL,a,b"))
                if "OMLOAD" in claimed:
                    send(frame(f"OMLOAD,{p.mission},0"))
                if "OPOS" in claimed:  # conductivity and temperature (always applied, RH-POS-2) outlive a reset
                    send(frame(fill("OPOS,{lat},{lon},0,35,12", self.ctx)))
                if start in ("N", "P"):
                    send(frame(f"OMSTART,0,0,0,0,{p.mission},"))
                    session.poll()
                if start == "P":
                    _reach_park(session, self.ctx)
                self.ctx = context(session)
            self._guard(go)

        def _sent(self, body: str) -> None:
            if body.startswith("ORWSET,") and ",W," in body:
                self.wrote.add(body.split(",")[1])
            self.mission = self.mission or body.startswith("OMSTART")
            self.timed = self.timed or body.startswith(("OMS,", "OMP,", "OPK,", "OMW,", "ODVL,"))

        def _command(self, body):
            self._sent(body)
            self._guard(lambda: send(frame(fill(body, self.ctx))))

        def _put_back(self) -> None:
            """The settings this sequence wrote, written back as the run found them: a setting outlives
            the verified reset, and the next sequence (and a replay, on a fresh vehicle) must not
            depend on this one."""
            cust = session.custodian
            if cust is None:
                return
            for rec in cust.records.values():
                if rec.name in self.wrote and rec.before is not None:
                    send(frame(f"ORWSET,{rec.name},W,{','.join(rec.before)}"))

        def teardown(self):
            """Back to a verified reset inside the example, so that whatever the example set going (a
            lockout, a park, a timer, a setting) is judged within it and its replay holds all of it."""
            try:
                if self.active and not self.failed and not state.batch_spent:
                    self._guard(lambda: (session.finish(), session.reset(mission=False), self._put_back()))
            finally:
                session.trace = None

    if aim is not None:
        return aimed(Base, state, p, aim)

    class VehicleMachine(Base):
        @rule(body=commands(p, tos, "motion"))
        def motion(self, body):
            self._command(body)

        @rule(body=commands(p, tos, "navigation"))
        def navigation(self, body):
            self._command(body)

        @rule(body=commands(p, tos, "mission"))
        def mission_command(self, body):
            self._command(body)

        @rule(body=commands(p, tos, "data"))
        def data(self, body):
            self._command(body)

        @rule(body=control_commands(speed, motor, tos))
        def control(self, body):
            self._command(body)

        def _line(self, line) -> None:
            kind, body = line
            state.lines_sent.add(kind)  # the aim sends the kinds not sent yet (:mod:`.aim`)
            self._guard(lambda: send(_raw(kind, fill(body, self.ctx), p)))

        @rule(line=invalid_lines("framing"))
        def framing(self, line):
            """A line the vehicle must read as written or discard (§1: RH-FRM-2..7)."""
            self._line(line)

        @rule(line=invalid_lines("refused"))
        def refused(self, line):
            """A well-framed line the vehicle must refuse, or discard for its ID (RH-ACK-3, RH-FRM-5)."""
            self._line(line)

        @rule(bodies=st.lists(st.one_of(commands(p, tos), control_commands(speed, motor, tos)), min_size=2,
                              max_size=3))
        def burst(self, bodies):
            """Lines written back to back before any answer is read (RH-ACK-6)."""
            for b in bodies:
                self._sent(b)

            self._guard(lambda: self._together(bodies))

        def _together(self, bodies) -> None:
            """Write the lines back to back, then read the answers (RH-ACK-6), coverage counted. A
            command that may set a timer going goes first: behind another command's data its ACK
            would wait on a paced line, and when it took effect (RH-RD-15) would be known only
            within their transmit time — at a high time scale too widely to time what it started
            (an observation the exploration must not book)."""
            bodies = sorted(bodies, key=lambda b: 0 if b.split(",", 1)[0] in _ARMING else 1)
            session.burst([frame(fill(b, self.ctx)) for b in bodies])

        @rule(bodies=st.lists(one_field_off(p, tos), min_size=2, max_size=6), together=st.booleans(),
              stopped=st.booleans())
        def edges(self, bodies, together, stopped):
            """Lines with one field at an edge of its range or one past it, the others inside (§4–6,
            RH-RD-9): one by one, each ``$OPOS`` between two reports (RH-POS-2: a position applied
            or not shows at once), or written back to back (RH-ACK-6: a slow command first).
            ``stopped``: after an ``$OMSTOP,0`` (RH-MSN-3: mode ``S``), where the commands accepted
            only in ``S`` (RH-MSN-1/2) are refused for their fields alone — in another mode the
            refusal for the mode hides a vehicle that accepts a name it must refuse."""
            if stopped and "OMSTOP" in claimed:
                bodies = ["OMSTOP,0"] + list(bodies)
            for b in bodies:
                self._sent(b)

            def go():
                if together:
                    self._together(bodies)
                    return
                for b in bodies:
                    if b.startswith("OPOS,"):
                        session.poll()
                    send(frame(fill(b, self.ctx)))
                    if b.startswith("OPOS,"):
                        session.poll()
                _here(session, self.ctx)
            self._guard(go)

        @precondition(lambda self: deep)  # it waits for the turn
        @rule(heading=st.sampled_from(["359.9", "359", "0", "1", "180", "350"]),
              letters=st.permutations(list(p.osd_letters or "S")))
        def steer_then_read(self, heading, letters):
            """In a running mission: steer to a heading at the wrap of the compass (or south), wait
            until the vehicle reports it, then ask for every letter (RH-OUT-3: every heading the data
            sentences show, true and magnetic, is within [0, 360))."""
            def go():
                if "OMS" not in claimed or mode() not in ("N", "P", "A"):
                    return
                send(frame(f"OMS,{heading},0,20,{min(speed, 1.0):g},{hi_to}"))
                end = session.now() + HORIZON_V / session.k
                while session.now() < end:
                    osi = session.poll()
                    if osi is None or osi.true_heading is None:  # not shown: read after a while
                        session.wait(5.0)
                        break
                    off = abs((float(osi.true_heading) - float(heading) + 180.0) % 360.0 - 180.0)
                    if osi.mode != "A" or off <= 2.0:
                        break
                    session.link.sleep(max(session.poll_gap, 0.05))
                send(frame("OSD," + ",".join(letters)))
                _here(session, self.ctx)
            self._guard(go)

        @precondition(lambda self: deep)
        @rule(v=st.sampled_from([0.5, 1.0, 2.0, 5.0]))
        def wait_a_while(self, v):
            def go():
                session.wait(v)
                _here(session, self.ctx)
            self._guard(go)

        @rule()
        def poll(self):
            self._guard(lambda: (session.poll(), _here(session, self.ctx)))

        @precondition(lambda self: deep and self.timed)
        @rule(side=st.sampled_from(["before", "after", "after"]))
        def boundary(self, side):
            """Land a report just before the next model timer's deadline, or poll across it until the
            vehicle has left the state (RH-TIM-1's brackets). Timers due past :data:`HORIZON_V` are
            left alone: waiting for them would spend the budget on one sequence."""
            def go():
                got = obs.state().timer()
                if got is None:
                    return
                due_v, dur, name = got
                due_wall = due_v / session.k
                if (due_wall - session.now()) * session.k > HORIZON_V:
                    return
                tol_wall = (tolerance(dur) + session.k * 2 * session.poll_gap) / session.k
                # the lockout's end shows in no report: a command only the lockout refuses shows it
                probe = None
                if name == "lockout":
                    probe = next((frame(b) for b in ("ORWSET,Sle,R", "OLOGL,probe") if b[:b.index(",")]
                                  in claimed), None)
                if side == "before":
                    before = due_wall - 2 * tol_wall - session.poll_gap
                    if before > session.now():
                        session.wait((before - session.now()) * session.k)
                        if obs.state().timer(name) is not None:
                            if probe is not None:
                                send(probe)
                            cov.boundary(name, "before")
                else:
                    session.settle(name, probe)
                    cov.boundary(name, "after")
                _here(session, self.ctx)
            self._guard(go)

        # ---------------------------------------------------------------- episodes
        # the model's deeper paths, one draw each: a control interrupted and released, a timer
        # bracketed, a safety episode with commands inside the lockout and the ascent

        def _settle_next(self, name: Optional[str] = None) -> None:
            got = obs.state().timer(name)
            if got is not None and (got[0] / session.k - session.now()) * session.k <= HORIZON_V:
                session.settle(got[2])
                cov.boundary(got[2], "after")
                _here(session, self.ctx)

        @precondition(lambda self: deep and self.mission)
        @rule(first=control_commands(speed, motor, short), then=st.one_of(control_commands(speed, motor, short),
                                                                       st.sampled_from(["OJW,{wp_other}",
                                                                                        "OMW,Clr", "OMSTOP,0"])),
              release=st.booleans())
        def interrupt(self, first, then, release):
            """A control (or the mission park) interrupted by another command, then — when drawn —
            the interrupting control let run out (RH-INT-1..3, RH-OMW-5, RH-JW-2, RH-MSN-3)."""
            self.timed = True

            def go():
                send(frame(fill(first, self.ctx)))
                session.poll()
                _here(session, self.ctx)
                send(frame(fill(then, self.ctx)))
                session.poll()
                if release:
                    self._settle_next("remote")
            self._guard(go)

        @precondition(lambda self: deep and self.mission and "OPK" in claimed)
        @rule(then=st.builds(lambda kind, t: kind.format(t=t), st.sampled_from(
                  [f"OMS,90,2,20,{min(speed, 1.0):g},{{t}}", f"OMP,80808080{motor:02X},00,{{t}}"]), short),
              minutes=st.sampled_from(["1", "2"]))
        def park_interrupted(self, then, minutes):
            """A ``$OPK`` park interrupted by another control, which is let run out: the park is
            abandoned, the mission resumes (RH-INT-3, RH-INT-2)."""
            self.timed = True

            def go():
                if mode() not in ("N", "P"):
                    return
                send(frame(fill(f"OPK,{{stn_lat}},{{lon}},{minutes},{speed:g}", self.ctx)))
                session.poll()
                if mode() != "mP":
                    return
                send(frame(fill(then, self.ctx)))
                session.poll()
                self._settle_next("remote")
                session.poll()
                _here(session, self.ctx)
            self._guard(go)

        @precondition(lambda self: deep and self.mission)
        @rule(then=st.one_of(control_commands(speed, motor, short), st.sampled_from(["OJW,{wp_other}", "OMW,Clr"])))
        def interrupt_park(self, then):
            """The mission park interrupted, the interruption let run out (RH-INT-2, RH-PK-3)."""
            self.timed = True

            def go():
                if mode() == "N":
                    _reach_park(session, self.ctx)
                if mode() != "P":
                    return
                send(frame(fill(then, self.ctx)))
                session.poll()
                self._settle_next()
            self._guard(go)

        @precondition(lambda self: deep)
        @rule(body=control_commands(speed, motor, short), refresh=st.booleans())
        def timed_control(self, body, refresh):
            """A control bracketed at its timeout; ``refresh``: the same control sent again halfway,
            which must restart its timeout (RH-SRV-3/4, RH-PRM-4, RH-TIM-1)."""
            self.timed = True

            def go():
                send(frame(fill(body, self.ctx)))
                got = obs.state().timer()
                if refresh and got is not None:
                    session.wait(max(0.0, (got[0] / session.k - session.now()) * session.k / 2))
                    send(frame(fill(body, self.ctx)))
                self._settle_next()
            self._guard(go)

        @precondition(lambda self: deep and self.mission and "OMW" in claimed)
        @rule(parks=st.lists(st.sampled_from(["0", "0", "{qpark}"]), min_size=1, max_size=3),
              then=st.sampled_from(["", "", "OMW,Clr", "OMS", "OJW,{wp_other}"]))
        def queue(self, parks, then):
            """A queue of waypoints 15 m apart (RH-OMW-2): followed to its end (RH-OMW-4, a park on a
            waypoint when drawn), or interrupted and released on the way (RH-OMW-5)."""
            self.timed = True

            def go():
                for i, park in enumerate(parks):
                    lat = float(self.ctx["lat"]) + 15.0 * (i + 1) / 111320.0
                    send(frame(fill(f"OMW,{lat:.6f},{{lon}},2,,15,{speed:g},{park},", self.ctx)))  # park: a template
                session.poll()
                if then:
                    body = fill("OMS,90,2,20,0,{to}" if then == "OMS" else then, self.ctx)
                    send(frame(body))
                    self._settle_next()
                end = session.now() + QUEUE_WITHIN_V / session.k
                while session.now() < end and mode() == "W":
                    session.poll()
                    session.link.sleep(max(session.poll_gap, 0.05))
                _here(session, self.ctx)
            self._guard(go)

        @precondition(lambda self: deep and oxflt and self.faults == 0)
        @rule(code=st.sampled_from(["Sle", "Sop", "Sed"]), inside=commands(p, tos, "motion"),
              after=st.one_of(control_commands(speed, motor, tos), commands(p, tos, "navigation")),
              dive=st.booleans())
        def safety(self, code, inside, after, dive):
            """A whole safety episode (RH-SAF-1..4): optionally dive first, the violation, a command
            inside the lockout, the lockout's end bracketed with a probe, a command in the ascent,
            then the surface."""
            self.faults += 1
            self.timed = True

            def go():
                if obs.state().phase != "none":
                    return
                if dive and mode() in ("N", "P"):
                    send(frame(fill("OMS,90,{dive_depth},20,{speed},120", self.ctx)))
                    session.wait(10.0)
                session.burst([frame(f"OXFLT,{code}"), frame("OSD,S")])  # its answer bounds the violation
                send(frame(fill(inside, self.ctx)))
                probe = next((frame(b) for b in ("ORWSET,Sle,R", "OLOGL,probe") if b[:b.index(",")] in claimed),
                             None)
                if probe is not None:
                    send(probe)
                got = obs.state().timer("lockout")
                if got is None:
                    return
                session.settle("lockout", probe)
                cov.boundary("lockout", "after")
                send(frame(fill(after, self.ctx)))
                session.poll()
                _here(session, self.ctx)
            self._guard(go)

        @precondition(lambda self: deep and self.mission)
        @rule()
        def mission_park(self):
            """Get the running mission to its park (then the other rules interrupt it)."""
            self.timed = True

            def go():
                if mode() == "N":
                    _reach_park(session, self.ctx)
            self._guard(go)

        @precondition(lambda self: not self.mission and "ORWSET" in claimed)
        @rule(setting=st.sampled_from(EXPLORE_WRITES))
        def write_then_read(self, setting):
            """RH-SET-2: write a changed state and value, read it back; the original written back."""
            from .interpreter import run_step
            self.wrote.add(setting)
            self._guard(lambda: run_step(session, SetRoundTrip(setting), self.ctx) if mode() == "S" else None)

        @precondition(lambda self: deep and oxflt and self.faults == 0)
        @rule(code=st.sampled_from(["Sle", "Sop", "Sed"]))
        def fault(self, code):
            """A safety violation (RH-SAF-5): one per sequence; the lockout and the ascent follow."""
            self.faults += 1
            self.timed = True
            self._guard(lambda: session.exchange(frame(f"OXFLT,{code}")) if obs.state().phase == "none" else None)

    return VehicleMachine
