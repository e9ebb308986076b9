"""The ``--line clean|noisy`` option every command that reads a line shares (one help text).

What the two models mean is :mod:`helmcheck.judge.linemodel`; how a port is guessed,
:mod:`helmcheck.line.linekind`.
"""

from __future__ import annotations

import argparse

__all__ = ["add_line_argument"]

_HELP = ("whether the link can damage bytes. clean: it cannot (a pty, TCP to this host): every "
         "broken line, lost byte and missing answer is the implementation's at once. noisy: "
         "it can (a UART, a serial server elsewhere): an error the line could have made is judged only "
         "when the observation, made again, repeats it. Default: {default}; the report says which and why")


def add_line_argument(p: argparse.ArgumentParser, default: str = "guessed from the port") -> None:
    p.add_argument("--line", choices=("clean", "noisy"), default=None, help=_HELP.format(default=default))
