"""``make demo``: the main job on the built-in emulator, end to end.

Until the certifier exists this validates the sample capture in ``examples/`` with
``helmcheck parse`` and says so; it does not pretend to certify anything.
"""

from __future__ import annotations

import sys
from pathlib import Path

from .cli import main as cli_main


def main() -> int:
    sample = Path(__file__).resolve().parent.parent / "examples" / "sample-capture.log"
    print(f"demo: validating {sample.name} line by line (certification not built yet)")
    return cli_main(["parse", str(sample)])


if __name__ == "__main__":
    sys.exit(main())
