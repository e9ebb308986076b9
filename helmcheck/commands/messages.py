"""Message forms every command shares, so each says the same thing the same way.

* :func:`report_line` — ``report: PATH``: where a command that writes a results directory put
  its report, one line on standard output after the verdict (``certify vehicle``, ``certify
  backseat``, ``check-log``, ``monitor``, ``make demo``); ``diff``'s is its ``diff.json``
  (:func:`report_line_for`).

(The closest known word to a mistyped one is :mod:`helmcheck.spelling`.)
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["report_line", "report_path", "report_line_for"]


def report_path(directory: Path | str, rendered: bool = True) -> Path:
    """The file to open: ``DIR/report.html``, or ``DIR/results.json`` when no report was rendered."""
    return Path(directory) / ("report.html" if rendered else "results.json")


def report_line(directory: Path | str, rendered: bool = True) -> str:
    """``report: DIR/report.html`` (module docstring)."""
    return f"report: {report_path(directory, rendered)}"


def report_line_for(path: Path | str) -> str:
    """``report: PATH`` for a report that is one named file (``diff``'s ``DIR/diff.json``)."""
    return f"report: {Path(path)}"
