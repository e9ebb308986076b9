"""The example workflow's install step works as written: helmcheck from its repository, into a
fresh virtual environment (``examples/ci/backseat-conformance.yml``; helmcheck is not on the
package index).

The step ``python -m pip install "$HELMCHECK"`` runs as written, in ``bash``, with the
workflow's own ``HELMCHECK`` (``helmcheck @ git+URL@REF``) pointed at this checkout's repository
and commit (``git+file://localhost/…@<sha>``): the requirement's form, pip's git checkout and the build
are all real. The installed ``helmcheck`` must then start. It downloads nothing new where pip's
cache holds the dependencies, but takes about a minute (a new environment, an isolated build):
``HELMCHECK_INSTALL_TEST=1`` runs it.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
WORKFLOW = ROOT / "examples" / "ci" / "backseat-conformance.yml"
GIT_REQ = re.compile(r'^\s*HELMCHECK:\s*"(helmcheck @ git\+)(\S+)@(\S+)"', re.M)


def _install_step() -> str:
    text = WORKFLOW.read_text(encoding="utf-8")
    steps = re.findall(r"run: (python -m pip install \"\$HELMCHECK\")\s*$", text, re.M)
    assert steps, "the workflow has no install step"
    return steps[0]


def test_the_workflow_installs_from_the_repository_not_the_package_index():
    text = WORKFLOW.read_text(encoding="utf-8")
    m = GIT_REQ.search(text)
    assert m, "HELMCHECK must name helmcheck's repository (helmcheck @ git+URL@REF)"
    assert _install_step() == 'python -m pip install "$HELMCHECK"'


@pytest.mark.skipif(os.environ.get("HELMCHECK_INSTALL_TEST") != "1",
                    reason="about a minute (a new environment): HELMCHECK_INSTALL_TEST=1 runs it")
def test_the_install_step_as_written_installs_a_working_helmcheck(tmp_path):
    sha = subprocess.run(["git", "rev-parse", "HEAD"], cwd=ROOT, check=True, capture_output=True,
                         text=True).stdout.strip()
    m = GIT_REQ.search(WORKFLOW.read_text(encoding="utf-8"))
    requirement = f"{m.group(1)}file://localhost{ROOT}@{sha}"  # a host: older pips refuse git+file:///
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PYTEST_", "PYTHON"))}
    env.update(PATH=f"{venv / 'bin'}{os.pathsep}{env.get('PATH', '')}", VIRTUAL_ENV=str(venv),
               HELMCHECK=requirement, PIP_DISABLE_PIP_VERSION_CHECK="1")
    step = subprocess.run(["bash", "-c", _install_step()], cwd=tmp_path, env=env, capture_output=True,
                          text=True, timeout=600)
    assert step.returncode == 0, step.stdout[-2000:] + step.stderr[-2000:]
    run = subprocess.run([str(venv / "bin" / "helmcheck"), "--version"], env=env, capture_output=True, text=True)
    assert run.returncode == 0 and run.stdout.startswith("helmcheck "), (run.stdout, run.stderr)
    where = subprocess.run([str(venv / "bin" / "python"), "-c", "import helmcheck; print(helmcheck.__file__)"],
                           env=env, capture_output=True, text=True, cwd=tmp_path)
    assert where.stdout.startswith(str(venv)), where  # installed into the new environment, not this checkout
