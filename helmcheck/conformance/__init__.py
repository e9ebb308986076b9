"""The drivers: what talks to an implementation under test over a line, or reads its recording.

* :mod:`.emulator` — the reference vehicle emulator on a serial line;
* :mod:`.vehicle` — ``certify vehicle``: helmcheck plays the backseat and judges a vehicle;
* :mod:`.backseat` — ``certify backseat``: helmcheck plays the vehicle and judges a backseat;
* :mod:`.checklog` — ``check-log``: a recorded log judged offline by the same observers;
* :mod:`.transport` — opening a byte link (pty, serial device, TCP) and moving bytes over it;
* :mod:`.recorder` — every event of a live run to the wire log (by the one wire-log writer,
  :mod:`helmcheck.grammar.wirelog`) and to the judges, identically;
* :mod:`.launcher` — start, watch and stop the implementation under test (``--exec CMD``);
* :mod:`.exec_port` — the tester's end of a port that a started vehicle opens.

Drivers use the grammar, the model, the judges and the reports, and offer library entry points;
the command lines that call them are in :mod:`helmcheck.commands`.
"""
