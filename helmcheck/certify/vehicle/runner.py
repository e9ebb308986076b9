"""One certification run of a vehicle: cases, exploration, results and reports.

:func:`certify` opens the port, records a ``link:`` note (the line's settings, RH-FRM-9), checks
that something answers (a link that carries nothing, or only garbage, is INCONCLUSIVE with the
reason; garbage that reads as sentences at another common baud rate names it, with the option
to run with), checks that the vehicle's clock runs at the declared time scale (:mod:`.clockprobe`: a
clear mismatch stops the run INCONCLUSIVE, naming both rates), runs the selected clause cases
in order (:mod:`.interpreter`; the port's error counters read around each, :mod:`.casecounters`),
then the hypothesis exploration (:mod:`.explore`), and writes ``DIR/results.json`` after every case (:mod:`.resultsfile`) — atomically, so a crash or Ctrl-C
leaves a valid partial report marked ``partial`` — plus ``DIR/wire.log`` and, at the end, every
report format.

Every byte and note goes through one :class:`~helmcheck.line.recorder.Recorder`: to the
wire log, to the one vehicle observer (:class:`~helmcheck.judge.vehicle.VehicleObserver`),
which writes the one ledger, and to the run facts (:class:`~helmcheck.judge.runfacts.RunFacts`:
the ``selection:`` note of a ``--select`` run, the ``process:`` note of ``--exec``, ``run
partial:``). ``results.json`` is assembled from that ledger and those facts by
:func:`helmcheck.reports.assemble.assemble` — the function ``check-log`` and ``helmcheck verify``
use on ``wire.log`` — and nothing changes a verdict after it.

A vanished device (EIO, the pty closed, the socket dropped) is waited for under the same name
for ``Options.reconnect_wait_s`` (``--reconnect-wait``): back in time, the gap is recorded as a
``run resumed`` note, the vehicle's state verified again and the case the gap cut run again from
its start (:mod:`.rejoin`); not back, the run stops partial, naming the ``--resume`` command that
goes on from that case (``Outcome.resume_command``). A link fault that is not a vanished device
(a vehicle that stops answering, garbage) stops the run: a ``run aborted`` note makes the clauses
not yet judged INCONCLUSIVE with that reason, and the report is still written.

With ``Options.exec_cmd`` (``--exec``) helmcheck starts the vehicle under test itself on the
port (:mod:`.exec_child`; :mod:`helmcheck.line.exec_port`, :mod:`helmcheck.line.launcher`),
checks it is still running before every case, and stops it at the end. If it ends before the run's end,
that is a finding about the vehicle, not a link fault: the clauses judged before keep their
verdicts, those not judged yet are NOT-TESTED with the exit as the reason (a ``not tested``
note), the exit is recorded as a ``process:`` note (``results.json`` ``process``), and the run
verdict is FAIL.
"""

from __future__ import annotations

import shutil
import time
from dataclasses import dataclass
from fnmatch import fnmatchcase
from pathlib import Path
from typing import IO, Any, Callable, Optional

from ... import __version__
from ...clauses import vehicle_clauses
from ...failures import describe_interrupt
from ...grammar import prepare
from ...grammar.wirelog import run_header
from ...judge import Ledger
from ...judge.runfacts import RunFacts, partial_note, selection_note
from ...judge.linebudget import NOMINAL_WIDENING_S
from ...judge.linemodel import line_note
from ...judge.vehicle import VehicleObserver
from ...judge.wire import tester_note
from ...line.linekind import line_for
from ...line.recorder import Recorder
from ...line.reopen import DEFAULT_WAIT_S, reopenable, wait_for_port
from ...line.transport import open_link
from ...profile import Profile
from ...reports import results as R
from ...reports.certificate import RunDeclaration, finish_run
from ..outcome import Outcome
from . import resultsfile
from .casecounters import CaseCounters
from .catalogue import select_cases
from .clockprobe import ClockMismatch, check_clock
from .exec_child import ExecChild
from .flow import CaseStop, LinkLost, LinkSilent
from .interpreter import run_case
from .link import TesterLink
from .progress import Progress, explored_text
from .generate import EXPLORE_WRITES
from .rejoin import rejoin
from .restore import Custodian, written_settings
from .resume import Resumed, resume_into
from .safety import BenchSafetyRefused
from .session import Session, frame

__all__ = ["Options", "certify", "Outcome", "Run", "CoarseTiming"]


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
    max_wait: Optional[float] = None  #: wall seconds any one wait may last (None: what the protocol needs)
    exec_cmd: Optional[str] = None  #: start the vehicle under test on ``port`` (module docstring)
    exec_grace_s: float = 5.0  #: SIGTERM → SIGKILL when stopping it
    exec_ready_s: float = 30.0  #: how long it may take to open (or listen on) the port
    certificate: Optional[RunDeclaration] = None  #: identity and signing key (helmcheck.reports.certificate)
    clock_check: bool = True  #: measure the vehicle's clock rate at start (:mod:`.clockprobe`)
    # Command-line hooks (helmcheck.commands.certify_vehicle_cmd): the link the command already
    # opened (a port that cannot be opened is a usage error there), and how to open wire.log
    # (a stream that remembers a write error for the command to report).
    link: Optional[Any] = None
    log_opener: Optional[Callable[[Path], IO[str]]] = None
    #: a person at a terminal can be told to trip a sensor (``violation_trigger = "operator"``)
    operator: bool = False
    #: continue the interrupted run in ``report_dir`` (:mod:`.resume`): its record is replayed
    #: into the observer, its wire log appended to, its completed cases not run again
    resume: bool = False
    #: what the wire log's header names the run (``helmcheck diff`` drives a Run for its machinery)
    title: str = "certify vehicle"
    #: ``"nominal"``: stop after the link check when this line at this time scale would judge
    #: timing coarser than nominal (:data:`~helmcheck.judge.linebudget.NOMINAL_WIDENING_S`), naming
    #: the time scale that would not (:class:`CoarseTiming`); ``"any"``: judge with what the line gives
    precision: str = "any"
    #: ``--line clean|noisy``: the line model the run states (None: guessed from the port,
    #: :func:`helmcheck.line.linekind.line_for`)
    line: Optional[str] = None
    #: wall seconds a vanished port is waited for under the same name before the run stops
    #: (``--reconnect-wait``; 0: not waited for), :mod:`.rejoin`
    reconnect_wait_s: float = DEFAULT_WAIT_S
    #: the command that goes on after a port that did not come back (the command line's own;
    #: default: ``helmcheck certify vehicle --port PORT --resume DIR``)
    resume_command: str = ""


#: ``$OSD,S`` requests the link check sends more when the first two get only garbage, and the
#: bytes it would like to read a baud rate from (:func:`garbage_reason`)
PROBE_MORE = 6
PROBE_BYTES = 120


def garbage_reason(captured: bytes, count: int, port: str, baud: int) -> str:
    """Why a link that carries only garbage is a link fault: the baud rate that would make the
    bytes sentences when one stands out (:func:`~helmcheck.line.baudguess.guess_baud`), with the
    option to run with; else what was seen."""
    from ...line.baudguess import guess_baud
    g = guess_baud(captured, baud)
    if g.baud is not None and g.baud != baud:
        return (f"the vehicle's bytes read as sentences at {g.baud} baud, not {baud}: run with --baud {g.baud} "
                f"({count} bytes from {port}, none a valid sentence at {baud})")
    return (f"{count} bytes from {port}, none of them a valid sentence at {baud} baud (garbage: {g.reason}; "
            f"not a remote-helm vehicle, or a line too noisy to read?)")


def selected_ids(select: Optional[list]) -> list[str]:
    ids = [c.id for c in vehicle_clauses()]
    if not select:
        return ids
    return [cid for cid in ids if any(fnmatchcase(cid, p) for p in select)]


class CoarseTiming(Exception):
    """``--precision nominal``: this line at this time scale judges timing coarser than nominal."""

    def __init__(self, budget):
        self.budget = budget
        self.scale = budget.nominal_scale()
        where = (f"--time-scale {self.scale:g} would" if self.scale is not None
                 else "no time scale on this line would (a faster baud, or a vehicle that answers sooner)")
        super().__init__(f"--precision nominal: at ×{budget.k:g} on this line timing is judged to RH-TIM-1's "
                         f"tolerance + {budget.widening_v():.2f} s of vehicle time (more than "
                         f"+{NOMINAL_WIDENING_S:g} s; the line: {budget.describe()}); {where}")


class Run(ExecChild):
    """State of one certification run (see :func:`certify`)."""

    def __init__(self, opts: Options):
        self.o = opts
        self.p = opts.profile
        self.k = opts.time_scale
        self.dir = Path(opts.report_dir)
        self.dir.mkdir(parents=True, exist_ok=True)
        self.ids = selected_ids(opts.select)
        #: every vehicle clause: a finding the observer makes outside the selection is kept
        self.ledger = Ledger([c.id for c in vehicle_clauses()])
        self.observer = VehicleObserver(self.p, self.ledger, time_scale=self.k, baud=self.p.baud)
        #: the run facts (selection, process, partial), fed by the recorder like the observer
        self.facts = RunFacts()
        self.progress = Progress(enabled=opts.progress)
        self.aborted: Optional[str] = None
        self.stopped: Optional[str] = None  #: a start-up check stopped the run: leads the verdict reason
        self.coarse: Optional[CoarseTiming] = None  #: ``--precision nominal`` stopped it
        self.gone: Optional[str] = None  #: the port vanished and did not come back (:mod:`.rejoin`)
        self.resume_command: Optional[str] = None  #: what goes on from there
        self.partial = False
        self.t_start = time.monotonic()
        self.results = resultsfile.new_results(opts)
        self.recorder: Optional[Recorder] = None
        self.link: Optional[TesterLink] = None
        self.session: Optional[Session] = None
        self.stats: dict = {}
        self.child = None  #: the vehicle under test, when helmcheck started it (a Launcher)
        writes = written_settings(select_cases(opts.select, self.p))
        if opts.explore and opts.examples != 0 and "ORWSET" in self.p.commands:
            writes += [x for x in EXPLORE_WRITES if x not in writes]  # read first, written back at the end
        self.custodian = Custodian(writes)
        self.resumed: Optional[Resumed] = None
        if opts.resume:
            self.resumed = resume_into(self)
            self.facts = RunFacts.from_wire_log(self.dir / R.WIRE_LOG_NAME)  # the first part's facts
        self.results["settings"]["reconnect_wait_s"] = float(opts.reconnect_wait_s)

    # ------------------------------------------------------------------ results
    def save(self, final: bool = False) -> None:
        """Write ``results.json`` (:func:`.resultsfile.save`)."""
        resultsfile.save(self, final)

    # ------------------------------------------------------------------ main
    def open(self) -> None:
        wire_path = self.dir / R.WIRE_LOG_NAME
        wire = (self.o.log_opener(wire_path) if self.o.log_opener is not None
                else open(wire_path, "a" if self.resumed is not None else "w", encoding="utf-8"))
        try:
            prepare()  # before the first byte: reading a malformed line must not stall the clock
            if self.o.exec_cmd:
                raw = self._start_child()
            elif self.o.link is not None:
                raw = self.o.link
            else:
                raw = open_link(self.o.port, role="client", baud=self.p.baud)
        except (OSError, ValueError) as e:
            self._record(wire, [])
            raise LinkLost(f"cannot open {self.o.port}: {getattr(e, 'strerror', None) or e}") from None
        except LinkLost:
            self._record(wire, [])
            raise
        meta = [f"started {time.strftime('%Y-%m-%dT%H:%M:%SZ', time.gmtime())}  port "
                f"{getattr(raw, 'name', None) or self.o.port}  baud {self.p.baud}  time_scale {self.k:g}",
                run_header(__version__, self.o.title, self.p.name)]
        if self.resumed is not None:  # the record goes on after a gap of a second
            lines, last_t = self.resumed.lines, self.resumed.last_t
            self.recorder = Recorder(wire, observers=[self.observer, self.facts], after=(lines, last_t))
            self.link = TesterLink(raw, self.p, self.recorder, start_at=last_t + 1.0)
            # stamped where the first part's record ends: the judge lets no time pass over a
            # command the interruption cut off before it knows (as after a link gap, :mod:`.rejoin`)
            self.recorder.note(last_t, f"run resumed: {time.strftime('%Y-%m-%dT%H:%M:%SZ', time.gmtime())}, "
                                       f"{self.resumed.done} case(s) already run")
        else:
            self._record(wire, meta)
            assert self.recorder is not None
            self.link = TesterLink(raw, self.p, self.recorder)
        try:
            ser = getattr(raw, "ser", None)
            if ser is not None:
                ser.reset_input_buffer()
        except Exception:  # noqa: BLE001
            pass
        self.link.note(f"link: {self.p.baud} baud 8N1 {self.o.port}")
        shown = getattr(raw, "name", None) if self.o.port == "announced" else None
        self.link.note(line_note(line_for(shown or self.o.port, self.o.line)))
        self.session = Session(self.link, self.p, self.k, self.observer, max_wait=self.o.max_wait)
        self.session.custodian = self.custodian
        self.session.reopen = self.reopen_link
        if self.o.operator:
            self.session.operator = self.tell_operator

    def reopen_link(self) -> Optional[str]:
        """Close the tester's end of the link and open it again under the same name (a client
        reconnecting: :class:`.steps.Quiet`); None where the name cannot come back (the run's own
        pty, ``/dev/pts/N``, a vehicle helmcheck started). A name that does not open again within
        10 s stops the case INCONCLUSIVE (the tester's own reopen, not a finding)."""
        port = self.o.port
        if self.o.exec_cmd is not None or not reopenable(port) or self.link is None:
            return None
        try:
            self.link.link.close()
        except Exception:  # noqa: BLE001
            pass
        raw, last = wait_for_port(port, baud=self.p.baud, within_s=10.0)
        if raw is None:
            raise CaseStop("inconclusive", f"{port} did not open again within 10 s after the tester closed it "
                                           f"({last}): the first command after a reconnection could not be sent")
        self.link.reattach(raw, f"link reopened by the tester: {port} closed and opened again after a quiet line")
        return f"line quiet: {port} closed and opened again"

    def _record(self, wire, meta: list) -> None:
        """The recorder of a new record: to the observer and the run facts; a ``--select`` run's
        first note is its selection (:mod:`helmcheck.judge.runfacts`)."""
        self.recorder = Recorder(wire, meta, [self.observer, self.facts])
        if self.o.select:
            self.recorder.note(0.0, selection_note(self.o.select))

    def tell_operator(self, text: str) -> None:
        """An instruction to the person at the bench: on the terminal, and in the record."""
        assert self.link is not None
        self.link.note(f"operator: {text}")
        self.progress.alert(text)

    def probe(self) -> None:
        """Does anything answer? Nothing at all, or only garbage, is a link fault. Garbage is
        asked a few more times and read for the baud rate that would make it sentences
        (:func:`helmcheck.line.baudguess.guess_baud`): a wrong ``--baud`` is named, with the one to
        run with."""
        link = self.link
        assert link is not None
        link.sleep(0.05)
        link.drain()
        captured = bytearray()
        for attempt in range(2 + PROBE_MORE):
            if attempt >= 2 and (link.bytes_in == 0 or len(captured) >= PROBE_BYTES):
                break  # silent, or enough garbage to read the rate from
            link.send(frame("OSD,S"))
            end = link.now() + self.p.ack_window_s + 0.5
            while True:
                rx = link.next(end)
                if rx is None:
                    break
                captured += rx.raw
                if self.observer.alive_t is not None:
                    link.sleep(0.1)
                    link.drain()
                    self._found()
                    return
        if link.bytes_in == 0:
            raise LinkSilent(f"no bytes at all from {self.o.port} in {link.now():.1f} s: is a vehicle on "
                             f"this port, powered, at {self.p.baud} baud?")
        why = garbage_reason(bytes(captured), link.bytes_in, self.o.port, self.p.baud)
        self.stopped = why  # the verdict's first words: what to change
        raise LinkLost(why)

    def _found(self) -> None:
        """What the vehicle was found in (:mod:`.restore`): its mode, and in ``S`` its settings."""
        osi = self.observer.last_osi
        self.custodian.found(osi)
        if osi is not None and osi.mode == "S" and self.session is not None:
            with self.session.not_stopping():
                self.custodian.survey(self.session)

    def restore(self) -> None:
        """Leave the vehicle as it was found (:mod:`.restore`), whatever ended the run."""
        c = self.custodian
        if self.session is None or self.link is None or not c.needed:
            return
        if self.child_gone():
            return  # the vehicle under test, started by helmcheck, has ended: nothing left to restore
        if self.link.lost and not self._reopen():
            c.could_not(f"the link is gone ({self.link.lost})")
            return
        self.progress.note("restoring the vehicle as it was found …")
        try:
            c.restore(self.session)
        except LinkLost as e:
            c.could_not(f"the link failed during the restore ({e})")
        except KeyboardInterrupt as e:
            c.could_not(f"interrupted again during the restore ({describe_interrupt(e)})")
        except BenchSafetyRefused as e:
            c.could_not(str(e))

    def _reopen(self) -> bool:
        """A link lost during the run: open the port again for the restore (a vehicle that came
        back after the run stopped waiting for it). ``--exec`` and a port that names nothing that
        can come back (:func:`~helmcheck.line.reopen.reopenable`) are not reopened."""
        if self.o.exec_cmd or self.link is None or not reopenable(self.o.port):
            return False
        try:
            raw = open_link(self.o.port, role="client", baud=self.p.baud)
        except (OSError, ValueError):
            return False
        self.link.reattach(raw, f"link reopened for the restore: {self.o.port}")
        return True

    def run_cases(self, cases: list) -> None:
        ses = self.session
        assert ses is not None
        ses.cover.source = "cases"  # what they reach the exploration need not reach again (:mod:`.aim`)
        try:
            self._run_cases(ses, cases)
        finally:
            ses.cover.source = None

    def _run_cases(self, ses, cases: list) -> None:
        counters = CaseCounters(self.link)  # the port's error counters around each case (casecounters.py)
        for case in cases:
            self.check_child()
            entry = {"id": case.id, "clauses": list(case.clauses), "title": case.title,
                     "expectation": case.expectation, "start": case.start, "steps": case.describe()["steps"]}
            if all(self.ledger.has_failed(cid) for cid in case.clauses):
                entry.update(verdict="not-run", reason="its clauses had already failed", wall_s=0.0,
                             line_counters={"available": False, "reason": "the case did not run"})
                self.results["cases"].append(entry)
                self.progress.step(f"{case.id} {case.subject}", "skipped (already failed)")
                continue
            cuts = 0
            while True:
                t0 = time.monotonic()
                counters.start()
                try:
                    try:
                        outcome, reason = run_case(ses, case)
                    finally:
                        entry["line_counters"] = counters.end(case.id, case.clauses)
                    break
                except LinkLost as e:
                    gone = self.child_gone(settle_s=1.0)
                    if gone:  # the vehicle under test died: not a link fault
                        self.aborted = gone
                        entry.update(verdict="not-tested", reason=gone, wall_s=round(time.monotonic() - t0, 3),
                                     cut=True)
                        self.results["cases"].append(entry)
                        self.progress.step(case.id, "not finished (the vehicle under test ended)")
                        raise
                    cut = dict(entry, verdict="inconclusive", reason=str(e), wall_s=round(time.monotonic() - t0, 3),
                               cut=True)
                    self.results["cases"].append(cut)
                    cuts += 1
                    if rejoin(self, e, f"case {case.id}", cuts):  # the port is back: the case again
                        cut["reason"] = f"cut by a link gap ({e}); run again from its start"
                        continue
                    self.progress.step(case.id, "inconclusive (link)")
                    raise
            entry.update(verdict="pass" if outcome == "done" else outcome, reason=reason,
                         wall_s=round(time.monotonic() - t0, 3))
            self.results["cases"].append(entry)
            self.progress.step(f"{case.id} {case.subject}", self.ledger.verdict(case.subject).verdict
                               if case.subject in self.ledger else outcome)
            self.save()

    def end(self, reason: Optional[str]) -> None:
        """Close the record: a ``run aborted`` note when it ended early (a ``not tested`` note for
        what a dead vehicle under test never reached), then the observer."""
        if self.recorder is not None:
            # a link still lost: at its loss (time the judge did not see, :mod:`.rejoin`)
            t = self.link.now() if self.link is not None and not self.link.lost else self.recorder.last_t
            gone = self.child_gone()
            if gone:
                left = [c for c in self.ids if not self.ledger.judged(c)]
                if left:
                    self.recorder.note(t, tester_note("not-tested", left, f"{gone}, before this clause's case ran"))
                self.recorder.note(t, "run ends")
            else:
                self.recorder.note(t, f"run aborted: {reason}" if reason else "run ends")
            if self.partial:  # a run fact: it cannot certify a pass
                self.recorder.note(t, partial_note(reason or "the run was interrupted"))
        self.observer.close()


def _precision(run: "Run", precision: str) -> None:
    """``--precision nominal`` (:class:`CoarseTiming`), after the link check measured the line."""
    if precision != "nominal" or run.session is None:
        return
    budget = run.session.meter.budget()
    if budget.widening_v() > NOMINAL_WIDENING_S:
        raise CoarseTiming(budget)


def _again(run: "Run", what: str, step: Callable[[], None]) -> None:
    """``step()``, run again from its start after each link gap it is cut by (:mod:`.rejoin`)."""
    cuts = 0
    while True:
        try:
            step()
            return
        except LinkLost as e:
            cuts += 1
            if not rejoin(run, e, what, cuts):
                raise


def _link_check(run: "Run", opts: Options) -> None:
    run.probe()
    run.session.measure_line()  # what the line costs: the durations the cases choose
    _precision(run, opts.precision)
    check_clock(run, opts.clock_check)


def certify(opts: Options) -> Outcome:
    """Run a whole certification (module docstring); never raises for vehicle or link faults."""
    run = Run(opts)
    cases = select_cases(opts.select, opts.profile)
    explore_now = opts.explore
    if run.resumed is not None:
        cases = [c for c in cases if c.id not in run.resumed.done_ids]
        explore_now = opts.explore and not run.resumed.explored
    run.progress.start(len(cases) + (1 if explore_now else 0))
    try:
        run.save()
        try:
            run.open()
            _again(run, "the link check", lambda: _link_check(run, opts))
            run.run_cases(cases)
            if explore_now and run.aborted is None:
                from .explore import explore
                _again(run, "the exploration", lambda: explore(run))
                run.progress.step("exploration", explored_text(run.stats.get("explore")))
        except (ClockMismatch, CoarseTiming) as e:  # the declared time scale is clearly wrong, or too
            run.aborted = run.stopped = str(e)          # coarse for --precision nominal: INCONCLUSIVE
            run.progress.note(f"stopped: {e}")
            if isinstance(e, CoarseTiming):
                run.coarse = e
        except LinkLost as e:
            run.aborted = run.aborted or f"link fault: {e}"
            run.progress.note(f"link fault: {e}")
    except KeyboardInterrupt as e:  # Ctrl-C, SIGTERM, SIGHUP (helmcheck.signals)
        run.partial = True
        run.aborted = describe_interrupt(e)
    except Exception as e:  # a tester error: the results say partial, the command line says why
        run.partial = True
        run.aborted = f"tester error ({type(e).__name__}){resultsfile.keep_traceback(run, e)}"
        raise
    finally:
        try:
            run.restore()
        except Exception as e:  # noqa: BLE001 - never lose the record over the restore
            run.custodian.could_not(f"tester error during the restore ({type(e).__name__}: {e})")
        run.progress.stop()
        try:
            try:
                run.stop_child()  # its end is a note: before the record closes
            finally:
                run.end(run.aborted)
        finally:
            if run.link is not None:
                run.link.close()
            if run.recorder is not None:
                run.recorder.close()
            run.save(final=True)
        # The certificate: profile.toml, digests, identity, scope and signature.
        try:
            finish_run(run.results, run.dir, opts.profile, opts.certificate)
        except (OSError, R.ReportError) as e:
            run.progress.note(f"certificate not recorded: {e}")
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
    code = R.exit_code(r["verdict"], opts.strict)
    reason = r["verdict_reason"]
    restore = r.get("restore")
    if restore is not None and restore["attempted"] and not restore["verified"]:
        from .restore import unverified_text
        reason = f"{reason.rstrip('.')}; {unverified_text(restore)}"
        if code != 1:  # the vehicle may have left with a setting changed: never a green run; a
            code = 2   # FAIL stays non-conformant (1), the restore named beside it
    if run.gone is not None and code == 0:
        code = 2
    return Outcome(r["verdict"], reason, code, run.dir, r,
                   nominal_time_scale=run.coarse.scale if run.coarse is not None else None,
                   resume_command=run.resume_command)
