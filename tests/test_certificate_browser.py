"""The certificate in a real browser: verdict, scope and identity above the fold at 1280×800.

Headless Chromium loads a measuring copy of ``report.html`` — the same page with its
Content-Security-Policy meta removed and a script added that writes the
``getBoundingClientRect()`` of the certificate's parts into the page — and ``--dump-dom``
prints the result. The fold is the page area of a 1280×800 window as the browser reports it
(``innerHeight``; Chromium leaves room for its toolbar in ``--dump-dom`` mode, so it may be less
than 800). A screenshot at the same size is taken too and its PNG size checked. The module is
skipped, with a line naming the Debian package, where Chromium is not installed
(:mod:`tests.browser`).
"""

from __future__ import annotations

import json
import shutil
import struct
from pathlib import Path

import pytest

from helmcheck.profile import DEFAULT
from helmcheck.reports.certificate import RunDeclaration, finish_run
from helmcheck.reports.identity import Declared
from helmcheck.reports.render import render_all
from helmcheck.reports.results import load_results
from helmcheck.reports.signing import generate_keypair, load_signing_key
from tests.browser import chromium, measure, needs_chromium

FIXTURES = Path(__file__).parent / "fixtures" / "reports"
WIDTH, HEIGHT = 1280, 800
PARTS = ("verdict", "scope", "identity", "signature", "digest")

pytestmark = needs_chromium

_MEASURE = """out.viewport = [window.innerWidth, window.innerHeight];
for (const id of %s) {
  const el = document.getElementById(id);
  if (el) { const r = el.getBoundingClientRect(); out[id] = [r.left, r.top, r.right, r.bottom]; }
}"""


def _run_dir(tmp_path: Path, name: str, declared: Declared, signed: bool) -> Path:
    d = tmp_path / name
    shutil.copytree(FIXTURES / name, d)
    key = None
    if signed:
        key_path, _, _ = generate_keypair(tmp_path / f"{name}-key")
        key = load_signing_key(key_path)
    finish_run(load_results(d), d, DEFAULT.replace(vehicle_serial="EMU-0001", uvc_version="5.2.1"),
               RunDeclaration(declared, key))
    render_all(d, formats=("html",))
    return d


def _measure(tmp_path: Path, report: Path) -> dict:
    return measure(report, _MEASURE % json.dumps(PARTS), WIDTH, HEIGHT, "--hide-scrollbars")


@pytest.mark.unverifiable  # hand-made results fixtures, not runs
@pytest.mark.parametrize("name,declared,signed", [
    ("pass_run", Declared(operator="J. Doe", site="Bench 2, Newport"), True),
    ("fail_run", Declared(), False),
    ("backseat_run", Declared(implementation_name="good-backseat", implementation_version="1.0"), True),
])
def test_verdict_scope_and_identity_are_above_the_fold(tmp_path, name, declared, signed):
    d = _run_dir(tmp_path, name, declared, signed)
    rects = _measure(tmp_path, d / "report.html")
    width, fold = rects["viewport"]
    assert width == WIDTH and 0 < fold <= HEIGHT  # a 1280×800 window; its page area may be shorter
    for part in PARTS:
        left, top, right, bottom = rects[part]
        assert 0 <= top < bottom <= fold, (part, rects)
        assert 0 <= left < right <= WIDTH, (part, rects)
    v, i = rects["verdict"], rects["identity"]
    assert v[3] <= i[1]  # the verdict and scope come first, what was tested under them


@pytest.mark.unverifiable
def test_screenshot_is_taken_at_the_viewport_size(tmp_path):
    d = _run_dir(tmp_path, "pass_run", Declared(operator="J. Doe"), True)
    shot = tmp_path / "certificate.png"
    proc = chromium(tmp_path / "chromium-profile", WIDTH, HEIGHT, "--hide-scrollbars", f"--screenshot={shot}",
                    (d / "report.html").as_uri())
    assert proc.returncode == 0 and shot.exists(), proc.stderr[-2000:]
    head = shot.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    assert struct.unpack(">II", head[16:24]) == (WIDTH, HEIGHT)
