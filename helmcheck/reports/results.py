"""``results.json`` schema 1: the builder, the validator, the loader and the verdict rules.

A results document is a plain ``dict`` (it is JSON on disk and JSON in memory); this module is
the one place that knows its shape. Certifiers build it with :func:`new_results`,
:func:`add_clause`, :func:`add_replay`, :func:`add_event`, :func:`add_mode` and :func:`finish`,
and save it with :func:`write_results_atomic`. Reports read it back with :func:`load_results`,
which validates it and turns every problem into a one-line :class:`ReportError` naming the file.

Verdict rules (reference profile, preamble: a MUST not met gives FAIL, a SHOULD not met gives
NON-STRICT):

* :func:`overall_verdict` — any ``fail`` → ``fail``; else any ``inconclusive`` →
  ``inconclusive``; else any ``non-strict`` → ``non-strict`` (``fail`` when *strict*: a SHOULD
  is then held to a MUST); else ``pass``. ``not-tested`` never lowers the verdict.
* :func:`run_verdict` — the verdict written into ``results.json``: :func:`overall_verdict`,
  except that a run that was interrupted (``partial``) or that judged no clause at all cannot
  certify ``pass``/``non-strict`` and is ``inconclusive`` instead. An observed ``fail`` stays.
* :func:`exit_code` — pass → 0, non-strict → 0 (1 when strict), fail → 1, inconclusive → 2.
"""

from __future__ import annotations

import json
import math
import re
from datetime import datetime, timezone
from pathlib import Path, PurePosixPath
from typing import Any, Iterable, Mapping

from helmcheck import __version__
from helmcheck.clauses import SPEC_NAME, catalogue

from .atomic import write_bytes_atomic

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

SCHEMA = 1
RESULTS_NAME = "results.json"
WIRE_LOG_NAME = "wire.log"

ROLES = ("vehicle", "backseat", "log")
VERDICTS = ("pass", "non-strict", "fail", "inconclusive")
CLAUSE_VERDICTS = VERDICTS + ("not-tested",)
LEVELS = ("MUST", "SHOULD")
DIRECTIONS = (">", "<", ">~", "<~", "!")  # docs/contracts.md, wire-log format 1
EVENT_KINDS = ("command", "ack-error", "lockout", "note")

_CLAUSE_ID = re.compile(r"^RH-[A-Z]+-\d+$")
_STEP_ACTIONS = ("send", "wait", "expect")


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


# --------------------------------------------------------------------------- verdict rules

_RANK = {"pass": 0, "non-strict": 1, "inconclusive": 2, "fail": 3}


def overall_verdict(clause_verdicts: Iterable[str], strict: bool = False) -> str:
    """The verdict of a set of clause verdicts (precedence fail > inconclusive > non-strict > pass).

    ``not-tested`` does not lower the verdict. With *strict*, a ``non-strict`` clause (a SHOULD
    not met) counts as ``fail``. An unknown verdict word raises ``ValueError``.
    """
    worst = "pass"
    for v in clause_verdicts:
        if v == "not-tested":
            continue
        if v not in _RANK:
            raise ValueError(f"unknown clause verdict {v!r}; expected one of {CLAUSE_VERDICTS}")
        if strict and v == "non-strict":
            v = "fail"
        if _RANK[v] > _RANK[worst]:
            worst = v
    return worst


def run_verdict(clause_verdicts: Iterable[str], *, strict: bool = False, partial: bool = False) -> str:
    """The verdict a run records: :func:`overall_verdict`, made ``inconclusive`` when the run was
    interrupted or judged nothing and would otherwise claim ``pass`` or ``non-strict``."""
    verdicts = list(clause_verdicts)
    verdict = overall_verdict(verdicts, strict)
    judged = any(v != "not-tested" for v in verdicts)
    if verdict in ("pass", "non-strict") and (partial or not judged):
        return "inconclusive"
    return verdict


def exit_code(verdict: str, strict: bool = False) -> int:
    """Process exit status for a run verdict: pass 0, non-strict 0 (1 if strict), fail 1,
    inconclusive 2."""
    if verdict == "pass":
        return 0
    if verdict == "non-strict":
        return 1 if strict else 0
    if verdict == "fail":
        return 1
    if verdict == "inconclusive":
        return 2
    raise ValueError(f"unknown verdict {verdict!r}; expected one of {VERDICTS}")


def _id_list(ids: list[str], limit: int = 5) -> str:
    shown = ", ".join(ids[:limit])
    return shown if len(ids) <= limit else f"{shown} and {len(ids) - limit} more"


def describe_verdict(clauses: list[Mapping[str, Any]], *, strict: bool = False, partial: bool = False) -> str:
    """One sentence explaining :func:`run_verdict` for these clause entries."""
    text = _describe(clauses, strict=strict, partial=partial)
    if partial and "interrupted" not in text:
        text += " The run was interrupted before it finished."
    return text


def _describe(clauses: list[Mapping[str, Any]], *, strict: bool, partial: bool) -> str:
    by: dict[str, list[str]] = {v: [] for v in CLAUSE_VERDICTS}
    for c in clauses:
        by.setdefault(c["verdict"], []).append(c["id"])
    verdict = run_verdict([c["verdict"] for c in clauses], strict=strict, partial=partial)
    judged = len(clauses) - len(by["not-tested"])
    if verdict == "fail":
        if by["fail"]:
            return f"{len(by['fail'])} clause(s) failed: {_id_list(by['fail'])}."
        return f"Strict run: {len(by['non-strict'])} SHOULD clause(s) not met: {_id_list(by['non-strict'])}."
    if verdict == "inconclusive":
        if by["inconclusive"]:
            return (f"No clause failed, but {len(by['inconclusive'])} could not be judged: "
                    f"{_id_list(by['inconclusive'])}.")
        if partial:
            return f"The run was interrupted after judging {judged} clause(s); nothing failed before it stopped."
        return "No clause was judged."
    if verdict == "non-strict":
        return (f"Every MUST judged is met; {len(by['non-strict'])} SHOULD clause(s) not met: "
                f"{_id_list(by['non-strict'])}.")
    untested = f" ({len(by['not-tested'])} not tested)" if by["not-tested"] else ""
    return f"All {judged} judged clause(s) pass{untested}."


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
        "verdict": "inconclusive",
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


def add_event(results: dict[str, Any], t: float, kind: str, label: str) -> None:
    """Mark a command, an ACK error, a lockout or a note on the run's time axis."""
    if kind not in EVENT_KINDS:
        raise ValueError(f"event kind must be one of {EVENT_KINDS}, not {kind!r}")
    results["events"].append({"t": t, "kind": kind, "label": label})


def add_mode(results: dict[str, Any], t: float, mode: str) -> None:
    """Extend the mode timeline; a mode equal to the current one is not repeated."""
    timeline = results["timeline"]
    if timeline and timeline[-1]["mode"] == mode:
        return
    timeline.append({"t": t, "mode": mode})


def finish(results: dict[str, Any], *, finished: str | None = None, partial: bool = False,
           strict: bool | None = None, duration_s: float | None = None) -> str:
    """Close the run: set ``finished``, ``duration_s``, ``partial``, ``verdict`` and its reason.

    *strict* defaults to ``settings.strict``. Returns the verdict.
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
    results["verdict"] = run_verdict(verdicts, strict=strict, partial=partial)
    results["verdict_reason"] = describe_verdict(results["clauses"], strict=strict, partial=partial)
    return results["verdict"]


# --------------------------------------------------------------------------- validator

class _Checker:
    """Collects schema errors, each prefixed with the JSON path it is about."""

    def __init__(self) -> None:
        self.errors: list[str] = []

    def err(self, path: str, msg: str) -> None:
        self.errors.append(f"{path}: {msg}")

    def typed(self, path: str, value: Any, kinds: tuple[type, ...], what: str, *,
              optional: bool = False) -> bool:
        if value is None and optional:
            return False
        if isinstance(value, bool) and bool not in kinds:
            ok = False
        else:
            ok = isinstance(value, kinds)
        if ok and isinstance(value, float) and not math.isfinite(value):
            self.err(path, "must be a finite number")
            return False
        if not ok:
            self.err(path, f"expected {what}{' or null' if optional else ''}, got {_jtype(value)}")
        return ok

    def number(self, path: str, value: Any, *, optional: bool = False, minimum: float | None = 0.0) -> bool:
        ok = self.typed(path, value, (int, float), "a number", optional=optional)
        if ok and minimum is not None and value < minimum:
            self.err(path, f"must be ≥ {minimum:g}, got {value!r}")
            return False
        return ok

    def string(self, path: str, value: Any, *, optional: bool = False) -> bool:
        return self.typed(path, value, (str,), "a string", optional=optional)

    def one_of(self, path: str, value: Any, words: tuple[str, ...]) -> bool:
        if not isinstance(value, str) or value not in words:
            self.err(path, f"{_short(value)} is not one of {', '.join(words)}")
            return False
        return True

    def obj(self, path: str, value: Any) -> bool:
        return self.typed(path, value, (dict,), "an object")

    def arr(self, path: str, value: Any) -> bool:
        return self.typed(path, value, (list,), "an array")

    def str_list(self, path: str, value: Any, length: int | None = None) -> None:
        if not self.arr(path, value):
            return
        if length is not None and len(value) != length:
            self.err(path, f"expected {length} items, got {len(value)}")
        for i, item in enumerate(value):
            self.string(f"{path}[{i}]", item)

    def timestamp(self, path: str, value: Any, *, optional: bool = False) -> None:
        if not self.string(path, value, optional=optional):
            return
        try:
            parsed = datetime.fromisoformat(value)
        except ValueError:
            self.err(path, f"{_short(value)} is not an ISO 8601 date-time")
            return
        if parsed.tzinfo is None:
            self.err(path, f"{_short(value)} has no time zone (write UTC with a trailing Z)")


def _jtype(value: Any) -> str:
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, (int, float)):
        return "a number"
    if isinstance(value, str):
        return "a string"
    if isinstance(value, list):
        return "an array"
    if isinstance(value, dict):
        return "an object"
    return type(value).__name__


def _short(value: Any, limit: int = 40) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 1] + "…"


_REQUIRED = ("schema", "tool", "role", "partial", "started", "finished", "duration_s", "verdict",
             "verdict_reason", "command", "implementation", "profile", "settings", "seed",
             "clauses", "replays", "coverage", "timeline", "events", "wire_log")

_IMPLEMENTATION_KEYS = {"port": str, "vehicle_name": str, "protocol": str, "osi_fields": int,
                        "fault_injection": str}
_SETTINGS_KEYS = {"time_scale": (int, float), "strict": bool, "seed": int, "examples": int,
                  "hypothesis_profile": str}

_KIND_WORDS: dict[Any, str] = {(int, float): "a number", bool: "a boolean", int: "an integer", str: "a string"}


def validate(results: Any) -> list[str]:
    """Every way *results* departs from schema 1, each message naming its JSON path.

    An empty list means the document is valid. Unknown keys are allowed (later schema-1 writers
    may add some); the verdict must follow from the clause verdicts (:func:`run_verdict`).
    """
    ck = _Checker()
    if not isinstance(results, dict):
        ck.err("$", f"expected an object, got {_jtype(results)}")
        return ck.errors
    for key in _REQUIRED:
        if key not in results:
            ck.err(key, "missing")
    r = results.get

    if "schema" in results and (r("schema") != SCHEMA or isinstance(r("schema"), bool)):
        ck.err("schema", f"expected {SCHEMA}, got {_short(r('schema'))}")
    if "tool" in results and ck.obj("tool", r("tool")):
        ck.string("tool.name", r("tool").get("name"))
        ck.string("tool.version", r("tool").get("version"))
    if "role" in results:
        ck.one_of("role", r("role"), ROLES)
    if "partial" in results:
        ck.typed("partial", r("partial"), (bool,), "a boolean")
    if "started" in results:
        ck.timestamp("started", r("started"))
    if "finished" in results:
        ck.timestamp("finished", r("finished"), optional=True)
    if "duration_s" in results:
        ck.number("duration_s", r("duration_s"), optional=True)
    if "verdict" in results:
        ck.one_of("verdict", r("verdict"), VERDICTS)
    for key in ("verdict_reason", "command"):
        if key in results:
            ck.string(key, r(key))
    if "implementation" in results and ck.obj("implementation", r("implementation")):
        for key, kind in _IMPLEMENTATION_KEYS.items():
            value = r("implementation").get(key)
            if value is not None:
                ck.typed(f"implementation.{key}", value, (kind,), "a " + ("string" if kind is str else "integer"))
    if "profile" in results and ck.obj("profile", r("profile")):
        bench = r("profile").get("bench_safety")
        if bench is not None:
            ck.obj("profile.bench_safety", bench)
    if "settings" in results and ck.obj("settings", r("settings")):
        for key, kind in _SETTINGS_KEYS.items():
            value = r("settings").get(key)
            if value is not None:
                kinds = kind if isinstance(kind, tuple) else (kind,)
                ck.typed(f"settings.{key}", value, kinds, _KIND_WORDS.get(kind, "a value"))
        ts = r("settings").get("time_scale")
        if isinstance(ts, (int, float)) and not isinstance(ts, bool) and ts <= 0:
            ck.err("settings.time_scale", f"must be > 0, got {ts!r}")
    if "seed" in results:
        ck.typed("seed", r("seed"), (int,), "an integer", optional=True)

    replay_files = _check_replays(ck, r("replays")) if "replays" in results else set()
    clause_ids = _check_clauses(ck, r("clauses"), replay_files) if "clauses" in results else set()
    if isinstance(r("replays"), list):
        for i, rep in enumerate(r("replays")):
            if isinstance(rep, dict) and isinstance(rep.get("clause"), str) and clause_ids \
                    and rep["clause"] not in clause_ids:
                ck.err(f"replays[{i}].clause", f"{rep['clause']!r} has no entry in clauses")
    if "coverage" in results:
        _check_coverage(ck, r("coverage"))
    if "timeline" in results:
        _check_timeline(ck, r("timeline"))
    if "events" in results:
        _check_events(ck, r("events"))
    if "wire_log" in results and ck.string("wire_log", r("wire_log")):
        _check_relative(ck, "wire_log", r("wire_log"))

    if not ck.errors:
        strict = bool(r("settings").get("strict", False))
        expected = run_verdict([c["verdict"] for c in r("clauses")], strict=strict, partial=r("partial"))
        if r("verdict") != expected:
            ck.err("verdict", f"{r('verdict')!r} does not follow from the clause verdicts "
                              f"(they give {expected!r}{', strict' if strict else ''}"
                              f"{', partial run' if r('partial') else ''})")
    return ck.errors


def _check_relative(ck: _Checker, path: str, value: str) -> None:
    p = PurePosixPath(value)
    if not value or value.startswith(("/", "\\")) or p.is_absolute() or ".." in p.parts \
            or "\\" in value or re.match(r"^[A-Za-z]:", value):
        ck.err(path, f"{_short(value)} must be a relative path inside the results directory")


def _check_clauses(ck: _Checker, clauses: Any, replay_files: set[str]) -> set[str]:
    ids: set[str] = set()
    if not ck.arr("clauses", clauses):
        return ids
    known = catalogue()
    for i, c in enumerate(clauses):
        p = f"clauses[{i}]"
        if not ck.obj(p, c):
            continue
        cid = c.get("id")
        if ck.string(f"{p}.id", cid):
            if not _CLAUSE_ID.match(cid):
                ck.err(f"{p}.id", f"{_short(cid)} is not a clause ID like RH-SRV-4")
            elif cid not in known:
                ck.err(f"{p}.id", f"{cid!r} is not a clause of {SPEC_NAME}")
            if cid in ids:
                ck.err(f"{p}.id", f"{cid!r} appears more than once")
            ids.add(cid)
        ck.one_of(f"{p}.verdict", c.get("verdict"), CLAUSE_VERDICTS)
        ck.string(f"{p}.reason", c.get("reason"))
        if ck.one_of(f"{p}.level", c.get("level"), LEVELS) and cid in known \
                and known[cid].level != c["level"]:
            ck.err(f"{p}.level", f"{c['level']!r}, but {SPEC_NAME} makes {cid} a {known[cid].level}")
        ck.str_list(f"{p}.cases", c.get("cases"))
        if ck.typed(f"{p}.offending_count", c.get("offending_count"), (int,), "an integer") \
                and c["offending_count"] < 0:
            ck.err(f"{p}.offending_count", "must be ≥ 0")
        evidence = c.get("evidence")
        if ck.arr(f"{p}.evidence", evidence):
            for j, ev in enumerate(evidence):
                q = f"{p}.evidence[{j}]"
                if ck.obj(q, ev):
                    ck.number(f"{q}.t", ev.get("t"))
                    ck.one_of(f"{q}.dir", ev.get("dir"), DIRECTIONS)
                    ck.string(f"{q}.line", ev.get("line"))
        if "replay" not in c:
            ck.err(f"{p}.replay", "missing (use null when there is no replay)")
        elif ck.string(f"{p}.replay", c["replay"], optional=True) and c["replay"] not in replay_files:
            ck.err(f"{p}.replay", f"{c['replay']!r} is not listed in replays")
    return ids


def _check_replays(ck: _Checker, replays: Any) -> set[str]:
    files: set[str] = set()
    if not ck.arr("replays", replays):
        return files
    for i, rep in enumerate(replays):
        p = f"replays[{i}]"
        if not ck.obj(p, rep):
            continue
        if ck.string(f"{p}.file", rep.get("file")):
            _check_relative(ck, f"{p}.file", rep["file"])
            if rep["file"] in files:
                ck.err(f"{p}.file", f"{rep['file']!r} appears more than once")
            files.add(rep["file"])
        ck.string(f"{p}.clause", rep.get("clause"))
        steps = rep.get("steps")
        if not ck.arr(f"{p}.steps", steps):
            continue
        for j, step in enumerate(steps):
            q = f"{p}.steps[{j}]"
            if not ck.obj(q, step):
                continue
            actions = [a for a in _STEP_ACTIONS if a in step]
            if len(actions) != 1:
                ck.err(q, f"needs exactly one of send, wait, expect (has {', '.join(actions) or 'none'})")
                continue
            if actions[0] == "wait":
                ck.number(f"{q}.wait", step["wait"])
            else:
                ck.string(f"{q}.{actions[0]}", step[actions[0]])
            if "t" in step:
                ck.number(f"{q}.t", step["t"])
    return files


def _check_coverage(ck: _Checker, cov: Any) -> None:
    if not ck.obj("coverage", cov):
        return
    for key, length in (("modes", None), ("transitions", 3), ("interrupt_pairs", 2)):
        value = cov.get(key)
        if value is None:
            ck.err(f"coverage.{key}", "missing")
            continue
        if key == "modes":
            ck.str_list("coverage.modes", value)
        elif ck.arr(f"coverage.{key}", value):
            for i, item in enumerate(value):
                ck.str_list(f"coverage.{key}[{i}]", item, length)


def _check_timeline(ck: _Checker, timeline: Any) -> None:
    if not ck.arr("timeline", timeline):
        return
    last = -math.inf
    for i, point in enumerate(timeline):
        p = f"timeline[{i}]"
        if not ck.obj(p, point):
            continue
        if ck.number(f"{p}.t", point.get("t")):
            if point["t"] < last:
                ck.err(f"{p}.t", f"{point['t']!r} is earlier than the point before it ({last!r})")
            last = point["t"]
        ck.string(f"{p}.mode", point.get("mode"))


def _check_events(ck: _Checker, events: Any) -> None:
    if not ck.arr("events", events):
        return
    for i, ev in enumerate(events):
        p = f"events[{i}]"
        if ck.obj(p, ev):
            ck.number(f"{p}.t", ev.get("t"))
            ck.one_of(f"{p}.kind", ev.get("kind"), EVENT_KINDS)
            ck.string(f"{p}.label", ev.get("label"))


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
