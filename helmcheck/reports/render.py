"""Writing the reports of a results directory: :func:`render_all`, :func:`render_run`.

Reads ``DIR/results.json`` and ``DIR/wire.log`` (nothing is re-run) and writes, each atomically,
``DIR/report.html``, ``DIR/junit.xml`` and ``DIR/report.md`` (and the comparison with an older
run, given one). The command line is :mod:`helmcheck.commands.report_cmd`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Mapping, Sequence

from .atomic import write_text_atomic
from .compare import compare_html, compare_markdown, compare_runs
from .html import render_html
from .junit import render_junit
from .markdown import render_markdown
from .results import ReportError
from .rundir import Run, load_run

__all__ = ["FORMATS", "OUTPUT_NAMES", "render_all", "render_run"]

FORMATS = ("html", "junit", "md")
OUTPUT_NAMES = {"html": "report.html", "junit": "junit.xml", "md": "report.md"}


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
