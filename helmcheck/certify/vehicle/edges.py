"""The range edges of §4–8 and §8b, and which of them a run reached.

:func:`edge_list` lists every bound and keyword a vehicle's answer can turn on, both sides of
each, generated — never written out by hand — from:

* the value checks of the commands (:data:`helmcheck.grammar.ranges.COMMAND_CHECKS`): for a
  numeric range (:class:`~helmcheck.grammar.ranges.Bound`) the bound itself, accepted, and the
  value just past it, refused — one unit past an integer's, 0.1 past a decimal's (the decimals of
  §4–6 are given to a tenth); for an open end (heading below 360) 0.1 inside and the end itself;
  for a set of values (:class:`~helmcheck.grammar.ranges.Choice`) each value, accepted — each
  keyword in lower, upper and title case where case does not count (RH-RD-4) — and the
  neighbours it names, refused; for a mission name (:class:`~helmcheck.grammar.ranges.NameRule`)
  a name inside the mission directory and each kind a vehicle must refuse (RH-MSN-1, RH-RD-6);
* the grammar (:mod:`helmcheck.grammar.compile`): a repeated field's count (``$OLOGL``'s 1–12
  labels, ``$ORWSET``'s 0–3 values: each end and one past it), a fixed-width hex field (``$OMP``'s
  ten digits: nine and eleven refused, lower case accepted, RH-PRM-2), the ``$OSD`` letters
  (each served letter, a lower-case one refused, RH-RD-7) and the checksum's lower-case hex
  (RH-FRM-3, as the profile's ``lowercase_checksum_in`` says);
* the model's checks that need the vehicle's state (:data:`helmcheck.model.handlers.CHECKS` and
  RH-POS-2): ``$OJW`` to the mission's last waypoint and one past it, ``$OLOGD`` with as many
  values as labels and one more, the ``$OPK`` 10-mile limit (``opk_max_distance_m``) just inside
  and just outside, measured from where the vehicle is, and ``$OPOS`` on each side of the GPS fix
  (RH-RD-10: at the surface with no mission and in a mission started normally — not applied;
  in a mission started with ignore-GPS at the surface, and under water — applied).

An edge is *reached* when a line at it was sent where its answer turns on that bound alone
(:class:`EdgeTally`): the inside value where a conforming vehicle does not refuse the command for
its fields (it accepts it, or refuses it for a later check of RH-RD-2: a file look-up, the
distance); the outside value with every other field inside, in a state where the command with the
inside value would be accepted (so that the refusal can only be the bound's), and the vehicle
answered it. The tally reads the observer's model before each line and the answer the model gives
it: it counts, it never judges (the observer does).

Decisions (the profile is silent): the ``$OPK`` edge is 0.5 % of the limit either side of it
(10 miles: 16 013 m and 16 173 m; the sphere the model measures on and an ellipsoid differ by less
over 16 km, so a vehicle measuring on either is on the same side), and counts within 1 % of the
limit; an ``$OPOS`` reaches a GPS-fix edge only where the position it gives is far enough from the
vehicle's (:data:`OPOS_APART_M`) for the next report to tell whether it was applied.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from decimal import Decimal, InvalidOperation
from functools import lru_cache
from typing import Optional

from ...grammar import checksum_hex, decode
from ...grammar import sentences as S
from ...grammar.compile import grammar_text, sentence_classes_by_rule, specs
from ...grammar.ranges import COMMAND_CHECKS, Bound, Choice, NameRule, mission_name_problem
from ...model.geo import EARTH_RADIUS_M, distance_m
from ...profile import Profile

__all__ = ["Edge", "edge_list", "edge_values", "EdgeTally", "OPK_EDGE", "OPOS_APART_M", "NAME_KINDS",
           "opk_edge_m", "north_of", "STATE_CHECKED"]

#: The ``$OPK`` edge's distance from the limit, a share of it (module docstring).
OPK_EDGE = 0.005
#: Metres an ``$OPOS`` must be from the vehicle for a GPS-fix edge (the judge tells applied from not
#: applied only beyond 30 m and three times the way the vehicle can make between two reports).
OPOS_APART_M = 100.0
#: The kinds of mission name a vehicle must refuse, as :func:`~helmcheck.grammar.ranges.mission_name_problem`
#: words them (RH-MSN-1, RH-RD-6).
NAME_KINDS = ("empty", "absolute path", "drive letter", "'..' component")
#: The commands whose model check (:data:`helmcheck.model.handlers.CHECKS`) has edges here; the others
#: look files up (err 1, 3, 17, 31: no bound to be on either side of).
STATE_CHECKED = ("OJW", "OLOGD", "OPK")

_TENTH = Decimal("0.1")


@dataclass(frozen=True)
class Edge:
    """One side of one bound: ``side`` is ``in`` (a conforming vehicle does not refuse it for this
    bound) or ``out`` (it must), or for the GPS fix ``fix`` / ``no-fix``; ``probe`` is the value a
    line carries there (the text of the field, or for a state edge what the state is)."""

    clause: str
    command: str
    field: str
    bound: str
    side: str
    probe: str
    kind: str  #: range | choice | name | count | width | case | letter | checksum | state

    @property
    def id(self) -> str:
        return f"${self.command} {self.field} {self.bound} {self.side} {self.probe}".rstrip()


# ============================================================================ the list

def _text(v) -> str:
    """A number as the edges write it: ``100``, ``4.6``, ``-0.1``."""
    if isinstance(v, Decimal):
        return format(v.normalize(), "f")
    if isinstance(v, float):
        return _text(Decimal(repr(v)))
    return str(v)


def _numeric(cls: type, field: str) -> bool:
    """Whether the grammar reads ``field`` of ``cls`` as a decimal (else an integer)."""
    spec = _spec(cls)
    return next(f for f in spec.fields if f.attr == field).convert is Decimal


@lru_cache(maxsize=None)
def _spec(cls: type):
    return next(sp for sp in specs().values() if sp.cls is cls)


def _range_edges(b: Bound, p: Profile) -> list[Edge]:
    lo, hi = b.limits(p)
    step = _TENTH if _numeric(b.sentence, b.field) else Decimal(1)
    cid = b.sentence.ID
    out = []
    if lo is not None:
        lo = Decimal(_text(lo))
        out += [Edge(b.clause, cid, b.field, f">={_text(lo)}", "in", _text(lo), "range"),
                Edge(b.clause, cid, b.field, f">={_text(lo)}", "out", _text(lo - step), "range")]
    if hi is not None:
        hi = Decimal(_text(hi))
        if b.hi_open:
            out += [Edge(b.clause, cid, b.field, f"<{_text(hi)}", "in", _text(hi - step), "range"),
                    Edge(b.clause, cid, b.field, f"<{_text(hi)}", "out", _text(hi), "range")]
        else:
            out += [Edge(b.clause, cid, b.field, f"<={_text(hi)}", "in", _text(hi), "range"),
                    Edge(b.clause, cid, b.field, f"<={_text(hi)}", "out", _text(hi + step), "range")]
    return out


def _choice_edges(c: Choice, p: Profile) -> list[Edge]:
    allowed = [str(a) for a in c.allowed(p)]
    cid = c.sentence.ID
    bound = "{" + ",".join(allowed) + "}"
    out = []
    for a in allowed:
        variants = dict.fromkeys((a.lower(), a.upper(), a.title())) if c.fold else {a: None}
        out += [Edge(c.clause, cid, c.field, bound, "in", v, "choice") for v in variants]
    out += [Edge(c.clause, cid, c.field, bound, "out", str(r), "choice") for r in c.refused
            if (str(r).lower() not in {a.lower() for a in allowed} if c.fold else str(r) not in allowed)]
    if c.fold:  # a keyword of the grammar the profile leaves out is refused
        for word in _grammar_keywords():
            if word.lower() not in {a.lower() for a in allowed}:
                out.append(Edge(c.clause, cid, c.field, bound, "out", word.upper(), "choice"))
    return out


def _name_edges(r: NameRule, p: Profile) -> list[Edge]:
    cid = r.sentence.ID
    out = [Edge(r.clause, cid, r.field, "in the mission directory", "in", "a name inside", "name")]
    out += [Edge(r.clause, cid, r.field, "in the mission directory", "out", kind, "name")
            for kind in NAME_KINDS if not (r.optional and kind == "empty")]
    return out


@lru_cache(maxsize=1)
def _grammar_facts() -> tuple[dict, dict, dict]:
    """From ``remote_helm.lark``: repeated fields (item rule -> (lo, hi)), field rule -> terminal,
    terminal -> regex."""
    text = grammar_text()
    items = {m.group(1): (int(m.group(2)), int(m.group(3)))
             for m in re.finditer(r"(\w+_item)~(\d+)\.\.(\d+)", text)}
    field_term = dict(re.findall(r"^([a-z_0-9]+): ([A-Z_0-9]+)\s*$", text, re.M))
    terms = dict(re.findall(r"^([A-Z_0-9]+): /(.*)/\s*$", text, re.M))
    return items, field_term, terms


def _grammar_keywords() -> list[str]:
    """The ``$OMW`` keywords the grammar reads (``CLEAR_KW``)."""
    rx = _grammar_facts()[2].get("CLEAR_KW", "")
    m = re.fullmatch(r"\(\?i:([a-z|]+)\)", rx)
    return m.group(1).split("|") if m else []


def _grammar_edges(p: Profile, claimed: set) -> list[Edge]:
    items, field_term, terms = _grammar_facts()
    out = []
    for rule, cls in sentence_classes_by_rule().items():
        if not issubclass(cls, S.Command) or cls.ID not in claimed or cls is S.OXFLT:
            continue
        err = ACK_CLAUSE.get(cls.ID, "RH-ACK-3")
        for f in specs()[rule].fields:
            if f.kind == "items" and f.rule in items and cls is not S.OSD:
                lo, hi = items[f.rule]
                bound = f"{lo}..{hi}"
                out += [Edge(err, cls.ID, f.attr, bound, "in", str(lo), "count"),
                        Edge(err, cls.ID, f.attr, bound, "in", str(hi), "count"),
                        Edge(err, cls.ID, f.attr, bound, "out", str(hi + 1), "count")]
                if lo > 0:
                    out.append(Edge(err, cls.ID, f.attr, bound, "out", str(lo - 1), "count"))
            term = terms.get(field_term.get(f.rule, ""), "")
            m = re.fullmatch(r"\[([^\]]+)\]\{(\d+)\}", term)
            if m:
                n = int(m.group(2))
                clause = _FIELD_CLAUSE.get((cls.ID, f.attr), err)
                bound = f"{n} digits"
                out += [Edge(clause, cls.ID, f.attr, bound, "in", str(n), "width"),
                        Edge(clause, cls.ID, f.attr, bound, "out", str(n - 1), "width"),
                        Edge(clause, cls.ID, f.attr, bound, "out", str(n + 1), "width")]
                if "a-f" in m.group(1) and "A-F" in m.group(1):
                    out.append(Edge(clause, cls.ID, f.attr, "hex case", "in", "lower", "case"))
    letters = re.fullmatch(r"\[([A-Z]+)\]", terms.get("OSD_LETTER", ""))
    if letters:
        for x in letters.group(1):
            out.append(Edge("RH-RD-7", "OSD", "letters", letters.group(1), "in", x, "letter"))
        out.append(Edge("RH-RD-7", "OSD", "letters", letters.group(1), "out", "lower case", "letter"))
    return out


#: The clause that states a grammar field's rule, where it is not the command's RH-ACK-3.
_FIELD_CLAUSE = {("OMP", "actuators"): "RH-PRM-2"}
#: The clause of a repeated field's count (RH-LOG-1's labels, RH-LOG-2's values, RH-RD-8's values).
ACK_CLAUSE = {"OLOGL": "RH-LOG-1", "OLOGD": "RH-LOG-2", "ORWSET": "RH-RD-8"}


def _state_edges(p: Profile, claimed: set) -> list[Edge]:
    out = []
    if "OJW" in claimed:
        out += [Edge("RH-JW-1", "OJW", "waypoint", "<=last waypoint", "in", "the last waypoint", "state"),
                Edge("RH-JW-1", "OJW", "waypoint", "<=last waypoint", "out", "one past the last", "state")]
    if "OLOGD" in claimed:
        out += [Edge("RH-LOG-2", "OLOGD", "values", "<=labels", "in", "as many as labels", "state"),
                Edge("RH-LOG-2", "OLOGD", "values", "<=labels", "out", "one more than labels", "state")]
    if "OPK" in claimed:
        lim = _text(Decimal(repr(float(p.opk_max_distance_m))))
        out += [Edge("RH-PK-1", "OPK", "distance", f"<={lim} m", "in", "just inside", "state"),
                Edge("RH-PK-1", "OPK", "distance", f"<={lim} m", "out", "just outside", "state")]
    if "OPOS" in claimed:
        for side, where in (("fix", "no mission, at the surface"), ("fix", "a mission, at the surface"),
                            ("no-fix", "ignore-GPS start, at the surface"), ("no-fix", "under water")):
            out.append(Edge("RH-POS-2", "OPOS", "position", "GPS fix", side, where, "state"))
    return out


@lru_cache(maxsize=32)
def edge_list(profile: Profile) -> tuple[Edge, ...]:
    """Every edge of §4–8 and §8b for the commands ``profile`` claims (module docstring)."""
    claimed = set(profile.commands) | {"OSD"}
    out: list[Edge] = []
    for cls, rows in COMMAND_CHECKS.items():
        if cls.ID not in claimed:
            continue
        for row in rows:
            if isinstance(row, Bound):
                out += _range_edges(row, profile)
            elif isinstance(row, Choice):
                out += _choice_edges(row, profile)
            elif isinstance(row, NameRule):
                out += _name_edges(row, profile)
    out += _grammar_edges(profile, claimed)
    out.append(Edge("RH-FRM-3", "*", "checksum", "hex case", "in" if profile.lowercase_checksum_in else "out",
                    "lower", "checksum"))
    out += _state_edges(profile, claimed)
    seen: dict[str, Edge] = {}
    for e in out:
        seen.setdefault(e.id, e)
    return tuple(seen.values())


def _find(edges, command: str, field: str, side: str, bound_prefix: str) -> str:
    return next(e.probe for e in edges if e.command == command and e.field == field and e.side == side
                and e.bound.startswith(bound_prefix))


def edge_values(profile: Profile) -> dict[str, str]:
    """The case templates for the profile's own bounds (:mod:`.steps`), from :func:`edge_list`:
    ``{to_lo}``/``{to_hi}`` the timeout range's ends and ``{to_under}``/``{to_over}`` one past them,
    ``{depth_max}``/``{depth_out}``, ``{speed_max}``/``{speed_out}``, ``{wp_first}``/``{wp_under}``."""
    p = profile.replace(commands=tuple(set(profile.commands) | {"OMS", "OJW"}))
    e = edge_list(p)
    return {"to_lo": _find(e, "OMS", "timeout", "in", ">="), "to_under": _find(e, "OMS", "timeout", "out", ">="),
            "to_hi": _find(e, "OMS", "timeout", "in", "<="), "to_over": _find(e, "OMS", "timeout", "out", "<="),
            "depth_max": _find(e, "OMS", "depth", "in", "<="), "depth_out": _find(e, "OMS", "depth", "out", "<="),
            "speed_max": _find(e, "OMS", "speed", "in", "<="), "speed_out": _find(e, "OMS", "speed", "out", "<="),
            "wp_first": _find(e, "OJW", "waypoint", "in", ">="), "wp_under": _find(e, "OJW", "waypoint", "out", ">=")}


def opk_edge_m(profile: Profile, side: str) -> float:
    """The ``$OPK`` edge's distance on ``side`` (``in``/``out``) of the limit, metres."""
    margin = OPK_EDGE * profile.opk_max_distance_m
    return profile.opk_max_distance_m + (margin if side == "out" else -margin)


def north_of(lat: float, metres: float) -> str:
    """The latitude ``metres`` due north of ``lat`` on the sphere the model measures on."""
    return f"{lat + math.degrees(metres / EARTH_RADIUS_M):.6f}"


# ============================================================================ the tally

def _fields(raw: bytes) -> Optional[list[str]]:
    """The comma-separated fields of a framed line's body (ID first), or None."""
    try:
        text = raw.decode("ascii")
    except UnicodeDecodeError:
        return None
    dollar, star = text.rfind("$"), text.rfind("*")
    if dollar < 0 or star < dollar:
        return None
    return text[dollar + 1:star].split(",")


def _frame(fields: list[str]) -> bytes:
    body = ",".join(fields)
    return f"${body}*{checksum_hex(body)}\r\n".encode()


def _same(a: str, b: str) -> bool:
    try:
        return Decimal(a) == Decimal(b)
    except (InvalidOperation, ValueError):
        return a == b


@lru_cache(maxsize=None)
def _pos(cls: type, field: str) -> int:
    """The field's position in the line (the ID is 0)."""
    return 1 + next(i for i, f in enumerate(_spec(cls).fields) if f.attr == field)


class EdgeTally:
    """Which edges a run reached (module docstring). The session calls :meth:`before` with each
    line and the observer's model before it is sent, then :meth:`track` with what the observer
    made of the line, or :meth:`refused` when the bench-safety interlock kept it back."""

    def __init__(self, profile: Profile):
        self.profile = profile
        self.edges = edge_list(profile)
        self._by_cmd: dict[str, list[Edge]] = {}
        for e in self.edges:
            self._by_cmd.setdefault(e.command, []).append(e)
        self.reached: dict[str, str] = {}  #: edge id -> the case that reached it first ("" outside cases)
        self.held: dict[str, str] = {}  #: edge id -> why a line at it was not sent
        self._pending: list = []

    # ------------------------------------------------------------------ classifying
    def before(self, raw: bytes, model) -> list[tuple[Edge, str]]:
        """The edges ``raw`` is at in ``model``'s state, each with the answer the model must give
        it for the edge to count (``keep``: not refused for its fields; ``own``: refused with the
        command's own error; ``err40``; ``ack``/``silent``: read / discarded, RH-FRM-3)."""
        f = _fields(raw)
        if not f or not f[0]:
            return []
        out = []
        star = raw.rfind(b"*")
        ck = raw[star + 1:star + 3].decode("latin-1") if star >= 0 else ""
        if ck != ck.upper():
            for e in self._by_cmd.get("*", ()):
                out.append((e, "ack" if e.side == "in" else "silent"))
        edges = self._by_cmd.get(f[0])
        if not edges:
            return out
        d = decode(raw, self.profile)
        for e in edges:
            need = self._match(e, f, d, model)
            if need:
                out.append((e, need))
        return out

    def _match(self, e: Edge, f: list[str], d, model) -> Optional[str]:
        kind = e.kind
        if kind == "state":
            return self._state(e, d, model)
        if kind == "letter":
            if e.side == "in":
                return "keep" if d.sentence is not None and e.probe in getattr(d.sentence, "letters", ()) else None
            x = f[1] if len(f) == 2 else ""
            return self._out(f, 1, x.upper(), d, model, S.OSD) if x.islower() and x.upper() in e.bound else None
        cls = _CLASS_OF.get((e.command, e.field))
        if e.command == "OMSTART":
            cls = S.OMSTARTPaper if e.field == "flag" else S.OMSTART
        if cls is None:
            return None
        i = _pos(cls, e.field)
        if kind == "count":
            n, (lo, hi) = len(f) - i, map(int, e.bound.split(".."))
            if str(n) != e.probe:
                return None
            if e.side == "in":
                return "keep" if isinstance(d.sentence, cls) else None
            twin = f[:i + hi] if n > hi else f + ["a"] * (lo - n)
            return self._twin(twin, cls, d, model)
        if len(f) <= i:
            return None
        text = f[i]
        if kind == "width":
            if re.fullmatch(r"[0-9A-Fa-f]*", text) is None or str(len(text)) != e.probe:
                return None
            if e.side == "in":
                return "keep" if isinstance(d.sentence, cls) else None
            width = int(e.bound.split()[0])
            return self._out(f, i, (text + "0" * width)[:width], d, model, cls)
        if kind == "case":
            return "keep" if isinstance(d.sentence, cls) and re.search(r"[a-f]", text) else None
        if kind == "name":
            why = mission_name_problem(text) if (text or e.field != "srp") else None
            if e.side == "in":
                return "keep" if why is None and text and isinstance(d.sentence, cls) else None
            if why is None or _name_kind(why) != e.probe:
                return None
            return self._out(f, i, self.profile.mission, d, model, cls)
        if kind == "choice" and e.field == "values":  # $ORWSET,SafetyAction,W,<state>,<one value>
            if f[1:2] != ["SafetyAction"] or f[i:] != [e.probe]:
                return None
        elif not (_same(text, e.probe) if kind == "range" else text == e.probe):
            return None
        if e.side == "in":
            return "keep" if isinstance(d.sentence, cls) else None
        inside = self._inside(e)
        return self._out(f, i, inside, d, model, cls) if inside is not None else None

    def _inside(self, e: Edge) -> Optional[str]:
        """The value on the inside of ``e``'s bound (its twin's)."""
        for x in self._by_cmd[e.command]:
            if x.field == e.field and x.bound == e.bound and x.side == "in" and x.kind == e.kind:
                return x.probe
        return None

    def _out(self, f: list[str], i: int, inside: str, d, model, cls) -> Optional[str]:
        """The line with ``inside`` in place of its field ``i`` (:meth:`_twin`)."""
        return self._twin(f[:i] + [inside] + f[i + 1:], cls, d, model)

    def _twin(self, twin: list[str], cls, d, model) -> Optional[str]:
        """An outside value counts when the line itself is refused and its twin — the same line
        with the field moved inside — is a valid command a conforming vehicle in ``model``'s state
        does not refuse for its fields (so that the refusal can only be the bound's)."""
        if d.sentence is not None or model is None:
            return None
        t = decode(_frame(twin), self.profile).sentence
        if t is None or not isinstance(t, cls):
            return None
        replies = model.clone().receive(t, model.now if model.now is not None else 0.0)
        ack = next((r for r in replies if isinstance(r, S.ACK)), None)
        if ack is None:
            return None
        return "own" if not ack.status or ack.err not in (_OWN_ERR.get(cls.ID), 26) else None

    def _state(self, e: Edge, d, model) -> Optional[str]:
        s, m = d.sentence, model
        if s is None or m is None:
            return None
        if e.command == "OJW" and isinstance(s, S.OJW) and m.mission is not None:
            n = s.waypoint - self.profile.waypoint_base
            want = m.mission.last + (0 if e.side == "in" else 1)
            return ("keep" if e.side == "in" else "own") if n == want else None
        if e.command == "OLOGD" and isinstance(s, S.OLOGD) and m.log_labels is not None:
            want = len(m.log_labels) + (0 if e.side == "in" else 1)
            return ("keep" if e.side == "in" else "own") if len(s.values) == want else None
        if e.command == "OPK" and isinstance(s, S.OPK):
            snap = m.snapshot
            lim = self.profile.opk_max_distance_m
            dist = distance_m(snap.lat, snap.lon, float(s.lat), float(s.lon))
            if e.side == "in" and lim * (1 - 2 * OPK_EDGE) <= dist <= lim:
                return "keep"
            if e.side == "out" and lim < dist <= lim * (1 + 2 * OPK_EDGE):
                return "err40"
            return None
        if e.command == "OPOS" and isinstance(s, S.OPOS):
            snap = m.snapshot
            if distance_m(snap.lat, snap.lon, float(s.lat), float(s.lon)) < OPOS_APART_M:
                return None
            fix_depth = self.profile.gps_fix_depth_m
            surface, under = snap.depth_m <= fix_depth, snap.depth_m > 2 * fix_depth + 0.5
            if m.mission is None:
                where = "no mission, at the surface" if surface else None
            elif getattr(m, "ignore_gps", False):
                where = "ignore-GPS start, at the surface" if surface else None
            else:
                where = "a mission, at the surface" if surface else ("under water" if under else None)
            return "keep" if where == e.probe else None
        return None

    # ------------------------------------------------------------------ answers
    def track(self, sent, cands: list) -> None:
        """What the observer made of the line ``cands`` were found for (settled when answered)."""
        if cands and sent is not None:
            self._pending.append((sent, cands))
        self._settle()

    def refused(self, cands: list, why: str) -> None:
        """A line at these edges was kept back (``why``: the bench-safety interlock)."""
        for e, _ in cands:
            self.held.setdefault(e.id, why)

    def _settle(self, final: bool = False) -> None:
        keep = []
        for sent, cands in self._pending:
            if not sent.done and not final:
                keep.append((sent, cands))
                continue
            ack = next((r for r in sent.expected if isinstance(r, S.ACK)), None)
            for e, need in cands:
                if self.reached.get(e.id) or not self._answered(sent, ack, need, e):
                    continue  # the first case that reached it (a line outside any case, until one does)
                self.reached[e.id] = sent.case or ""
        self._pending = keep

    def _answered(self, sent, ack, need: str, e: Edge) -> bool:
        if need == "silent":
            return ack is None
        if ack is None or sent.ack is None:
            return False
        err = int(ack.err) if int(ack.status) else 0
        if need == "ack":
            return True
        own = _OWN_ERR.get(e.command)
        if need == "keep":
            return err not in (own, 26)
        if need == "own":
            return err == own
        return err == 40

    def summary(self) -> dict:
        """What ``results.json`` keeps (``stats.edges``): how many edges there are and were
        reached, per clause, and those not reached (with why, where a line at one was kept back)."""
        self._settle(final=True)
        by_clause: dict[str, list[int]] = {}
        unreached = []
        for e in self.edges:
            got = by_clause.setdefault(e.clause, [0, 0])
            got[1] += 1
            if e.id in self.reached:
                got[0] += 1
            else:
                item = {"edge": e.id, "clause": e.clause}
                if e.id in self.held:
                    item["why"] = self.held[e.id]
                unreached.append(item)
        return {"of": len(self.edges), "reached": len(self.edges) - len(unreached),
                "by_clause": {c: {"reached": n, "of": m} for c, (n, m) in sorted(by_clause.items())},
                "unreached": unreached}


def _name_kind(why: str) -> str:
    for kind in NAME_KINDS:
        if kind in why:
            return kind
    return ""


#: (command, field) -> the class the field belongs to (``$OMSTART``'s two forms: :meth:`EdgeTally._match`).
_CLASS_OF = {(cls.ID, f.attr): cls for cls in (S.OMS, S.OMP, S.OJW, S.OMSTOP, S.OMLOAD, S.OPOS, S.ORWSET, S.ODVL,
                                                S.OPK, S.OMW, S.OLOGL, S.OLOGD, S.OSD) for f in _spec(cls).fields}
_CLASS_OF[("OMW", "keyword")] = S.OMWClear

#: Each command's own "incorrect values" error (RH-ACK-3).
_OWN_ERR = {cls.ID: cls.ERR for cls in sentence_classes_by_rule().values() if issubclass(cls, S.Command)
            and getattr(cls, "ERR", None)}
