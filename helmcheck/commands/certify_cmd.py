"""``helmcheck certify vehicle|backseat``: dispatches to the two certifiers.

Each role's command line is its own module (:mod:`.certify_vehicle_cmd`,
:mod:`.certify_backseat_cmd`) exposing ``add_arguments(parser)``, ``run(args) -> int`` and
``EPILOG``; the certifiers they drive are ``helmcheck.certify.vehicle`` and
``helmcheck.certify.backseat``.
"""

from __future__ import annotations

import argparse
import importlib

from . import certificate_opts

ROLES = {
    "vehicle": ("helmcheck.commands.certify_vehicle_cmd",
                "certify a vehicle: helmcheck plays the backseat and judges every reply",
                "Certify a vehicle: helmcheck plays the backseat, runs a case for every vehicle clause the "
                "profile claims, explores, and judges every reply against the reference model."),
    "backseat": ("helmcheck.commands.certify_backseat_cmd",
                 "certify a backseat: helmcheck plays the vehicle and judges every command",
                 "Certify a backseat: helmcheck plays the reference vehicle, stages the scenarios below, "
                 "and judges every line the backseat sends."),
}

EPILOG = """\
examples:
  helmcheck certify vehicle --port /dev/pts/N --time-scale 20 --profile examples/emulator.toml
  helmcheck certify backseat --time-scale 10 \\
      --exec 'python3 examples/backseat.py --port {port} --time-scale {time_scale}'

Run 'helmcheck certify vehicle --help' or 'helmcheck certify backseat --help' for each role's options.

exit status: 0 conformant, 1 non-conformant, 2 inconclusive or tester error, 64 usage.
"""


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = sub.add_parser("certify", help="certify a vehicle or a backseat over a serial port",
                       description="Certify an implementation of the remote helm protocol against "
                                   "the reference profile: a vehicle (helmcheck plays the backseat) or a "
                                   "backseat (helmcheck plays the vehicle).",
                       epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    roles = p.add_subparsers(dest="role", metavar="ROLE", parser_class=type(p))
    for role, (module, help_, description) in ROLES.items():
        try:
            mod = importlib.import_module(module)
        except ModuleNotFoundError as e:
            if not module.startswith(e.name or "\0"):
                raise
            continue
        rp = roles.add_parser(role, help=help_, description=description,
                              formatter_class=argparse.RawDescriptionHelpFormatter,
                              epilog=getattr(mod, "EPILOG", None))
        mod.add_arguments(rp)
        certificate_opts.add_arguments(rp, role)  # --sign-key, --operator, --site, --implementation
        rp.set_defaults(func=mod.run)
    p.set_defaults(func=_no_role)
    return p


def _no_role(args: argparse.Namespace) -> int:
    from ..failures import UsageError

    raise UsageError(f"choose a role: {' or '.join(ROLES)} (see 'helmcheck certify --help')")
