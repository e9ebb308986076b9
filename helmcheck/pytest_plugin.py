"""pytest plugin: a helmcheck certification as test items, one per clause (``pytest11`` entry point).

Without one of its options this plugin only registers them: it imports nothing of helmcheck's
protocol code, adds no item and changes no outcome. With one of

* ``--helm-vehicle URL`` — certify the vehicle on that port (what ``certify vehicle --port`` opens);
* ``--helm-vehicle-exec CMD`` — start the vehicle under test and certify it (``certify vehicle --exec``);
* ``--helm-backseat-exec CMD`` — start the backseat under test and certify it (``certify backseat --exec``);

it adds one item per clause of that role, named by clause ID (``helmcheck.vehicle::RH-SRV-4``,
``helmcheck.backseat::RH-BS-1``), then the item ``run-verdict``. The certification runs once per
session, in the setup of the first helmcheck item that runs (its time is charged to that item),
through the library entries :func:`helmcheck.certify.vehicle.runner.certify` for a vehicle and
:func:`helmcheck.certify.backseat.certifier.certify` for a backseat (no command line is parsed); the report
directory (``--helm-report-dir``) gets ``results.json``, the wire log and every report format,
as the commands write them. The directory belongs to the plugin: each session replaces the
previous session's run in it.

Item outcomes (decisions where the issue left a choice):

* ``pass`` → passed; ``fail`` → failed, the clause's reason and evidence lines in the failure
  text; ``non-strict`` (a SHOULD missed) → passed with a :class:`HelmcheckNonStrict` warning,
  failed under ``--helm-strict``; ``not-tested`` → skipped with the reason;
* ``inconclusive`` → failed with an ``INCONCLUSIVE:`` prefix, because a gate must not go green on
  a run that could not judge; ``--helm-inconclusive=skip`` skips it instead;
* ``run-verdict`` carries the run's verdict (the same rules). It exists because a run can be
  worse than all its clauses: an implementation that died (FAIL), a backseat that never
  connected (INCONCLUSIVE, every clause NOT-TESTED) — a gate must see that too.

``-k RH-SRV`` deselects items as usual, and for a vehicle only the clauses still selected are
certified (as ``--select``), so a filtered run is also a short one. ``-x`` stops after the
first failing item; ``--junitxml`` gets one testcase per item (classname ``helmcheck.<role>``),
with the clause verdict, level and report path as properties.
"""

from __future__ import annotations

import shlex
import warnings
from pathlib import Path
from typing import Any, Optional

import pytest

__all__ = ["HelmcheckNonStrict", "RUN_ITEM"]

RUN_ITEM = "run-verdict"
_OPTIONS = ("helm_vehicle", "helm_vehicle_exec", "helm_backseat_exec")
_EVIDENCE_LINES = 20


class HelmcheckNonStrict(UserWarning):
    """A SHOULD clause not met (NON-STRICT): the item passes unless ``--helm-strict``."""


def pytest_addoption(parser: pytest.Parser) -> None:
    g = parser.getgroup("helmcheck", "helmcheck conformance of the remote helm protocol (one item per clause)")
    g.addoption("--helm-vehicle", metavar="URL",
                help="certify the vehicle on this port (/dev/ttyUSB0, /dev/pts/N, socket://HOST:PORT)")
    g.addoption("--helm-vehicle-exec", metavar="CMD",
                help="start the vehicle under test with CMD ({port} is replaced) and certify it")
    g.addoption("--helm-backseat-exec", metavar="CMD",
                help="start the backseat under test with CMD ({port} is replaced) and certify it")
    g.addoption("--helm-profile", metavar="FILE", help="TOML profile (default: rh5)")
    g.addoption("--helm-time-scale", type=float, metavar="K", help="time scale (default: the profile's)")
    g.addoption("--helm-report-dir", metavar="DIR",
                help="where results.json and the reports go, replaced each session "
                     "(default: helmcheck-reports/<role>)")
    g.addoption("--helm-exec-port", metavar="PORT", default="pty",
                help="with an --helm-*-exec option: pty (default) or socket://127.0.0.1:0")
    g.addoption("--helm-strict", action="store_true", help="a SHOULD not met (NON-STRICT) fails its item")
    g.addoption("--helm-inconclusive", choices=("fail", "skip"), default="fail",
                help="what an INCONCLUSIVE clause does to its item (default: fail)")
    g.addoption("--helm-duration", type=float, metavar="S", default=None,
                help="backseat: seconds of judged run (default: what the scenarios need at the time scale "
                     "and baud, as helmcheck certify backseat --plan prints)")
    g.addoption("--helm-scenario", action="append", metavar="NAME",
                help="backseat: run only these scenarios (repeatable)")
    g.addoption("--helm-examples", type=int, metavar="N",
                help="vehicle: hypothesis examples after the cases (0: none)")
    g.addoption("--helm-seed", type=int, metavar="N", help="vehicle: hypothesis seed")


def pytest_configure(config: pytest.Config) -> None:
    given = [name for name in _OPTIONS if config.getoption(name)]
    if not given:
        return
    if len(given) > 1:
        raise pytest.UsageError("helmcheck: give one of --helm-vehicle, --helm-vehicle-exec, --helm-backseat-exec")
    if config.getoption("numprocesses", default=None):
        raise pytest.UsageError("helmcheck: the certification runs once per session; run it without "
                                "pytest-xdist's -n (each worker would certify on its own)")
    plan = _Certification(config, given[0])
    config.addinivalue_line("markers", "helmcheck: a clause of a helmcheck certification")
    config.pluginmanager.register(plan, "helmcheck-certification")


def _usage(msg: str) -> pytest.UsageError:
    return pytest.UsageError(f"helmcheck: {msg}")


class _Certification:
    """The one certification of this session: options checked up front, run once, looked up per item."""

    def __init__(self, config: pytest.Config, option: str):
        from .clauses import backseat_clauses, vehicle_clauses
        from .profile import ProfileError, load_profile

        opt = config.getoption
        self.config = config
        self.role = "backseat" if option == "helm_backseat_exec" else "vehicle"
        self.target = opt(option)
        self.exec_cmd = self.target if option.endswith("_exec") else None
        self.strict = bool(opt("helm_strict"))
        self.skip_inconclusive = opt("helm_inconclusive") == "skip"
        try:
            self.profile = load_profile(opt("helm_profile"))
        except ProfileError as e:
            raise _usage(f"--helm-profile: {e}") from None
        k = opt("helm_time_scale")
        if k is not None and not (k > 0 and k != float("inf")):
            raise _usage(f"--helm-time-scale must be a positive number (got {k})")
        self.time_scale = float(k if k is not None else self.profile.time_scale)
        if self.exec_cmd is not None:
            from .line.launcher import check_command
            why = check_command(self.exec_cmd)
            if why:
                raise _usage(f"--helm-{self.role}-exec: {why}")
        base = Path(config.invocation_params.dir)
        self.report_dir = base / (opt("helm_report_dir") or f"helmcheck-reports/{self.role}")
        self.clause_ids = [c.id for c in (backseat_clauses() if self.role == "backseat" else vehicle_clauses())]
        self.selected: Optional[list[str]] = None
        self.results: Optional[dict] = None
        self.error: Optional[str] = None
        self.exit_code: Optional[int] = None
        if self.role == "backseat":
            self.backseat_options = self._backseat_options()

    # ------------------------------------------------------------------ collection
    @pytest.hookimpl(tryfirst=True)
    def pytest_collection_modifyitems(self, session: pytest.Session, config: pytest.Config,
                                      items: list[pytest.Item]) -> None:
        """Add the clause items before ``-k``/``-m`` deselect (so they apply to them too)."""
        name = f"helmcheck.{self.role}"
        collector = _Collector.from_parent(session, name=name, nodeid=name, plan=self)
        items.extend(session.genitems(collector))

    def pytest_collection_finish(self, session: pytest.Session) -> None:
        ids = [i.name for i in session.items if isinstance(i, _ClauseItem) and i.name != RUN_ITEM]
        if self.role == "vehicle" and set(ids) != set(self.clause_ids):
            self.selected = ids

    # ------------------------------------------------------------------ the run
    def _backseat_options(self):
        """The backseat run's options, checked now (usage errors before the first item)."""
        from .certify.backseat.certifier import Options, problems

        opt = self.config.getoption
        opts = Options(profile=self.profile, report_dir=self.report_dir, port=opt("helm_exec_port"),
                       time_scale=self.time_scale, duration=opt("helm_duration"),
                       scenarios=list(opt("helm_scenario") or ()) or None, strict=self.strict,
                       exec_cmd=self.exec_cmd, progress=False, command=self._command())
        wrong = problems(opts, spell=lambda name: {"exec": "--helm-backseat-exec",
                                                   "port": "--helm-exec-port"}.get(name, f"--helm-{name}"))
        if wrong:
            raise _usage(wrong[0])
        return opts

    def ensure_run(self) -> None:
        if self.results is not None or self.error is not None:
            return
        try:
            if self.role == "backseat":
                self._run_backseat()
            else:
                self._run_vehicle()
        except Exception as e:  # noqa: BLE001 - every item reports it
            self.error = f"{type(e).__name__}: {e}"
            raise

    def _command(self) -> str:
        return "pytest " + shlex.join(self.config.invocation_params.args)

    def _run_vehicle(self) -> None:
        from .certify.vehicle.runner import Options, certify

        opt = self.config.getoption
        examples = opt("helm_examples")
        profile = self.profile.replace(time_scale=self.time_scale)
        port = self.target if self.exec_cmd is None else opt("helm_exec_port")
        out = certify(Options(port=port, profile=profile, time_scale=self.time_scale, report_dir=self.report_dir,
                              select=self.selected, examples=examples, seed=opt("helm_seed"), strict=self.strict,
                              hypothesis_profile="fast" if self.time_scale > 1 else "patient",
                              explore=examples != 0, progress=False, command=self._command(),
                              exec_cmd=self.exec_cmd))
        self.results, self.exit_code = out.results, out.exit_code

    def _run_backseat(self) -> None:
        from .certify.backseat.certifier import certify
        from .outputs import prepare_report_dir

        prepare_report_dir(self.report_dir, overwrite=True)  # the plugin's own directory: each session replaces it
        out = certify(self.backseat_options)
        self.results, self.exit_code = out.results, out.exit_code

    # ------------------------------------------------------------------ reporting
    def entry(self, cid: str) -> Optional[dict]:
        assert self.results is not None
        for c in self.results["clauses"]:
            if c["id"] == cid:
                return c
        return None

    def pytest_terminal_summary(self, terminalreporter) -> None:
        if self.results is None and self.error is None:
            return
        terminalreporter.section(f"helmcheck {self.role}")
        if self.error is not None:
            terminalreporter.write_line(f"the certification did not run: {self.error}")
            return
        r = self.results
        assert r is not None
        terminalreporter.write_line(f"{r['verdict'].upper()}{' (partial)' if r['partial'] else ''}: "
                                    f"{r['verdict_reason']}")
        terminalreporter.write_line(f"report: {self.report_dir / 'report.html'}")


class _Collector(pytest.Collector):
    """``helmcheck.<role>``: the clause items, then ``run-verdict``."""

    def __init__(self, *, plan: _Certification, **kw: Any):
        super().__init__(**kw)
        self.plan = plan

    def collect(self):
        for cid in self.plan.clause_ids:
            yield _ClauseItem.from_parent(self, name=cid, plan=self.plan)
        yield _ClauseItem.from_parent(self, name=RUN_ITEM, plan=self.plan)


class _Outcome(Exception):
    """A clause (or the run) did not pass: the verdict word and the failure text."""

    def __init__(self, word: str, message: str, lines: list[str]):
        super().__init__(message)
        self.word, self.message, self.lines = word, message, lines


class _Repr:
    """The failure text of an item: the verdict and reason first, then evidence and the report."""

    def __init__(self, outcome: _Outcome, location: str):
        self.lines = outcome.lines
        self.reprcrash = _Crash(outcome.message, location)

    def toterminal(self, tw) -> None:
        for line in self.lines:
            tw.line(line)

    def __str__(self) -> str:
        return "\n".join(self.lines)


class _Crash:
    def __init__(self, message: str, path: str):
        self.message, self.path, self.lineno = message, path, 0


class _ClauseItem(pytest.Item):
    def __init__(self, *, plan: _Certification, **kw: Any):
        super().__init__(**kw)
        self.plan = plan
        self.add_marker("helmcheck")

    def reportinfo(self):
        return self.path, None, f"helmcheck {self.plan.role} {self.name}"

    def setup(self) -> None:
        if self.plan.error is not None:
            pytest.fail(f"the certification did not run: {self.plan.error}", pytrace=False)
        self.plan.ensure_run()

    def runtest(self) -> None:
        plan = self.plan
        r = plan.results
        assert r is not None
        report = plan.report_dir / "report.html"
        self.user_properties.append(("report", str(report)))
        if self.name == RUN_ITEM:
            self._judge(r["verdict"], r["verdict_reason"], [], "run", report)
            return
        entry = plan.entry(self.name)
        if entry is None:
            pytest.fail(f"{self.name}: not in {plan.report_dir / 'results.json'}", pytrace=False)
        self.user_properties += [("verdict", entry["verdict"]), ("level", entry["level"])]
        self._judge(entry["verdict"], entry["reason"], entry["evidence"], entry["level"], report)

    def _judge(self, verdict: str, reason: str, evidence: list, level: str, report: Path) -> None:
        from .judge.verdict import Verdict

        word = verdict.upper()
        if verdict == Verdict.PASS:
            return
        if verdict == Verdict.NOT_TESTED:
            pytest.skip(f"NOT-TESTED: {reason}")
        if verdict == Verdict.INCONCLUSIVE and self.plan.skip_inconclusive:
            pytest.skip(f"INCONCLUSIVE: {reason}")
        if verdict == Verdict.NON_STRICT and not self.plan.strict:
            warnings.warn(HelmcheckNonStrict(f"{self.name} NON-STRICT ({level}): {reason}"), stacklevel=1)
            return
        message = f"{word}: {reason}"
        lines = [f"{self.name} {word} ({level}): {reason}"]
        if evidence:
            lines.append("evidence (t, direction, line):")
            lines += [f"  {e['t']:12.6f} {e['dir']:<2} {e['line']}" for e in evidence[:_EVIDENCE_LINES]]
            if len(evidence) > _EVIDENCE_LINES:
                lines.append(f"  … {len(evidence) - _EVIDENCE_LINES} more in results.json")
        if self.name == RUN_ITEM and self.plan.results and self.plan.results.get("process"):
            tail = self.plan.results["process"].get("output_tail") or []
            if tail:
                lines.append(f"last output of the {self.plan.role} under test:")
                lines += [f"  {line}" for line in tail]
        lines.append(f"report: {report}")
        raise _Outcome(word, message, lines)

    def repr_failure(self, excinfo, style=None):
        if isinstance(excinfo.value, _Outcome):
            return _Repr(excinfo.value, str(self.path))
        return super().repr_failure(excinfo, style=style)
