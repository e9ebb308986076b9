"""``helmcheck certify vehicle``: helmcheck plays the backseat and judges a vehicle.

Modules, one concern each:

* :mod:`.link` — the tester's side of the serial line: send a sentence (through the bench-safety
  choke point), collect timestamped replies, record the wire log, notice silence, garbage and a
  vanished device.
* :mod:`.safety` — the bench-safety interlock (profile ``[bench_safety]``).
* :mod:`.mirror` — the reference model mirrored from what was sent and seen (the oracle).
* :mod:`.judge` — findings, per-clause verdicts and their wire evidence.
* :mod:`.cases` — the numbered, data-described clause cases (description, expectation, steps).
* :mod:`.session` — runs steps against a vehicle: verified reset, send, poll, timed waits.
* :mod:`.explore` — hypothesis sequences of valid and invalid commands, shrunk on failure.
* :mod:`.replay` — version-independent replay files: write, read, re-drive.
* :mod:`.clockrate` — the vehicle's clock rate from ``$GPRMC`` readings, and whether it is the
  declared time scale (sans-IO); :mod:`.clockprobe` reads the clock at start.
* :mod:`.runner` — one certification run: cases, exploration, results and reports.
* :mod:`.progress` — the progress display (rich on a terminal, plain lines otherwise).
* :mod:`.cli` — ``add_arguments``/``run`` for ``helmcheck certify vehicle``.
"""
