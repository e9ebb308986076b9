"""``DIR/diff.json`` and the one-line result of a diff.

``diff.json`` (``format`` ``helmcheck-diff``, ``version`` 1) holds: ``result`` (``diverged``,
``no divergence``, ``inconclusive``), ``exit_code``, ``line`` (the one-line result), ``reason``
(why it is inconclusive), ``settings``; ``sides`` — for ``A`` and ``B``: the vehicle (port or
``--exec`` command), time scale, profile name, wire log, every clause its judge failed
(``findings``) and its replay file; ``divergence`` — the smallest divergent sequence: the step,
what each side showed there, the differences, which side broke which clause in the sequence,
and every step of it as both sides showed it; ``stats`` — sequences run, divergent sequences
(shrinking included), sequences whose comparison ended on an explained difference (by
explanation), wall time, whether the budget was spent.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Optional

from ... import __version__, exitcodes
from ...reports.atomic import write_text_atomic

__all__ = ["document", "write", "FILE"]

FILE = "diff.json"


def _side(s, replays: dict) -> dict:
    return {"vehicle": s.spec.label, "time_scale": s.k, "profile": s.spec.profile.name,
            "wire_log": f"{s.name}/wire.log", "findings": s.findings(), "replay": replays.get(s.name)}


def document(opts, pair, state, replays: dict, stopped: Optional[str], error: Optional[BaseException],
             wall_s: float) -> dict:
    best = state.best if state is not None else None
    ran = state.executions if state is not None else 0
    if error is not None:
        result, code = "inconclusive", exitcodes.INCONCLUSIVE
        reason = f"tester error: {type(error).__name__}: {(str(error).splitlines() or [''])[0][:160]}"
        line = f"diff: INCONCLUSIVE: {reason}"
    elif best is not None:
        result, code, reason = "diverged", exitcodes.NONCONFORMANT, ""
        line = f"diff: {best['record']['summary']}"
        if stopped:
            line += f" (then stopped: {stopped})"
    elif stopped or ran == 0 or ran <= sum(state.unreset.values()):
        result, code = "inconclusive", exitcodes.INCONCLUSIVE
        reason = stopped or ("no sequence ran within the budget" if ran == 0 else
                             "no sequence could be compared: the verified reset failed every time")
        line = f"diff: INCONCLUSIVE after {ran} sequence(s): {reason}"
    else:
        result, code, reason = "no divergence", exitcodes.OK, ""
        line = f"diff: no divergence in {ran} sequence(s) (budget {opts.budget_s:g} s)"
        unreset = sum(state.unreset.values())
        if unreset:
            line += f"; {unreset} not compared (a reset failed)"
    if result == "no divergence":  # the same behaviour is not a conforming one
        fails = [f"{s.name} fails {', '.join(f['clause'] for f in s.findings())}"
                 for s in pair.sides if s.findings()]
        if fails:
            line += f"; but {'; '.join(fails)} (see diff.json)"
    spent = state is not None and state.skipped > 0
    return {
        "format": "helmcheck-diff", "version": 1, "tool_version": __version__, "command": opts.command,
        "result": result, "exit_code": code, "line": line, "reason": reason,
        "settings": {"examples": opts.examples, "steps": opts.steps, "budget_s": opts.budget_s, "seed": opts.seed},
        "sides": {s.name: _side(s, replays) for s in pair.sides},
        "divergence": best["record"] if best is not None else None,
        "stats": {"sequences": ran, "divergent_sequences": state.divergent if state else 0,
                  "explained": dict(state.excused) if state else {}, "budget_spent": spent,
                  "reset_failed": dict(state.unreset) if state else {},
                  "first_divergence_s": state.found_s if state else None,
                  "wall_s": round(wall_s, 3)},
    }


def write(directory: Path, doc: dict) -> Path:
    path = Path(directory) / FILE
    write_text_atomic(path, json.dumps(doc, indent=1, default=str) + "\n")
    return path
