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
  of the replies before its ACK at the line's baud (10 bits per byte, 8N1), plus
  :data:`ACK_GRACE_S` and two timestamp steps. Wall time; never scaled (RH-TIM-2). An ACK later than that but within
  :func:`ack_fail_after` is INCONCLUSIVE (host load can explain it); beyond, FAIL.
* :data:`REACTION_S` — the backseat's reaction allowance default (profile ``reaction_s``).
* :data:`PLANT_REACT_S` — how long a vehicle may take to act on what its own sensors show (on
  station, at the surface) before an ``$OSI`` that shows it there but not acting is a FAIL.

Decisions (spec silent), properties of the observer (a process on a general-purpose OS), named
here and shown in reports: timestamping jitter :data:`JITTER_S` = 0.03 s; the ACK window's grace
for a loaded host reading late :data:`ACK_GRACE_S` = 0.25 s (a late ACK within twice the
allowance is INCONCLUSIVE, never PASS).
"""

from __future__ import annotations

from ..model.timers import tolerance

__all__ = ["tolerance", "slack", "judgeable", "ack_allowance", "ack_fail_after", "transmit_time",
           "JITTER_S", "ACK_GRACE_S", "REACTION_S", "BITS_PER_BYTE", "PLANT_REACT_S"]

#: Wall seconds of timestamping jitter the observer allows itself.
JITTER_S = 0.03
#: Wall seconds of grace on the ACK window for a host that reads late (RH-ACK-2).
ACK_GRACE_S = 0.25
#: Default backseat reaction allowance (profile key ``reaction_s``, RH-BS-3/5).
REACTION_S = 0.25
#: Vehicle seconds a vehicle may take to act on being on station or at the surface (decision:
#: the spec gives no figure; a UVC's control loop runs several times a second).
PLANT_REACT_S = 2.0
#: 8N1: one start bit, eight data bits, one stop bit (RH-FRM-9).
BITS_PER_BYTE = 10


def transmit_time(nbytes: int, baud: int) -> float:
    """Wall seconds the line needs for ``nbytes`` at ``baud`` (0 for an unpaced link)."""
    return nbytes * BITS_PER_BYTE / baud if baud else 0.0


def slack(k: float, t_sent: float, t_recv: float, resolution: float = 0.0, extra_v: float = 0.0) -> float:
    """Vehicle seconds of observer uncertainty for something produced in ``[t_sent, t_recv]``."""
    half = max(0.0, (t_recv - t_sent) / 2)
    return k * (half + resolution + JITTER_S) + extra_v


def judgeable(duration: float, slack_v: float) -> bool:
    """RH-TIM-1: can an observation with ``slack_v`` of uncertainty judge ``duration``?"""
    return slack_v <= 0.5 * max(duration, 1.0)


def ack_allowance(ack_window_s: float, command_bytes: int, reply_bytes: int, baud: int,
                  resolution: float = 0.0) -> float:
    """RH-ACK-2: wall seconds an ACK may take after the command's last byte was written."""
    return (ack_window_s + transmit_time(command_bytes + reply_bytes, baud) + ACK_GRACE_S
            + 2 * resolution)


def ack_fail_after(allowance: float) -> float:
    """Beyond this delay a late ACK is a FAIL; between the allowance and this, INCONCLUSIVE."""
    return 2 * allowance + 0.5
