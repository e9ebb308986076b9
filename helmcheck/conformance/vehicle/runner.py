"""One certification run of a vehicle: cases, exploration, results and reports.

:func:`certify` opens the port, checks that something answers (a link that carries nothing, or
only garbage, is INCONCLUSIVE with the reason), runs the selected clause cases in order with a
verified reset before each (:mod:`.cases`), then the hypothesis exploration (:mod:`.explore`),
and writes ``DIR/results.json`` (schema 1, ``role: vehicle``) after every case — atomically, so a
crash or Ctrl-C leaves a valid partial report marked ``partial`` — plus ``DIR/wire.log`` and, at
the end, every report format (:func:`helmcheck.reports.render.render_all`).

A vanished device stops the run: the clauses not yet judged are INCONCLUSIVE with that reason,
and the report is still written.
"""

from __future__ import annotations

import shutil
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any, Callable, Optional

from ... import __version__
from ...clauses import vehicle_clauses
from ...failures import describe_interrupt
from ...model.transitions import REMOTE_MODES
from ...profile import Profile
from ...reports import results as R
from ..transport import open_link
from .cases import Case, run_case, select_cases
from .judge import Book, CaseFail, CaseInconclusive, CaseNotTested
from .link import LinkLost, TesterLink
from .progress import Progress
from .session import LinkSilent, Session, frame

__all__ = ["Options", "certify", "Outcome"]

_INTERRUPTS = ("OMS", "OMP", "OPK", "OMW", "OJW")
_MAX_EVENTS = 5000


@dataclass
class Options:
    port: str
    profile: Profile
    time_scale: float
    report_dir: Path
    select: Optional[list] = None
    examples: Optional[int] = None
    seed: Optional[int] = None
    strict: bool = False
    wire_log: Optional[Path] = None
    hypothesis_profile: str = "fast"
    explore: bool = True
    progress: bool = True
    command: str = ""
    render: bool = True
    explore_budget_s: Optional[float] = None  #: wall seconds for exploration (default: the hypothesis profile's)
    # Command-line hooks (helmcheck.conformance.vehicle.cli): the link the command already
    # opened (a port that cannot be opened is a usage error there), and how to open wire.log
    # (a stream that remembers a write error for the command to report).
    link: Optional[Any] = None
    log_opener: Optional[Callable[[Path], IO[str]]] = None


@dataclass
class Outcome:
    verdict: str
    reason: str
    exit_code: int
    report_dir: Path
    results: dict = field(default_factory=dict)


class Recorder:
    """Timeline, events and model coverage for ``results.json``."""

    def __init__(self, results: dict):
        self.r = results
        self.modes: set = set()
        self.transitions: set = set()
        self.pairs: set = set()
        self.last_mode: Optional[str] = None

    def _event(self, t: float, kind: str, label: str) -> None:
        if len(self.r["events"]) < _MAX_EVENTS:
            R.add_event(self.r, round(t, 6), kind, label[:120])

    def event(self, t: float, kind: str, label: str) -> None:
        self._event(t, kind, label)

    def command(self, t: float, raw: bytes) -> None:
        text = raw.decode("latin-1", "replace").strip()
        self._event(t, "command", text)

    def answered(self, ex, before: str, after: str) -> None:
        a = ex.ack
        item = ex.item
        cid = getattr(item, "ID", None) or getattr(item, "sentence_id", None) or "?"
        if a is not None and a.status != 0:
            self._event(ex.t_ack, "ack-error", f"$ACK,{a.type},{a.status},{a.err} for ${cid}")
            if a.err == 26:
                self._event(ex.t_ack, "lockout", f"${cid} refused: lockout (26)")
        elif a is not None:
            if before != after and cid != "OSD":
                self.transitions.add((before, cid, after))
            if before in REMOTE_MODES and cid in _INTERRUPTS:
                self.pairs.add((before, cid))

    def mode(self, t: float, mode: str) -> None:
        R.add_mode(self.r, round(t, 6), mode)
        self.modes.add(mode)
        if self.last_mode is not None and self.last_mode != mode:
            self.transitions.add((self.last_mode, "observed", mode))
        self.last_mode = mode

    def flush(self) -> None:
        self.r["coverage"] = {"modes": sorted(self.modes),
                              "transitions": [list(t) for t in sorted(self.transitions)],
                              "interrupt_pairs": [list(p) for p in sorted(self.pairs)]}


def _selected_ids(select: Optional[list]) -> list[str]:
    from fnmatch import fnmatchcase
    ids = [c.id for c in vehicle_clauses()]
    if not select:
        return ids
    return [cid for cid in ids if any(fnmatchcase(cid, p) for p in select)]


class Run:
    """State of one certification run (see :func:`certify`)."""

    def __init__(self, opts: Options):
        self.o = opts
        self.p = opts.profile
        self.k = opts.time_scale
        self.dir = Path(opts.report_dir)
        self.dir.mkdir(parents=True, exist_ok=True)
        self.ids = _selected_ids(opts.select)
        self.book = Book(self.ids)
        self.progress = Progress(enabled=opts.progress)
        self.aborted: Optional[str] = None
        self.partial = False
        self.t_start = time.monotonic()
        settings = {"time_scale": self.k, "strict": opts.strict, "hypothesis_profile": opts.hypothesis_profile,
                    "select": list(opts.select or []), "ack_window_s": self.p.ack_window_s,
                    "bench_safety": {"enforced": not self.p.bench_safety.in_water,
                                     "max_motor_byte": self.p.bench_safety.max_motor_byte,
                                     "max_speed_kn": self.p.bench_safety.max_speed_kn}}
        if opts.seed is not None:
            settings["seed"] = opts.seed
        if opts.examples is not None:
            settings["examples"] = opts.examples
        prof = self.p.as_dict()
        self.results = R.new_results("vehicle", command=opts.command, tool_version=__version__,
                                     implementation={"port": opts.port, "protocol": self.p.protocol,
                                                     "osi_fields": self.p.osi_fields,
                                                     "fault_injection": self.p.fault_injection},
                                     profile=prof, settings=settings, seed=opts.seed)
        self.results["cases"] = []
        self.rec = Recorder(self.results)
        self.link: Optional[TesterLink] = None
        self.session: Optional[Session] = None
        self.log_file = None
        self.stats: dict = {}

    # ------------------------------------------------------------------ results
    def save(self, final: bool = False) -> None:
        self.rec.flush()
        r = self.results
        r["clauses"] = []
        r_ids = set()
        for cid in self.ids:
            verdict, reason, cases, ev, n = self.book.verdict(cid, self._default_reason(cid))
            if self.aborted and verdict == "not-tested" and cid not in self._not_applicable:
                verdict, reason = "inconclusive", f"not judged: {self.aborted}"
            R.add_clause(r, cid, verdict, reason, cases=cases, evidence=ev[-16:], offending_count=n)
            r_ids.add(cid)
        for c in vehicle_clauses():
            if c.id not in r_ids:
                R.add_clause(r, c.id, "not-tested", "not selected (--select)")
        for rep in r["replays"]:
            for c in r["clauses"]:
                if c["id"] == rep["clause"]:
                    c["replay"] = rep["file"]
        if self.session is not None:
            r["settings"]["bench_safety"]["refused_lines"] = self.session.link.guard.refused
            self.stats["forced_wait_s"] = round(self.session.forced_wait, 3)
        self.stats["wall_s"] = round(time.monotonic() - self.t_start, 3)
        r["stats"] = self.stats
        if final:
            R.finish(r, partial=self.partial, strict=self.o.strict, duration_s=self.stats["wall_s"])
            if self.partial and self.aborted:
                r["verdict_reason"] = f"{self.aborted[:1].upper()}{self.aborted[1:]}. {r['verdict_reason']}"
        else:
            r["partial"] = True
            r["verdict"] = R.run_verdict([c["verdict"] for c in r["clauses"]], strict=self.o.strict, partial=True)
            r["verdict_reason"] = "The run is in progress."
        R.write_results_atomic(self.dir, r)

    _not_applicable: set = set()

    def _default_reason(self, cid: str) -> str:
        return "no case exercised this clause"

    # ------------------------------------------------------------------ main
    def open(self) -> None:
        wire_path = self.dir / R.WIRE_LOG_NAME
        if self.o.log_opener is not None:
            self.log_file = self.o.log_opener(wire_path)
        else:
            self.log_file = open(wire_path, "w", encoding="utf-8")
        meta = (f"started {time.strftime('%Y-%m-%dT%H:%M:%SZ', time.gmtime())}  port {self.o.port}  "
                f"baud {self.p.baud}  time_scale {self.k:g}")
        try:
            raw = self.o.link if self.o.link is not None else open_link(self.o.port, role="client",
                                                                         baud=self.p.baud)
        except (OSError, ValueError) as e:
            self.log_file.write("# helmcheck wire-log 1\n")
            raise LinkLost(f"cannot open {self.o.port}: {getattr(e, 'strerror', None) or e}") from None
        self.link = TesterLink(raw, self.p, log=self.log_file, meta=meta)
        try:
            ser = getattr(raw, "ser", None)
            if ser is not None:
                ser.reset_input_buffer()
        except Exception:  # noqa: BLE001
            pass
        self.session = Session(self.link, self.p, self.k, self.book, self.rec)

    def probe(self) -> None:
        """Does anything answer? Nothing at all, or only garbage, is a link fault."""
        link = self.link
        assert link is not None
        link.sleep(0.05)
        link.drain()
        for _ in range(2):
            link.send(frame("OSD,S"))
            end = link.now() + self.p.ack_window_s + 0.5
            while True:
                rx = link.next(end)
                if rx is None:
                    break
                if rx.valid:  # something speaks the protocol; the cases judge the rest
                    link.sleep(0.1)
                    link.drain()
                    return
        if link.bytes_in == 0:
            raise LinkSilent(f"no bytes at all from {self.o.port} in {link.now():.1f} s: is a vehicle on "
                             f"this port, powered, at {self.p.baud} baud?")
        if link.valid_in == 0:
            raise LinkLost(f"{link.bytes_in} bytes from {self.o.port}, none of them a valid sentence "
                           f"(garbage: wrong baud or not a remote-helm vehicle?)")
        raise LinkLost(f"{self.o.port}: no valid sentence in reply to $OSD,S")  # pragma: no cover

    def run_cases(self, cases: list[Case]) -> None:
        ses = self.session
        assert ses is not None
        for case in cases:
            ses.case, ses.case_t0 = case.id, ses.now()
            ses.link.note(f"case {case.id} {' '.join(case.clauses)}: {case.title}")
            entry = {"id": case.id, "clauses": list(case.clauses), "title": case.title,
                     "expectation": case.expectation, "start": case.start,
                     "steps": case.describe()["steps"]}
            if all(self.book.failed(cid) for cid in case.clauses):
                # first fail wins: a later case cannot change these clauses' verdicts
                entry.update(verdict="not-run", reason="its clauses had already failed", wall_s=0.0)
                self.results["cases"].append(entry)
                self.progress.step(f"{case.id} {case.subject}", "skipped (already failed)")
                continue
            t0 = time.monotonic()
            try:
                verdict, reason, _ = run_case(ses, case)
                for cid in case.clauses:
                    self.book.add(cid, "pass", reason, case.id, ses.evidence()[-6:])
            except CaseFail as f:
                verdict, reason = "fail", f"{f.clause}: {f.reason}"
                ev = ses.evidence()
                self.book.add(f.clause, "fail", f"{case.id}: {f.reason}", case.id, ev)
                for extra in f.also:
                    if extra != f.clause:
                        self.book.add(extra, "fail", f"{case.id}: {f.reason}", case.id, ev)
                if f.clause not in case.clauses:
                    for cid in case.clauses:
                        self.book.add(cid, "inconclusive", f"{case.id} stopped: {f.clause} failed first",
                                      case.id, ev)
            except CaseInconclusive as e:
                verdict, reason = "inconclusive", e.reason
                self.book.add(e.clause if e.clause in case.clauses or not e.clause else case.subject,
                              "inconclusive", f"{case.id}: {e.reason}", case.id, ses.evidence())
            except CaseNotTested as e:
                verdict, reason = "not-tested", e.reason
                for cid in case.clauses:
                    self.book.add(cid, "not-tested", f"{case.id}: {e.reason}", case.id)
            except LinkLost as e:
                self.aborted = f"link fault during {case.id}: {e}"
                entry.update(verdict="inconclusive", reason=str(e))
                self.results["cases"].append(entry)
                for cid in case.clauses:
                    self.book.add(cid, "inconclusive", f"{case.id}: {e}", case.id, ses.evidence())
                self.progress.step(case.id, "inconclusive (link)")
                raise
            entry.update(verdict=verdict, reason=reason, wall_s=round(time.monotonic() - t0, 3))
            self.results["cases"].append(entry)
            self.progress.step(f"{case.id} {case.subject}", verdict)
            self.save()

    def finish_clauses(self) -> None:
        """Clauses judged by all observations rather than by one case."""
        b = self.book
        link = self.session.link if self.session else None
        if link is not None and link.garbage_in:
            b.add("RH-FRM-1", "inconclusive" if link.garbage_in > 2 else "pass",
                  f"{link.garbage_in} runs of bytes from the vehicle were not well-framed sentences "
                  f"(line noise or a vehicle fault: cannot attribute)")
        if self.p.fault_injection != "oxflt":
            for cid in ("RH-SAF-1", "RH-SAF-2", "RH-SAF-3", "RH-SAF-4", "RH-SAF-5"):
                if not b.outcomes.get(cid):
                    b.add(cid, "not-tested", "the profile declares fault_injection = \"none\" and no safety "
                                             "violation happened by itself during the run")
            self._not_applicable = {"RH-SAF-1", "RH-SAF-2", "RH-SAF-3", "RH-SAF-4", "RH-SAF-5"}
        if self.p.bench_safety.in_water is False:
            self.stats["bench_safety"] = "enforced"


def certify(opts: Options) -> Outcome:
    """Run a whole certification (module docstring); never raises for vehicle or link faults."""
    run = Run(opts)
    cases = select_cases(opts.select, opts.profile)
    n_steps = len(cases) + (1 if opts.explore else 0)
    run.progress.start(n_steps)
    try:
        run.save()
        try:
            run.open()
            run.probe()
            run.run_cases(cases)
            if opts.explore and run.aborted is None:
                from .explore import explore
                explore(run)
                run.progress.step("exploration", "done")
        except LinkLost as e:
            run.aborted = run.aborted or f"link fault: {e}"
            run.progress.note(f"link fault: {e}")
    except KeyboardInterrupt as e:  # Ctrl-C, SIGTERM, SIGHUP (helmcheck.signals)
        run.partial = True
        run.aborted = describe_interrupt(e)
    except Exception as e:  # a tester error: the results say partial, the command line says why
        run.partial = True
        run.aborted = f"tester error ({type(e).__name__})"
        raise
    finally:
        run.progress.stop()
        try:
            run.finish_clauses()
        except Exception:  # noqa: BLE001
            pass
        if run.link is not None:
            run.link.close()
        elif run.log_file is not None:
            run.log_file.close()
        run.save(final=True)
        if opts.wire_log is not None:
            try:
                shutil.copyfile(run.dir / R.WIRE_LOG_NAME, opts.wire_log)
            except OSError:
                pass
        if opts.render:
            try:
                from ...reports.render import render_all
                render_all(run.dir)
            except Exception as e:  # noqa: BLE001 - the results file is the certificate
                run.progress.note(f"reports not rendered: {e}")
    r = run.results
    return Outcome(r["verdict"], r["verdict_reason"], R.exit_code(r["verdict"], opts.strict), run.dir, r)
