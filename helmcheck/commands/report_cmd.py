"""``helmcheck report``: render a results directory (the renderings are :mod:`helmcheck.reports.render`).

This module owns the command's failure mapping, as every command does (the contracts table):
a results directory, ``results.json``, wire log or ``--compare`` directory that cannot be read
or is not a valid results document is an unreadable input, exit 64; a report that cannot be
written is exit 2 naming the file. Each report is written atomically.
"""

from __future__ import annotations

import argparse

from ..reports import render


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = sub.add_parser("report", help="render results.json to HTML, JUnit XML and Markdown",
                       description=render.__doc__.strip().splitlines()[0] if render.__doc__ else None,
                       formatter_class=argparse.RawDescriptionHelpFormatter,
                       epilog="exit status: 0 written; 2 a report could not be written; 64 usage "
                              "(bad option, an unreadable or invalid results directory).")
    render.add_arguments(p)
    p.set_defaults(func=run)
    return p


def run(args: argparse.Namespace) -> int:
    import sys

    from ..failures import OutputLost, PathError
    from ..reports.compare import compare_runs, compare_text
    from ..reports.results import ReportError
    from ..reports.rundir import load_run
    from ..reports.view import VERDICT_LABEL

    try:
        run_ = load_run(args.directory)
        cmp = compare_runs(load_run(args.compare_dir), run_) if args.compare_dir is not None else None
    except ReportError as exc:
        raise PathError(f"cannot read {exc}") from None
    try:
        paths = render.render_run(run_, args.formats, cmp)
    except ReportError as exc:
        raise OutputLost(str(exc)) from None
    r = run_.results
    partial = " (PARTIAL)" if r["partial"] else ""
    print(f"{VERDICT_LABEL[r['verdict']]}{partial}: {r['verdict_reason']}")
    print(f"digest {run_.digest.combined}")
    for path in paths:
        print(f"wrote {path}")
    if cmp:
        print(compare_text(cmp), end="", file=sys.stdout)
    return 0
