"""The third vehicle we did not write (``../shared/third-party/vehicle3``): started, its port read.

``vehicle3.py`` makes its own pseudo-terminal and prints ``port: /dev/pts/N`` as its first line;
:func:`vehicle3` starts it (a single-fault mutant with ``mutant``) and yields that port, and ends
it with SIGTERM. :func:`mutants` is its own list (``--list-mutants``: name, clause, fault).
:data:`PROFILE` is the ICS its README gives for it, with the fast line's baud; the time scale is
added per run. :data:`TIMING` names its faults that are timing faults just past RH-TIM-1's
tolerance (tolerance + 0.6 s, its README): told from a conforming vehicle only at the time scale
``--precision nominal`` names (:func:`nominal_scale`).
"""

from __future__ import annotations

import contextlib
import json
import re
import subprocess
import sys
from pathlib import Path
from typing import Iterator, Optional

from tests.processes import announced_port

ROOT = Path(__file__).resolve().parent.parent
V3 = ROOT.parent / "shared" / "third-party" / "vehicle3" / "vehicle3.py"

#: The ICS of its README (every rh5 default but the served letters and the fault injection).
PROFILE = ('protocol = "rh5"\ndepth_unit = "m"\nack_window_s = 1.0\nlockout_s = 20.0\ntimeout_range = [1, 120]\n'
           'max_depth_m = 100.0\nmax_speed_kn = 4.5\nosi_fields = 21\nosd_letters = "GCSPDTI"\n'
           'commands = ["OMS","OMP","OJW","OMSTOP","OMLOAD","OMSTART","OPOS","OSD","OLOGL","OLOGD","ORWSET",'
           '"ODVL","OPK","OMW"]\nmission = "conformance.mis"\nmission_waypoints = 4\nfault_injection = "oxflt"\n'
           'violation_trigger = "oxflt"\nbaud = 115200\n')
#: The fast line its runs use: replies within 40 ms, 115200 baud.
LINE = ("--baud", "115200", "--latency-max-ms", "40")
#: Its timing faults (tolerance + 0.6 s: README, "Mutants").
TIMING = ("oms-timeout-late", "omp-timeout-early", "lockout-short")


def available() -> bool:
    return V3.is_file()


def mutants() -> list[tuple[str, str, str]]:
    """``(name, clause, fault)`` of each single-fault mutant, as the vehicle lists them."""
    out = subprocess.run([sys.executable, str(V3), "--list-mutants"], capture_output=True, text=True, timeout=60)
    rows = []
    for line in out.stdout.splitlines():
        m = re.match(r"(\S+)\s+(RH-[A-Z]+-\d+)\s+(.*)", line)
        if m:
            rows.append((m.group(1), m.group(2), m.group(3).strip()))
    return rows


def profile_text(k: float) -> str:
    return PROFILE + f"time_scale = {k:g}\n"


@contextlib.contextmanager
def vehicle3(tmp: Path, k: float, mutant: str = "", *extra: str) -> Iterator[str]:
    """``vehicle3.py`` on its own pty at time scale ``k`` on the fast line, its missions in
    ``tmp/missions`` and its log in ``tmp/vehicle3.log``; yields its port."""
    tmp.mkdir(parents=True, exist_ok=True)
    cmd = [sys.executable, str(V3), "--time-scale", f"{k:g}", *LINE, "--mission-dir", str(tmp / "missions"),
           "--log", str(tmp / "vehicle3.log"), *(("--mutant", mutant) if mutant else ()), *extra]
    with announced_port(cmd, "vehicle3.py") as port:
        yield port


def certify(tmp: Path, port: str, k: float, *args: str, timeout: float = 1800) -> dict:
    """``helmcheck certify vehicle`` of it into ``tmp/run``: the results."""
    prof = tmp / "profile.toml"
    prof.write_text(profile_text(k))
    subprocess.run([sys.executable, "-m", "helmcheck", "certify", "vehicle", "--port", port, "--time-scale",
                    f"{k:g}", "--profile", str(prof), "--report-dir", str(tmp / "run"), "--overwrite",
                    "--no-progress", *args], capture_output=True, text=True, timeout=timeout)
    return json.loads((tmp / "run" / "results.json").read_text())


def nominal_scale(tmp: Path, k: float = 20.0) -> Optional[float]:
    """The time scale ``--precision nominal`` names for it on this line (measured at ``k``; the
    run stops after the link check), or None when no time scale would do."""
    from helmcheck.judge.linebudget import from_settings
    with vehicle3(tmp, k) as port:
        results = certify(tmp, port, k, "--precision", "nominal", "--select", "RH-POS-1", timeout=300)
    budget = from_settings(((results.get("settings") or {}).get("line_budget")) or {})
    return budget.nominal_scale() if budget is not None else None
