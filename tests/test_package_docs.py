"""Every package's docstring says what it holds, and is kept true.

The docstring at the top of each package (``__init__.py``) lists its modules: every module it
names with ``:mod:`` exists, and every module of the package is named there — a module added,
renamed or removed without its package's docstring following fails here. Subpackages count as
modules of their parent.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1] / "helmcheck"
PACKAGES = sorted(p.parent for p in ROOT.rglob("__init__.py") if "__pycache__" not in p.parts)
MOD_REF = re.compile(r":mod:`~?([\w.]+)`")


def _dotted(path: Path) -> str:
    rel = path.relative_to(ROOT.parent).with_suffix("")
    parts = list(rel.parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _exists(dotted: str) -> bool:
    path = ROOT.parent.joinpath(*dotted.split("."))
    return path.with_suffix(".py").is_file() or (path / "__init__.py").is_file()


def _members(pkg: Path) -> set[str]:
    mods = {p.stem for p in pkg.glob("*.py") if p.stem not in ("__init__", "__main__")}
    subs = {p.name for p in pkg.iterdir() if (p / "__init__.py").is_file()}
    return mods | subs


def _named(pkg: Path) -> set[str]:
    doc = ast.get_docstring(ast.parse((pkg / "__init__.py").read_text(encoding="utf-8"))) or ""
    here = _dotted(pkg / "__init__.py")
    out = set()
    for ref in MOD_REF.findall(doc):
        full = here + ref if ref.startswith(".") else ref
        out.add(full)
    return out


#: packages whose docstring describes them without listing modules (few, small, obvious)
UNLISTED = {"helmcheck", "helmcheck.spec"}


@pytest.mark.parametrize("pkg", PACKAGES, ids=lambda p: _dotted(p / "__init__.py"))
def test_the_package_docstring_names_modules_that_exist(pkg):
    missing = sorted(m for m in _named(pkg) if m.startswith("helmcheck") and not _exists(m))
    assert not missing, f"{pkg}/__init__.py names modules that do not exist: {missing}"


@pytest.mark.parametrize("pkg", [p for p in PACKAGES if _dotted(p / "__init__.py") not in UNLISTED],
                         ids=lambda p: _dotted(p / "__init__.py"))
def test_every_module_is_named_in_its_package_docstring(pkg):
    here = _dotted(pkg / "__init__.py")
    named = {m for m in _named(pkg)}
    left_out = sorted(m for m in _members(pkg) if f"{here}.{m}" not in named)
    assert not left_out, f"{here}: modules its docstring does not name: {left_out}"
