"""The readings table (``helmcheck/model/readings.py``): every question the profile leaves open, every reading accepted.

A row is a promise in four places, and each is checked here:

* the table itself: at least two readings, a clause of the profile, the profile's words quoted;
* the emulator takes every reading (``--set KEY=VALUE``), and refuses a value no row names;
* the docs page (``docs/readings.md``) and ``helmcheck profile readings`` list every row;
* the judge accepts every reading: the emulator's core under each reading, driven in virtual time
  into the very situation the question is about, judged offline by the vehicle observer — no
  FAIL, and the report names the reading the vehicle took — while an answer no reading allows
  still FAILs on its clause; and a certification of the clauses whose cases meet the question
  (``Reading.certify``) PASSes under every reading (a real emulator process on a pty, ×20).

A reading added in one place and not the others fails one of these tests.
"""

from __future__ import annotations

import dataclasses
import io
from contextlib import redirect_stdout
from pathlib import Path

import pytest

from helmcheck.checklog.checker import check_log
from helmcheck.clauses import catalogue
from helmcheck.emulator.freedoms import EmulatorSettings, SettingsError, parse_assignment, settings_from_dict
from helmcheck.emulator.missionfile import DirectoryCatalog, builtin_dir
from helmcheck.grammar import checksum_hex
from helmcheck.model.readings import BY_KEY, DEFAULTS, READINGS
from tests.faulty_vehicles import EMU_PROFILE
from tests.virtual_vehicle import VirtualVehicle, osi_fields

ROOT = Path(__file__).resolve().parents[1]
PROFILE = EMU_PROFILE.replace(time_scale=1.0, baud=19200)


# ============================================================================ the table, everywhere

@pytest.mark.parametrize("r", READINGS, ids=[r.key for r in READINGS])
def test_every_row_is_a_real_question_with_every_reading_takeable(r):
    ids = set(catalogue())
    assert r.clause in ids, r.clause
    assert len(r.choices) >= 2 and len(set(r.values)) == len(r.values), r.values
    assert r.words and r.question.endswith("?")
    assert r.how in ("model", "judge", "freedom", "backseat")
    if r.setting is None:  # nothing differs on the wire that a judge rules on (its text says why)
        assert (r.how == "judge" and ("not judged" in r.judge or "sends only" in r.judge)
                or r.how == "backseat" and "judged" in r.judge), r.judge
        return
    fields = {f.name for f in dataclasses.fields(EmulatorSettings)}
    assert r.setting in fields, f"the emulator has no setting {r.setting!r} for reading {r.key}"
    word = lambda v: str(v).lower()  # noqa: E731 - a boolean setting's readings are its words
    assert word(getattr(EmulatorSettings(), r.setting)) == r.default, "the emulator's default is the model's own"
    for value in r.values:
        assert word(getattr(settings_from_dict(parse_assignment(f"{r.setting}={value}")), r.setting)) == value
    with pytest.raises(SettingsError):
        settings_from_dict({r.setting: "no-such-reading"})


def test_the_docs_page_and_the_command_list_every_row():
    from helmcheck.cli import main
    page = (ROOT / "docs" / "readings.md").read_text()
    buf = io.StringIO()
    with redirect_stdout(buf):
        assert main(["profile", "readings"]) == 0
    for r in READINGS:
        assert r.key in buf.getvalue() and (f"`{r.setting}`" in page if r.setting else r.clause in page)
        for value in r.values:
            assert f"`{value}`" in page, (r.key, value)
    assert "docs/readings.md" in (ROOT / "docs" / "choices.md").read_text() or "readings.md" in \
        (ROOT / "docs" / "choices.md").read_text(), "docs/choices.md cites the readings table"


# ============================================================================ the judge, sans-IO

def frame(body: str) -> str:
    return f"${body}*{checksum_hex(body)}"


class Drive:
    """The emulator's core under one reading, in virtual time, its wire log judged offline."""

    def __init__(self, **readings: str):
        self.v = VirtualVehicle(PROFILE, settings=settings_from_dict(dict(readings)))
        self.send("OSD,S")  # the state known from the start, as a tester makes it

    def send(self, body: str) -> bytes:
        return self.v.send(body)

    def after(self, seconds: float, poll_every: float = 2.0) -> None:
        """Let ``seconds`` pass, polling ``$OSD,S`` every ``poll_every`` s (the judge sees the way)."""
        end = self.v.now + seconds
        while self.v.now < end:
            self.v.now = min(end, self.v.now + poll_every)
            self.v.core.tick(self.v.now)
            self.send("OSD,S")

    def judged(self, tmp_path: Path, edit=None) -> dict:
        log = self.v.write(tmp_path / "v.log")
        if edit is not None:
            log.write_text(edit(log.read_text()))
        out = check_log(log, profile=PROFILE, role="vehicle", catalog=DirectoryCatalog([builtin_dir()]))
        return {c["id"]: c for c in out.clauses}


def failed(v: dict) -> dict:
    return {cid: c["reason"] for cid, c in v.items() if c["verdict"] in ("fail", "inconclusive")}


def answer(out: bytes) -> str:
    acks = [ln for ln in out.decode().split("\r\n") if ln.startswith("$ACK")]
    return acks[-1].split("*")[0] if acks else ""


def _srp(d: Drive) -> list[str]:
    got = [answer(d.send("OMSTART,0,0,0,0,conformance.mis,/conformance.mis")),
           answer(d.send("OMSTART,0,0,0,0,conformance.mis,sub/../../srp.mis"))]
    d.send("OMSTART,0,0,0,0,conformance.mis,")
    d.after(2.0)
    got.append(answer(d.send("OMSTART,0,0,0,0,conformance.mis,C:srp.mis")))  # running: the state first
    return got


def _ascent(d: Drive) -> list[str]:
    d.send("OMSTART,0,0,0,0,conformance.mis,")
    d.after(2.0)
    d.send("OMS,90,10,20,2,120")
    d.after(30.0)
    d.send("OXFLT,Sed")
    d.after(23.0, poll_every=1.0)  # past the lockout and its tolerance: in the ascent
    return [answer(d.send("OMS,360,2,20,1,10")), answer(d.send("OMS,90,2,20,1,10"))]


def _omw(d: Drive) -> list[str]:
    d.send("OMSTART,0,0,0,0,conformance.mis,")
    d.after(2.0)
    got = [answer(d.send("OMW,41.5205,-71.3195,2,,45.1,1,0,")), answer(d.send("OMW,41.5205,-71.3195,2,,15,4.6,0,"))]
    d.after(2.0)
    return got


def _stop(d: Drive) -> list[str]:
    d.send("OMLOAD,conformance.mis,0")
    got = [answer(d.send("OMSTART,0"))]
    d.after(2.0)
    d.send("OMSTOP,0")
    d.after(1.0)
    got.append(answer(d.send("OMSTART,0")))
    d.after(1.0)
    return got


def _ctd(d: Drive) -> list[str]:
    got = []
    for c, t in (("42.5", "17.5"), ("43.5", "18.5")):
        d.send(f"OPOS,41.53,-71.32,0,{c},{t}")  # 1.1 km away, at the surface in S: not applied (RH-RD-10)
        d.after(1.0)
        out = d.send("OSD,T").decode()
        ctd = next(ln for ln in out.split("\r\n") if ln.startswith("$OCTD"))
        got.append("shown" if ctd.split("*")[0].split(",")[1:3] == [f"{c}0", f"{t}0"] else "own")
    return got


def _park(d: Drive) -> list[str]:
    d.send("OMSTART,0,0,0,0,conformance.mis,")
    for _ in range(200):  # until the mission park (virtual seconds)
        d.after(5.0, poll_every=5.0)
        f = osi_fields(d.send("OSD,S"))
        if f[2] == "P":
            d.after(5.0)
            return [f[3]]
    raise AssertionError("the test mission never parked")


def _flag(d: Drive) -> list[str]:
    return [answer(d.send(f"OMLOAD,conformance.mis,{flag}")) for flag in (0, 1, 3, 4)]


#: key -> (how the situation is reached, the answers under each reading, the clauses judged,
#: an answer no reading allows: (the text to replace, its replacement, the clause it fails))
SITUATIONS = {
    "srp_bad_path": (_srp, {"30": ["$ACK,3,1,30"] * 3, "31": ["$ACK,3,1,31", "$ACK,3,1,31", "$ACK,3,1,30"]},
                     ("RH-MSN-1", "RH-MSN-2"), ("$ACK,3,1,30", "$ACK,3,1,32", "RH-ACK-3")),
    "ascent_refusal_order": (_ascent, {"first": ["$ACK,9,1,26", "$ACK,9,1,26"],
                                       "after fields": ["$ACK,9,1,20", "$ACK,9,1,26"]},
                             ("RH-SAF-3", "RH-SRV-2"), ("$ACK,9,1,26", "$ACK,9,0,0", "RH-SAF-3")),
    "omw_pitch_speed": (_omw, {"bounded": ["$ACK,16,1,36", "$ACK,16,1,36"],
                               "unbounded": ["$ACK,16,0,0", "$ACK,16,0,0"]},
                        ("RH-OMW-1", "RH-ACK-3"), ("$ACK,16,1,36", "$ACK,16,1,20", "RH-ACK-3")),
    "opos_ctd": (_ctd, {"reported": ["shown", "shown"], "internal": ["own", "own"]}, ("RH-POS-2",),
                 ("$OCTD,43.50,18.50", "$OCTD,42.50,17.50", "RH-POS-2")),  # shown once, then not: held to it
    "park_waypoint": (_park, {"parked": ["1"], "next": ["2"]}, ("RH-OUT-4",),
                      (",P,1,", ",P,3,", "RH-OUT-4", 0)),
    "omload_flag": (_flag, {"any": ["$ACK,2,0,0"] * 4, "0-3": ["$ACK,2,0,0"] * 3 + ["$ACK,2,1,29"],
                            "0": ["$ACK,2,0,0"] + ["$ACK,2,1,29"] * 3}, ("RH-MSN-1",),
                    ("$ACK,2,0,0", "$ACK,2,1,28", "RH-MSN-1", 2)),
    "stop_unloads": (_stop, {"kept": ["$ACK,3,0,0", "$ACK,3,0,0"], "unloaded": ["$ACK,3,0,0", "$ACK,3,1,17"]},
                     ("RH-MSN-2",), ("$ACK,3,0,0", "$ACK,3,1,30", "RH-MSN-2", 2)),
}


def test_every_reading_the_model_answers_by_has_a_situation_here():
    assert {r.key for r in READINGS if r.in_model} == set(SITUATIONS)
    assert {r.key for r in READINGS if r.how == "model"} <= {r.key for r in READINGS if r.in_model}


@pytest.mark.parametrize("key,value", [(k, v) for k in SITUATIONS for v in BY_KEY[k].values],
                         ids=[f"{k}={v}" for k in SITUATIONS for v in BY_KEY[k].values])
def test_the_judge_accepts_every_reading_and_names_the_one_taken(key, value, tmp_path):
    drive, answers, clauses, _ = SITUATIONS[key]
    d = Drive(**{BY_KEY[key].setting: value})
    assert drive(d) == answers[value], "the emulator takes the reading"
    v = failed(d.judged(tmp_path))
    assert not v, v
    judged = d.judged(tmp_path)
    assert any(judged[c]["verdict"] == "pass" for c in clauses), {c: judged[c]["verdict"] for c in clauses}
    if value != DEFAULTS[key]:
        assert any(f"{key} = {value}" in c["reason"] for c in judged.values()), "the report names the reading"


@pytest.mark.parametrize("key", list(SITUATIONS))
def test_an_answer_no_reading_allows_still_fails_on_its_clause(key, tmp_path):
    drive, _, _, (old, new, clause, *nth) = SITUATIONS[key]
    d = Drive()
    drive(d)

    def edit(text: str) -> str:
        if nth == [0]:  # every such answer (a vehicle that always gives it)
            while old in text:
                text = edit_one(text, 1)
            return text
        return edit_one(text, nth[0] if nth else 1)

    def edit_one(text: str, n: int) -> str:
        first = -1
        for _ in range(n):  # the answer the question turns on, made one no reading gives
            first = text.index(old, first + 1)
        start, end = text.rindex("$", 0, first + 1), text.index("*", first)  # the whole sentence, its sum again
        body = text[start + 1:end].replace(old.lstrip("$"), new.lstrip("$"), 1)
        return text[:start] + f"${body}*{checksum_hex(body)}" + text[end + 3:]
    v = d.judged(tmp_path, edit)
    assert v[clause]["verdict"] == "fail", failed(v)


# ============================================================================ certified, every reading

import os  # noqa: E402

#: readings the emulator already takes in make test's other certifications (tests/test_emulator_freedoms.py:
#: idle_distance = last; tests/test_checklog_opk_over_park.py: resumed_park = on station, judged offline):
#: certified here only in make matrix (HELMCHECK_MATRIX=1)
ELSEWHERE = ("idle_distance", "resumed_park")
MATRIX = os.environ.get("HELMCHECK_MATRIX") == "1"
CERTIFIED = [(r.key, value) for r in READINGS if r.setting and r.certify and (MATRIX or r.key not in ELSEWHERE)
             for value in r.values if value != r.default]


@pytest.mark.xdist_group("readings")
@pytest.mark.parametrize("key,value", CERTIFIED, ids=[f"{k}={v}" for k, v in CERTIFIED])
def test_the_emulator_under_each_reading_certifies(key, value, tmp_path):
    from tests.test_emulator_freedoms import certify_with, judge, settings_of
    r = BY_KEY[key]
    sets = [f"{r.setting}={value}"]
    got = certify_with(sets, 20.0, list(r.certify), tmp_path / "r")
    assert got["agree"], got["disagree"]
    left = judge(got, settings_of(sets), True)
    assert not left, left
    assert got["exit"] == 0, got
