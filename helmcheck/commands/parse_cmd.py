"""``helmcheck parse``: validate sentences line by line, from files, stdin or wire logs.

Each input line is either a bare sentence (``$OMS,…*hh``) or a wire-log record
(``12.345678 > $OMS,…*hh``, see :mod:`helmcheck.grammar.capture`); the format is detected per
line, so a wire log can be validated as it is. Invalid lines print as
``FILE:LINE: CLAUSE: message``; ``--json`` prints one JSON object per line instead.
Exit 0 when every line is valid, 1 when any is not, 64 on usage errors.
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import IO, Iterator

from .. import exitcodes
from ..grammar import decode
from ..grammar.capture import WireLogError, parse_record
from ..profile import Profile, ProfileError, load_profile

EPILOG = """\
examples:
  helmcheck parse capture.txt               # one sentence per line
  helmcheck parse wire.log --json           # a wire log written by emulate/certify --log
  printf '$OMSTOP,0*06\\r\\n' | helmcheck parse -

A line is judged against the reference profile: framing and checksum (RH-FRM-*), the grammar,
and value ranges from the profile (--profile FILE; default rh5). Wire-log comment lines (#) and
notes (!) are skipped.
"""


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = sub.add_parser("parse", help="validate sentences line by line",
                       description=__doc__.split("\n\n")[0].split(": ", 1)[1],
                       epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("files", nargs="*", default=["-"], metavar="FILE",
                   help="files to read ('-' or nothing: standard input)")
    p.add_argument("--profile", metavar="FILE", help="TOML profile (default: rh5)")
    p.add_argument("--json", action="store_true", help="one JSON object per input line")
    p.set_defaults(func=run)
    return p


def _lines(name: str) -> Iterator[bytes]:
    if name == "-":
        yield from sys.stdin.buffer
        return
    with open(name, "rb") as f:
        yield from f


def _check_file(name: str, profile: Profile, as_json: bool, out: IO[str]) -> tuple[int, int]:
    checked = bad = 0
    for lineno, raw in enumerate(_lines(name), 1):
        stripped = raw.rstrip(b"\r\n")
        if not stripped.strip() or stripped.startswith(b"#"):
            continue
        direction = None
        if stripped[:1].isdigit():
            try:
                rec = parse_record(raw.decode("latin-1"), lineno)
            except WireLogError as e:
                checked += 1
                bad += 1
                _emit(out, as_json, name, lineno, None, None, f"WIRELOG: {e}")
                continue
            if rec is None or rec.is_note:
                continue
            raw, direction = rec.raw, rec.direction
        checked += 1
        d = decode(raw, profile)
        if not d.valid:
            bad += 1
        _emit(out, as_json, name, lineno, d, direction, None)
    return checked, bad


def _emit(out, as_json, name, lineno, d, direction, failure) -> None:
    if as_json:
        obj = {"file": name, "line": lineno}
        if d is None:
            obj.update({"type": None, "valid": False, "fields": None,
                        "errors": [{"clause": None, "text": failure}]})
        else:
            obj.update(d.as_dict())
        if direction:
            obj["direction"] = direction
        out.write(json.dumps(obj) + "\n")
    elif d is None:
        out.write(f"{name}:{lineno}: {failure}\n")
    elif d.error is not None:
        out.write(f"{name}:{lineno}: {d.error}\n")


def run(args: argparse.Namespace) -> int:
    try:
        profile = load_profile(args.profile)
    except ProfileError as e:
        print(f"helmcheck parse: {e}", file=sys.stderr)
        return exitcodes.USAGE
    total = invalid = 0
    for name in args.files:
        try:
            c, b = _check_file(name, profile, args.json, sys.stdout)
        except OSError as e:
            print(f"helmcheck parse: {name}: {e.strerror or e}", file=sys.stderr)
            return exitcodes.USAGE
        total += c
        invalid += b
    if not args.json:
        print(f"{total} lines checked, {invalid} invalid", file=sys.stderr)
    return exitcodes.NONCONFORMANT if invalid else exitcodes.OK
