"""Realistic wire logs for the benchmarks: a long session of the reference vehicle driven by a
scripted backseat, in virtual time.

``write_session(path, lines, seed=0, faults=False, notes=False)`` writes a helmcheck wire log
(format 1, the one ``helmcheck emulate --log`` writes and ``check-log`` reads) of about ``lines``
lines and returns the number of lines written. The vehicle is the project's own emulator core
(:class:`helmcheck.emulator.core.EmulatorCore`: the reference model and the plant, sans-IO), run
at time scale 1 and 19200 baud with the clock an argument, so every vehicle line is what a
conforming vehicle answers at that moment — positions, times, attitude, battery, modes and park
counters all move, as a real vehicle's do. The backseat is a script of what a mission-support
computer does (:class:`Backseat`): it polls ``$OSD,G,C,S`` (now and then ``P``) twice a second,
starts missions by name, steers servo episodes (``$OMS`` refreshed at a third of its timeout,
then released by timeout or ``$OMW,Clr``), parks (``$OPK``), queues on-the-fly waypoints
(``$OMW``), jumps (``$OJW``), reports positions (``$OPOS``) and log data (``$OLOGL``/``$OLOGD``),
reads a setting while stopped (``$ORWSET``), stops and restarts missions, and waits out the odd
safety lockout (an operator tripping the leak sensor, as on a bench) with ``$OSD`` only.

``faults=True`` adds a handful of faults at fixed points of the session, each on its clause:
the vehicle acknowledges a line with a wrong checksum (RH-FRM-4; the backseat's bad line is an
RH-BS-1 finding too), an ``$ACK`` is lost (RH-ACK-1, RH-ACK-2), and an out-of-range ``$OMS``
(timeout 150 s: RH-BS-2) is acknowledged as accepted (RH-SRV-2, the range the vehicle should
have refused it by). They go in between 15 % and 90 % of the lines, each while a mission runs:
a session of fewer than some thousands of lines may have room for none.

The backseat does what once made ``check-log`` FAIL a conforming vehicle's answers, so that
the sessions keep those situations judged: an ``$OPK`` over a running mission park (and the
mission park resumed when the ``$OPK`` time is up, RH-INT-2 —
``tests/test_checklog_opk_over_park.py``), ``$OMW`` waypoints with a park time (RH-OMW-4 —
``tests/test_checklog_omw_park.py``), waypoints appended to a queue the vehicle is following
(RH-OMW-2 — ``tests/test_checklog_omw_queue.py``), and
``$OPOS`` fixes a few metres off the vehicle's own last reported position (RH-POS-2 applies them
while it is submerged — ``tests/test_checklog_opos_arrival.py``). The emulator's own notes (plant
and model events) are left out: a recording of a real vehicle's line has none; ``notes=True``
(``--notes``) keeps them, as ``helmcheck emulate --log`` writes them
(``tests/test_checklog_emulator_notes.py``).

The same seed gives the same bytes; different seeds differ. ``cached_session`` keeps generated
files under the system temp directory, keyed by lines, seed, faults, notes and a hash of the
sources the log depends on (this file, the emulator, the model, the grammar).

CLI: ``python benchmarks/realistic_log.py OUT --lines N [--seed S] [--faults] [--notes]``.
"""

from __future__ import annotations

import argparse
import hashlib
import os
import random
import sys
import tempfile
import time
from pathlib import Path
from typing import Optional

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from helmcheck.emulator.core import EmulatorCore  # noqa: E402
from helmcheck.emulator.missionfile import DirectoryCatalog, builtin_dir  # noqa: E402
from helmcheck.grammar import checksum_hex  # noqa: E402
from helmcheck.grammar import sentences as s  # noqa: E402
from helmcheck.grammar.wirelog import FROM_VEHICLE, WireLogWriter  # noqa: E402
from helmcheck.profile import DEFAULT  # noqa: E402

__all__ = ["write_session", "cached_session", "BAUD", "TIME_SCALE"]

BAUD = 19200
TIME_SCALE = 1.0
POLL_S = 0.5  #: the backseat's state poll period (wall seconds)
RUNNING = frozenset({"N", "P", "mP", "Mp", "A", "W"})
LABELS = ("temp", "cond", "chl", "turb")


def frame(body: str) -> bytes:
    return f"${body}*{checksum_hex(body)}\r\n".encode("ascii")


class _NoFlush:
    """A buffered text file whose per-record flush is free (the log is written at once)."""

    def __init__(self, f):
        self.write = f.write

    def flush(self) -> None:
        pass


class TamperingWriter(WireLogWriter):
    """The wire log writer with the injected vehicle faults: the next ``$ACK`` of a type lost,
    or the next refusal of a type rewritten as an acceptance."""

    def __init__(self, stream, meta, notes: bool = False):
        super().__init__(stream, meta)
        self.lose: set[bytes] = set()      #: ACK types whose next ACK is lost
        self.accept: set[bytes] = set()    #: ACK types whose next refusal reads accepted
        self.notes = notes                 #: keep the emulator's own notes

    def bytes(self, t, direction, raw):
        if direction == FROM_VEHICLE and raw.startswith(b"$ACK,"):
            kind = raw.split(b",", 2)[1]
            if kind in self.lose:
                self.lose.discard(kind)
                return None
            if kind in self.accept and raw.split(b",", 3)[2] == b"1":
                self.accept.discard(kind)
                raw = frame(f"ACK,{kind.decode()},0,0")
        return super().bytes(t, direction, raw)

    def note(self, t, text):
        """The emulator's notes (its plant's and model's events) are not on the wire: a recording
        of a real vehicle's line has none, so neither has this log — unless asked for."""
        return super().note(t, text) if self.notes else None


class Backseat:
    """The scripted backseat: what it sends when, from what the vehicle last reported."""

    def __init__(self, rng: random.Random):
        self.rng = rng
        self.mode: Optional[str] = None
        self.error = "N"
        self.lat, self.lon = 41.52, -71.32
        self.running_since: Optional[float] = None
        self.stopped_at = 0.0
        self.logging = False
        self.pending_start = False
        self.hold_until = -1.0            #: lockout: $OSD only until then
        self.in_lockout = False
        self.activity: Optional[str] = None
        self.activity_until = 0.0
        self.next_activity = 20.0
        self.mission_until = 0.0
        self.servo: dict = {}
        self.backoff: dict[str, float] = {}
        self.next_opos = 10.0
        self.next_logd = 5.0
        self.polls = 0

    # ---------------------------------------------------------------- what the vehicle said
    def receive(self, data: bytes, now: float) -> None:
        for line in data.split(b"\r\n"):
            if not line.startswith(b"$") or b"*" not in line:
                continue
            f = line[1:line.index(b"*")].decode("ascii", "replace").split(",")
            if f[0] == "OSI" and len(f) > 8:
                self.on_state(f[2], f[8], f[4], f[5], now)
            elif f[0] == "ACK" and len(f) >= 4:
                self.on_ack(f[1], f[2], f[3], now)

    def on_state(self, mode: str, error: str, lat: str, lon: str, now: float) -> None:
        was = self.mode
        self.mode, self.error = mode, error
        try:
            self.lat, self.lon = float(lat), float(lon)
        except ValueError:
            pass
        if error != "N" and not self.in_lockout and now > self.stopped_at + 1.0:
            self.in_lockout = True
            self.hold_until = now + 20.0 / TIME_SCALE + 2.0
            self.activity = None
        if mode in RUNNING and self.running_since is None:
            self.started(now)
        if mode == "S" and was in RUNNING:
            self.ended(now)

    def started(self, now: float) -> None:
        self.running_since = now
        self.mission_until = now + self.rng.uniform(1800, 5400)
        self.next_activity = now + self.rng.uniform(10, 40)

    def ended(self, now: float) -> None:
        self.running_since = None
        self.activity = None
        self.stopped_at = now

    def on_ack(self, kind: str, status: str, err: str, now: float) -> None:
        if kind == "3":
            self.pending_start = False
            if status == "0" and self.mode not in RUNNING:  # started: before any $OSI says so
                self.mode = "N"
                self.started(now)
        if kind == "1" and status == "0":
            self.mode = "S"
            self.ended(now)
        if status != "0":
            self.backoff[kind] = now + 1.5  # RH-BS-5: not again within the second
            if kind == "9":
                self.activity = None

    # ---------------------------------------------------------------- what to send
    def poll(self) -> str:
        self.polls += 1
        return "OSD,G,C,S,P" if self.polls % 10 == 0 else "OSD,G,C,S"

    def decide(self, now: float) -> list[str]:
        """The commands for this turn of the loop (between two polls)."""
        rng = self.rng
        if self.in_lockout:
            if now < self.hold_until:
                return []
            self.in_lockout = False
            self.stopped_at = now
            self.ended(now)
            return ["OMSTOP,0"]  # the episode ends; the mission starts afresh
        if self.mode is None:
            return []
        out: list[str] = []
        if self.mode not in RUNNING:
            if self.pending_start or now < self.stopped_at + 8.0 or now < self.backoff.get("3", 0):
                return []
            if not self.logging:
                self.logging = True
                return ["OLOGL," + ",".join(LABELS)]
            if rng.random() < 0.3 and now >= self.backoff.get("12", 0):
                self.stopped_at = now - 6.0
                code = rng.choice(("Sop", "Stl", "Sle", "Sfp", "Sed", "SafetyAction"))
                return [f"ORWSET,{code},R"]
            self.pending_start = True
            name = "short.mis" if rng.random() < 0.25 else "conformance.mis"
            return [f"OMSTART,0,0,0,0,{name}"]
        if now >= self.next_opos:
            self.next_opos = now + rng.uniform(20, 40)
            north, east = rng.gauss(0.0, 3.0) / 111_320, rng.gauss(0.0, 3.0) / 83_500  # its own fix, metres off
            out.append(f"OPOS,{self.lat + north:.6f},{self.lon + east:.6f},"
                       f"{rng.uniform(1.5, 2.5):.1f},{rng.uniform(30, 36):.2f},{rng.uniform(8, 16):.1f}")
        if self.logging and now >= self.next_logd:
            self.next_logd = now + rng.uniform(8, 12)
            out.append("OLOGD," + ",".join(f"{rng.uniform(0, 50):.2f}" for _ in LABELS))
        if now >= self.mission_until and self.activity is None:
            self.mission_until = now + 3600
            return out + ["OMSTOP,0"]
        out += self._activity(now)
        return out

    def _activity(self, now: float) -> list[str]:
        rng = self.rng
        act = self.activity
        if act is None:
            if now < self.next_activity:
                return []
            # in a mission park the $OPK over it is as likely as a servo episode (module docstring)
            weights = (3, 4, 2, 1) if self.mode == "P" else (5, 2, 2, 1)
            act = rng.choices(("servo", "park", "omw", "jump"), weights)[0]
            if now < self.backoff.get({"servo": "9", "park": "11", "omw": "16", "jump": "7"}[act], 0):
                return []
            self.activity = act
            if act == "servo":
                t = rng.randint(3, 15)
                self.servo = {"hdg": rng.uniform(0, 359), "depth": rng.uniform(1, 6), "t": t,
                              "every": t / 3.0, "next": now}
                self.activity_until = now + rng.uniform(20, 120)
            elif act == "park":
                self.activity_until = now + rng.uniform(60, 200)
                return [f"OPK,{self.lat + rng.uniform(-3e-4, 3e-4):.6f},"
                        f"{self.lon + rng.uniform(-3e-4, 3e-4):.6f},{rng.randint(1, 3)},2.0"]
            elif act == "omw":
                self.activity_until = now + rng.uniform(120, 300)
                return [self._omw() for _ in range(rng.randint(1, 3))]
            else:
                self.activity = None
                self.next_activity = now + rng.uniform(30, 90)
                return [f"OJW,{rng.randint(0, 1)}"]
        if act == "servo":
            sv = self.servo
            if now >= self.activity_until:  # released: at once, or let lapse by its timeout
                clear = rng.random() < 0.3
                out = self._end_activity(now, "OMW,Clr" if clear else None)
                if not clear:  # a new episode comes well after the lapse, never as a late refresh
                    self.next_activity = max(self.next_activity, now + 2 * sv["t"] + 5)
                return out
            if now < sv["next"]:
                return []
            sv["next"] = now + sv["every"]
            sv["hdg"] = round(sv["hdg"] + rng.gauss(0, 4), 1) % 360
            sv["depth"] = min(8.0, max(0.5, sv["depth"] + rng.gauss(0, 0.2)))
            return [f"OMS,{sv['hdg']:.1f},{sv['depth']:.1f},20,{rng.uniform(1.8, 2.4):.1f},{sv['t']}"]
        if now >= self.activity_until or self.mode in ("N", "P") and now > self.activity_until - 50:
            return self._end_activity(now, "OMW,Clr" if self.mode in ("W", "mP") else None)
        if act == "omw" and self.mode == "W" and rng.random() < 0.02:  # one more, behind the queue
            return [self._omw()]
        return []

    def _omw(self) -> str:
        """An ``$OMW`` near the vehicle, with a park time now and then."""
        rng = self.rng
        return (f"OMW,{self.lat + rng.uniform(-5e-4, 5e-4):.6f},{self.lon + rng.uniform(-5e-4, 5e-4):.6f},"
                f"{rng.uniform(1, 4):.1f},,20,2.0,{rng.randint(5, 60) if rng.random() < 0.4 else 0},")

    def _end_activity(self, now: float, command: Optional[str]) -> list[str]:
        self.activity = None
        self.next_activity = now + self.rng.uniform(15, 60)
        return [command] if command else []


def write_session(path: Path, lines: int, seed: int = 0, faults: bool = False, notes: bool = False) -> int:
    """Write a wire log of about ``lines`` lines (see the module docstring); the number written.
    ``notes``: keep the emulator's own notes (their lines count)."""
    rng = random.Random(seed)
    path = Path(path)
    with open(path, "w", encoding="ascii", newline="\n", buffering=1 << 20) as f:
        log = TamperingWriter(_NoFlush(f), (f"started 2026-11-25T08:00:00.000000Z  port virtual "
                                            f"seed {seed}  baud {BAUD}  time_scale {TIME_SCALE:g}",), notes)
        core = EmulatorCore(DEFAULT, DirectoryCatalog([builtin_dir()]), start=0.0,
                            time_scale=TIME_SCALE, baud=BAUD, log=log)
        bs = Backseat(rng)
        fault_at = sorted(rng.uniform(0.15, 0.9) * lines for _ in range(3)) if faults else []
        trip_every = rng.uniform(5000, 9000)  # vehicle seconds between leak-sensor trips
        next_trip = trip_every
        next_poll = rng.uniform(0.0, POLL_S)
        next_decide = next_poll + POLL_S / 2
        pending: list[tuple[float, str]] = []  # (when, body): a turn's commands, 20 ms apart
        now = 0.0
        stop_at: Optional[float] = None
        while True:
            wake = core.next_wakeup()
            t_bs = min(next_poll, next_decide, pending[0][0] if pending else 1e18)
            if stop_at is not None:
                if wake is None or wake > stop_at:
                    break
                t_bs = 1e18
            if wake is not None and wake <= t_bs:
                now = max(now, wake)
                bs.receive(core.tick(now), now)
                continue
            now = t_bs
            if pending and pending[0][0] <= now:
                bs.receive(core.feed(frame(pending.pop(0)[1]), now), now)
            elif next_poll <= now:
                next_poll = now + POLL_S + rng.uniform(-0.01, 0.01)
                bs.receive(core.feed(frame(bs.poll()), now), now)
            else:
                next_decide = now + POLL_S
                cmds = bs.decide(now)
                if fault_at and log.lineno >= fault_at[0] and bs.mode in RUNNING and not bs.in_lockout:
                    fault_at.pop(0)
                    cmds += _fault(len(fault_at), log, core, now)
                pending += [(now + 0.02 * (i + 1), c) for i, c in enumerate(cmds)]
                if core.v >= next_trip and bs.mode in RUNNING and bs.activity is None and not bs.in_lockout:
                    next_trip = core.v + trip_every
                    bs.receive(core.inject_fault("Sle", now, source="leak sensor"), now)
            if stop_at is None and log.lineno >= lines:
                stop_at = now + 1.5  # the last answers go out, nothing more is asked
        return log.lineno


def _fault(which: int, log: TamperingWriter, core: EmulatorCore, now: float) -> list[str]:
    """One injected fault (``which`` counts down from 2); the commands the backseat sends for it."""
    if which == 2:  # a lost $ACK: the vehicle never answers this $OPOS as far as the line shows
        log.lose.add(b"6")
        return ["OPOS,41.520000,-71.320000,2.0,33.00,12.0"]
    if which == 1:  # an out-of-range $OMS (timeout 150 s) the vehicle acknowledges as accepted
        log.accept.add(b"9")
        return ["OMS,90.0,2.0,20,2.0,150"]
    # a line with a wrong checksum: the vehicle discards it (RH-FRM-4) but answers all the same
    core.feed(b"$OSD,G,C,S*00\r\n", now)
    core.queue_reply(s.ACK(8, 0, 0), now)
    return []


def _source_hash() -> str:
    h = hashlib.sha256()
    files = [Path(__file__).resolve()]
    for pkg in ("emulator", "model", "grammar"):
        files += sorted((ROOT / "helmcheck" / pkg).rglob("*.py"))
        files += sorted((ROOT / "helmcheck" / pkg).rglob("*.mis"))
        files += sorted((ROOT / "helmcheck" / pkg).rglob("*.lark"))
    files.append(ROOT / "helmcheck" / "profile.py")
    for p in files:
        h.update(p.name.encode())
        h.update(p.read_bytes())
    return h.hexdigest()[:16]


def cached_session(lines: int, seed: int = 0, faults: bool = False, notes: bool = False) -> tuple[Path, bool]:
    """The session for these arguments from the cache, generated when missing: (path, generated)."""
    d = Path(tempfile.gettempdir()) / "helmcheck-realistic"
    d.mkdir(exist_ok=True)
    kind = ("faults" if faults else "clean") + ("-notes" if notes else "")
    path = d / f"session-{lines}-{seed}-{kind}-{_source_hash()}.log"
    if path.exists():
        return path, False
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        write_session(tmp, lines, seed, faults, notes)
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)
    return path, True


def main(argv: Optional[list[str]] = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", type=Path, help="the wire log to write")
    ap.add_argument("--lines", type=int, default=1_000_000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--faults", action="store_true", help="inject a handful of vehicle faults")
    ap.add_argument("--notes", action="store_true", help="keep the emulator's own notes (plant and model events)")
    args = ap.parse_args(argv)
    if args.lines < 1:
        ap.error("--lines must be at least 1")
    t0 = time.perf_counter()
    n = write_session(args.out, args.lines, args.seed, args.faults, args.notes)
    print(f"{args.out}: {n} lines, {args.out.stat().st_size / 1e6:.1f} MB in {time.perf_counter() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
