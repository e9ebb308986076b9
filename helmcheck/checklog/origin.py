"""What a log says about the run that wrote it, and how ``check-log`` judges it by default.

A helmcheck wire log's header names the run that wrote it (:func:`helmcheck.grammar.wirelog.run_header`)::

    # helmcheck wire-log 1
    # started 2026-11-27T18:59:08Z  port /dev/pts/3  baud 19200  time_scale 40
    # helmcheck 0.1.0 certify vehicle; profile helmcheck/profiles/emulator.toml

This module owns reading that (:func:`read_origin`: an :class:`Origin` from the header lines
:func:`helmcheck.checklog.checker.log_meta` collected) and deciding from it what a check
of the log judges when the command line does not say (:func:`resolve`, a :class:`Judging`):

* **the role** — the role the run tested: a ``certify vehicle`` (``diff``, ``replay``) log is
  judged as the vehicle's (helmcheck played the backseat: its own lines, some malformed on
  purpose, are never judged as a backseat's), a ``certify backseat`` log as the backseat's, a
  ``monitor`` or ``emulate`` log as both; a log that names no run as the ``results.json`` of
  the results directory it sits in records, else both;
* **the profile** — the run directory's ``profile.toml`` beside the log (the resolved profile
  the run's judges used, as :func:`helmcheck.reports.certificate.finish_run` wrote it), else
  the profile the header names when it can be loaded here (``rh5``, the built-in emulator's, or
  a file that exists), else the ``rh5`` defaults with ``$OXFLT`` taken as honoured, as
  ``helmcheck emulate`` does;
* **the time scale and baud** — the header's (the checker reads them), else the profile's;
* **the missions** — the mission directories the header names (``emulate``) when they exist;
  a certification's own judges use none, so neither does its check.

``--role``, ``--profile``, ``--time-scale`` and ``--missions`` override each. What the header does
not say (an older log, a socat capture) is one line in :attr:`Judging.lacking`; the defaults
are used.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Optional

from ..grammar.wirelog import MISSIONS_SEP, read_run_header
from ..profile import DEFAULT, EMULATOR_PROFILE, Profile, ProfileError, emulator_profile, load_profile
from ..reports.manifest import PROFILE_NAME, RESULTS_NAME
from .records import LogMeta

__all__ = ["Origin", "Judging", "RUN_ROLES", "read_origin", "resolve"]

#: The run a header names -> the role its log is judged as: the implementation that run tested.
RUN_ROLES = {"certify vehicle": "vehicle", "diff": "vehicle", "replay": "vehicle",
             "certify backseat": "backseat", "monitor": "both", "emulate": "both"}


@dataclass(frozen=True)
class Origin:
    """What a log's header says about the run that wrote it (``None``: it does not say)."""

    run: Optional[str] = None  #: ``certify vehicle``, ``certify backseat``, ``monitor``, …
    version: Optional[str] = None  #: the helmcheck that wrote it
    profile: Optional[str] = None  #: the profile's name as the run gave it (a path, or ``rh5``)
    missions: tuple[str, ...] = ()  #: mission directories the run used
    time_scale: Optional[float] = None
    baud: Optional[int] = None

    @property
    def role(self) -> Optional[str]:
        """The role the run tested (``None``: the header names no run)."""
        return RUN_ROLES.get(self.run or "")


def read_origin(meta: LogMeta) -> Origin:
    """The :class:`Origin` of a log from its header lines (``meta.header``: each without ``#``)."""
    for text in meta.header or ():
        h = read_run_header(text)
        if h is not None:
            return Origin(run=h.run, version=h.version, profile=h.profile, missions=h.missions,
                          time_scale=meta.time_scale, baud=meta.baud)
    return Origin(time_scale=meta.time_scale, baud=meta.baud)


@dataclass
class Judging:
    """How one log is judged: what the command line said, else what its header says (module
    docstring), and where each came from, for the summary and ``results.json``."""

    role: str
    profile: Profile
    missions: Optional[list[Path]]  #: mission directories (``None``: no catalogue)
    time_scale: Optional[float]  #: ``--time-scale`` (``None``: the header's, else the profile's)
    origin: Origin
    sources: dict = field(default_factory=dict)  #: what -> where it came from (one phrase each)
    lacking: Optional[str] = None  #: one line: what the header does not say, and what was used
    profile_path: Optional[str] = None  #: the profile file read, if one was

    def describe(self) -> str:
        """One line: the role, profile, time scale and missions, each with where it came from."""
        parts = [f"{self.role} ({self.sources['role']})", f"profile {self.profile.name} ({self.sources['profile']})",
                 f"time scale {self.sources['time_scale']}"]
        if self.missions:
            parts.append(f"missions {MISSIONS_SEP.join(map(str, self.missions))} ({self.sources['missions']})")
        return "judged as: " + "; ".join(parts)

    def as_dict(self) -> dict:
        """For ``results.json`` (``log.origin``)."""
        o = self.origin
        return {"run": o.run, "tool_version": o.version, "profile": o.profile, "missions": list(o.missions),
                "time_scale": o.time_scale, "baud": o.baud, "judged_as": self.role,
                "profile_used": self.profile.name, "sources": dict(self.sources), "lacking": self.lacking}


def _run_profile(path: Path, origin: Origin) -> Optional[Path]:
    """The run directory's ``profile.toml`` beside the log, if the log is a run's (its header
    names one, or a ``results.json`` sits beside it)."""
    prof = path.parent / PROFILE_NAME
    if prof.is_file() and (origin.run is not None or (path.parent / RESULTS_NAME).is_file()):
        return prof
    return None


def _run_role(path: Path) -> Optional[str]:
    """The role the results directory the log sits in judged it as, if it is that run's log."""
    import json
    try:
        doc = json.loads((path.parent / RESULTS_NAME).read_bytes())
    except (OSError, ValueError):
        return None
    if not isinstance(doc, dict) or doc.get("wire_log", "wire.log") != path.name:
        return None
    role = doc.get("role")
    if role == "log":
        role = (doc.get("log") or {}).get("role") if isinstance(doc.get("log"), dict) else None
    return role if role in ("vehicle", "backseat", "both") else None


def _named_profile(name: str) -> tuple[Optional[Profile], Optional[str]]:
    """The profile a header names, if it can be loaded here: ``(profile, file read)``."""
    if name == DEFAULT.name:
        return DEFAULT, None
    if Path(name).is_file():
        try:
            return load_profile(name), name
        except ProfileError:
            return None, None
    if name.replace(os.sep, "/").endswith("helmcheck/" + EMULATOR_PROFILE):
        return emulator_profile(), None  # the built-in emulator's, as shipped with this helmcheck
    return None, None


def resolve(path: Path, meta: LogMeta, *, role: Optional[str] = None, profile_arg: Optional[str] = None,
            missions_arg: Optional[str] = None, time_scale: Optional[float] = None) -> Judging:
    """How to judge the log at *path* (whose head :func:`helmcheck.checklog.checker.log_meta`
    read into *meta*): each of *role*, *profile_arg* (a file), *missions_arg* (a directory) and
    *time_scale* as given, else from the header (module docstring). :class:`ProfileError` for a
    ``--profile`` that cannot be used (a usage error); a profile the header names that cannot be
    used is passed over, with a note."""
    origin = read_origin(meta)
    src: dict[str, str] = {}
    missing: list[str] = []
    named = f"a {origin.run} run, as its header says" if origin.run else ""
    recorded = _run_role(path) if role is None and origin.role is None else None
    if role is not None:
        src["role"] = "--role"
    elif origin.role is not None:
        role, src["role"] = origin.role, named
    elif recorded is not None:
        role, src["role"] = recorded, "the run's results.json"
    else:
        role, src["role"] = "both", "the default: the log names no run"
        missing.append("which run wrote it")
    profile_path: Optional[str] = None
    if profile_arg is not None:
        profile, src["profile"], profile_path = load_profile(profile_arg), "--profile", profile_arg
    else:
        profile = None
        unusable = ""
        run_prof = _run_profile(path, origin)
        if run_prof is not None:
            try:
                profile, src["profile"], profile_path = load_profile(run_prof), "the run's", str(run_prof)
            except ProfileError as e:
                unusable = f"; the run's {run_prof} cannot be used: {e}"
        if profile is None and origin.profile:
            profile, profile_path = _named_profile(origin.profile)
            if profile is not None:
                src["profile"] = "the one its header names"
        if profile is None:
            # Without a declared profile, $OXFLT is taken as honoured, as helmcheck emulate does.
            profile = DEFAULT.replace(fault_injection="oxflt")
            if origin.profile:
                src["profile"] = f"the default: the header's {origin.profile} is not here{unusable}"
                missing.append(f"a profile that can be read here ({origin.profile})")
            else:
                src["profile"] = f"the default{unusable}"
                missing.append("the profile")
    if time_scale is not None:
        src["time_scale"] = f"{time_scale:g} (--time-scale)"
    elif meta.time_scale is not None:
        src["time_scale"] = f"{meta.time_scale:g} (the header's)"
    else:
        src["time_scale"] = f"{profile.time_scale or 1.0:g} (the profile's)"
        missing.append("the time scale")
    missions: Optional[list[Path]] = None
    if missions_arg is not None:
        missions, src["missions"] = [Path(missions_arg)], "--missions"
    elif origin.missions:
        there = [Path(d) for d in origin.missions if Path(d).is_dir()]
        if there:
            missions, src["missions"] = there, "the header's"
        if len(there) < len(origin.missions):
            missing.append("mission directories that are here ("
                           + ", ".join(d for d in origin.missions if not Path(d).is_dir()) + " are not)")
    lacking = None
    if missing:
        lacking = (f"the log's header does not say {_and(missing)}"
                   f"{' (a log written before headers named them, or not by helmcheck)' if not origin.run else ''}: "
                   f"the defaults are used; --role, --profile, --time-scale and --missions choose")
    return Judging(role=role, profile=profile, missions=missions, time_scale=time_scale, origin=origin,
                   sources=src, lacking=lacking, profile_path=profile_path)


def _and(items: list[str]) -> str:
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " or " + items[-1]
