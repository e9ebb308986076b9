"""``make demo``: certify the built-in emulator end to end and write every report format.

``python -m helmcheck.demo [--out DIR]`` starts ``helmcheck emulate`` on a pty at time scale 40
as a subprocess, runs ``helmcheck certify vehicle`` against it with the emulator's own profile
(the package's ``helmcheck/profiles/emulator.toml``; the recorded command names
``examples/emulator.toml``, the same claims with every key written out: the ``$OXFLT`` test
extension, so the lockout clauses are judged too, and the missions it ships for RH-MSN-4 and the
SRP branch of RH-SAF-4), writes
``DIR/{results.json, wire.log, profile.toml, report.html, junit.xml, report.md}`` and the
emulator's own log beside them, stops the emulator, and prints the verdict line ``certify
vehicle`` prints (the scope, the reason, what coarse timing means), the
report's path (``report: DIR/report.html``) and how to run ``helmcheck`` from the virtual
environment. Exit status is the certification's.

``DIR`` is :data:`DEMO_DIR` (``demo-out/``, ignored by git: ``make demo`` leaves the checkout as
it was, so the certificates made after it do not say ``-dirty``). The example report committed
with the sources, :data:`EXAMPLE_DIR` (``reports/demo/``), is the same run written there:
``make example-report`` regenerates it.
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
from pathlib import Path

from .certify.vehicle.runner import Options, certify
from .emulator.process import EmulatorProcess
from .profile import emulator_profile
from .reports.identity import source_revision
from .reports.scope import exploration_note, headline, precision_note, what_to_change

TIME_SCALE = 40.0
BAUD = 115200
#: Where ``make demo`` writes (relative to the working directory; ignored by git).
DEMO_DIR = Path("demo-out")
#: The example report committed with the sources (``make example-report``).
EXAMPLE_DIR = Path("reports") / "demo"


def _how_to_run() -> str:
    """How to run ``helmcheck`` from the environment this module runs in."""
    here = Path(sys.executable).parent
    if (here / "activate").is_file() and (here / "helmcheck").exists():
        rel = os.path.relpath(here.parent)
        venv = rel if not rel.startswith("..") else str(here.parent)
        return (f"to run helmcheck: . {venv}/bin/activate  (then: helmcheck --help), "
                f"or {venv}/bin/helmcheck without activating")
    return "to run helmcheck: helmcheck --help (or python -m helmcheck --help)"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m helmcheck.demo",
                                     description="Certify the built-in emulator and write every report format.")
    parser.add_argument("--out", type=Path, default=DEMO_DIR,
                        help=f"the results directory, replaced if it exists (default {DEMO_DIR}/)")
    out = parser.parse_args(argv).out
    source_revision()  # the checkout as found, before the run rewrites anything (make example-report)
    if out.exists():
        shutil.rmtree(out)
    out.mkdir(parents=True)
    profile = emulator_profile().replace(baud=BAUD, time_scale=TIME_SCALE)
    print(f"demo: starting the reference emulator on a pty (time scale {TIME_SCALE:g}, {BAUD} baud)…",
          flush=True)
    emu = EmulatorProcess(["--log", str(out / "emulator-wire.log")], time_scale=TIME_SCALE, baud=BAUD)
    try:
        emu.start()
        print(f"demo: emulator on {emu.port}; certifying (about a minute)…", flush=True)
        res = certify(Options(port=emu.port, profile=profile, time_scale=TIME_SCALE, report_dir=out,
                              examples=10, seed=1, progress=True,
                              command=f"helmcheck certify vehicle --port {emu.port} --time-scale {TIME_SCALE:g} "
                                      f"--baud {BAUD} --profile examples/emulator.toml --examples 10 --seed 1 "
                                      f"--report-dir {out}"))
    finally:
        emu.stop()
    notes = [x for x in (what_to_change(res.results), precision_note(res.results), exploration_note(res.results))
             if x]
    print(f"{headline(res.results)}. {res.reason}{''.join(' ' + x for x in notes)}")  # as certify vehicle says it
    print(f"report: {out / 'report.html'}")
    print(f"demo: also {out}/results.json, wire.log, profile.toml, junit.xml, report.md; "
          f"helmcheck verify {out} re-judges it")
    print(f"demo: {_how_to_run()}")
    return res.exit_code


if __name__ == "__main__":
    sys.exit(main())
