"""``helmcheck profile init [PATH]``: write a commented profile for a real vehicle to fill in;
``helmcheck profile keys``: list every key; ``helmcheck profile readings``: the readings table
(:mod:`helmcheck.model.readings`).

The text is :func:`helmcheck.profile_template.render` — every key of
:class:`~helmcheck.profile.Profile` with its documentation, allowed values and a safe starting
value, ``FILL IN`` on those only the vehicle can give. Options prefill keys (``--name``,
``--serial``, ``--uvc-version``, ``--mission``, ``--baud``, ``--set KEY=VALUE``, ``--emulator``);
the result is loaded back as ``--profile`` will load it before anything is written, so a bad
value is a usage error naming the key. ``PATH`` omitted or ``-``: standard output. An existing
file is refused unless ``--overwrite``; the file is written atomically.

Exit status: 0 written; 64 usage (a bad option or value, a file that exists, a path that cannot
be written); 2 a write that failed after the checks (:class:`~helmcheck.failures.OutputLost`).
"""

from __future__ import annotations

import argparse
import sys
import tomllib
from pathlib import Path
from typing import Any

from .. import exitcodes

EPILOG = """\
what you get:
  Every profile key, grouped (identity, link, missions, safety, protocol claims), each with what
  it is, its clauses, the values it takes and a starting value that is safe on the bench:
  violation_trigger = "none" (no safety violation is raised), end_mission = srp_mission = ""
  (no mission assumed on the vehicle but the test mission), bench safety on. Keys marked
  FILL IN need a value from the vehicle (its name, serial, UVC version, baud, test mission …).
  The file loads as it is; a key you delete takes the rh5 default.

--set KEY=VALUE takes a TOML value (a string may be given bare: --set mission=survey.mis);
bench_safety.KEY for the [bench_safety] table; 'helmcheck profile keys' lists every key.

examples:
  helmcheck profile init iver3-042.toml --name IVER3-042 --serial 3042 --uvc-version 5.2.1
  helmcheck profile init --set baud=57600 --set 'commands=["OMS","OMP","OSD","OMSTOP","OMSTART"]'
  helmcheck profile init --emulator emu.toml       # the built-in emulator's claims, all keys
  helmcheck certify vehicle --port /dev/ttyUSB0 --profile iver3-042.toml

exit status: 0 written, 64 usage (bad option or value, existing file without --overwrite,
  unwritable path), 2 the write failed.
"""

PROFILE_EPILOG = """\
examples:
  helmcheck profile init my-vehicle.toml            # a commented profile to fill in
  helmcheck profile keys                            # every key, one line each
  helmcheck profile readings                        # every question the profile leaves open

exit status: 0 written or listed, 64 usage, 2 a write that failed.
"""

KEYS_EPILOG = """\
examples:
  helmcheck profile keys
  helmcheck profile keys | grep -i mission

exit status: 0 listed.
"""

#: option -> profile key, for the common identity fields.
SHORTCUTS = {"name": "vehicle_name", "serial": "vehicle_serial", "uvc_version": "uvc_version",
             "mission": "mission", "baud": "baud"}


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = sub.add_parser("profile", help="write a commented profile for a vehicle; list the profile keys",
                       description="Write a commented profile for a vehicle to fill in, or list every profile "
                                   "key. A profile declares what an implementation claims (reference "
                                   "profile §10).",
                       epilog=PROFILE_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    actions = p.add_subparsers(dest="action", metavar="ACTION", parser_class=type(p))
    ip = actions.add_parser("init", help="write a commented TOML profile for a real vehicle to fill in",
                            description="Write a commented TOML profile for a real vehicle: every key with "
                                        "its documentation and a safe starting value; FILL IN marks what "
                                        "only the vehicle can tell.",
                            epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    ip.add_argument("path", nargs="?", default="-", metavar="PATH",
                    help="where to write it (default, or '-': standard output)")
    ip.add_argument("--overwrite", action="store_true", help="replace PATH if it exists")
    ip.add_argument("--name", metavar="NAME", help="vehicle_name: the vehicle's name ($OSI field 18)")
    ip.add_argument("--serial", metavar="SERIAL", help="vehicle_serial: its serial number")
    ip.add_argument("--uvc-version", metavar="VERSION", help="uvc_version: the UVC version it runs")
    ip.add_argument("--mission", metavar="NAME", help="mission: the test mission on the vehicle")
    ip.add_argument("--baud", type=int, metavar="N", help="baud: the serial line's rate")
    ip.add_argument("--set", dest="sets", action="append", default=[], metavar="KEY=VALUE",
                    help="any key (bench_safety.KEY for the table); VALUE in TOML, or a bare string")
    ip.add_argument("--emulator", action="store_true",
                    help="start from the built-in emulator's profile ($OXFLT, its missions) instead of a "
                         "real vehicle's safe values")
    ip.set_defaults(func=run_init)
    kp = actions.add_parser("keys", help="list every profile key with what it is and its default",
                            description="List every key a profile file may hold: its name, what it is, the "
                                        "clauses it serves and its rh5 default, one line each.",
                            epilog=KEYS_EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    kp.set_defaults(func=run_keys)
    rp = actions.add_parser("readings", help="list every question the profile leaves open, and every answer accepted",
                            description="List the readings table: every question the reference profile's words "
                                        "leave open (clause, question, the profile's words), every reading "
                                        "helmcheck accepts, how the judge accepts each and the emulator setting "
                                        "that takes each.",
                            epilog="examples:\n  helmcheck profile readings\n  helmcheck profile readings --markdown"
                                   "\n\nexit status: 0 listed.",
                            formatter_class=argparse.RawDescriptionHelpFormatter)
    rp.add_argument("--markdown", action="store_true", help="as the Markdown table of the docs site")
    rp.set_defaults(func=run_readings)
    p.set_defaults(func=_no_action)
    return p


def _no_action(args: argparse.Namespace) -> int:
    from ..failures import UsageError

    raise UsageError("choose an action: init, keys or readings (see 'helmcheck profile --help')")


def _keys() -> dict[str, Any]:
    """Every key a file may hold (``bench_safety.x`` flattened) -> its default."""
    import dataclasses

    from ..profile import BenchSafety, profile_keys

    out: dict[str, Any] = {}
    for f in profile_keys():
        if f.name == "bench_safety":
            out.update({f"bench_safety.{g.name}": g.default for g in dataclasses.fields(BenchSafety)})
        else:
            out[f.name] = f.default
    return out


def _parse_set(item: str, keys: dict[str, Any]) -> tuple[str, Any]:
    from ..failures import UsageError

    key, eq, text = item.partition("=")
    key = key.strip()
    if not eq or not key:
        raise UsageError(f"--set {item!r}: expected KEY=VALUE")
    if key not in keys:
        from ..spelling import did_you_mean
        raise UsageError(f"--set: unknown key {key!r}{did_you_mean(key, keys)}; every key: helmcheck profile keys")
    try:
        value = tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        if not isinstance(keys[key], str):
            raise UsageError(f"--set {key}: {text!r} is not a TOML value") from None
        value = text  # a bare string
    return key, value


def _emulator_values() -> dict[str, Any]:
    from importlib import resources

    from ..profile import EMULATOR_PROFILE

    data = tomllib.loads(resources.files("helmcheck").joinpath(EMULATOR_PROFILE).read_text(encoding="utf-8"))
    flat: dict[str, Any] = {}
    for k, v in data.items():
        if isinstance(v, dict):
            flat.update({f"{k}.{kk}": vv for kk, vv in v.items()})
        else:
            flat[k] = v
    return flat


def run_readings(args: argparse.Namespace) -> int:
    """``profile readings``: the readings table (:mod:`helmcheck.model.readings`)."""
    from ..model import readings
    print(readings.markdown() if args.markdown else readings.text(), end="")
    return exitcodes.OK


def run_keys(args: argparse.Namespace) -> int:  # noqa: ARG001 - the command's signature
    """``profile keys``: every key, one line each (the profile's own key table)."""
    import dataclasses

    from ..profile import BenchSafety, profile_keys

    rows = []
    for f in profile_keys():
        fields = ([(f"bench_safety.{g.name}", g) for g in dataclasses.fields(BenchSafety)]
                  if f.name == "bench_safety" else [(f.name, f)])
        for name, g in fields:
            meta = g.metadata
            default = g.default if g.default is not dataclasses.MISSING else g.default_factory()  # type: ignore[misc]
            where = "; ".join(x for x in (meta.get("group", ""), meta.get("clause", "")) if x)
            rows.append((name, f"{meta.get('doc', '')} ({where}; default {_toml(default)})"))
    width = max(len(n) for n, _ in rows)
    for name, text in rows:
        print(f"{name:<{width}}  {text}")
    return exitcodes.OK


def _toml(value: Any) -> str:
    from ..profile_toml import toml_value
    try:
        return toml_value(value)
    except (TypeError, ValueError):
        return repr(value)


def run_init(args: argparse.Namespace) -> int:
    from ..failures import OutputLost, PathError
    from ..outputs import check_writable
    from ..profile import ProfileError
    from ..profile_template import check, render
    from ..reports.atomic import write_text_atomic

    keys = _keys()
    prefill: dict[str, Any] = _emulator_values() if args.emulator else {}
    for opt, key in SHORTCUTS.items():
        value = getattr(args, opt)
        if value is not None:
            prefill[key] = value
    for item in args.sets:
        key, value = _parse_set(item, keys)
        prefill[key] = value
    text = render(prefill, emulator=args.emulator)
    try:
        check(text, where="helmcheck profile init")
    except ProfileError as e:  # a prefilled value the loader refuses: exit 64, naming the key
        raise ProfileError(str(e).replace("helmcheck profile init: ", "", 1)) from None
    except tomllib.TOMLDecodeError as e:  # pragma: no cover - the renderer writes valid TOML
        raise RuntimeError(f"profile template is not valid TOML: {e}") from None
    if args.path == "-":
        sys.stdout.write(text)
        return exitcodes.OK
    path = check_writable(args.path, "PATH")
    if path.exists() and not args.overwrite:
        raise PathError(f"{path} exists; --overwrite replaces it")
    try:
        write_text_atomic(path, text)
    except OSError as e:
        raise OutputLost(f"cannot write {Path(e.filename or path)}: {e.strerror or e}") from None
    print(f"wrote {path}: fill in the keys marked FILL IN, then: "
          f"helmcheck certify vehicle --port PORT --profile {path}", file=sys.stderr)
    return exitcodes.OK
