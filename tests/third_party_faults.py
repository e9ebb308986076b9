"""Faulty variants of the independent simulator: ``python tests/third_party_faults.py FAULT [uvc_sim args]``.

Each fault changes one behaviour of ``../shared/third-party/uvc_sim.py`` (imported from there,
never copied) the way a firmware bug would, then runs its ``main``. They are vehicles we did not
write with one defect each: a case must tell each from the conforming simulator on the clause
the fault breaks (``tests/test_third_party_vehicle.py``). ``FAULT`` is a key of :data:`FAULTS`;
``ok-…`` variants stay inside the bound their faulty twin crosses.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

SIM_DIR = Path(__file__).resolve().parents[2] / "shared" / "third-party"


def _late_deadline(sim, extra_s: float):
    """``$OMS`` control released ``extra_s`` vehicle seconds after its timeout (RH-SRV-4, RH-TIM-1)."""
    real = sim.Vehicle.c_OMS

    def c_OMS(self, f, data):
        real(self, f, data)
        if self.remote is not None and self.remote.kind == "A":
            self.remote.deadline += extra_s
    sim.Vehicle.c_OMS = c_OMS


def _next_waypoint_after_release(sim):
    """When servo control times out, head for the waypoint after the one it was heading for (RH-INT-2)."""
    real = sim.Vehicle.release

    def release(self, why):
        kind = self.remote.kind if self.remote is not None else None
        real(self, why)
        m = self.mission
        if kind == "A" and m is not None and m.mode == "N" and m.wp + 1 < len(m.wps):
            m.wp += 1
    sim.Vehicle.release = release


def _omp_nine_hex(sim):
    """``$OMP`` field 1 of nine hex digits accepted (RH-PRM-2)."""
    real = sim.Vehicle.c_OMP

    def c_OMP(self, f, data):
        if len(f) == 3 and len(f[0]) == 9:
            f = [f[0] + "0", f[1], f[2]]
        return real(self, f, data)
    sim.Vehicle.c_OMP = c_OMP


def _no_omp_after_lockout(sim):
    """``$OMP`` stays refused (26) after the lockout until the surface (RH-SAF-3)."""
    real = sim.Vehicle.locked

    def locked(self, ident):
        s = self.safety
        if s is not None and s.phase == "ascent" and ident == "OMP":
            return True
        return real(self, ident)
    sim.Vehicle.locked = locked


def _unknown_id_answered(sim):
    """A line of an unknown ID answered ``$ACK,0,1,0`` (RH-FRM-5)."""
    real = sim.Vehicle.on_line

    def on_line(self, ep, raw, now):
        cmd, _ = sim.parse_line(raw)
        if cmd is not None and cmd[0] not in sim.ACK_TYPE and cmd[0] != "OXFLT":
            self.emit(ep, self.frame("ACK,0,1,0").encode("latin-1"))
            return None
        return real(self, ep, raw, now)
    sim.Vehicle.on_line = on_line


def _ack_late(sim, delay_s: float):
    """Every command processed — and so answered — ``delay_s`` wall seconds after it arrived
    (RH-ACK-2; RH-RD-15: its effects date from its ACK, as the profile reads a slow vehicle)."""
    real = sim.Vehicle.on_line

    def on_line(self, ep, raw, now):
        time.sleep(delay_s)
        now = time.monotonic()
        self.advance(self.vclock(now))
        return real(self, ep, raw, now)
    sim.Vehicle.on_line = on_line


def _arrive_within(sim, metres: float):
    """"On station" (waypoints, parks) at ``metres`` instead of 3 m (RH-RD-5, RH-PK-2)."""
    sim.ARRIVE_M = metres


FAULTS = {
    "park-counts-7m-off": lambda sim: _arrive_within(sim, 7.0),
    "ok-park-counts-2.5m-off": lambda sim: _arrive_within(sim, 2.5),
    "timeout-late-0.7": lambda sim: _late_deadline(sim, 0.7),
    "ok-timeout-late-0.3": lambda sim: _late_deadline(sim, 0.3),
    "release-to-next-waypoint": _next_waypoint_after_release,
    "omp-nine-hex": _omp_nine_hex,
    "omp-refused-after-lockout": _no_omp_after_lockout,
    "unknown-id-answered": _unknown_id_answered,
    "ack-late-1.3": lambda sim: _ack_late(sim, 1.3),
    "ok-ack-at-0.6": lambda sim: _ack_late(sim, 0.6),
}


def main(argv: list[str]) -> int:
    fault, rest = argv[0], argv[1:]
    sys.path.insert(0, str(SIM_DIR))
    import uvc_sim  # noqa: E402 - the simulator as its authors ship it

    FAULTS[fault](uvc_sim)
    return uvc_sim.main(rest) or 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
