"""The ``results.json`` schema 1 validator: every departure, each named by its JSON path.

:func:`validate` checks types, the closed vocabularies (roles, verdict words, levels, wire-log
directions as :mod:`helmcheck.grammar.wirelog` defines them, event kinds), that clause IDs are
clauses of the reference profile with the level the profile gives them, that replays referenced
by clauses exist, that the timeline runs forward, that the wire log path stays inside the
results directory, and that the run verdict follows from the clause verdicts
(:func:`helmcheck.reports.verdicts.run_verdict`). Unknown keys are allowed.

The optional ``stats.explore.model_coverage`` (a vehicle run's exploration, :mod:`helmcheck.certify.vehicle.modelcover`)
is checked when present: each dimension's counts, percent and texts (:func:`_check_model_coverage`).

The optional ``process`` object describes an implementation under test that helmcheck started
(``certify … --exec``): ``command``, ``pid``, ``exit_code`` (integer or null), ``signal`` (a
signal name or null), ``ended_at_s``, ``ended_early`` (a boolean: it ended before the run's
end, which makes the run ``fail``) and ``output_tail`` (its last lines of output).

The optional ``line_model`` object says whether the link could damage bytes: ``kind`` (``clean``
or ``noisy``) and ``why`` (:mod:`helmcheck.judge.linemodel`).

The certificate keys (:mod:`helmcheck.reports.certificate`) are optional, so documents written
before them stay valid; when present they are checked: ``certificate`` must follow from the
clause verdicts by the scope rule (:func:`helmcheck.reports.scope.scope_of`), ``digests`` map file
names inside the directory to SHA-256 hex (or null for a missing file), ``identity`` and
``signature`` have their documented shapes, and ``negative_test`` marks only ``ack-error`` events.
"""

from __future__ import annotations

import math
import re
from datetime import datetime
from pathlib import PurePosixPath
from typing import Any

from helmcheck.clauses import SPEC_NAME, catalogue
from helmcheck.grammar.wirelog import DIRECTIONS

from .scope import scope_of
from .verdicts import CLAUSE_VERDICTS, VERDICTS, ended_early, run_verdict

__all__ = ["SCHEMA", "ROLES", "LEVELS", "DIRECTIONS", "EVENT_KINDS", "validate"]

SCHEMA = 1
ROLES = ("vehicle", "backseat", "log")
LEVELS = ("MUST", "SHOULD")
EVENT_KINDS = ("command", "ack-error", "lockout", "note")

_CLAUSE_ID = re.compile(r"^RH-[A-Z]+-\d+$")
_SHA256 = re.compile(r"^[0-9a-f]{64}$")
_STEP_ACTIONS = ("send", "wait", "expect")


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
    if isinstance(r("stats"), dict) and isinstance(r("stats").get("explore"), dict) \
            and "model_coverage" in r("stats")["explore"]:
        _check_model_coverage(ck, r("stats")["explore"]["model_coverage"])
    if "timeline" in results:
        _check_timeline(ck, r("timeline"))
    if "events" in results:
        _check_events(ck, r("events"))
    if "wire_log" in results and ck.string("wire_log", r("wire_log")):
        _check_relative(ck, "wire_log", r("wire_log"))
    if "process" in results:
        _check_process(ck, r("process"))
    if "restore" in results:
        _check_restore(ck, r("restore"))
    if "line_model" in results and ck.obj("line_model", r("line_model")):
        if r("line_model").get("kind") not in ("clean", "noisy"):
            ck.err("line_model.kind", f"{_short(r('line_model').get('kind'))} is not clean or noisy")
        ck.string("line_model.why", r("line_model").get("why"))
    _check_certificate_keys(ck, results)

    if not ck.errors:
        strict = bool(r("settings").get("strict", False))
        died = ended_early(results)
        expected = run_verdict([c["verdict"] for c in r("clauses")], strict=strict, partial=r("partial"),
                               process_failed=died)
        if r("verdict") != expected:
            ck.err("verdict", f"{r('verdict')!r} does not follow from the clause verdicts "
                              f"(they give {expected!r}{', strict' if strict else ''}"
                              f"{', partial run' if r('partial') else ''}"
                              f"{', the implementation under test ended early' if died else ''})")
        if "certificate" in results:
            scope = scope_of(results)
            if r("certificate") != scope.certificate:
                ck.err("certificate", f"{r('certificate')!r} does not follow from the clause verdicts "
                                      f"(scope: {scope.statement})")
    return ck.errors


def _check_process(ck: _Checker, process: Any) -> None:
    if not ck.obj("process", process):
        return
    ck.string("process.command", process.get("command"))
    if "pid" in process:
        ck.typed("process.pid", process["pid"], (int,), "an integer", optional=True)
    for key in ("exit_code", "signal", "ended_at_s"):
        if key not in process:
            ck.err(f"process.{key}", "missing (use null when unknown)")
    ck.typed("process.exit_code", process.get("exit_code"), (int,), "an integer", optional=True)
    if ck.string("process.signal", process.get("signal"), optional=True) \
            and not re.match(r"^SIG[A-Z0-9+-]+$", process["signal"]):
        ck.err("process.signal", f"{_short(process['signal'])} is not a signal name like SIGKILL")
    ck.number("process.ended_at_s", process.get("ended_at_s"), optional=True, minimum=None)
    ck.typed("process.ended_early", process.get("ended_early"), (bool,), "a boolean")
    if "output_tail" in process:
        ck.str_list("process.output_tail", process["output_tail"])


def _check_restore(ck: _Checker, restore: Any) -> None:
    """The vehicle left as found (``helmcheck.certify.vehicle.restore``)."""
    if not ck.obj("restore", restore):
        return
    for key in ("attempted", "verified"):
        ck.typed(f"restore.{key}", restore.get(key), (bool,), "a boolean")
    for key in ("found", "left"):
        if ck.obj(f"restore.{key}", restore.get(key)):
            ck.string(f"restore.{key}.mode", restore[key].get("mode"), optional=True)
    ck.str_list("restore.problems", restore.get("problems"))
    ck.str_list("restore.by_hand", restore.get("by_hand"))
    settings = restore.get("settings")
    if not isinstance(settings, list):
        ck.err("restore.settings", "must be a list")
        return
    for i, st in enumerate(settings):
        path = f"restore.settings[{i}]"
        if not ck.obj(path, st):
            continue
        ck.string(f"{path}.name", st.get("name"))
        for key in ("before", "after"):
            if st.get(key) is not None:
                ck.str_list(f"{path}.{key}", st[key])
        for key in ("written", "verified"):
            ck.typed(f"{path}.{key}", st.get(key), (bool,), "a boolean")
    if restore.get("verified") is True and restore.get("problems"):
        ck.err("restore.verified", "true, but problems are listed")


def _check_sha(ck: _Checker, path: str, value: Any, *, optional: bool = False) -> None:
    if ck.string(path, value, optional=optional) and not _SHA256.match(value):
        ck.err(path, f"{_short(value)} is not a SHA-256 in lower-case hex")


def _check_certificate_keys(ck: _Checker, results: dict[str, Any]) -> None:
    """``certificate``, ``scope``, ``digests``, ``identity``, ``signature`` (all optional)."""
    if "certificate" in results:
        ck.typed("certificate", results["certificate"], (bool,), "a boolean")
    if "scope" in results and ck.obj("scope", results["scope"]):
        sc = results["scope"]
        for key in ("claimed", "judged"):
            if ck.typed(f"scope.{key}", sc.get(key), (int,), "an integer") and sc[key] < 0:
                ck.err(f"scope.{key}", "must be ≥ 0")
        ck.string("scope.statement", sc.get("statement"))
        if ck.arr("scope.gaps", sc.get("gaps")):
            for i, gap in enumerate(sc["gaps"]):
                if ck.obj(f"scope.gaps[{i}]", gap):
                    ck.str_list(f"scope.gaps[{i}].clauses", gap.get("clauses"))
                    ck.one_of(f"scope.gaps[{i}].verdict", gap.get("verdict"), ("not-tested", "inconclusive", "missing"))
                    ck.string(f"scope.gaps[{i}].reason", gap.get("reason"))
    if "digests" in results and ck.obj("digests", results["digests"]):
        for name, value in results["digests"].items():
            _check_relative(ck, f"digests[{name!r}]", name)
            _check_sha(ck, f"digests[{name!r}]", value, optional=True)
    if "identity" in results and ck.obj("identity", results["identity"]):
        ident = results["identity"]
        if ck.obj("identity.implementation", ident.get("implementation")):
            impl = ident["implementation"]
            ck.one_of("identity.implementation.role", impl.get("role"), ROLES)
            for key in ("name", "serial", "version", "name_on_wire"):
                if key in impl:
                    ck.string(f"identity.implementation.{key}", impl[key], optional=True)
        for key in ("operator", "site"):
            ck.string(f"identity.{key}", ident.get(key), optional=True)
        _check_sha(ck, "identity.profile_sha256", ident.get("profile_sha256"))
        pf = ident.get("profile_file")
        if pf is not None and ck.obj("identity.profile_file", pf):
            ck.string("identity.profile_file.path", pf.get("path"))
            _check_sha(ck, "identity.profile_file.sha256", pf.get("sha256"), optional=True)
        if ck.obj("identity.tester", ident.get("tester")):
            for key in ("name", "version", "revision"):
                ck.string(f"identity.tester.{key}", ident["tester"].get(key))
    if results.get("signature") is not None and ck.obj("signature", results["signature"]):
        sig = results["signature"]
        if ck.string("signature.file", sig.get("file")):
            _check_relative(ck, "signature.file", sig["file"])
        ck.one_of("signature.algorithm", sig.get("algorithm"), ("Ed25519",))
        _check_sha(ck, "signature.key_id", sig.get("key_id"))


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


def _check_model_coverage(ck: _Checker, mc: Any) -> None:
    """``stats.explore.model_coverage``: per dimension (``rows``, ``modes``, ``interrupt_pairs``,
    ``timers``, ``boundaries``, ``error_codes``, and ``rules`` when the traceability table is
    plugged in) ``covered`` ≤ ``of``, ``percent``, ``uncovered`` (what was not reached, as texts) and
    optionally ``with_cases`` (the cases and the exploration together: between ``covered`` and ``of``)."""
    base = "stats.explore.model_coverage"
    if not ck.obj(base, mc):
        return
    for name, d in mc.items():
        q = f"{base}.{name}"
        if not ck.obj(q, d):
            continue
        ok = ck.typed(f"{q}.covered", d.get("covered"), (int,), "an integer") and \
            ck.typed(f"{q}.of", d.get("of"), (int,), "an integer")
        ck.number(f"{q}.percent", d.get("percent"))
        ck.str_list(f"{q}.uncovered", d.get("uncovered"))
        if not ok:
            continue
        covered, of = d["covered"], d["of"]
        if not 0 <= covered <= of:
            ck.err(f"{q}.covered", f"must be between 0 and of ({of}), got {covered}")
        both = d.get("with_cases")
        if both is not None and ck.typed(f"{q}.with_cases", both, (int,), "an integer") \
                and not covered <= both <= of:
            ck.err(f"{q}.with_cases", f"must be between covered ({covered}) and of ({of}), got {both}")


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
            if "negative_test" in ev and ck.typed(f"{p}.negative_test", ev["negative_test"], (bool,), "a boolean") \
                    and ev["negative_test"] and ev.get("kind") != "ack-error":
                ck.err(f"{p}.negative_test", "only an ack-error event can be a negative test")
