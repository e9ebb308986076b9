"""Command-line subcommands, one module each; :mod:`helmcheck.cli` dispatches to them.

``certify`` dispatches again, by role, to :mod:`.certify_vehicle_cmd` and
:mod:`.certify_backseat_cmd`; :mod:`.ports` (opening the port a command names) and
:mod:`.certificate_opts` (``--sign-key``, ``--operator``, ``--site``, ``--implementation``) are
shared by the commands. This is the top layer: a command may import the drivers
(:mod:`helmcheck.line`, :mod:`helmcheck.emulator`,
:mod:`helmcheck.checklog`, :mod:`helmcheck.certify`) and the reports, and nothing below imports a command.
"""
