"""helmcheck: the formal model and conformance suite for the Iver3 remote helm protocol.

Subpackages: ``grammar`` (wire format), ``model`` (reference state machine, sans-IO),
``conformance`` (emulator, certifiers, log checking), ``reports`` (compliance reports).
"""

__version__ = "0.1.0"
