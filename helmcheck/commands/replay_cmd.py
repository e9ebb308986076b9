"""``helmcheck replay FILE --port URL``: re-drive a saved failing sequence against a vehicle.

The replay file (written by ``helmcheck certify vehicle`` when exploration finds a failure, see
:mod:`helmcheck.certify.vehicle.replay`) lists the exact bytes sent and the protocol waits.
Every reply is judged again by the present reference model. Exit status: 1 it still fails,
0 it passes now, 2 inconclusive (link fault, a step not sent; a wire log that could not be
written), 64 usage (bad option, unreadable replay file or profile, a port that cannot be opened).
"""

from __future__ import annotations

import argparse
import math
import sys

from .. import exitcodes
from .lineopt import add_line_argument

EPILOG = """\
A replay file is what certify vehicle writes into DIR/replays/ for each failure its exploration
found (and diff for each divergence): the exact bytes sent and the protocol's waits. --time-scale
defaults to the one the replay was recorded at; waits are vehicle seconds divided by it.

examples:
  helmcheck replay failing.json --port /dev/pts/N --time-scale 20   # e.g. reports/vehicle/replays/*.json
  helmcheck replay failing.json --port socket://10.0.0.5:4001 --profile iver3.toml

exit status: 1 it still fails, 0 it passes now, 2 it cannot be judged (a link fault, or the vehicle
  went another way), 64 usage (bad option, replay file or profile, a port that cannot be opened).
"""


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = sub.add_parser("replay", help="re-drive a saved failing sequence against a vehicle",
                       description="Re-drive a saved failing sequence against a vehicle and say whether it "
                                   "still fails, passes now, or cannot be judged.",
                       epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("file", metavar="FILE", help="a replay file (replays/*.json in a results directory)")
    p.add_argument("--port", required=True, metavar="URL", help="the vehicle's port (what pyserial opens)")
    p.add_argument("--profile", metavar="FILE", help="TOML profile (default: the one stored in the replay)")
    p.add_argument("--time-scale", type=float, metavar="K", help="the vehicle's time scale (default: recorded)")
    p.add_argument("--wire-log", metavar="FILE", help="write the wire log of the re-drive here")
    add_line_argument(p)
    p.set_defaults(func=run)
    return p


def run(args: argparse.Namespace) -> int:
    import time

    from .. import __version__
    from ..clauses import vehicle_clauses
    from ..grammar.wirelog import run_header
    from ..line.recorder import Recorder
    from ..certify.vehicle.flow import LinkLost
    from ..certify.vehicle.link import TesterLink
    from ..certify.vehicle.replay import ReplayError, load_replay
    from ..certify.vehicle.session import Session
    from ..judge import Ledger
    from ..judge.vehicle import VehicleObserver
    from ..failures import PathError, UsageError
    from ..outputs import check_writable, open_output_stream
    from ..profile import load_profile, profile_from_dict
    from .ports import open_port, port_spec

    try:
        doc = load_replay(args.file)
    except ReplayError as e:
        raise PathError(str(e)) from None
    for i, st in enumerate(doc["steps"]):  # every value usable before the port is opened
        ok = (isinstance(st.get("send", ""), str) and isinstance(st.get("expect", ""), str)
              and (not isinstance(st.get("wait", 0.0), bool) and isinstance(st.get("wait", 0.0), (int, float))
                   and math.isfinite(st.get("wait", 0.0)) and st.get("wait", 0.0) >= 0))
        if not ok:
            raise PathError(f"{args.file}: step {i}: send and expect must be text, wait a number of "
                            f"seconds ≥ 0")
    if args.profile:
        profile = load_profile(args.profile)  # a ProfileError is exit 64 (helmcheck.cli)
    else:
        stored = doc.get("profile") or {}
        if not isinstance(stored, dict):
            raise PathError(f"{args.file}: the stored profile is not a table")
        stored = {k: v for k, v in stored.items() if k != "name"}
        profile = profile_from_dict(stored, where=f"{args.file} (stored profile)")
    try:
        k = args.time_scale if args.time_scale is not None else float(doc.get("time_scale") or profile.time_scale)
    except (TypeError, ValueError):
        raise PathError(f"{args.file}: time_scale is not a number") from None
    if not math.isfinite(k) or k <= 0:
        raise UsageError("--time-scale must be a positive number")
    spec = port_spec(args.port)
    if args.wire_log:
        check_writable(args.wire_log, "--wire-log")
    raw = open_port(spec, role="client", baud=profile.baud)
    log = None
    link = None
    try:
        if args.wire_log:
            log = open_output_stream(args.wire_log, "--wire-log", stop=False, what="wire log")
        from ..certify.vehicle.replay import redrive
        ledger = Ledger([c.id for c in vehicle_clauses()])
        observer = VehicleObserver(profile, ledger, time_scale=k, baud=profile.baud)
        recorder = Recorder(log, [f"started {time.strftime('%Y-%m-%dT%H:%M:%SZ', time.gmtime())}  port {args.port}  "
                                  f"baud {profile.baud}  time_scale {k:g}",
                                  run_header(__version__, "replay", profile.name, more=f" {args.file}".replace(";", ","))],
                            [observer])
        link = TesterLink(raw, profile, recorder)
        from ..judge.linemodel import line_note
        from ..line.linekind import line_for
        link.note(line_note(line_for(args.port, args.line)))
        session = Session(link, profile, k, observer)
        try:
            got = redrive(doc, session)
            verdict, reason = got.verdict, got.reason
        except LinkLost as e:
            verdict, reason = "inconclusive", f"link fault: {e}"
    finally:
        if link is not None:
            link.close()
        else:
            raw.close()
        if log is not None:
            log.close()
    was = doc.get("clause", "?")
    if verdict == "fail":
        print(f"STILL FAILS: {reason} (recorded as {was})")
        code = exitcodes.NONCONFORMANT
    elif verdict == "pass":
        print(f"PASSES NOW: {reason} (recorded as {was}: {doc.get('reason', '')})")
        code = exitcodes.OK
    else:
        print(f"INCONCLUSIVE: {reason}")
        code = exitcodes.INCONCLUSIVE
    if log is not None:
        sys.stdout.flush()
        log.check()  # a wire log lost on the way: exit 2, after the verdict line
    return code
