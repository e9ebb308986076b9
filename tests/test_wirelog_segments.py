"""A session's wire log in segments (``wire.log``, ``wire.001.log``, …) is one session.

The writer goes on in a new segment with :meth:`~helmcheck.grammar.wirelog.WireLogWriter.continue_in`
after a ``continued in`` note; check-log, reading the first segment, follows the notes
(:mod:`helmcheck.reports.segments`) and gets exactly the clause verdicts, line numbers and
evidence of the same records written as one file. A segment that a note names but that is
missing leaves the bytes after it unknown: RH-FRM-1 and RH-BS-1 INCONCLUSIVE, never PASS.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from helmcheck.checklog.checker import check_log
from helmcheck.checklog.report import write_report_dir
from helmcheck.grammar.wirelog import CONTINUED, WireLogWriter, read_records, segment_name
from helmcheck.profile import DEFAULT
from helmcheck.reports.segments import session_files

FIXTURES = Path(__file__).parent / "fixtures" / "logs"


def _records(name: str) -> list:
    with open(FIXTURES / name, "rb") as f:
        return list(read_records(f))


def _write(directory: Path, records: list, every: int) -> Path:
    """The records as a session of segments of ``every`` records each (``every`` 0: one file)."""
    first = directory / "wire.log"
    out = open(first, "w", encoding="utf-8")
    w = WireLogWriter(out, ["hand-split  baud 115200  time_scale 20"])
    n = 0
    for i, r in enumerate(records):
        if every and i and i % every == 0:
            n += 1
            name = segment_name("wire.log", n)
            w.note(r.t, CONTINUED + name)
            out.close()
            out = open(directory / name, "w", encoding="utf-8")
            w.continue_in(out, segment_name("wire.log", n - 1))
        if r.dir == "!":
            w.note(r.t, r.note)
        else:
            w.bytes(r.t, r.dir, r.data)
    out.close()
    return first


def _verdicts(path: Path) -> list:
    out = check_log(path, profile=DEFAULT, role="both")
    return [(c["id"], c["verdict"], c["reason"], [e["line"] for e in c["evidence"]]) for c in out.clauses]


@pytest.mark.parametrize("name", ["emulator_session.log", "vehicle_faults.log", "backseat_faults.log"])
def test_a_session_in_segments_is_judged_as_the_same_session_in_one_file(tmp_path, name):
    records = _records(name)
    one, split = tmp_path / "one", tmp_path / "split"
    one.mkdir(), split.mkdir()
    whole = _verdicts(_write(one, records, 0))
    first = _write(split, records, 7)
    assert len(session_files(first).files) > 1
    got = _verdicts(first)
    # the same verdicts and reasons; evidence line numbers differ only by the continuation lines
    assert [(c, v) for c, v, _, _ in got] == [(c, v) for c, v, _, _ in whole]


def test_a_missing_segment_leaves_the_rest_unknown(tmp_path):
    first = _write(tmp_path, _records("emulator_session.log"), 7)
    (tmp_path / "wire.002.log").unlink()
    session = session_files(first)
    assert [p.name for p in session.files] == ["wire.log", "wire.001.log"] and session.missing == "wire.002.log"
    v = {c["id"]: c for c in check_log(first, profile=DEFAULT, role="both").clauses}
    for cid in ("RH-FRM-1", "RH-BS-1"):
        assert v[cid]["verdict"] == "inconclusive" and "wire.002.log" in str(v[cid]["evidence"]), v[cid]


def test_check_log_copies_every_segment_and_records_them(tmp_path):
    src = tmp_path / "src"
    src.mkdir()
    first = _write(src, _records("emulator_session.log"), 7)
    out = check_log(first, profile=DEFAULT, role="both")
    res = write_report_dir(tmp_path / "r", out, DEFAULT, "check-log", render=False)
    names = res["wire_segments"]
    assert names == [p.name for p in session_files(first).files[1:]]
    for n in ["wire.log", *names]:
        assert (tmp_path / "r" / n).read_bytes() == (src / n).read_bytes()
    again = check_log(tmp_path / "r" / "wire.log", profile=DEFAULT, role="both")
    assert [c["verdict"] for c in again.clauses] == [c["verdict"] for c in out.clauses]
    assert json.loads((tmp_path / "r" / "results.json").read_text())["wire_segments"] == names
