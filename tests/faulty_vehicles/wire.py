"""Faulty vehicles for §1–3 and §6: framing, acknowledgements, output sentences, read/write
commands (RH-FRM-*, RH-ACK-*, RH-OUT-*, RH-POS-*, RH-OSD-*, RH-LOG-*, RH-SET-*, RH-DVL-*)."""

from __future__ import annotations

from dataclasses import replace
from decimal import Decimal

from helmcheck.emulator.core import EmulatorCore
from helmcheck.grammar import Discard, Line, decode, format as format_sentence
from helmcheck.grammar import sentences as s
from helmcheck.model.vehicle import VehicleModel

from .base import Model, Mutant, body, reframe

__all__ = ["MUTANTS", "BAD_FIELD_SELECT"]

#: What a vehicle with one bad ``$OSI`` field is certified on: its field's clause, and clauses
#: judged from what the reports show (the mode, the fins and motor, the position), a setting
#: written (the restore puts it back), and the lockout (polled through).
BAD_FIELD_SELECT = ("RH-OUT-3", "RH-OUT-1", "RH-OUT-4", "RH-SRV-3", "RH-PRM-3", "RH-MSN-3", "RH-SET-2", "RH-POS-2",
                    "RH-SAF-1")


class AcceptsBadChecksum(EmulatorCore):
    """RH-FRM-4: acts on a line whose checksum is wrong (it must be discarded)."""

    def _line(self, raw, now, v):
        if b"*" in raw and raw.startswith(b"$"):
            raw = reframe(raw, body(raw))
        return super()._line(raw, now, v)


class UnpaddedChecksumOut(EmulatorCore):
    """RH-FRM-2: writes a checksum under 0x10 as one hex digit (``%X``, not zero-padded)."""

    def _send(self, raw, now):
        star = raw.rfind(b"*")
        if raw.startswith(b"$") and star > 0 and raw[star + 1:star + 2] == b"0":
            raw = raw[:star + 1] + raw[star + 2:]
        return super()._send(raw, now)


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


class BareLfOut(EmulatorCore):
    """RH-FRM-1: ends its sentences with a bare LF (a Unix ``\\n`` line ending), not CR LF."""

    def _send(self, raw, now):
        return super()._send(raw[:-2] + b"\n", now)


class ChecksumOptional(EmulatorCore):
    """RH-FRM-4: treats the checksum as optional: a line without ``*hh`` is acted on."""

    def _line(self, raw, now, v):
        if raw.startswith(b"$") and b"*" not in raw:
            raw = reframe(raw, raw[1:].rstrip(b"\r\n"))
        return super()._line(raw, now, v)


class IdAnyCase(EmulatorCore):
    """RH-FRM-5: matches sentence IDs without regard to case, so ``$omstop`` is acted on."""

    def _line(self, raw, now, v):
        if raw.startswith(b"$") and b"*" in raw:
            head, sep, rest = body(raw).partition(b",")
            if head.upper() != head:
                raw = reframe(raw, head.upper() + sep + rest)
        return super()._line(raw, now, v)


class _LfFramer:
    """A framer that cuts lines at LF only and reads each from its first ``$``."""

    def __init__(self):
        self.buf = b""
        self.pending = 0

    def feed(self, data):
        self.buf += data
        out = []
        while b"\n" in self.buf:
            line, self.buf = self.buf.split(b"\n", 1)
            line += b"\n"
            i = line.find(b"$")
            if i < 0:
                out.append(Discard(line, 0, len(line), "RH-FRM-7", "no '$'"))
                continue
            if i:
                out.append(Discard(line[:i], 0, i, "RH-FRM-7", "bytes before '$'"))
            out.append(Line(line[i:], 0))
        self.pending = len(self.buf)
        return out

    def close(self):
        self.buf, self.pending = b"", 0
        return []


class NoResyncOnDollar(EmulatorCore):
    """RH-FRM-7: reads a line up to LF from its first ``$``; a ``$`` inside a line does not
    start a new sentence, so the sentence after a torn one is lost."""

    def __init__(self, *a, **kw):
        super().__init__(*a, **kw)
        self.framer = _LfFramer()


class CompassWithCommas(EmulatorCore):
    """RH-FRM-8: writes ``$C`` through the comma-separated writer: ``$C90.0,P0.00,R0.00,…``."""

    def _send(self, raw, now):
        if raw[:2] == b"$C" and raw[2:3] in b"-0123456789":
            b = body(raw)
            for letter in (b"P", b"R", b"T", b"D"):
                b = b.replace(letter, b"," + letter, 1)
            raw = reframe(raw, b)
        return super()._send(raw, now)


def _even_parity(byte: int) -> int:
    return byte | (0x80 if bin(byte & 0x7F).count("1") % 2 else 0)


class SevenE1(EmulatorCore):
    """RH-FRM-9: its UART is set to 7E1: each byte it sends carries even parity in bit 7 (as an
    8N1 receiver reads it); parity errors on input are ignored."""

    def _release(self, now):
        return bytes(_even_parity(c) for c in super()._release(now))


class SlowOposAck(EmulatorCore):
    """RH-ACK-2: writes each $OPOS fix to its log synchronously before acknowledging it; the
    write takes 3.5 s (the ACK window is 1 s) and holds up all its output."""

    stall_until = 0.0

    def _send(self, raw, now):
        if raw.startswith(b"$ACK,6,"):
            self.stall_until = now + 3.5
        return super()._send(raw, now)

    def _release(self, now):
        return b"" if now < self.stall_until else super()._release(now)

    def next_wakeup(self):
        w = super().next_wakeup()
        return max(w, self.stall_until) if w is not None and self._out else w


class OposAckNextCycle(EmulatorCore):
    """RH-ACK-6: acknowledges an $OPOS at the navigation filter's next cycle (100 ms), after the
    commands that came behind it."""

    def __init__(self, *a, **kw):
        super().__init__(*a, **kw)
        self.held = []  #: (wall time due, the $ACK,6)

    def _send(self, raw, now):
        if raw.startswith(b"$ACK,6,"):
            self.held.append((now + 0.1, raw))
            return None
        return super()._send(raw, now)

    def _release(self, now):
        while self.held and self.held[0][0] <= now:
            super()._send(self.held.pop(0)[1], now)
        return super()._release(now)

    def next_wakeup(self):
        w = super().next_wakeup()
        if self.held:
            w = self.held[0][0] if w is None else min(w, self.held[0][0])
        return w


class OsdStreamsThenRefuses(EmulatorCore):
    """RH-OSD-2: streams the data of the letters before an unknown one, then refuses the $OSD."""

    def _line(self, raw, now, v):
        if raw.startswith(b"$OSD,") and b"*" in raw:
            d = decode(raw, self.profile)
            if d.error is not None and d.error.answered:
                for f in body(raw).split(b",")[1:]:
                    x = f.decode("latin-1")
                    if not x:
                        continue
                    if len(x) != 1 or x not in "GCSPYDTI":
                        break
                    if x in self.profile.osd_letters:
                        self._send(format_sentence(self.model.data(x, v)), now)
        return super()._line(raw, now, v)


class OpiWithoutLeak(EmulatorCore):
    """RH-OUT-2: writes $OPI without its last field, the leak flag (seven fields, not eight)."""

    def _send(self, raw, now):
        if raw.startswith(b"$OPI,"):
            raw = reframe(raw, body(raw).rsplit(b",", 1)[0])
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


class NotRunningErr45(Model):
    """RH-ACK-4: refuses $OMS, $OJW, $OPK, $OMW without a mission with err 45 ("must be
    running") instead of the command's own incorrect-values error."""

    def receive(self, item, now):
        row = self.row_for(item) if isinstance(item, s.Command) else None
        out = super().receive(item, now)
        if (row is not None and row.error not in (None, 26) and not self.running
                and item.ID in ("OMS", "OJW", "OPK", "OMW")):
            out = [s.ACK(r.type, 1, 45) if isinstance(r, s.ACK) and r.status else r for r in out]
        return out


class MagneticUnwrapped(Model):
    """RH-OUT-3: the $C magnetic heading is true heading minus declination, never wrapped into
    [0, 360): heading north with a west declination it reads over 360."""

    def data(self, letter, now=None):
        out = super().data(letter, now)
        if letter == "C":
            p = self.snapshot
            true = (p.heading + p.declination) % 360.0
            out = replace(out, heading=Decimal(f"{true - p.declination:.1f}"))
        return out


class TrueHeadingNegative(Model):
    """RH-OUT-3: $OSI field 14, the true heading, is -0.1 (just below its range [0, 360)) in every
    report; every other field is right."""

    def osi(self, now=None):
        return replace(super().osi(now), true_heading=Decimal("-0.1"))


class BatteryOver100(Model):
    """RH-OUT-3: $OSI field 16, the battery percent, is 100.1 (just above its range [0, 100]) in
    every report; every other field is right."""

    def osi(self, now=None):
        return replace(super().osi(now), battery="100.1")


class WaypointOneBased(Model):
    """RH-OUT-4: $OSI field 3 is the waypoint index plus one (1-based), so it shows 1 in S."""

    def osi(self, now=None):
        o = super().osi(now)
        return replace(o, next_waypoint=o.next_waypoint + 1)


class OposSixthFieldRefused(Model):
    """RH-POS-1: refuses an $OPOS with a sixth, empty field (18) instead of tolerating it."""

    def receive(self, item, now):
        if isinstance(item, s.OPOS) and item.trailing_empty and self.phase != "lockout":
            return [s.ACK(6, 1, 18)]
        return super().receive(item, now)


class OposIgnoresFix(Model):
    """RH-POS-2: applies the $OPOS position even while it has a GPS fix."""

    _opos = False

    @property
    def gps_fix(self):
        return not self._opos and VehicleModel.gps_fix.fget(self)

    def receive(self, item, now):
        self._opos = isinstance(item, s.OPOS)
        try:
            return super().receive(item, now)
        finally:
            self._opos = False


class OsdFixedOrder(Model):
    """RH-OSD-1: answers $OSD in its own fixed order (GCSPYDTI), each letter once, not in the
    order requested."""

    def receive(self, item, now):
        out = super().receive(item, now)
        if isinstance(item, s.OSD) and out and out[-1].status == 0:
            want = set(item.requested) & self._letters
            out = [self.data(x, now) for x in "GCSPYDTI" if x in want] + [out[-1]]
        return out


class OlogLDuringMission(Model):
    """RH-LOG-1: accepts $OLOGL while a mission runs (labels may change at any time)."""

    def receive(self, item, now):
        if isinstance(item, s.OLOGL) and self.running and self.phase == "none":
            self.log_labels = tuple(item.labels)
            return [s.ACK(5, 0, 0)]
        return super().receive(item, now)


class OlogDExtraDropped(Model):
    """RH-LOG-2: accepts an $OLOGD with more values than labels, dropping the extra ones."""

    def receive(self, item, now):
        if isinstance(item, s.OLOGD) and self.log_labels and len(item.values) > len(self.log_labels):
            item = s.OLOGD(values=item.values[:len(self.log_labels)])
        return super().receive(item, now)


class OrwsetReadDuringMission(Model):
    """RH-SET-1: answers an $ORWSET read while a mission runs (reads look harmless)."""

    def receive(self, item, now):
        if (isinstance(item, s.ORWSET) and item.access == "R" and item.state is None and self.running
                and self.phase == "none" and item.setting in self.settings.as_dict()):
            return [s.ACK(12, 0, 0, self.settings.reply_extra(item.setting))]
        return super().receive(item, now)


class OrwsetCountsValuesOnly(Model):
    """RH-SET-1: the $ORWSET reply's n counts the values only, not the state before them."""

    def receive(self, item, now):
        out = super().receive(item, now)
        return [replace(r, extra=(r.extra[0], str(int(r.extra[1]) - 1), *r.extra[2:]))
                if isinstance(r, s.ACK) and r.type == 12 and len(r.extra) >= 2 else r for r in out]


MUTANTS = (
    Mutant("accepts-bad-checksum", "RH-FRM-4", ("RH-FRM-4",), core=AcceptsBadChecksum),
    Mutant("unpadded-checksum-out", "RH-FRM-2", ("RH-FRM-2",), core=UnpaddedChecksumOut),
    Mutant("lowercase-checksum-out", "RH-FRM-3", ("RH-FRM-3",), core=LowercaseOut),
    Mutant("rejects-lowercase-checksum-in", "RH-FRM-3", ("RH-FRM-3",),
           profile_changes=(("lowercase_checksum_in", False),)),
    Mutant("no-ack-for-osd", "RH-ACK-1", ("RH-ACK-1",), core=NoAckForOsd),
    Mutant("ack-before-data", "RH-ACK-5", ("RH-ACK-5",), core=AckBeforeData),
    Mutant("spells-mP-as-Mp", "RH-OUT-1", ("RH-OUT-1", "RH-PK-1"), core=Mp),
    Mutant("orwset-write-not-stored", "RH-SET-2", ("RH-SET-2",), model=SettingNotStored),
    Mutant("wrong-err-number", "RH-ACK-3", ("RH-ACK-3",), model=WrongErrNumber),
    Mutant("bare-lf-out", "RH-FRM-1", ("RH-FRM-1",), core=BareLfOut),
    Mutant("checksum-optional", "RH-FRM-4", ("RH-FRM-4",), core=ChecksumOptional),
    Mutant("id-any-case", "RH-FRM-5", ("RH-FRM-5",), core=IdAnyCase),
    # RH-FRM-6: reads lines into a 512-byte buffer, so a 257-byte line is acted on
    Mutant("line-limit-512", "RH-FRM-6", ("RH-FRM-6",), profile_changes=(("max_line_bytes", 512),)),
    Mutant("no-resync-on-dollar", "RH-FRM-7", ("RH-FRM-7",), core=NoResyncOnDollar),
    Mutant("compass-with-commas", "RH-FRM-8", ("RH-FRM-8",), core=CompassWithCommas),
    Mutant("uart-7e1", "RH-FRM-9", ("RH-FRM-9",), core=SevenE1),
    Mutant("slow-opos-ack", "RH-ACK-2", ("RH-ACK-2",), core=SlowOposAck),
    Mutant("not-running-err-45", "RH-ACK-4", ("RH-ACK-4",), model=NotRunningErr45),
    Mutant("opos-ack-next-cycle", "RH-ACK-6", ("RH-ACK-6",), core=OposAckNextCycle),
    Mutant("opi-without-leak", "RH-OUT-2", ("RH-OUT-2",), core=OpiWithoutLeak),
    Mutant("magnetic-heading-unwrapped", "RH-OUT-3", ("RH-OUT-3",), model=MagneticUnwrapped),
    # one bad field in every report blinds the tester to nothing else (judge.vehicle.lines)
    Mutant("osi-true-heading-negative", "RH-OUT-3", BAD_FIELD_SELECT, model=TrueHeadingNegative, only=True,
           blinds_nothing=True),
    Mutant("osi-battery-over-100", "RH-OUT-3", BAD_FIELD_SELECT, model=BatteryOver100, only=True, blinds_nothing=True),
    Mutant("waypoint-one-based", "RH-OUT-4", ("RH-OUT-4",), model=WaypointOneBased),
    Mutant("opos-sixth-field-refused", "RH-POS-1", ("RH-POS-1",), model=OposSixthFieldRefused),
    Mutant("opos-ignores-gps-fix", "RH-POS-2", ("RH-POS-2",), model=OposIgnoresFix),
    Mutant("osd-fixed-order", "RH-OSD-1", ("RH-OSD-1",), model=OsdFixedOrder),
    Mutant("osd-streams-then-refuses", "RH-OSD-2", ("RH-OSD-2",), core=OsdStreamsThenRefuses),
    Mutant("ologl-during-mission", "RH-LOG-1", ("RH-LOG-1",), model=OlogLDuringMission),
    Mutant("ologd-extra-dropped", "RH-LOG-2", ("RH-LOG-2",), model=OlogDExtraDropped),
    Mutant("orwset-read-during-mission", "RH-SET-1", ("RH-SET-1",), model=OrwsetReadDuringMission),
    Mutant("orwset-counts-values-only", "RH-SET-1", ("RH-SET-1",), model=OrwsetCountsValuesOnly),
    # RH-DVL-1: takes a timeout of 0 (as "no timeout") instead of refusing it (35)
    Mutant("odvl-timeout-zero", "RH-DVL-1", ("RH-DVL-1",), profile_changes=(("timeout_range", (0, 120)),)),
)
