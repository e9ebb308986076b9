"""The ``helmcheck`` command line: one entry point, one module per subcommand, one failure layer.

Exit codes (see :mod:`helmcheck.exitcodes`): 0 conformant, 1 non-conformant, 2 inconclusive or
tester error, 64 usage. Subcommand modules are imported only when used, so ``--help`` is fast.

:func:`main` is the only place a failure becomes an exit code and a message (the table
"Failures and exit codes" in ``docs/contracts.md``):

- a :class:`~helmcheck.failures.Failure` (usage, path, profile, link, output) prints
  ``helmcheck COMMAND: message`` — one line — and exits with the class's code;
- SIGINT, SIGTERM and SIGHUP raise :class:`~helmcheck.failures.Interrupted` (a
  :class:`KeyboardInterrupt`) through :mod:`helmcheck.signals`; a command that runs a session
  ends it with partial results, anything else exits 2 (``emulate``: 0, it was asked to stop);
- standard output and error are :class:`~helmcheck.streams.GuardedStream` s: a reader that went
  away (``| head``, a closed terminal) ends the command quietly, any other write error on
  standard output is exit 2;
- any other exception is a tester error: exit 2, the traceback saved to ``tester-error.txt`` in
  the command's report directory (or a temporary file) and one line on stderr pointing to it.
  A tester error never exits 1 and never prints a bare traceback.
"""

from __future__ import annotations

import argparse
import ast
import importlib
import re
import sys
from pathlib import Path
from typing import Optional

from . import __version__, exitcodes
from .failures import TRACEBACK_NAME, Failure, UsageError, describe_interrupt
from .signals import ending_signals
from .streams import GuardedStream

#: subcommand -> (module, one-line help). Each module has add_parser(sub) and run(args); its
#: parser's ``help`` is this same text (tests/test_cli_help.py).
SUBCOMMANDS = {
    "parse": ("helmcheck.commands.parse_cmd", "validate sentences line by line"),
    "emulate": ("helmcheck.commands.emulate_cmd", "run the reference vehicle emulator on a serial port"),
    "certify": ("helmcheck.commands.certify_cmd", "certify a vehicle or a backseat over a serial port"),
    "replay": ("helmcheck.commands.replay_cmd", "re-drive a saved failing sequence against a vehicle"),
    "diff": ("helmcheck.commands.diff_cmd", "drive two vehicles with the same sequences; report their first divergence"),
    "check-log": ("helmcheck.commands.checklog_cmd", "judge a recorded serial log against the reference model"),
    "monitor": ("helmcheck.commands.monitor_cmd", "judge a live backseat-vehicle session (tap or in line)"),
    "relay": ("helmcheck.commands.relay_cmd", "relay between two ports through a line with faults (for testing on a bad line)"),
    "report": ("helmcheck.commands.report_cmd", "render a results directory as HTML, JUnit XML and Markdown"),
    "matrix": ("helmcheck.commands.matrix_cmd", "one overview of several runs: clauses x implementations"),
    "verify": ("helmcheck.commands.verify_cmd", "re-judge a results directory from its evidence; check its signature"),
    "keygen": ("helmcheck.commands.keygen_cmd", "make an Ed25519 key pair for signing results"),
    "profile": ("helmcheck.commands.profile_cmd", "write a commented profile for a vehicle; list the profile keys"),
    "docs": ("helmcheck.commands.docs_cmd", "regenerate the generated documentation"),
}

#: Commands that record the tester's revision in their results (``identity.tester.revision``):
#: it is read before the command writes anything, so a run's own outputs never make it ``-dirty``.
RECORDS_REVISION = ("certify", "check-log", "monitor", "diff")

#: Exit code of a command stopped by a signal before it could end its run itself.
INTERRUPT_CODE = {"emulate": exitcodes.OK, "relay": exitcodes.OK}

DESCRIPTION = """\
helmcheck — the formal model and conformance suite for the Iver3 remote helm protocol.

typical use:
  helmcheck emulate --port pty --time-scale 20 &     # a reference vehicle; prints port: /dev/pts/N
  helmcheck certify vehicle --port /dev/pts/N --time-scale 20 --profile examples/emulator.toml
  helmcheck certify backseat --time-scale 10 \\
      --exec 'python3 examples/backseat.py --port {port} --time-scale {time_scale}'
  helmcheck check-log reports/vehicle/wire.log      # judge a recorded log as the run that wrote it did
  helmcheck monitor --tap /dev/ttyUSB0 /dev/ttyUSB1  # judge a live session from a Y-cable, live
  helmcheck relay --between pty /dev/ttyUSB0 --impair 'flip=1e-5,cut=5s@60'  # test on a bad line
  helmcheck diff --port /dev/pts/5 --port /dev/pts/7 # two vehicles, same sequences: first divergence
  helmcheck report reports/vehicle                  # render results.json to HTML/JUnit/Markdown again
  helmcheck verify reports/vehicle                  # re-judge the wire log; check the signature
  helmcheck matrix reports/vehicle reports/check-log-wire --out matrix/   # runs side by side
  helmcheck parse reports/vehicle/wire.log          # validate a capture line by line
  helmcheck profile init my-vehicle.toml            # a commented profile for a vehicle to fill in

exit status: 0 conformant, 1 non-conformant, 2 inconclusive or tester error, 64 usage error.
Run 'helmcheck COMMAND --help' for each command's options and examples.
"""


def one_line(text: str) -> str:
    """``text`` as one printable line: control characters (a ``\\r`` in an argument) escaped."""
    return "".join(c if c.isprintable() or c == " " else repr(c)[1:-1] for c in " ".join(text.split(" ")))


_INVALID_CHOICE = re.compile(r"^argument (?P<arg>[^:]+): invalid choice: (?P<got>'.*?') \(choose from (?P<known>.*)\)$")


def _did_you_mean_choice(message: str) -> str:
    """argparse's "invalid choice" message with the closest choices named first: ``checklog`` →
    ``unknown command 'checklog' (did you mean 'check-log'?)``, the choices after."""
    from .spelling import did_you_mean

    m = _INVALID_CHOICE.match(message)
    if m is None:
        return message
    try:
        got = ast.literal_eval(m.group("got"))
        known = [ast.literal_eval(k.strip()) for k in m.group("known").split(",")]
    except (ValueError, SyntaxError):
        return message
    what = {"COMMAND": "command", "ROLE": "role", "ACTION": "action"}.get(m.group("arg"), None)
    head = f"unknown {what} {got!r}" if what else f"argument {m.group('arg')}: invalid choice {got!r}"
    return f"{head}{did_you_mean(str(got), map(str, known))}; choose from {', '.join(map(str, known))}"


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # usage errors exit 64 (not argparse's 2), in one line
        message = _did_you_mean_choice(message)
        self.exit(exitcodes.USAGE, one_line(f"{self.prog}: error: {message} (see '{self.prog} --help')") + "\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="helmcheck", description=DESCRIPTION,
                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=f"helmcheck {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    argv = sys.argv[1:]
    wanted = next((a for a in argv if not a.startswith("-")), None)
    for name, (module, help_) in SUBCOMMANDS.items():
        if wanted in SUBCOMMANDS and name != wanted:
            sub.add_parser(name, help=help_)
            continue
        try:
            mod = importlib.import_module(module)
        except ModuleNotFoundError as e:
            if e.name != module:
                raise
            continue  # a subcommand not built yet is simply not offered
        mod.add_parser(sub)
    return parser


def prog_of(args: Optional[argparse.Namespace]) -> str:
    """``helmcheck certify vehicle``, ``helmcheck parse``, … for messages."""
    words = ["helmcheck"]
    if args is not None and getattr(args, "command", None):
        words.append(args.command)
        if args.command == "certify" and getattr(args, "role", None):
            words.append(args.role)
    return " ".join(words)


def _say(prog: str, message: str) -> None:
    print(one_line(f"{prog}: {message}"), file=sys.stderr)


def save_traceback(exc: BaseException, args: Optional[argparse.Namespace]) -> str:
    """Write the traceback of a tester error to a file; returns where (or why it could not)."""
    import os
    import tempfile
    import time
    import traceback

    text = (f"helmcheck {__version__} tester error\n"
            f"command: helmcheck {' '.join(sys.argv[1:])}\n"
            f"time: {time.strftime('%Y-%m-%dT%H:%M:%SZ', time.gmtime())}\n"
            f"python: {sys.version.split()[0]} on {sys.platform}\n\n"
            + "".join(traceback.format_exception(exc)))
    rdir = (getattr(args, "current_report_dir", None) or getattr(args, "report_dir", None)) if args else None
    if rdir and Path(rdir).is_dir():
        path = Path(rdir) / TRACEBACK_NAME
        try:
            path.write_text(text, encoding="utf-8")
            return str(path)
        except OSError:
            pass
    try:
        fd, name = tempfile.mkstemp(prefix="helmcheck-tester-error-", suffix=".txt")
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        return name
    except OSError as e:
        return f"(not saved: {e.strerror or e})"


def _dispatch(argv: list[str]) -> int:
    args: Optional[argparse.Namespace] = None
    try:
        parser = build_parser()
        try:
            args, extra = parser.parse_known_args(argv)
        except SystemExit as e:  # --help, --version (0) or a usage error (64)
            return e.code if isinstance(e.code, int) else exitcodes.USAGE
        if extra:  # named by the subcommand that got them, not by the top-level parser
            raise UsageError(f"error: unrecognized arguments: {' '.join(extra)} (see '{prog_of(args)} --help')")
        if not getattr(args, "func", None):
            raise UsageError(f"no command given; choose one of {', '.join(SUBCOMMANDS)} "
                             f"(see 'helmcheck --help')")
        if args.command in RECORDS_REVISION:
            from .reports.identity import source_revision
            source_revision()  # the checkout as the run found it (cached for the run)
        return int(args.func(args))
    except Failure as f:
        _say(prog_of(args), f.message)
        return f.code
    except KeyboardInterrupt as e:
        _say(prog_of(args), describe_interrupt(e))
        return INTERRUPT_CODE.get(getattr(args, "command", None) or "", exitcodes.INCONCLUSIVE)
    except Exception as e:  # noqa: BLE001 - the tester-error row of the contracts table
        from .profile import ProfileError
        if isinstance(e, ProfileError):
            _say(prog_of(args), str(e))
            return exitcodes.USAGE
        if isinstance(e, OSError) and e.filename:
            _say(prog_of(args), f"{e.filename}: {e.strerror or e}")
            return exitcodes.INCONCLUSIVE
        where = save_traceback(e, args)
        first = (str(e).splitlines() or [""])[0]
        _say(prog_of(args), f"tester error: {type(e).__name__}{': ' + first if first else ''} — "
                            f"traceback in {where}; please report it")
        return exitcodes.INCONCLUSIVE


def main(argv: Optional[list[str]] = None) -> int:
    """Run one command; returns its exit status (see the module docstring)."""
    entry = argv is None  # the process's own entry point (console script, python -m helmcheck)
    if argv is not None:
        sys.argv[1:] = argv
    saved = sys.stdout, sys.stderr
    out = GuardedStream(sys.stdout, "standard output")
    err = GuardedStream(sys.stderr, "standard error")
    sys.stdout, sys.stderr = out, err  # type: ignore[assignment]
    try:
        with ending_signals(linger=entry):
            code = _dispatch(sys.argv[1:])
            try:
                out.flush()
                if out.error is not None:
                    _say(f"helmcheck {sys.argv[1]}" if sys.argv[1:] else "helmcheck",
                         f"cannot write standard output: {out.error.strerror or out.error}")
                    code = exitcodes.INCONCLUSIVE
                err.flush()
            except KeyboardInterrupt:  # a signal after the command ended changes nothing
                pass
        return code
    finally:
        sys.stdout, sys.stderr = saved


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
