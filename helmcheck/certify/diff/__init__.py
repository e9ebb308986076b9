"""``helmcheck diff``: two vehicle implementations driven side by side, their first divergence.

The same generated command sequences go to vehicle A and vehicle B at once; what the reference
profile pins of each step is compared, and the first divergence is shrunk and saved as a replay
file per side. Each side is also judged on its own by the vehicle observer ``certify vehicle``
uses, so a divergence says which side (if any) breaks the profile, on which clause. The command
line is :mod:`helmcheck.commands.diff_cmd`; the library entry point is :func:`.driver.diff`.
Modules, one concern each:

* :mod:`.view` — what the profile pins of one step, and where two views differ (sans-IO);
* :mod:`.side` — one vehicle: opened through a certification run's machinery (port or
  ``--exec``, wire log, judge, session), one step carried out and looked at, closed;
* :mod:`.pair` — both vehicles at once, each in its own thread;
* :mod:`.machine` — the hypothesis state machine whose steps act on both, and what counts as a
  divergence (timing within RH-TIM-1 and the model's leeway do not);
* :mod:`.driver` — one diff: open, search, shrink, save the replays, close;
* :mod:`.report` — ``diff.json`` and the one-line result.
"""
