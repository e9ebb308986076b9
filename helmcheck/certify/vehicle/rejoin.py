"""The vehicle's port vanished mid-run: wait for it under the same name, record the gap, go on.

When the device goes away — EIO from a serial adapter pulled out or a pty closed, a TCP serial
server's connection dropped: the link's ``link lost`` note (:mod:`.link`) — :func:`rejoin`:

* waits for the port to come back under the name the run opened
  (:func:`helmcheck.line.reopen.wait_for_port`), for at most ``Options.reconnect_wait_s``
  (``--reconnect-wait``; :data:`~helmcheck.line.reopen.DEFAULT_WAIT_S` by default), saying so on
  the terminal and in a ``link gap:`` note;
* records the gap as the judges know it: a ``run resumed:`` note (:mod:`helmcheck.judge.wire`),
  the note ``--resume`` writes after an interruption. The vehicle observer then takes the
  vehicle's state as unknown (from the next report that shows it whole), and does not judge a
  command the gap cut off (a remark on RH-ACK-1 naming the gap, never a verdict); ``check-log`` and ``helmcheck
  verify`` read the same note, so the record alone gives the same verdicts. Then ``link
  reopened: …`` at the time the port was back: the gap's time is in the record as time nobody
  saw;
* re-verifies the vehicle's state with the verified reset (:meth:`.session.Session.reset`:
  ``$OMSTOP,0`` until an ``$OSI`` shows ``S``, the settings a case may write read again), and
  the caller runs the case the gap cut from its start (:meth:`.runner.Run.run_cases`) — or the
  link check (the probe, the line's measurement, the clock check), or the exploration.

Every gap is in ``results.json`` ``link_gaps`` (when, how long, which port, why, what it cut, and
whether the port came back) and the wait allowed in ``settings.reconnect_wait_s``.

Not back in time: :func:`rejoin` returns False with the run marked partial, its reason naming
the port, the wait and what ``--resume DIR`` goes on from, and the command that does it in
``results.json`` ``resume_command`` (``Options.resume_command``; the command line prints it on
a line of its own, ``resume: …``). The record and
``results.json`` already hold everything up to the cut: every record is flushed as it is
written, and ``results.json`` is saved (atomically) before the wait.

Decisions (the reference profile is silent on the tester's link):

* The ``run resumed`` note is stamped with the time of the ``link lost`` note, not the time the
  port came back (nor is the ``link gap`` note of a port that did not come back): the judge must
  not let the gap's time pass over a command still waiting for its ``$ACK`` — it would be judged
  late (RH-ACK-2) for an answer the cut lost. The note's text gives both times, and the records
  after it carry the real ones.
* The vehicle helmcheck started (``--exec``) is not waited for: its port going away is its
  process ending (a finding, :mod:`.exec_child`), or the run's own pty. ``pty``, ``/dev/pts/N``
  and ``loop://`` name nothing that can come back (:func:`helmcheck.line.reopen.reopenable`); nor
  is a port waited for with a wait of 0. Either way the run stops at once, as one whose port did
  not come back (the ``--resume`` command included).
* After :data:`MAX_CUTS` gaps in a row have cut the same case (or the link check, or the
  exploration), one more stops the run as if the port had not come back: a line that drops out
  that often is not one to certify over.
"""

from __future__ import annotations

from typing import Any

from ...line.reopen import reopenable, wait_for_port
from .flow import CaseStop, LinkLost, LinkSilent

__all__ = ["MAX_CUTS", "rejoin", "can_rejoin", "vanished"]

#: Gaps in a row that may cut the same case (or the link check, or the exploration) and be waited
#: for; one more stops the run.
MAX_CUTS = 3


def vanished(run: Any, err: BaseException) -> bool:
    """Whether ``err`` is the run's port gone (EIO, closed, dropped), not the vehicle helmcheck
    started ending (:mod:`.exec_child`) nor a vehicle that stopped answering (``LinkSilent``)."""
    link = run.link
    return (isinstance(err, LinkLost) and not isinstance(err, LinkSilent) and link is not None
            and link.lost is not None and run.session is not None and not run.o.exec_cmd)


def can_rejoin(run: Any, err: BaseException) -> bool:
    """Whether ``err`` is a vanished port the run may wait for (module docstring)."""
    return vanished(run, err) and run.o.reconnect_wait_s > 0 and reopenable(run.o.port)


def rejoin(run: Any, err: LinkLost, what: str, cuts: int = 1) -> bool:
    """The link of ``run`` was lost during ``what`` (``"case V-12"``, ``"the link check"``, ``"the
    exploration"``): wait for the port, record the gap, verify the vehicle's state (module
    docstring). True when the run can run ``what`` again; False when it cannot (the run is then
    partial, its reason saying how to go on). ``cuts``: the gaps in a row that cut ``what``."""
    if not vanished(run, err):
        return False
    link, rec, port = run.link, run.recorder, run.o.port
    wait_s = float(run.o.reconnect_wait_s)
    while True:
        lost_t = link.lost_t if link.lost_t is not None else rec.last_t
        why = link.lost
        gap = {"lost_at_s": round(lost_t, 6), "back_at_s": None, "gap_s": None, "port": port, "why": why,
               "cut": what}
        run.results.setdefault("link_gaps", []).append(gap)
        run.save()  # everything up to the cut, atomically, before the wait
        if cuts > MAX_CUTS:
            return _gone(run, gap, lost_t, f"came back, but {what} was cut by {cuts} gaps in a row: the line is "
                                           f"not stable enough to certify over")
        if not can_rejoin(run, err):
            return _gone(run, gap, lost_t, "was not waited for" + (" (--reconnect-wait 0)" if wait_s <= 0 else
                                                                   f": {port} names nothing that can come back"))
        rec.note(lost_t, f"link gap: waiting up to {wait_s:g} s for {port} to come back (--reconnect-wait)")
        run.progress.note(f"link lost ({why}) during {what}; waiting up to {wait_s:g} s for {port} to come back")
        raw, last = wait_for_port(port, baud=run.p.baud, within_s=wait_s)
        if raw is None:
            return _gone(run, gap, lost_t, f"did not come back within {wait_s:g} s (--reconnect-wait; last: {last})")
        back_t = link.now()
        gap.update(back_at_s=round(back_t, 6), gap_s=round(back_t - lost_t, 6))
        rec.note(lost_t, f"run resumed: the link came back after a gap of {back_t - lost_t:.2f} s ({port} was "
                         f"gone from {lost_t:.3f} s to {back_t:.3f} s: {why}); what crossed the line meanwhile "
                         f"was not seen: the vehicle's state is verified again and {what} starts again")
        link.reattach(raw, f"link reopened: {port} is back after {back_t - lost_t:.2f} s")
        ser = getattr(raw, "ser", None)
        try:
            if ser is not None:
                ser.reset_input_buffer()  # what a half-plugged adapter read is nobody's
        except Exception:  # noqa: BLE001
            pass
        run.progress.note(f"{port} is back after {back_t - lost_t:.1f} s; verifying the vehicle's state, "
                          f"then {what} starts again")
        try:
            _verify(run)
        except LinkLost as e:  # gone again during the reset: another gap
            if not vanished(run, e):
                raise
            err, cuts = e, cuts + 1
            continue
        run.save()
        return True


def _verify(run: Any) -> None:
    """The verified reset after a gap: the vehicle stopped (``S`` seen), the settings read. A
    vehicle that cannot be verified is noted; the case run next starts with its own reset, which
    says what it needs (``LinkSilent`` when nothing answers: the run stops, a link fault)."""
    ses = run.session
    case, clauses = ses.case, ses.case_clauses
    ses.case, ses.case_clauses = "", ()
    try:
        with ses.not_stopping():
            ses.reset(mission=False)
    except CaseStop as e:
        ses.note(f"after the link gap the vehicle's state could not be verified: {e.reason}")
    finally:
        ses.case, ses.case_clauses = case, clauses


def _gone(run: Any, gap: dict, lost_t: float, how: str) -> bool:
    """The port did not come back: the run stops, partial, saying how to go on."""
    port = run.o.port
    gap["back_at_s"] = None
    run.recorder.note(lost_t, f"link gap: {port} {how}")
    cmd = run.o.resume_command or _default_resume(run)
    run.gone = f"{port} was gone from {lost_t:.1f} s and {how}"
    run.resume_command = run.results["resume_command"] = cmd
    run.partial = True
    run.aborted = f"link fault: the vehicle's port {run.gone}; --resume {run.dir} goes on from {gap['cut']}"
    run.progress.note(f"{port} {how}")
    return False


def _default_resume(run: Any) -> str:
    import shlex

    return f"helmcheck certify vehicle --port {shlex.quote(run.o.port)} --resume {shlex.quote(str(run.dir))}"
