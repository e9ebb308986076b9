"""Exit codes every helmcheck command uses, so a CI can gate on them."""

OK = 0  #: conformant (or non-strict without --strict); every line valid
NONCONFORMANT = 1  #: a MUST failed (or a SHOULD, with --strict); an invalid line
INCONCLUSIVE = 2  #: the link or the tester failed; nothing could be judged
USAGE = 64  #: bad command line or unusable input file (EX_USAGE)


def usage_error(prog: str, message: str) -> int:
    """Raise :class:`helmcheck.failures.UsageError` (exit 64); :mod:`helmcheck.cli` prints it as
    ``PROG: message``. Typed ``-> int`` so that ``return usage_error(…)`` reads naturally."""
    from .failures import UsageError

    del prog  # the command line knows which command it is running
    raise UsageError(message)
