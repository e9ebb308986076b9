"""``helmcheck monitor``: a live session judged while it runs, on real ptys and real processes.

* **In line** (``--between``): the reference emulator and the example backseat talk through the
  monitor; the session's results are exactly what ``check-log`` gives for its ``wire.log`` (both
  roles), and ``verify`` re-judges them (the suite's every-run-verifies fixture). A faulty
  backseat (``faulty_backseat.py --fault bad-checksum``, RH-BS-1) and a faulty vehicle (writes
  lower-case checksum hex, RH-FRM-3) are each reported on standard output within one second of
  the record that shows the violation.
* **Tap** (``--tap``): the test is the Y-cable — it carries the bytes between the backseat's pty
  and the emulator and copies each direction to a pty of its own, which the monitor reads; the
  monitor writes nothing, and its results are check-log's for its log.
* **Evidence from the first byte**: SIGKILL in the middle of a session leaves a wire log whose
  every line is a record, which check-log judges; a log rotated by size is one session to
  check-log and verify.
"""

from __future__ import annotations

import json
import os
import re
import select
import signal
import subprocess
import sys
import threading
import time
import tty
from datetime import datetime, timezone
from pathlib import Path

import pytest

from helmcheck.checklog.checker import check_log
from helmcheck.emulator.process import EmulatorProcess
from helmcheck.grammar.wirelog import read_records
from helmcheck.line.pty_link import PtyLink
from helmcheck.profile import DEFAULT
from helmcheck.reports.segments import session_files
from tests import processes

ROOT = Path(__file__).resolve().parents[1]
BACKSEATS = ROOT / "tests" / "backseats"
K = 20.0

pytestmark = pytest.mark.xdist_group("monitor")


class Monitor:
    """``helmcheck monitor`` in a subprocess; its stdout lines are kept with their arrival time."""

    def __init__(self, args: list[str], report_dir: Path):
        self.dir = report_dir
        self.proc = subprocess.Popen([sys.executable, "-m", "helmcheck", "monitor", *args, "--report-dir",
                                      str(report_dir), "--no-tui", "--time-scale", f"{K:g}"],
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=ROOT,
                                     start_new_session=True)
        self.lines: list[tuple[float, str]] = []
        self._t = threading.Thread(target=self._read, daemon=True)
        self._t.start()

    def _read(self) -> None:
        for raw in self.proc.stdout:  # type: ignore[union-attr]
            self.lines.append((time.time(), raw.decode(errors="replace").rstrip("\n")))

    def wait_for(self, pattern: str, timeout: float = 20.0) -> re.Match:
        end = time.time() + timeout
        while time.time() < end:
            for _, ln in self.lines:
                m = re.search(pattern, ln)
                if m:
                    return m
            time.sleep(0.05)
        raise AssertionError(f"no {pattern!r} from the monitor: {self.lines} {self.proc.stderr.read1() if self.proc.poll() is not None else ''}")

    def finish(self, timeout: float = 60.0) -> int:
        code = self.proc.wait(timeout)
        self._t.join(5)
        return code

    def results(self) -> dict:
        return json.loads((self.dir / "results.json").read_text())

    def started(self) -> float:
        """The session's start (wall clock), from the wire log's header."""
        head = (self.dir / "wire.log").read_text().splitlines()[1]
        stamp = re.search(r"started (\S+)Z", head).group(1)
        return datetime.fromisoformat(stamp).replace(tzinfo=timezone.utc).timestamp()


def backseat(port: str, *extra: str, faulty: str = "") -> subprocess.Popen:
    prog = [str(BACKSEATS / "faulty_backseat.py"), port, "--fault", faulty] if faulty else \
        [str(BACKSEATS / "good_backseat.py"), port]
    return subprocess.Popen([sys.executable, *prog, "--time-scale", f"{K:g}", *extra],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)


def stop(proc: subprocess.Popen) -> None:
    processes.stop(proc, within=5.0)


def offline(d: Path) -> list:
    """check-log's clause entries for the session's log."""
    return check_log(d / "wire.log", profile=DEFAULT, role="both").clauses


def same_as_check_log(res: dict, d: Path) -> None:
    live = [(c["id"], c["verdict"], c["reason"]) for c in res["clauses"]]
    got = {c["id"]: (c["verdict"], c["reason"]) for c in offline(d)}
    for cid, verdict, reason in live:
        want_v, want_r = got[cid]
        assert verdict == want_v, (cid, verdict, want_v, reason, want_r)
        assert reason.endswith(want_r) or want_r in reason, (cid, reason, want_r)


def session(tmp_path: Path, seconds: float, vehicle_port: str, *, faulty: str = "", mode: str = "between"):
    mon = Monitor([f"--{mode}", "pty", vehicle_port, "--duration", f"{seconds:g}"], tmp_path / "mon")
    port = mon.wait_for(r"^backseat port: (\S+)").group(1)
    bs = backseat(port, faulty=faulty)
    try:
        code = mon.finish(seconds + 60)
    finally:
        stop(bs)
    return mon, code


# ----------------------------------------------------------------------------- in line

def test_between_the_emulator_and_a_good_backseat_the_verdicts_are_check_logs(tmp_path):
    with EmulatorProcess(time_scale=K) as emu:
        mon, code = session(tmp_path, 10.0, emu.port)
    res = mon.results()
    judged = {c["id"]: c["verdict"] for c in res["clauses"] if c["verdict"] != "not-tested"}
    assert judged.get("RH-ACK-1") == "pass" and judged.get("RH-BS-1") == "pass", judged  # both ways forwarded
    assert not [c for c, v in judged.items() if v == "fail"], res["verdict_reason"]
    assert code in (0, 2)
    assert res["monitor"]["mode"] == "between" and res["monitor"]["relay"]["undelivered"] == {">": 0, "<": 0}
    priority = res["monitor"]["relay_priority"]
    assert priority.startswith(("real-time", "normal (")), priority
    assert f" ! monitor: relay priority {priority}\n" in (mon.dir / "wire.log").read_text()
    same_as_check_log(res, mon.dir)
    assert (mon.dir / "profile.toml").is_file() and (mon.dir / "report.html").is_file()


def _first_fail(mon: Monitor, clause: str) -> float:
    """Seconds between the record that revealed ``clause``'s first violation and the monitor's
    line saying so."""
    started = mon.started()
    for arrived, ln in mon.lines:
        m = re.match(r"\s*([\d.]+) s  FAIL  (\S+)", ln)
        if m and m.group(2) == clause:
            return arrived - (started + float(m.group(1)))
    raise AssertionError(f"no live FAIL for {clause}: {mon.lines}")


@pytest.mark.parametrize("mode", ["between", "tap"])
def test_a_faulty_backseat_is_reported_within_a_second(tmp_path, mode):
    with EmulatorProcess(time_scale=K) as emu:
        mon, code = RUN[mode](tmp_path, 14.0, emu.port, faulty="bad-checksum")
    assert code == 1
    lag = _first_fail(mon, "RH-BS-1")
    assert lag < 1.0, lag
    verdicts = {c["id"]: c["verdict"] for c in mon.results()["clauses"]}
    assert verdicts["RH-BS-1"] == "fail"
    same_as_check_log(mon.results(), mon.dir)


@pytest.mark.parametrize("mode", ["between", "tap"])
def test_a_faulty_vehicle_is_reported_within_a_second(tmp_path, mode):
    sys.path.insert(0, str(ROOT))
    from tests.faulty_vehicles.base import make_core, serve
    from tests.faulty_vehicles.wire import MUTANTS

    [mutant] = [m for m in MUTANTS if m.name == "lowercase-checksum-out"]
    with serve(lambda start: make_core(mutant, K, start)) as port:
        mon, code = RUN[mode](tmp_path, 6.0, port)
    assert code == 1
    assert _first_fail(mon, "RH-FRM-3") < 1.0
    same_as_check_log(mon.results(), mon.dir)


# ----------------------------------------------------------------------------- tap

class YCable(threading.Thread):
    """The wire between the backseat's pty and the emulator's port, each direction copied to a
    tap pty (what a Y-cable gives the two receive lines of two adapters)."""

    def __init__(self, vehicle_port: str):
        super().__init__(daemon=True)
        self.bs = PtyLink(19200)  # the backseat opens bs.name
        self.veh = os.open(vehicle_port, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
        tty.setraw(self.veh)
        self.tap_bs, self.tap_veh = PtyLink(19200), PtyLink(19200)  # the monitor reads their slave ends
        self.running = True

    def run(self) -> None:
        while self.running:
            r, _, _ = select.select([self.bs.master, self.veh], [], [], 0.05)
            if self.bs.master in r:
                data = os.read(self.bs.master, 4096)
                os.write(self.veh, data)
                os.write(self.tap_bs.master, data)
            if self.veh in r:
                try:
                    data = os.read(self.veh, 4096)
                except BlockingIOError:
                    continue
                os.write(self.bs.master, data)
                os.write(self.tap_veh.master, data)

    def close(self) -> None:
        self.running = False
        self.join(2)
        os.close(self.veh)
        for link in (self.bs, self.tap_bs, self.tap_veh):
            link.close()


def tap_session(tmp_path: Path, seconds: float, vehicle_port: str, *, faulty: str = ""):
    """A session through a Y-cable (:class:`YCable`) with the monitor on its two tap lines; the
    monitor must write nothing to either."""
    y = YCable(vehicle_port)
    y.start()
    mon = Monitor(["--tap", y.tap_bs.name, y.tap_veh.name, "--duration", f"{seconds:g}"], tmp_path / "mon")
    deadline = time.monotonic() + 20  # reading both lines once its relay runs (the log says so)
    while "relay priority" not in ((mon.dir / "wire.log").read_text() if (mon.dir / "wire.log").exists() else ""):
        assert time.monotonic() < deadline and mon.proc.poll() is None, "the monitor did not start"
        time.sleep(0.05)
    bs = backseat(y.bs.name, faulty=faulty)
    try:
        code = mon.finish(seconds + 60)
    finally:
        stop(bs)
        written = [os.read(link.master, 65536) if select.select([link.master], [], [], 0)[0] else b""
                   for link in (y.tap_bs, y.tap_veh)]
        y.close()
    assert written == [b"", b""]  # the monitor wrote nothing to either line
    return mon, code


RUN = {"between": session, "tap": tap_session}


def test_a_tap_reads_both_lines_writes_nothing_and_gets_check_logs_verdicts(tmp_path):
    with EmulatorProcess(time_scale=K) as emu:
        mon, code = tap_session(tmp_path, 8.0, emu.port)
    res = mon.results()
    judged = {c["id"]: c["verdict"] for c in res["clauses"] if c["verdict"] != "not-tested"}
    assert judged.get("RH-ACK-1") == "pass" and judged.get("RH-BS-1") == "pass", judged
    assert code in (0, 2) and res["monitor"]["mode"] == "tap"
    same_as_check_log(res, mon.dir)


# ----------------------------------------------------------------------------- evidence

def test_sigkill_leaves_a_log_that_check_log_judges(tmp_path):
    with EmulatorProcess(time_scale=K) as emu:
        mon = Monitor(["--between", "pty", emu.port], tmp_path / "mon")
        bs = backseat(mon.wait_for(r"^backseat port: (\S+)").group(1))
        try:
            time.sleep(4.0)
            os.killpg(mon.proc.pid, signal.SIGKILL)
            mon.finish(10)
        finally:
            stop(bs)
    with open(mon.dir / "wire.log", "rb") as f:
        records = list(read_records(f))  # raises on any line that is not a whole record
    assert len(records) > 20
    verdicts = {c["id"]: c["verdict"] for c in offline(mon.dir)}
    assert verdicts["RH-ACK-1"] == "pass" and verdicts["RH-BS-1"] == "pass"


def test_a_rotated_log_is_one_session_to_check_log_and_verify(tmp_path):
    with EmulatorProcess(time_scale=K) as emu:
        mon = Monitor(["--between", "pty", emu.port, "--duration", "6", "--rotate-mb", "0.001"], tmp_path / "mon")
        bs = backseat(mon.wait_for(r"^backseat port: (\S+)").group(1))
        try:
            mon.finish(60)
        finally:
            stop(bs)
    res = mon.results()
    files = session_files(mon.dir / "wire.log").files
    assert len(files) >= 3 and res["wire_segments"] == [p.name for p in files[1:]]
    assert set(res["digests"]) >= {p.name for p in files}
    same_as_check_log(res, mon.dir)


# ----------------------------------------------------------------------------- usage

@pytest.mark.parametrize("args, says", [
    ([], "one of the arguments --tap --between is required"),
    (["--tap", "a"], "expected 2 arguments"),
    (["--tap", "/dev/null-no", "/dev/null-no", "--between", "a", "b"], "not allowed with"),
    (["--between", "pty", "/dev/no-such-port"], "cannot open"),
    (["--between", "pty", "pty", "--duration", "0"], "--duration"),
])
def test_bad_usage_is_one_line_and_exit_64(tmp_path, args, says):
    proc = subprocess.run([sys.executable, "-m", "helmcheck", "monitor", *args, "--report-dir", str(tmp_path / "r")],
                          capture_output=True, text=True, timeout=30, cwd=ROOT)
    assert proc.returncode == 64, proc.stderr
    assert says in proc.stderr and proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr


def test_sigterm_ends_the_session_as_its_normal_end(tmp_path):
    """Ctrl-C or SIGTERM is how a session of unknown length ends: results, reports, verdict code."""
    with EmulatorProcess(time_scale=K) as emu:
        mon = Monitor(["--between", "pty", emu.port], tmp_path / "mon")
        bs = backseat(mon.wait_for(r"^backseat port: (\S+)").group(1))
        try:
            time.sleep(4.0)
            os.killpg(mon.proc.pid, signal.SIGTERM)
            code = mon.finish(60)
        finally:
            stop(bs)
    res = mon.results()
    assert "SIGTERM" in res["monitor"]["ended"]
    assert code == {"pass": 0, "non-strict": 0, "fail": 1, "inconclusive": 2}[res["verdict"]]
    same_as_check_log(res, mon.dir)
