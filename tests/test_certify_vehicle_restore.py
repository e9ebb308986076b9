"""The vehicle left as found: settings read before they are written, written back and read again
at the end of every run — also after SIGTERM — and a restore that cannot be verified is exit 2 (1, named
beside the verdict, when the run failed).

Real vehicles here: the emulator as a subprocess with its settings kept in a file
(``helmcheck emulate --settings``), and faulty vehicles served behind ptys: one that will not
read a setting (so the tester must never write it) and one whose settings stick at the first
value written (so the restore cannot be verified).
"""

from __future__ import annotations

import signal
import subprocess
import sys
from pathlib import Path

from helmcheck.emulator.process import EmulatorProcess, HelmClient
from helmcheck.line.transport import open_link
from helmcheck.certify.vehicle.runner import Options, certify
from helmcheck.grammar import sentences as s
from helmcheck.reports.results import load_results
from tests.faulty_vehicles.base import EMU_PROFILE, EmulatorCore, Model, Mutant, make_core, reframe, serve
from tests.waiting import wait_for_text

K = 40.0
SETTINGS = ("Sop", "SafetyAction")


def _read_settings(port: str) -> dict:
    """What the vehicle says its settings are, read as a backseat would (the vehicle in S)."""
    link = open_link(port, role="client", baud=115200)
    try:
        c = HelmClient(link)
        c.send("OMSTOP,0")
        c.drain(0.3)
        out = {}
        for name in SETTINGS:
            c.send(f"ORWSET,{name},R")
            acks = [x for x in c.drain(0.3) if x.startswith(b"$ACK,12,")]
            assert acks, name
            out[name] = acks[-1].split(b"*")[0].decode()
        return out
    finally:
        link.close()



def test_sigterm_in_the_middle_of_a_settings_case_leaves_the_settings_as_found(tmp_path):
    rdir = tmp_path / "r"
    prof = tmp_path / "emu.toml"
    prof.write_text('fault_injection = "oxflt"\nbaud = 115200\nsrp_mission = "srp.mis"\n')
    with EmulatorProcess(["--settings", str(tmp_path / "settings.json")], time_scale=K, baud=115200) as emu:
        before = _read_settings(emu.port)
        proc = subprocess.Popen([sys.executable, "-m", "helmcheck", "certify", "vehicle", "--port", emu.port,
                                 "--time-scale", str(K), "--profile", str(prof), "--select", "RH-SAF-4",
                                 "--examples", "0", "--no-progress", "--report-dir", str(rdir)],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, stdin=subprocess.DEVNULL)
        try:
            wait_for_text(rdir / "wire.log", "$ORWSET,SafetyAction,W,1,srp")  # V-63 wrote srp: SIGTERM now
            proc.send_signal(signal.SIGTERM)
            out, err = proc.communicate(timeout=90)
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait()
        after = _read_settings(emu.port)
    assert after == before, (before, after)
    assert b"Traceback" not in err
    r = load_results(rdir)
    assert r["partial"] is True and proc.returncode == 2, out
    rec = r["restore"]
    assert rec["verified"] is True and rec["left"]["mode"] == "S", rec
    sa = next(x for x in rec["settings"] if x["name"] == "SafetyAction")
    assert sa["written"] and sa["before"] == sa["after"] == before["SafetyAction"].split(",")[6:], (sa, before)
    assert "Vehicle restored" in (rdir / "report.html").read_text()


class WillNotReadSettings(EmulatorCore):
    """$ORWSET reads refused (err 23), writes accepted: the tester cannot know what to restore."""

    def _line(self, raw, now, v):
        if raw.startswith(b"$ORWSET,") and b",R*" in raw:
            return self._send(reframe(raw, b"ACK,12,1,23"), now)
        return super()._line(raw, now, v)


class SticksAtFirstWrite(Model):
    """Each setting keeps the first value written to it; later writes are acknowledged, ignored."""

    stuck: frozenset = frozenset()

    def receive(self, item, now):
        if isinstance(item, s.ORWSET) and item.access == "W":
            if item.setting in self.stuck:
                before = self.settings.copy()
                out = super().receive(item, now)
                self.settings = before
                return out
            self.stuck = self.stuck | {item.setting}
        return super().receive(item, now)


def _certify(port: str, tmp_path: Path, select: list[str]):
    return certify(Options(port=port, profile=EMU_PROFILE.replace(time_scale=K, srp_mission="srp.mis"),
                           time_scale=K, report_dir=tmp_path / "r", select=select, examples=0, progress=False,
                           render=True, seed=1))


def test_a_setting_whose_value_cannot_be_read_is_never_written(tmp_path):
    m = Mutant("will-not-read-settings", "RH-SET-2", ("RH-SET-2",), core=WillNotReadSettings)
    with serve(lambda start: make_core(m, K, start)) as port:
        out = _certify(port, tmp_path, ["RH-SET-2"])
    wire = (tmp_path / "r" / "wire.log").read_text()
    writes = [ln for ln in wire.splitlines()  # lines sent: a $GPRMC's west longitude is ",W," too
              if " > $ORWSET," in ln and ",W," in ln and "$ORWSET,Bogus" not in ln]
    assert not writes, f"a setting was written without its restore known: {writes}"
    set2 = next(c for c in out.results["clauses"] if c["id"] == "RH-SET-2")
    assert set2["verdict"] != "pass", set2


def test_a_restore_that_does_not_stick_is_named_beside_the_fail_and_what_to_set_by_hand(tmp_path, capsys):
    """The vehicle fails RH-SET-2 (a write does not stick) and so cannot be restored either: the
    run is non-conformant (exit 1, the verdict stands), and its reason names the restore too."""
    m = Mutant("sticks-at-first-write", "RH-SET-2", ("RH-SET-2",), model=SticksAtFirstWrite)
    with serve(lambda start: make_core(m, K, start)) as port:
        out = _certify(port, tmp_path, ["RH-SET-2"])
    rec = out.results["restore"]
    assert out.verdict == "fail" and out.exit_code == 1, (out.verdict, rec)
    assert "NOT verified as restored" in out.reason and "$ORWSET,Sop,W," in out.reason, out.reason
    assert rec["verified"] is False
    sop = next(x for x in rec["settings"] if x["name"] == "Sop")
    assert sop["written"] and sop["after"] != sop["before"]
    assert any(h.startswith(f"$ORWSET,Sop,W,{','.join(sop['before'])}") for h in rec["by_hand"]), rec["by_hand"]
    assert "NOT verified as restored" in (tmp_path / "r" / "report.html").read_text()
    assert load_results(tmp_path / "r")["restore"] == rec


def test_a_conforming_vehicle_is_left_stopped_with_its_settings_verified(tmp_path):
    with serve(lambda start: make_core(None, K, start)) as port:
        out = _certify(port, tmp_path, ["RH-SET-2"])
    rec = out.results["restore"]
    assert out.exit_code == 0 and rec["verified"] is True, rec
    assert rec["found"]["mode"] == "S" and rec["left"]["mode"] == "S"
    assert [x["name"] for x in rec["settings"] if x["written"]] == ["Sop", "Sle", "SafetyAction"]  # V-55, V-73

