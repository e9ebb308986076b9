"""The reference vehicle emulator: the model's behaviour on a real serial line.

Modules, one concern each:

* :mod:`.core` — :class:`~.core.EmulatorCore`, the sans-IO core (model + plant + framer + logs).
* :mod:`.timeline` — the core's clock: vehicle time, catching up, control ticks (RH-TIM-2).
* :mod:`.outbox` — the core's output queue, capped and paced at the line's baud (RH-ACK-2), and
  what it does when requests ask for more replies than the line carries (queue or drop).
* :mod:`.outload` — the meter of that demand: how far the line was over-asked, how long replies
  waited, what was dropped.
* :mod:`.logs` — the main log CSV (RH-LOG-2) and the live view's history entries.
* :mod:`.settingsfile` — the ``$ORWSET`` settings kept across runs (RH-SET-2).
* :mod:`.plant` — plant dynamics (motion, depth, battery) that feed the model's plant events.
* :mod:`.missionfile` — the mission file format and the directory catalogue (RH-MSN-1).
* :mod:`.freedoms` — settings for the choices the reference profile leaves a conforming vehicle.
* :mod:`.rules` — the emulated vehicle's own safety rules that trip by themselves (RH-SAF-5).
* :mod:`.server` — the I/O loop on a pty, serial device or TCP serial server.
* :mod:`.tui` — the optional live view in the spirit of the UVC remote-helm debug window.
* :mod:`.process` — start an emulator subprocess and learn its port (tests, benchmarks, tools).

The protocol behaviour is the model's (:mod:`helmcheck.model`), exactly, except where the profile
leaves a vehicle room and a setting of :mod:`.freedoms` chooses otherwise (timing, the spelling of
reports); this package adds only physics, files, logs and I/O.
"""

from .core import EmulatorCore, HistoryEntry, MainLog
from .missionfile import DirectoryCatalog, builtin_dir, parse_mission

__all__ = ["EmulatorCore", "HistoryEntry", "MainLog", "DirectoryCatalog", "builtin_dir",
           "parse_mission"]
