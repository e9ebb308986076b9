"""What a judge is fed: timestamped wire events, and the recorder notes it understands.

A judge never reads a port, a file or a clock. Whoever drives it — a live certification, an
offline log check — hands it the same :class:`WireEvent` s, in order:

* bytes the backseat sent the vehicle (``dir = ">"``) or the vehicle sent the backseat
  (``"<"``), split anywhere, with the time they were seen (wall seconds since the record began);
* notes (``"!"``): what the recorder knew besides the bytes.

A :class:`WireEvent` is a wire-log record: it and the directions are defined with the format
in :mod:`helmcheck.grammar.wirelog`, and re-exported here for the judges. A live run writes every
event to its wire log *and* feeds it to the judge with the time and line number it was written
with (:class:`helmcheck.line.recorder.Recorder`); an offline check reads the same records
back with the same module's reader. So one log gives one verdict, whoever reads it.

The lines in those bytes are read by :class:`Decodings` (:func:`helmcheck.grammar.decode` with a
bounded cache), one per session: observers of the same session share it, so a line is decoded
once whichever roles judge it.

Notes a judge acts on (anything else is kept as evidence only); the words are part of the
wire-log format (``docs/contracts.md``):

==========================================  ===================================================
``case V-22 RH-INT-2: <title>``             a clause case starts; findings inside it are booked
                                            on its clauses where they touch them
``case explore: <title>``                   a case about no clause (the exploration): findings
                                            are booked on what each observation speaks to
``case V-22 end``                           the case is over
``not tested RH-X,RH-Y: <reason>``          the tester could not exercise these clauses
``inconclusive RH-X,RH-Y: <reason>``        the tester exercised them but cannot judge them
``link: <baud> baud 8N1 <port>``            the line's settings as the tester opened it (RH-FRM-9)
``line budget: baud … jitter … k …``        what the line costs the observer, as measured
                                            (:mod:`.linebudget`): the host's jitter it uses
``plant: <Event>(<args>) at v=<seconds>``   an emulator's physics event (exact, when present)
``fault injected (<source>): <code>``       a safety violation raised off the wire (RH-SAF-5)
``lockout starts (<code>)`` / ``… ends``    the vehicle's lockout, as the vehicle knows it
``scenario <name> starts``                  a certify-backseat scenario
``silence starts`` / ``silence ends``       the vehicle stops / resumes answering
``reject: …`` / ``reject: window ends``     staged refusals start / end
``operator: <instruction>``                 an operator was asked to act (RH-SAF-5)
``run aborted: <reason>``                   the run ended early: what was not judged is
                                            INCONCLUSIVE with this reason
``held: <why>``                             from here on a violation is held: booked only at
                                            the next ``confirmed``/``unconfirmed`` note
``confirmed: <how>``                        the held violations are booked as violations
``unconfirmed: <how>``                      the held violations are INCONCLUSIVE with ``<how>``
                                            (also when the record ends, or resumes, first)
``confirmed RH-X,RH-Y: <how>``              the same for these clauses' held violations only;
``unconfirmed RH-X: <how>``                 holding goes on for the others
``run resumed: <what>``                     an interrupted run goes on (``--resume``), or a
                                            link gap ended: the vehicle's state is unknown
                                            again; commands left unanswered at the
                                            interruption are not judged
``line fault <dir> <kind>: <detail>``       what a line-fault relay did to the line
                                            (:mod:`helmcheck.grammar.faultnote`): the judges
                                            give what it touched to the line
                                            (:mod:`.linefaults`)
``relay started: …``                        the record is a line-fault relay's: what no
                                            ``line fault`` note touched, the line did not do
``line model: clean|noisy — <why>``         whether the link can damage bytes
                                            (:mod:`.linemodel`); clean: every broken line,
                                            lost byte or missing answer is the
                                            implementation's; none stated: noisy
``line overrun: <what>``                    the backseat's requests asked for more replies
                                            than the line carries (``certify backseat``): a
                                            remark on RH-BS-4, never a verdict
``re-run …``                                the tester makes a spoilt observation again
                                            (evidence only: the judge's repetition rule,
                                            :mod:`.streaks`, reads the lines themselves)
==========================================  ===================================================
"""

from __future__ import annotations

import ast
import re
from dataclasses import dataclass
from typing import Any, Optional

from ..grammar import Decoded, decode
from ..grammar.faultnote import PREFIX as FAULT_PREFIX, read_fault_note
from ..grammar.wirelog import FROM_VEHICLE, NOTE, TO_VEHICLE, WireEvent
from ..profile import SAFETY_CODES
from .linebudget import parse_budget
from .linemodel import read_line_note

#: Lines a judge's per-line caches keep (decoded sentences, classifications, evidence text, by
#: the line's bytes): enough for the lines a session repeats (polls, acknowledgements), small
#: enough that a session of hours, whose reports all differ, keeps its memory flat.
LINE_CACHE = 512

__all__ = ["LINE_CACHE", "Decodings", "WireEvent", "TO_VEHICLE", "FROM_VEHICLE", "NOTE", "Note", "parse_note", "case_note",
           "case_end_note", "tester_note", "parse_plant"]


class Decodings:
    """Each line read once: :func:`~helmcheck.grammar.decode` against one profile, the latest
    :data:`LINE_CACHE` lines kept (by their bytes). A line's reading depends on its bytes and the
    profile alone, so the observers of one session share one: a line both roles read (every
    ``$OSI``, every ``$ACK``, every command) is decoded once, not once per role."""

    __slots__ = ("profile", "_cache")

    def __init__(self, profile):
        self.profile = profile
        self._cache: dict[bytes, Decoded] = {}

    def __call__(self, raw: bytes) -> Decoded:
        hit = self._cache.get(raw)
        if hit is None:
            cache = self._cache
            if len(cache) >= LINE_CACHE:
                cache.clear()
            hit = cache[raw] = decode(raw, self.profile)
        return hit


@dataclass(frozen=True, slots=True)
class Note:
    """A note a judge acts on: ``kind`` and its parts (see the module docstring)."""

    kind: str  #: case | case-end | not-tested | inconclusive | link | budget | plant | fault | lockout |
    #: lockout-end | scenario | silence | silence-end | reject | reject-end | operator | aborted |
    #: resumed | line-fault | relay | line-model | overrun
    case: str = ""
    clauses: tuple[str, ...] = ()
    text: str = ""
    code: str = ""
    value: Any = None  #: plant: (event class name, kwargs, v); link: baud; line-fault: its FaultNote


_CASE = re.compile(r"^case (\S+)(?: ((?:RH-[A-Z]+-\d+ ?)+))?: (.*)$")
_CASE_END = re.compile(r"^case (\S+) end$")
_TESTER = re.compile(r"^(not tested|inconclusive) ((?:RH-[A-Z]+-\d+,?)+): (.*)$")
_RELEASE = re.compile(r"^(confirmed|unconfirmed)(?: ((?:RH-[A-Z]+-\d+,?)+))?: (.*)$")
_LINK = re.compile(r"^link: (\d+) baud 8N1\b")
_PLANT = re.compile(r"^plant: (\w+)\((.*?)\)(?: \[[^\]]*\])? at v=([-0-9.eE]+)\s*$")
_FAULT = re.compile(r"^fault injected \(([^)]*)\): (\w+)\s*$")
_LOCKOUT = re.compile(r"^lockout (starts|ends)\b(?: \((\w+)\))?")
_SCENARIO = re.compile(r"^scenario (\S+) starts")


def parse_plant(args: str) -> Optional[dict]:
    kwargs: dict[str, Any] = {}
    for part in filter(None, (p.strip() for p in args.split(","))):
        k, _, v = part.partition("=")
        try:
            kwargs[k.strip()] = ast.literal_eval(v.strip())
        except (ValueError, SyntaxError):
            return None
    return kwargs


def parse_note(text: str) -> Optional[Note]:
    """The :class:`Note` a judge acts on, or ``None`` for a note that is evidence only."""
    if text.startswith(FAULT_PREFIX):
        fault = read_fault_note(text)
        return Note("line-fault", value=fault, text=text) if fault is not None else None
    if text.startswith("relay started: "):
        return Note("relay", text=text)
    model = read_line_note(text)
    if model is not None:
        return Note("line-model", value=model, text=model.why)
    m = _CASE.match(text)
    if m:
        return Note("case", case=m.group(1), clauses=tuple((m.group(2) or "").split()), text=m.group(3))
    m = _CASE_END.match(text)
    if m:
        return Note("case-end", case=m.group(1))
    m = _TESTER.match(text)
    if m:
        kind = "not-tested" if m.group(1) == "not tested" else "inconclusive"
        return Note(kind, clauses=tuple(c for c in m.group(2).split(",") if c), text=m.group(3))
    m = _LINK.match(text)
    if m:
        return Note("link", value=int(m.group(1)), text=text)
    if text.startswith("line budget: "):
        budget = parse_budget(text)
        return Note("budget", value=budget, text=text) if budget is not None else None
    m = _PLANT.match(text)
    if m:
        kwargs = parse_plant(m.group(2))
        if kwargs is None:
            return None
        try:
            v = float(m.group(3))
        except ValueError:
            return None
        return Note("plant", value=(m.group(1), kwargs, v), text=text)
    m = _FAULT.match(text)
    if m and m.group(2) in SAFETY_CODES:
        return Note("fault", code=m.group(2), text=m.group(1))
    m = _LOCKOUT.match(text)
    if m:
        return Note("lockout" if m.group(1) == "starts" else "lockout-end", code=m.group(2) or "")
    m = _SCENARIO.match(text)
    if m:
        return Note("scenario", text=m.group(1))
    if text.startswith("silence starts"):
        return Note("silence")
    if text.startswith("silence ends"):
        return Note("silence-end")
    if text.startswith("reject: window ends"):
        return Note("reject-end")
    if text.startswith("reject: "):
        return Note("reject", text=text[8:])
    if text.startswith("operator: "):
        return Note("operator", text=text[10:])
    if text.startswith("run aborted: "):
        return Note("aborted", text=text[13:])
    if text.startswith("held: "):
        return Note("held", text=text[6:])
    m = _RELEASE.match(text)
    if m:
        return Note(m.group(1), clauses=tuple(c for c in (m.group(2) or "").split(",") if c), text=m.group(3))
    if text.startswith("run resumed: "):
        return Note("resumed", text=text[13:])
    if text.startswith("line overrun: "):
        return Note("overrun", text=text[14:])
    return None


def case_note(case_id: str, clauses: tuple[str, ...] | list[str], title: str) -> str:
    """``case V-12 RH-ACK-3: title``; a case about no clause in particular (the exploration) is
    ``case explore: title``, and its findings are booked on what each observation speaks to."""
    return f"case {case_id} {' '.join(clauses)}: {title}" if clauses else f"case {case_id}: {title}"


def case_end_note(case_id: str) -> str:
    return f"case {case_id} end"


def tester_note(kind: str, clauses, reason: str) -> str:
    """``not tested RH-X,RH-Y: reason`` or ``inconclusive RH-X: reason`` (one line)."""
    word = {"not-tested": "not tested", "inconclusive": "inconclusive"}[kind]
    return f"{word} {','.join(clauses)}: {reason}".replace("\n", " ")
