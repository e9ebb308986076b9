"""The backseat under test when helmcheck starts it (``certify backseat --exec CMD``).

Three steps around the run, each a small function so the command and the loop only call them:

* :func:`start_backseat` — once the port is open (after the ``port:`` line), start the command
  on it (:class:`~helmcheck.line.launcher.Launcher`: ``{port}`` is the pty path or
  ``socket://HOST:PORT``; output into ``backseat.stdout.log`` / ``backseat.stderr.log``).
* :func:`end_backseat` — when the run is over, before its record closes
  (:class:`~.runner.Runner`): let an exit that closed the port become visible (up to 1 s), stop
  it (SIGTERM to its process group, SIGKILL after the grace period) and return the ``process``
  object for ``results.json``. It *ended early* when it was seen ended before helmcheck began to
  stop it.
* :func:`process_notes` — the run facts of that end, as wire-log notes
  (:mod:`helmcheck.judge.runfacts`): a ``not judged`` note for every clause whose exercising
  scenarios (:data:`EXERCISED_BY`) had not all finished when it ended early, with the exit as
  the reason, then the ``process:`` note. A backseat that ended early is a finding about the
  backseat, never a link fault: :func:`helmcheck.reports.assemble.assemble` makes the run
  verdict FAIL (:func:`helmcheck.reports.verdicts.run_verdict`), the clauses with an offence
  keep their verdict, the clauses not judged are NOT-TESTED. Nothing rewrites a verdict after
  the ledger: ``helmcheck verify`` reads the same notes.

Decision (§9 is silent on which scenario judges what; every clause is judged all the time):
:data:`EXERCISED_BY` follows :mod:`.scenarios` — ``nominal`` exercises every clause,
``reject`` and ``lockout`` RH-BS-5, ``mission-end`` RH-BS-3, ``silence`` RH-BS-4 and RH-BS-8.
A clause none of whose exercising scenarios was planned needs the whole plan to finish.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Iterable, Optional

from ...judge.runfacts import not_judged_note, process_note
from ...line.launcher import Launcher
from ...line.transport import parse_port_spec
from .scenarios import Plan

__all__ = ["EXERCISED_BY", "start_backseat", "end_backseat", "process_notes", "unfinished_clauses"]

EXERCISED_BY: dict[str, tuple[str, ...]] = {
    "RH-BS-1": ("nominal",),
    "RH-BS-2": ("nominal",),
    "RH-BS-3": ("nominal", "mission-end"),
    "RH-BS-4": ("nominal", "silence"),
    "RH-BS-5": ("nominal", "reject", "lockout"),
    "RH-BS-6": ("nominal",),
    "RH-BS-7": ("nominal",),
    "RH-BS-8": ("nominal", "silence"),
}

_SETTLE_S = 1.0


def start_backseat(command: str, port_name: str, directory: Path, *, time_scale: float,
                   grace_s: float) -> Launcher:
    """Start *command* on the open port *port_name*; ``OSError`` if it cannot be started."""
    child = Launcher(command, subject="backseat", directory=directory, grace_s=grace_s)
    host = tcp_port = ""
    try:
        spec = parse_port_spec(port_name)
        if spec.kind == "socket":
            host, tcp_port = spec.host, str(spec.port)
    except ValueError:
        pass
    child.start(port_name, host=host, tcp_port=tcp_port, time_scale=time_scale)
    return child


def end_backseat(child: Launcher, *, epoch: float, link_lost: bool) -> dict[str, Any]:
    """Stop the backseat at the run's end; its ``process`` object (times since *epoch*)."""
    if link_lost and not child.ended:
        child.wait(_SETTLE_S)  # the port closes before the exit is reaped
    child.stop()
    return child.record(epoch=epoch)


def unfinished_clauses(clauses: Iterable[str], plan: Plan, connected_at: Optional[float],
                       ended_at: float, finished: Optional[Iterable[str]] = None) -> dict[str, list[str]]:
    """Clause ID → the exercising scenarios that had not finished by *ended_at*, for every clause
    of *clauses* that has some (times in seconds since the certifier started; *finished*: the
    scenarios the run saw end, when it knows — a scenario held open past its plan ends later)."""
    planned = [slot.name for slot in plan.slots]
    if finished is not None:
        done = set(finished)
    else:
        done = {slot.name for slot in plan.slots
                if connected_at is not None and connected_at + slot.end <= ended_at + 1e-9}
    out: dict[str, list[str]] = {}
    for cid in clauses:
        need = [n for n in EXERCISED_BY.get(cid, ()) if n in planned] or planned
        missing = [n for n in need if n not in done]
        if missing:
            out[cid] = missing
    return out


def process_notes(process: dict[str, Any], *, clauses: Iterable[str], plan: Plan,
                  connected_at: Optional[float], ended_at: float,
                  finished: Optional[Iterable[str]] = None) -> list[str]:
    """The run-fact notes of the backseat's end (module docstring), in the order to record them."""
    notes: list[str] = []
    if process.get("ended_early"):
        how = (f"was killed by {process['signal']}" if process.get("signal")
               else f"exited with code {process.get('exit_code')}")
        at = process.get("ended_at_s")
        when = f" at {at:.1f} s" if at is not None else ""
        groups: dict[str, list[str]] = {}
        for cid, scenarios in unfinished_clauses(clauses, plan, connected_at, ended_at, finished).items():
            reason = (f"the backseat {how}{when}, before the scenario(s) exercising this clause "
                      f"({', '.join(scenarios)}) finished")
            groups.setdefault(reason, []).append(cid)
        notes += [not_judged_note(ids, reason) for reason, ids in groups.items()]
    notes.append(process_note(process))
    return notes
