"""The HTML report: complete, correctly coloured, self-contained, and safe against hostile data."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
from html.parser import HTMLParser
from pathlib import Path

import pytest

from helmcheck.reports.digest import digest_dir
from helmcheck.reports.render import render_all
from helmcheck.reports.results import finish, write_results_atomic
from tests.browser import CHROMIUM, needs_chromium

FIXTURES = Path(__file__).parent / "fixtures" / "reports"
HOSTILE = "<script>alert(1)</script>"
_VOID = {"meta", "br", "img", "input", "link", "hr", "source", "wbr", "area", "base", "col", "embed"}


class Page(HTMLParser):
    """Elements with their attributes and the ids of their ancestors; text per id'd element."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.elements: list[tuple[str, dict[str, str], tuple[str, ...], tuple[str, ...]]] = []
        self.stack: list[tuple[str, str | None, str]] = []
        self.text: dict[str, list[str]] = {}
        self.style = ""

    def handle_starttag(self, tag, attrs):
        a = {k: v or "" for k, v in attrs}
        ids = tuple(i for _, i, _ in self.stack if i)
        classes = tuple(c for _, _, c in self.stack)
        self.elements.append((tag, a, ids, classes))
        if tag not in _VOID:
            self.stack.append((tag, a.get("id"), a.get("class", "")))

    def handle_startendtag(self, tag, attrs):
        a = {k: v or "" for k, v in attrs}
        self.elements.append((tag, a, tuple(i for _, i, _ in self.stack if i), ()))

    def handle_endtag(self, tag):
        for i in range(len(self.stack) - 1, -1, -1):
            if self.stack[i][0] == tag:
                del self.stack[i:]
                break

    def handle_data(self, data):
        if self.stack and self.stack[-1][0] == "style":
            self.style += data
        for _, el_id, _ in self.stack:
            if el_id:
                self.text.setdefault(el_id, []).append(data)

    def find(self, tag=None, cls=None, inside=None):
        out = []
        for t, a, ids, _ in self.elements:
            if tag and t != tag:
                continue
            if cls and cls not in a.get("class", "").split():
                continue
            if inside and inside not in ids:
                continue
            out.append(a)
        return out

    def text_of(self, el_id: str) -> str:
        return "".join(self.text.get(el_id, []))


def render(tmp_path: Path, name: str, mutate=None) -> tuple[Path, str, Page, dict]:
    d = tmp_path / name
    shutil.copytree(FIXTURES / name, d)
    if mutate is not None:
        doc = json.loads((d / "results.json").read_text(encoding="utf-8"))
        mutate(doc)
        write_results_atomic(d, doc)
    render_all(d, formats=("html",))
    raw = (d / "report.html").read_text(encoding="utf-8")
    page = Page()
    page.feed(raw)
    page.close()
    return d, raw, page, json.loads((d / "results.json").read_text(encoding="utf-8"))


@pytest.mark.parametrize("name", ["pass_run", "fail_run", "backseat_run"])
def test_every_clause_is_in_the_matrix_with_its_verdict_class(tmp_path, name):
    _, _, page, doc = render(tmp_path, name)
    rows = page.find("tr", "clause")
    assert len(rows) == len(doc["clauses"])
    for c in doc["clauses"]:
        row_id = f"clause-{c['id']}"
        [row] = [r for r in rows if r.get("id") == row_id]
        assert row["data-verdict"] == c["verdict"]
        [cell] = page.find("td", "verdict", inside=row_id)
        assert f"v-{c['verdict']}" in cell["class"].split()
        assert c["id"] in page.text_of(row_id)
        assert c["reason"] in page.text_of(row_id)


def test_verdict_colour_classes_are_styled_distinctly(tmp_path):
    _, _, page, _ = render(tmp_path, "fail_run")
    colours = {}
    for verdict in ("pass", "non-strict", "fail", "inconclusive", "not-tested"):
        m = re.search(r"\.v-" + re.escape(verdict) + r"\{color:([^;]+);background:([^;}]+)", page.style)
        assert m, verdict
        colours[verdict] = m.groups()
    assert len(set(colours.values())) == 5
    assert page.find("div", "v-fail")[0]["id"] == "verdict"


def test_requirement_text_comes_from_the_profile(tmp_path):
    from helmcheck.clauses import catalogue

    _, _, page, _ = render(tmp_path, "pass_run")
    text = page.text_of("clause-RH-SRV-4")
    assert "If no accepted $OMS arrives within the timeout" in text
    assert catalogue()["RH-SRV-4"].text.replace("`", "") in text


def test_hostile_strings_appear_only_escaped(tmp_path):
    _, raw, page, doc = render(tmp_path, "fail_run")
    assert not page.find("script")
    assert not page.find("img")
    assert "<b>from A</b>" not in raw and "&lt;b&gt;from A&lt;/b&gt;" in raw  # markup in a reason stays text
    assert "<b>from A</b>" in page.text_of("finding-RH-FRM-4")
    for _, attrs, _, _ in page.elements:
        assert not any(k.lower().startswith("on") for k in attrs), attrs
    assert HOSTILE not in raw and "<img src=x" not in raw
    assert "&lt;script&gt;alert(1)&lt;/script&gt; &amp; $OMS" in raw
    assert HOSTILE in page.text_of("finding-RH-FRM-4")  # shown to the reader, as text
    assert doc["implementation"]["vehicle_name"] in page.text_of("implementation")


def test_hostile_mode_names_and_event_labels_in_the_timeline(tmp_path):
    def mutate(doc):
        doc["timeline"].append({"t": 10.0, "mode": "<g onload=alert(3)>"})
        doc["events"].append({"t": 10.1, "kind": "ack-error", "label": '"/><script>alert(4)</script>'})

    _, raw, page, _ = render(tmp_path, "fail_run", mutate)
    assert not page.find("script") and not page.find("g")
    assert "<g onload" not in raw and "<script>alert(4)" not in raw
    assert "<g onload=alert(3)>" in page.text_of("timeline")  # shown as text
    assert '"/><script>alert(4)</script>' in page.text_of("timeline")


def test_digest_is_in_the_page(tmp_path):
    d, _, page, _ = render(tmp_path, "fail_run")
    digest = digest_dir(d)
    assert digest.combined in page.text_of("digest")
    assert digest.results in page.text_of("digest") and digest.wire in page.text_of("digest")
    assert digest.combined in page.text_of("digest-footer")
    assert [m for m in page.find("meta") if m.get("name") == "helmcheck-digest"][0]["content"] == digest.combined


def test_findings_show_replay_steps_and_wire_excerpt(tmp_path):
    _, _, page, doc = render(tmp_path, "fail_run")
    judged_non_pass = {c["id"] for c in doc["clauses"] if c["verdict"] in ("fail", "inconclusive", "non-strict")}
    assert judged_non_pass
    assert {a["id"] for a in page.find("section", "finding")} == {f"finding-{cid}" for cid in judged_non_pass}
    for c in doc["clauses"]:
        if c["id"] in judged_non_pass:
            assert c["reason"] in page.text_of(f"finding-{c['id']}")
    replay = next(r for r in doc["replays"] if r["clause"] == "RH-SRV-4")
    steps = [a for a in page.find("li", inside="finding-RH-SRV-4")]
    assert len(steps) == len(replay["steps"])
    text = page.text_of("finding-RH-SRV-4")
    for ev in next(c for c in doc["clauses"] if c["id"] == "RH-SRV-4")["evidence"]:
        assert f"{ev['t']:.6f}" in text and ev["line"] in text
    assert not page.text_of("finding-RH-SRV-3")  # passing clauses get no finding


def test_partial_runs_are_marked(tmp_path):
    def interrupt(doc):
        finish(doc, finished=doc["finished"], partial=True, duration_s=5.0)

    _, _, page, doc = render(tmp_path, "pass_run", interrupt)
    assert doc["partial"] is True and doc["verdict"] == "inconclusive"
    assert "PARTIAL RUN" in page.text_of("partial")
    assert page.find("div", "partial")[0]["id"] == "partial"
    _, _, full, _ = render(tmp_path / "b", "pass_run")
    assert not full.find("div", "partial")


def test_missing_wire_log_is_reported_not_fatal(tmp_path):
    d = tmp_path / "run"
    shutil.copytree(FIXTURES / "pass_run", d)
    (d / "wire.log").unlink()
    render_all(d, formats=("html",))
    page = Page()
    page.feed((d / "report.html").read_text(encoding="utf-8"))
    assert "missing" in page.text_of("no-wire-log")
    assert "absent" in page.text_of("digest")


def test_page_is_self_contained(tmp_path):
    _, raw, page, _ = render(tmp_path, "fail_run")
    assert not page.find("link") and not page.find("iframe") and not page.find("object")
    for tag, attrs, _, _ in page.elements:
        for key, value in attrs.items():
            if key == "xmlns":
                continue
            assert not re.match(r"\s*(https?:|//|javascript:)", value, re.I), (tag, key, value)
            if key in ("href", "src"):
                assert value.startswith("#"), (tag, key, value)
    csp = [m for m in page.find("meta") if m.get("http-equiv") == "Content-Security-Policy"][0]["content"]
    assert "default-src 'none'" in csp and "script-src" not in csp


def test_coverage_and_timeline(tmp_path):
    _, _, page, doc = render(tmp_path, "fail_run")
    reached = {a.get("class") for a in page.find("span", "chip", inside="coverage")}
    assert reached == {"chip reached", "chip unreached"}
    cov_text = page.text_of("coverage")
    for a, b, via in doc["coverage"]["transitions"]:
        assert via in cov_text
    assert len(page.find("td", "hit", inside="coverage")) == len(doc["coverage"]["interrupt_pairs"])
    assert len(page.find("svg", "timeline")) == 1
    assert len(page.find("path", "step")) == 1
    assert len(page.find("rect", "seg")) == len(doc["timeline"])
    kinds = [e["kind"] for e in doc["events"]]
    assert len(page.find("circle", "ev-ack-error")) == kinds.count("ack-error")
    assert len(page.find("rect", "ev-command")) == kinds.count("command")
    assert len(page.find("path", "ev-lockout")) == kinds.count("lockout")


def test_same_directory_renders_the_same_bytes(tmp_path):
    d, raw, _, _ = render(tmp_path, "fail_run")
    render_all(d, formats=("html",))
    assert (d / "report.html").read_text(encoding="utf-8") == raw


@needs_chromium
def test_a_real_browser_sees_every_clause_and_no_script(tmp_path):
    d, _, _, doc = render(tmp_path, "fail_run")
    proc = subprocess.run(
        [CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--dump-dom", (d / "report.html").as_uri()],
        capture_output=True, text=True, timeout=60,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    dom = Page()
    dom.feed(proc.stdout)
    assert len(dom.find("tr", "clause")) == len(doc["clauses"])
    assert not dom.find("script") and not dom.find("img")
    assert HOSTILE in dom.text_of("finding-RH-FRM-4")
