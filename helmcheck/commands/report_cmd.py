"""``helmcheck report``: render a results directory (the renderings are :mod:`helmcheck.reports.render`).

This module owns the command's failure mapping, as every command does (the contracts table):
a results directory, ``results.json``, wire log or ``--compare`` directory that cannot be read
or is not a valid results document is an unreadable input, exit 64; a report that cannot be
written is exit 2 naming the file. Each report is written atomically.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ..reports import render


def _formats(value: str) -> list[str]:
    names = [v.strip() for v in value.split(",") if v.strip()]
    bad = [n for n in names if n not in render.OUTPUT_NAMES]
    if bad or not names:
        raise argparse.ArgumentTypeError(
            f"unknown format {', '.join(bad) or repr(value)}; choose from {','.join(render.FORMATS)}")
    return names


EPILOG = """\
examples:
  helmcheck report reports/vehicle                  # report.html, junit.xml and report.md again
  helmcheck report reports/vehicle --format html    # one format
  helmcheck report reports/vehicle --compare reports/previous --fail-on-regression   # against an earlier run

exit status: 0 written; 1 with --fail-on-regression, when a clause regressed or lost coverage;
  2 a report could not be written; 64 usage (bad option, an unreadable or invalid results
  directory).
"""


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = sub.add_parser("report", help="render a results directory as HTML, JUnit XML and Markdown",
                       description="Rebuild the compliance reports of a results directory (nothing is "
                                   "re-run): DIR/report.html, DIR/junit.xml and DIR/report.md, each "
                                   "written atomically.",
                       formatter_class=argparse.RawDescriptionHelpFormatter, epilog=EPILOG)
    p.add_argument("directory", metavar="DIR", type=Path, help="results directory holding results.json and wire.log")
    p.add_argument("--format", dest="formats", type=_formats, default=list(render.FORMATS),
                   metavar="LIST", help="comma-separated formats to write: html,junit,md (default: all)")
    p.add_argument("--compare", dest="compare_dir", type=Path, metavar="OLD_DIR",
                   help="an earlier results directory to compare with")
    p.add_argument("--fail-on-regression", action="store_true",
                   help="with --compare: exit 1 when a clause regressed or lost coverage (judged before, "
                        "not judged now)")
    p.set_defaults(func=run)
    return p


def run(args: argparse.Namespace) -> int:
    import sys

    from ..failures import OutputLost, PathError, UsageError
    from ..reports.compare import compare_runs, compare_text, worsened
    from ..reports.results import ReportError
    from ..reports.rundir import load_run
    from ..reports.scope import headline

    if getattr(args, "fail_on_regression", False) and args.compare_dir is None:
        raise UsageError("--fail-on-regression needs --compare OLD_DIR")
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
    print(f"{headline(r)}. {r['verdict_reason']}")  # the headline says when the run was cut short
    print(f"digest {run_.digest.combined}")
    for path in paths:
        print(f"wrote {path}")
    if cmp:
        print(compare_text(cmp), end="", file=sys.stdout)
        if getattr(args, "fail_on_regression", False) and worsened(cmp):
            print(f"helmcheck report: {len(cmp['regressed'])} clause(s) regressed and {len(cmp['lost'])} lost "
                  f"coverage since {args.compare_dir}", file=sys.stderr)
            return 1
    return 0
