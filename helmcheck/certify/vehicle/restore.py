"""Leaving the vehicle as it was found: its settings and its mode, however the run ends.

A certification changes the vehicle under test: it writes settings (``$ORWSET``: a safety rule's
state, ``SafetyAction``) and leaves missions running. A bench vehicle must not leave the lab with
a safety rule disabled, so :class:`Custodian` keeps what it found and puts it back:

* **Found.** The mode of the first ``$OSI``; the value of every setting a selected case may write
  (:func:`written_settings`), read while the vehicle is in ``S`` (``$ORWSET`` is refused while a
  mission runs, RH-SET-1) before anything is written: at once for a vehicle found stopped, else at
  the first verified reset.
* **The write interlock.** An ``$ORWSET`` write of a setting whose original value is not known is
  never sent: :meth:`Custodian.check_write` refuses it like the bench-safety interlock does (the
  step is not sent, its clause NOT-TESTED with the reason). Nothing that disables a safety rule
  goes out unless its restore is known.
* **Restore** (:meth:`Custodian.restore`, at the end of every run: pass, fail, Ctrl-C, SIGTERM,
  SIGHUP, after a link that came back): ``$OMSTOP`` until ``S`` (waiting out a lockout), every
  setting that was written put back and read again, compared with what was found. The vehicle is
  left stopped: found in ``S``, it is in ``S`` again; found running a mission, it is stopped too
  (a mission cannot be resumed where it was; the record says so).

The record (``results.json`` ``restore``, the report's "Vehicle restored" section): what was
found, each setting before and after, whether every restore was verified, and, when not, what to
set by hand. An unverified restore makes the command exit 2 (:func:`unverified_text`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Iterable, Optional

from .safety import BenchSafetyRefused
from .steps import SetRoundTrip, WithSetting

__all__ = ["Custodian", "SettingRecord", "written_settings", "unverified_text"]


def written_settings(cases: Iterable[Any]) -> list[str]:
    """The settings the steps of ``cases`` may write, in first-use order."""
    out: dict[str, None] = {}

    def walk(steps) -> None:
        for st in steps:
            if isinstance(st, (WithSetting, SetRoundTrip)):
                out.setdefault(st.setting, None)
            if isinstance(st, WithSetting):
                walk(st.steps)

    for case in cases:
        walk(case.steps)
    return list(out)


def _orwset_write(raw: bytes) -> Optional[str]:
    """The setting an ``$ORWSET,<name>,W,…`` line writes (any case of the ID), else ``None``."""
    text = raw.decode("latin-1")
    for chunk in text.split("$")[1:]:
        fields = chunk.split("*", 1)[0].rstrip("\r\n").split(",")
        if fields[0].strip().upper() == "ORWSET" and len(fields) > 2 and fields[2].strip().upper() == "W":
            return fields[1].strip()
    return None


@dataclass
class SettingRecord:
    """One setting: as found (``before``), whether the run wrote it, as left (``after``)."""

    name: str
    before: Optional[list[str]] = None
    written: bool = False
    after: Optional[list[str]] = None
    verified: bool = False

    def as_dict(self) -> dict:
        return {"name": self.name, "before": self.before, "written": self.written, "after": self.after,
                "verified": self.verified}


@dataclass
class Custodian:
    """See the module docstring."""

    names: list[str]
    records: dict = field(default_factory=dict)
    found_mode: Optional[str] = None
    found_mission: Optional[str] = None
    left_mode: Optional[str] = None
    problems: list = field(default_factory=list)
    attempted: bool = False
    touched: bool = False  #: anything but ``$OSD`` was sent: the vehicle may have changed

    def __post_init__(self) -> None:
        self.records = {n: SettingRecord(n) for n in self.names}

    # ------------------------------------------------------------------ found
    def found(self, osi: Any) -> None:
        """The first ``$OSI`` of the run: the mode the vehicle was found in and the mission its
        field 12 names (loaded in ``S``, running otherwise: the record keeps the name as reported)."""
        if self.found_mode is None and osi is not None:
            self.found_mode = osi.mode
            self.found_mission = getattr(osi, "mission_name", None) or None

    def survey(self, session: Any) -> None:
        """In ``S``: read every setting not read yet (``$ORWSET,<name>,R``) — when the profile
        claims ``$ORWSET`` (what cannot be read is never written: the interlock)."""
        if "ORWSET" not in session.profile.commands:
            return
        for rec in self.records.values():
            if rec.before is not None:
                continue
            sent = session.exchange(_frame(f"ORWSET,{rec.name},R"))
            if sent is not None and sent.accepted and len(sent.ack.extra) >= 3:
                rec.before = list(sent.ack.extra[2:])

    def check_write(self, raw: bytes) -> None:
        """The write interlock (module docstring): raises :class:`BenchSafetyRefused`."""
        if not raw.lstrip(b"\r\n").upper().startswith(b"$OSD,"):
            self.touched = True
        name = _orwset_write(raw)
        if name is None:
            return
        rec = self.records.get(name)
        if rec is None or rec.before is None:
            raise BenchSafetyRefused(f"$ORWSET writes {name}, whose value on the vehicle was not read first, "
                                     f"so it could not be restored")
        rec.written = True

    # ------------------------------------------------------------------ restore
    @property
    def needed(self) -> bool:
        """Something to put back: the run sent more than ``$OSD`` to a vehicle it saw."""
        return self.touched and (self.found_mode is not None or any(r.written for r in self.records.values()))

    def restore(self, session: Any) -> None:
        """Stop the vehicle, put every written setting back, read it again (module docstring)."""
        self.attempted = True
        session.note("restore: leaving the vehicle as it was found")
        with session.not_stopping():
            why = self._stop(session)
            if why:
                self.problems.append(f"the vehicle could not be verified as stopped: {why}")
                return
            self.left_mode = "S"
            self.survey(session)
            for rec in self.records.values():
                if not rec.written or rec.before is None:
                    continue
                rec.after = self._read(session, rec.name)
                if rec.after != rec.before:
                    session.exchange(_frame(f"ORWSET,{rec.name},W,{','.join(rec.before)}"))
                    rec.after = self._read(session, rec.name)
                rec.verified = rec.after == rec.before
                if not rec.verified:
                    self.problems.append(f"{rec.name} reads {_show(rec.after)} after the restore, not "
                                         f"{_show(rec.before)}")

    def _stop(self, session: Any) -> Optional[str]:
        """``$OMSTOP,0`` until an ``$OSI`` after it shows ``S``; why not. A refusal in the lockout
        (err 26) is waited out, and so is a vehicle that accepts the stop but goes on under remote
        control until that control times out: at most the longest remote timeout plus one and a
        half lockouts and a minute of vehicle time."""
        from .flow import CaseStop

        p = session.profile
        if "OMSTOP" not in p.commands:
            return "the profile does not claim $OMSTOP"
        end = session.now() + (p.timeout_range[1] + p.lockout_s * 1.5 + 60.0) / session.k + 5.0
        why = "no answer"
        while True:
            sent = session.exchange(_frame("OMSTOP,0"))
            if sent is not None and sent.accepted:
                t = session.now()
                try:
                    session.poll()
                except CaseStop:
                    pass  # the report itself is what counts, whatever else was wrong with the answer
                obs = session.obs
                if obs.last_osi is not None and obs.last_osi_t >= t - 1e-6 and obs.last_osi.mode == "S":
                    return None
                why = ("no $OSI came after $OMSTOP,0" if obs.last_osi is None or obs.last_osi_t < t - 1e-6
                       else f"after $OMSTOP,0 the vehicle reports {obs.last_osi.mode}")
            else:
                ack = sent.ack if sent is not None else None
                why = f"$OMSTOP,0 was answered {'nothing' if ack is None else f'$ACK,{ack.type},{ack.status},{ack.err}'}"
                if ack is None or ack.err != 26:
                    return why
            if session.now() >= end:
                return why
            session.link.sleep(max(0.1, 4 * session.poll_gap))

    def _read(self, session: Any, name: str) -> Optional[list[str]]:
        sent = session.exchange(_frame(f"ORWSET,{name},R"))
        if sent is not None and sent.accepted and len(sent.ack.extra) >= 3:
            return list(sent.ack.extra[2:])
        return None

    def could_not(self, why: str) -> None:
        """The restore could not run at all (``why``: the link is gone, …)."""
        self.attempted = True
        self.problems.append(f"the restore could not run: {why}")

    # ------------------------------------------------------------------ record
    @property
    def verified(self) -> bool:
        written = [r for r in self.records.values() if r.written]
        return not self.problems and all(r.verified for r in written)

    def record(self) -> dict:
        """The ``results.json`` ``restore`` object."""
        mode_note = None
        if self.found_mode is not None and self.found_mode != "S":
            mode_note = (f"found running ({self.found_mode}"
                         f"{', mission ' + self.found_mission if self.found_mission else ''}); left stopped "
                         f"in S: a mission cannot be resumed where it was")
        return {"found": {"mode": self.found_mode, "mission": self.found_mission},
                "left": {"mode": self.left_mode, "note": mode_note},
                "settings": [r.as_dict() for r in self.records.values()],
                "attempted": self.attempted, "verified": self.verified, "problems": list(self.problems),
                "by_hand": by_hand(self)}


def by_hand(c: Custodian) -> list[str]:
    """What an operator must set on the vehicle when the restore was not verified."""
    out = [f"$ORWSET,{r.name},W,{','.join(r.before)}" for r in c.records.values()
           if r.written and r.before is not None and not r.verified]
    if c.found_mode is not None and c.left_mode != "S":
        out.append("$OMSTOP,0 (the vehicle may still be running a test mission)")
    return out


def unverified_text(record: dict) -> str:
    """One line for the terminal when ``record`` (a ``restore`` object) was not verified."""
    steps = "; ".join(record.get("by_hand") or []) or "check the vehicle's settings by hand"
    why = "; ".join(record.get("problems") or [])
    return f"the vehicle was NOT verified as restored ({why}); set by hand: {steps}"


def _show(values: Optional[list[str]]) -> str:
    return ",".join(values) if values is not None else "nothing (no answer)"


def _frame(body: str) -> bytes:
    from .session import frame
    return frame(body)
