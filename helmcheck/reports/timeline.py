"""The mode timeline as inline SVG: mode over run time, one lane per mode, events marked.

The step line follows ``results["timeline"]`` (RH-OUT-4: the mode the vehicle reported, over
run time in seconds). Below the lanes, one row each marks ``command`` events, real ``ack-error``
events (red), the tester's deliberate negative tests — ``ack-error`` events with
``"negative_test": true``, refusals the tester provoked on purpose — in a row of their own
(grey, "expected refusals"), ``lockout`` events (RH-SAF-1, also drawn as a line across the
lanes) and notes. Every mark has a ``<title>`` so a browser shows its label on hover, without any
script. All text is HTML-escaped: the SVG is embedded in the HTML report.
"""

from __future__ import annotations

import math
from html import escape
from typing import Any, Mapping

from .text import printable

__all__ = ["timeline_svg", "MODE_ORDER", "event_row", "event_counts"]

#: Lane order: stopped, mission modes, then the remote-helm modes (§3).
MODE_ORDER = ("S", "N", "P", "mP", "A", "M", "W")
_EVENT_ROWS = (("command", "commands"), ("ack-error", "ACK errors"), ("negative-test", "expected refusals"),
               ("lockout", "lockouts"), ("note", "notes"))
_MAX_MARKS = 4000  # per event kind; a longer run is thinned evenly and says so

_LEFT, _RIGHT, _TOP = 124, 16, 12
_WIDTH = 960
_LANE = 24
_ROW = 18


def _e(value: object) -> str:
    return escape(printable(value), quote=True)


def _nice_step(span: float, target: int = 10) -> float:
    raw = span / target
    mag = 10 ** math.floor(math.log10(raw)) if raw > 0 else 1
    for k in (1, 2, 5, 10):
        if raw <= k * mag:
            return k * mag
    return 10 * mag


def _thin(items: list[Any]) -> tuple[list[Any], int]:
    if len(items) <= _MAX_MARKS:
        return items, 0
    stride = len(items) / _MAX_MARKS
    return [items[int(i * stride)] for i in range(_MAX_MARKS)], len(items) - _MAX_MARKS


def event_row(event: Mapping[str, Any]) -> str:
    """The row an event is drawn in: its kind, or ``negative-test`` for a deliberate refusal."""
    if event.get("kind") == "ack-error" and event.get("negative_test") is True:
        return "negative-test"
    return str(event.get("kind"))


def event_counts(results: Mapping[str, Any]) -> dict[str, int]:
    """Events per row (:func:`event_row`): real ACK errors and negative tests counted apart."""
    out = {kind: 0 for kind, _ in _EVENT_ROWS}
    for ev in results.get("events") or []:
        row = event_row(ev)
        out[row] = out.get(row, 0) + 1
    return out


def timeline_svg(results: Mapping[str, Any]) -> str:
    """An ``<svg>`` element (a string) drawing the run's mode timeline and events."""
    timeline = list(results.get("timeline") or [])
    events = sorted(results.get("events") or [], key=lambda ev: ev["t"])
    modes = list(MODE_ORDER)
    for point in timeline:
        if point["mode"] not in modes:
            modes.append(point["mode"])
    t_end = max([results.get("duration_s") or 0.0]
                + [p["t"] for p in timeline] + [ev["t"] for ev in events])
    if t_end <= 0:
        t_end = 1.0
    plot_w = _WIDTH - _LEFT - _RIGHT
    lanes_h = len(modes) * _LANE
    rows_top = _TOP + lanes_h + 8
    axis_y = rows_top + len(_EVENT_ROWS) * _ROW + 4
    height = axis_y + 30

    def x(t: float) -> float:
        return round(_LEFT + plot_w * (t / t_end), 2)

    def lane_y(mode: str) -> float:
        return _TOP + modes.index(mode) * _LANE + _LANE / 2

    out = [f'<svg xmlns="http://www.w3.org/2000/svg" class="timeline" role="img" '
           f'viewBox="0 0 {_WIDTH} {height}" width="100%" '
           f'aria-label="Mode over run time, with commands, ACK errors, expected refusals and lockouts">']
    out.append("<title>Mode timeline</title>")
    for i, mode in enumerate(modes):
        y = _TOP + i * _LANE
        out.append(f'<rect class="lane{i % 2}" x="{_LEFT}" y="{y}" width="{plot_w}" height="{_LANE}"/>')
        out.append(f'<text class="lane-label" x="{_LEFT - 8}" y="{y + _LANE / 2 + 4}" '
                   f'text-anchor="end">{_e(mode)}</text>')
    for i, (_, label) in enumerate(_EVENT_ROWS):
        y = rows_top + i * _ROW
        out.append(f'<text class="row-label" x="{_LEFT - 8}" y="{y + _ROW / 2 + 4}" '
                   f'text-anchor="end">{_e(label)}</text>')
        out.append(f'<line class="row-rule" x1="{_LEFT}" x2="{_LEFT + plot_w}" '
                   f'y1="{y + _ROW / 2}" y2="{y + _ROW / 2}"/>')

    step = _nice_step(t_end)
    for k in range(int(t_end / step + 1e-9) + 1):
        tick = k * step
        tx = x(tick)
        out.append(f'<line class="grid" x1="{tx}" x2="{tx}" y1="{_TOP}" y2="{axis_y}"/>')
        label = f"{tick:g}" if step >= 1 else f"{tick:.{max(0, -math.floor(math.log10(step)))}f}"
        out.append(f'<text class="tick" x="{tx}" y="{axis_y + 14}" text-anchor="middle">{label} s</text>')

    if timeline:
        pts: list[str] = []
        for i, point in enumerate(timeline):
            t0 = point["t"]
            t1 = timeline[i + 1]["t"] if i + 1 < len(timeline) else t_end
            y = lane_y(point["mode"])
            pts.append(f"{'M' if i == 0 else 'L'}{x(t0)},{y}")
            pts.append(f"L{x(t1)},{y}")
        out.append(f'<path class="step" d="{" ".join(pts)}"/>')
        for i, point in enumerate(timeline):
            t1 = timeline[i + 1]["t"] if i + 1 < len(timeline) else t_end
            y = lane_y(point["mode"])
            out.append(f'<rect class="seg" x="{x(point["t"])}" y="{y - 5}" '
                       f'width="{max(0.5, round(x(t1) - x(point["t"]), 2))}" height="10">'
                       f'<title>{_e(point["mode"])} from {point["t"]:.3f} s to {t1:.3f} s</title></rect>')
    else:
        out.append(f'<text class="empty" x="{_LEFT + plot_w / 2}" y="{_TOP + lanes_h / 2}" '
                   f'text-anchor="middle">no mode timeline was recorded</text>')

    notes: list[str] = []
    for i, (kind, label) in enumerate(_EVENT_ROWS):
        cy = rows_top + i * _ROW + _ROW / 2
        marks, dropped = _thin([ev for ev in events if event_row(ev) == kind])
        if dropped:
            notes.append(f"{dropped} {label} not drawn")
        for ev in marks:
            ex = x(ev["t"])
            tip = f'<title>{ev["t"]:.3f} s {_e(ev["label"])}</title>'
            if kind == "command":
                out.append(f'<rect class="ev-command" x="{ex - 1}" y="{cy - 6}" width="2" height="12">{tip}</rect>')
            elif kind == "ack-error":
                out.append(f'<circle class="ev-ack-error" cx="{ex}" cy="{cy}" r="4">{tip}</circle>')
            elif kind == "negative-test":
                tip = f'<title>{ev["t"]:.3f} s expected refusal (negative test): {_e(ev["label"])}</title>'
                out.append(f'<circle class="ev-negative" cx="{ex}" cy="{cy}" r="3.5">{tip}</circle>')
            elif kind == "lockout":
                out.append(f'<line class="ev-lockout-line" x1="{ex}" x2="{ex}" y1="{_TOP}" y2="{cy}"/>')
                out.append(f'<path class="ev-lockout" d="M{ex},{cy - 6} L{ex + 6},{cy + 5} '
                           f'L{ex - 6},{cy + 5} Z">{tip}</path>')
            else:
                out.append(f'<path class="ev-note" d="M{ex},{cy - 5} L{ex + 5},{cy} L{ex},{cy + 5} '
                           f'L{ex - 5},{cy} Z">{tip}</path>')
    if notes:
        out.append(f'<text class="empty" x="{_LEFT}" y="{height - 2}">{_e("; ".join(notes))}</text>')
    out.append("</svg>")
    return "\n".join(out)
