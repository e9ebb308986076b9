"""The "From Python" example (``docs/guide/python.md``) names entries that exist, with the options it uses.

The example is not run (it would need a vehicle on /dev/ttyUSB0 and a backseat binary); its
imports are executed and each ``Options(...)`` call in it is built for real, so a renamed entry
or option breaks this test, not a user's harness.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

PAGE = Path(__file__).resolve().parents[1] / "docs" / "guide" / "python.md"


def _example() -> str:
    text = PAGE.read_text(encoding="utf-8")
    return re.search(r"```python\n(.*?)```", text, re.S).group(1)


def test_the_example_imports_and_builds_its_options(tmp_path):
    tree = ast.parse(_example())
    ns: dict = {}
    imports = [n for n in tree.body if isinstance(n, (ast.Import, ast.ImportFrom))]
    exec(compile(ast.Module(body=imports, type_ignores=[]), "python.md", "exec"), ns)
    from helmcheck.profile import DEFAULT

    built = 0
    for node in ast.walk(tree):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id.endswith("Options"):
            kwargs = {k.arg: ast.literal_eval(k.value) if not isinstance(k.value, ast.Call) else tmp_path
                      for k in node.keywords if k.arg != "profile"}
            opts = ns[node.func.id](profile=DEFAULT, **kwargs)
            assert opts.profile is DEFAULT
            built += 1
    assert built == 2
    for name in ("certify_vehicle", "certify_backseat", "check_log"):
        assert callable(ns[name])
