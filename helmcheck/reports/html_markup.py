"""Markup helpers for the HTML report: escaping, profile Markdown to HTML, key/value tables,
verdict cells, and the two section wrappers: a plain section and a fold (a ``<details>`` whose
summary line carries the title and a one-line digest of what is inside).
"""

from __future__ import annotations

import json
import re
from html import escape
from typing import Any, Iterable, Mapping

from .text import printable
from .view import VERDICT_LABEL


def _e(value: object) -> str:
    """Escape any value for HTML text or a quoted attribute."""
    return escape(printable(value), quote=True)


def md_inline(markdown: str) -> str:
    """Profile Markdown (``code``, **bold**, *italic*) to escaped HTML; emphasis may hold code."""
    parts = markdown.split("`")
    codes: list[str] = []
    out = []
    for i, part in enumerate(parts):
        if i % 2 and i < len(parts) - 1:
            codes.append(f"<code>{_e(part)}</code>")
            out.append(f"\x00{len(codes) - 1}\x00")  # escaped text never holds NUL (printable())
            continue
        if i % 2:  # an unmatched backtick: keep it literally
            part = "`" + part
        out.append(_e(part))
    text = "".join(out)
    text = re.sub(r"\*\*(.+?)\*\*", r"<strong>\1</strong>", text)
    text = re.sub(r"(?<![\w*])\*(?!\s)(.+?)(?<!\s)\*(?![\w*])", r"<em>\1</em>", text)
    return re.sub("\x00(\\d+)\x00", lambda m: codes[int(m.group(1))], text)


def _kv_table(rows: Iterable[tuple[str, Any]], cls: str = "kv") -> str:
    body = "".join(f"<tr><th>{_e(k)}</th><td>{_fmt_value(v)}</td></tr>" for k, v in rows)
    return f'<table class="{cls}"><tbody>{body}</tbody></table>' if body else '<p class="muted">none recorded</p>'


def _fmt_value(value: Any) -> str:
    if value is None:
        return '<span class="muted">—</span>'
    if isinstance(value, str):
        return _e(value)
    if isinstance(value, (bool, int, float)):
        return _e(json.dumps(value))
    if isinstance(value, (list, tuple)) and all(isinstance(v, (str, int, float)) for v in value):
        return _e(", ".join(str(v) for v in value))
    return f'<span class="mono">{_e(json.dumps(value, ensure_ascii=False))}</span>'


def _flatten(mapping: Mapping[str, Any], prefix: str = "") -> list[tuple[str, Any]]:
    rows: list[tuple[str, Any]] = []
    for key, value in mapping.items():
        name = f"{prefix}{key}"
        if isinstance(value, Mapping) and value:
            rows.extend(_flatten(value, f"{name}."))
        else:
            rows.append((name, value))
    return rows


def _verdict_cell(verdict: str) -> str:
    return f'<td class="verdict v-{_e(verdict)}">{_e(VERDICT_LABEL.get(verdict, verdict))}</td>'



def _section(anchor: str, title: str, body: str) -> str:
    return f'<section id="{anchor}">\n<h2>{_e(title)}</h2>\n{body}\n</section>'


def _fold(anchor: str, title: str, body: str, gist: str = "", open_: bool = False) -> str:
    """A section folded behind its title (open when *open_*): *gist* (escaped HTML) is shown
    beside the title while it is folded, so a reader knows what is inside without opening it.
    A link into a folded section opens it (browsers expand a ``<details>`` holding the target)."""
    gist_html = f' <span class="gist">{gist}</span>' if gist else ""
    return (f'<details class="fold" id="{anchor}"{" open" if open_ else ""}>\n'
            f'<summary><h2>{_e(title)}</h2>{gist_html}</summary>\n'
            f'<div class="fold-body">\n{body}\n</div>\n</details>')
