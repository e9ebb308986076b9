"""``make demo``: certify the built-in emulator end to end and write every report format.

Starts ``helmcheck emulate`` on a pty at time scale 40 as a subprocess, runs
``helmcheck certify vehicle`` against it with the emulator's own profile
(``helmcheck/profiles/emulator.toml``: the ``$OXFLT`` test extension, so the lockout clauses
are judged too, and the missions it ships for RH-MSN-4 and the SRP branch of RH-SAF-4), writes
``reports/demo/{results.json, wire.log, report.html, junit.xml, report.md}``, stops the emulator, and prints the one-line verdict and
the report's path. Exit status is the certification's.
"""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

from .emulator.process import EmulatorProcess
from .certify.vehicle.runner import Options, certify
from .profile import EMULATOR_PROFILE, emulator_profile

TIME_SCALE = 40.0
BAUD = 115200


def main(argv: list[str] | None = None) -> int:
    out = Path("reports") / "demo"
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
                              examples=10, seed=1, progress=sys.stderr.isatty(),
                              command=f"helmcheck certify vehicle --port {emu.port} --time-scale {TIME_SCALE:g} "
                                      f"--baud {BAUD} --profile helmcheck/{EMULATOR_PROFILE} --examples 10 --seed 1 "
                                      f"--report-dir {out}"))
    finally:
        emu.stop()
    print(f"{res.verdict.upper()}: {res.reason}")
    print(f"report: {out / 'report.html'} (also results.json, wire.log, junit.xml, report.md)")
    return res.exit_code


if __name__ == "__main__":
    sys.exit(main())
