"""``helmcheck docs``: regenerate (or, with ``--check``, verify) every generated document.

The grammar reference comes from ``remote_helm.lark``, and so do the fast path's tables
(``helmcheck/grammar/derived.py``, :mod:`helmcheck.grammar.derive`); the model's transition
table and state diagram come from ``helmcheck/model/transitions.py``; the documentation site's
reference pages (every profile key, the clause catalogue, the reference profile:
``docs/reference/``, :mod:`helmcheck.reference_docs`) from the ``Profile`` dataclass and the
shipped reference profile; the rules of the profile and the steps that fail each
(``docs/reference/rules.md``) from the traceability table (:mod:`helmcheck.rules`); the
line-fault relay's page (``docs/line-faults.md``) from
:mod:`helmcheck.line.faultdocs`; ``examples/emulator.toml`` is what ``helmcheck profile init
--emulator`` writes; ``docs/readings.md`` is the readings table (:mod:`helmcheck.model.readings`).
The other pages of ``docs/`` are written by hand. Each file is written
atomically; one that cannot be written is exit 2 naming it. ``--check`` exits 1 when a
checked-in copy is stale.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from .. import exitcodes

#: The emulator's profile written out in full, as ``helmcheck profile init --emulator`` writes it.
EMULATOR_EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "emulator.toml"
#: The readings table's page (:mod:`helmcheck.model.readings`).
READINGS_PAGE = Path(__file__).resolve().parents[2] / "docs" / "readings.md"


EPILOG = """\
generated: docs/grammar.md and helmcheck/grammar/derived.py (from remote_helm.lark), and
docs/model/ (from helmcheck/model/transitions.py), in the checkout helmcheck runs from.

examples:
  helmcheck docs --check                            # is every generated file current?
  helmcheck docs                                    # regenerate them

exit status: 0 written (with --check: every file current), 1 with --check: a file is stale (each
  named), 2 a file could not be written.
"""


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = sub.add_parser("docs", help="regenerate the generated documentation",
                       description="Regenerate every generated document, or with --check verify that the "
                                   "checked-in copies are current.",
                       epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--check", action="store_true", help="exit 1 if a checked-in copy is stale")
    p.set_defaults(func=run)
    return p


def emulator_example() -> str:
    """The text of ``examples/emulator.toml``: the built-in emulator's profile, every key."""
    from ..profile_template import render
    from .profile_cmd import _emulator_values

    return render(_emulator_values(), emulator=True)


def targets() -> dict[Path, str]:
    """Every generated file and its text."""
    from .. import reference_docs, rules
    from ..grammar import derive
    from ..grammar import docs as grammar_docs
    from ..line import faultdocs as fault_docs
    from ..model import docs as model_docs
    from ..model import readings

    out = {grammar_docs.DOCS_FILE: grammar_docs.render_markdown(), derive.TABLE_FILE: derive.render_table(),
           fault_docs.DOCS_FILE: fault_docs.render_markdown()}
    out.update({model_docs.DOCS_DIR / name: text for name, text in model_docs.render_all().items()})
    out.update(reference_docs.render_all())
    out[rules.DOCS_FILE] = rules.render_markdown()
    out[EMULATOR_EXAMPLE] = emulator_example()
    out[READINGS_PAGE] = readings.markdown()
    return out


def stale() -> list[str]:
    """The generated files whose checked-in copy differs (paths relative to the checkout)."""
    root = EMULATOR_EXAMPLE.parents[1]
    out = []
    for path, text in targets().items():
        try:
            current = path.read_text(encoding="utf-8")
        except OSError:
            current = None
        if current != text:
            out.append(str(path.relative_to(root)))
    return out


def run(args: argparse.Namespace) -> int:
    from ..failures import OutputLost
    from ..reports.atomic import write_text_atomic

    if args.check:
        names = stale()
        for name in names:
            print(f"stale: {name} (run 'helmcheck docs')")
        return exitcodes.NONCONFORMANT if names else exitcodes.OK
    for path, text in targets().items():
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            write_text_atomic(path, text)
        except OSError as e:
            raise OutputLost(f"cannot write {path}: {e.strerror or e}") from None
        print(f"wrote {path}")
    return exitcodes.OK
