"""The live certifiers: helmcheck on one end of a line, an implementation under test on the other.

* :mod:`.vehicle` — ``certify vehicle``: helmcheck plays the backseat and judges a vehicle
  (§1–8); library entry :func:`helmcheck.certify.vehicle.runner.certify`;
* :mod:`.backseat` — ``certify backseat``: helmcheck plays the vehicle (the reference emulator's
  core, in-process) and judges a backseat (§9); library entry
  :func:`helmcheck.certify.backseat.certifier.certify`;
* :mod:`.diff` — ``diff``: two vehicles driven with the same sequences side by side, each judged
  by the vehicle observer, their first divergence shrunk; library entry
  :func:`helmcheck.certify.diff.driver.diff`;
* :mod:`.outcome` — :class:`~.outcome.Outcome`, what both return.

Both judge through the observers of :mod:`helmcheck.judge`, fed by the recorder of
:mod:`helmcheck.line.recorder` exactly as the wire log records the bytes, and turn the ledger into
results by :func:`helmcheck.reports.assemble.assemble` (the function ``verify`` runs again). The
command lines are :mod:`helmcheck.commands.certify_vehicle_cmd` and
:mod:`helmcheck.commands.certify_backseat_cmd`.
"""
