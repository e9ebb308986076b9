"""The documentation site builds in strict mode, its generated pages are current, and what the
README hands over to it is there.

``mkdocs build --strict`` (``mkdocs.yml``: every page in the navigation, every link and anchor
resolved, every included file present) runs on the checked-in ``docs/`` into a temporary
directory, in about two seconds; every local link of its pages names a file, so the site works
opened from disk (``use_directory_urls: false``; tests/test_docs_site_browser.py clicks through
it in a browser). The generated files (``helmcheck docs``: the grammar, the model, the profile
keys, the clause catalogue, the reference profile, ``examples/emulator.toml``) must equal a fresh
render.
"""

from __future__ import annotations

import dataclasses
import os
import re
import subprocess
import sys
import time
from pathlib import Path

import pytest

from helmcheck.clauses import catalogue
from helmcheck.commands import docs_cmd
from helmcheck.profile import BenchSafety, profile_keys
from helmcheck.profile_template import check as load_template

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"


def _build(config: Path, site: Path) -> subprocess.CompletedProcess:
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1")
    return subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--config-file", str(config),
                           "--site-dir", str(site)], capture_output=True, text=True, env=env, timeout=120)


def test_the_site_builds_in_strict_mode(tmp_path):
    started = time.monotonic()
    run = _build(ROOT / "mkdocs.yml", tmp_path / "site")
    took = time.monotonic() - started
    assert run.returncode == 0 and "WARNING" not in run.stderr, run.stderr[-4000:]
    for page in ("index.html", "reference/profile-keys.html", "reference/clauses.html",
                 "guide/certify-backseat.html", "examples.html"):
        assert (tmp_path / "site" / page).is_file(), page
    assert took < 60, f"the strict build took {took:.1f} s"
    assert not _unresolved(tmp_path / "site"), _unresolved(tmp_path / "site")


def _unresolved(site: Path) -> list[str]:
    """Every local link of every page that does not name a file (a directory is what a browser
    shows as a file listing when the site is opened from disk); 404.html is served, not opened."""
    bad = []
    for page in site.rglob("*.html"):
        if page.name == "404.html":
            continue
        for ref in re.findall(r'(?:href|src)="([^"#?]+)', page.read_text(encoding="utf-8")):
            if not ref.startswith(("http:", "https:", "mailto:", "data:")) and not (page.parent / ref).is_file():
                bad.append(f"{page.relative_to(site)}: {ref}")
    return bad


def test_a_directory_link_is_unresolved(tmp_path):
    (tmp_path / "guide").mkdir()
    (tmp_path / "index.html").write_text('<a href="guide/">g</a> <a href="x.html#a">x</a> <a href="#top">t</a>')
    (tmp_path / "x.html").write_text('<a href="index.html">i</a>')
    assert _unresolved(tmp_path) == ["index.html: guide/"]


def test_a_broken_link_fails_the_strict_build(tmp_path):
    """The check can fail: the same configuration on a copy of the site with one broken link."""
    text = (ROOT / "mkdocs.yml").read_text(encoding="utf-8")
    docs = tmp_path / "docs"
    docs.mkdir()
    (docs / "index.md").write_text("# x\n\nSee [the missing page](missing.md) and [a section](#nowhere).\n")
    config = tmp_path / "mkdocs.yml"
    config.write_text(re.sub(r"(?ms)^nav:.*", "nav:\n  - Home: index.md\n", text))
    run = _build(config, tmp_path / "site")
    assert run.returncode != 0
    assert "missing.md" in run.stderr and "nowhere" in run.stderr


def test_every_generated_file_is_current():
    stale = docs_cmd.stale()
    assert not stale, f"stale: {stale}: run 'helmcheck docs'"


def test_the_profile_key_page_has_every_key():
    text = (DOCS / "reference" / "profile-keys.md").read_text(encoding="utf-8")
    keys = [f.name for f in profile_keys() if f.name != "bench_safety"]
    keys += [f"bench_safety.{g.name}" for g in dataclasses.fields(BenchSafety)]
    missing = [k for k in keys if f"### `{k}`" not in text]
    assert not missing, missing


def test_the_clause_catalogue_page_has_every_clause():
    text = (DOCS / "reference" / "clauses.md").read_text(encoding="utf-8")
    profile = (DOCS / "reference" / "reference-profile.md").read_text(encoding="utf-8")
    for cid in catalogue():
        assert f'<span id="{cid}"></span>[{cid}]' in text, cid
        assert f'<span id="{cid}"></span>**{cid}**' in profile, cid


def test_the_example_profile_loads():
    load_template((ROOT / "examples" / "emulator.toml").read_text(encoding="utf-8"), where="examples/emulator.toml")


def _readme_links() -> list[str]:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    return [t for t in re.findall(r"\]\(([^)\s]+)\)", text) if not t.startswith(("http", "#"))]


def test_every_link_of_the_readme_resolves():
    links = _readme_links()
    assert any(t.startswith("docs/") for t in links)
    missing = [t for t in links if not (ROOT / t.split("#", 1)[0]).exists()]
    assert not missing, missing


#: What the README held before it became a landing page, and the page that holds it now.
MOVED = [
    ("guide/certify-vehicle.md", "`--plan` says so"),
    ("bench-safety.md", "## Time scale check"),
    ("bench-safety.md", "## On a bench vehicle"),
    ("exploration.md", "make explore-reach"),
    ("exploration.md", "| measured | emulator mutants"),
    ("guide/diff.md", "Not a divergence"),
    ("guide/check-log.md", "a log of 4 MiB or more"),
    ("known-wrong-verdicts.md", "RH-OUT-4"),
    ("guide/archives.md", "check-key.json"),
    ("guide/archives.md", "## A cluster"),
    ("guide/monitor.md", "DB9 pin 3"),
    ("guide/monitor.md", "rtprio"),
    ("guide/parse-report.md", "helmcheck matrix"),
    ("guide/sign-verify.md", "not a certificate"),
    ("reference/exit-codes.md", "| 64 |"),
    ("guide/ci.md", "--exec-grace"),
    ("guide/ci.md", "## As pytest items"),
    ("guide/python.md", "certify_backseat(BackseatOptions("),
    ("reference/wire-log.md", "# helmcheck wire-log 1"),
    ("guide/profiles.md", "profile init"),
    ("choices.md", "CLEAR_FACTOR"),
    ("benchmarks.md", "check_log_bench.py"),
    ("benchmarks.md", "Why the 10 s target stays out of reach"),
    ("architecture.md", "tests/test_layering.py"),
]


@pytest.mark.parametrize(("page", "phrase"), MOVED, ids=[f"{p}:{w[:20]}" for p, w in MOVED])
def test_what_the_readme_handed_over_is_on_the_site(page, phrase):
    assert phrase in (DOCS / page).read_text(encoding="utf-8")
