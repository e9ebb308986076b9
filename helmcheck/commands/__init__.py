"""Command-line subcommands, one module each; :mod:`helmcheck.cli` dispatches to them.

* :mod:`.certify_cmd` — ``certify vehicle|backseat``; :mod:`.certify_vehicle_cmd`,
  :mod:`.certify_backseat_cmd` — the two roles;
* :mod:`.emulate_cmd` — ``emulate``; :mod:`.checklog_cmd` — ``check-log`` (a whole archive:
  :mod:`.checklog_fleet_cmd`); :mod:`.monitor_cmd` —
  ``monitor``; :mod:`.relay_cmd` — ``relay`` (a line with faults); :mod:`.verify_cmd` —
  ``verify``; :mod:`.report_cmd` — ``report``; :mod:`.matrix_cmd` — ``matrix``;
* :mod:`.replay_cmd` — ``replay``; :mod:`.diff_cmd` — ``diff``; :mod:`.parse_cmd` — ``parse``; :mod:`.keygen_cmd` — ``keygen``;
  :mod:`.profile_cmd` — ``profile init``; :mod:`.docs_cmd` — ``docs``.

``certify`` dispatches again, by role, to :mod:`.certify_vehicle_cmd` and
:mod:`.certify_backseat_cmd`; :mod:`.ports` (opening the port a command names) and
:mod:`.certificate_opts` (``--sign-key``, ``--operator``, ``--site``, ``--implementation``) are
shared by the commands, :mod:`.lineopt` the ``--line clean|noisy`` option every command that reads
a line takes, and :mod:`.messages` the message forms they share (``report: PATH``).
This is the top layer: a command may import the drivers (:mod:`helmcheck.line`,
:mod:`helmcheck.emulator`, :mod:`helmcheck.checklog`, :mod:`helmcheck.certify`) and the reports,
and nothing below imports a command.
"""
