"""Exit codes every helmcheck command uses, so a CI can gate on them.

A usage error is raised, not returned: ``raise helmcheck.failures.UsageError(message)`` (exit
:data:`USAGE`); :mod:`helmcheck.cli` prints it as ``helmcheck COMMAND: message``.
"""

OK = 0  #: conformant (or non-strict without --strict); every line valid
NONCONFORMANT = 1  #: a MUST failed (or a SHOULD, with --strict); an invalid line
INCONCLUSIVE = 2  #: the link or the tester failed; nothing could be judged
USAGE = 64  #: bad command line or unusable input file (EX_USAGE)
