"""The mirror's shortcut for polls: an ``$OSD`` answered in place is answered as on copies.

:meth:`~helmcheck.judge.vehicle.belief.Beliefs.command` answers an ``$OSD`` that every candidate
can only have met in one state in place (``Beliefs._poll``), and otherwise — or when no answer is
the vehicle's — on copies of the candidates. Both must leave the same mirror and the same result.
"""

from __future__ import annotations

from helmcheck.grammar import sentences as s
from helmcheck.judge.vehicle.belief import Beliefs
from helmcheck.judge.vehicle.catalog import KnownMissions
from helmcheck.model.testing import oms, omstart, osd
from helmcheck.profile import DEFAULT

OSD = osd("G", "C", "S")
ANSWER = ["GPRMC", "Compass", "OSI", s.ACK(8, 0, 0)]


def _session(monkeypatch, shortcut: bool) -> tuple[list, list]:
    b = Beliefs(DEFAULT, KnownMissions(DEFAULT), 1.0)
    if not shortcut:
        monkeypatch.setattr(b, "_poll", lambda *a: None)
    inputs = [(omstart(), 1.0, [s.ACK(3, 0, 0)])]
    inputs += [(OSD, 1.5 + 0.5 * i, ANSWER) for i in range(6)]
    inputs += [(oms(timeout=2), 5.0, [s.ACK(9, 0, 0)])]  # a servo timeout: polls that race it
    inputs += [(OSD, 5.5 + 0.25 * i, ANSWER) for i in range(12)]
    inputs += [(OSD, 9.0, ["GPRMC", s.ACK(8, 0, 0)]), (OSD, 9.5, [s.ACK(8, 1, 26)])]  # wrong answers
    results, mirrors = [], []
    for item, v, observed in inputs:
        r = b.command(item, v, 0.05, list(observed))
        results.append((r.expected, r.matched, r.row, r.before, r.adopted, r.desync, r.timings))
        mirrors.append([(c.signature(), c.model.now, c.model.last_row, len(c.model.trace), c.pending, c.events)
                        for c in b.cands])
    return results, mirrors


def test_polls_answered_in_place_are_answered_as_on_copies(monkeypatch):
    assert _session(monkeypatch, True) == _session(monkeypatch, False)
