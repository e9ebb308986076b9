"""The ``helmcheck`` command line: one entry point, one module per subcommand.

Exit codes (see :mod:`helmcheck.exitcodes`): 0 conformant, 1 non-conformant, 2 inconclusive or
tester error, 64 usage. Subcommand modules are imported only when used, so ``--help`` is fast.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from . import __version__, exitcodes

#: subcommand -> (module, one-line help). Each module has add_parser(sub) and run(args).
SUBCOMMANDS = {
    "parse": ("helmcheck.commands.parse_cmd", "validate sentences line by line"),
    "emulate": ("helmcheck.commands.emulate_cmd", "run the reference vehicle emulator on a serial port"),
    "certify": ("helmcheck.commands.certify_cmd", "certify a vehicle or a backseat over a serial port"),
    "replay": ("helmcheck.commands.replay_cmd", "re-drive a saved failing sequence against a vehicle"),
    "check-log": ("helmcheck.commands.checklog_cmd", "check a recorded serial log against the model"),
    "report": ("helmcheck.commands.report_cmd", "render a results directory as HTML, JUnit, Markdown"),
    "matrix": ("helmcheck.commands.matrix_cmd", "one overview of several runs: clauses x implementations"),
    "verify": ("helmcheck.commands.verify_cmd", "check a results directory against its evidence and signature"),
    "keygen": ("helmcheck.commands.keygen_cmd", "make an Ed25519 key pair for signing results"),
    "docs": ("helmcheck.commands.docs_cmd", "regenerate the generated documentation"),
}

DESCRIPTION = """\
helmcheck — the formal model and conformance suite for the Iver3 remote helm protocol.

Typical use:
  helmcheck emulate --port pty                     # a reference vehicle on a pseudo-terminal
  helmcheck certify vehicle --port /dev/pts/5      # certify whatever answers on that port
  helmcheck certify backseat --port pty            # play the vehicle, judge a backseat
  helmcheck report reports/demo                    # render results.json to HTML/JUnit/Markdown
  helmcheck matrix out/a out/b --out out/          # several runs side by side, clause by clause
  helmcheck verify reports/demo                    # re-judge the wire log; check the signature
  helmcheck parse wire.log                         # validate a capture line by line

Exit codes: 0 conformant, 1 non-conformant, 2 inconclusive or tester error, 64 usage error.
Run 'helmcheck COMMAND --help' for each command's options.
"""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # usage errors exit 64, not argparse's 2
        self.print_usage(sys.stderr)
        self.exit(exitcodes.USAGE, f"{self.prog}: error: {message}\n")


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


def main(argv: list[str] | None = None) -> int:
    if argv is not None:
        sys.argv[1:] = argv
    parser = build_parser()
    args = parser.parse_args(sys.argv[1:])
    if not getattr(args, "func", None):
        parser.print_help(sys.stderr)
        return exitcodes.USAGE
    try:
        return int(args.func(args))
    except KeyboardInterrupt:
        print("helmcheck: interrupted", file=sys.stderr)
        return exitcodes.INCONCLUSIVE


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
