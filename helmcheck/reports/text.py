"""Text hygiene shared by the renderers: control characters, Markdown-to-plain, short titles.

Nothing here escapes for a particular output language; each renderer escapes for its own
(HTML, XML, Markdown). This module only makes strings printable and short.
"""

from __future__ import annotations

import re

__all__ = ["printable", "plain", "short_title", "section_name"]

# Characters XML 1.0 forbids, C1 controls, DEL and lone surrogates: never copied into output.
_UNPRINTABLE = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\x7f-\x9f\ud800-\udfff\ufffe\uffff]")


def printable(value: object) -> str:
    """``str(value)`` with control characters written as ``\\xNN`` (as in the wire log)."""
    return _UNPRINTABLE.sub(lambda m: f"\\x{ord(m.group()):02x}" if ord(m.group()) < 0x100
                            else f"\\u{ord(m.group()):04x}", str(value))


def plain(markdown: str) -> str:
    """Inline Markdown (``code``, **bold**, *italic*) as plain text."""
    text = re.sub(r"`([^`]*)`", r"\1", markdown)
    text = re.sub(r"\*\*(.+?)\*\*", r"\1", text)
    text = re.sub(r"(?<![\w*])\*(?!\s)(.+?)(?<!\s)\*(?![\w*])", r"\1", text)
    return " ".join(text.split())


def short_title(markdown: str, limit: int = 72) -> str:
    """The first sentence of a clause text, plain, cut at a word boundary to *limit* chars."""
    text = plain(markdown)
    m = re.search(r"(?<=[A-Za-z0-9)\]])(?<!e\.g)(?<!i\.e)\.(\s|$)", text)
    if m and m.start() + 1 <= limit:
        return text[: m.start()]
    if len(text) <= limit:
        return text
    cut = text[: limit - 1].rsplit(" ", 1)[0]
    return cut.rstrip(",;:") + "…"


def section_name(section: str, title: str) -> str:
    """``"4", "Control commands and modes — `RH-SRV`, …"`` → ``"§4 Control commands and modes"``."""
    head = title.split(" — ", 1)[0].strip()
    return f"§{section} {plain(head)}".strip()
