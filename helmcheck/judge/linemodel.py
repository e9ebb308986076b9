"""The line model: whether the link between the tester and the implementation can damage bytes.

A serial line (a UART, a radio modem, an RS-232 cable past its length) flips bits, loses bytes and
stalls; a judge reading it holds what such a line could have done until the observation is made
again (``docs/contracts.md``, "A faulty line"). A pseudo-terminal, or a TCP connection to this
host, cannot: the kernel copies the bytes. On such a **clean** link every broken line, lost byte
and missing answer is the implementation's, at once — no holding, no re-runs. (A late answer alone
may still be this host's: an implementation on a pty or local TCP shares its CPU, and a stall of it
delays an answer; late again when made again, it is the implementation's.)

This module owns the two models, their wire-log note and what a judge makes of it:

* :class:`LineModel` — ``kind`` (``clean`` or ``noisy``) and ``why`` (one phrase for the report:
  "a pty helmcheck made", "--line clean given", "a capture that does not say");
* :func:`line_note` / :func:`read_line_note` — the note a recorder writes at the start of its
  record (``line model: clean — <why>``), which every judge reads, live and offline alike, so a
  run's ``wire.log`` checked again is judged under the same model;
* :data:`UNKNOWN` — a record that names no model (a ``socat -v`` capture, an older log) is judged
  as **noisy**: a judge may assume only what it was told.

Which model a port gets (its path, a symlink to a pty, a host) is the drivers' business
(:mod:`helmcheck.line.linekind`); which one a log gets, ``check-log``'s. Pure: no I/O.
"""

from __future__ import annotations

import re
from typing import NamedTuple, Optional

__all__ = ["CLEAN", "NOISY", "KINDS", "LineModel", "UNKNOWN", "line_note", "read_line_note", "given"]

CLEAN = "clean"
NOISY = "noisy"
KINDS = (CLEAN, NOISY)
PREFIX = "line model: "
_NOTE = re.compile(r"^line model: (clean|noisy)(?: — (.*))?$")


class LineModel(NamedTuple):
    """A link's model: ``kind`` (:data:`CLEAN` or :data:`NOISY`) and why it was chosen."""

    kind: str
    why: str

    @property
    def can_damage(self) -> bool:
        """The link may flip, lose or add bytes and stall: the faulty-line rule applies."""
        return self.kind != CLEAN

    def describe(self) -> str:
        """One sentence for a report: ``clean (a pty helmcheck made): every broken line …``."""
        if self.kind == CLEAN:
            return (f"clean ({self.why}): it cannot damage a byte, so every broken line, lost byte and "
                    f"missing answer is the implementation's")
        return (f"noisy ({self.why}): an error the line could have made is judged only when the "
                f"observation, made again, repeats it")

    def as_dict(self) -> dict:
        return {"kind": self.kind, "why": self.why}


#: What a record that names no model is judged under (module docstring).
UNKNOWN = LineModel(NOISY, "the record does not say what the link was")


def given(kind: str) -> LineModel:
    """The model a user named (``--line clean|noisy``)."""
    if kind not in KINDS:
        raise ValueError(f"unknown line model {kind!r}: want clean or noisy")
    return LineModel(kind, f"--line {kind} given")


def line_note(model: LineModel) -> str:
    """The wire-log note that states ``model`` (one line)."""
    why = " ".join(model.why.split())
    return f"{PREFIX}{model.kind} — {why}" if why else f"{PREFIX}{model.kind}"


def read_line_note(text: str) -> Optional[LineModel]:
    """The model a ``line model:`` note states, or None for any other note."""
    if not text.startswith(PREFIX):
        return None
    m = _NOTE.match(text)
    if m is None:
        return None
    return LineModel(m.group(1), m.group(2) or "")
