"""An ending signal never cuts a record in two: the recorder writes a record to the wire log and
feeds it to every judge before Ctrl-C or SIGTERM raises (:func:`helmcheck.signals.deferred`), so
the live verdicts stay the verdicts of the log (the "one judge per role" agreement)."""

from __future__ import annotations

import io
import os
import signal
import threading

import pytest

from helmcheck.line.recorder import Recorder
from helmcheck.failures import Interrupted
from helmcheck.signals import deferred, ending_signals

pytestmark = pytest.mark.skipif(threading.current_thread() is not threading.main_thread(),
                                reason="signal handlers are installed on the main thread only")


class _Judge:
    """An observer that records what it was fed; ``kill`` sends the signal mid-feed."""

    def __init__(self, kill: bool = False):
        self.kill = kill
        self.fed: list = []

    def feed(self, ev) -> None:
        if self.kill:
            os.kill(os.getpid(), signal.SIGTERM)
        self.fed.append(ev)  # the rest of the judge's work on the record


def test_a_signal_inside_a_deferred_block_raises_when_the_block_ends():
    reached_end = False
    with ending_signals():
        with pytest.raises(Interrupted, match="SIGTERM"):
            with deferred():
                os.kill(os.getpid(), signal.SIGTERM)
                for _ in range(1000):  # time enough for the handler to run
                    pass
                reached_end = True
    assert reached_end


@pytest.mark.parametrize("kind", ["bytes", "note"])
def test_a_signal_while_a_record_is_judged_lets_every_judge_see_it(kind):
    log = io.StringIO()
    first, second = _Judge(kill=True), _Judge()
    with ending_signals():
        rec = Recorder(log, [], [first, second])
        with pytest.raises(Interrupted):
            if kind == "bytes":
                rec.bytes(0.5, ">", b"$OSD,S*27\r\n")
            else:
                rec.note(0.5, "case V-1 RH-ACK-1: x")
    assert len(first.fed) == len(second.fed) == 1
    assert first.fed[0] == second.fed[0]
    assert log.getvalue().splitlines()[-1].startswith("0.500000 ")
