"""The certificate digest changes with any byte of results.json or the wire log, and every
rendering prints it."""

from __future__ import annotations

import hashlib
import json
import shutil
from pathlib import Path

import pytest

from helmcheck.reports.digest import digest_bytes, digest_dir
from helmcheck.reports.render import render_all

FIXTURES = Path(__file__).parent / "fixtures" / "reports"


@pytest.fixture
def run_dir(tmp_path: Path) -> Path:
    d = tmp_path / "run"
    shutil.copytree(FIXTURES / "fail_run", d)
    return d


def _flip(path: Path, index: int) -> None:
    data = bytearray(path.read_bytes())
    data[index] ^= 0x01
    path.write_bytes(bytes(data))


def test_digest_is_sha256_of_each_file(run_dir):
    d = digest_dir(run_dir)
    assert d.results == hashlib.sha256((run_dir / "results.json").read_bytes()).hexdigest()
    assert d.wire == hashlib.sha256((run_dir / "wire.log").read_bytes()).hexdigest()
    assert len(d.combined) == 64 and d.combined not in (d.results, d.wire)


@pytest.mark.parametrize("where", [0, 0.5, -1])
def test_one_byte_of_results_changes_results_and_combined(run_dir, where):
    before = digest_dir(run_dir)
    size = (run_dir / "results.json").stat().st_size
    _flip(run_dir / "results.json", int(size * where) if where != -1 else size - 1)
    after = digest_dir(run_dir)
    assert after.results != before.results and after.combined != before.combined
    assert after.wire == before.wire


@pytest.mark.parametrize("where", [0, 0.5, -1])
def test_one_byte_of_wire_log_changes_wire_and_combined(run_dir, where):
    before = digest_dir(run_dir)
    size = (run_dir / "wire.log").stat().st_size
    _flip(run_dir / "wire.log", int(size * where) if where != -1 else size - 1)
    after = digest_dir(run_dir)
    assert after.wire != before.wire and after.combined != before.combined
    assert after.results == before.results


def test_absent_wire_log_differs_from_an_empty_one():
    absent = digest_bytes(b"{}", None)
    empty = digest_bytes(b"{}", b"")
    assert absent.wire is None and empty.wire is not None
    assert absent.combined != empty.combined


def test_every_rendering_prints_the_digest_and_an_edit_shows(run_dir):
    render_all(run_dir)
    d = digest_dir(run_dir)
    outputs = {name: (run_dir / name).read_text(encoding="utf-8") for name in ("report.html", "junit.xml", "report.md")}
    for name, text in outputs.items():
        assert d.combined in text, name
        assert d.results in text and d.wire in text, name

    # Edit the results (still valid): the old report no longer matches the directory...
    doc = json.loads((run_dir / "results.json").read_text(encoding="utf-8"))
    doc["clauses"][0]["reason"] += " (edited)"
    (run_dir / "results.json").write_text(json.dumps(doc, indent=2), encoding="utf-8")
    edited = digest_dir(run_dir)
    assert edited.combined not in outputs["report.html"]
    # ... and a rebuilt report carries the new digest.
    render_all(run_dir, formats=("html",))
    assert edited.combined in (run_dir / "report.html").read_text(encoding="utf-8")


def test_rendering_leaves_the_digested_files_untouched(run_dir):
    before = digest_dir(run_dir)
    render_all(run_dir)
    assert digest_dir(run_dir) == before
