"""The documentation site works opened as files: ``site/index.html`` from disk, in a real browser
(headless Chromium, :mod:`tests.browser`), every navigation link clicked leads to a page of the
site — not to the browser's "Index of …" file listing, not to a missing file.

The site is built as ``make docs`` builds it (``mkdocs.yml``, strict) into a temporary directory.
A probe page beside it loads ``index.html`` in a frame, takes the destinations of its navigation
(the left-hand pages and the header's title link, as the browser resolves them) and clicks each in
turn, from the page the previous click led to (so the relative links of nested pages are followed
too), back from ``index.html`` after a page that was not one. On every page, at 1280 px, no code
block scrolls sideways (``docs/stylesheets/extra.css`` wraps them: the ``# …`` comment at the end
of a long command stays in view). Chromium runs with
``--allow-file-access-from-files`` so the probe can read the frame's document. About ten seconds.
"""

from __future__ import annotations

import html
import json
import re
import shutil
from pathlib import Path

import pytest

from tests.browser import chromium, needs_chromium
from tests.test_docs_site import ROOT, _build

pytestmark = [needs_chromium, pytest.mark.xdist_group("docs-site-browser")]  # one build for the module

#: The probe: ``LIMIT`` bad pages stop it (0: none does).
_PROBE = r"""<!doctype html><html><body>
<iframe id="f" style="width:1200px;height:800px"></iframe><pre id="measured"></pre>
<script>
"use strict";
const START = new URL("site/index.html", location.href).href, LIMIT = %(limit)d;
const out = {links: [], pages: {}, bad: {}};
const f = document.getElementById("f");
const NAV = "nav.md-nav a.md-nav__link[href], a.md-header__button.md-logo[href]";
function go(act) {
  return new Promise(done => {
    const t = setTimeout(() => done("no load event in 10 s"), 10000);
    f.addEventListener("load", () => { clearTimeout(t); done(null); }, {once: true});
    act();
  });
}
function doc() { try { return f.contentDocument; } catch (e) { return null; } }
function page(where) {
  const d = doc();
  if (!d || !d.body) return "no page (a missing file?)";
  if (/^Index of /.test(d.title) || d.querySelector("#parentDirLinkBox"))
    return "a file listing: " + d.title;
  if (!d.querySelector("article.md-content__inner")) return "not a page of the site: " + JSON.stringify(d.title);
  const wide = [...d.querySelectorAll("pre > code")].filter(c => c.scrollWidth > c.clientWidth + 1);
  if (wide.length) return "a code block scrolls sideways: " + JSON.stringify(wide[0].textContent.slice(0, 60));
  return null;
}
function destinations() {
  return [...new Set([...doc().querySelectorAll(NAV)].map(a => a.href.split("#")[0]))];
}
(async () => {
  try {
    let why = await go(() => { f.src = START; }) || page();
    if (why) { out.bad[START] = why; return; }
    out.links = destinations();
    let good = true;
    for (const href of out.links) {
      if (!good) {
        why = await go(() => { f.src = START; });
        if (why) { out.bad[START] = why; return; }
      }
      const from = f.contentWindow.location.href;
      const a = [...doc().querySelectorAll(NAV)].find(x => x.href.split("#")[0] === href);
      if (!a) { out.bad[href] = "no link to it on " + from; good = false; continue; }
      why = await go(() => a.click());
      const at = why ? "" : (doc() ? f.contentWindow.location.href.split("#")[0] : "");
      why = why || page() || (at !== href ? "the link led to " + at : null);
      out.pages[href] = from;
      good = !why;
      if (why) {
        out.bad[href] = why;
        if (LIMIT && Object.keys(out.bad).length >= LIMIT) return;
      }
    }
  } catch (e) {
    out.script_error = String(e);
  } finally {
    document.getElementById("measured").textContent = JSON.stringify(out);
  }
})();
</script></body></html>
"""


def crawl(site: Path, limit: int = 0) -> dict:
    """Click through *site*'s navigation from its ``index.html`` (opened as a file)."""
    probe = site.parent / "probe.html"
    probe.write_text(_PROBE % {"limit": limit}, encoding="utf-8")
    proc = chromium(site.parent / "chromium-profile", 1280, 800, "--allow-file-access-from-files",
                    "--dump-dom", probe.as_uri())
    assert proc.returncode == 0, proc.stderr[-2000:]
    m = re.search(r'<pre id="measured">(.*?)</pre>', proc.stdout, re.S)
    assert m and m.group(1), (proc.stdout[-2000:], proc.stderr[-2000:])
    out = json.loads(html.unescape(m.group(1)))
    assert "script_error" not in out, out["script_error"]
    return out


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    where = tmp_path_factory.mktemp("docs-site")
    run = _build(ROOT / "mkdocs.yml", where / "site")
    assert run.returncode == 0, run.stderr[-4000:]
    return where / "site"


def _relative(url: str, site: Path) -> str:
    return url.removeprefix(site.as_uri() + "/")


def test_every_navigation_link_opens_a_page_from_disk(site):
    out = crawl(site)
    pages = {_relative(u, site) for u in out["links"]}
    assert not out["bad"], {_relative(u, site): why for u, why in out["bad"].items()}
    nav = len(re.findall(r"^\s*- [^:]+: \S+\.md$", (ROOT / "mkdocs.yml").read_text(encoding="utf-8"), re.M))
    assert len(pages) == nav and "index.html" in pages and "guide/certify-vehicle.html" in pages, sorted(pages)
    assert set(out["pages"]) == set(out["links"])
    assert any("/guide/" in u for u in out["pages"].values()), "no link was followed from a nested page"


def test_the_check_fails_on_a_file_listing_a_missing_page_and_a_scrolling_code_block(site, tmp_path):
    """A copy of the site, damaged three ways: one page where directory URLs (mkdocs' default,
    what the site had) put it, ``guide/certify-vehicle/index.html``, every link to it naming the
    directory (a browser opened on files shows the directory's listing); one page missing; the
    site's stylesheet gone (a long command line scrolls, its comment out of view)."""
    copy = tmp_path / "site"
    shutil.copytree(site, copy)
    (copy / "guide" / "certify-vehicle").mkdir()
    (copy / "guide" / "certify-vehicle.html").rename(copy / "guide" / "certify-vehicle" / "index.html")
    for page in copy.rglob("*.html"):
        text = page.read_text(encoding="utf-8")
        text = re.sub(r'href="((?:\.\./)*(?:guide/)?)certify-vehicle\.html', r'href="\1certify-vehicle/', text)
        page.write_text(text, encoding="utf-8")
    (copy / "guide" / "certify-backseat.html").unlink()
    (copy / "stylesheets" / "extra.css").write_text("", encoding="utf-8")
    out = crawl(copy, limit=3)
    bad = {_relative(u, copy): why for u, why in out["bad"].items()}
    assert bad.get("guide/certify-vehicle/", "").startswith("a file listing"), bad
    assert bad.get("guide/certify-backseat.html", "").startswith("no page (a missing file"), bad
    assert any(why.startswith("a code block scrolls sideways") for why in bad.values()), bad
