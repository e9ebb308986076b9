"""The start-up time-scale check of ``certify vehicle``: read the vehicle's clock over the wire.

A user who declares the wrong ``--time-scale`` (×1 against a vehicle running ×20) would get
FAILs with no hint. So after the probe, before any case, :func:`check_clock` asks ``$OSD,G``
repeatedly for up to :data:`MAX_WALL_S` wall seconds and hands the ``$GPRMC`` times to
:mod:`.clockrate` (sans-IO), which gives an interval for the vehicle's clock rate and a verdict:

* ``mismatch`` — the interval excludes the declared rate by :data:`.clockrate.CLEAR_FACTOR`:
  an ``inconclusive`` note on every selected clause, then :class:`ClockMismatch`; the runner
  ends the run (a ``run aborted`` note), so live and offline judging give INCONCLUSIVE, exit 2,
  with the message naming both rates;
* ``consistent`` / ``unresolved`` — the run goes on;
* ``not-measured`` — nothing to measure with (no ``G`` in the profile's ``osd_letters``, no
  ``$OSD`` claimed, no ``$GPRMC`` or no time in it, a time that never moved, the check turned
  off): recorded, and the run goes on.

Whatever the outcome, it is written as a ``clock check: …`` note in the wire log and as
``settings.clock_check`` in ``results.json``. Measuring stops as soon as the verdict is decided
(a few tenths of a second against an emulator; a mismatch is measured until the interval
names one rate, about half a second); requests are at least :data:`GAP_S` apart so a
slow line is not flooded. ``$GPRMC`` is the clock read: no ``$OSI`` field moves with vehicle
time while the vehicle is idle (field 13, time left, moves only during a mission).
"""

from __future__ import annotations

from typing import Optional

from ...grammar import decode
from ...grammar import sentences as s
from ...judge.wire import tester_note
from .clockrate import MIN_SAMPLES, ClockCheck, Sample, gprmc_clock, judge_rate, not_measured
from .session import frame

__all__ = ["check_clock", "ClockMismatch", "MAX_WALL_S", "GAP_S"]

#: Wall seconds the check may spend reading (it usually decides much sooner); the last answer
#: is awaited 0.5 s more at most.
MAX_WALL_S = 2.0
#: Wall seconds from one request to the next, at least.
GAP_S = 0.05
#: Requests in a row that may go unanswered before the check gives up.
MISSES = 2
#: Wall seconds a reading waits for the ``$ACK`` once its ``$GPRMC`` is in.
ACK_AFTER_S = 0.25


class ClockMismatch(Exception):
    """The vehicle's clock is clearly not at the declared time scale (the run stops, INCONCLUSIVE)."""

    def __init__(self, check: ClockCheck):
        super().__init__(check.message())
        self.check = check


def _reading(link, profile, hard_end: float) -> tuple[Optional[Sample], str]:
    """One ``$OSD,G``: the sample, or why there is none. Waits for its ``$ACK`` or the ACK
    window, never past ``hard_end``, and at most :data:`ACK_AFTER_S` after the ``$GPRMC`` (a
    vehicle that does not acknowledge ``$OSD`` is still read at the pace of its data)."""
    link.drain()  # a late answer to the previous request is not taken for this one's
    sent = link.send(frame("OSD,G"))
    end = min(sent + profile.ack_window_s + 0.5, hard_end)
    got: Optional[Sample] = None
    why = "no answer to $OSD,G"
    while True:
        rx = link.next(end)
        if rx is None:
            break
        if not rx.line:
            continue
        sentence = decode(rx.raw, profile).sentence
        if isinstance(sentence, s.GPRMC) and got is None:
            clock = gprmc_clock(sentence.time, sentence.date)
            if clock is None:
                why = f"the $GPRMC carries no time ({sentence.time!r})"
            else:
                got = Sample(sent, rx.t, clock[0], clock[1])
                end = min(end, rx.t + ACK_AFTER_S)
        elif isinstance(sentence, s.ACK) and sentence.type == 8:
            if got is None and why == "no answer to $OSD,G":
                why = "$OSD,G was answered without a $GPRMC"
            break
    return got, why


def decided(check: ClockCheck) -> bool:
    """Measuring can stop: the clock agrees, or it clearly does not and the interval is narrow
    enough to name the vehicle's rate in the message."""
    return check.status == "consistent" or (check.status == "mismatch" and check.rate is not None
                                            and check.rate.named is not None)


def measure_clock(link, profile, declared: float, max_wall_s: float = MAX_WALL_S) -> ClockCheck:
    """Read the clock until the verdict is decided or ``max_wall_s`` has passed."""
    if "OSD" not in profile.commands:
        return not_measured(declared, "the profile does not claim $OSD")
    if "G" not in profile.osd_letters:
        return not_measured(declared, "the profile's osd_letters lack G (no $GPRMC to read the vehicle's time)")
    samples: list[Sample] = []
    misses, why = 0, ""
    start = link.now()
    hard_end = start + max_wall_s + 0.5  # the last reading's answer may come this late
    check: Optional[ClockCheck] = None
    while link.now() - start < max_wall_s:
        t0 = link.now()
        got, why = _reading(link, profile, hard_end)
        if got is None:
            misses += 1
            if misses >= MISSES:
                break
        else:
            misses = 0
            samples.append(got)
            if len(samples) >= MIN_SAMPLES:
                check = judge_rate(samples, declared)
                if decided(check):
                    return check
        left = GAP_S - (link.now() - t0)
        if left > 0:
            link.sleep(left)
    if len(samples) < 2:
        return not_measured(declared, why or "no reading of the vehicle's time")
    return check or judge_rate(samples, declared)


def check_clock(run, enabled: bool = True) -> ClockCheck:
    """The runner's start-up call: measure, record (note and ``settings.clock_check``), and raise
    :class:`ClockMismatch` when the run must stop."""
    if enabled:
        check = measure_clock(run.link, run.p, run.k)
        run.link.drain()  # an answer the check stopped waiting for is not left to the first case
    else:
        check = not_measured(run.k, "the check was turned off (--no-clock-check)")
    run.link.note(check.note())
    ses = run.session
    if enabled and ses is not None and any(not x.done or x.spoil for x in ses.obs.sent):
        # a request the line may have spoilt (or a vehicle that does not answer it): settled, and
        # made again (session.finish) — the judge's business, after the check's own budget
        with ses.not_stopping():
            ses.finish()
    run.results["settings"]["clock_check"] = check.as_settings()
    if check.stops:
        run.link.note(tester_note("inconclusive", run.ids, check.message()))
        raise ClockMismatch(check)
    return check
