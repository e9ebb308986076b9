"""Faulty vehicles for the rules the traceability table found no case could fail
(``helmcheck/spec/rules.toml``; the cases V-80..V-89, :mod:`helmcheck.certify.vehicle.rulecases`).

Each breaks exactly one rule, in the history the rule names, and behaves like the reference
everywhere else: a conforming vehicle's answers up to the moment the rule bites, so that only the
case that does what the rule forbids can tell it apart. Each is certified at one time scale (the
judges are the ones every other mutant exercises at two).
"""

from __future__ import annotations

import posixpath
import re

from helmcheck.emulator.core import EmulatorCore
from helmcheck.grammar import sentences as s
from helmcheck.model.handlers import ack

from .base import Model, Mutant, body, reframe

__all__ = ["MUTANTS"]

ONE_SCALE = (25.0,)


class OmsAcceptedAfterStop(Model):
    """RH-SRV-1, RH-RD-1: once a mission was started, ``$OMS`` is acknowledged as accepted (and
    ignored) after ``$OMSTOP`` too — the vehicle keeps "a mission was started" for "a mission runs"."""

    started = False

    def receive(self, item, now):
        if isinstance(item, s.OMSTART):
            out = super().receive(item, now)
            self.started = self.started or self.running
            return out
        if isinstance(item, s.OMS) and self.started and not self.running and self.phase == "none":
            return [ack(9)]
        return super().receive(item, now)


class OmsAcceptedInPrimitiveFromS(Model):
    """RH-SRV-1, RH-RD-1: in an ``M`` entered from ``S`` (no mission running) ``$OMS`` is
    acknowledged as accepted and ignored — the vehicle takes any control mode for a running mission."""

    def receive(self, item, now):
        if isinstance(item, s.OMS) and self.mode == "M" and not self.running and self.phase == "none":
            return [ack(9)]
        return super().receive(item, now)


class LookupBeforeState(Model):
    """RH-ACK-4, RH-RD-2: ``$OMLOAD`` looks the file up before it checks the state: a missing file
    while a mission runs is err 1, not the precondition's 29."""

    def receive(self, item, now):
        if isinstance(item, s.OMLOAD) and self.running and self.phase == "none":
            if type(self._lookup(item.name)).__name__ == "MissingMission":
                return [ack(2, 1)]
        return super().receive(item, now)


class OmloadDotDotInside(EmulatorCore):
    """RH-MSN-1: a name with a ``..`` component is accepted when it resolves inside the mission
    directory (``sub/../x.mis`` loads ``x.mis``); one that leads out of it is still refused."""

    def _line(self, raw, now, v):
        if raw.startswith((b"$OMLOAD,", b"$OMSTART,")) and b"*" in raw:
            f = body(raw).decode("latin-1").split(",")
            i = 1 if f[0] == "OMLOAD" else 5
            if len(f) > i and ".." in re.split(r"[\\/]", f[i]):
                norm = posixpath.normpath(f[i].replace("\\", "/"))
                if not norm.startswith(("..", "/")):
                    f[i] = norm
                    raw = reframe(raw, ",".join(f).encode("latin-1"))
        return super()._line(raw, now, v)


class OmwKeywordOnlyInW(Model):
    """RH-OMW-3, RH-RD-4: the ``$OMW`` keyword alone ends the queue (W) but, under another remote
    control (A, M, mP), is acknowledged and changes nothing."""

    def receive(self, item, now):
        if (isinstance(item, s.OMWClear) and item.waypoint is None and self.mode in ("A", "M", "mP")
                and self.phase == "none"):
            return [ack(16)]
        return super().receive(item, now)


class LockoutAfterFields(Model):
    """RH-SAF-1, RH-RD-2: in the lockout a command with bad fields gets its own "incorrect values"
    error, not 26 (the field check runs before the lockout's)."""

    def _receive_error(self, err):
        if self.phase == "lockout" and err.ack_type is not None:
            saved, self.phase = self.phase, "none"
            try:
                return super()._receive_error(err)
            finally:
                self.phase = saved
        return super()._receive_error(err)


class RefusedOmsRestartsTimeout(Model):
    """RH-SRV-4: an ``$OMS`` refused for its fields under servo control still restarts the servo
    timeout (it must be an *accepted* ``$OMS``)."""

    def _receive_error(self, err):
        out = super()._receive_error(err)
        if err.sentence_id == "OMS" and self.mode == "A" and self.timers.armed("remote") and self.now is not None:
            self.timers.arm("remote", self.now, self.timers.duration("remote"))
        return out


class OjwFractionTruncated(EmulatorCore):
    """RH-JW-1, RH-RD-9: an ``$OJW`` waypoint with a fraction (``1.5``) is read as its integer part."""

    def _line(self, raw, now, v):
        if raw.startswith(b"$OJW,") and b"*" in raw:
            f = body(raw).split(b",")
            if len(f) == 2 and re.fullmatch(rb"\d+\.\d+", f[1]):
                raw = reframe(raw, b"OJW," + f[1].split(b".")[0])
        return super()._line(raw, now, v)


class MissionTypeIgnored(Model):
    """RH-MSN-2, RH-RD-6: the rh5 ``$OMSTART`` mission type 1 starts the mission as a normal one
    (``$OSI`` field 17 stays ``False``)."""

    def receive(self, item, now):
        out = super().receive(item, now)
        if isinstance(item, s.OMSTART) and getattr(item, "mission_type", 0) == 1 and self.running:
            self.srp_active = False
        return out


class ThreeDigitChecksumRead(EmulatorCore):
    """RH-FRM-4: a checksum of three hex digits is read by its first two (it must be discarded as malformed)."""

    def _line(self, raw, now, v):
        m = re.fullmatch(rb"(\$[^*]*\*[0-9A-Fa-f]{2})[0-9A-Fa-f](\r?\n)", raw)
        if m:
            raw = m.group(1) + m.group(2)
        return super()._line(raw, now, v)


class LabelsFromRefusedOlogl(EmulatorCore):
    """RH-LOG-2: an ``$OLOGL`` refused for an empty label still sets the labels (the count an
    ``$OLOGD`` is held to): the labels must be the last *accepted* ``$OLOGL``'s."""

    def _line(self, raw, now, v):
        out = super()._line(raw, now, v)
        if raw.startswith(b"$OLOGL,") and b"*" in raw:
            f = body(raw).decode("latin-1").split(",")[1:]
            if "" in f and 1 <= len(f) <= 12:
                self.model.log_labels = tuple(f)
        return out


class AnswersTwiceAfterSilence(EmulatorCore):
    """RH-ACK-1: after 2.5 s with nothing received, the first line is processed twice (an input
    stage that wakes on a quiet line and replays what woke it): two ``$ACK`` for one command.
    (One that *loses* that line is not told apart: a lone lost answer answered on its re-run is the
    line's, as the observer's line model takes it.)"""

    last_in = None

    def _line(self, raw, now, v):
        quiet = self.last_in is not None and now - self.last_in > 2.5
        self.last_in = now
        if quiet:
            super()._line(raw, now, v)
        return super()._line(raw, now, v)


MUTANTS = (
    Mutant("oms-accepted-after-omstop", "RH-SRV-1", ("RH-SRV-1",), model=OmsAcceptedAfterStop,
           time_scales=ONE_SCALE),
    Mutant("oms-accepted-in-M-from-S", "RH-SRV-1", ("RH-SRV-1",), model=OmsAcceptedInPrimitiveFromS,
           time_scales=ONE_SCALE),
    Mutant("omload-looks-up-first", "RH-ACK-4", ("RH-ACK-4",), model=LookupBeforeState, time_scales=ONE_SCALE),
    Mutant("omload-dotdot-inside", "RH-MSN-1", ("RH-MSN-1",), core=OmloadDotDotInside, time_scales=ONE_SCALE),
    Mutant("omw-keyword-only-in-W", "RH-OMW-3", ("RH-OMW-3",), model=OmwKeywordOnlyInW, time_scales=ONE_SCALE),
    Mutant("lockout-after-fields", "RH-SAF-1", ("RH-SAF-1",), model=LockoutAfterFields, time_scales=ONE_SCALE),
    Mutant("refused-oms-restarts-timeout", "RH-SRV-4", ("RH-SRV-4",), model=RefusedOmsRestartsTimeout,
           time_scales=ONE_SCALE),
    Mutant("ojw-fraction-truncated", "RH-JW-1", ("RH-JW-1",), core=OjwFractionTruncated, time_scales=ONE_SCALE),
    Mutant("mission-type-ignored", "RH-MSN-2", ("RH-MSN-2",), model=MissionTypeIgnored, time_scales=ONE_SCALE),
    Mutant("three-digit-checksum-read", "RH-FRM-4", ("RH-FRM-4",), core=ThreeDigitChecksumRead,
           time_scales=ONE_SCALE),
    Mutant("labels-from-refused-ologl", "RH-LOG-2", ("RH-LOG-2",), core=LabelsFromRefusedOlogl, time_scales=ONE_SCALE),
    Mutant("answers-twice-after-silence", "RH-ACK-1", ("RH-ACK-1",), core=AnswersTwiceAfterSilence,
           time_scales=ONE_SCALE),
)
