"""helmcheck: the formal model and conformance suite for the Iver3 remote helm protocol.

Subpackages: ``grammar`` (wire format), ``model`` (reference state machine, sans-IO),
``judge`` (the observers and the verdict ledger, sans-IO), ``reports`` (compliance reports),
the drivers — ``line`` (ports, the recorder, the implementation under test as a process),
``emulator`` (the reference vehicle on a line), ``checklog`` (recorded sessions judged offline),
``monitor`` (a live session judged while it runs), ``certify`` (the live certifiers) — and
``commands`` (one module per CLI subcommand, dispatched by ``cli``), ``spec`` (the reference
profile). Imports run one way, grammar ← model ← judge ← reports ← line ← emulator ← checklog ←
monitor ← certify ← commands (``tests/test_layering.py``).
"""

__version__ = "0.1.0"
