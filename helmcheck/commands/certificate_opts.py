"""The certificate options of ``certify vehicle`` and ``certify backseat``.

``--sign-key KEY`` (sign the run, :mod:`helmcheck.reports.signing`), ``--operator NAME`` and
``--site NAME`` (who ran it, where), and for a backseat ``--implementation NAME[@VERSION]`` (what
is under test; a vehicle is named by its profile). :func:`add_arguments` adds them to a role's
parser; :func:`declaration` turns parsed arguments into a
:class:`~helmcheck.reports.certificate.RunDeclaration`, loading the key before the run starts so
that a bad key is a usage error (exit 64), not a lost run.
"""

from __future__ import annotations

import argparse
from typing import Optional

__all__ = ["add_arguments", "declaration", "DeclarationError"]


class DeclarationError(ValueError):
    """A certificate option that cannot be used; the message names the option or file."""


def add_arguments(p: argparse.ArgumentParser, role: str) -> None:
    g = p.add_argument_group("certificate")
    g.add_argument("--sign-key", metavar="KEY", help="sign the run with this Ed25519 private key (helmcheck keygen)")
    g.add_argument("--operator", metavar="NAME", help="who ran the certification (shown in every report)")
    g.add_argument("--site", metavar="NAME", help="where it ran (lab, bench, vessel)")
    if role == "backseat":
        g.add_argument("--implementation", metavar="NAME[@VERSION]",
                       help="the backseat under test, e.g. moos-ivp-helm@2.1.0 (shown in every report)")


def _text(args: argparse.Namespace, name: str, option: str) -> Optional[str]:
    value = getattr(args, name, None)
    if value is None:
        return None
    if not value.strip() or any(ord(c) < 0x20 or ord(c) == 0x7F for c in value):
        raise DeclarationError(f"{option} must be printable text, not {value!r}")
    return value.strip()


def declaration(args: argparse.Namespace, role: str):
    """The :class:`RunDeclaration` of parsed arguments; :class:`DeclarationError` for bad values."""
    from ..reports.certificate import RunDeclaration
    from ..reports.identity import Declared, parse_implementation
    from ..reports.signing import KeyFileError, load_signing_key

    name = version = None
    impl = _text(args, "implementation", "--implementation") if role == "backseat" else None
    if impl is not None:
        try:
            name, version = parse_implementation(impl)
        except ValueError as e:
            raise DeclarationError(str(e)) from None
    key = None
    if getattr(args, "sign_key", None):
        try:
            key = load_signing_key(args.sign_key)
        except KeyFileError as e:
            raise DeclarationError(f"--sign-key: {e}") from None
    declared = Declared(operator=_text(args, "operator", "--operator"), site=_text(args, "site", "--site"),
                        implementation_name=name, implementation_version=version,
                        profile_file=getattr(args, "profile", None))
    return RunDeclaration(declared, key)
