"""The example backseats (``examples/``) are plain Python and pyserial, so a backseat team can run
them without helmcheck: they import nothing but the standard library, pyserial and each other.

Their behaviour is tested where the README shows it (``tests/test_readme_walkthroughs.py``:
``certify backseat --exec 'python3 examples/backseat.py …'`` is PASS, a certificate; the faulty
one FAIL on RH-BS-2; the monitored session; the pytest items).
"""

from __future__ import annotations

import ast
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
SCRIPTS = sorted(EXAMPLES.glob("*.py"))
ALLOWED = set(sys.stdlib_module_names) | {"serial"} | {p.stem for p in SCRIPTS}


def _imports(path: Path) -> set[str]:
    out = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            out |= {a.name.split(".")[0] for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.level == 0:
            out.add(node.module.split(".")[0])
    return out


@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: p.name)
def test_an_example_backseat_needs_only_python_and_pyserial(script):
    extra = _imports(script) - ALLOWED
    assert not extra, f"{script.name} imports {sorted(extra)}"
    assert "serial" in _imports(EXAMPLES / "backseat.py")


def test_the_import_check_can_fail(tmp_path):
    bad = tmp_path / "x.py"
    bad.write_text("import helmcheck.grammar\nfrom rich import print\n")
    assert _imports(bad) - ALLOWED == {"helmcheck", "rich"}


@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: p.name)
def test_an_example_backseat_starts_outside_helmcheck(script, tmp_path):
    """Run from elsewhere, without PYTHONPATH (``-E``) or the user's site (``-s``):
    its ``--help`` works, and a port that is not there is one line and exit 2."""
    run = subprocess.run([sys.executable, "-E", "-s", str(script), "--help"], capture_output=True, text=True,
                         cwd=tmp_path, timeout=60)
    assert run.returncode == 0 and "--port" in run.stdout and "--time-scale" in run.stdout, run.stderr
    gone = subprocess.run([sys.executable, "-E", "-s", str(script), "--port", str(tmp_path / "no-such-tty")],
                          capture_output=True, text=True, cwd=tmp_path, timeout=60)
    assert gone.returncode == 2 and gone.stderr.count("\n") == 1 and "cannot open" in gone.stderr, gone.stderr


@pytest.mark.skipif(shutil.which("python3") is None, reason="no python3 on PATH")
def test_the_system_python_runs_it_when_it_has_pyserial(tmp_path):
    system = shutil.which("python3", path="/usr/bin:/bin")
    if system is None or subprocess.run([system, "-c", "import serial"], capture_output=True).returncode:
        pytest.skip("the system python3 has no pyserial (python3 -m pip install pyserial, or apt python3-serial)")
    run = subprocess.run([system, str(EXAMPLES / "backseat.py"), "--help"], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
