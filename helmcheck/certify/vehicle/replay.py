"""Version-independent replay files: write one, read one, re-drive it against a vehicle.

A replay file is JSON::

    {"format": "helmcheck-replay", "version": 1, "clause": "RH-SRV-4", "reason": "...",
     "time_scale": 20.0, "profile": {...},
     "steps": [{"send": "$OMS,90,2,20,0.5,5*hh\\r\\n"}, {"expect": "$ACK,9,0,0"},
               {"wait": 6.0}, {"send": "$OSD,S*27\\r\\n"}, ...]}

``send`` is the exact bytes, escaped as in the wire log (``\\r``, ``\\n``, ``\\xNN``); ``wait``
is vehicle seconds (divided by the time scale when re-driven, RH-TIM-2); ``expect`` says in
words what the model expected then (for people; the re-drive asks the model afresh). Nothing in
it depends on a hypothesis version. :func:`redrive` sends it again, judging every reply with
the present model, and says whether it still fails.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Optional

from ...grammar.wirelog import unescape
from ...profile import Profile
from ...reports.atomic import write_text_atomic

__all__ = ["save_replay", "load_replay", "redrive", "ReplayError", "FORMAT"]

FORMAT = "helmcheck-replay"


class ReplayError(ValueError):
    """A replay file that cannot be used; names the file."""


def save_replay(path: Path, clause: str, reason: str, steps: list, time_scale: float, profile: Profile) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    doc = {"format": FORMAT, "version": 1, "clause": clause, "reason": reason, "time_scale": time_scale,
           "profile": profile.as_dict(), "steps": [dict(s) for s in steps]}
    write_text_atomic(path, json.dumps(doc, indent=1) + "\n")
    return path


def load_replay(path: Path) -> dict:
    try:
        doc = json.loads(Path(path).read_text(encoding="utf-8"))
    except OSError as e:
        raise ReplayError(f"{path}: cannot read: {e.strerror or e}") from None
    except ValueError as e:
        raise ReplayError(f"{path}: not JSON: {e}") from None
    if not isinstance(doc, dict) or doc.get("format") != FORMAT or not isinstance(doc.get("steps"), list):
        raise ReplayError(f"{path}: not a helmcheck replay file (want format {FORMAT!r} and a steps list)")
    for i, st in enumerate(doc["steps"]):
        if not isinstance(st, dict) or sum(k in st for k in ("send", "wait", "expect")) != 1:
            raise ReplayError(f"{path}: step {i} needs exactly one of send, wait, expect")
    return doc


def redrive(doc: dict, session) -> tuple[str, str, Optional[str]]:
    """Re-drive the steps on ``session``: (``fail``/``pass``/``inconclusive``, reason, clause).

    The steps start with the verified reset the sequence began with; the session's observer
    judges every reply, as in any run."""
    from .flow import CaseStop
    from .safety import BenchSafetyRefused

    session.mark = session.ledger.mark()
    try:
        for st in doc["steps"]:
            if "send" in st:
                raw = unescape(st["send"])
                try:
                    session.exchange(raw)
                except BenchSafetyRefused as e:
                    return "inconclusive", f"a step was not sent: {e}", None
            elif "wait" in st:
                session.wait(float(st["wait"]))
    except CaseStop as f:
        return ("fail" if f.outcome == "fail" else "inconclusive"), f.reason, f.clause
    return "pass", f"all {len(doc['steps'])} steps agreed with the model", None
