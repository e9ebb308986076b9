"""``helmcheck report``: render a results directory (see :mod:`helmcheck.reports.render`)."""

from __future__ import annotations

import argparse

from ..reports import render


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = sub.add_parser("report", help="render results.json to HTML, JUnit XML and Markdown",
                       description=render.__doc__.strip().splitlines()[0] if render.__doc__ else None,
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    render.add_arguments(p)
    p.set_defaults(func=render.run)
    return p
