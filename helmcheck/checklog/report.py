"""Writing a log check's results directory: ``results.json`` (role ``log``), the log, the reports.

This module owns turning a :class:`~.checker.CheckOutcome` into a schema-1 results document
(:mod:`helmcheck.reports.results`; the clause entries, run verdict and ``process`` assembled from
the check's ledger entries and run facts by :func:`helmcheck.reports.assemble.assemble`, the one
function every certifier and ``helmcheck verify`` use) and a results directory: ``results.json`` (atomic), the
checked log as ``wire.log`` (a copy for a helmcheck wire log; for a socat capture the copy keeps
its own name and ``wire.log`` is not written; above :data:`COPY_LIMIT` bytes the log is only
referenced by path and SHA-256), closed as a certificate like every run
(:func:`helmcheck.reports.certificate.finish_run`: ``profile.toml`` — the profile the check
used, at the check's time scale —, the digests of the log and the profile, the identity), so
``helmcheck verify`` re-judges it; and every report format (:func:`helmcheck.reports.render_all`).

``settings`` records what a re-judging needs besides the log and the profile: ``time_scale``,
``strict``, ``role`` (the role judged), ``missions`` (the mission directories used, or absent)
and ``swap_directions``; ``log.origin`` what the log's header said and where the role, profile,
time scale and missions came from (:mod:`.origin`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Optional

from ..profile import Profile
from ..reports import results as R
from ..reports.assemble import apply, assemble
from ..reports.atomic import copy_file_atomic
from ..reports.certificate import RunDeclaration, finish_run
from ..reports.render import render_all
from .checker import CheckOutcome

__all__ = ["build_results", "write_report_dir", "COPY_LIMIT"]

COPY_LIMIT = 32 * 1024 * 1024


def build_results(out: CheckOutcome, profile: Profile, command: str, *, strict: bool = False,
                  wire_log: str = "wire.log", settings: Optional[dict[str, Any]] = None,
                  origin: Optional[dict[str, Any]] = None) -> dict[str, Any]:
    """The results document for one checked log (finished, so its verdict is valid);
    *settings*: more of what the check was run with (module docstring), *origin*: ``log.origin``."""
    res = R.new_results("log", command=command,
                        implementation={"protocol": profile.protocol, "osi_fields": profile.osi_fields,
                                        "fault_injection": profile.fault_injection},
                        profile=profile.as_dict(),
                        settings={"time_scale": out.time_scale, "strict": strict, "role": out.role,
                                  **({"select": list(out.facts.select)} if out.facts.select else {}),
                                  **(settings or {})}, wire_log=wire_log)
    entries = [{**c, "cases": [f"log:{out.path.name}", *c.get("cases", ())]} for c in out.clauses]
    if out.segments:  # the session goes on in these files beside the first (helmcheck.reports.segments)
        res["wire_segments"] = list(out.segments)
    apply(res, assemble("log", entries, out.facts, strict=strict), duration_s=round(out.seconds, 3))
    res["timeline"] = out.timeline
    res["events"] = out.events
    res["log"] = {
        "source": str(out.path.resolve()), "sha256": out.sha256, "format": out.format,
        "role": out.role, "time_scale": out.time_scale, "timestamp_resolution_s": out.resolution,
        "one_direction": out.one_direction, "mission_files": out.mission_known,
        "header": out.meta.header, "stats": out.stats, "findings": out.findings,
        "check_seconds": round(out.seconds, 3),
    }
    if origin is not None:
        res["log"]["origin"] = origin
    if out.one_direction:
        res["log"]["one_direction_note"] = (
            f"The log carries traffic of one side only ({out.one_direction}); clauses that need "
            f"the other side are NOT-TESTED.")
    return res


def write_report_dir(directory: Path, out: CheckOutcome, profile: Profile, command: str, *,
                     strict: bool = False, render: bool = True, settings: Optional[dict[str, Any]] = None,
                     origin: Optional[dict[str, Any]] = None,
                     declaration: Optional[RunDeclaration] = None) -> dict[str, Any]:
    """Write the results directory (module docstring); returns the results document.
    ``OSError``/``ReportError``."""
    profile = profile.replace(time_scale=out.time_scale)  # profile.toml holds the check's time scale
    directory.mkdir(parents=True, exist_ok=True)
    segments = [out.path.parent / name for name in out.segments]
    size = sum(p.stat().st_size for p in (out.path, *segments))
    wire_name = "wire.log"
    copied: Optional[str] = None
    if size <= COPY_LIMIT:
        if out.format == "wirelog":
            copied = wire_name
        else:
            copied = "capture-" + out.format + ".log"
            wire_name = copied
        if out.path.resolve() != (directory / copied).resolve():
            copy_file_atomic(out.path, directory / copied)
            for p in segments:  # each further segment under its own name: the first one's note names it
                copy_file_atomic(p, directory / p.name)
    res = build_results(out, profile, command, strict=strict, wire_log=wire_name, settings=settings, origin=origin)
    res["log"]["copy"] = copied
    if copied is None:
        res["log"]["copy_note"] = (f"The log ({size} bytes) is larger than {COPY_LIMIT} bytes; it is "
                                   f"referenced by path and SHA-256, not copied.")
    finish_run(res, directory, profile, declaration)  # profile.toml, digests, identity; results.json written
    if render:
        render_all(directory)
    return res
