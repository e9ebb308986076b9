"""The one timing formula: RH-TIM-1 tolerances, the observer's own uncertainty, the ACK window.

Every judge takes its timing from here, so a duration is judged the same way live and offline.

* :func:`tolerance` — RH-TIM-1: a protocol duration ``d`` (vehicle seconds) may be off by
  ``max(0.5 s, 5 % of d)``, widened by the observer's slack.
* :func:`slack` — what the observer cannot see, in vehicle seconds: half the window in which
  the vehicle produced what it observed (the request went out at ``t_sent``, the answer came
  back at ``t_recv``), the timestamp step of the record, and :data:`JITTER_S` of timestamping
  jitter, all wall time multiplied by the time scale ``k`` (RH-TIM-2). The recorder stamps a
  request before writing it and an answer after reading it, so the window itself brackets the
  moment the vehicle acted, whatever the host's load; the jitter only covers the clock.
* :func:`judgeable` — an observation whose slack exceeds half the duration cannot say whether
  the duration held: INCONCLUSIVE, never PASS or FAIL (RH-TIM-1's last sentence).
* :func:`ack_allowance` — RH-ACK-2: the ACK window plus serial transmit time of the command and
  of the replies up to its ACK at the line's baud (:func:`transmit_time`, 10 bits per byte,
  8N1: defined with the wire log in :mod:`helmcheck.grammar.wirelog`, re-exported here), plus
  what the observer cannot see (:func:`ack_uncertainty`): two timestamp steps of the record (the
  command's stamp and the ACK's, each up to a step off whichever way the recorder rounds) and
  :data:`JITTER_S`.
  Wall time; never scaled (RH-TIM-2). No fixed grace: an ACK measured later than the allowance
  is late by more than the observer's own uncertainty, so it is a FAIL. Only when the
  timestamps are too coarse to bound the window (a step over a tenth of it) is an ACK within
  the allowance that the steps could hide past the window INCONCLUSIVE (:func:`ack_verdict`).
* :func:`ack_give_up_after` — how long a command waits for its ACK before the ACK counts as
  missing (RH-ACK-1; the tester stops waiting and probes): long enough to *see* a late ACK and
  judge it late (FAIL on RH-ACK-2 with its measured delay) rather than call it missing.
* :data:`REACTION_S` — the backseat's reaction allowance default (profile ``reaction_s``).
* :data:`PLANT_REACT_S` — how long a vehicle may take to act on what its own sensors show (on
  station, at the surface) before an ``$OSI`` that shows it there but not acting is a FAIL.

Decisions (spec silent), properties of the observer (a process on a general-purpose OS), named
here and shown in reports: timestamping and scheduling jitter :data:`JITTER_S` = 0.03 s (how
late a recorder woken late may stamp a line it reads — the only slack RH-ACK-2 adds to the
window and transmit time besides the record's own timestamp step); a late ACK is awaited for
twice the allowance and one second more (:func:`ack_give_up_after`: a 2.5 s answer to a 1 s
window is still seen, and failed as late).
"""

from __future__ import annotations

from ..grammar.wirelog import BITS_PER_BYTE, transmit_time
from ..model.timers import tolerance
from .verdict import FAIL, INCONCLUSIVE, PASS

__all__ = ["tolerance", "slack", "judgeable", "ack_allowance", "ack_uncertainty", "ack_verdict",
           "ack_give_up_after", "transmit_time", "JITTER_S", "REACTION_S", "BITS_PER_BYTE", "PLANT_REACT_S"]

#: Wall seconds of timestamping and scheduling jitter the observer allows itself.
JITTER_S = 0.03
#: Default backseat reaction allowance (profile key ``reaction_s``, RH-BS-3/5).
REACTION_S = 0.25
#: Vehicle seconds a vehicle may take to act on being on station or at the surface (decision:
#: the spec gives no figure; a UVC's control loop runs several times a second).
PLANT_REACT_S = 2.0


def slack(k: float, t_sent: float, t_recv: float, resolution: float = 0.0, extra_v: float = 0.0) -> float:
    """Vehicle seconds of observer uncertainty for something produced in ``[t_sent, t_recv]``."""
    half = max(0.0, (t_recv - t_sent) / 2)
    return k * (half + resolution + JITTER_S) + extra_v


def judgeable(duration: float, slack_v: float) -> bool:
    """RH-TIM-1: can an observation with ``slack_v`` of uncertainty judge ``duration``?"""
    return slack_v <= 0.5 * max(duration, 1.0)


def ack_uncertainty(resolution: float, jitter: float = JITTER_S) -> float:
    """Wall seconds by which the observer may misjudge the delay between two lines it stamped:
    a timestamp step on each stamp, and the host's jitter (:data:`JITTER_S`, or more where the
    host was measured to add more: :mod:`.linebudget`)."""
    return 2 * resolution + jitter


def ack_allowance(ack_window_s: float, command_bytes: int, reply_bytes: int, baud: int,
                  resolution: float = 0.0, jitter: float = JITTER_S) -> float:
    """RH-ACK-2: wall seconds an ACK may come after its command was stamped (the recorder stamps
    before writing): the window, transmit time of the command and of the replies up to and with
    its ACK, and the observer's own uncertainty (:func:`ack_uncertainty`). Nothing else: an ACK
    measured later is late beyond doubt."""
    return ack_window_s + transmit_time(command_bytes + reply_bytes, baud) + ack_uncertainty(resolution, jitter)


def ack_verdict(dt: float, allowance: float, ack_window_s: float, resolution: float,
                jitter: float = JITTER_S) -> str:
    """RH-ACK-2 for an ACK measured ``dt`` wall seconds after its command: ``"fail"`` beyond the
    allowance; ``"pass"`` within it when the timestamps are fine enough to bound the window (a
    step of at most a tenth of it, RH-TIM-1: the vehicle gets the benefit of the doubt) or when
    even the worst case of the steps keeps the ACK inside the window; else ``"inconclusive"``
    (coarse steps could hide an ACK past the window)."""
    if dt > allowance:
        return FAIL
    if resolution <= ack_window_s / 10 or dt + 2 * ack_uncertainty(resolution, jitter) <= allowance:
        return PASS
    return INCONCLUSIVE


def ack_give_up_after(allowance: float) -> float:
    """Wall seconds after a command's send at which its ACK counts as missing (RH-ACK-1): twice
    the allowance and one second more, so an ACK well past the window is still seen and judged
    late (RH-ACK-2) with its delay. An ACK that comes later still belongs to its command."""
    return 2 * allowance + 1.0
