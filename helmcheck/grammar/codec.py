"""Parse one line into a typed sentence, and format a sentence into canonical bytes.

``decode(line, profile)`` is the full reading of one line — framing (RH-FRM-1..7), checksum
(RH-FRM-2/3), ID (RH-FRM-5, RH-RD-16), field syntax (the grammar), and value ranges (the
profile) — and returns a :class:`Decoded` with the sentence, or the first error, plus SHOULD
findings. ``parse`` is the same but raises :class:`SentenceError`. ``format`` writes canonical
bytes: upper-case zero-padded checksum and CR LF, so ``parse(format(s)) == s`` and, for
canonical input, ``format(parse(b)) == b``.

A line that is framed, checksummed and split into its sentence's fields, but has a field the
grammar cannot read or a value out of its range, is still invalid; its :attr:`Decoded.partial` is
the sentence read without those fields (each ``None``), and :attr:`Decoded.field_errors` names
every one of them with its clause and its text as sent (:func:`_split_fields`: the grammar and the
range rules decide which field is bad, nothing else does). Only a line that cannot be framed, or
whose fields cannot be told apart (one missing, one too many), has no partial reading.

Two engines read the body: ``"fast"`` (regular expressions compiled from the grammar, the
default) and ``"lark"`` (the Lark LALR parser over the same grammar). They agree; the property
tests prove it. Errors are always located with Lark, which knows where a parse went wrong;
Lark is imported then, and not before (a process that reads only valid lines never needs it).
"""

from __future__ import annotations

import builtins
import re
from dataclasses import dataclass, replace
from decimal import Decimal
from typing import TYPE_CHECKING, Optional

from ..profile import DEFAULT, Profile
from . import sentences as S
from .checksum import checksum
from .compile import build_sentence, fast_builder, lark_parser, specs
from .errors import SYNTAX, Finding, SentenceError
from .ranges import check_ranges, field_text, range_errors

if TYPE_CHECKING:
    from lark import Tree

__all__ = ["decode", "parse", "format", "format_body", "Decoded", "KNOWN_IDS", "rules_for_id", "prepare"]


@dataclass(frozen=True)
class Decoded:
    """Everything learned from one line."""

    raw: bytes
    sentence: Optional[S.Sentence] = None
    error: Optional[SentenceError] = None
    findings: tuple[Finding, ...] = ()
    sentence_id: Optional[str] = None
    terminator: str = ""  #: "\r\n", "\n" or "" (none)
    #: an invalid line split into its sentence's fields: the sentence without its bad fields
    #: (each ``None``), which :attr:`field_errors` name; None when the line has no such reading
    partial: Optional[S.Sentence] = None
    #: every field fault of :attr:`partial` (syntax first, then ranges); ``error`` is the first
    field_errors: tuple[SentenceError, ...] = ()

    @property
    def valid(self) -> bool:
        return self.sentence is not None

    @property
    def unread(self) -> frozenset:
        """The fields of :attr:`partial` left out (``None``) because they are bad."""
        if self.partial is None:
            return frozenset()
        names = self.partial.field_names()
        return frozenset(e.field for e in self.field_errors if e.field in names)

    def as_dict(self) -> dict:
        s = self.sentence
        out = {
            "type": type(s).__name__ if s is not None else None,
            "id": self.sentence_id,
            "valid": self.valid,
            "fields": s.as_dict() if s is not None else None,
            "errors": [e.as_dict() for e in self.field_errors] or ([self.error.as_dict()] if self.error else []),
            "findings": [f.as_dict() for f in self.findings],
        }
        if self.partial is not None:
            out["type"] = type(self.partial).__name__
            out["partial"] = self.partial.as_dict()
        return out


# --------------------------------------------------------------------------- ID dispatch

def _first_literal(rule_pattern: str) -> str:
    m = re.match(r"[A-Z]+", rule_pattern)
    return m.group(0) if m else ""


class _Builders(dict):
    """ID -> [(body regex's fullmatch, builder)], each ID's made on its first line (a capture
    holds a few IDs of the protocol's thirty; :func:`prepare` makes them all)."""

    def __missing__(self, sid: str) -> list:
        entry = self[sid] = [(spec.regex.fullmatch, fast_builder(spec.rule)) for spec in _RULES_BY_ID[sid]]
        return entry


_RULES_BY_ID: dict[str, list] = {}
_FAST = _Builders()
for _spec in specs().values():
    _RULES_BY_ID.setdefault(_first_literal(_spec.regex.pattern), []).append(_spec)
KNOWN_IDS = frozenset(_RULES_BY_ID)
_COMMAND_ERR = {cls.ID: (cls.ACK_TYPE, cls.ERR) for cls in S.COMMAND_CLASSES if cls.ACK_TYPE}
_REPLY_CLAUSE = {"OSI": "RH-OUT-1", "ACK": "RH-ACK-1"}
_ID_RE = re.compile(r"[A-Z]+")
_CHECKSUM_RE = re.compile(r"[0-9A-Fa-f]{2}")
_BAD_BYTE = re.compile(rb"[^\x20-\x7e]")


def rules_for_id(sentence_id: str) -> list:
    """The compiled sentence rules whose body starts with this ID (OMSTART and OMW have two)."""
    return _RULES_BY_ID.get(sentence_id, [])


# --------------------------------------------------------------------------- decoding

def _fail(raw: bytes, err: SentenceError, findings=(), sid=None, term="") -> Decoded:
    return Decoded(raw, None, err, tuple(findings), sid, term)


_RANGES = check_ranges
_HEX_UPPER = {b"%02X" % i: i for i in range(256)}


def _fast(raw: bytes, profile: Profile) -> Optional[S.Sentence]:
    """The sentence of a clean, valid line, or None to send the line through the full reading.

    This is only a shortcut: it accepts nothing the full reading would refuse. A clean line is
    ``$`` body ``*`` two upper-case hex digits CR LF; the body's bytes are not scanned here,
    because the sentence regexes match only printable ASCII without ``$`` and ``*`` (proved for
    every compiled regex by ``tests/test_grammar_fastpath.py``), so a body one of them matches
    is clean, and any other goes to the full reading.
    """
    n = len(raw)
    if n < 6 or n > profile.max_line_bytes or raw[0] != 36 or raw[-5] != 42 or raw[-2] != 13 or raw[-1] != 10:
        return None  # not "$" … "*" hh CR LF, or too long
    want = _HEX_UPPER.get(raw[-4:-2])
    body = raw[1:-5]
    if want is None or checksum(body) != want:
        return None
    text = body.decode("latin-1")  # never fails; a byte beyond ASCII fails every regex below
    comma = text.find(",")
    head = text if comma < 0 else text[:comma]
    candidates = _FAST.get(head)
    if candidates is None:
        if head not in KNOWN_IDS:
            if head[:1] != "C" or head[1:2] not in "-0123456789":
                return None
            head = "C"
        candidates = _FAST[head]
    for fullmatch, build in candidates:
        mm = fullmatch(text)
        if mm is not None:
            s = build(mm)
            return s if _RANGES(s, profile) is None else None
    return None


_new, _set = object.__new__, object.__setattr__


def _valid(raw: bytes, s: S.Sentence) -> Decoded:
    """``Decoded(raw, s, None, (), s.ID, "\\r\\n")``, the reading of a clean valid line, made at
    about half the cost of the frozen dataclass's ``__init__`` (one attribute dict set, not six
    guarded ``setattr`` s): a judge reads one for nearly every line of a log."""
    d = _new(Decoded)
    _set(d, "__dict__", {"raw": raw, "sentence": s, "error": None, "findings": (), "sentence_id": s.ID,
                         "terminator": "\r\n"})
    return d


def decode(line: bytes | str, profile: Profile = DEFAULT, engine: str = "fast") -> Decoded:
    """Read one line (with or without its terminator). Never raises for bad input."""
    raw = line.encode("latin-1", "replace") if isinstance(line, str) else bytes(line)
    if engine == "fast":
        s = _fast(raw, profile)
        if s is not None:
            return _valid(raw, s)
    findings: list[Finding] = []
    if raw.endswith(b"\r\n"):
        term, data = "\r\n", raw[:-2]
    elif raw.endswith(b"\n"):
        term, data = "\n", raw[:-1]
        findings.append(Finding("RH-FRM-7", "line ends in a bare LF; CR LF expected (RH-BS-7)", len(raw)))
    else:
        term, data = "", raw
    total = len(data) + (len(term) or 2)
    if total > profile.max_line_bytes:
        return _fail(raw, SentenceError("RH-FRM-6", f"line is {total} bytes, longer than "
                                        f"{profile.max_line_bytes} with its terminator", profile.max_line_bytes + 1), findings, term=term)
    if not data.startswith(b"$"):
        return _fail(raw, SentenceError("RH-FRM-7", "line does not start with '$'", 1), findings, term=term)
    bad = _BAD_BYTE.search(data)
    if bad:
        return _fail(raw, SentenceError("RH-FRM-1", f"byte 0x{data[bad.start()]:02X} is not printable ASCII",
                                        bad.start() + 1), findings, term=term)
    text = data.decode("ascii")
    star = text.find("*")
    if star < 0:
        return _fail(raw, SentenceError("RH-FRM-4", "checksum missing: no '*'", len(text) + 1), findings, term=term)
    if text.find("*", star + 1) >= 0:
        return _fail(raw, SentenceError("RH-FRM-4", "line has two '*' (RH-RD-16)", text.find("*", star + 1) + 1),
                     findings, term=term)
    cks = text[star + 1:]
    if not (len(cks) == 2 and _CHECKSUM_RE.fullmatch(cks)):
        return _fail(raw, SentenceError("RH-FRM-4", f"checksum {cks!r} is not exactly two hex digits", star + 2),
                     findings, term=term)
    if cks != cks.upper():
        if not profile.lowercase_checksum_in:
            return _fail(raw, SentenceError("RH-FRM-3", f"checksum {cks} is lower-case hex", star + 2), findings, term=term)
        findings.append(Finding("RH-FRM-3", f"checksum {cks} is lower-case hex; upper case expected (RH-BS-7)", star + 2))
    body = text[1:star]
    want = checksum(data[1:star])
    if int(cks, 16) != want:
        return _fail(raw, SentenceError("RH-FRM-2", f"checksum {cks.upper()} does not match computed {want:02X}",
                                        star + 2), findings, term=term)
    m = _ID_RE.match(body)
    head = body.split(",", 1)[0]
    if m is None or (m.end() != len(head) and not (m.group(0) == "C" and head[1:2] in "-0123456789")):
        return _fail(raw, SentenceError("RH-FRM-5", f"unknown ID {head!r} (IDs are upper-case letters, RH-RD-16)", 2),
                     findings, term=term)
    sid = "C" if m.group(0) == "C" and m.end() != len(head) else m.group(0)
    if sid not in KNOWN_IDS:
        return _fail(raw, SentenceError("RH-FRM-5", f"unknown ID {sid!r}", 2), findings, sid, term)
    sentence = _read_body(body, sid, engine)
    bad: list[SentenceError] = []
    if isinstance(sentence, SentenceError):
        split = _split_fields(body, sid, sentence, engine)
        if split is None:
            return _fail(raw, sentence, findings, sid, term)
        sentence, bad = split
    unreadable = {e.field for e in bad}
    names = sentence.field_names()
    problems = [e for e in range_errors(sentence, profile) if e.field not in unreadable]
    if unreadable and any(e.field not in names for e in problems):
        return _fail(raw, bad[0], findings, sid, term)  # read with stand-ins to a wrong field count:
        # a field missing or one too many, not a field the grammar cannot read
    bad += problems
    if not bad:
        return Decoded(raw, sentence, None, tuple(findings), sid, term)
    partial = replace(sentence, **{e.field: None for e in bad if e.field in names})
    return Decoded(raw, None, replace(bad[0], partial=partial), tuple(findings), sid, term, partial, tuple(bad))


def parse(line: bytes | str, profile: Profile = DEFAULT, engine: str = "fast") -> S.Sentence:
    """The sentence on this line; raises :class:`SentenceError` naming clause and column."""
    if engine == "fast" and type(line) is bytes:
        s = _fast(line, profile)
        if s is not None:
            return s
    d = decode(line, profile, engine)
    if d.error is not None:
        raise d.error
    return d.sentence  # type: ignore[return-value]


def _read_body(body: str, sid: str, engine: str):
    if engine == "fast":
        for fullmatch, build in _FAST[sid]:
            m = fullmatch(body)
            if m is not None:
                return build(m)
        return _locate_error(body, sid)
    if engine == "lark":
        from lark.exceptions import UnexpectedInput

        try:
            tree = lark_parser().parse(body, start="body")
        except UnexpectedInput:
            return _locate_error(body, sid)
        return _from_tree(tree.children[0])
    raise ValueError(f"unknown engine {engine!r}")


#: Texts tried in place of a field the grammar cannot read, to read the fields around it: the
#: grammar decides which one fits there (a number, a park time, a mode or error letter, the SRP
#: flag, the fins and motor, text, or nothing for a field that may be empty).
_STAND_INS = ("0", "P0", "N", "False", "8080808080", "00", "X", "")
#: (sentence ID, field index) → the stand-in that fitted there last (tried first next time)
_FITTED: dict = {}


def _field_index(body: str, err: SentenceError) -> Optional[int]:
    """The comma-separated field (1 = the first after the ID) where ``err`` was found."""
    if err.column is None or err.column - 2 > len(body):
        return None  # at the end of the body: a field is missing, not wrong
    return body[: max(err.column - 2, 0)].count(",")


def _split_fields(body: str, sid: str, err: SentenceError, engine: str):
    """``(sentence, [field errors])`` for a body whose fields are all there but some cannot be
    read, else None (module docstring). Each unreadable field is found where the grammar stops
    (:func:`_locate_error`), and set aside by putting in its place a stand-in the grammar accepts
    there (:data:`_STAND_INS`); the sentence built from that is kept, each stand-in's field being
    a bad one. A field that takes no stand-in, or a stand-in that lands in another field (a field
    missing, or one too many), leaves the line without a partial reading."""
    rules = rules_for_id(sid)
    if not rules:
        return None
    names = rules[0].cls.field_names()
    sent = parts = body.split(",")
    bad: list[tuple[str, str, SentenceError]] = []
    got = err
    for _ in range(len(parts)):
        idx = _field_index(",".join(parts), got)
        if idx is None or not 0 < idx < len(parts) or idx > len(names):
            return None
        text = parts[idx]
        tried = (_FITTED[(sid, idx)],) if (sid, idx) in _FITTED else ()
        for stand_in in tried + tuple(x for x in _STAND_INS if x not in tried and x != text):
            trial = parts[:idx] + [stand_in] + parts[idx + 1:]
            nxt = _read_body(",".join(trial), sid, engine)
            if isinstance(nxt, SentenceError):
                after = _field_index(",".join(trial), nxt)
                if after is None or after <= idx:
                    continue  # the stand-in does not fit there either
            _FITTED[(sid, idx)] = stand_in
            # (the grammar's column where it stopped, for the first; for the others, where the field
            # begins in the line as sent: their errors were found with stand-ins before them)
            column = got.column if not bad else len(",".join(sent[:idx])) + 3
            bad.append((names[idx - 1], stand_in, _field_error(got, sid, names[idx - 1], idx, text, column)))
            parts, got = trial, nxt
            break
        else:
            return None
        if not isinstance(got, SentenceError):
            break
    if isinstance(got, SentenceError):
        return None
    for name, stand_in, _ in bad:
        if (field_text(got, name) or "") != stand_in:
            return None  # a stand-in landed in another field: the fields are not where they seem
    return got, [e for _, _, e in bad]


def _field_error(err: SentenceError, sid: str, name: str, idx: int, text: str, column) -> SentenceError:
    """The grammar's error as the fault of field ``idx`` (``name``), with the text sent there."""
    message = err.message if err.field == name else (
        f"${sid} {name}: field {idx} is empty" if not text else f"${sid} {name}: {text!r} is not its form")
    return replace(err, message=message, field=name, value=text, column=column)


def _from_tree(node: Tree) -> S.Sentence:
    """Build the sentence from a Lark tree, through the same builder as the fast path."""
    from lark import Tree

    spec = specs()[str(node.data)]
    raw: dict[str, Optional[str]] = {}
    for child in node.children:
        if child is None or not isinstance(child, Tree):
            continue
        name = str(child.data)
        if name.endswith("_item"):
            raw[name] = (raw.get(name) or "") + _text(child, with_separators=True)
        elif name.endswith("_opt"):
            raw[name] = _text(child, with_separators=True)
        elif name == "trailing_empty":
            raw[name] = ","
        else:
            raw[name] = _text(child, with_separators=False)
    return build_sentence(spec, raw)


_ITEM_SEPARATOR = {"compass_extra_item": ""}


def _text(t: Tree, with_separators: bool) -> str:
    """Text of a field subtree. Items and opts get their separator back (Lark drops literals)."""
    from lark import Token

    parts = [str(c) for c in t.children if isinstance(c, Token)]
    if not with_separators:
        return "".join(parts)
    name = str(t.data)
    sep = _ITEM_SEPARATOR.get(name, ",")
    if name == "oysi_readings_item":
        return "," + ",".join(parts)
    return sep + "".join(parts)


def _locate_error(body: str, sid: str) -> SentenceError:
    """Why and where the body does not follow the grammar (RH-ACK-3 / RH-OUT-1/2)."""
    from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedToken

    column = None
    what = "does not follow the grammar"
    try:
        lark_parser().parse(body, start="body")
    except UnexpectedEOF:
        column, what = len(body) + 2, "too few fields"
    except UnexpectedToken as e:
        column = (e.column or 0) + 1
        if e.token.type == "$END":
            what = "too few fields"
        elif e.token.type == "COMMA":
            what = "too many fields or an empty field"
        else:
            what = f"unexpected {str(e.token)!r}"
    except UnexpectedCharacters as e:
        column = e.column + 1
        what = f"unexpected {body[e.pos_in_stream:e.pos_in_stream + 8]!r}"
    field_name = None
    if what in ("too few fields", "too many fields or an empty field"):
        what = f"{what} (got {body.count(',')})"
    elif column is not None:
        idx = body[: max(column - 2, 0)].count(",")  # 0 = the ID, 1 = first field
        names = _RULES_BY_ID[sid][0].cls.field_names() if _RULES_BY_ID.get(sid) else ()
        field_name = names[idx - 1] if 0 < idx <= len(names) else f"field {idx}"
        what = f"{field_name}: {what}" if idx > 0 else what
    ack_type, ack_err = _COMMAND_ERR.get(sid, (None, None))
    clause = "RH-ACK-3" if ack_type is not None else _REPLY_CLAUSE.get(sid, "RH-OUT-2")
    if sid == "OXFLT":
        clause = "RH-SAF-5"
    return SentenceError(clause, f"${sid} {what}", column, SYNTAX, sid, field_name, ack_type, ack_err)


# --------------------------------------------------------------------------- formatting

def _fmt(v) -> str:
    if isinstance(v, Decimal):
        return builtins.format(v, "f")
    if v is None:
        return ""
    return str(v)


#: Optional fields whose ``None`` means "absent" (the sentence stops there), not "empty".
_TAIL_OPTIONAL = {
    S.OMSTART: ("srp",),
    S.GPRMC: ("mode",),
    S.OMWClear: ("waypoint",),
    S.ORWSET: ("state",),
    S.OSI: ("mission_name", "remaining_time", "true_heading", "depth", "battery", "srp_active",
            "vehicle_name"),
}


def _fields(s: S.Sentence) -> list[str]:
    cls = type(s)
    tail = _TAIL_OPTIONAL.get(cls, ())
    out: list[str] = []
    for name in cls.field_names():
        v = getattr(s, name)
        if name in tail and v is None:
            break
        if isinstance(v, bool):
            if v:
                out.append("")
            continue
        if isinstance(v, tuple):
            for item in v:
                if isinstance(item, tuple):
                    out.extend(_fmt(x) for x in item)
                else:
                    out.append(_fmt(item))
            continue
        if isinstance(v, S.Sentence):
            out.extend(_fields(v))
            continue
        if name == "park_time" and cls is S.OSI:
            out.append(f"P{v}")
            continue
        out.append(_fmt(v))
    return out


def format_body(s: S.Sentence) -> str:
    """The text between ``$`` and ``*``."""
    if isinstance(s, S.Compass):
        text = (f"C{_fmt(s.heading)}P{_fmt(s.pitch)}R{_fmt(s.roll)}T{_fmt(s.temperature)}"
                f"D{_fmt(s.depth)}")
        return text + "".join(f"{k}{_fmt(v)}" for k, v in s.extra)
    parts = _fields(s)
    return s.ID + "".join("," + p for p in parts)


def format(s: S.Sentence, lowercase: bool = False, terminator: str = "\r\n") -> bytes:  # noqa: A001
    """Canonical bytes of a sentence: ``$body*HH`` + CR LF (RH-FRM-1..3)."""
    body = format_body(s).encode("latin-1")
    cks = "%02x" % checksum(body) if lowercase else "%02X" % checksum(body)
    return b"$" + body + b"*" + cks.encode() + terminator.encode()


def prepare() -> None:
    """Build now what :func:`decode` builds on first need (the compiled sentences, and the Lark
    parser that locates a syntax error), so a live process answers its first malformed line as
    fast as its hundredth: a vehicle must ACK within its window (RH-ACK-2) and a tester must
    timestamp what it reads, and building the parser takes 0.1 s on an idle host, several
    times that on a loaded one. Idempotent and cheap after the first call."""
    specs()
    for sid in KNOWN_IDS:
        _FAST[sid]  # noqa: B018 - builds the ID's fast-path builders
    lark_parser()

