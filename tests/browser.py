"""Headless Chromium for the report tests: where it is, how it is started, and how a page is
measured.

A measuring copy of a report is the same page with its Content-Security-Policy meta removed and
a script added at the end of ``<body>`` that writes its measurements, as JSON, into a ``<pre>``
of the page; ``--dump-dom`` prints the page after the script ran. Chromium is Debian's
``chromium`` package (``.ci/run`` installs it when it is missing); elsewhere the tests that
need it skip with :data:`SKIP_REASON`.
"""

from __future__ import annotations

import html
import json
import re
import shutil
import subprocess
from pathlib import Path

import pytest

CHROMIUM = next((p for p in (shutil.which("chromium"), "/usr/bin/chromium") if p and Path(p).exists()), None)
SKIP_REASON = "needs headless Chromium: install the Debian package chromium (apt-get install chromium)"
#: ``pytestmark = needs_chromium`` in a module whose tests all drive the browser.
needs_chromium = pytest.mark.skipif(CHROMIUM is None, reason=SKIP_REASON)

_CSP = re.compile(r'<meta http-equiv="Content-Security-Policy"[^>]*>')


def chromium(profile_dir: Path, width: int, height: int, *args: str) -> subprocess.CompletedProcess:
    """Run headless Chromium with a window of *width* × *height* and its own profile directory."""
    assert CHROMIUM is not None, SKIP_REASON
    return subprocess.run(
        [CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         f"--user-data-dir={profile_dir}", f"--window-size={width},{height}", *args],
        capture_output=True, text=True, timeout=90)


def measure(report: Path, script: str, width: int, height: int, *args: str) -> dict:
    """Load a measuring copy of *report* at *width* × *height*; *script* (JavaScript) sets
    ``out``, an object, which is returned as a dict."""
    page = report.with_name(f"measure-{width}x{height}.html")
    probe = ('<pre id="measured"></pre><script>"use strict"; const out = {};\ntry {\n' + script +
             '\n} catch (e) { out.script_error = String(e); }\n'
             'document.getElementById("measured").textContent = JSON.stringify(out);</script></body>')
    page.write_text(_CSP.sub("", report.read_text(encoding="utf-8")).replace("</body>", probe), encoding="utf-8")
    proc = chromium(report.parent / f"chromium-{width}", width, height, *args, "--dump-dom", page.as_uri())
    assert proc.returncode == 0, proc.stderr[-2000:]
    m = re.search(r'<pre id="measured">(.*?)</pre>', proc.stdout, re.S)
    assert m and m.group(1), (proc.stdout[-2000:], proc.stderr[-2000:])
    out = json.loads(html.unescape(m.group(1)))
    assert "script_error" not in out, out["script_error"]
    return out
