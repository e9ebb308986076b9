"""``--resume DIR``: an interrupted certification goes on from its last completed case.

A bench session at time scale 1 lasts half an hour; an interruption (Ctrl-C, a lost link, a
flat battery) should not send it back to the start. :func:`resume_into` prepares a
:class:`~.runner.Run` to continue the run recorded in its report directory:

* the record is the truth: ``DIR/wire.log`` is read by the one wire-log reader
  (:func:`helmcheck.grammar.wirelog.read_records`) and replayed through the run's (fresh)
  vehicle observer, so the ledger holds exactly the verdicts the first part earned — the same
  way an offline ``check-log`` or ``verify`` reads it;
* the wire log is appended to, after a ``run resumed`` note (the observer takes the vehicle's
  state as unknown again, and does not judge commands the interruption cut off), with the record's
  time going on a second after its last record;
* the cases already completed are not run again; a case the interruption (or a lost link) cut
  off runs again from its start; exploration runs if the first part had not finished it;
* what the vehicle was found in (the settings' original values, :mod:`.restore`) is taken from
  the first part, whose own restore may already have put them back; a setting it wrote and could
  not put back (its port vanished, :mod:`.rejoin`) is put back at the end of this part.

The run's profile, selection, time scale, seed and the like are the first part's (the command
line checks that nothing contradicts them, :mod:`.cli`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

from ...grammar.wirelog import read_records
from ...reports import results as R

__all__ = ["Resumed", "resume_into"]


@dataclass
class Resumed:
    """What the first part left: its completed cases, where its record ends, its wall time."""

    done_ids: set = field(default_factory=set)
    lines: int = 0
    last_t: float = 0.0
    wall_s: float = 0.0
    explored: bool = False

    @property
    def done(self) -> int:
        return len(self.done_ids)


def resume_into(run: Any) -> Resumed:
    """Load ``run.dir``'s record into ``run`` (module docstring); the :class:`Resumed` facts."""
    prior = R.load_results(run.dir)
    cases = [c for c in prior.get("cases", []) if not c.get("cut")]
    stats = dict(prior.get("stats") or {})
    out = Resumed(done_ids={c["id"] for c in cases}, wall_s=float(stats.pop("wall_s", 0.0) or 0.0),
                  explored="explore" in stats)
    r = prior
    r["cases"] = cases
    r["partial"] = True
    r.pop("resume_command", None)  # this is that command
    settings = r.setdefault("settings", {})
    settings.setdefault("resumed", []).append(
        {"at": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()), "completed_cases": len(cases),
         "command": run.o.command})
    run.results = r
    run.stats = stats
    wire = run.dir / R.WIRE_LOG_NAME
    with open(wire, "rb") as f:
        for rec in read_records(f):
            run.observer.feed(rec)
            out.last_t = max(out.last_t, rec.t)
    with open(wire, "rb") as f:
        out.lines = sum(1 for _ in f)
    restore = prior.get("restore") or {}
    for st in restore.get("settings") or ():
        rec = run.custodian.records.get(st.get("name"))
        if rec is not None and st.get("before") is not None:
            rec.before = list(st["before"])
            # written and not verified as put back (a port that vanished before the restore):
            # this part puts it back at its end, whether it writes it again or not
            rec.written = bool(st.get("written")) and not st.get("verified")
    found = restore.get("found") or {}
    if found.get("mode"):
        run.custodian.found_mode, run.custodian.found_mission = found["mode"], found.get("mission")
    return out
