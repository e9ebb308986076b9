"""Faulty variants of the independent simulator: ``python tests/third_party_faults.py FAULT [uvc_sim args]``.

Each fault changes one behaviour of ``../shared/third-party/uvc_sim.py`` (imported from there,
never copied) the way a firmware bug would, then runs its ``main``. They are vehicles we did not
write with one defect each: a case must tell each from the conforming simulator on the clause
the fault breaks (``tests/test_third_party_vehicle.py``). ``FAULT`` is a key of :data:`FAULTS`;
``ok-…`` variants stay inside the bound their faulty twin crosses.
"""

from __future__ import annotations

import os
import re
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


# ---- §1 framing ---------------------------------------------------------------------------------

def _lowercase_checksum_out(sim):
    """Checksums written in lower-case hex (RH-FRM-3: a vehicle emits upper-case checksum hex)."""
    def frame(self, body):
        return f"${body}*{sim.xor(body.encode('latin-1')):02x}\r\n"
    sim.Vehicle.frame = frame


def _accepts_wrong_checksum(sim):
    """A line whose checksum is wrong is executed anyway (RH-FRM-4: discarded silently, no ACK, no
    state change); missing or malformed checksums are still discarded."""
    real = sim.parse_line

    def parse_line(raw):
        cmd, why = real(raw)
        if why == "wrong checksum":
            parts = sim.LINE_RE.match(raw).group(1).decode("latin-1").split(",")
            if re.fullmatch("[A-Z]+", parts[0]):
                return (parts[0], parts[1:]), ""
        return cmd, why
    sim.parse_line = parse_line


def _line_limit(sim, nbytes: int):
    """Receive buffer of ``nbytes`` instead of 256: longer lines are executed (RH-FRM-6)."""
    sim.MAX_LINE = nbytes


def _bare_lf_discarded(sim):
    """Only CR LF ends a line; one ended by a bare LF is discarded (RH-FRM-7: a bare LF terminator is
    accepted by a vehicle)."""
    sim.LINE_RE = re.compile(rb"\$([^*]*)\*([0-9A-Fa-f]{2})\r\n\Z")


# ---- §2 acknowledgements ------------------------------------------------------------------------

def _opos_not_acked(sim):
    """``$OPOS`` applied but never acknowledged (RH-ACK-1: every command gets exactly one ``$ACK``)."""
    real = sim.Vehicle.reply

    def reply(self, ep, data, ack):
        if ack.startswith("ACK,6,"):
            return None
        return real(self, ep, data, ack)
    sim.Vehicle.reply = reply


def _opk_bad_fields_err_21(sim):
    """``$OPK`` with bad fields rejected with ``$OMP``'s error 21 instead of its own 22 (RH-ACK-3)."""
    real = sim.Vehicle.c_OPK

    def c_OPK(self, f, data):
        try:
            return real(self, f, data)
        except sim.Reject as e:
            if e.err == 22 and e.why == "fields":
                raise sim.Reject(21, e.why) from None
            raise
    sim.Vehicle.c_OPK = c_OPK


def _precondition_err_17(sim):
    """A command refused for its state precondition answers err 17 ("cannot start") instead of the
    command's own incorrect-values error (RH-ACK-4)."""
    real = sim.Reject.__init__

    def __init__(self, err, why="fields"):
        real(self, sim.E_START if why == "state" else err, why)
    sim.Reject.__init__ = __init__


def _osd_ack_before_data(sim):
    """``$ACK,8`` written before the ``$OSD`` data sentences (RH-ACK-5: data first)."""
    def reply(self, ep, data, ack):
        lines = [self.frame(ack)] + [self.frame(d) for d in data]
        self.emit(ep, "".join(lines).encode("latin-1"))
    sim.Vehicle.reply = reply


def _osd_served_after_batch(sim):
    """``$OSD`` requests are served at low priority: among the lines of one read, the other commands
    go first (RH-ACK-6: processed and answered in arrival order)."""
    real = sim.Framer.feed

    def feed(self, data):
        out = real(self, data)
        osd = [x for x in out if x[0] == "LINE" and x[1].startswith(b"$OSD")]
        return [x for x in out if not (x[0] == "LINE" and x[1].startswith(b"$OSD"))] + osd
    sim.Framer.feed = feed


# ---- §3 output sentences ------------------------------------------------------------------------

def _osi_20_fields(sim):
    """``$OSI`` with 20 fields: the last reserved field is not sent (RH-OUT-1: rh5 has 21)."""
    real = sim.Vehicle.s_S

    def s_S(self):
        return real(self).rsplit(",", 1)[0]
    sim.Vehicle.s_S = s_S


def _battery_raw_scale(sim):
    """``$OSI`` field 16 (battery percent) sent on the gauge's raw 0–255 scale (RH-OUT-3: percent in
    [0, 100])."""
    real = sim.Vehicle.s_S

    def s_S(self):
        parts = real(self).split(",")
        parts[16] = f"{self.battery * 2.55:.1f}"
        return ",".join(parts)
    sim.Vehicle.s_S = s_S


# ---- §4 control commands ------------------------------------------------------------------------

def _no_mission_precondition(sim, ident: str):
    """``$<ident>`` accepted with no mission running: the "mission running" precondition is not
    checked (for ``OMS``: RH-SRV-1; likewise RH-PK-1 for ``OPK``, RH-OMW-1 for ``OMW``)."""
    real = getattr(sim.Vehicle, "c_" + ident)

    def handler(self, f, data):
        if self.mission is not None:
            return real(self, f, data)
        self.mission = object()          # the "mission running?" check always passes
        try:
            return real(self, f, data)
        finally:
            self.mission = None
    setattr(sim.Vehicle, "c_" + ident, handler)


def _oms_heading_360(sim):
    """``$OMS`` heading checked against the closed range [0, 360]: 360 accepted (RH-SRV-2: [0,360))."""
    real = sim.Vehicle.c_OMS

    def c_OMS(self, f, data):
        if len(f) == 5 and sim.DEC.fullmatch(f[0]) and float(f[0]) == 360.0:
            f = ["0", *f[1:]]
        return real(self, f, data)
    sim.Vehicle.c_OMS = c_OMS


def _oms_refresh_keeps_deadline(sim):
    """A new ``$OMS`` in ``A`` updates the set-points but not the timeout (RH-SRV-3: each accepted
    ``$OMS`` restarts it)."""
    real = sim.Vehicle.c_OMS

    def c_OMS(self, f, data):
        r = self.remote
        old = r.deadline if r is not None and r.kind == "A" else None
        real(self, f, data)
        if old is not None and self.remote is r:
            r.deadline = old
    sim.Vehicle.c_OMS = c_OMS


def _omp_fins_reversed(sim):
    """In ``M``, ``$OSI`` field 1 echoes the commanded bytes in reverse order (motor first)
    (RH-PRM-3: field 1 reports the commanded bytes)."""
    real = sim.Vehicle.fins

    def fins(self):
        r = self.remote
        if r is not None and r.kind == "M":
            return bytes(reversed(r.fins))
        return real(self)
    sim.Vehicle.fins = fins


def _omp_timeout_fins_stuck(sim):
    """When a primitive entered from ``S`` times out, fins and motor keep the last command instead of
    going neutral (RH-PRM-4: back to ``S`` with ``8080808080``)."""
    real_release, real_fins = sim.Vehicle.release, sim.Vehicle.fins

    def release(self, why):
        r = self.remote
        self._stuck = r.fins if r is not None and r.kind == "M" and self.mission is None else None
        real_release(self, why)

    def fins(self):
        stuck = getattr(self, "_stuck", None)
        if stuck is not None and self.remote is None and self.mission is None:
            return stuck
        return real_fins(self)
    sim.Vehicle.release, sim.Vehicle.fins = release, fins


def _ojw_last_waypoint_refused(sim):
    """``$OJW`` to the last waypoint refused (19): an off-by-one range check (RH-JW-1: n in
    [0, waypoints−1])."""
    real = sim.Vehicle.c_OJW

    def c_OJW(self, f, data):
        if (len(f) == 1 and re.fullmatch("[0-9]+", f[0]) and self.mission is not None
                and int(f[0]) == len(self.mission.wps) - 1):
            raise sim.Reject(19)
        return real(self, f, data)
    sim.Vehicle.c_OJW = c_OJW


def _ojw_keeps_remote(sim):
    """``$OJW`` sets the mission's next waypoint but leaves the active remote control running
    (RH-JW-2: it ends A, M, mP, W; the mode becomes ``N``)."""
    real = sim.Vehicle.c_OJW

    def c_OJW(self, f, data):
        r = self.remote
        real(self, f, data)
        self.remote = r
    sim.Vehicle.c_OJW = c_OJW


def _release_ends_mission(sim, why: str):
    """When remote control ends for ``why``, the mission is stopped (``S``) instead of resumed
    (RH-INT-2 via RH-PK-3 / RH-OMW-4)."""
    real = sim.Vehicle.release

    def release(self, reason):
        real(self, reason)
        if reason == why and self.mission is not None:
            self.mission = None
            self.event(f"{reason}: mission ended, mode S")
    sim.Vehicle.release = release


def _omw_replaces_queue(sim):
    """A new ``$OMW`` in ``W`` replaces the on-the-fly waypoint instead of queueing behind it
    (RH-OMW-2: waypoints queue in arrival order)."""
    real = sim.Vehicle.c_OMW

    def c_OMW(self, f, data):
        r = self.remote
        was_w = r is not None and r.kind == "W"
        real(self, f, data)
        if was_w and self.remote is r and len(r.queue) > 1:
            last = r.queue[-1]
            r.queue.clear()
            r.queue.append(last)
    sim.Vehicle.c_OMW = c_OMW


def _omw_clear_synonyms_refused(sim):
    """Only ``Clr`` is known as the ``$OMW`` keyword: ``CLEAR`` and ``STOP`` are rejected (36)
    (RH-OMW-3: accepted as synonyms)."""
    real = sim.Vehicle.c_OMW

    def c_OMW(self, f, data):
        if f and f[0].upper() in ("CLEAR", "STOP"):
            raise sim.Reject(36)
        return real(self, f, data)
    sim.Vehicle.c_OMW = c_OMW


def _resume_interrupted(sim, kind):
    """A remote control of ``kind`` (any kind when ``None``) that another control interrupts is kept
    aside and taken up again when that control ends: a stack of remote controls
    (RH-INT-1, RH-INT-3, RH-OMW-5)."""
    real_takeover, real_release, real_drop = sim.Vehicle.takeover, sim.Vehicle.release, sim.Vehicle.drop_remote

    def takeover(self, new):
        old = self.remote
        if old is not None and old.kind != new.kind and (kind is None or old.kind == kind):
            self._held = old
        real_takeover(self, new)

    def release(self, why):
        held, self._held = getattr(self, "_held", None), None
        real_release(self, why)
        if held is not None and self.mission is not None:
            self.remote = held
            self.event(f"{why}: interrupted {held.kind} taken up again")

    def drop_remote(self):
        self._held = None
        real_drop(self)
    sim.Vehicle.takeover, sim.Vehicle.release, sim.Vehicle.drop_remote = takeover, release, drop_remote


# ---- §5 mission commands ------------------------------------------------------------------------

def _omload_path_traversal(sim):
    """Mission names are checked for an absolute path and a drive letter only: a ``..`` component is
    followed out of the mission directory (RH-MSN-1: rejected with 29, nothing outside opened)."""
    def bad_path(name):
        return (not name or "\0" in name or name[0] in "/\\" or re.match(r"[A-Za-z]:", name) is not None)

    def load(self, name, err_bad, err_missing=sim.E_NOTFOUND):
        if sim.bad_path(name):
            raise sim.Reject(err_bad)
        path = os.path.join(self.mdir, *re.split(r"[\\/]", name))
        if not os.path.isfile(path):
            raise sim.Reject(err_missing, "not found")
        try:
            with open(path, encoding="latin-1") as fh:
                return sim.parse_mission(fh.read(1 << 20))
        except (OSError, ValueError):
            raise sim.Reject(sim.E_LOADERR if err_missing == sim.E_NOTFOUND else err_missing, "load error")
    sim.bad_path, sim.Vehicle.load = bad_path, load


def _omstop_keeps_remote(sim):
    """``$OMSTOP`` stops the mission but leaves the active remote control (A, M, W) running
    (RH-MSN-3: mode ``S``, remote control cleared, fins and motor neutral)."""
    real = sim.Vehicle.c_OMSTOP

    def c_OMSTOP(self, f, data):
        r = self.remote
        real(self, f, data)
        self.remote = r
    sim.Vehicle.c_OMSTOP = c_OMSTOP


def _mission_end_loops(sim):
    """After the last waypoint the mission starts over at waypoint 0 (RH-MSN-4: the mode becomes ``S``)."""
    real = sim.Vehicle.next_wp

    def next_wp(self, m):
        if m.wp + 1 >= len(m.wps):
            m.mode, m.park_left, m.wp = "N", 0.0, 0
            return self.event("mission complete: starting over at waypoint 0")
        return real(self, m)
    sim.Vehicle.next_wp = next_wp


# ---- §6 read/write commands ---------------------------------------------------------------------

def _opos_applied_with_fix(sim):
    """``$OPOS`` position and speed applied even with a valid GPS fix (RH-POS-2: only without one)."""
    real = sim.Vehicle.c_OPOS

    def c_OPOS(self, f, data):
        real(self, f, data)
        self.lat, self.lon, self.speed = float(f[0]), float(f[1]), float(f[2])
    sim.Vehicle.c_OPOS = c_OPOS


def _osd_canonical_order(sim):
    """``$OSD`` replies in the vehicle's sensor-table order (G C S P Y D T I), not the order requested
    (RH-OSD-1: replies come in the order requested)."""
    real = sim.Vehicle.c_OSD

    def c_OSD(self, f, data):
        letters = [x for x in f if x]
        if all(len(x) == 1 and x in sim.OSD_LETTERS for x in letters):
            f = sorted(letters, key=sim.OSD_LETTERS.index)
        return real(self, f, data)
    sim.Vehicle.c_OSD = c_OSD


def _osd_unknown_letter_skipped(sim):
    """An ``$OSD`` field outside ``GCSPYDTI`` is skipped and the rest served, ``$ACK,8,0,0``
    (RH-OSD-2: the request is rejected, err 27, no data)."""
    real = sim.Vehicle.c_OSD

    def c_OSD(self, f, data):
        return real(self, [x for x in f if len(x) == 1 and x in sim.OSD_LETTERS], data)
    sim.Vehicle.c_OSD = c_OSD


def _accepted_during_mission(sim, ident: str):
    """``$<ident>`` accepted while a mission runs (for ``OLOGL``: RH-LOG-1, accepted only in ``S``;
    likewise RH-SET-1 for ``ORWSET``)."""
    real = getattr(sim.Vehicle, "c_" + ident)

    def handler(self, f, data):
        m, self.mission = self.mission, None      # the "no mission running?" check always passes
        try:
            return real(self, f, data)
        finally:
            self.mission = m
    setattr(sim.Vehicle, "c_" + ident, handler)


def _ologd_extra_values_accepted(sim):
    """``$OLOGD`` with more values than ``$OLOGL`` labels accepted, the extra ones dropped
    (RH-LOG-2: at most as many values as labels)."""
    real = sim.Vehicle.c_OLOGD

    def c_OLOGD(self, f, data):
        if self.labels and len(f) > len(self.labels):
            f = f[:len(self.labels)]
        return real(self, f, data)
    sim.Vehicle.c_OLOGD = c_OLOGD


def _orwset_write_not_stored(sim):
    """``$ORWSET`` writes are acknowledged (echoing the written values) but not stored
    (RH-SET-2: a read returns the written state and values)."""
    real = sim.Vehicle.c_ORWSET

    def c_ORWSET(self, f, data):
        saved = dict(self.settings)
        try:
            return real(self, f, data)
        finally:
            self.settings = saved
    sim.Vehicle.c_ORWSET = c_ORWSET


def _odvl_refused_in_s(sim):
    """``$ODVL`` refused (35) when no mission runs (RH-DVL-1: accepted in any mode outside the lockout)."""
    real = sim.Vehicle.c_ODVL

    def c_ODVL(self, f, data):
        if self.mission is None:
            raise sim.Reject(35, "state")
        return real(self, f, data)
    sim.Vehicle.c_ODVL = c_ODVL


# ---- §7 safety ----------------------------------------------------------------------------------

def _lockout(sim, seconds: float):
    """The lockout lasts ``seconds`` instead of ``lockout_s`` = 20 s (RH-SAF-1)."""
    sim.LOCKOUT_S = seconds


def _omp_applied_after_lockout(sim):
    """An ``$OMP`` refused (26) during the lockout is kept and carried out when the lockout ends
    (RH-SAF-2: a command sent during the lockout has no effect even after it ends)."""
    real_on_line, real_fire = sim.Vehicle.on_line, sim.Vehicle.fire_events

    def on_line(self, ep, raw, now):
        cmd, _ = sim.parse_line(raw)
        s = self.safety
        if cmd is not None and cmd[0] == "OMP" and s is not None and s.phase == "lockout":
            self._deferred = cmd[1]
        return real_on_line(self, ep, raw, now)

    def fire_events(self):
        real_fire(self)
        f = getattr(self, "_deferred", None)
        if f is not None and (self.safety is None or self.safety.phase != "lockout"):
            self._deferred = None
            try:
                self.c_OMP(f, [])
                self.event("deferred OMP carried out after the lockout")
            except sim.Reject:
                pass
    sim.Vehicle.on_line, sim.Vehicle.fire_events = on_line, fire_events


def _surface_resumes_mission(sim):
    """At the surface after a violation the mission simply resumes; ``SafetyAction`` is not carried
    out (RH-SAF-4: ``park`` → mode ``P`` at the present position, no end time)."""
    def safety_action(self):
        self.safety = None
        self.event(f"at the surface after the violation: mode {self.mode()}")
    sim.Vehicle.safety_action = safety_action


def _code_cleared_after_lockout(sim):
    """``$OSI`` field 8 goes back to ``N`` as soon as the lockout ends (RH-RD-13: it keeps the code
    through the ascent and SafetyAction, until ``$OMSTOP``/``$OMSTART``; RH-SAF-4)."""
    real = sim.Vehicle.fire_events

    def fire_events(self):
        s = self.safety
        was = s is not None and s.phase == "lockout"
        real(self)
        if was and (self.safety is None or self.safety.phase != "lockout"):
            self.err_state = "N"
    sim.Vehicle.fire_events = fire_events


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
    # §1 framing
    "checksum-lowercase-out": _lowercase_checksum_out,
    "wrong-checksum-accepted": _accepts_wrong_checksum,
    "line-limit-300": lambda sim: _line_limit(sim, 300),
    "bare-lf-discarded": _bare_lf_discarded,
    # §2 acknowledgements
    "opos-not-acked": _opos_not_acked,
    "opk-bad-fields-err-21": _opk_bad_fields_err_21,
    "precondition-err-17": _precondition_err_17,
    "osd-ack-before-data": _osd_ack_before_data,
    "osd-served-after-batch": _osd_served_after_batch,
    # §3 output sentences
    "osi-20-fields": _osi_20_fields,
    "battery-raw-scale": _battery_raw_scale,
    # §4 control commands and interrupts
    "oms-accepted-in-s": lambda sim: _no_mission_precondition(sim, "OMS"),
    "oms-heading-360-accepted": _oms_heading_360,
    "oms-refresh-keeps-deadline": _oms_refresh_keeps_deadline,
    "omp-fins-echoed-reversed": _omp_fins_reversed,
    "omp-timeout-fins-stuck": _omp_timeout_fins_stuck,
    "ojw-last-waypoint-refused": _ojw_last_waypoint_refused,
    "ojw-keeps-remote": _ojw_keeps_remote,
    "opk-timeup-stops-mission": lambda sim: _release_ends_mission(sim, "OPK park time up"),
    "omw-replaces-queue": _omw_replaces_queue,
    "omw-clear-synonyms-refused": _omw_clear_synonyms_refused,
    "omw-done-stops-mission": lambda sim: _release_ends_mission(sim, "OMW queue done"),
    "omw-resumed-after-interrupt": lambda sim: _resume_interrupted(sim, "W"),
    "remote-control-stack": lambda sim: _resume_interrupted(sim, None),
    "opk-resumed-after-interrupt": lambda sim: _resume_interrupted(sim, "mP"),
    # §5 mission commands
    "omload-path-traversal": _omload_path_traversal,
    "omstop-keeps-remote": _omstop_keeps_remote,
    "mission-end-loops": _mission_end_loops,
    # §6 read/write commands
    "opos-applied-with-fix": _opos_applied_with_fix,
    "osd-canonical-order": _osd_canonical_order,
    "osd-unknown-letter-skipped": _osd_unknown_letter_skipped,
    "ologl-during-mission": lambda sim: _accepted_during_mission(sim, "OLOGL"),
    "ologd-extra-values-accepted": _ologd_extra_values_accepted,
    "orwset-write-not-stored": _orwset_write_not_stored,
    "odvl-refused-in-s": _odvl_refused_in_s,
    # §7 safety
    "lockout-10s": lambda sim: _lockout(sim, 10.0),
    "omp-applied-after-lockout": _omp_applied_after_lockout,
    "surface-resumes-mission": _surface_resumes_mission,
    "code-cleared-after-lockout": _code_cleared_after_lockout,
}


def main(argv: list[str]) -> int:
    fault, rest = argv[0], argv[1:]
    sys.path.insert(0, str(SIM_DIR))
    import uvc_sim  # noqa: E402 - the simulator as its authors ship it

    FAULTS[fault](uvc_sim)
    return uvc_sim.main(rest) or 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
