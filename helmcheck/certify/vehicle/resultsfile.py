"""``DIR/results.json`` of a vehicle run: what it starts as, and every save of it.

:func:`new_results` is what a run's results hold before anything is judged (the implementation,
the profile, the settings); :func:`save` writes them after every case and at the end —
atomically, marked ``partial`` until the final save — assembled from the run's one ledger and
its run facts by :func:`helmcheck.reports.assemble.assemble`, with the timeline, coverage,
restore record and stats beside (and each link gap as an event, :mod:`.rejoin`); :func:`keep_traceback` puts a tester error's traceback beside
them (``tester-error.txt``).
"""

from __future__ import annotations

import time

from ... import __version__
from ...line.reopen import gap_event
from ...reports import results as R
from ...reports.assemble import apply, assemble

__all__ = ["new_results", "save", "keep_traceback"]


def new_results(opts) -> dict:
    """The results of a run with these :class:`~.runner.Options`, before anything is judged."""
    p, k = opts.profile, opts.time_scale
    settings = {"time_scale": k, "strict": opts.strict, "hypothesis_profile": opts.hypothesis_profile,
                "select": list(opts.select or []), "ack_window_s": p.ack_window_s,
                "bench_safety": {"enforced": not p.bench_safety.in_water,
                                 "max_motor_byte": p.bench_safety.max_motor_byte,
                                 "max_speed_kn": p.bench_safety.max_speed_kn}}
    if opts.seed is not None:
        settings["seed"] = opts.seed
    if opts.examples is not None:
        settings["examples"] = opts.examples
    results = R.new_results("vehicle", command=opts.command, tool_version=__version__,
                            implementation={"port": opts.port, "protocol": p.protocol,
                                            "osi_fields": p.osi_fields,
                                            "fault_injection": p.fault_injection},
                            profile=p.as_dict(), settings=settings, seed=opts.seed)
    results["cases"] = []
    return results


def save(run, final: bool = False) -> None:
    """Write ``results.json`` (module docstring): ``partial`` unless ``final``."""
    r = run.results
    obs = run.observer
    if run.recorder is None:  # no record at all: the facts the notes would have given
        run.facts.select = tuple(run.o.select or ())
    partial = None  # from the record's own ``run partial`` note
    if not final or (run.partial and run.facts.partial is None):
        partial = True
    lead = (run.aborted if run.partial else run.stopped) or ""
    assembly = assemble("vehicle", run.ledger, run.facts, strict=run.o.strict, partial=partial,
                        lead=lead if final else "")
    r["timeline"] = [{"t": t, "mode": m} for t, m in obs.timeline]
    r["events"] = list(obs.events) + [gap_event(g) for g in r.get("link_gaps") or ()]
    modes = sorted({m for _, m in obs.timeline})
    pairs = [list(p) for p in sorted(obs.interrupt_pairs)]
    steps = [[a, b, "observed"] for (_, a), (_, b) in zip(obs.timeline, obs.timeline[1:]) if a != b]
    r["coverage"] = {"modes": modes, "transitions": [list(x) for x in sorted({tuple(s) for s in steps})],
                     "interrupt_pairs": pairs}
    if obs.last_osi is not None and obs.last_osi.vehicle_name:
        r["implementation"]["vehicle_name"] = obs.last_osi.vehicle_name
    if run.link is not None:
        r["settings"]["bench_safety"]["refused_lines"] = run.link.guard.refused
    if run.custodian.attempted or any(x.before is not None for x in run.custodian.records.values()):
        r["restore"] = run.custodian.record()
    if run.session is not None:
        run.stats["forced_wait_s"] = round(run.session.forced_wait, 3)
        run.stats["edges"] = run.session.edges.summary()  # the range edges reached (:mod:`.edges`)
        if run.session.meter.measured:  # the line the verdicts were reached on (:mod:`.linemeter`)
            r["settings"]["line_budget"] = run.session.meter.budget().as_dict()
    run.stats["wall_s"] = round(time.monotonic() - run.t_start
                                + (run.resumed.wall_s if run.resumed is not None else 0.0), 3)
    r["stats"] = run.stats
    apply(r, assembly, final=final, duration_s=run.stats["wall_s"])
    for rep in r["replays"]:  # where a clause's replay script is (not a verdict)
        for c in r["clauses"]:
            if c["id"] == rep["clause"]:
                c["replay"] = rep["file"]
    if not final:
        r["verdict_reason"] = "The run is in progress."
    R.write_results_atomic(run.dir, r)


def keep_traceback(run, exc: BaseException) -> str:
    """A tester error's traceback beside ``results.json`` (``tester-error.txt``, where the command
    line writes it too): ``"; traceback in tester-error.txt"`` for the verdict reason, or ``""``."""
    import traceback

    from ...failures import TRACEBACK_NAME
    text = (f"helmcheck {__version__} tester error\ncommand: {run.o.command or 'certify()'}\n"
            f"time: {time.strftime('%Y-%m-%dT%H:%M:%SZ', time.gmtime())}\n\n"
            + "".join(traceback.format_exception(exc)))
    try:
        (run.dir / TRACEBACK_NAME).write_text(text, encoding="utf-8")
    except OSError:
        return ""
    return f"; traceback in {TRACEBACK_NAME}"
