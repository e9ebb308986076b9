"""Checking a results directory against its evidence (``helmcheck verify DIR``).

:func:`verify_run` trusts nothing in ``results.json`` that the evidence can decide. In order:

1. ``results.json`` must parse and be a valid schema-1 document (:func:`~.schema.validate`);
2. the wire log and ``profile.toml`` must have the SHA-256 that ``results.json`` records
   (``digests``), so one changed byte shows even in an unsigned run;
3. ``profile.toml`` must load (:func:`helmcheck.profile.load_profile`) and be the profile
   ``results.json`` records (``profile``, key by key);
4. the wire log is **re-judged** under that profile by the offline observer
   (:func:`helmcheck.conformance.checklog.check_log`, role ``vehicle`` or ``backseat`` as
   recorded, the recorded time scale), and every clause verdict, the run verdict and the
   ``certificate`` flag of ``results.json`` must be the ones the re-judged verdicts give. Only
   verdict words are compared, not reasons or evidence. Clauses a ``--select`` run did not select
   must be NOT-TESTED — or a FAIL the run observed anyway, which is re-judged like the others;
5. if the run is signed (``signature.json``, :mod:`.certificate`), the Ed25519 signature must
   hold over the manifest and the manifest must name the files as they are now; with a trusted
   public key (``--public-key``) the signature must be that key's, and an unsigned run fails.

Every difference is a :class:`Finding` naming the file or clause. A directory that is not a
results directory at all raises :class:`VerifyUsageError` (exit 64).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from fnmatch import fnmatchcase
from pathlib import Path
from typing import Any, Mapping, Optional

from .manifest import PROFILE_NAME, RESULTS_NAME, differing_files, evidence_files, sha256_file
from .results import parse_results
from .schema import validate
from .scope import scope_of
from .signing import ALGORITHM, key_id, public_key_from_b64
from .verdicts import run_verdict
from .view import VERDICT_LABEL

__all__ = ["Finding", "Verification", "VerifyUsageError", "verify_run"]

_SIGNATURE_NAME = "signature.json"
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
    """The outcome of :func:`verify_run`."""

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


def verify_run(directory: Path | str, public_key=None, *, public_key_name: str = "the given public key") -> Verification:
    """Check *directory* (module docstring). *public_key*: a trusted Ed25519 public key or ``None``."""
    directory = Path(directory)
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
    if results is not None:
        _check_digests(out, directory, results)
        profile = _check_profile(out, directory, results)
        if profile is not None:
            _rejudge(out, directory, results, profile)
    _check_signature(out, directory, results, public_key, public_key_name)
    return out


# --------------------------------------------------------------------------- digests, profile

def _check_digests(out: Verification, directory: Path, results: Mapping[str, Any]) -> None:
    recorded = results.get("digests")
    wire_name, _ = evidence_files(results)
    if not isinstance(recorded, Mapping):
        out.add(RESULTS_NAME, "records no digests of the wire log and profile (a run made before they were "
                              "recorded cannot be verified)")
        return
    for name in (wire_name, PROFILE_NAME):
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


def _check_profile(out: Verification, directory: Path, results: Mapping[str, Any]):
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

def _selected(results: Mapping[str, Any], cid: str) -> bool:
    select = (results.get("settings") or {}).get("select") or []
    if not isinstance(select, list) or not select:
        return True
    return any(isinstance(p, str) and fnmatchcase(cid, p) for p in select)


def _rejudge(out: Verification, directory: Path, results: Mapping[str, Any], profile) -> None:
    from ..conformance.checklog.checker import LogFormatError, check_log

    role = results["role"]
    if role == "log":
        role = (results.get("log") or {}).get("role") or "both"
    time_scale = results["settings"].get("time_scale")
    wire_name, _ = evidence_files(results)
    wire_path = directory / wire_name
    if not wire_path.is_file():
        out.add(wire_name, "missing: there is no evidence to re-judge")
        return
    try:
        outcome = check_log(wire_path, profile=profile, role=role,
                            time_scale=float(time_scale) if time_scale else None)
    except (LogFormatError, OSError, ValueError) as e:
        out.add(wire_name, f"cannot be re-judged: {e}")
        return
    rejudged = {c["id"]: c for c in outcome.clauses}
    recorded = {c["id"]: c for c in results["clauses"]}
    verdicts: dict[str, str] = {}
    for cid, entry in recorded.items():
        said = entry["verdict"]
        if not _selected(results, cid) and said not in ("fail", "non-strict"):
            # outside the selection only what was observed to fail is reported; it is re-judged
            verdicts[cid] = said
            if said != "not-tested":
                out.add(f"clause {cid}", f"results.json says {_word(said)}, but the run did not select it "
                                         f"(--select {' '.join(results['settings']['select'])})")
            continue
        got = rejudged.get(cid)
        if got is None:
            verdicts[cid] = said
            out.add(f"clause {cid}", f"results.json says {_word(said)}; re-judging the wire log as a {role} "
                                     f"run does not judge this clause")
            continue
        verdicts[cid] = got["verdict"]
        out.clauses_compared += 1
        if got["verdict"] != said:
            reason = " ".join(str(got.get("reason") or "").split())
            out.add(f"clause {cid}", f"results.json says {_word(said)}, the wire log gives {_word(got['verdict'])}"
                                     + (f" ({reason[:160]})" if reason else ""))
    for cid, got in rejudged.items():
        if cid not in recorded and _selected(results, cid) and got["verdict"] != "not-tested":
            verdicts[cid] = got["verdict"]
            out.add(f"clause {cid}", f"missing from results.json; the wire log gives {_word(got['verdict'])}")
    strict = bool(results["settings"].get("strict", False))
    ordered = [verdicts[cid] for cid in verdicts]
    expected = run_verdict(ordered, strict=strict, partial=bool(results["partial"]))
    if expected != results["verdict"]:
        out.add("verdict", f"results.json says {_word(results['verdict'])}, the re-judged clauses give "
                           f"{_word(expected)}")
    if "certificate" in results:
        scope = scope_of(results, verdicts)
        if scope.certificate != results["certificate"]:
            out.add("certificate", f"results.json says {str(results['certificate']).lower()}, the re-judged "
                                   f"clauses give {str(scope.certificate).lower()} ({scope.statement})")
    tool = results.get("tool") or {}
    from helmcheck import __version__
    if tool.get("version") != __version__:
        out.notes.append(f"recorded by helmcheck {tool.get('version')}, re-judged by helmcheck {__version__}")


# --------------------------------------------------------------------------- signature

def _check_signature(out: Verification, directory: Path, results: Optional[Mapping[str, Any]], public_key,
                     public_key_name: str) -> None:
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
    key = embedded
    if public_key is not None:
        trusted = key_id(public_key)
        if trusted != signer:
            out.add("signature", f"made with key {signer}, not with {public_key_name} (key {trusted})")
        key = public_key
        out.trusted_key = trusted == signer
    if not check(key, doc["manifest"], doc["signature"]):
        out.add("signature", "does not verify: the signed manifest was changed or the signature is not this key's")
        out.trusted_key = False
        return
    files = doc["manifest"].get("files")
    if not isinstance(files, dict):
        out.add(_SIGNATURE_NAME, "the signed manifest lists no files")
        return
    wanted = {RESULTS_NAME, PROFILE_NAME, evidence_files(results)[0] if results is not None else "wire.log"}
    for name in sorted(wanted - set(files)):
        out.add(_SIGNATURE_NAME, f"the signed manifest does not cover {name}")
    for name, want, got in differing_files(directory, files):
        out.add(name, "missing, but it is signed" if got is None else
                f"SHA-256 {got} is not the signed {want}")
    tool = doc["manifest"].get("tool") or {}
    if results is not None and tool.get("version") != (results.get("tool") or {}).get("version"):
        out.add(_SIGNATURE_NAME, f"signed tool version {tool.get('version')} is not the "
                                 f"{(results.get('tool') or {}).get('version')} results.json records")
