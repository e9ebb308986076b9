"""``helmcheck certify vehicle``: helmcheck plays the backseat and judges a vehicle.

The judging is not here: it is :class:`helmcheck.judge.vehicle.VehicleObserver` (the mirror of
the reference model, findings and per-clause verdicts), the same observer ``check-log`` feeds
from a wire log. The command line is :mod:`helmcheck.commands.certify_vehicle_cmd`; the library
entry point is :func:`.runner.certify`. Modules, one concern each:

* :mod:`.link` — the tester's side of the serial line: send a sentence (through the bench-safety
  choke point), collect timestamped replies, record the wire log, notice silence, garbage and a
  vanished device.
* :mod:`.safety` — the bench-safety interlock (profile ``[bench_safety]``).
* :mod:`.catalogue` — the numbered, data-described clause cases (description, expectation,
  steps); :mod:`.rulecases` — the cases that probe a rule of the traceability table no other case
  could fail (:mod:`helmcheck.rules`); :mod:`.steps` — their step vocabulary; :mod:`.interpreter` —
  runs a case's steps.
* :mod:`.session` — runs steps against a vehicle: verified reset, send, poll, timed waits.
* :mod:`.linemeter` — what the line costs, measured as the run goes (reply latency, the host's
  jitter, the report's size); :mod:`.durations` — the timeouts, parks and waits chosen from it
  so that the observer can time every one (or a case NOT-TESTED before it runs).
* :mod:`.flow` — how a case stops early (flow control, never a verdict).
* :mod:`.casecounters` — the port's error counters read around each case (a rise: the case's
  clauses INCONCLUSIVE).
* :mod:`.explore` — hypothesis sequences aimed at the model (:mod:`.machine`: the rules and
  episodes), shrunk on failure, within a budget
  in wall and vehicle seconds; :mod:`.generate` — what they draw (every claimed command at its
  range edges and error codes, every mutation of a line); :mod:`.modelcover` — what of the
  model a run's lines reached (modes, transitions, interrupt pairs, timers run out, timer
  boundaries, error codes); :mod:`.aim` — what is not reached yet on this vehicle, as targets
  (a way into the state each needs, a firing there, its cost from the vehicle's own mission and
  the line), and :mod:`.tour` — the machine that drives tours of them.
* :mod:`.edges` — the range edges of §4–8b (both sides of every bound and keyword, generated from
  the command checks, the grammar and the model's state checks) and which of them the lines sent
  reached (``stats.edges``).
* :mod:`.replay` — version-independent replay files: write, read, re-drive from the verified
  reset, naming the step that failed or went another way; :mod:`.relocate` moves the positions
  a replay's lines send to where the vehicle begins it.
* :mod:`.clockrate` — the vehicle's clock rate from ``$GPRMC`` readings, and whether it is the
  declared time scale (sans-IO); :mod:`.clockprobe` reads the clock at start.
* :mod:`.restore` — leaving the vehicle as it was found: its settings and its mode.
* :mod:`.resume` — ``--resume DIR``: an interrupted run goes on from its last completed case.
* :mod:`.rejoin` — a port that vanished mid-run, waited for under the same name: the gap
  recorded, the vehicle's state verified again, the case it cut run again (or ``--resume``).
* :mod:`.plan` — ``--plan``: the run's estimated time, from the cases run in virtual time
  (:mod:`.virtual`: a serial line in virtual time with the reference vehicle at its far end).
* :mod:`.runner` — one certification run: cases, exploration, results and reports;
  :mod:`.resultsfile` — its ``results.json``: what it starts as, each save, a tester error's
  traceback beside it; :mod:`.exec_child` — the vehicle under test when helmcheck starts it
  (``--exec``).
* :mod:`.progress` — the progress display (rich on a terminal, plain lines otherwise).
"""
