"""The settings file: the ``$ORWSET`` settings a vehicle keeps across runs (RH-SET-2), as JSON
(``{name: [state, [values]]}``), restored at start and written atomically after every write.
"""

from __future__ import annotations

import json
from pathlib import Path

from ..model.settings import SettingsStore

__all__ = ["load_settings", "save_settings"]


def load_settings(store: SettingsStore, path: Path) -> None:
    """Restore ``$ORWSET`` settings saved by an earlier run (RH-SET-2); a bad file is ignored."""
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return
    if not isinstance(data, dict):
        return
    known = store.as_dict()
    for name, value in data.items():
        if name not in known or not isinstance(value, list) or len(value) != 2:
            continue
        state, values = value
        if state in (0, 1) and isinstance(values, list) and all(isinstance(x, str) for x in values):
            store.write(name, state, tuple(values[:3]))


def save_settings(store: SettingsStore, path: Path) -> None:
    """Keep the ``$ORWSET`` settings across runs (RH-SET-2), written atomically (a crash leaves
    the old file or the new one); raises :class:`OSError` when the file cannot be written."""
    from ..reports.atomic import write_text_atomic

    data = {k: [st, list(vals)] for k, (st, vals) in store.as_dict().items()}
    write_text_atomic(path, json.dumps(data, indent=1) + "\n")
