"""``helmcheck matrix DIR… [--out OUT]``: one overview of several runs, clauses × implementations.

Reads ``results.json`` of every results directory given (validated; nothing is re-run), and
writes ``OUT/matrix.html`` (self-contained) and ``OUT/matrix.md``, each atomically
(:mod:`helmcheck.reports.atomic`); the rendering is :mod:`helmcheck.reports.matrix`. Columns
come in the order the directories are given; each cell links to ``DIR/report.html`` relative to
``OUT``. Exit status: 0 written; 2 a results directory could not be read or a file not written
(one line on standard error naming it); 64 a usage error.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from .. import exitcodes
from ..failures import UsageError

EPILOG = """\
Each column is one run, labelled by its identity (the profile's implementation name and version,
else the vehicle name, else the program --exec started), plus its start date. Each cell is that
clause's verdict, linking to the clause in the run's report.html. — marks a clause the run has
no entry for (a backseat run has no vehicle clauses).

examples:
  helmcheck matrix reports/vehicle reports/previous --out matrix/
  helmcheck matrix reports/*/ --title 'vehicles, nightly' --out matrix/   # every run under reports/

exit status: 0 written, 2 a results directory could not be read or a file not written (one line
  naming it), 64 usage.
"""


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = sub.add_parser("matrix", help="one overview of several runs: clauses x implementations",
                       description="Render the verdicts of several results directories side by side, "
                                   "clause by clause (HTML and Markdown); nothing is re-run.",
                       epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("directories", nargs="+", metavar="DIR", type=Path,
                   help="results directories (each with results.json), one column each, in this order")
    p.add_argument("--out", default=Path("."), type=Path, metavar="OUT",
                   help="directory for matrix.html and matrix.md (default: the current directory)")
    p.add_argument("--title", default="helmcheck conformance matrix", help="heading of both files")
    p.set_defaults(func=run)
    return p


def run(args: argparse.Namespace) -> int:
    from ..reports.atomic import write_text_atomic
    from ..reports.matrix import MatrixRun, render_matrix_html, render_matrix_markdown
    from ..reports.results import ReportError, load_results

    out_dir: Path = args.out
    if out_dir.exists() and not out_dir.is_dir():
        raise UsageError(f"--out {out_dir}: not a directory")
    runs = []
    for d in args.directories:
        try:
            results = load_results(d)
        except ReportError as e:
            print(f"helmcheck matrix: error: {e}", file=sys.stderr)
            return exitcodes.INCONCLUSIVE
        report = d / "report.html"
        if not report.is_file():
            print(f"helmcheck matrix: warning: {report} does not exist (helmcheck report {d} writes it)",
                  file=sys.stderr)
        href = Path(os.path.relpath(report.resolve(), out_dir.resolve())).as_posix()
        runs.append(MatrixRun(results, href=href, source=str(d)))
    written = []
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
        for name, text in (("matrix.html", render_matrix_html(runs, title=args.title)),
                           ("matrix.md", render_matrix_markdown(runs, title=args.title))):
            written.append(write_text_atomic(out_dir / name, text))
    except OSError as e:
        print(f"helmcheck matrix: error: cannot write {getattr(e, 'filename', None) or out_dir}: "
              f"{e.strerror or e}", file=sys.stderr)
        return exitcodes.INCONCLUSIVE
    for path in written:
        print(f"wrote {path}")
    return exitcodes.OK
