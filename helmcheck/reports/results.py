"""``results.json`` schema 1: the builder, the loader and the atomic writer.

A results document is a plain ``dict`` (it is JSON on disk and JSON in memory). Certifiers start
it with :func:`new_results`, add :func:`add_replay`, :func:`add_event` and :func:`add_mode`, take
the clause entries, ``partial``, ``process`` and the run verdict from
:func:`helmcheck.reports.assemble.assemble` (the one function ``helmcheck verify`` runs again),
and save it with :func:`write_results_atomic`. :func:`add_clause`, :func:`add_process` and
:func:`finish` build a document by hand (report fixtures, tests). Reports read it back with :func:`load_results`, which validates it (:mod:`helmcheck.reports.schema`) and turns
every problem into a one-line :class:`ReportError` naming the file. The verdict rules live in
:mod:`helmcheck.reports.verdicts` and are re-exported here.
"""

from __future__ import annotations

import json
from datetime import datetime, timezone
from pathlib import Path
from typing import Any, Iterable, Mapping

from helmcheck import __version__
from helmcheck.clauses import SPEC_NAME, catalogue

from ..judge.verdict import Verdict
from .atomic import write_bytes_atomic
from .schema import DIRECTIONS, EVENT_KINDS, LEVELS, ROLES, SCHEMA, validate
from .verdicts import (CLAUSE_VERDICTS, VERDICTS, describe_verdict, ended_early, exit_code, overall_verdict,
                       run_verdict)

__all__ = [
    "SCHEMA",
    "RESULTS_NAME",
    "WIRE_LOG_NAME",
    "ROLES",
    "VERDICTS",
    "CLAUSE_VERDICTS",
    "LEVELS",
    "DIRECTIONS",
    "EVENT_KINDS",
    "ReportError",
    "new_results",
    "add_clause",
    "add_replay",
    "add_event",
    "add_mode",
    "add_process",
    "finish",
    "validate",
    "load_results",
    "parse_results",
    "dump_results",
    "write_results_atomic",
    "overall_verdict",
    "run_verdict",
    "describe_verdict",
    "exit_code",
]

RESULTS_NAME = "results.json"
WIRE_LOG_NAME = "wire.log"


class ReportError(Exception):
    """A results directory that cannot be read, parsed or validated (or a report not written).

    ``str(err)`` is one line that names the file; ``err.path`` is that file and ``err.errors``
    the individual schema errors, if any.
    """

    def __init__(self, path: Path | str, message: str, errors: Iterable[str] = ()) -> None:
        self.path = Path(path)
        self.message = message
        self.errors = list(errors)
        super().__init__(f"{self.path}: {message}")


# --------------------------------------------------------------------------- builder

def _utc_now() -> str:
    return datetime.now(timezone.utc).isoformat(timespec="seconds").replace("+00:00", "Z")


def new_results(
    role: str,
    *,
    command: str = "",
    implementation: Mapping[str, Any] | None = None,
    profile: Mapping[str, Any] | None = None,
    settings: Mapping[str, Any] | None = None,
    seed: int | None = None,
    started: str | None = None,
    tool_version: str | None = None,
    wire_log: str = WIRE_LOG_NAME,
) -> dict[str, Any]:
    """A fresh schema-1 document for a run that has just started.

    It is valid as it stands and says ``partial: true`` / ``inconclusive`` until :func:`finish`
    is called, so a copy saved mid-run (or left behind by a crash) never claims a pass.
    """
    if role not in ROLES:
        raise ValueError(f"role must be one of {ROLES}, not {role!r}")
    settings = dict(settings or {})
    if seed is None:
        seed = settings.get("seed")
    return {
        "schema": SCHEMA,
        "tool": {"name": "helmcheck", "version": tool_version or __version__},
        "role": role,
        "partial": True,
        "started": started or _utc_now(),
        "finished": None,
        "duration_s": None,
        "verdict": Verdict.INCONCLUSIVE,
        "verdict_reason": "The run has not finished.",
        "command": command,
        "implementation": dict(implementation or {}),
        "profile": dict(profile or {}),
        "settings": settings,
        "seed": seed,
        "clauses": [],
        "replays": [],
        "coverage": {"modes": [], "transitions": [], "interrupt_pairs": []},
        "timeline": [],
        "events": [],
        "wire_log": wire_log,
    }


def add_clause(
    results: dict[str, Any],
    cid: str,
    verdict: str,
    reason: str,
    *,
    cases: Iterable[str] = (),
    evidence: Iterable[Mapping[str, Any]] = (),
    offending_count: int = 0,
    replay: str | None = None,
    level: str | None = None,
) -> dict[str, Any]:
    """Record (or replace) the verdict of one clause; the level defaults to the profile's."""
    if verdict not in CLAUSE_VERDICTS:
        raise ValueError(f"clause verdict must be one of {CLAUSE_VERDICTS}, not {verdict!r}")
    if level is None:
        known = catalogue().get(cid)
        if known is None:
            raise KeyError(f"no clause {cid!r} in {SPEC_NAME}")
        level = known.level
    entry = {
        "id": cid,
        "verdict": verdict,
        "reason": reason,
        "level": level,
        "cases": list(cases),
        "offending_count": offending_count,
        "evidence": [{"t": e["t"], "dir": e["dir"], "line": e["line"]} for e in evidence],
        "replay": replay,
    }
    clauses = results["clauses"]
    for i, old in enumerate(clauses):
        if old.get("id") == cid:
            clauses[i] = entry
            break
    else:
        clauses.append(entry)
    return entry


def add_replay(results: dict[str, Any], cid: str, steps: Iterable[Mapping[str, Any]],
               file: str | None = None) -> dict[str, Any]:
    """Record a replay script for a clause and point the clause entry (if any) at it."""
    file = file or f"replays/{cid}.json"
    entry = {"file": file, "clause": cid, "steps": [dict(s) for s in steps]}
    results["replays"] = [r for r in results["replays"] if r.get("file") != file] + [entry]
    for c in results["clauses"]:
        if c.get("id") == cid:
            c["replay"] = file
    return entry


def add_event(results: dict[str, Any], t: float, kind: str, label: str, *, negative_test: bool = False) -> None:
    """Mark a command, an ACK error, a lockout or a note on the run's time axis.

    *negative_test* marks an ``ack-error`` the tester provoked on purpose (an expected refusal):
    the event then carries ``"negative_test": true`` and the reports count it apart from real
    ACK errors.
    """
    if kind not in EVENT_KINDS:
        raise ValueError(f"event kind must be one of {EVENT_KINDS}, not {kind!r}")
    if negative_test and kind != "ack-error":
        raise ValueError("only an ack-error event can be a negative test")
    event = {"t": t, "kind": kind, "label": label}
    if negative_test:
        event["negative_test"] = True
    results["events"].append(event)


def add_mode(results: dict[str, Any], t: float, mode: str) -> None:
    """Extend the mode timeline; a mode equal to the current one is not repeated."""
    timeline = results["timeline"]
    if timeline and timeline[-1]["mode"] == mode:
        return
    timeline.append({"t": t, "mode": mode})


def add_process(results: dict[str, Any], process: Mapping[str, Any], *,
                not_run: Iterable[str] = (), reason: str = "") -> None:
    """Record the implementation under test that helmcheck started (``--exec``).

    *process* has the keys the schema names (``command``, ``pid``, ``exit_code``, ``signal``,
    ``ended_at_s``, ``ended_early``, ``output_tail``). When it ended early, the clauses in
    *not_run* — those whose cases or scenarios had not run, or had not finished, when it ended —
    become NOT-TESTED with *reason*; the clauses judged before keep their verdicts. Call
    :func:`finish` afterwards: the run verdict is then ``fail`` (:func:`run_verdict`).
    """
    results["process"] = dict(process)
    if process.get("ended_early") is True:
        todo = set(not_run)
        for c in results["clauses"]:
            if c["id"] in todo:
                c.update(verdict=Verdict.NOT_TESTED, reason=reason, offending_count=0, evidence=[], replay=None)


def finish(results: dict[str, Any], *, finished: str | None = None, partial: bool = False,
           strict: bool | None = None, duration_s: float | None = None) -> str:
    """Close the run: set ``finished``, ``duration_s``, ``partial``, ``verdict`` and its reason.

    *strict* defaults to ``settings.strict``. A ``process`` that ended early (see
    :func:`add_process`) makes the verdict ``fail``. Returns the verdict.
    """
    if strict is None:
        strict = bool(results.get("settings", {}).get("strict", False))
    results["finished"] = finished or _utc_now()
    if duration_s is None:
        try:
            t0 = datetime.fromisoformat(results["started"])
            t1 = datetime.fromisoformat(results["finished"])
            duration_s = max(0.0, round((t1 - t0).total_seconds(), 3))
        except (TypeError, ValueError):
            duration_s = None
    results["duration_s"] = duration_s
    results["partial"] = bool(partial)
    verdicts = [c["verdict"] for c in results["clauses"]]
    died = ended_early(results)
    results["verdict"] = run_verdict(verdicts, strict=strict, partial=partial, process_failed=died)
    results["verdict_reason"] = describe_verdict(results["clauses"], strict=strict, partial=partial,
                                                 process=results.get("process"),
                                                 subject=str(results.get("role", "implementation")))
    return results["verdict"]


# --------------------------------------------------------------------------- load / save

def _reject_constant(name: str) -> Any:
    raise ValueError(f"{name} is not allowed in JSON")


def results_path(directory: Path | str) -> Path:
    """``DIR/results.json`` (a path to the file itself is accepted too)."""
    p = Path(directory)
    return p if p.name == RESULTS_NAME and not p.is_dir() else p / RESULTS_NAME


def parse_results(data: bytes, path: Path | str = RESULTS_NAME, *, check: bool = True) -> dict[str, Any]:
    """Decode and (with *check*) validate the bytes of a ``results.json``; :class:`ReportError`
    naming *path* on any problem."""
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ReportError(path, f"not UTF-8 text (byte 0x{data[exc.start]:02x} at offset {exc.start})") from None
    try:
        doc = json.loads(text, parse_constant=_reject_constant)
    except json.JSONDecodeError as exc:
        raise ReportError(path, f"not valid JSON: {exc.msg} at line {exc.lineno} column {exc.colno}") from None
    except (ValueError, RecursionError) as exc:
        raise ReportError(path, f"not valid JSON: {exc}") from None
    if check:
        errors = validate(doc)
        if errors:
            more = f" (and {len(errors) - 3} more)" if len(errors) > 3 else ""
            raise ReportError(path, f"not a valid helmcheck results document: {'; '.join(errors[:3])}{more}",
                              errors)
    return doc


def read_results_bytes(directory: Path | str) -> tuple[Path, bytes]:
    """The path and raw bytes of ``DIR/results.json``; :class:`ReportError` if unreadable."""
    directory = Path(directory)
    path = results_path(directory)
    if not path.parent.is_dir():
        raise ReportError(path.parent, "no such results directory")
    try:
        return path, path.read_bytes()
    except FileNotFoundError:
        raise ReportError(path, "no such file (is this a helmcheck results directory?)") from None
    except IsADirectoryError:
        raise ReportError(path, "is a directory, not a results file") from None
    except OSError as exc:
        raise ReportError(path, f"cannot read: {exc.strerror or exc}") from None


def load_results(directory: Path | str, *, check: bool = True) -> dict[str, Any]:
    """Read, parse and validate ``DIR/results.json``.

    Raises :class:`ReportError` (one line, naming the file) when the directory or file is
    missing or unreadable, the bytes are not UTF-8 JSON, or (with *check*) the document is not
    valid schema 1.
    """
    path, data = read_results_bytes(directory)
    return parse_results(data, path, check=check)


def dump_results(results: Mapping[str, Any]) -> bytes:
    """The canonical bytes of a results document (UTF-8, two-space indent, final newline)."""
    return (json.dumps(results, indent=2, ensure_ascii=False, allow_nan=False) + "\n").encode("utf-8")


def write_results_atomic(directory: Path | str, results: Mapping[str, Any], *, check: bool = True) -> Path:
    """Write ``DIR/results.json`` through a temporary file in DIR and ``os.replace``.

    A reader never sees a half-written file. With *check*, an invalid document is refused with
    :class:`ReportError` listing its schema errors (nothing is written).
    """
    directory = Path(directory)
    path = directory / RESULTS_NAME
    if check:
        errors = validate(results)
        if errors:
            raise ReportError(path, f"refusing to write an invalid results document: {'; '.join(errors[:3])}",
                              errors)
    directory.mkdir(parents=True, exist_ok=True)
    try:
        write_bytes_atomic(path, dump_results(results))
    except OSError as exc:
        raise ReportError(path, f"cannot write: {exc.strerror or exc}") from None
    return path
