"""check-log's socat readers on real captures (tests/fixtures/logs/socat, recorded with socat
1.7.4.4, see its README.md) and the per-file detection of the timestamp fraction's unit.

These tests assert what the reader yields — times, directions, bytes — never check-log verdicts.
The emulator's own wire log of each captured session (``*.emu.log.gz``) is the independent
witness: the same bytes, in the same order, stamped by another clock.
"""

from __future__ import annotations

import gzip
import json
import statistics
from datetime import datetime
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from helmcheck.checklog import checker as checker_mod
from helmcheck.checklog.checker import check_log
from helmcheck.checklog.readers import (HEAD_BYTES, NOTE, LogMeta, detect_format, read_chunks,
                                                    socat_time_unit, timestamp_resolution)
from helmcheck.grammar import Framer, Line, decode
from helmcheck.profile import DEFAULT

HERE = Path(__file__).parent / "fixtures" / "logs" / "socat"
MANIFEST = json.loads((HERE / "manifest.json").read_text())
CAPTURES = sorted(MANIFEST["captures"])
BACKSEAT = [n for n in CAPTURES if n.startswith("backseat_")]


# --------------------------------------------------------------------------- helpers

def read(path: Path, opener=open):
    """(format, meta, chunks) exactly as check-log reads a file."""
    with opener(path, "rb") as f:
        head = f.read(HEAD_BYTES)
    fmt = detect_format(head)
    meta = LogMeta(format=fmt, resolution=timestamp_resolution(head, fmt))
    with opener(path, "rb") as f:
        chunks = list(read_chunks(f, fmt, meta))
    return fmt, meta, chunks


def read_text(tmp_path: Path, text: str):
    p = tmp_path / "capture.txt"
    p.write_bytes(text.encode("latin-1"))
    return read(p)


def streams(chunks) -> dict:
    out = {">": bytearray(), "<": bytearray()}
    for c in chunks:
        if c.dir in out:
            out[c.dir] += c.data
    return {d: bytes(b) for d, b in out.items()}


def framed(chunks) -> dict:
    """Per direction: (event, time of the chunk that completed it), framed as a receiver would."""
    framers = {">": Framer(DEFAULT.max_line_bytes), "<": Framer(DEFAULT.max_line_bytes)}
    out: dict = {">": [], "<": []}
    for c in chunks:
        if c.dir in framers:
            out[c.dir] += [(e, c.t) for e in framers[c.dir].feed(c.data)]
    for d, fr in framers.items():
        out[d] += [(e, None) for e in fr.close()]
    return out


def emulator_log(name: str):
    return read(HERE / MANIFEST["captures"][name]["emulator_log"], opener=gzip.open)


def stamp(text: str) -> float:
    """A socat header stamp, its nine digits read as microseconds (socat 1.7.4.4, README.md)."""
    whole, frac = text.split(".")
    assert len(frac) == 9 and frac[:3] == "000"
    return datetime.strptime(whole, "%Y/%m/%d %H:%M:%S").timestamp() + int(frac) / 1e6


# --------------------------------------------------------------------------- real captures

@pytest.mark.parametrize("name", CAPTURES)
def test_socat_capture_format_and_fraction_unit_detected_from_data(name):
    m = MANIFEST["captures"][name]
    fmt, meta, chunks = read(HERE / name)
    assert fmt == m["format"]
    assert (meta.time_unit, meta.time_digits) == (m["time_unit"], m["time_digits"]) == ("us", 9)
    assert not meta.time_unit_ambiguous
    assert "begin 000" in meta.time_unit_basis
    assert meta.resolution == 1e-6  # a microsecond clock, not a nanosecond one
    assert {c.dir for c in chunks} == {">", "<"}  # nothing unreadable, no notes


@pytest.mark.parametrize("name", CAPTURES)
def test_socat_capture_span_matches_recorded_duration(name):
    """First to last block spans the driver's wall time (README.md), less its start-up."""
    m = MANIFEST["captures"][name]
    _, _, chunks = read(HERE / name)
    assert chunks[0].t == 0.0
    assert [c.t for c in chunks] == sorted(c.t for c in chunks)
    span = chunks[-1].t
    wall = m["wall_seconds"]
    assert wall - max(0.02 * wall, 1.0) <= span <= wall
    assert span == pytest.approx(stamp(m["last_stamp"]) - stamp(m["first_stamp"]), abs=1e-6)
    if name in BACKSEAT:
        assert span > 180.0  # several minutes, not squeezed


@pytest.mark.parametrize("name", CAPTURES)
def test_socat_capture_blocks_and_bytes_match_socat_counters(name):
    m = MANIFEST["captures"][name]
    _, _, chunks = read(HERE / name)
    blocks = {d: sum(1 for c in chunks if c.dir == d) for d in "<>"}
    assert blocks == m["blocks"]
    got = streams(chunks)
    assert {d: len(b) for d, b in got.items()} == m["bytes"]


@pytest.mark.parametrize("name", BACKSEAT)
def test_socat_capture_bytes_equal_emulator_wire_log(name):
    """Every byte of both directions, in order, as the vehicle side logged it."""
    _, _, chunks = read(HERE / name)
    _, _, emu = emulator_log(name)
    assert streams(chunks) == streams(emu)


def test_socat_certify_capture_bytes_equal_emulator_wire_log():
    """The certify run's noise survives -x exactly; the emulator's log keeps only the first 256
    bytes of an overlong run and says how many it dropped (RH-FRM-6)."""
    name = "certify_x.log"
    _, _, chunks = read(HERE / name)
    _, _, emu = emulator_log(name)
    got, want = streams(chunks), streams(emu)
    assert got["<"] == want["<"]
    dropped = 0
    for c in emu:
        if c.dir == NOTE and "bytes discarded, first" in c.note:
            n, _, rest = c.note.partition(" bytes discarded, first ")
            dropped += int(n.split()[-1]) - int(rest.split()[0])
    assert dropped > 0
    assert len(got[">"]) == len(want[">"]) + dropped
    lines = lambda cs: [e.raw for e, _ in framed(cs)[">"] if type(e) is Line]  # noqa: E731
    assert lines(chunks) == lines(emu)


@pytest.mark.parametrize("name", CAPTURES)
def test_socat_capture_reassembles_into_valid_sentences(name):
    """RH-FRM-6/7 framing of each direction gives only whole lines that decode; in the certify
    capture the backseat side also carries the negative cases, and nothing else is invalid."""
    m = MANIFEST["captures"][name]
    _, _, chunks = read(HERE / name)
    ev = framed(chunks)
    assert all(type(e) is Line and decode(e.raw).valid for e, _ in ev["<"])
    assert len(ev["<"]) == m["emulator_records"]["<"]
    to_vehicle = [e for e, _ in ev[">"]]
    if name in BACKSEAT:
        assert all(type(e) is Line and decode(e.raw).valid for e in to_vehicle)
        assert len(to_vehicle) == m["emulator_records"][">"]
        return
    discards = [e for e in to_vehicle if type(e) is not Line]
    lines = [e for e in to_vehicle if type(e) is Line]
    assert sorted(e.clause for e in discards) == ["RH-FRM-6", "RH-FRM-6", "RH-FRM-7", "RH-FRM-7"]
    assert {e.reason.split(":")[0] for e in discards} == {
        "line longer than 256 bytes", "bytes before '$' (noise)", "sentence torn"}
    errors = {decode(e.raw).error.clause for e in lines if not decode(e.raw).valid}
    assert {"RH-FRM-2", "RH-FRM-4", "RH-FRM-5", "RH-SRV-2"} <= errors  # checksums, IDs, ranges
    bare_lf = [e for e in lines if not e.raw.endswith(b"\r\n")]
    assert len(bare_lf) == 1
    # the emulator logs a line ended by a bare LF as a partial record, like a discarded run
    assert len(discards) + len(bare_lf) == m["emulator_records"][">~"]
    assert len(lines) - len(bare_lf) == m["emulator_records"][">"]


@pytest.mark.parametrize("name", CAPTURES)
def test_socat_capture_times_agree_with_emulator_clock(name):
    """Each line's time agrees with the emulator's own clock to a few milliseconds once the two
    clocks' offset is removed. Read as nanoseconds (the old reading), the sub-second part of
    every stamp would vanish and lines would be off by up to a whole second."""
    _, _, chunks = read(HERE / name)
    _, _, emu = emulator_log(name)
    a, b = framed(chunks), framed(emu)
    for d in "<>":
        la = [(e.raw, t) for e, t in a[d] if type(e) is Line]
        lb = [(e.raw, t) for e, t in b[d] if type(e) is Line]
        assert [r for r, _ in la] == [r for r, _ in lb]
        diffs = [ta - tb for (_, ta), (_, tb) in zip(la, lb)]
        offset = statistics.median(diffs)
        residual = sorted(abs(x - offset) for x in diffs)
        assert residual[int(0.99 * len(residual))] < 0.02, d
        assert residual[-1] < 0.3, d


def test_socat_capture_ack_latency_is_subsecond_not_collapsed():
    """The old nanosecond reading put replies either microseconds or about a second after their
    command; read in microseconds, every $ACK follows the backseat's last line within 0.5 s and
    typically some milliseconds later (19200 baud pacing of the replies before it)."""
    _, _, chunks = read(HERE / "backseat_v.log")
    ev = framed(chunks)
    merged = sorted([(t, ">", e.raw) for e, t in ev[">"]] + [(t, "<", e.raw) for e, t in ev["<"]],
                    key=lambda x: x[0])
    last_cmd = None
    latencies = []
    for t, d, raw in merged:
        if d == ">":
            last_cmd = t
        elif raw.startswith(b"$ACK") and last_cmd is not None:
            latencies.append(t - last_cmd)
    assert len(latencies) > 300
    assert max(latencies) < 0.5
    assert statistics.median(latencies) > 0.002
    assert sum(1 for x in latencies if x < 0.0005) < len(latencies) // 10


def test_socat_capture_check_log_records_unit():
    """check-log carries the detected unit in its LogMeta and its resolution (no verdicts)."""
    out = check_log(HERE / "backseat_x.log")
    assert out.format == "socat-x"
    assert out.meta.time_unit == "us" and out.meta.time_digits == 9
    assert out.resolution == 1e-6
    assert out.stats["unreadable"] == 0
    assert out.stats["bytes_to_vehicle"] == MANIFEST["captures"]["backseat_x.log"]["bytes"][">"]


def test_socat_head_is_the_checkers_head():
    """The reader decides the unit from the same first bytes the checker reads."""
    assert HEAD_BYTES == checker_mod.HEAD_BYTES


# --------------------------------------------------------------------------- synthetic cases

BODY = "$OSD,S*27\\r\n"  # 11 bytes as socat -v writes them


def socat_v(stamps: list[str]) -> str:
    """A socat -v capture with one 11-byte block per stamp, directions alternating."""
    out = []
    for i, s in enumerate(stamps):
        out.append(f"{'><'[i % 2]} 2026/11/22 {s}  length=11 from={11 * (i // 2)} to={11 * (i // 2) + 10}\n")
        out.append(BODY)
    return "".join(out)


@pytest.mark.parametrize("stamps,unit,digits,times", [
    (["12:00:00.278241", "12:00:00.290000", "12:00:01.000500"], "us", 6, [0.0, 0.011759, 0.722259]),
    (["12:00:00.000278241", "12:00:00.000290000", "12:00:01.000000500"], "us", 9,
     [0.0, 0.011759, 0.722259]),
    (["12:00:00.278241000", "12:00:00.290000000", "12:00:01.000500000"], "ns", 9,
     [0.0, 0.011759, 0.722259]),
    (["12:00:00.000278241", "12:00:00.005000000"], "ns", 9, [0.0, 0.004721759]),
    (["12:00:00.278", "12:00:01.5"], "decimal", None, [0.0, 1.222]),
    (["12:00:00.278", "12:00:00.300"], "ms", 3, [0.0, 0.022]),
], ids=["us-6-digits", "us-zero-padded-9", "ns-9", "ns-proved-by-one-stamp", "mixed-widths", "ms-3"])
def test_socat_fraction_unit_detected_from_data(tmp_path, stamps, unit, digits, times):
    _, meta, chunks = read_text(tmp_path, socat_v(stamps))
    assert (meta.time_unit, meta.time_digits) == (unit, digits)
    assert not meta.time_unit_ambiguous
    assert [c.t for c in chunks] == pytest.approx(times, abs=1e-9)
    assert [c.data for c in chunks] == [b"$OSD,S*27\r\n"] * len(stamps)


def test_socat_fraction_unit_ambiguous_head_reads_microseconds(tmp_path):
    """All stamps within one clock second and all beginning 000: both readings fit; read as
    microseconds (1000 times likelier) and say so."""
    _, meta, chunks = read_text(tmp_path, socat_v(["12:00:00.000100123", "12:00:00.000350456"]))
    assert meta.time_unit == "us" and meta.time_unit_ambiguous
    assert "one clock second" in meta.time_unit_basis
    assert chunks[1].t == pytest.approx(0.250333, abs=1e-9)
    assert meta.resolution == 1e-6


def test_socat_fraction_unit_settled_by_two_clock_seconds(tmp_path):
    _, meta, chunks = read_text(tmp_path, socat_v(["12:00:00.000900000", "12:00:01.000100000"]))
    assert meta.time_unit == "us" and not meta.time_unit_ambiguous
    assert chunks[1].t == pytest.approx(0.2)


def test_socat_fraction_unit_switches_when_a_later_stamp_proves_nanoseconds(tmp_path):
    """A head that fits both readings, then past the head a stamp no microsecond count reaches:
    the rest is read as nanoseconds, re-based on the first stamp, with a note on that line."""
    n = HEAD_BYTES // 60 + 10  # more header lines than fit in the head, all in one clock second
    stamps = [f"12:00:00.000{100 + i:06d}" for i in range(n)] + ["12:00:00.500000000", "12:00:01.000000250"]
    _, meta, chunks = read_text(tmp_path, socat_v(stamps))
    notes = [c for c in chunks if c.dir == NOTE]
    assert len(notes) == 1 and "nanoseconds" in notes[0].note
    assert notes[0].lineno == 2 * n + 1
    assert meta.time_unit == "ns" and f"line {2 * n + 1}" in meta.time_unit_basis
    data = [c for c in chunks if c.dir != NOTE]
    assert data[-2].t == pytest.approx(0.5 - 100e-9, abs=1e-12)
    assert data[-1].t == pytest.approx(1.0 + 150e-9, abs=1e-12)
    assert data[1].t == pytest.approx(1e-6, abs=1e-12)  # read before the proof: as microseconds


def test_socat_whole_second_stamps(tmp_path):
    _, meta, chunks = read_text(tmp_path, socat_v(["12:00:00", "12:00:02"]))
    assert meta.time_unit == "none" and meta.resolution == 1.0
    assert [c.t for c in chunks] == [0.0, 2.0]


def test_socat_timestamp_resolution_follows_unit():
    head = socat_v(["12:00:00.000278240", "12:00:01.000500000"]).encode()
    assert timestamp_resolution(head, "socat-v") == pytest.approx(1e-5)
    head = socat_v(["12:00:00.278241001", "12:00:01.000500000"]).encode()
    assert timestamp_resolution(head, "socat-v") == pytest.approx(1e-9)


def test_socat_header_cut_at_head_end_is_no_evidence():
    head = socat_v(["12:00:00.000278241", "12:00:01.000000500"]).encode() + b"> 2026/11/22 12:00:02.0001"
    u = socat_time_unit(head)
    assert (u.name, u.digits, u.ambiguous) == ("us", 9, False)
    assert "2 9-digit" in u.basis


ENCODINGS = ("us-6", "us-9", "ns-9")


@settings(derandomize=True, max_examples=150, deadline=None)
@given(encoding=st.sampled_from(ENCODINGS),
       start_ns=st.one_of(st.integers(0, 999), st.integers(0, 10**9 - 1)),
       gaps_ns=st.lists(st.one_of(st.integers(0, 2000), st.integers(0, 3 * 10**9)), min_size=1, max_size=12))
def test_socat_fraction_unit_detected_from_data_property(tmp_path_factory, encoding, start_ns, gaps_ns):
    """Whatever the clock and encoding, the reader gives the true times (to the clock's step),
    except a nanosecond capture whose every stamp lies in the first millisecond of its second:
    that one is indistinguishable from microseconds and is read as microseconds, flagged
    ambiguous exactly when it lies within one clock second."""
    step = 1000 if encoding.startswith("us") else 1
    abs_ns = [start_ns]
    for g in gaps_ns:
        abs_ns.append(abs_ns[-1] + g)
    abs_ns = [t - t % step for t in abs_ns]  # what the clock can show

    def fmt(t: int) -> str:
        sec, frac = divmod(t, 10**9)
        hms = f"12:{sec // 60:02d}:{sec % 60:02d}"
        if encoding == "us-6":
            return f"{hms}.{frac // 1000:06d}"
        if encoding == "us-9":
            return f"{hms}.{frac // 1000:09d}"
        return f"{hms}.{frac:09d}"

    _, meta, chunks = read_text(tmp_path_factory.mktemp("p"), socat_v([fmt(t) for t in abs_ns]))
    truth = [(t - abs_ns[0]) / 1e9 for t in abs_ns]
    looks_padded = encoding == "ns-9" and all(t % 10**9 < 10**6 for t in abs_ns)
    if looks_padded:
        assert meta.time_unit == "us"
        assert meta.time_unit_ambiguous == (len({t // 10**9 for t in abs_ns}) == 1)
        read_as_us = [((t // 10**9 - abs_ns[0] // 10**9) + (t % 10**9 - abs_ns[0] % 10**9) / 1e6)
                      for t in abs_ns]
        assert [c.t for c in chunks] == pytest.approx(read_as_us, abs=1e-9)
        return
    assert meta.time_unit == ("ns" if encoding == "ns-9" else "us")
    assert [c.t for c in chunks] == pytest.approx(truth, abs=1e-9)


# ============================================================================ the line model

def _judged(name: str, line=None) -> dict:
    out = check_log(HERE / name, role="vehicle", line=line)
    return {c["id"]: c for c in out.clauses}


def test_a_capture_of_a_vehicle_every_answer_late_fails_RH_ACK_2_judged_clean():
    """``late_v.log``: the emulator with every line processed 2.5 s after it came (socat -v between
    ptys): told the link was clean, every late ``$ACK`` is the vehicle's (RH-ACK-2 FAIL); told
    nothing, the same lateness on every answer in a row is the vehicle's too (no line repeats it)."""
    assert _judged("late_v.log", "clean")["RH-ACK-2"]["verdict"] == "fail"
    assert _judged("late_v.log")["RH-ACK-2"]["verdict"] in ("fail", "inconclusive")


def test_a_capture_of_one_broken_line_fails_judged_clean_and_names_line_clean_otherwise(tmp_path):
    """``once_bad_v.log``: one ``$OSI`` with its checksum one bit off, once, on a pty (its vehicle:
    ``once_bad_vehicle.py``). Judged clean: RH-FRM-2 FAIL. Judged as the capture says (nothing: a
    line that can damage bytes): given to the line, and the verdict line says to run with
    ``--line clean`` if the link was a pty or TCP."""
    import subprocess
    import sys
    assert _judged("once_bad_v.log", "clean")["RH-FRM-2"]["verdict"] == "fail"
    assert _judged("once_bad_v.log")["RH-FRM-2"]["verdict"] != "fail"
    run = subprocess.run([sys.executable, "-m", "helmcheck", "check-log", str(HERE / "once_bad_v.log"), "--role",
                          "vehicle", "--report-dir", str(tmp_path / "r")], capture_output=True, text=True, timeout=120)
    first = run.stdout.splitlines()[0]
    assert "run with --line clean" in first and run.returncode == 0, (run.returncode, run.stdout, run.stderr)
    run = subprocess.run([sys.executable, "-m", "helmcheck", "check-log", str(HERE / "once_bad_v.log"), "--role",
                          "vehicle", "--line", "clean", "--report-dir", str(tmp_path / "c")],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 1 and "RH-FRM-2" in run.stdout.splitlines()[0], run.stdout
    import json
    assert json.loads((tmp_path / "c" / "results.json").read_text())["line_model"] == {
        "kind": "clean", "why": "--line clean given"}
