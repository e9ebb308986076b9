"""``helmcheck verify DIR [--public-key PUB]``: does a results directory follow from its evidence?

:func:`verify_run` is the verification: it runs the checks of :mod:`helmcheck.reports.verify` in
their order and re-judges the wire log under the recorded profile with the offline checker
(:func:`helmcheck.checklog.check_log`, a driver, which is why this runs here and not
in the reports package), then compares every clause verdict, the run verdict and the certificate
flag with ``results.json``, checks the recorded digests, and checks the signature when the run
is signed (against ``--public-key`` when given).

Exit status: 0 verified; 1 something differs (one line per difference on standard output, each
naming the clause or file); 64 usage (no such results directory, unreadable public key).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .. import exitcodes
from ..failures import UsageError

EPILOG = """\
what is checked (in any results directory: certify vehicle, certify backseat, check-log, monitor):
  results.json    a valid results document whose digests match wire.log and profile.toml
  profile.toml    the profile the run recorded, key by key
  clause verdicts re-judged from wire.log under profile.toml (same observer as check-log);
                  every clause verdict, the run verdict and the certificate flag must agree
  signature.json  if present: the Ed25519 signature over results.json, wire.log, profile.toml
                  and the tool version; with --public-key it must be that key's signature

examples:
  helmcheck verify reports/vehicle
  helmcheck keygen --out lab                        # once: lab.key signs, lab.pub checks
  helmcheck certify vehicle --port /dev/pts/N --time-scale 20 --profile examples/emulator.toml \\
      --sign-key lab.key --report-dir reports/signed
  helmcheck verify reports/signed --public-key lab.pub   # the run must be signed by this key

exit status: 0 verified, 1 mismatch (one line per difference, each naming the clause or file),
  64 usage (no such results directory, an unreadable public key).
"""


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = sub.add_parser("verify", help="re-judge a results directory from its evidence; check its signature",
                       description="Re-judge a results directory's wire log under its recorded profile and "
                                   "check that results.json follows from it; check the signature if signed.",
                       epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("directory", metavar="DIR", help="results directory (results.json, wire.log, profile.toml)")
    p.add_argument("--public-key", metavar="PUB",
                   help="the trusted public key (PREFIX.pub from 'helmcheck keygen'); the run must be signed by it")
    p.set_defaults(func=run)
    return p


def verify_run(directory: Path | str, public_key=None, *, public_key_name: str = "the given public key"):
    """Check the results directory *directory* against its evidence and, if signed, its signature
    (the steps of :mod:`helmcheck.reports.verify`); a
    :class:`~helmcheck.reports.verify.Verification` listing every difference.

    *public_key*: a trusted Ed25519 public key, or ``None``. A directory that is not a results
    directory raises :class:`~helmcheck.reports.verify.VerifyUsageError`."""
    from ..checklog.checker import LogFormatError, check_log
    from ..reports.verify import check_digests, check_profile, check_signature, compare_rejudged, open_run, rejudging

    directory = Path(directory)
    out, results = open_run(directory)
    if results is not None:
        check_digests(out, directory, results)
        profile = check_profile(out, directory, results)
        job = rejudging(out, directory, results, profile) if profile is not None else None
        if job is not None:
            catalog = None
            if job.missions:
                from ..emulator.missionfile import DirectoryCatalog
                catalog = DirectoryCatalog(list(job.missions))
            try:
                outcome = check_log(job.wire_path, profile=profile, role=job.role, time_scale=job.time_scale,
                                    swap=job.swap, catalog=catalog, line=job.line)
            except (LogFormatError, OSError, ValueError) as e:
                out.add(job.wire_name, f"cannot be re-judged: {e}")
            else:
                if job.sha256 is not None and outcome.sha256 != job.sha256:
                    out.add(job.wire_name, f"SHA-256 {outcome.sha256} differs from the {job.sha256} recorded in "
                                           f"results.json (log.sha256)")
                compare_rejudged(out, results, outcome.clauses, outcome.facts, job.role)
    check_signature(out, directory, results, public_key, public_key_name)
    return out


def run(args: argparse.Namespace) -> int:
    from ..reports.signing import KeyFileError, load_public_key
    from ..reports.verify import VerifyUsageError

    public = None
    if args.public_key is not None:
        try:
            public = load_public_key(args.public_key)
        except KeyFileError as e:
            raise UsageError(str(e)) from None
    try:
        result = verify_run(args.directory, public, public_key_name=str(args.public_key))
    except VerifyUsageError as e:
        raise UsageError(str(e)) from None
    for note in result.notes:
        print(f"note: {note}")
    if not result.ok:
        for finding in result.findings:
            print(f"MISMATCH {finding}")
        print(f"NOT VERIFIED: {len(result.findings)} difference(s) in {args.directory}")
        sys.stdout.flush()
        return exitcodes.NONCONFORMANT
    if result.signed and result.trusted_key:
        signed = f"; signed by the given key {result.key_id}"
    elif result.signed:
        signed = (f"; signature valid, made by key {result.key_id} "
                  f"(give --public-key to check it is a key you trust)")
    else:
        signed = "; not signed"
    print(f"VERIFIED: {result.clauses_compared} clause verdict(s), the run verdict and the certificate flag "
          f"follow from the wire log under the recorded profile{signed}")
    return exitcodes.OK
