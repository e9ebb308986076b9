"""The CI recipe (``docs/guide/ci.md``, and the README's *Run it in CI*) and the example workflow
(``examples/ci/backseat-conformance.yml``) use only options helmcheck and its pytest plugin have.

Every ``helmcheck …`` and ``pytest …`` command line in them is parsed with the real parsers, so
a renamed or removed option breaks this test rather than a team's pipeline.
"""

from __future__ import annotations

import argparse
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from helmcheck.commands import certify_backseat_cmd as backseat_cli
from helmcheck.commands import certify_vehicle_cmd as vehicle_cli
from helmcheck.commands import matrix_cmd
from helmcheck.line.launcher import build_argv

ROOT = Path(__file__).resolve().parent.parent
WORKFLOW = ROOT / "examples" / "ci" / "backseat-conformance.yml"


def _workflow_commands() -> list[str]:
    """The shell lines of every ``run:`` step (folded ``>`` blocks joined)."""
    lines = WORKFLOW.read_text().splitlines()
    out, i = [], 0
    while i < len(lines):
        m = re.match(r"^(\s*)(?:- )?run: (.*)$", lines[i])
        i += 1
        if not m:
            continue
        if m.group(2).strip() in (">", "|"):
            indent, block = None, []
            while i < len(lines) and (not lines[i].strip() or indent is None or lines[i].startswith(indent)):
                if indent is None:
                    indent = re.match(r"^\s*", lines[i]).group(0)
                    if len(indent) <= len(m.group(1)):
                        break
                block.append(lines[i].strip())
                i += 1
            out.append(" ".join(block))
        else:
            out.append(m.group(2).split(" #", 1)[0].strip())
    return [re.sub(r"\$\{\{ matrix\.build \}\}", "release", c) for c in out]


def _readme_commands() -> list[str]:
    guide = (ROOT / "docs" / "guide" / "ci.md").read_text()
    readme = (ROOT / "README.md").read_text().split("### Run it in CI", 1)[1].split("\n### ", 1)[0]
    blocks = re.findall(r"```sh\n(.*?)```", guide + readme, re.S)
    return [line.strip() for b in blocks for line in b.replace("\\\n", " ").splitlines() if line.strip()]


def _parser(add) -> argparse.ArgumentParser:
    class P(argparse.ArgumentParser):
        def error(self, message):  # noqa: D401
            raise AssertionError(message)

    p = P()
    add(p)
    return p


def _matrix_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser()
    sub = p.add_subparsers()
    matrix_cmd.add_parser(sub)
    return p


def _check_helmcheck(line: str) -> str:
    argv = shlex.split(line)
    assert argv[0] == "helmcheck"
    if argv[1:3] == ["certify", "backseat"]:
        args = _parser(backseat_cli.add_arguments).parse_args(argv[3:])
    elif argv[1:3] == ["certify", "vehicle"]:
        args = _parser(vehicle_cli.add_arguments).parse_args(argv[3:])
    elif argv[1] == "matrix":
        _matrix_parser().parse_args(argv[1:])
        return "matrix"
    else:
        raise AssertionError(f"unexpected command {line}")
    if args.exec_cmd:
        started = build_argv(args.exec_cmd, {"port": "/dev/pts/9", "time_scale": "10"})
        assert "/dev/pts/9" in started and "{" not in " ".join(started)
    return " ".join(argv[1:3])


def _helm_options() -> set[str]:
    out = subprocess.run([sys.executable, "-m", "pytest", "--help"], capture_output=True, text=True).stdout
    return set(re.findall(r"(--helm-[a-z-]+)", out))


def test_every_command_of_the_workflow_parses():
    commands = _workflow_commands()
    helm = [c for c in commands if c.startswith("helmcheck ")]
    assert sorted({_check_helmcheck(c) for c in helm}) == ["certify backseat", "certify vehicle", "matrix"]
    known = _helm_options()
    pytest_lines = [c for c in commands if c.startswith("pytest ")]
    assert pytest_lines
    for line in pytest_lines:
        used = {a.split("=", 1)[0] for a in shlex.split(line) if a.startswith("--helm-")}
        assert used and used <= known, used - known


def test_every_command_of_the_readme_recipe_parses():
    commands = _readme_commands()
    kinds = {_check_helmcheck(c) for c in commands if c.startswith("helmcheck ")}
    assert "certify backseat" in kinds
    known = _helm_options()
    for line in (c for c in commands if c.startswith("pytest ")):
        used = {a.split("=", 1)[0] for a in shlex.split(line) if a.startswith("--helm-")}
        assert used <= known, used - known


@pytest.mark.parametrize("line", ["helmcheck certify backseat --no-such-flag", "helmcheck frobnicate"])
def test_the_checker_itself_can_fail(line):
    with pytest.raises(AssertionError):
        _check_helmcheck(line)
