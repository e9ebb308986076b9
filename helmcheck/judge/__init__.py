"""The judges: one sans-IO observer per role, one verdict ledger, one timing formula.

Live certification and offline log checking feed the same observer the same
:class:`~helmcheck.judge.wire.WireEvent` s, so the same bytes get the same verdict, whoever
reads them. Modules:

* :mod:`~helmcheck.judge.verdict` — :class:`Verdict`, the one type of a clause or run verdict;
* :mod:`~helmcheck.judge.ledger` — the one verdict ledger and its one combining rule;
* :mod:`~helmcheck.judge.timing` — RH-TIM-1 tolerances, observer slack, the ACK window;
* :mod:`~helmcheck.judge.linebudget` — what the line costs the observer (reply latency, transmit
  time, the host's jitter, at the time scale) and which durations it can time on it;
* :mod:`~helmcheck.judge.facts` — protocol facts derived from the transition table;
* :mod:`~helmcheck.judge.wire` — wire events and the recorder notes a judge understands;
* :mod:`~helmcheck.judge.runfacts` — the run facts (selection, the implementation's end, a
  run cut short) the wire log's notes record, booked into a ledger;
* a faulty line: :mod:`~helmcheck.judge.spoil` — the form of a broken line a line fault gives;
  :mod:`~helmcheck.judge.streaks` — observations it may have spoilt, held until made again
  (the repetition rule); :mod:`~helmcheck.judge.linefaults` — a line-fault relay's notes;
  :mod:`~helmcheck.judge.linemodel` — whether the link can damage bytes at all (clean or noisy);
* :mod:`~helmcheck.judge.vehicle` — the vehicle observer (§1–8);
* :mod:`~helmcheck.judge.backseat` — the backseat observer (§9).

Nothing here imports ``serial``, ``time``, ``threading`` or ``asyncio``.
"""

from .ledger import ClauseVerdict, Evidence, Ledger
from .verdict import Verdict
from .wire import FROM_VEHICLE, NOTE, TO_VEHICLE, WireEvent

__all__ = ["Verdict", "Ledger", "Evidence", "ClauseVerdict", "WireEvent", "TO_VEHICLE", "FROM_VEHICLE", "NOTE"]
