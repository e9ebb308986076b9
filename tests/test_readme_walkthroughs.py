"""The README's walkthroughs run as written, on a fresh clone, and end as the README says.

Every fenced ``sh`` block after a ``<!-- walkthrough: JOURNEY -->`` comment belongs to that
journey. A journey's blocks run in README order in one ``bash`` (so the emulator a block starts
with ``&`` is the ``%1`` a later block stops), from the top of a ``git clone`` of this checkout,
in the environment ``. .venv/bin/activate`` gives: this interpreter's ``bin`` first on ``PATH``
(``helmcheck``, ``python3``, ``pytest``), and the clone's own package first on ``PYTHONPATH``,
so the clone's code and data are what run. A command whose last line ends ``# → TEXT, exit N``
must exit with N and print TEXT: every ``…``-separated fragment of it, the first at the start of
a line or after ``: ``.

Every journey runs twice in the same clone, the second time over what the first left in
``out/``: a block a newcomer runs again must still print what the README says (the commands
pass ``--overwrite`` where an earlier run is in the way). In ``make test`` the journeys of
:data:`AGAIN_IN_MATRIX` run once: the second run of their backseat certifications over an earlier
``out/`` is the ``sign`` journey's too, and each run waits about 40 s on the backseat's poll
intervals; ``make matrix`` (``HELMCHECK_MATRIX=1``) runs them twice.

Blocks marked ``slow`` (the whole vehicle certification, about two minutes at ×20) run only with
``HELMCHECK_WALKTHROUGH=all`` (the ``vehicle-full`` journey); the others run in the suite, each
journey a test of its own (25 to 65 s for both runs, mostly waiting on scaled time).
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
MARKER = re.compile(r"^<!-- walkthrough: ([\w-]+)(, slow)? -->$")
EXPECT = re.compile(r"#\s*→\s*(?P<text>.*?),\s*exit\s+(?P<rc>\d+)\s*$")
SLOW = os.environ.get("HELMCHECK_WALKTHROUGH") == "all"
#: Journeys run once in ``make test``, twice in ``make matrix`` (module docstring).
AGAIN_IN_MATRIX = frozenset({"backseat", "ci"})
TWICE = SLOW or os.environ.get("HELMCHECK_MATRIX") == "1"


@dataclass
class Command:
    lines: list[str]  #: as written, continuation lines included
    text: str = ""  #: what it must print (``…`` between fragments); "" = not checked
    rc: int | None = None


@dataclass
class Block:
    journey: str
    slow: bool
    commands: list[Command] = field(default_factory=list)


def walkthroughs(readme: str) -> list[Block]:
    """Every marked block of the README, in order, split into commands."""
    lines = readme.splitlines()
    blocks, i = [], 0
    while i < len(lines):
        m = MARKER.match(lines[i].strip())
        i += 1
        if not m:
            continue
        assert lines[i] == "```sh", f"README line {i + 1}: a walkthrough marker must precede a ```sh block"
        block = Block(m.group(1), bool(m.group(2)))
        i += 1
        current: list[str] = []
        while lines[i] != "```":
            current.append(lines[i])
            if not lines[i].split(" #", 1)[0].rstrip().endswith("\\"):
                cmd = Command(current)
                e = EXPECT.search(current[-1])
                if e:
                    cmd.text, cmd.rc = e.group("text"), int(e.group("rc"))
                block.commands.append(cmd)
                current = []
            i += 1
        blocks.append(block)
    return blocks


def script(blocks: list[Block], results: Path) -> str:
    """One bash script for a journey: each checked command's output and status go to files."""
    out = []
    n = 0
    for b in blocks:
        for c in b.commands:
            if c.rc is None:
                out += c.lines
                continue
            out += ["{", *c.lines, f"}} > {results}/{n}.out 2>&1", f"echo $? > {results}/{n}.rc"]
            n += 1
    out += ["kill $(jobs -p) 2>/dev/null", "wait"]  # nothing left running, whatever happened
    return "\n".join(out) + "\n"


def shows(output: str, text: str) -> bool:
    """``text``'s ``…``-separated fragments all appear in ``output``, in order, the first at the
    start of a line or after ``: `` (so ``VERIFIED`` does not match ``NOT VERIFIED``)."""
    frags = [f.strip() for f in text.split("…") if f.strip()]
    first = re.compile(r"(^|: )" + re.escape(frags[0]), re.M).search(output)
    if not first:
        return False
    at = first.end()
    for f in frags[1:]:
        at = output.find(f, at)
        if at < 0:
            return False
        at += len(f)
    return True


def _journeys() -> dict[str, list[Block]]:
    out: dict[str, list[Block]] = {}
    for b in walkthroughs(README.read_text(encoding="utf-8")):
        out.setdefault(b.journey, []).append(b)
    return out


def _tampers(blocks: list[Block]) -> bool:
    """A journey that edits a results file on purpose (to show ``verify`` catching it): the
    suite's check that every results directory verifies (tests/conftest.py) leaves it out."""
    return any(c.lines[0].startswith("sed ") for b in blocks for c in b.commands)


JOURNEYS = _journeys()
PARAMS = [pytest.param(name, [b for b in blocks if not b.slow], id=name,
                       marks=[pytest.mark.unverifiable] if _tampers(blocks) else [])
          for name, blocks in JOURNEYS.items()]
PARAMS.append(pytest.param(
    "vehicle-full", JOURNEYS.get("vehicle", []), id="vehicle-full",
    marks=[pytest.mark.skipif(not SLOW, reason="about two minutes: HELMCHECK_WALKTHROUGH=all runs it")]))


@pytest.fixture
def clone(tmp_path) -> Path:
    """A fresh clone of this checkout's committed state."""
    dest = tmp_path / "helmcheck"
    subprocess.run(["git", "clone", "--quiet", str(ROOT), str(dest)], check=True, capture_output=True)
    return dest


def _environment(clone: Path) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PYTEST_", "HYPOTHESIS_"))}
    bindir = str(Path(sys.executable).parent)
    env["PATH"] = bindir + os.pathsep + env.get("PATH", "")
    env["VIRTUAL_ENV"] = sys.prefix
    env["PYTHONPATH"] = str(clone)
    env["PYTHONDONTWRITEBYTECODE"] = "1"
    return env


def run_twice(journey: str, blocks: list[Block], clone: Path, tmp_path: Path, timeout: float,
              again: bool = True) -> list[str]:
    """The journey, then (``again``) the same journey again in the same clone (its ``out/`` as the
    first run left it); what a checked command did otherwise than the README says, run by run."""
    checked = [c for b in blocks for c in b.commands if c.rc is not None]
    assert checked, f"journey {journey}: no command says what it shows (# → TEXT, exit N)"
    wrong = []
    for run in ("first", "again") if again else ("first",):
        results = tmp_path / f"results-{run}"
        results.mkdir()
        log = tmp_path / f"journey-{run}.log"
        with open(log, "wb") as f:
            p = subprocess.Popen(["bash", "-c", script(blocks, results)], cwd=clone, env=_environment(clone),
                                 stdin=subprocess.DEVNULL, stdout=f, stderr=subprocess.STDOUT, start_new_session=True)
            try:
                p.wait(timeout=timeout)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait()
                pytest.fail(f"journey {journey} ({run}) still running after {timeout} s:\n"
                            f"{log.read_text(errors='replace')}")
        for n, c in enumerate(checked):
            shown = " ".join(line.strip() for line in c.lines)
            out = (results / f"{n}.out").read_text(errors="replace")
            rc = int((results / f"{n}.rc").read_text())
            if rc != c.rc or not shows(out, c.text):
                wrong.append(f"README, run {run}: `{shown}`\nsays it shows {c.text!r} and exits {c.rc}; it exited "
                             f"{rc} and printed:\n{out[-3000:]}")
    return wrong


@pytest.mark.parametrize(("journey", "blocks"), PARAMS)
def test_the_readme_walkthrough_runs_as_written(journey, blocks, clone, tmp_path):
    """Twice: a newcomer retrying a step gets what the README says, not a refusal (the journeys of
    :data:`AGAIN_IN_MATRIX` once, outside ``make matrix``)."""
    wrong = run_twice(journey, blocks, clone, tmp_path, 600 if journey == "vehicle-full" else 240,
                      again=TWICE or journey not in AGAIN_IN_MATRIX)
    assert not wrong, "\n\n".join(wrong)


def test_a_block_that_cannot_run_again_is_caught(tmp_path):
    """The second run is judged too: a block that works once only fails it."""
    blocks = walkthroughs("<!-- walkthrough: x -->\n```sh\n"
                          "mkdir -p out && mkdir out/once && echo made: once     # → made: once, exit 0\n```\n")
    (tmp_path / "clone").mkdir()
    wrong = run_twice("x", blocks, tmp_path / "clone", tmp_path, 30)
    assert len(wrong) == 1 and wrong[0].startswith("README, run again: `mkdir"), wrong


def test_every_journey_of_the_readme_is_a_walkthrough():
    """The seven journeys the README walks through are all marked, so all are run."""
    assert set(JOURNEYS) == {"vehicle", "backseat", "check-log", "monitor", "sign", "ci", "diff"}
    assert any(b.slow for b in JOURNEYS["vehicle"])


def test_the_readme_is_a_landing_page():
    assert len(README.read_text(encoding="utf-8").splitlines()) <= 200


def test_the_checker_can_fail():
    """A command that does not print what it says, or exits otherwise, is caught."""
    assert shows("x: PASS — partial: 4 of 60; not a certificate", "PASS — partial: … not a certificate")
    assert not shows("NOT VERIFIED: 3 difference(s)", "VERIFIED")
    assert not shows("FAIL — 1 clause(s) failed: RH-BS-1.", "FAIL — … RH-BS-2")
    blocks = walkthroughs("<!-- walkthrough: x -->\n```sh\nfalse a \\\n  b     # → PASS, exit 0\ntrue\n```\n")
    assert [(c.lines, c.text, c.rc) for c in blocks[0].commands] == [
        (["false a \\", "  b     # → PASS, exit 0"], "PASS", 0), (["true"], "", None)]
