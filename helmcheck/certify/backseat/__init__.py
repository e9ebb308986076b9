"""``helmcheck certify backseat``: helmcheck plays the vehicle and judges a backseat (§9).

The judging is not here: it is :class:`helmcheck.judge.backseat.BackseatObserver`, the same
observer ``check-log`` feeds from a wire log. Modules, one concern each:

* :mod:`.scenarios` — the scenarios the tester stages while the backseat runs (``nominal``,
  ``reject``, ``lockout``, ``mission-end``, ``silence``) and the plan: how long each lasts, from
  what it must show at the time scale and on the line (``--plan``).
* :mod:`.stage` — each scenario's moments, whether they reached the backseat in time, how long the
  run holds a scenario open for them, and what is not claimed when they did not.
* :mod:`.certifier` — the library entry: :func:`~.certifier.certify` (:class:`~.certifier.Options`) →
  :class:`~.certifier.Outcome`, used by the command line and the pytest plugin.
* :mod:`.progress` — the progress bar on standard error.
* :mod:`.runner` — the I/O loop: one link, one reference vehicle
  (:class:`~helmcheck.emulator.core.EmulatorCore`), the recorder (wire log and
  observer) and the scenario plan; it owns the clock and the descriptors.
* :mod:`.link` — the certifier's pty, which notices the backseat going away.
* :mod:`.process` — the backseat under test when helmcheck starts it (``--exec CMD``).
* :mod:`.report` — turns the verdict ledger into a ``results.json`` (schema 1,
  ``"role": "backseat"``) and renders every report format.

The command line (``add_arguments``, ``run``, ``EPILOG``) is
:mod:`helmcheck.commands.certify_backseat_cmd`.
"""
