"""The failure classes of the command line: what went wrong, and which exit code it means.

Every problem a command can meet that is not a verdict about the implementation under test is
one of these classes (the table "Failures and exit codes" in ``docs/contracts.md``). A command
raises the class with a one-line message; :mod:`helmcheck.cli` prints it as
``helmcheck COMMAND: message`` on standard error and exits with the class's code. Nothing here
prints, and nothing here imports more than the standard library, so any layer may raise them
(the emulator core raises :class:`OutputLost` when its settings file cannot be saved).

- :class:`UsageError` (64): a bad option or argument on the command line.
- :class:`PathError` (64): a path or port the user named cannot be used at start — an
  unreadable input (profile, log, results directory, replay), an output directory that cannot
  be created or holds an earlier run, a port that does not exist or cannot be opened, an
  unknown URL scheme.
- :class:`~helmcheck.profile.ProfileError` (64): a profile with a bad key or value; defined
  with the profile, mapped by :mod:`helmcheck.cli` like the classes here.
- :class:`LinkFault` (2): the link worked at start and failed during the run.
- :class:`OutputLost` (2): an output file could not be written (a full disk, a vanished
  directory); the message names the file.
- :class:`Interrupted`: SIGINT, SIGTERM or SIGHUP, a :class:`KeyboardInterrupt`, so code that
  already ends a run cleanly on Ctrl-C does the same.

Any other exception is a tester error: exit 2, with the traceback saved to a file
(:data:`TRACEBACK_NAME` in the command's report directory).
"""

from __future__ import annotations

__all__ = ["Failure", "UsageError", "PathError", "LinkFault", "OutputLost",
           "Interrupted", "USAGE", "TESTER", "TRACEBACK_NAME", "describe_interrupt"]

USAGE = 64  #: EX_USAGE: the run did not start
TESTER = 2  #: inconclusive: the tester or its surroundings failed
#: A tester error's traceback, in the report directory (:mod:`helmcheck.cli`, the vehicle runner).
TRACEBACK_NAME = "tester-error.txt"


class Failure(Exception):
    """A failure with a one-line message and an exit code (module docstring)."""

    code: int = TESTER
    kind: str = "failure"

    def __init__(self, message: str):
        super().__init__(str(message) or self.kind)

    @property
    def message(self) -> str:
        return str(self)


class UsageError(Failure):
    """A bad option or argument (exit 64)."""

    code = USAGE
    kind = "usage"


class PathError(Failure):
    """A path, directory or port named on the command line cannot be used at start (exit 64)."""

    code = USAGE
    kind = "path"


class LinkFault(Failure):
    """The link failed during the run (exit 2): a device that vanished, a peer that went away."""

    code = TESTER
    kind = "link"


class OutputLost(Failure):
    """An output file could not be written (exit 2); the message names the file."""

    code = TESTER
    kind = "output"


class Interrupted(KeyboardInterrupt):
    """A signal that ends the run like Ctrl-C. ``str()`` is ``interrupted (SIGTERM)``."""

    def __init__(self, signal_name: str = "SIGINT"):
        super().__init__(f"interrupted ({signal_name})")
        self.signal_name = signal_name


def describe_interrupt(exc: BaseException) -> str:
    """``interrupted (SIGTERM)`` for :class:`Interrupted`, ``interrupted (Ctrl-C)`` for a plain
    :class:`KeyboardInterrupt`."""
    text = str(exc)
    return text if text.startswith("interrupted") else "interrupted (Ctrl-C)"
