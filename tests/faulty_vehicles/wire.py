"""Faulty vehicles for §1–3 and §6: framing, acknowledgements, output sentences, read/write
commands (RH-FRM-*, RH-ACK-*, RH-OUT-*, RH-POS-*, RH-OSD-*, RH-LOG-*, RH-SET-*, RH-DVL-*)."""

from __future__ import annotations

from helmcheck.conformance.emulator.core import EmulatorCore
from helmcheck.grammar import sentences as s

from .base import Model, Mutant, body, reframe

__all__ = ["MUTANTS"]


class AcceptsBadChecksum(EmulatorCore):
    """RH-FRM-2: acts on a line whose checksum is wrong."""

    def _line(self, raw, now, v):
        if b"*" in raw and raw.startswith(b"$"):
            raw = reframe(raw, body(raw))
        return super()._line(raw, now, v)


class LowercaseOut(EmulatorCore):
    """RH-FRM-3: writes its checksums in lower-case hex."""

    def _send(self, raw, now):
        return super()._send(reframe(raw, body(raw), lower=True), now)


class NoAckForOsd(EmulatorCore):
    """RH-ACK-1: sends the data of an $OSD but never its $ACK,8."""

    def _send(self, raw, now):
        if raw.startswith(b"$ACK,8,"):
            return None
        return super()._send(raw, now)


class AckBeforeData(EmulatorCore):
    """RH-ACK-5: answers $OSD with the $ACK first, then the data."""

    def _command(self, item, now, v):
        if isinstance(item, s.OSD):
            sent = []
            real = self._send
            self._send = lambda raw, now: sent.append(raw)  # type: ignore[assignment]
            try:
                super()._command(item, now, v)
            finally:
                del self._send
            acks = [r for r in sent if r.startswith(b"$ACK")]
            for r in acks + [r for r in sent if not r.startswith(b"$ACK")]:
                real(r, now)
            return
        super()._command(item, now, v)


class Mp(EmulatorCore):
    """RH-OUT-1: spells the manual-park mode ``Mp`` in its $OSI."""

    def _send(self, raw, now):
        if raw.startswith(b"$OSI,") and b",mP," in raw:
            raw = reframe(raw, body(raw).replace(b",mP,", b",Mp,"))
        return super()._send(raw, now)


# ============================================================================ model mutants

class SettingNotStored(Model):
    """RH-SET-2: an $ORWSET write is acknowledged but not stored."""

    def receive(self, item, now):
        if isinstance(item, s.ORWSET) and item.access == "W":
            before = self.settings.copy()
            out = super().receive(item, now)
            self.settings = before
            return out
        return super().receive(item, now)


class WrongErrNumber(Model):
    """RH-ACK-3: $OMS with bad fields is rejected with 21 instead of its own 20."""

    def receive(self, item, now):
        return [s.ACK(9, 1, 21) if isinstance(r, s.ACK) and (r.type, r.err) == (9, 20) else r
                for r in super().receive(item, now)]

    def _receive_error(self, err):
        return [s.ACK(9, 1, 21) if isinstance(r, s.ACK) and (r.type, r.err) == (9, 20) else r
                for r in super()._receive_error(err)]


MUTANTS = (
    Mutant("accepts-bad-checksum", "RH-FRM-2", ("RH-FRM-2",), core=AcceptsBadChecksum),
    Mutant("lowercase-checksum-out", "RH-FRM-3", ("RH-FRM-3",), core=LowercaseOut),
    Mutant("rejects-lowercase-checksum-in", "RH-FRM-3", ("RH-FRM-3",),
           profile_changes=(("lowercase_checksum_in", False),)),
    Mutant("no-ack-for-osd", "RH-ACK-1", ("RH-ACK-1",), core=NoAckForOsd),
    Mutant("ack-before-data", "RH-ACK-5", ("RH-ACK-5",), core=AckBeforeData),
    Mutant("spells-mP-as-Mp", "RH-OUT-1", ("RH-OUT-1", "RH-PK-1"), core=Mp),
    Mutant("orwset-write-not-stored", "RH-SET-2", ("RH-SET-2",), model=SettingNotStored),
    Mutant("wrong-err-number", "RH-ACK-3", ("RH-ACK-3",), model=WrongErrNumber),
)
