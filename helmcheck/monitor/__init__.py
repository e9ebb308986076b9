"""``helmcheck monitor``: judge a live session between a real backseat and a real vehicle.

Two ways onto the line: **tap** (``--tap``: the two receive lines of a Y-cable, read only, nothing
is ever written) and **in line** (``--between``: every byte forwarded unchanged, in arrival order,
at once, and a copy judged). Modules, one concern each:

* the I/O thread is :class:`helmcheck.line.relay.Relay` (:mod:`helmcheck.line.relay`): it reads
  both sides with one clock, forwards in line, hands each chunk on; the monitor gives it no
  impairment stage, so it never alters, delays on purpose, drops or injects a byte;
* :mod:`.sessionlog` — the session's wire log: each record written, flushed and handed to the
  judges as written; rotated by size (``wire.log``, ``wire.001.log``, …);
* :mod:`.live` — check-log's judges (:class:`helmcheck.checklog.checker.SessionJudge`) fed the
  records on a thread of their own; new findings as they are made;
* :mod:`.gaps` — a side whose device vanished: opened again under its name when it is back (the
  relay's ``reopen``), the gap recorded for the judges (what one side shows alone is held);
* :mod:`.view` — a finding as one line, or a live screen on a terminal;
* :mod:`.session` — :func:`~.session.monitor`: one session from the open ports to a results
  directory that ``check-log`` would give for its log and ``verify`` re-judges.

The command line is :mod:`helmcheck.commands.monitor_cmd`.
"""
