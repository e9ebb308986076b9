"""``helmcheck report``: outputs, exit codes, error lines (the one command line that renders a
results directory; ``helmcheck.reports`` has no entry point of its own)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from helmcheck.cli import main as cli_main
from helmcheck.reports.render import render_all

ROOT = Path(__file__).resolve().parents[1]
FIXTURES = Path(__file__).parent / "fixtures" / "reports"


def main(argv: list[str]) -> int:
    return cli_main(["report", *argv])


@pytest.fixture
def run_dir(tmp_path: Path) -> Path:
    d = tmp_path / "run"
    shutil.copytree(FIXTURES / "fail_run", d)
    return d


def test_writes_all_three_reports_and_nothing_else(run_dir, capsys):
    assert main([str(run_dir)]) == 0
    assert sorted(os.listdir(run_dir)) == ["junit.xml", "report.html", "report.md", "results.json", "wire.log"]
    out = capsys.readouterr().out
    assert out.startswith("FAIL — partial: 57 of 60 claimed clauses judged; not a certificate. ") and "digest " in out and str(run_dir / "report.html") in out


def test_format_selects_outputs(run_dir):
    assert main([str(run_dir), "--format", "md,junit"]) == 0
    assert sorted(p.name for p in run_dir.iterdir() if p.name.startswith(("report", "junit"))) == \
        ["junit.xml", "report.md"]


def test_render_all_returns_paths_and_rejects_unknown_formats(run_dir):
    assert render_all(run_dir, formats=("md",)) == [run_dir / "report.md"]
    with pytest.raises(ValueError, match="pdf"):
        render_all(run_dir, formats=("pdf",))


@pytest.mark.parametrize("argv", [[], ["--format", "pdf", "X"], ["X", "--bogus"], ["X", "--format", ""]])
def test_usage_errors_exit_64(argv, capsys):
    assert main(argv) == 64
    err = capsys.readouterr().err
    assert err.startswith("helmcheck report: error: ") and err.count("\n") == 1


def test_help_exits_0(capsys):
    assert main(["--help"]) == 0
    assert "--compare" in capsys.readouterr().out


def test_unreadable_results_exit_64_with_one_line_naming_the_file(tmp_path, capsys):
    (tmp_path / "results.json").write_text("{garbage", encoding="utf-8")
    assert main([str(tmp_path)]) == 64
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(tmp_path / "results.json") in err and "not valid JSON" in err
    assert not (tmp_path / "report.html").exists()


def test_missing_directory_and_missing_compare_dir_exit_64(run_dir, tmp_path, capsys):
    assert main([str(tmp_path / "nowhere")]) == 64
    assert "nowhere" in capsys.readouterr().err
    assert main([str(run_dir), "--compare", str(tmp_path / "old")]) == 64
    assert str(tmp_path / "old") in capsys.readouterr().err


def test_compare_prints_a_summary(run_dir, tmp_path, capsys):
    old = tmp_path / "old"
    shutil.copytree(FIXTURES / "pass_run", old)
    assert main([str(run_dir), "--compare", str(old)]) == 0
    out = capsys.readouterr().out
    assert "overall: PASS -> FAIL" in out and "regressed: RH-SRV-4 PASS -> FAIL" in out


def test_unwritable_directory_exits_2(run_dir, capsys):
    if os.geteuid() == 0:
        (run_dir / "report.html").mkdir()  # root ignores permissions; a directory cannot be replaced by a file
        assert main([str(run_dir), "--format", "html"]) == 2
        assert "report.html" in capsys.readouterr().err
    else:
        run_dir.chmod(0o555)
        try:
            assert main([str(run_dir)]) == 2
        finally:
            run_dir.chmod(0o755)
    assert not [p for p in os.listdir(run_dir) if p.endswith(".tmp")]


def test_the_reports_package_has_no_command_line_of_its_own():
    """``helmcheck report`` is the one way (the command line lives in ``helmcheck.commands``)."""
    import importlib.util

    assert importlib.util.find_spec("helmcheck.reports.__main__") is None
    proc = subprocess.run([sys.executable, "-m", "helmcheck", "report"], capture_output=True, text=True,
                          env=dict(os.environ, PYTHONPATH=str(ROOT)), timeout=60)
    assert proc.returncode == 64 and proc.stderr.startswith("helmcheck report: error: ")
