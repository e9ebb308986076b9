"""``helmcheck keygen --out PREFIX``: an Ed25519 key pair for signing runs.

Writes ``PREFIX.key`` (private, PKCS #8 PEM, mode 0600) and ``PREFIX.pub`` (public, PEM) with
:mod:`helmcheck.reports.signing` and prints the key id (the SHA-256 of the public key) that
reports and ``helmcheck verify`` show. An existing key is never overwritten unless ``--force``.
Exit status: 0 written; 64 usage (a file exists, or cannot be written).
"""

from __future__ import annotations

import argparse

from .. import exitcodes
from ..failures import UsageError

EPILOG = """\
examples:
  helmcheck keygen --out lab                         # lab.key (keep it secret), lab.pub (hand it out)
  helmcheck certify vehicle --port /dev/ttyUSB0 --profile iver3.toml --sign-key lab.key --report-dir signed/
  helmcheck verify signed/ --public-key lab.pub

exit status: 0 written, 64 usage (a key file exists without --force, or cannot be written).
"""


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = sub.add_parser("keygen", help="make an Ed25519 key pair for signing results",
                       description="Write an Ed25519 key pair PREFIX.key and PREFIX.pub for "
                                   "'certify --sign-key' and 'verify --public-key'.",
                       epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", required=True, metavar="PREFIX", help="write PREFIX.key and PREFIX.pub")
    p.add_argument("--force", action="store_true", help="overwrite existing key files")
    p.set_defaults(func=run)
    return p


def run(args: argparse.Namespace) -> int:
    from ..reports.signing import generate_keypair

    try:
        key, pub, kid = generate_keypair(args.out, overwrite=args.force)
    except FileExistsError as e:
        raise UsageError(f"{e}; use --force to replace it") from None
    except OSError as e:
        raise UsageError(f"cannot write {e.filename or args.out}: {e.strerror or e}") from None
    print(f"private key: {key} (keep it secret)")
    print(f"public key:  {pub}")
    print(f"key id:      {kid}")
    return exitcodes.OK
