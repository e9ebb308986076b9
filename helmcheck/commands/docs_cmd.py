"""``helmcheck docs``: regenerate (or, with ``--check``, verify) every generated document.

The grammar reference comes from ``remote_helm.lark``, and so do the fast path's tables
(``helmcheck/grammar/derived.py``, :mod:`helmcheck.grammar.derive`); the model's transition
table and state diagram come from ``helmcheck/model/transitions.py``. Nothing in ``docs/`` is
written by hand except ``contracts.md``. Each file is written atomically; one that cannot be written is exit 2
naming it. ``--check`` exits 1 when a checked-in copy is stale.
"""

from __future__ import annotations

import argparse

from .. import exitcodes


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


def run(args: argparse.Namespace) -> int:
    from ..failures import OutputLost
    from ..grammar import derive
    from ..grammar import docs as grammar_docs
    from ..model import docs as model_docs
    from ..reports.atomic import write_text_atomic

    if args.check:
        stale = ((["docs/grammar.md"] if grammar_docs.stale() else [])
                 + (["helmcheck/grammar/derived.py"] if derive.stale() else []) + list(model_docs.stale()))
        for name in stale:
            print(f"stale: {name} (run 'helmcheck docs')")
        return exitcodes.NONCONFORMANT if stale else exitcodes.OK
    targets = {grammar_docs.DOCS_FILE: grammar_docs.render_markdown(), derive.TABLE_FILE: derive.render_table()}
    targets.update({model_docs.DOCS_DIR / name: text for name, text in model_docs.render_all().items()})
    for path, text in targets.items():
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            write_text_atomic(path, text)
        except OSError as e:
            raise OutputLost(f"cannot write {path}: {e.strerror or e}") from None
        print(f"wrote {path}")
    return exitcodes.OK
