"""Identity: what was tested, by whom, where, under which profile, with which tester.

``results.json`` key ``identity`` (written by :func:`helmcheck.reports.certificate.finish_run`)::

    {"implementation": {"role": "vehicle", "name": …, "serial": …, "version": …, "name_on_wire": …},
     "operator": …, "site": …,
     "profile_sha256": HEX, "profile_file": {"path": …, "sha256": HEX} | null,
     "tester": {"name": "helmcheck", "version": "0.1.0", "revision": "git describe" | "unknown"}}

* A **vehicle** is named by its profile (``vehicle_name``, ``vehicle_serial``, ``uvc_version`` —
  what the owner declares; ``version`` is the UVC/firmware version) and by what it says itself:
  ``name_on_wire`` is field 18 of the first ``$OSI`` in the wire log (RH-OUT-1).
* A **backseat** is named by ``certify backseat --implementation NAME[@VERSION]``, else by the
  command ``--exec`` ran (``process.command``, :func:`backseat_name`); the vehicle helmcheck
  played is not the implementation under test and is named nowhere a report names the
  implementation (its ``$OSI`` name is helmcheck's own).
* ``operator`` and ``site`` are what ``--operator`` / ``--site`` said (``null`` when not given).
* ``profile_sha256`` is the SHA-256 of ``profile.toml`` in the run directory (the resolved
  profile the judges used); ``profile_file`` the path and SHA-256 of the file given with
  ``--profile``, if any, so it can be matched with the owner's copy.
* ``revision`` is ``git describe --always --dirty --tags`` of the checkout the running helmcheck
  package lives in, or ``unknown`` when it is not in a git checkout (an installed wheel). It is
  read once per process (:func:`source_revision`), by the commands that record it before they
  write anything (:data:`helmcheck.cli.RECORDS_REVISION`, ``make demo``): a run whose results go
  into a tracked directory (``make example-report``) is not ``-dirty`` by its own files.

Empty declared values are ``null``. :func:`identity_rows` is the one list of labelled rows every
rendering shows, so the HTML, Markdown and JUnit reports name the implementation alike.
"""

from __future__ import annotations

import subprocess
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any, Mapping, Optional

import helmcheck

__all__ = ["Declared", "parse_implementation", "source_revision", "build_identity", "identity_rows", "still_going",
           "backseat_name", "EXEC_NAMED"]


@dataclass(frozen=True)
class Declared:
    """What the command line declared about a run (``--operator``, ``--site``, ``--implementation``)."""

    operator: Optional[str] = None
    site: Optional[str] = None
    implementation_name: Optional[str] = None
    implementation_version: Optional[str] = None
    profile_file: Optional[str] = None  #: the ``--profile`` path, if one was given


def parse_implementation(text: str) -> tuple[str, Optional[str]]:
    """``NAME[@VERSION]`` → ``(name, version or None)``; ``ValueError`` for an empty name."""
    if "@" in text:
        name, _, version = text.rpartition("@")
        if not version.strip():
            raise ValueError(f"--implementation {text!r}: nothing after '@' (give NAME@VERSION)")
    else:
        name, version = text, ""
    if not name.strip():
        raise ValueError(f"--implementation {text!r}: give NAME or NAME@VERSION")
    return name.strip(), (version.strip() or None)


@lru_cache(maxsize=1)
def source_revision() -> str:
    """``git describe`` of the checkout holding the helmcheck package, else ``unknown``."""
    pkg = Path(helmcheck.__file__).resolve().parent
    root = pkg.parent

    def git(*args: str) -> Optional[str]:
        try:
            done = subprocess.run(["git", "-C", str(root), *args], capture_output=True, text=True, timeout=10,
                                  stdin=subprocess.DEVNULL)
        except (OSError, subprocess.SubprocessError):
            return None
        return done.stdout.strip() if done.returncode == 0 and done.stdout.strip() else None

    top = git("rev-parse", "--show-toplevel")
    if top is None or Path(top).resolve() != root:
        return "unknown"  # the package is not the top of a checkout (e.g. in site-packages)
    return git("describe", "--always", "--dirty", "--tags") or "unknown"


def _or_none(value: Any) -> Optional[str]:
    return value if isinstance(value, str) and value.strip() else None


def build_identity(results: Mapping[str, Any], profile, *, declared: Declared, profile_sha256: str,
                   profile_file_sha256: Optional[str], name_on_wire: Optional[str]) -> dict[str, Any]:
    """The ``identity`` object of a finished run (module docstring)."""
    role = results.get("role")
    if role == "backseat":
        impl = {"role": "backseat", "name": _or_none(declared.implementation_name),
                "version": _or_none(declared.implementation_version)}
    else:
        impl = {"role": role, "name": _or_none(profile.vehicle_name), "serial": _or_none(profile.vehicle_serial),
                "version": _or_none(profile.uvc_version), "name_on_wire": name_on_wire}
    tool = results.get("tool") or {}
    return {
        "implementation": impl,
        "operator": _or_none(declared.operator),
        "site": _or_none(declared.site),
        "profile_sha256": profile_sha256,
        "profile_file": ({"path": declared.profile_file, "sha256": profile_file_sha256}
                         if declared.profile_file else None),
        "tester": {"name": tool.get("name", "helmcheck"), "version": tool.get("version", helmcheck.__version__),
                   "revision": source_revision()},
    }


_NOT_GIVEN = "not given"
#: Said after a backseat named by the command ``--exec`` ran (no ``--implementation``).
EXEC_NAMED = "the command --exec ran; --implementation NAME@VERSION names it"


def backseat_name(results: Mapping[str, Any]) -> tuple[Optional[str], bool]:
    """The backseat under test as the reports name it, and whether that is the ``--exec``
    command: its ``--implementation`` name (``NAME@VERSION``), else the command helmcheck
    started it with, else ``(None, False)``."""
    ident = results.get("identity") if isinstance(results.get("identity"), Mapping) else {}
    impl = ident.get("implementation") or {}
    name = impl.get("name") if isinstance(impl.get("name"), str) and impl.get("name") else None
    if name:
        version = impl.get("version")
        return (f"{name}@{version}" if isinstance(version, str) and version else name), False
    proc = results.get("process")
    command = proc.get("command") if isinstance(proc, Mapping) else None
    if isinstance(command, str) and command.strip():
        return " ".join(command.split()), True
    return None, False


def still_going(results: Mapping[str, Any]) -> bool:
    """A document written while its run was still going (``finished`` null, or a monitor's check
    of the session so far): the run's end records the certificate."""
    monitor = results.get("monitor")
    return results.get("finished") is None or (isinstance(monitor, Mapping) and bool(monitor.get("in_progress")))


def _unrecorded(results: Mapping[str, Any]) -> str:
    """Why a document has no identity, as far as the document itself tells."""
    if still_going(results):
        return "not recorded yet: results.json was written while the run was still going (its end records it)"
    return "not recorded in results.json"


def identity_rows(results: Mapping[str, Any], wire_name: Optional[str] = None) -> list[tuple[str, str, bool]]:
    """``(label, value, missing)`` rows naming what was tested; *missing* marks a value that a
    certificate should carry but the run did not record.

    Works for documents without ``identity`` (a run still going, or a document written by an
    earlier helmcheck): the implementation is then taken from ``implementation`` and *wire_name*
    (the ``$OSI`` name in the wire log), and the rest is shown as not recorded, saying why when
    the document tells (:func:`still_going`).
    """
    ident = results.get("identity") if isinstance(results.get("identity"), Mapping) else None
    role = results.get("role")
    rows: list[tuple[str, str, bool]] = []

    def row(label: str, value: Any, required: bool = True) -> None:
        text = value if isinstance(value, str) and value else None
        rows.append((label, text or _NOT_GIVEN, required and text is None))

    if ident is None:
        legacy = results.get("implementation") or {}
        if role == "backseat":
            name, by_exec = backseat_name(results)
            row("backseat", f"{name} ({EXEC_NAMED})" if by_exec else name)
        else:
            row("vehicle", legacy.get("vehicle_name") or wire_name)
            row("name on the wire ($OSI 18)", wire_name)
        row("port", legacy.get("port"), required=False)
        tool = results.get("tool") or {}
        row("tester", f"{tool.get('name', 'helmcheck')} {tool.get('version', '?')}")
        rows.append(("identity", _unrecorded(results), True))
        return rows
    impl = ident.get("implementation") or {}
    if impl.get("role") == "backseat":
        name, by_exec = backseat_name(results)
        row("backseat", f"{name} ({EXEC_NAMED})" if by_exec else impl.get("name"))
        row("backseat version", impl.get("version"))
    else:
        row("vehicle", impl.get("name"))
        row("serial number", impl.get("serial"))
        row("UVC / firmware version", impl.get("version"))
        seen, declared = impl.get("name_on_wire"), impl.get("name")
        if seen and declared and seen != declared:
            rows.append(("name on the wire ($OSI 18)", f"{seen} (differs from the profile's vehicle_name)", True))
        else:
            row("name on the wire ($OSI 18)", seen)
    row("operator", ident.get("operator"), required=False)
    row("site", ident.get("site"), required=False)
    port = (results.get("implementation") or {}).get("port")
    row("port", port, required=False)
    row("profile SHA-256", ident.get("profile_sha256"))
    pf = ident.get("profile_file")
    if isinstance(pf, Mapping) and pf.get("path"):
        row("profile file", f"{pf.get('path')} (SHA-256 {pf.get('sha256') or 'unreadable'})", required=False)
    tester = ident.get("tester") or {}
    row("tester", f"{tester.get('name', 'helmcheck')} {tester.get('version', '?')} "
                  f"(revision {tester.get('revision') or 'unknown'})")
    return rows
