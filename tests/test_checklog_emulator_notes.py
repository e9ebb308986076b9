"""RH-OUT-4 with RH-RD-5: the emulator's own log, its notes kept, checked without the mission files.

``helmcheck emulate --log`` writes, besides the line, the emulator's notes: the plant's events
(``plant: WaypointReached(index=1) at v=…``) and the model's. The vehicle judge acts on the plant
notes (exact moments it would otherwise have to place in a window). Without ``--missions`` it
does not know what a waypoint holds — a mission park, how long, whether it is the last — and
learns it from the reports; a plant note that a waypoint was reached must not be applied as if
the waypoint held nothing (the judge then expected ``N`` toward the next waypoint where the
vehicle rightly reports its mission park): such a note is left to the reports, as if the log had
no notes. The session is the reference emulator's core driven in virtual time to and through the
park of ``conformance.mis`` (waypoint 1, 300 s), its log kept whole.

A note also comes between an ``$OSD`` and its ``$OSI`` when the event happened while the report
was on its way: the report shows the state the vehicle was in when it processed the ``$OSD``,
before the event, and is judged before the note is applied (it was judged against the state
after it: a queued waypoint reached, the park on it expected, ``P0`` FAILed).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from helmcheck.checklog.checker import check_log
from helmcheck.emulator.missionfile import DirectoryCatalog, builtin_dir
from helmcheck.profile import DEFAULT
from tests.virtual_vehicle import VirtualVehicle, osi_fields

M_PER_DEG = 111_320.0


def session(path: Path, through: bool = True) -> list:
    """Start ``conformance.mis``, report every 0.5 s until the vehicle heads for waypoint 2 after
    the park (``through``) or 30 s into the park; keep the log with its notes."""
    vv = VirtualVehicle(DEFAULT)
    seen = []
    vv.send("OMSTART,0,0,0,0,conformance.mis,")
    park_at = None
    while vv.now < 900:
        vv.now += 0.5
        f = osi_fields(vv.send("OSD,S"))
        seen.append((f[2], int(f[3]), f[10]))
        if f[2] == "P" and park_at is None:
            park_at = vv.now
        if int(f[3]) >= 2 or (not through and park_at is not None and vv.now > park_at + 30):
            break
    path.write_text(vv.buf.getvalue())  # the whole log: the emulator's notes kept
    return seen


@pytest.mark.parametrize("missions", [False, True], ids=["learnt", "given"])
def test_the_emulator_s_own_log_with_its_notes_passes_with_or_without_the_missions(tmp_path, missions):
    path = tmp_path / "wire.log"
    seen = session(path)
    assert ("P", 1) in [(m, w) for m, w, _ in seen] and seen[-1][:2] == ("N", 2), seen[-3:]
    assert " ! plant: WaypointReached(index=1)" in path.read_text()  # the notes are there
    catalog = DirectoryCatalog([builtin_dir()]) if missions else None
    out = check_log(path, profile=DEFAULT, role="vehicle", catalog=catalog)
    bad = {c["id"]: c["reason"] for c in out.clauses if c["verdict"] == "fail"}
    assert not bad, bad
    verdicts = {c["id"]: c["verdict"] for c in out.clauses}
    assert verdicts["RH-OUT-4"] == "pass"


@pytest.mark.parametrize("missions", [False, True], ids=["learnt", "given"])
def test_a_park_count_that_jumps_is_still_caught_with_the_notes(tmp_path, missions):
    """The faulty counterpart: the same log with the mission park's reports from its 10th second on
    rewritten to show a minute less (a count that jumps): still RH-OUT-4's FAIL."""
    path = tmp_path / "wire.log"
    session(path, through=False)
    out_lines, first = [], None
    for ln in path.read_text().splitlines(keepends=True):
        if "$OSI," in ln and ",P,1," in ln:
            t = float(ln.split()[0])
            first = t if first is None else first
            if t > first + 10:
                ln = _shorten(ln)
        out_lines.append(ln)
    path.write_text("".join(out_lines))
    catalog = DirectoryCatalog([builtin_dir()]) if missions else None
    out = check_log(path, profile=DEFAULT, role="vehicle", catalog=catalog)
    verdicts = {c["id"]: c["verdict"] for c in out.clauses}
    assert verdicts["RH-OUT-4"] == "fail", verdicts


def _shorten(line: str) -> str:
    """An ``$OSI`` line in the mission park with field 10 lowered by 60 s (checksum redone)."""
    from helmcheck.grammar import checksum_hex
    head, sentence = line.split("$", 1)
    body = sentence.split("*", 1)[0]
    f = body.split(",")
    f[10] = f"P{max(0, int(f[10][1:]) - 60)}"
    body = ",".join(f)
    return f"{head}${body}*{checksum_hex(body)}\n"


def in_flight_session(path: Path, margin_m: float) -> list:
    """A waypoint queued 30 m north with a 20 s park; reports every 0.5 s until it is 4.5 m off,
    then the plant alone until it is ``margin_m`` from on station (3 m), then a report — the
    vehicle arrives while that report is on its way — and reports for 4 s. The log keeps its notes.
    Returns the lines of the log from that report's ``$OSD`` to its ``$OSI``."""
    vv = VirtualVehicle(DEFAULT)
    m = vv.core.model
    vv.send("OMSTART,0,0,0,0,conformance.mis,")
    vv.now += 5.0
    f = osi_fields(vv.send("OSD,G,C,S"))
    vv.send(f"OMW,{float(f[4]) + 30 / M_PER_DEG:.6f},{float(f[5]):.6f},2.0,,20,2.0,20,")
    while float(f[7]) >= 4.5 and vv.now < 100:
        vv.now += 0.5
        f = osi_fields(vv.send("OSD,G,C,S"))
    while m._distance() > 3.0 + margin_m:
        vv.now += 0.005
        vv.core.tick(vv.now)
    mark = len(vv.buf.getvalue())
    vv.send("OSD,G,C,S")
    between = vv.buf.getvalue()[mark:].splitlines()
    for _ in range(8):
        vv.now += 0.5
        vv.send("OSD,G,C,S")
    path.write_text(vv.buf.getvalue())
    return between[:next(i for i, ln in enumerate(between) if "$OSI," in ln) + 1]


@pytest.mark.parametrize("margin_m", [0.01, 0.02, 0.04, 0.08])
def test_a_plant_note_while_a_report_is_on_its_way_is_applied_after_it(tmp_path, margin_m):
    path = tmp_path / "wire.log"
    between = in_flight_session(path, margin_m)
    if margin_m <= 0.04:  # the case in question: the note comes before the report it follows
        assert any("plant: QueueWaypointReached" in ln for ln in between), between
        assert ",P0," in between[-1], between[-1]
    out = check_log(path, profile=DEFAULT, role="vehicle")
    bad = {c["id"]: c["reason"] for c in out.clauses if c["verdict"] == "fail"}
    assert not bad, bad
