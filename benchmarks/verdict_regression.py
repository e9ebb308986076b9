"""check-log's verdicts before and after a change: every fixture log, socat capture and run, and
generated realistic sessions, checked and byte-compared.

``python benchmarks/verdict_regression.py --record DIR`` runs ``helmcheck check-log --no-render``
(a process each, as a user runs it) on every log below and keeps, per check, the exit status
and ``results.json`` normalised; ``--compare DIR`` does the same with the present code and
byte-compares with what was recorded, naming every check that differs (exit 1). Run it with
``--record`` on the code before a change to the judges (``git stash`` or a worktree of the older
commit: the package imported is the one beside this script) and with ``--compare`` after.

The logs: ``tests/fixtures/logs/**`` (wire logs, socat ``-v``/``-x`` captures, and the
emulator's gzipped logs of those captures), the wire logs of ``tests/fixtures/reports/*`` (also
under the run's own ``profile.toml``), ``reports/demo/wire.log``, and realistic sessions from
``realistic_log.py`` (clean and with faults, 100,000 lines, one of 300,000 so that the backseat
role is judged in a second process, one with the emulator's own notes kept; the clean ones also
with the built-in mission directory).

Left out of the comparison, because they vary from run to run and say nothing of the verdicts:
``started``, ``finished``, ``duration_s`` and ``log.check_seconds`` (the run's own clock),
``command`` and ``log.source`` (the paths of the log and the report directory; the log's
``sha256`` stays, so a realistic log generated afresh must be the same bytes). Everything else — every clause's verdict, reason,
counts and evidence, the timeline, events, statistics — must be identical.
"""

from __future__ import annotations

import argparse
import gzip
import json
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(Path(__file__).resolve().parent))

from realistic_log import cached_session  # noqa: E402

VOLATILE = ("started", "finished", "duration_s", "command")
MISSIONS = ROOT / "helmcheck" / "emulator" / "missions"
#: (lines, seed, faults, the emulator's own notes kept)
REALISTIC = ((100_000, 0, False, False), (100_000, 1, True, False), (100_000, 2, True, False),
             (300_000, 3, False, False), (100_000, 4, False, True))


def checks(work: Path) -> list[tuple[str, Path, list[str]]]:
    """(name, log, extra check-log arguments) for every check."""
    fx = ROOT / "tests" / "fixtures"
    out: list[tuple[str, Path, list[str]]] = []
    for p in sorted((fx / "logs").rglob("*.log")):
        out.append((str(p.relative_to(fx)), p, []))
    for p in sorted((fx / "logs").rglob("*.log.gz")):
        plain = work / p.name[:-3]
        with gzip.open(p, "rb") as src, open(plain, "wb") as dst:
            shutil.copyfileobj(src, dst)
        out.append((str(p.relative_to(fx)), plain, []))
    runs = sorted((fx / "reports").glob("*/wire.log")) + [ROOT / "reports" / "demo" / "wire.log"]
    for p in runs:
        if not p.exists():
            continue
        name = str(p.relative_to(ROOT))
        out.append((name, p, []))
        if (p.parent / "profile.toml").exists():
            # relative to the checkout (check-log runs there): results name the profile file
            out.append((name + " --profile", p, ["--profile", str((p.parent / "profile.toml").relative_to(ROOT))]))
    for lines, seed, faults, notes in REALISTIC:
        name = f"realistic-{lines}-{seed}-{'faults' if faults else 'clean'}{'-notes' if notes else ''}"
        path = work / f"{name}.log"  # under one name whatever the cache calls it (reports name the log)
        shutil.copyfile(cached_session(lines, seed, faults, notes)[0], path)
        out.append((name, path, []))
        if not faults:
            out.append((name + " --missions", path, ["--missions", str(MISSIONS)]))
    return out


def normalised(results: Path, status: int) -> bytes:
    d = json.loads(results.read_text()) if results.exists() else {}
    for k in VOLATILE:
        d.pop(k, None)
    if isinstance(d.get("log"), dict):
        for k in ("source", "check_seconds"):
            d["log"].pop(k, None)
    return json.dumps({"exit": status, "results": d}, sort_keys=True, indent=1).encode()


def run_all(out_dir: Path, compare: bool) -> int:
    differ = []
    with tempfile.TemporaryDirectory(prefix="helmcheck-verdicts-") as tmp:
        work = Path(tmp)
        todo = checks(work)
        for i, (name, log, extra) in enumerate(todo):
            rep = work / f"r{i}"
            cmd = [sys.executable, "-m", "helmcheck", "check-log", str(log), "--no-render",
                   "--report-dir", str(rep), *extra]
            st = subprocess.run(cmd, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE).returncode
            got = normalised(rep / "results.json", st)
            key = out_dir / (name.replace("/", "__").replace(" ", "_") + ".json")
            if compare:
                same = key.exists() and key.read_bytes() == got
                if not same:
                    differ.append(name)
                    key.with_suffix(".new.json").write_bytes(got)
                print(f"{'same ' if same else 'DIFFERS'}  exit {st}  {name}")
            else:
                key.write_bytes(got)
                print(f"recorded  exit {st}  {name}")
    if compare:
        print(f"{len(todo) - len(differ)} of {len(todo)} checks identical"
              + (f"; differ: {', '.join(differ)} (the new results beside the old, *.new.json)" if differ else ""))
    return 1 if differ else 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("--record", type=Path, metavar="DIR", help="keep the present code's results in DIR")
    g.add_argument("--compare", type=Path, metavar="DIR", help="compare with the results kept in DIR")
    args = ap.parse_args(argv)
    d = args.record or args.compare
    if args.record:
        d.mkdir(parents=True, exist_ok=True)
    elif not d.is_dir():
        ap.error(f"{d}: no recorded results (run --record first)")
    return run_all(d, compare=bool(args.compare))


if __name__ == "__main__":
    sys.exit(main())
