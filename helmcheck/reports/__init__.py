"""Compliance reports: pure functions of a results directory (``results.json`` + ``wire.log``).

Modules, one concern each:

* :mod:`~helmcheck.reports.results` — ``results.json`` schema 1: builder, loader;
  :mod:`~helmcheck.reports.schema` — its validator; :mod:`~helmcheck.reports.verdicts` — the
  verdict rules (:func:`overall_verdict`, :func:`run_verdict`, :func:`exit_code`).
* :mod:`~helmcheck.reports.assemble` — the one way from a verdict ledger and the run facts to
  clause entries, run verdict and certificate flag (every certifier, ``check-log`` and
  ``verify``).
* :mod:`~helmcheck.reports.atomic` — atomic file writes.
* :mod:`~helmcheck.reports.digest` — the certificate digest (SHA-256 of both files).
* :mod:`~helmcheck.reports.wirelog` — a tolerant summary of the wire log;
  :mod:`~helmcheck.reports.segments` — a session's log in segments (``wire.log``, ``wire.001.log``, …).
* :mod:`~helmcheck.reports.rundir` — one read of a results directory (:class:`Run`).
* :mod:`~helmcheck.reports.view` — clause rows joined with the profile, grouped and counted.
* :mod:`~helmcheck.reports.text` — printable text, short titles.
* :mod:`~helmcheck.reports.linecounters` — the line a run was judged on, in a sentence each: its model
  (clean or noisy, and why) and its port's error counters.
* :mod:`~helmcheck.reports.timeline` — the mode timeline SVG.
* :mod:`~helmcheck.reports.html`, :mod:`~helmcheck.reports.junit`,
  :mod:`~helmcheck.reports.markdown`, :mod:`~helmcheck.reports.compare` — the renderings.
* The HTML report's parts: :mod:`~helmcheck.reports.html_style` — its CSS and
  Content-Security-Policy; :mod:`~helmcheck.reports.html_markup` — escaping, profile Markdown,
  tables; :mod:`~helmcheck.reports.html_certificate` — the first page;
  :mod:`~helmcheck.reports.html_clauses` — clause matrix, findings, passing evidence;
  :mod:`~helmcheck.reports.html_run` — implementation, run, process, restore;
  :mod:`~helmcheck.reports.html_coverage` — model coverage and the event table;
  :mod:`~helmcheck.reports.html_scenarios` — a backseat run's scenarios, what each exercised.
* :mod:`~helmcheck.reports.render` — :func:`render_all` (the command line is ``helmcheck report``).
* :mod:`~helmcheck.reports.matrix` — several runs side by side (``helmcheck matrix``).

Certificates (issue: certificates anyone can verify):

* :mod:`~helmcheck.reports.scope` — claimed clauses, ``certificate`` and the headline;
* :mod:`~helmcheck.reports.identity` — what was tested, by whom, with which tester;
* :mod:`~helmcheck.reports.manifest` — file digests and the signed manifest;
* :mod:`~helmcheck.reports.signing` — Ed25519 keys and signatures;
* :mod:`~helmcheck.reports.certificate` — :func:`finish_run`, the end of every certification;
* :mod:`~helmcheck.reports.verify` — the checks of ``helmcheck verify``: digests, profile,
  signature, and the assembly again, on the re-judged evidence, compared (the wire log is
  re-judged by :func:`helmcheck.commands.verify_cmd.verify_run`, which runs these checks).
"""

from .digest import Digest, digest_bytes, digest_dir
from .render import render_all
from .results import (
    CLAUSE_VERDICTS,
    VERDICTS,
    ReportError,
    add_clause,
    add_event,
    add_mode,
    add_process,
    add_replay,
    exit_code,
    finish,
    load_results,
    new_results,
    overall_verdict,
    run_verdict,
    validate,
    write_results_atomic,
)
from .rundir import Run, load_run

__all__ = [
    "CLAUSE_VERDICTS",
    "VERDICTS",
    "Digest",
    "ReportError",
    "Run",
    "add_clause",
    "add_event",
    "add_mode",
    "add_process",
    "add_replay",
    "digest_bytes",
    "digest_dir",
    "exit_code",
    "finish",
    "load_results",
    "load_run",
    "new_results",
    "overall_verdict",
    "render_all",
    "run_verdict",
    "validate",
    "write_results_atomic",
]
