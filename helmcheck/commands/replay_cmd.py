"""``helmcheck replay FILE --port URL``: re-drive a saved failing sequence against a vehicle.

The replay file (written by ``helmcheck certify vehicle`` when exploration finds a failure, see
:mod:`helmcheck.conformance.vehicle.replay`) lists the exact bytes sent and the protocol waits.
Every reply is judged again by the present reference model. Exit status: 1 it still fails,
0 it passes now, 2 inconclusive (link fault, a step not sent), 64 usage.
"""

from __future__ import annotations

import argparse
import math
import sys

from .. import exitcodes

EPILOG = """\
examples:
  helmcheck replay reports/vehicle/replays/RH-SRV-4-1.json --port /dev/pts/5 --time-scale 20
  helmcheck replay failing.json --port socket://10.0.0.5:4001 --profile iver3.toml

--time-scale defaults to the one the replay was recorded at; waits are vehicle seconds divided by it.
"""


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = sub.add_parser("replay", help="re-drive a saved failing sequence against a vehicle",
                       description="Re-drive a saved failing sequence against a vehicle and say whether it "
                                   "still fails (exit 1), passes now (0) or cannot be judged (2).",
                       epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("file", metavar="FILE", help="a replay file (replays/*.json in a results directory)")
    p.add_argument("--port", required=True, metavar="URL", help="the vehicle's port (what pyserial opens)")
    p.add_argument("--profile", metavar="FILE", help="TOML profile (default: the one stored in the replay)")
    p.add_argument("--time-scale", type=float, metavar="K", help="the vehicle's time scale (default: recorded)")
    p.add_argument("--wire-log", metavar="FILE", help="write the wire log of the re-drive here")
    p.set_defaults(func=run)
    return p


def run(args: argparse.Namespace) -> int:
    from ..clauses import vehicle_clauses
    from ..conformance.recorder import Recorder
    from ..conformance.transport import open_link, parse_port_spec
    from ..conformance.vehicle.flow import LinkLost
    from ..conformance.vehicle.link import TesterLink
    from ..conformance.vehicle.replay import ReplayError, load_replay, redrive
    from ..conformance.vehicle.session import Session
    from ..judge import Ledger
    from ..judge.vehicle import VehicleObserver
    from ..profile import ProfileError, load_profile, profile_from_dict

    try:
        doc = load_replay(args.file)
    except ReplayError as e:
        print(f"helmcheck replay: {e}", file=sys.stderr)
        return exitcodes.USAGE
    try:
        if args.profile:
            profile = load_profile(args.profile)
        else:
            stored = {k: v for k, v in (doc.get("profile") or {}).items() if k != "name"}
            profile = profile_from_dict(stored, where=f"{args.file} (stored profile)")
    except ProfileError as e:
        print(f"helmcheck replay: {e}", file=sys.stderr)
        return exitcodes.USAGE
    k = args.time_scale if args.time_scale is not None else float(doc.get("time_scale") or profile.time_scale)
    if not math.isfinite(k) or k <= 0:
        print("helmcheck replay: --time-scale must be positive", file=sys.stderr)
        return exitcodes.USAGE
    try:
        parse_port_spec(args.port)
    except ValueError as e:
        print(f"helmcheck replay: --port: {e}", file=sys.stderr)
        return exitcodes.USAGE
    log = open(args.wire_log, "w", encoding="utf-8") if args.wire_log else None
    link = None
    try:
        try:
            raw = open_link(args.port, role="client", baud=profile.baud)
        except (OSError, ValueError) as e:
            print(f"INCONCLUSIVE: cannot open {args.port}: {e}", file=sys.stderr)
            return exitcodes.INCONCLUSIVE
        ledger = Ledger([c.id for c in vehicle_clauses()])
        observer = VehicleObserver(profile, ledger, time_scale=k, baud=profile.baud)
        recorder = Recorder(log, [f"replay {args.file} port {args.port} time_scale {k:g}"], [observer])
        link = TesterLink(raw, profile, recorder)
        session = Session(link, profile, k, observer)
        try:
            verdict, reason, clause = redrive(doc, session)
        except LinkLost as e:
            verdict, reason = "inconclusive", f"link fault: {e}"
    finally:
        if link is not None:
            link.close()
        if log is not None:
            log.close()
    was = doc.get("clause", "?")
    if verdict == "fail":
        print(f"STILL FAILS: {reason} (recorded as {was})")
        return exitcodes.NONCONFORMANT
    if verdict == "pass":
        print(f"PASSES NOW: {reason} (recorded as {was}: {doc.get('reason', '')})")
        return exitcodes.OK
    print(f"INCONCLUSIVE: {reason}")
    return exitcodes.INCONCLUSIVE
