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
                "certify a vehicle: helmcheck plays the backseat and judges every reply"),
    "backseat": ("helmcheck.commands.certify_backseat_cmd",
                 "certify a backseat: helmcheck plays the vehicle and judges every command"),
}


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = sub.add_parser("certify", help="certify a vehicle or a backseat over a serial port",
                       description="Certify an implementation of the remote helm protocol against "
                                   "the reference profile. Exit 0 conformant, 1 non-conformant, "
                                   "2 inconclusive, 64 usage.")
    roles = p.add_subparsers(dest="role", metavar="ROLE", parser_class=type(p))
    for role, (module, help_) in ROLES.items():
        try:
            mod = importlib.import_module(module)
        except ModuleNotFoundError as e:
            if not module.startswith(e.name or "\0"):
                raise
            continue
        rp = roles.add_parser(role, help=help_, description=help_,
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
