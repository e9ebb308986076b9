"""The package's imports run one way: foundation ← grammar ← model ← judge ← reports ← drivers ← commands.

Each module under ``helmcheck/`` belongs to one layer (:data:`LAYERS`, lowest first) and may
import only its own layer and the layers below it:

* ``foundation`` — the top-level helper modules that import nothing above the standard library
  and each other (:data:`TOP_LEVEL`), and the ``spec`` data package;
* ``grammar`` (``helmcheck/grammar``), ``model`` (``helmcheck/model``), ``judge``
  (``helmcheck/judge``);
* ``reports`` (``helmcheck/reports``) sits beside the judge: it reads what the judge decided and
  may import it, never the other way round, and never a driver or a command;
* the drivers, lowest first: ``line`` (``helmcheck/line``: ports, the recorder, the implementation
  under test as a process), ``emulator`` (``helmcheck/emulator``), ``checklog``
  (``helmcheck/checklog``: the offline checker), ``monitor`` (``helmcheck/monitor``: check-log's
  judges on a live session) and ``certify`` (``helmcheck/certify``: the live
  certifiers, which may run the emulator in-process to plan a run);
* ``commands`` (``helmcheck/commands``, ``helmcheck/cli.py`` and the other entry points).

:func:`upward_imports` parses every module (no import is executed), resolves ``import
helmcheck.x``, ``from helmcheck.x import y`` and relative imports (``from ..x import y``),
including those inside functions (they are dependencies too), and a string constant that is
exactly a module's dotted name (a dispatch table for :func:`importlib.import_module`). Every
import that runs up the layers is one line ``file:line: module (layer) imports target (layer)``.
"""

from __future__ import annotations

import ast
from pathlib import Path
from typing import Callable, Iterator, Optional

import pytest

ROOT = Path(__file__).resolve().parents[1] / "helmcheck"

#: The layers, lowest first: a module may import its own layer and those before it.
LAYERS = ("foundation", "grammar", "model", "judge", "reports", "line", "emulator", "checklog", "monitor",
          "certify", "commands")
RANK = {name: i for i, name in enumerate(LAYERS)}

#: Subpackages of ``helmcheck`` and their layer.
PACKAGES = {
    "spec": "foundation",  # the reference profile as package data; no code
    "grammar": "grammar",
    "model": "model",
    "judge": "judge",
    "reports": "reports",
    "line": "line",
    "emulator": "emulator",
    "checklog": "checklog",
    "monitor": "monitor",
    "certify": "certify",
    "commands": "commands",
}

#: Top-level modules of ``helmcheck`` and their layer, decided by what each one imports.
TOP_LEVEL = {
    "__init__": "foundation",  # __version__ only; imports nothing
    "failures": "foundation",  # the failure classes; standard library only
    "exitcodes": "foundation",  # the exit-code constants; standard library only
    "streams": "foundation",  # GuardedStream; standard library only
    "signals": "foundation",  # ending signals as Interrupted; imports failures
    "profile": "foundation",  # the profile (grammar and model read it); standard library only
    "profile_toml": "foundation",  # the TOML emitter; imports profile
    "profile_template": "foundation",  # the `profile init` template; imports profile, profile_toml
    "spelling": "foundation",  # did you mean …: the closest known words; standard library only
    "clauses": "foundation",  # the clause catalogue; standard library and the spec package data
    "reference_docs": "foundation",  # the site's generated reference pages; imports profile*, clauses
    "rules": "foundation",  # the traceability table (spec/rules.toml) and its page; imports clauses
    "outputs": "reports",  # report directories and output files; imports failures, reports.atomic
    "demo": "certify",  # `python -m helmcheck.demo`; imports the emulator and the vehicle certifier
    "pytest_plugin": "commands",  # the pytest11 entry point; runs the certifiers through their library entries
    "cli": "commands",  # the `helmcheck` entry point; dispatches to helmcheck.commands
    "__main__": "commands",  # `python -m helmcheck`; imports cli
}


def layer_of(module: str) -> Optional[str]:
    """The layer of a dotted module name under ``helmcheck`` (``None``: not mapped)."""
    parts = module.split(".")
    if len(parts) == 1:
        return TOP_LEVEL["__init__"]
    if parts[1] in PACKAGES:
        return PACKAGES[parts[1]]
    return TOP_LEVEL.get(parts[1]) if len(parts) == 2 else None


def _modules(root: Path) -> dict[str, Path]:
    """Dotted name → file for every ``.py`` file under *root* (a package directory)."""
    found = {}
    for path in sorted(root.rglob("*.py")):
        parts = [root.name, *path.relative_to(root).with_suffix("").parts]
        if parts[-1] == "__init__":
            parts.pop()
        found[".".join(parts)] = path
    return found


def _imports(tree: ast.AST, module: str, is_package: bool, known: set[str],
             top: str) -> Iterator[tuple[int, str, str]]:
    """``(line, what the source says, dotted target)`` for every import of a module under *top*."""

    def resolve(name: str) -> str:
        # the longest prefix that is a module (``helmcheck.x.attr`` → ``helmcheck.x``)
        parts = name.split(".")
        while len(parts) > 1 and ".".join(parts) not in known:
            parts.pop()
        return ".".join(parts)

    package = module if is_package else module.rpartition(".")[0]
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split(".")[0] == top:
                    yield node.lineno, f"import {alias.name}", resolve(alias.name)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                if node.level - 1 >= len(base):
                    yield node.lineno, f"from {'.' * node.level}{node.module or ''} import …", "<outside>"
                    continue
                base = base[:len(base) - (node.level - 1)]
                source = ".".join(base + ([node.module] if node.module else []))
            else:
                source = node.module or ""
            if source.split(".")[0] != top:
                continue
            said = f"from {'.' * node.level}{node.module or ''} import "
            for alias in node.names:
                # ``from pkg import sub`` imports the submodule when there is one
                target = resolve(f"{source}.{alias.name}") if alias.name != "*" else resolve(source)
                yield node.lineno, said + alias.name, target
        elif isinstance(node, ast.Constant) and isinstance(node.value, str) and node.value in known:
            yield node.lineno, repr(node.value), node.value


def upward_imports(root: Path, layer: Callable[[str], Optional[str]] = layer_of) -> list[str]:
    """Every import under the package directory *root* that runs up the layers, and every module
    *layer* does not place, as ``file:line: …`` lines (empty: the layering holds)."""
    modules = _modules(root)
    known = set(modules)
    problems = []
    for module, path in modules.items():
        where = path.relative_to(root.parent)
        own = layer(module)
        if own is None:
            problems.append(f"{where}:1: {module} has no layer (add it to TOP_LEVEL or PACKAGES)")
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
        for line, said, target in _imports(tree, module, path.name == "__init__.py", known, root.name):
            if target == "<outside>":
                problems.append(f"{where}:{line}: `{said}` goes above the package")
                continue
            theirs = layer(target)
            if theirs is None:
                problems.append(f"{where}:{line}: `{said}` imports {target}, which has no layer")
            elif RANK[theirs] > RANK[own]:
                problems.append(f"{where}:{line}: {module} ({own}) imports {target} ({theirs}) "
                                f"upward: `{said}`")
    return problems


def test_imports_run_down_the_layers():
    problems = upward_imports(ROOT)
    assert not problems, "imports that run up the layers:\n" + "\n".join(problems)


def test_every_top_level_module_has_a_layer():
    names = {p.stem for p in ROOT.glob("*.py")}
    packages = {p.name for p in ROOT.iterdir() if (p / "__init__.py").is_file()}
    assert names == set(TOP_LEVEL), (sorted(names - set(TOP_LEVEL)), sorted(set(TOP_LEVEL) - names))
    assert packages == set(PACKAGES), (sorted(packages - set(PACKAGES)), sorted(set(PACKAGES) - packages))


def _tree(base: Path, files: dict[str, str]) -> Path:
    for name, text in files.items():
        path = base / "helmcheck" / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    return base / "helmcheck"


_DOWNWARD = {
    "__init__.py": "",
    "profile.py": "import math\n",
    "grammar/__init__.py": "",
    "grammar/codec.py": "from ..profile import math\n",
    "judge/__init__.py": "from . import wire\n",
    "judge/wire.py": "from helmcheck.grammar import codec\nfrom ..grammar.codec import math\n",
    "reports/__init__.py": "",
    "reports/verify.py": "from ..judge.wire import codec\nimport helmcheck.profile\n",
    "line/__init__.py": "",
    "line/transport.py": "from ..grammar import codec\n",
    "emulator/__init__.py": "",
    "emulator/core.py": "from ..line import transport\nfrom ..judge import wire\n",
    "checklog/__init__.py": "",
    "checklog/checker.py": "from ..reports import verify\nfrom ..judge import wire\n",
    "certify/__init__.py": "",
    "certify/vehicle/__init__.py": "",
    "certify/vehicle/runner.py": "from ...emulator import core\nfrom ...line.transport import codec\n",
    "commands/__init__.py": "",
    "commands/verify_cmd.py": ("def run():\n    from ..checklog.checker import check_log\n"
                               "    from ..reports.verify import verify\n"
                               "MODULES = ['helmcheck.checklog.checker']\n"),
    "cli.py": "from .commands import verify_cmd\n",
}


def test_the_check_passes_a_tree_whose_imports_run_down(tmp_path):
    assert upward_imports(_tree(tmp_path, _DOWNWARD)) == []


@pytest.mark.parametrize("name, text, says", [
    ("judge/wire.py", "from ..checklog import checker\n",
     "helmcheck/judge/wire.py:1: helmcheck.judge.wire (judge) imports helmcheck.checklog.checker "
     "(checklog) upward: `from ..checklog import checker`"),
    ("reports/verify.py", "def f():\n    from helmcheck.checklog.checker import check_log\n",
     "helmcheck/reports/verify.py:2: helmcheck.reports.verify (reports) imports "
     "helmcheck.checklog.checker (checklog) upward"),
    ("emulator/core.py", "from ..certify.vehicle import runner\n",
     "helmcheck/emulator/core.py:1: helmcheck.emulator.core (emulator) imports "
     "helmcheck.certify.vehicle.runner (certify) upward"),
    ("line/transport.py", "from ..emulator import core\n",
     "helmcheck/line/transport.py:1: helmcheck.line.transport (line) imports helmcheck.emulator.core (emulator)"),
    ("reports/verify.py", "import helmcheck.commands.verify_cmd\n",
     "helmcheck/reports/verify.py:1: helmcheck.reports.verify (reports) imports helmcheck.commands.verify_cmd"),
    ("checklog/checker.py", "from .. import cli\n",
     "helmcheck/checklog/checker.py:1: helmcheck.checklog.checker (checklog) imports "
     "helmcheck.cli (commands) upward: `from .. import cli`"),
    ("checklog/checker.py", "ROLES = {'x': 'helmcheck.commands.verify_cmd'}\n",
     "helmcheck/checklog/checker.py:1: helmcheck.checklog.checker (checklog) imports "
     "helmcheck.commands.verify_cmd (commands) upward"),
    ("judge/wire.py", "from ..reports.verify import x\n",
     "helmcheck/judge/wire.py:1: helmcheck.judge.wire (judge) imports helmcheck.reports.verify (reports)"),
    ("profile.py", "from .grammar import codec\n",
     "helmcheck/profile.py:1: helmcheck.profile (foundation) imports helmcheck.grammar.codec (grammar)"),
    ("newmodule.py", "", "helmcheck/newmodule.py:1: helmcheck.newmodule has no layer"),
])
def test_the_check_catches_an_upward_import(tmp_path, name, text, says):
    files = dict(_DOWNWARD)
    files[name] = text
    problems = upward_imports(_tree(tmp_path, files))
    assert len(problems) == 1 and problems[0].startswith(says), problems
