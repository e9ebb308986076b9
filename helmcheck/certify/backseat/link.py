"""The certifier's pty: a :class:`~helmcheck.line.transport.PtyLink` that notices the
backseat going away.

A plain ``PtyLink`` keeps its own slave descriptor open so that the master never sees a
hang-up. The certifier wants the hang-up: once the backseat's first byte has arrived,
:meth:`HangupPty.peer_seen` closes that descriptor, and from then on the backseat closing the
port (or dying) makes the master read fail, which ``PtyLink.poll`` reports as
:class:`~helmcheck.line.transport.LinkClosed`. Bytes the backseat wrote before it went
are still read first. This module imports no grammar, so the ``port:`` line goes out at once.
"""

from __future__ import annotations

import os

from ...line.transport import PtyLink

__all__ = ["HangupPty"]


class HangupPty(PtyLink):
    """A pty that can let go of its own slave descriptor, so the peer's close is a hang-up."""

    def peer_seen(self) -> None:
        slave = getattr(self, "_slave", -1)
        if slave is not None and slave >= 0:
            try:
                os.close(slave)
            except OSError:
                pass
            self._slave = -1
