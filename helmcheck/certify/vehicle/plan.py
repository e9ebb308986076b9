"""``certify vehicle --plan``: how long a certification will take, before it starts.

:func:`estimate` runs the very cases a certification runs — the same catalogue, interpreter,
session, tester link, vehicle observer and custodian (:mod:`.restore`) — against the reference
vehicle (the emulator's sans-IO core, in-process) over a line in virtual time (:mod:`.virtual`).
Every case's estimate therefore comes from the steps that really run: the protocol durations it
waits out (vehicle seconds ÷ k), its polls and exchanges at the line's baud, and the ACK windows
the tester sits out for lines the vehicle must discard (wall time, never scaled). No port is
opened, nothing is written and no real time passes waiting. The lines follow the runner's
phases: the link check (with the settings survey of a vehicle found stopped), the cases, the
exploration, the restore.

What it cannot run in virtual time is the hypothesis exploration: it stops on its budget, in wall
seconds and in vehicle seconds (whichever ends first: on a vehicle at ×1 the forced waits bind),
so the plan shows that budget as its own line (it ends sooner when its examples are done).
A profile whose safety violations an operator raises (``violation_trigger = "operator"``) is
planned with someone at the terminal who trips the sensor :data:`OPERATOR_REACTION_S` after
being told.

The estimate assumes the vehicle behaves like the reference model and answers each line
``latency_s`` after its last byte (``--latency``, default :data:`~helmcheck.judge.linebudget.ASSUMED_LATENCY_S`):
a vehicle that answers more slowly, runs a longer mission or surfaces more slowly takes longer.
The line budget the run measures at its link check is here that assumption
(:mod:`helmcheck.judge.linebudget`): the durations the cases choose follow from it, and a case no
allowed duration lets the observer time on that line at that time scale is "not run", with the
time scale or baud that would let it run. It uses the profile's
missions from ``--missions DIR`` when given, else the emulator's built-in ones; a profile mission
found in neither is stood in for by the built-in mission of the same role, and the plan says so.

:class:`Plan` holds the lines; :func:`render_text` and :func:`as_json` present it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Optional

from ...clauses import vehicle_clauses
from ...failures import Failure
from ...grammar.wirelog import BITS_PER_BYTE
from ...judge import Ledger
from ...judge.vehicle import VehicleObserver
from ...model.missions import Mission, MissingMission, normalise_name
from ...profile import Profile
from ...line.recorder import Recorder
from .catalogue import select_cases
from .explore import PROFILES as EXPLORE_PROFILES
from .flow import LinkLost
from .interpreter import OPERATOR_WAIT_S, run_case
from .link import TesterLink
from .restore import Custodian, written_settings
from ...judge.linebudget import ASSUMED_LATENCY_S, NOMINAL_WIDENING_S, from_settings
from .session import Session, frame
from .virtual import VirtualLine

__all__ = ["Plan", "PlanLine", "estimate", "render_text", "as_json", "PlanError", "OPERATOR_REACTION_S"]

#: Which built-in mission stands in for each mission the profile names (``violation_mission``
#: with the profile's ``violation_after_s`` as its Maximum Operation Time).
STAND_INS = (("mission", "conformance.mis"), ("end_mission", "short.mis"), ("srp_mission", "srp.mis"),
             ("violation_mission", "conformance.mis"))
#: Wall seconds the plan gives an operator, once told, to trip a sensor (``violation_trigger =
#: "operator"``); the run itself waits up to :data:`.interpreter.OPERATOR_WAIT_S`.
OPERATOR_REACTION_S = 10.0
#: The sensor the operator trips in the plan (the emulator's leak sensor, as SIGUSR1 trips it).
OPERATOR_CODE = "Sle"


class PlanError(Failure):
    """The reference vehicle could not be driven through the plan (a tester fault: exit 2)."""


@dataclass
class PlanLine:
    """One line of the plan: the link check, a case, or the exploration."""

    id: str
    kind: str  #: ``setup``, ``case`` or ``exploration``
    title: str
    wall_s: float
    vehicle_s: float
    wait_s: float = 0.0  #: wall seconds of it spent waiting out protocol durations
    clauses: tuple = ()
    outcome: str = "ran"  #: ``ran``, ``not-run`` (the profile does not let it), ``stopped``, ``budget``
    note: str = ""

    def as_dict(self) -> dict:
        return {"id": self.id, "kind": self.kind, "clauses": list(self.clauses), "title": self.title,
                "vehicle_s": self.vehicle_s, "wall_s": self.wall_s, "protocol_wait_s": self.wait_s,
                "outcome": self.outcome, "note": self.note}


@dataclass
class Plan:
    profile: str
    protocol: str
    time_scale: float
    baud: int
    select: list
    lines: list[PlanLine] = field(default_factory=list)
    missions: dict = field(default_factory=dict)
    assumptions: list[str] = field(default_factory=list)
    latency_s: float = ASSUMED_LATENCY_S
    line: dict = field(default_factory=dict)  #: the line budget (``LineBudget.as_dict``)
    durations: dict = field(default_factory=dict)  #: the durations chosen from it (``Durations.context``)
    verdicts: dict = field(default_factory=dict)  #: clause → the judge's verdict on the planned vehicle
    #: the range edges the planned cases reach on the reference vehicle (:meth:`.edges.EdgeTally.summary`)
    edges: dict = field(default_factory=dict)
    #: edge id → the case that reached it first on the reference vehicle
    edge_cases: dict = field(default_factory=dict)

    @property
    def total_wall_s(self) -> float:
        return round(sum(x.wall_s for x in self.lines), 3)

    @property
    def total_vehicle_s(self) -> float:
        return round(sum(x.vehicle_s for x in self.lines), 3)

    @property
    def wait_s(self) -> float:
        return round(sum(x.wait_s for x in self.lines), 3)


# ============================================================================ missions

class _PlanCatalog:
    """The missions the estimate runs: ``--missions DIR`` first, then the built-in ones; a
    mission the profile names and neither holds is stood in for (:data:`STAND_INS`)."""

    def __init__(self, profile: Profile, missions_dir: Optional[Path]):
        from ...emulator.missionfile import DirectoryCatalog, builtin_dir
        self.dirs = ([missions_dir] if missions_dir is not None else []) + [builtin_dir()]
        self.inner = DirectoryCatalog(self.dirs)
        builtin = DirectoryCatalog([builtin_dir()])
        self.stand_ins: dict[str, str] = {}  #: the profile's name -> the built-in file standing in
        self._missions: dict[str, Mission] = {}
        for key, default in STAND_INS:
            name = getattr(profile, key, "")
            if not name or not isinstance(self.inner.lookup(name), MissingMission):
                continue
            found = builtin.lookup(default)
            if isinstance(found, Mission):
                limit = profile.violation_after_s if key == "violation_mission" else found.max_time_s
                self.stand_ins[name] = default + (f" (max_time_s {limit:g})" if limit else "")
                self._missions[normalise_name(name)] = Mission(name, found.waypoints, max_time_s=limit or None)

    def lookup(self, name: str):
        found = self.inner.lookup(name)
        if isinstance(found, MissingMission) and isinstance(name, str):
            return self._missions.get(normalise_name(name), found)
        return found


# ============================================================================ the estimate

def estimate(profile: Profile, time_scale: float, *, select: Optional[list] = None,
             examples: Optional[int] = None, hypothesis_profile: str = "fast",
             missions_dir: Optional[Path] = None, latency_s: float = ASSUMED_LATENCY_S,
             vehicle=None) -> Plan:
    """Time the run's phases at ``time_scale`` (module docstring): the link check, the selected
    cases, the exploration's budget and the restore, in the runner's order. ``vehicle``: the
    reference vehicle's freedoms (an :class:`~helmcheck.emulator.freedoms.EmulatorSettings`), or a
    callable ``(profile, catalog, k) -> core`` that makes another vehicle: the suite runs the cases
    on vehicles that choose otherwise, and on faulty ones, over lines in virtual time (``latency_s``
    may then be a callable that draws each line's delay); :attr:`Plan.verdicts` holds what the
    judge made of them."""
    from ...emulator.core import EmulatorCore

    k = float(time_scale)
    profile = profile.replace(time_scale=k)
    catalog = _PlanCatalog(profile, missions_dir)
    if callable(vehicle):
        core = vehicle(profile, catalog, k)
    else:
        core = EmulatorCore(profile, catalog, start=0.0, time_scale=k, baud=profile.baud, settings=vehicle)
    line = VirtualLine(core, profile.baud, vehicle_delay_s=latency_s)
    ledger = Ledger([c.id for c in vehicle_clauses()])
    observer = VehicleObserver(profile, ledger, time_scale=k, baud=profile.baud)
    recorder = Recorder(None, [], [observer])
    link = TesterLink(line, profile, recorder, clock=line.clock)
    session = Session(link, profile, k, observer)
    cases = select_cases(select, profile)
    custodian = Custodian(written_settings(cases))
    session.custodian = custodian
    if profile.trigger == "operator":
        session.operator = _operator(line, core)
    plan = Plan(profile=profile.name, protocol=profile.protocol, time_scale=k, baud=profile.baud,
                select=list(select or []), latency_s=latency_s if not callable(latency_s) else -1.0)

    def timed(fn) -> tuple[float, float]:
        t0, w0 = link.now(), session.forced_wait
        fn()
        return round(link.now() - t0, 3), round(session.forced_wait - w0, 3)

    try:
        wall, _ = timed(lambda: _link_check(session, custodian))
        plan.lines.append(PlanLine("link", "setup", "check that the vehicle answers ($OSD,S), measure the line",
                                   wall, round(wall * k, 3)))
        durations = session.durations()
        plan.line = durations.budget.as_dict()
        plan.durations = durations.context()
        for case in cases:
            got: list = []
            wall, wait = timed(lambda: got.append(run_case(session, case)))
            outcome, reason = got[0]
            if outcome == "done":
                state, note = "ran", ""
            elif outcome == "not-tested":
                state, note = "not-run", reason
            else:
                state, note = "stopped", f"{outcome} on the reference model: {reason}"
            plan.lines.append(PlanLine(case.id, "case", case.title, wall, round(wall * k, 3), wait,
                                       tuple(case.clauses), state, note))
        budget = EXPLORE_PROFILES.get(hypothesis_profile, EXPLORE_PROFILES["fast"])
        n = budget.examples if examples is None else examples
        if n > 0:
            wall = min(budget.wall_s, budget.vehicle_s / k)  # whichever clock runs out first
            plan.lines.append(PlanLine("explore", "exploration",
                                       f"hypothesis exploration: {n} examples ({hypothesis_profile})",
                                       float(wall), round(wall * k, 3), outcome="budget",
                                       note=f"its budget ({hypothesis_profile} profile): {budget.wall_s:g} s wall, "
                                            f"{budget.vehicle_s:g} s vehicle time, whichever ends first"))
            custodian.touched = True  # it sends commands
        if custodian.needed:
            wall, wait = timed(lambda: custodian.restore(session))
            plan.lines.append(PlanLine("restore", "setup", "leave the vehicle as it was found", wall,
                                       round(wall * k, 3), wait))
    except LinkLost as e:
        raise PlanError(f"the reference vehicle stopped answering in the virtual run: {e}") from None
    finally:
        recorder.close()
        observer.close()
    plan.verdicts = {v.id: v.verdict for v in ledger.verdicts()}
    plan.edges = session.edges.summary()
    plan.edge_cases = dict(session.edges.reached)
    plan.missions = {"directories": [str(d) for d in catalog.dirs], "given": missions_dir is not None,
                     "stand_ins": dict(catalog.stand_ins)}
    plan.assumptions = _assumptions(plan, profile, catalog, missions_dir, n, budget, hypothesis_profile)
    return plan


def _link_check(session: Session, custodian: Custodian) -> None:
    """The runner's link check (:meth:`.runner.Run.probe`): ``$OSD,S`` until the vehicle answers,
    then what it was found in (its settings read when found in ``S``, :mod:`.restore`)."""
    link, obs = session.link, session.obs
    link.sleep(0.05)
    link.drain()
    for _ in range(2):
        link.send(frame("OSD,S"))
        end = link.now() + session.profile.ack_window_s + 0.5
        while link.next(end) is not None:
            if obs.alive_t is not None:
                link.sleep(0.1)
                link.drain()
                custodian.found(obs.last_osi)
                if obs.last_osi is not None and obs.last_osi.mode == "S":
                    with session.not_stopping():
                        custodian.survey(session)
                session.measure_line(host=False)
                return
    raise PlanError("the reference vehicle did not answer $OSD,S in the virtual run")


def _operator(line: VirtualLine, core):
    """``violation_trigger = "operator"``: told to trip a sensor, the operator does so
    :data:`OPERATOR_REACTION_S` later (on the in-process vehicle, off the wire)."""
    pending: list = []

    def told(text: str) -> None:
        now = line.clock()
        if core.lockout_active or any(t > now for t in pending):
            return  # the thanks after the code was seen, or a trip already on its way
        pending.append(now + OPERATOR_REACTION_S)
        line.at(now + OPERATOR_REACTION_S, lambda t: core.inject_fault(OPERATOR_CODE, t, "operator (plan)"))
    return told


def _assumptions(plan: Plan, profile: Profile, catalog: _PlanCatalog, missions_dir: Optional[Path],
                 examples: int, budget, hp: str) -> list[str]:
    out = ["the vehicle behaves and answers like the reference model (the built-in emulator), which "
           "these times come from: the cases were run on it in virtual time; a vehicle slower to answer, "
           "with longer missions or slower to surface takes longer",
           f"the line: {plan.baud} baud 8N1 both ways (every byte's transmit time), the vehicle acting "
           f"{plan.latency_s * 1000:g} ms after a line's last byte (--latency; the run measures it at its link "
           f"check and chooses its durations from what it measures); the tester's own computing time is not "
           f"counted"]
    if missions_dir is not None:
        out.append(f"the missions: {missions_dir} (--missions), then the emulator's built-in ones")
    else:
        out.append("the missions: the emulator's built-in ones (conformance.mis, short.mis, srp.mis); "
                   "--missions DIR gives the vehicle's own mission files")
    for name, builtin in catalog.stand_ins.items():
        out.append(f"the profile's {name} is not among them: the built-in {builtin} stands in for it")
    if profile.trigger == "operator":
        out.append(f"someone at the terminal trips a sensor {OPERATOR_REACTION_S:g} s after being told (the run "
                   f"waits up to {OPERATOR_WAIT_S:g} s for it)")
    if examples > 0:
        out.append(f"the exploration is counted at its budget ({hp} profile, {examples} examples): "
                   f"{budget.wall_s:g} s of wall time or {budget.vehicle_s:g} s of vehicle time, whichever "
                   f"ends first; it ends sooner when its examples are done, and starts none once the budget "
                   f"is spent (the one running then finishes); --examples 0 leaves it out")
    stopped = [x.id for x in plan.lines if x.outcome == "stopped"]
    if stopped:
        out.append(f"{', '.join(stopped)} stopped early on the reference model (see their notes): on a "
                   f"vehicle that gets further they take longer")
    return out


# ============================================================================ presenting it

def _hms(seconds: float) -> str:
    s = int(round(seconds))
    h, rest = divmod(s, 3600)
    m, sec = divmod(rest, 60)
    return f"{h} h {m:02d} min {sec:02d} s" if h else (f"{m} min {sec:02d} s" if m else f"{sec} s")


def render_text(plan: Plan) -> str:
    """The plan as a table, its total and its assumptions."""
    sel = f", --select {','.join(plan.select)}" if plan.select else ""
    out = [f"Plan: helmcheck certify vehicle, profile {plan.profile}, time scale {plan.time_scale:g}, "
           f"{plan.baud} baud{sel}",
           "(estimated on the reference vehicle in virtual time: no port opened, nothing sent)", ""]
    width = 52
    out.append(f"{'case':<8} {'title':<{width}} {'vehicle s':>10} {'wall s':>9}")
    not_run: dict[str, list[str]] = {}
    for x in plan.lines:
        title = x.title if len(x.title) <= width else x.title[:width - 1] + "…"
        if x.outcome == "not-run":
            not_run.setdefault(x.note, []).append(x.id)
            out.append(f"{x.id:<8} {title:<{width}} {'-':>10} {'-':>9}  not run")
            continue
        mark = {"budget": "  its budget", "stopped": "  stopped early"}.get(x.outcome, "")
        out.append(f"{x.id:<8} {title:<{width}} {x.vehicle_s:>10.1f} {x.wall_s:>9.1f}{mark}")
    out.append(f"{'total':<8} {'':<{width}} {plan.total_vehicle_s:>10.1f} {plan.total_wall_s:>9.1f}"
               f"  ({_hms(plan.total_wall_s)} of wall time)")
    out.append("")
    timed_wall = sum(x.wall_s for x in plan.lines if x.kind != "exploration")
    if timed_wall > 0:
        out.append(f"Of the {timed_wall:.1f} s besides the exploration, {plan.wait_s:.1f} s wait out protocol "
                   f"durations (they shrink as --time-scale grows); the rest is exchanges, line time and ACK "
                   f"windows (they do not).")
    if plan.line:
        d = plan.durations
        out.append(f"Line: {plan.line['describe']}.")
        out.append(f"  Durations chosen on it: timeouts {d['to']} s (restarted: {d['to_restart']} s, long: "
                   f"{d['to_long']} s), $OPK {d['opk_min']} min, park on a queued waypoint {d['qpark']} s.")
        out.append(f"  {precision_text(plan.line)}")
    for reason, ids in not_run.items():
        out.append(f"Not run (the profile or the line does not let them): {', '.join(ids)}: {reason}")
    for x in plan.lines:
        if x.outcome == "stopped":
            out.append(f"{x.id}: {x.note}")
    out.append("Assumptions:")
    out += [f"  - {a}" for a in plan.assumptions]
    return "\n".join(out)


def precision_text(line: dict) -> str:
    """What the line budget (``LineBudget.as_dict``) lets the observer judge timing to, and the time
    scale for nominal precision (RH-TIM-1's tolerance + :data:`NOMINAL_WIDENING_S`)."""
    b = from_settings(line)
    if b is None:
        return ""
    k = b.k
    nominal = b.nominal_scale()
    text = (f"Timing precision at ×{k:g}: RH-TIM-1's tolerance + {b.widening_v():.2f} s of vehicle time "
            f"(the observer's uncertainty and the spacing of reports)")
    if b.widening_v() <= NOMINAL_WIDENING_S:
        return text + "; nominal (≤ +0.3 s)."
    if nominal is not None:
        return text + f"; nominal (≤ +{NOMINAL_WIDENING_S:g} s) at --time-scale {nominal:g} or less."
    return text + f"; nominal (≤ +{NOMINAL_WIDENING_S:g} s) at no time scale on this line."


def as_json(plan: Plan) -> dict:
    """The plan as one JSON object; ``total_wall_s``/``total_vehicle_s`` are the sums of its lines."""
    return {"plan": "certify vehicle", "version": 1, "profile": plan.profile, "protocol": plan.protocol,
            "time_scale": plan.time_scale, "baud": plan.baud, "select": plan.select,
            "cases": [x.as_dict() for x in plan.lines],
            "total_wall_s": plan.total_wall_s, "total_vehicle_s": plan.total_vehicle_s,
            "protocol_wait_s": plan.wait_s,
            "line": {"baud": plan.baud, "bits_per_byte": BITS_PER_BYTE, "vehicle_delay_s": plan.latency_s,
                     "budget": plan.line, "durations": plan.durations},
            "missions": plan.missions, "assumptions": plan.assumptions}
