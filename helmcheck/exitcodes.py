"""Exit codes every helmcheck command uses, so a CI can gate on them."""

import sys

OK = 0  #: conformant (or non-strict without --strict); every line valid
NONCONFORMANT = 1  #: a MUST failed (or a SHOULD, with --strict); an invalid line
INCONCLUSIVE = 2  #: the link or the tester failed; nothing could be judged
USAGE = 64  #: bad command line or unusable input file (EX_USAGE)


def usage_error(prog: str, message: str) -> int:
    """Print ``PROG: message`` on stderr and return :data:`USAGE` (for ``return usage_error(…)``)."""
    print(f"{prog}: {message}", file=sys.stderr)
    return USAGE
