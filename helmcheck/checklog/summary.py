"""The summary of an archive check: ``summary.json`` (the source of truth), ``summary.md``, the matrix.

This module owns what an archive check says about the whole archive and the exit status over
all its files. :func:`build_summary` turns the per-file entries (:mod:`.fleettask`) and what
:mod:`.archive` found (skipped and unreadable files) into one JSON document; :func:`write_summary`
writes it and its renderings into the report directory, each atomically
(:mod:`helmcheck.reports.atomic`): ``summary.json``, ``summary.md`` (the run's verdict, per-file
verdicts, clause × file counts, what was skipped and why, then the matrix) and ``matrix.html``
— the matrix view is :mod:`helmcheck.reports.matrix`'s, one column per file, as ``helmcheck
matrix`` draws it.

**Exit status over all** (:func:`exit_status`; ``docs/contracts.md``): the worst over the files,
ranked 0 < 2 < 1 as for several ``check-log`` FILEs — each judged (or cached) file by its verdict
(:func:`helmcheck.reports.results.exit_code`), each file that could not be judged (unreadable,
a report not written, a tester error) as 2. So a run with an unreadable file never exits 0, and
still exits 1 when another file failed. An interrupted run is at least 2 (1 if a finished file
failed), its summary marked ``partial``. Skipped files (not logs) do not count.
"""

from __future__ import annotations

import json
import os
from collections import Counter
from datetime import datetime, timezone
from pathlib import Path
from typing import Any, Optional, Sequence

from ..reports import results as R
from ..reports.markdown import md_escape
from ..reports.view import VERDICT_LABEL
from .archive import Archive

__all__ = ["build_summary", "write_summary", "exit_status", "verdict_line", "SUMMARY_FORMAT", "CLAUSE_VERDICTS"]

SUMMARY_FORMAT = "helmcheck-archive-summary-1"
CLAUSE_VERDICTS = ("pass", "non-strict", "fail", "inconclusive", "not-tested")
_RANK = {0: 0, 2: 1, 1: 2}
_NOT_JUDGED = ("unreadable", "error", "not-judged")


def _worst(codes) -> int:
    return max(codes, key=lambda c: _RANK.get(c, 3), default=0)


def exit_status(files: Sequence[dict[str, Any]], strict: bool, partial: bool) -> int:
    """The archive's exit code (module docstring)."""
    codes = [R.exit_code(f["verdict"], strict) if f["status"] in ("judged", "cached") else 2
             for f in files if f["status"] != "not-judged"]
    if partial:
        codes.append(2)
    return _worst(codes)


def build_summary(archive: Archive, entries: Sequence[dict[str, Any]], *, report_dir: Path, options: dict,
                  command: str, started: str, strict: bool, partial_reason: Optional[str] = None,
                  planned: Sequence[str] = ()) -> dict[str, Any]:
    """The ``summary.json`` document. ``planned``: every log's path, so a file an interruption left
    unjudged is listed (``not-judged``)."""
    files = {e["path"]: dict(e) for e in entries}
    for u in archive.unreadable:
        files[u.rel] = {"path": u.rel, "status": "unreadable", "message": u.reason}
    for rel in planned:
        if rel not in files:
            late = (Path(report_dir) / rel / "check-key.json").is_file()  # a worker finished it as the run stopped
            files[rel] = {"path": rel, "status": "not-judged",
                          "message": "finished as the run was interrupted: the next run takes it from the cache"
                          if late else "the run was interrupted first"}
    rows = []
    for rel in sorted(files):
        f = files[rel]
        if f["status"] in ("judged", "cached"):
            f["results"] = rel + "/"
            f["exit_code"] = R.exit_code(f["verdict"], strict)
            tally = Counter(f.get("clauses", {}).values())
            f["clause_counts"] = {v: tally[v] for v in CLAUSE_VERDICTS if tally[v]}
            f["failed"] = sorted(c for c, v in f.get("clauses", {}).items() if v in ("fail", "non-strict"))
        else:
            f["exit_code"] = None if f["status"] == "not-judged" else 2
        rows.append(f)
    clause_rows: dict[str, Counter] = {}
    for f in rows:
        for cid, v in f.pop("clauses", {}).items():
            clause_rows.setdefault(cid, Counter())[v] += 1
    partial = partial_reason is not None
    code = exit_status(rows, strict, partial)
    by_status = Counter(f["status"] for f in rows)
    by_verdict = Counter(f["verdict"] for f in rows if f["status"] in ("judged", "cached"))
    doc = {
        "format": SUMMARY_FORMAT,
        "tool": {"name": "helmcheck", "version": options.get("version")},
        "partial": partial,
        "partial_reason": partial_reason,
        "started": started,
        "finished": datetime.now(timezone.utc).isoformat(timespec="seconds").replace("+00:00", "Z"),
        "command": command,
        "root": str(archive.root),
        "report_dir": str(report_dir),
        "options": options,
        "exit_code": code,
        "counts": {"files": len(rows), **{s: by_status[s] for s in ("judged", "cached", *_NOT_JUDGED)},
                   **{v: by_verdict[v] for v in ("pass", "non-strict", "fail", "inconclusive")},
                   "skipped": len(archive.skipped)},
        "files": rows,
        "clauses": {cid: {v: c[v] for v in CLAUSE_VERDICTS if c[v]} for cid, c in sorted(clause_rows.items())},
        "skipped": [{"path": s.rel, "reason": s.reason} for s in archive.skipped],
    }
    doc["verdict_line"] = verdict_line(doc)
    return doc


def verdict_line(doc: dict[str, Any]) -> str:
    """One line: the exit status's word, then the counts."""
    n = doc["counts"]
    word = {0: "PASS", 1: "FAIL", 2: "INCONCLUSIVE"}.get(doc["exit_code"], "ERROR")
    parts = [f"{n[v]} {v}" for v in ("pass", "non-strict", "fail", "inconclusive") if n[v]]
    parts += [f"{n[s]} {s.replace('-', ' ')}" for s in _NOT_JUDGED if n[s]]
    judged = f"{n['judged']} judged now, {n['cached']} cached"
    skipped = f"; {n['skipped']} skipped (not logs)" if n["skipped"] else ""
    partial = " (partial: interrupted)" if doc["partial"] else ""
    return f"{word}{partial} — {n['files']} log(s): {', '.join(parts) or 'none'} ({judged}){skipped}"


def _markdown(doc: dict[str, Any], matrix_md: str) -> str:
    out = ["# helmcheck archive check", ""]
    if doc["partial"]:
        out += [f"> **PARTIAL**: {md_escape(doc['partial_reason'])}. Files not judged are listed as such; "
                "the next run judges them (the others are cached).", ""]
    out += [f"**{md_escape(doc['verdict_line'])}** (exit {doc['exit_code']})", "",
            f"Archive `{md_escape(doc['root'])}`, started {md_escape(doc['started'])}, "
            f"command `{md_escape(doc['command'])}`.", "",
            "## Files", "", "| file | verdict | status | clauses | failed |", "|---|---|---|---|---|"]
    for f in doc["files"]:
        name = md_escape(f["path"])
        if f.get("results"):
            name = f"[{name}](<{f['results']}report.md>)"
        verdict = VERDICT_LABEL.get(f.get("verdict", ""), "—")
        status = f["status"] + (f": {md_escape(f['message'])}" if f.get("message") else "")
        tally = ", ".join(f"{n} {v}" for v, n in f.get("clause_counts", {}).items())
        out.append(f"| {name} | {verdict} | {status} | {tally} | {', '.join(f.get('failed', []))} |")
    out += ["", "## Clauses × files", "", "Files per verdict, for each clause.", "",
            "| clause | " + " | ".join(VERDICT_LABEL[v] for v in CLAUSE_VERDICTS) + " |",
            "|---|" + "---:|" * len(CLAUSE_VERDICTS)]
    for cid, c in doc["clauses"].items():
        out.append(f"| {cid} | " + " | ".join(str(c.get(v, "")) for v in CLAUSE_VERDICTS) + " |")
    if doc["skipped"]:
        out += ["", "## Skipped", ""] + [f"- `{md_escape(s['path'])}`: {md_escape(s['reason'])}"
                                         for s in doc["skipped"]]
    out += ["", matrix_md]
    return "\n".join(out)


def write_summary(report_dir: Path, doc: dict[str, Any]) -> Path:
    """``summary.json``, ``summary.md`` and ``matrix.html`` in ``report_dir`` (atomic); returns
    the path of ``summary.md``. ``OSError`` if one cannot be written."""
    from ..reports.atomic import write_text_atomic
    from ..reports.matrix import MatrixRun, render_matrix_html, render_matrix_markdown
    from ..reports.results import ReportError, load_results

    runs = []
    for f in doc["files"]:
        if f.get("results"):
            try:
                res = load_results(report_dir / f["results"])
            except ReportError:
                continue
            href = f["results"] + "report.html" if (report_dir / f["results"] / "report.html").is_file() else None
            runs.append(MatrixRun(res, href=href, source=f["path"]))
    title = f"helmcheck archive check: {os.path.basename(doc['root']) or doc['root']}"
    write_text_atomic(report_dir / "summary.json", json.dumps(doc, indent=2) + "\n")
    write_text_atomic(report_dir / "matrix.html", render_matrix_html(runs, title=title))
    return write_text_atomic(report_dir / "summary.md", _markdown(doc, render_matrix_markdown(runs, title=title)))
