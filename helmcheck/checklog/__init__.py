"""Offline checking of recorded serial logs against the reference model (``helmcheck check-log``).

A recorded two-direction capture is replayed through :class:`~helmcheck.model.VehicleModel` with
its recorded timestamps — the remote-helm analogue of Jepsen's ``analyze`` and of TLA+ trace
validation: the whole log is consumed and every byte is attributed to a sentence, a discarded
run, a recorder note, or a finding with its line number. Results are per clause, in the
certifiers' verdicts, in a results directory of role ``log``.

Modules, one concern each:

* :mod:`.readers` — format detection, timestamp resolution, and one reader per format (a wire
  log by the one wire-log reader, :func:`helmcheck.grammar.wirelog.read_wire_log`);
* :mod:`.socat` — the ``socat -v`` / ``-x`` / ``-v -x`` reader and its timestamp unit;
* :mod:`.records` — what the readers yield (:data:`~.records.Chunk`) and learn (:class:`~.records.LogMeta`);
* :mod:`.origin` — what the log's header says about the run that wrote it, and from it how a
  check judges the log when the command line does not say (the role that run tested, the run's
  profile, the header's time scale and missions);
* :mod:`.checker` — :func:`~.checker.check_log`: one pass over the records, each fed to the role's
  observer (:mod:`helmcheck.judge`: the vehicle observer for §1–8, the backseat observer for §9,
  the same ones the certifiers use), bounded bookkeeping;
* :mod:`.sidejob` — a second process for the backseat role of a long log;
* :mod:`.report` — ``results.json``, the log copy, the rendered reports.

Whole archives (``check-log DIR|GLOB…``):

* :mod:`.archive` — finding the logs of directories and patterns (by content), what is skipped
  and why, where each log's results go (mirroring the tree);
* :mod:`.fleettask` — one log judged into its results directory, or found judged already (the
  cache key ``check-key.json``): the task every engine runs;
* :mod:`.fleet` — running the tasks in this process or in ``--jobs`` processes, and interruption;
* :mod:`.cluster` — the same tasks on a Dask distributed scheduler (``--cluster``, the optional
  extra ``cluster``);
* :mod:`.summary` — ``summary.json``, ``summary.md``, the matrix view, the exit status over all.
"""

from .checker import CheckOutcome, LogFormatError, check_log
from .readers import FORMATS, detect_format

__all__ = ["check_log", "CheckOutcome", "LogFormatError", "detect_format", "FORMATS"]
