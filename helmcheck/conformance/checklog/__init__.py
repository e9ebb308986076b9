"""Offline checking of recorded serial logs against the reference model (``helmcheck check-log``).

A recorded two-direction capture is replayed through :class:`~helmcheck.model.VehicleModel` with
its recorded timestamps — the remote-helm analogue of Jepsen's ``analyze`` and of TLA+ trace
validation: the whole log is consumed and every byte is attributed to a sentence, a discarded
run, a recorder note, or a finding with its line number. Results are per clause, in the
certifiers' verdicts, in a results directory of role ``log``.

Modules, one concern each:

* :mod:`.readers` — the capture formats (helmcheck wire-log 1, ``socat -v``, ``socat -x``),
  format and timestamp-resolution detection, streaming records (:data:`~.readers.Chunk`).
* :mod:`.checker` — :func:`~.checker.check_log`: re-framing per direction, decoding, dispatch to
  the judges, vehicle framing/content clauses (RH-FRM-*, RH-OUT-1..3), bounded bookkeeping.
* :mod:`.vehicle` — the replay through the model: RH-ACK-*, RH-OUT-4, the command and timer
  clauses, plant events from recorder notes or inferred from ``$OSI``.
* RH-BS-1..8 are judged by :class:`helmcheck.judge.backseat.BackseatObserver`, the observer
  ``certify backseat`` uses, fed every record by the checker.
* :mod:`.accounting` — per-clause counts, bounded evidence, verdicts.
* :mod:`.report` — ``results.json``, the log copy, the rendered reports.
"""

from .checker import CheckOutcome, LogFormatError, check_log
from .readers import FORMATS, detect_format

__all__ = ["check_log", "CheckOutcome", "LogFormatError", "detect_format", "FORMATS"]
