"""The backseat observer (reference profile §9, RH-BS-1..8): one judge for live and offline.

``certify backseat`` feeds it every record of a run as it happens; ``check-log --role
backseat|both`` feeds it the same records read back from the wire log. Modules, one concern
each:

* :mod:`.observer` — :class:`BackseatObserver`, the facade (``feed``, ``close``) and the
  dispatch of each event to its rule;
* :mod:`.common` — settings, one sent line, the verdict of a measured interval;
* :mod:`.knowledge` — what the backseat could know, and from when (state reports, answers,
  the lockout);
* :mod:`.lines` — RH-BS-1, RH-BS-2, RH-BS-7 per line;
* :mod:`.budget` — RH-BS-4, the line budget;
* :mod:`.preconditions` — RH-BS-3;
* :mod:`.reaction` — RH-BS-5, rejections and the lockout;
* :mod:`.servo` — RH-BS-6, the servo refresh;
* :mod:`.polling` — RH-BS-8, state polls;
* :mod:`.words` — the findings in the backseat's words (what it sent, the rule of §1–6 it broke,
  quoted).
"""

from .budget import line_budget
from .common import BS_CLAUSES
from .observer import BackseatObserver
from .polling import POLL_INTERVAL_S
from .reaction import RESEND_SPACING_S

__all__ = ["BackseatObserver", "BS_CLAUSES", "line_budget", "POLL_INTERVAL_S", "RESEND_SPACING_S"]
