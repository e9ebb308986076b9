"""``helmcheck certify backseat``: helmcheck plays the vehicle and judges a backseat (§9).

Modules, one concern each:

* :mod:`.judge` — :class:`~.judge.BackseatJudge`, sans-IO: every byte the backseat sends (and
  every byte the vehicle sent it, to know what it could know) in, per-clause findings out
  (RH-BS-1..8).
* :mod:`.scenarios` — the scenarios the tester stages while the backseat runs (``nominal``,
  ``reject``, ``lockout``, ``mission-end``, ``silence``) and how a run's duration is split.
* :mod:`.runner` — the I/O loop: one link, one reference vehicle
  (:class:`~helmcheck.conformance.emulator.core.EmulatorCore`), the judge and the scenario
  plan; it owns the clock, the descriptors and the wire log.
* :mod:`.report` — turns the judge's findings into a ``results.json`` (schema 1,
  ``"role": "backseat"``) and renders every report format.
* :mod:`.cli` — the command line (``add_arguments``, ``run``, ``EPILOG``).
"""
