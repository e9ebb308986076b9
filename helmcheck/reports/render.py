"""Writing the reports of a results directory, and the ``helmcheck report`` command.

``helmcheck report DIR [--format html,junit,md] [--compare OLD_DIR [--fail-on-regression]]``
reads ``DIR/results.json`` and ``DIR/wire.log`` (nothing is re-run) and writes, each atomically,
``DIR/report.html``, ``DIR/junit.xml`` and ``DIR/report.md``. Exit status: 0 written; 1 with
``--fail-on-regression``, when a clause regressed or lost coverage since OLD_DIR; 2 a results
directory could not be read or a report could not be written (one line on stderr naming the
file); 64 a usage error (EX_USAGE).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any, Mapping, Sequence

from .atomic import write_text_atomic
from .compare import compare_html, compare_markdown, compare_runs, compare_text, worsened
from .html import render_html
from .junit import render_junit
from .markdown import render_markdown
from .results import ReportError
from .rundir import Run, load_run
from .scope import headline

__all__ = ["FORMATS", "OUTPUT_NAMES", "render_all", "render_run", "main", "build_parser", "add_arguments", "run",
           "EXIT_OK", "EXIT_WORSENED", "EXIT_UNREADABLE", "EXIT_USAGE"]

FORMATS = ("html", "junit", "md")
OUTPUT_NAMES = {"html": "report.html", "junit": "junit.xml", "md": "report.md"}
EXIT_OK, EXIT_WORSENED, EXIT_UNREADABLE, EXIT_USAGE = 0, 1, 2, 64


def render_all(directory: Path | str, formats: Sequence[str] = FORMATS,
               compare_dir: Path | str | None = None) -> list[Path]:
    """Render *formats* of the results in *directory* into it; returns the paths written.

    With *compare_dir*, the HTML and Markdown reports gain a section comparing with that
    earlier run. Raises :class:`ReportError` naming the file that could not be read or written,
    ``ValueError`` for an unknown format.
    """
    _check_formats(formats)
    run_ = load_run(directory)
    cmp = compare_runs(load_run(compare_dir), run_) if compare_dir is not None else None
    return render_run(run_, formats, cmp)


def _check_formats(formats: Sequence[str]) -> None:
    unknown = [f for f in formats if f not in OUTPUT_NAMES]
    if unknown:
        raise ValueError(f"unknown report format(s) {', '.join(unknown)}; choose from {', '.join(FORMATS)}")


def render_run(run_: Run, formats: Sequence[str] = FORMATS,
               comparison: Mapping[str, Any] | None = None) -> list[Path]:
    """Write the reports of an already loaded run (see :func:`render_all`)."""
    _check_formats(formats)
    written = []
    for fmt in dict.fromkeys(formats):
        if fmt == "html":
            text = render_html(run_, compare_html(comparison) if comparison else None)
        elif fmt == "junit":
            text = render_junit(run_)
        else:
            text = render_markdown(run_, compare_markdown(comparison) if comparison else None)
        path = run_.directory / OUTPUT_NAMES[fmt]
        try:
            write_text_atomic(path, text)
        except OSError as exc:
            raise ReportError(path, f"cannot write: {exc.strerror or exc}") from None
        written.append(path)
    return written


# --------------------------------------------------------------------------- command line

class _Parser(argparse.ArgumentParser):
    """argparse, but a usage error exits 64 (EX_USAGE) instead of 2, which means "unreadable"."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.print_usage(sys.stderr)
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message}\n")


def _formats(value: str) -> list[str]:
    names = [v.strip() for v in value.split(",") if v.strip()]
    bad = [n for n in names if n not in OUTPUT_NAMES]
    if bad or not names:
        raise argparse.ArgumentTypeError(
            f"unknown format {', '.join(bad) or repr(value)}; choose from {','.join(FORMATS)}")
    return names


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the ``report`` arguments to *parser* (for a subcommand of the top-level CLI)."""
    parser.add_argument("directory", metavar="DIR", type=Path,
                        help="results directory holding results.json and wire.log")
    parser.add_argument("--format", dest="formats", type=_formats, default=list(FORMATS),
                        metavar="LIST", help="comma-separated formats to write: html,junit,md (default: all)")
    parser.add_argument("--compare", dest="compare_dir", type=Path, metavar="OLD_DIR",
                        help="an earlier results directory to compare with")
    parser.add_argument("--fail-on-regression", action="store_true",
                        help="with --compare: exit 1 when a clause regressed or lost coverage (judged "
                             "before, not judged now)")


def build_parser(prog: str = "helmcheck report") -> argparse.ArgumentParser:
    parser = _Parser(prog=prog, description="Rebuild the compliance reports of a results directory "
                                            "(nothing is re-run).")
    add_arguments(parser)
    return parser


def run(args: argparse.Namespace, out=None, err=None) -> int:
    """Carry out a parsed ``report`` command; returns the exit status."""
    out = out or sys.stdout
    err = err or sys.stderr
    if getattr(args, "fail_on_regression", False) and args.compare_dir is None:
        print("helmcheck report: error: --fail-on-regression needs --compare OLD_DIR", file=err)
        return EXIT_USAGE
    try:
        run_ = load_run(args.directory)
        cmp = compare_runs(load_run(args.compare_dir), run_) if args.compare_dir is not None else None
        paths = render_run(run_, args.formats, cmp)
    except ReportError as exc:
        print(f"helmcheck report: error: {exc}", file=err)
        return EXIT_UNREADABLE
    r = run_.results
    print(f"{headline(r)}. {r['verdict_reason']}", file=out)  # the headline says when the run was cut short
    print(f"digest {run_.digest.combined}", file=out)
    for path in paths:
        print(f"wrote {path}", file=out)
    if cmp:
        print(compare_text(cmp), end="", file=out)
        if getattr(args, "fail_on_regression", False) and worsened(cmp):
            print(f"helmcheck report: {len(cmp['regressed'])} clause(s) regressed and {len(cmp['lost'])} lost "
                  f"coverage since {args.compare_dir}", file=err)
            return EXIT_WORSENED
    return EXIT_OK


def main(argv: Sequence[str] | None = None) -> int:
    """``helmcheck report DIR [--format html,junit,md] [--compare OLD_DIR]``; returns the exit status."""
    try:
        args = build_parser().parse_args(argv)
    except SystemExit as exc:  # --help (0) or a usage error (64)
        return exc.code if isinstance(exc.code, int) else EXIT_USAGE
    return run(args)
