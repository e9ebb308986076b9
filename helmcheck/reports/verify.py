"""The checks of ``helmcheck verify DIR``: does a results directory follow from its evidence?

:func:`helmcheck.commands.verify_cmd.verify_run` runs them in this order and trusts nothing in
``results.json`` that the evidence can decide:

1. ``results.json`` must parse and be a valid schema-1 document (:func:`open_run`,
   :func:`~.schema.validate`);
2. the wire log and ``profile.toml`` must have the SHA-256 that ``results.json`` records
   (``digests``), so one changed byte shows even in an unsigned run (:func:`check_digests`);
3. ``profile.toml`` must load (:func:`helmcheck.profile.load_profile`) and be the profile
   ``results.json`` records (``profile``, key by key) (:func:`check_profile`);
4. ``settings.time_scale`` must be the ``time_scale`` of ``profile.toml``; :func:`rejudging`
   says which wire log to re-judge, as which role (``vehicle`` or ``backseat`` as recorded; a
   log check's ``log.role``) and at which time scale (the profile's; a log check's own), and for
   a log check with its ``--swap-directions`` and mission directories (``settings.missions``;
   one that is not here is a note) — and a log too large to have been copied is re-judged where
   the check referenced it, if it still has the SHA-256 recorded;
5. the wire log is **re-judged** under that profile by the offline observer (the command calls
   :func:`helmcheck.checklog.check_log`: a driver, which this package does not
   import), which also reads the run facts of its notes (:mod:`helmcheck.judge.runfacts`: the
   selection, the clauses not judged, the ``process`` note of an implementation helmcheck
   started, ``run partial``); then :func:`compare_rejudged` runs the one function that
   assembled ``results.json`` (:func:`.assemble.assemble`) again on that evidence and compares
   everything it decides: ``settings.select`` with the wire log's selection note, every clause
   verdict (inside and outside the selection), ``partial``, the ``process`` object key by key,
   the run verdict and the ``certificate`` flag. Only verdict words are compared for the
   clauses, not reasons or evidence. A document saved while the run was still going
   (``finished`` null, the run never closed it) is assembled as partial, as it was saved;
6. if the run is signed (``signature.json``, :mod:`.certificate`), the signature and manifest
   formats must be the ones this helmcheck writes, the Ed25519 signature must hold over the
   manifest and the manifest must name the files as they are now; with a trusted public key
   (``--public-key``) the signature must be that key's, and an unsigned run fails
   (:func:`check_signature`).

Every difference is a :class:`Finding` naming the file or clause, added to one
:class:`Verification`. A directory that is not a results directory at all raises
:class:`VerifyUsageError` (exit 64).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping, Optional

from ..judge.runfacts import RunFacts
from .assemble import Assembly, assemble
from .manifest import MANIFEST_FORMAT, PROFILE_NAME, RESULTS_NAME, differing_files, evidence_files, sha256_file
from .results import parse_results
from .schema import validate
from .segments import recorded_segments
from .signing import ALGORITHM, key_id, public_key_from_b64
from .view import VERDICT_LABEL

__all__ = ["Finding", "Verification", "VerifyUsageError", "Rejudging", "open_run", "check_digests",
           "check_profile", "rejudging", "compare_rejudged", "check_signature"]

_SIGNATURE_NAME = "signature.json"
_SIGNATURE_FORMAT = "helmcheck-signature-1"  #: :data:`helmcheck.reports.certificate.SIGNATURE_FORMAT`
_SCHEMA_ERRORS_SHOWN = 5


class VerifyUsageError(ValueError):
    """The directory is not a results directory (no such directory, no ``results.json``)."""


@dataclass(frozen=True)
class Finding:
    """One way the results directory does not hold: ``subject`` names the file or clause."""

    subject: str
    detail: str

    def __str__(self) -> str:
        return f"{self.subject}: {self.detail}"


@dataclass
class Verification:
    """The outcome of :func:`helmcheck.commands.verify_cmd.verify_run`: every finding, in the order found."""

    directory: Path
    findings: list[Finding] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    clauses_compared: int = 0
    signed: bool = False
    key_id: Optional[str] = None
    trusted_key: bool = False

    @property
    def ok(self) -> bool:
        return not self.findings

    def add(self, subject: str, detail: str) -> None:
        self.findings.append(Finding(subject, detail))


def _word(verdict: Any) -> str:
    return VERDICT_LABEL.get(verdict, str(verdict)) if verdict is not None else "absent"


def open_run(directory: Path) -> tuple[Verification, Optional[dict[str, Any]]]:
    """Step 1: the :class:`Verification` of *directory*, and its ``results.json`` if that is a
    valid results document (``None``: the findings say why). :class:`VerifyUsageError` if
    *directory* is not a results directory at all."""
    if not directory.is_dir():
        raise VerifyUsageError(f"{directory}: no such results directory")
    res_path = directory / RESULTS_NAME
    try:
        data = res_path.read_bytes()
    except FileNotFoundError:
        raise VerifyUsageError(f"{res_path}: no such file (is this a helmcheck results directory?)") from None
    except OSError as e:
        raise VerifyUsageError(f"{res_path}: cannot read: {e.strerror or e}") from None
    out = Verification(directory)
    results: Optional[dict[str, Any]] = None
    try:
        doc = parse_results(data, res_path, check=False)
    except Exception as e:  # ReportError: not UTF-8 / not JSON
        out.add(RESULTS_NAME, str(getattr(e, "message", e)))
        doc = None
    if isinstance(doc, dict):
        errors = validate(doc)
        for err in errors[:_SCHEMA_ERRORS_SHOWN]:
            out.add(RESULTS_NAME, f"not a valid results document: {err}")
        if len(errors) > _SCHEMA_ERRORS_SHOWN:
            out.add(RESULTS_NAME, f"and {len(errors) - _SCHEMA_ERRORS_SHOWN} more schema error(s)")
        if not errors:
            results = doc
    elif doc is not None:
        out.add(RESULTS_NAME, "not a results document (not a JSON object)")
    return out, results


# --------------------------------------------------------------------------- digests, profile

def check_digests(out: Verification, directory: Path, results: Mapping[str, Any]) -> None:
    """Step 2: the wire log and ``profile.toml`` have the digests ``results.json`` records."""
    recorded = results.get("digests")
    wire_name, _ = evidence_files(results)
    if not isinstance(recorded, Mapping):
        from .identity import still_going
        why = (": it was written while the run was still going (the run's end records them)"
               if still_going(results) else "")
        out.add(RESULTS_NAME, f"records no digests of the wire log and profile, so they cannot be checked{why}")
        return
    for name in (wire_name, *recorded_segments(results), PROFILE_NAME):
        if name not in recorded:
            out.add(RESULTS_NAME, f"records no digest of {name}")
    for name, want, got in differing_files(directory, recorded):
        if got is None:
            out.add(name, f"missing (results.json records SHA-256 {want})")
        elif want is None:
            out.add(name, f"present (SHA-256 {got}) but results.json records it as absent")
        else:
            out.add(name, f"SHA-256 {got} differs from the {want} recorded in results.json")


def _normal(value: Any) -> Any:
    return json.loads(json.dumps(value))


def check_profile(out: Verification, directory: Path, results: Mapping[str, Any]):
    """Step 3: ``profile.toml`` loads and is the profile ``results.json`` records; the loaded
    profile, or ``None`` (nothing can be re-judged)."""
    from ..profile import ProfileError, load_profile

    path = directory / PROFILE_NAME
    if not path.is_file():
        out.add(PROFILE_NAME, "missing: the profile the run was judged under is not in the directory")
        return None
    try:
        profile = load_profile(path)
    except ProfileError as e:
        out.add(PROFILE_NAME, f"cannot be used: {e}")
        return None
    ident = results.get("identity")
    if isinstance(ident, Mapping) and ident.get("profile_sha256") not in (None, sha256_file(path)):
        out.add(PROFILE_NAME, f"SHA-256 {sha256_file(path)} differs from the identity's profile_sha256 "
                              f"{ident.get('profile_sha256')}")
    recorded = results.get("profile") or {}
    loaded = _normal(profile.as_dict())
    for key in sorted(set(recorded) | set(loaded)):
        if key == "name":
            continue
        if _normal(recorded.get(key)) != loaded.get(key):
            out.add(PROFILE_NAME, f"key {key} is {json.dumps(loaded.get(key))}, but results.json records "
                                  f"{json.dumps(recorded.get(key))}")
    return profile


# --------------------------------------------------------------------------- re-judging

@dataclass(frozen=True)
class Rejudging:
    """What step 5 re-judges: the wire log, the role to judge it as, the time scale."""

    wire_name: str  #: the evidence file's name in the directory (a finding's subject)
    wire_path: Path
    role: str  #: ``vehicle``, ``backseat`` or ``both`` (a log check of both roles)
    time_scale: float
    swap: bool = False  #: a log check's ``--swap-directions``
    line: Optional[str] = None  #: a log check's ``--line`` (``settings.line``)
    missions: tuple[Path, ...] = ()  #: a log check's mission directories (``settings.missions``)
    sha256: Optional[str] = None  #: the SHA-256 the log must have (a log referenced, not copied)


def rejudging(out: Verification, directory: Path, results: Mapping[str, Any], profile) -> Optional[Rejudging]:
    """Step 4: ``settings.time_scale`` is the profile's, and what to re-judge (``None``: there is
    no wire log to re-judge; the finding says so)."""
    role = results["role"]
    judge_role = role if role != "log" else ((results.get("log") or {}).get("role") or "both")
    recorded_k = results["settings"].get("time_scale")
    time_scale = float(profile.time_scale or 1.0)
    if role in ("vehicle", "backseat") and not _same_number(recorded_k, time_scale):
        out.add("settings.time_scale", f"results.json says {recorded_k}, but profile.toml (the profile the run "
                                       f"was judged under) has time_scale {time_scale:g}")
    if role == "log" and isinstance(recorded_k, (int, float)) and recorded_k > 0:
        time_scale = float(recorded_k)  # a log check's time scale is its own (no profile.toml holds it)
    wire_name, _ = evidence_files(results)
    wire_path = directory / wire_name
    log = results.get("log") if role == "log" and isinstance(results.get("log"), Mapping) else {}
    sha = None
    if not wire_path.is_file() and log.get("copy") is None and log.get("source"):
        # a log check of a log too large to copy: the log is referenced by path and SHA-256
        wire_name, wire_path, sha = str(log["source"]), Path(str(log["source"])), log.get("sha256")
        if not wire_path.is_file():
            out.add(wire_name, "missing: the checked log was referenced by path (too large to copy into the "
                               "results directory) and is not there")
            return None
    elif not wire_path.is_file():
        out.add(wire_name, "missing: there is no evidence to re-judge")
        return None
    settings = results["settings"]
    missions: list[Path] = []
    for d in (settings.get("missions") or ()) if role == "log" else ():
        if Path(str(d)).is_dir():
            missions.append(Path(str(d)))
        else:
            out.notes.append(f"the mission directory {d} the check used is not here: re-judged without it")
    line = settings.get("line") if role == "log" and settings.get("line") in ("clean", "noisy") else None
    return Rejudging(wire_name, wire_path, judge_role, time_scale, swap=bool(settings.get("swap_directions")),
                     missions=tuple(missions), sha256=sha, line=line)


def compare_rejudged(out: Verification, results: Mapping[str, Any], clauses: list, facts: RunFacts,
                     role: str) -> None:
    """Step 5, after the wire log was re-judged as *role* (its clause verdicts *clauses* and run
    *facts*, as :func:`helmcheck.checklog.check_log` returns them): the assembly
    again, on that evidence, compared with *results*."""
    for text in facts.unreadable:
        out.add(evidence_files(results)[0], f"a run-fact note cannot be read: {text}")
    # the one function, again, on the evidence (:mod:`.assemble`); a document saved while the run
    # was still going (``finished`` null: the run never closed it) is partial, as it was saved
    in_progress = results.get("finished") is None
    got = assemble(results["role"], clauses, facts, strict=bool(results["settings"].get("strict", False)),
                   partial=True if in_progress else None)
    _compare(out, results, got, facts, role)
    tool = results.get("tool") or {}
    from helmcheck import __version__
    if tool.get("version") != __version__:
        out.notes.append(f"recorded by helmcheck {tool.get('version')}, re-judged by helmcheck {__version__}")


def _same_number(a: Any, b: float) -> bool:
    return isinstance(a, (int, float)) and not isinstance(a, bool) and abs(float(a) - b) <= 1e-9 * max(1.0, abs(b))


def _compare(out: Verification, results: Mapping[str, Any], got: Assembly, facts: RunFacts, role: str) -> None:
    """Every difference between *results* and the assembly of its evidence, one finding each."""
    said_select = (results["settings"].get("select") or [])
    if not isinstance(said_select, list) or [str(p) for p in said_select] != list(facts.select):
        out.add("settings.select", f"results.json says {_patterns(said_select)}, the wire log's selection is "
                                   f"{_patterns(list(facts.select))}")
    rejudged = {c["id"]: c for c in got.clauses}
    recorded = {c["id"]: c for c in results["clauses"]}
    for cid, entry in recorded.items():
        said = entry["verdict"]
        c = rejudged.get(cid)
        if c is None:
            out.add(f"clause {cid}", f"results.json says {_word(said)}; re-judging the wire log as a {role} "
                                     f"run does not judge this clause")
            continue
        out.clauses_compared += 1
        if c["verdict"] != said:
            reason = " ".join(str(c.get("reason") or "").split())
            out.add(f"clause {cid}", f"results.json says {_word(said)}, the wire log gives {_word(c['verdict'])}"
                                     + (f" ({reason[:160]})" if reason else ""))
    for cid, c in rejudged.items():
        if cid not in recorded:
            out.add(f"clause {cid}", f"missing from results.json; the wire log gives {_word(c['verdict'])}")
    if bool(results["partial"]) != got.partial:
        out.add("partial", f"results.json says {str(bool(results['partial'])).lower()}, the wire log says the run "
                           + (f"was cut short ({facts.partial})" if got.partial else "finished"))
    _compare_process(out, results.get("process"), got.process)
    if got.verdict != results["verdict"]:
        out.add("verdict", f"results.json says {_word(results['verdict'])}, the re-judged run gives "
                           f"{_word(got.verdict)} ({got.verdict_reason[:200]})")
    if "certificate" in results and got.certificate != results["certificate"]:
        out.add("certificate", f"results.json says {str(results['certificate']).lower()}, the re-judged "
                               f"run gives {str(got.certificate).lower()} ({got.scope.statement})")


def _patterns(select: Any) -> str:
    if not select:
        return "every clause (no --select)"
    return "--select " + ",".join(map(str, select)) if isinstance(select, list) else json.dumps(select)


def _compare_process(out: Verification, said: Any, evidence: Optional[dict]) -> None:
    if said is None and evidence is None:
        return
    if evidence is None:
        out.add("process", "results.json records the implementation under test's end, but the wire log has no "
                           "process note (helmcheck did not start it)")
        return
    if not isinstance(said, Mapping):
        out.add("process", "missing from results.json; the wire log records that helmcheck started the "
                           f"implementation under test and that it {_ending(evidence)}")
        return
    for key in sorted(set(said) | set(evidence)):
        if _normal(said.get(key)) != _normal(evidence.get(key)):
            out.add(f"process.{key}", f"results.json says {json.dumps(said.get(key))[:120]}, the wire log "
                                      f"records {json.dumps(evidence.get(key))[:120]}")


def _ending(process: Mapping[str, Any]) -> str:
    how = (f"was killed by {process.get('signal')}" if process.get("signal")
           else f"exited with code {process.get('exit_code')}")
    return how + (" before the run's end" if process.get("ended_early") else " when helmcheck stopped it")


# --------------------------------------------------------------------------- signature

def check_signature(out: Verification, directory: Path, results: Optional[Mapping[str, Any]], public_key,
                    public_key_name: str) -> None:
    """Step 6: the signature, if the run is signed; with *public_key* (a trusted Ed25519 public
    key, named *public_key_name* in findings) the run must be signed by it."""
    path = directory / _SIGNATURE_NAME
    declared = results.get("signature") if results is not None else None
    if not path.exists():
        if declared:
            out.add(_SIGNATURE_NAME, "missing, but results.json says the run was signed "
                                     f"(key {declared.get('key_id')})")
        elif public_key is not None:
            out.add("signature", f"the run is not signed (no {_SIGNATURE_NAME}); it cannot be checked against "
                                 f"{public_key_name}")
        return
    out.signed = True
    try:
        doc = json.loads(path.read_bytes().decode("utf-8"))
    except (OSError, UnicodeDecodeError, ValueError) as e:
        out.add(_SIGNATURE_NAME, f"cannot be read: {e}")
        return
    if not isinstance(doc, dict) or not isinstance(doc.get("manifest"), dict) \
            or not isinstance(doc.get("signature"), str) or not isinstance(doc.get("public_key"), str):
        out.add(_SIGNATURE_NAME, "not a helmcheck signature (needs public_key, manifest and signature)")
        return
    if doc.get("format") != _SIGNATURE_FORMAT:
        out.add(_SIGNATURE_NAME, f"format {doc.get('format')!r}; only {_SIGNATURE_FORMAT} is accepted")
    if doc["manifest"].get("format") != MANIFEST_FORMAT:
        out.add(_SIGNATURE_NAME, f"manifest format {doc['manifest'].get('format')!r}; only {MANIFEST_FORMAT} "
                                 f"is accepted")
    if doc.get("algorithm") != ALGORITHM:
        out.add(_SIGNATURE_NAME, f"algorithm {doc.get('algorithm')!r}; only {ALGORITHM} is accepted")
        return
    try:
        embedded = public_key_from_b64(doc["public_key"])
    except ValueError as e:
        out.add(_SIGNATURE_NAME, str(e))
        return
    signer = key_id(embedded)
    out.key_id = signer
    if doc.get("key_id") != signer:
        out.add(_SIGNATURE_NAME, f"key_id {doc.get('key_id')} is not the id of its public key ({signer})")
    if declared and declared.get("key_id") != signer:
        out.add(_SIGNATURE_NAME, f"signed by key {signer}, but results.json names key {declared.get('key_id')}")
    if results is not None and not declared:
        out.add(_SIGNATURE_NAME, "present, but results.json does not say the run was signed")
    from .signing import check
    if public_key is not None:
        trusted = key_id(public_key)
        out.trusted_key = trusted == signer
        if not out.trusted_key:
            # another key: say so, and check the signature with the key it names (whether the
            # files were changed is a question of its own, answered below)
            out.add("signature", f"made with key {signer}, not with the given key {public_key_name} (key {trusted}): "
                                 f"the run was signed by another key")
    if not check(embedded, doc["manifest"], doc["signature"]):
        out.add("signature", f"does not verify with the key it names ({signer}): the signed manifest or the "
                             f"signature was changed after signing")
        out.trusted_key = False
        return
    files = doc["manifest"].get("files")
    if not isinstance(files, dict):
        out.add(_SIGNATURE_NAME, "the signed manifest lists no files")
        return
    wanted = {RESULTS_NAME, PROFILE_NAME, evidence_files(results)[0] if results is not None else "wire.log",
              *(recorded_segments(results) if results is not None else ())}
    for name in sorted(wanted - set(files)):
        out.add(_SIGNATURE_NAME, f"the signed manifest does not cover {name}")
    for name, want, got in differing_files(directory, files):
        out.add(name, "missing, but it is signed" if got is None else
                f"SHA-256 {got} is not the signed {want}")
    tool = doc["manifest"].get("tool") or {}
    if results is not None and tool.get("version") != (results.get("tool") or {}).get("version"):
        out.add(_SIGNATURE_NAME, f"signed tool version {tool.get('version')} is not the "
                                 f"{(results.get('tool') or {}).get('version')} results.json records")
