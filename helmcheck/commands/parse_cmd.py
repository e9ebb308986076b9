"""``helmcheck parse``: validate sentences line by line, from files, stdin or wire logs.

Each input line is either a bare sentence (``$OMS,…*hh``) or a wire-log record
(``12.345678 > $OMS,…*hh``, read by :func:`helmcheck.grammar.wirelog.parse_record`, the one
wire-log reader); the format is detected per line, so a wire log can be validated as it is.
Invalid lines print as ``FILE:LINE: CLAUSE: message``; ``--json`` prints one JSON object per
line instead.
Exit 0 when every line is valid, 1 when any is not, 64 on usage errors or an unreadable file.

Speed (the whole process is measured against plain pynmea2 loops, ``benchmarks/parse_bench.py``):
the input is read in blocks of up to 1 MiB (as much as a pipe has, so a live capture is judged
as it comes) and split into lines in C, with exactly the lines a file's line iterator gives
(split at LF only). A line that starts with ``$`` goes straight to the codec's fast path
(:func:`helmcheck.grammar.parse`, no :class:`~helmcheck.grammar.Decoded` built for a valid line
without ``--json``); only other lines take the general path (blank lines, comments, wire-log
records). A valid line is valid again under the same profile, so a line seen valid before is
counted without being read again (captures repeat: the same polls, the same status). Output is
collected and written in blocks, and nothing is imported that the lines at hand do not need
(the JSON encoder with ``--json``, the wire-log reader with a wire log).

A reader that goes away (``helmcheck parse … | head -1``) ends the command quietly: reading
stops, and the exit status is the verdict on the lines judged so far (0 when all were valid,
1 when an invalid one was already reported). Decision recorded in ``docs/contracts.md``.
"""

from __future__ import annotations

import argparse
import re
import sys
from typing import IO, Iterable, Iterator

from .. import exitcodes
from ..failures import PathError

EPILOG = """\
A line is judged against the reference profile: framing and checksum (RH-FRM-*), the grammar,
and value ranges from the profile (--profile FILE; default rh5). Wire-log comment lines (#) and
notes (!) are skipped. Invalid lines print as FILE:LINE: CLAUSE: message.

examples:
  helmcheck parse reports/vehicle/wire.log          # a wire log (certify, emulate --log, monitor)
  helmcheck parse reports/vehicle/wire.log --json   # one JSON object per line
  printf '$OMSTOP,0*06\\r\\n$OMSTOP,0*07\\r\\n' | helmcheck parse -   # one sentence per line

exit status: 0 every line valid, 1 an invalid line, 64 usage (bad option or profile, unreadable file).
"""

_BLOCK = 512  #: output lines collected before one write
_READ = 1 << 20  #: bytes asked of the input at a time
_SEEN = 1 << 14  #: valid lines remembered (distinct lines; about 2 MB for 80-byte lines)
_LINE = re.compile(rb"[^\n]*\n|[^\n]+")  #: a line as a binary file's iterator gives it


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = sub.add_parser("parse", help="validate sentences line by line",
                       description="Validate sentences line by line, from files, standard input or wire logs.",
                       epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("files", nargs="*", default=["-"], metavar="FILE",
                   help="files to read ('-' or nothing: standard input)")
    p.add_argument("--profile", metavar="FILE", help="TOML profile (default: rh5)")
    p.add_argument("--json", action="store_true", help="one JSON object per input line")
    p.set_defaults(func=run)
    return p


class _Counts:
    __slots__ = ("checked", "bad")

    def __init__(self) -> None:
        self.checked = 0
        self.bad = 0


def read_lines(f) -> Iterator[list[bytes]]:
    """The lines of a binary stream, a block at a time: each line with its LF, the last one
    without when the stream does not end in one — what iterating over the stream gives."""
    read = getattr(f, "read1", f.read)
    rest = b""
    while True:
        block = read(_READ)
        if not block:
            break
        if rest:
            block = rest + block
        cut = block.rfind(b"\n") + 1
        rest = block[cut:]
        if cut:
            whole = block[:cut] if rest else block
            # bytes.splitlines also splits at a lone CR; where there is none it splits as we do
            yield whole.splitlines(True) if whole.count(b"\r") == whole.count(b"\r\n") else _LINE.findall(whole)
    if rest:
        yield [rest]


def _check_lines(name: str, blocks: Iterable[list[bytes]], profile, as_json: bool, out: IO[str], n: _Counts) -> bool:
    """Judge every line; False when the output's reader went away (stop reading)."""
    from ..grammar import SentenceError, decode, parse

    if as_json:
        import json
    pending: list[str] = []
    emit = pending.append
    seen: set[bytes] = set()  # lines found valid (plain output only: --json prints each)
    remember = seen.add
    checked = bad = 0
    lineno = 0
    try:
        for lines in blocks:
            for raw in lines:
                lineno += 1
                if raw in seen:
                    checked += 1
                    continue
                if raw[:1] == b"$":  # a bare sentence: the common case, kept short
                    checked += 1
                    if as_json:
                        d = decode(raw, profile)
                        if d.sentence is None:
                            bad += 1
                        obj = d.as_dict()
                        emit(json.dumps({"file": name, "line": lineno, **obj}))
                    else:
                        try:
                            parse(raw, profile)
                        except SentenceError as e:
                            bad += 1
                            emit(f"{name}:{lineno}: {e}")
                        else:
                            if len(seen) < _SEEN:
                                remember(raw)
                            continue
                else:
                    c, b = _other_line(name, lineno, raw, profile, as_json, emit)
                    checked += c
                    bad += b
                if len(pending) >= _BLOCK:
                    out.write("\n".join(pending) + "\n")
                    pending.clear()
                    if getattr(out, "lost", False):
                        return False
        if pending:
            out.write("\n".join(pending) + "\n")
    finally:
        n.checked += checked
        n.bad += bad
    return not getattr(out, "lost", False)


def _other_line(name: str, lineno: int, raw: bytes, profile, as_json: bool, emit) -> tuple[int, int]:
    """A line not starting with ``$``: blank, comment, wire-log record or junk; (checked, bad)."""
    from ..grammar import decode
    from ..grammar.wirelog import NOTE, WireLogError, parse_record

    stripped = raw.rstrip(b"\r\n")
    if not stripped.strip() or stripped.startswith(b"#"):
        return 0, 0
    direction = None
    if stripped[:1].isdigit():
        try:
            rec = parse_record(raw, lineno)
        except WireLogError as e:
            _emit(emit, as_json, name, lineno, None, None, f"WIRELOG: {e}")
            return 1, 1
        if rec is None or rec.dir == NOTE:
            return 0, 0
        raw, direction = rec.data, rec.dir
    d = decode(raw, profile)
    _emit(emit, as_json, name, lineno, d, direction, None)
    return 1, 0 if d.valid else 1


def _emit(emit, as_json, name, lineno, d, direction, failure) -> None:
    if as_json:
        import json

        obj = {"file": name, "line": lineno}
        if d is None:
            obj.update({"type": None, "valid": False, "fields": None,
                        "errors": [{"clause": None, "text": failure}]})
        else:
            obj.update(d.as_dict())
        if direction:
            obj["direction"] = direction
        emit(json.dumps(obj))
    elif d is None:
        emit(f"{name}:{lineno}: {failure}")
    elif d.error is not None:
        emit(f"{name}:{lineno}: {d.error}")


def _why(e: OSError) -> str:
    return e.strerror or str(e)


def run(args: argparse.Namespace) -> int:
    from ..profile import load_profile

    profile = load_profile(args.profile)  # a ProfileError is exit 64 (helmcheck.cli)
    for name in args.files:  # every file readable before any output: 64 means nothing was judged
        if name == "-":
            continue
        try:
            with open(name, "rb"):
                pass
        except OSError as e:
            raise PathError(f"cannot read {name}: {_why(e)}") from None
    out = sys.stdout
    n = _Counts()
    going = True
    for name in args.files:
        try:
            if name == "-":
                going = _check_lines(name, read_lines(sys.stdin.buffer), profile, args.json, out, n)
            else:
                with open(name, "rb") as f:
                    going = _check_lines(name, read_lines(f), profile, args.json, out, n)
        except OSError as e:
            raise PathError(f"cannot read {name}: {_why(e)}") from None
        if not going:
            break
    if not args.json:
        cut = "" if going else " (standard output closed; the rest was not read)"
        print(f"{n.checked} lines checked, {n.bad} invalid{cut}", file=sys.stderr)
    return exitcodes.NONCONFORMANT if n.bad else exitcodes.OK
