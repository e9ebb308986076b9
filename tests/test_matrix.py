"""``helmcheck matrix``: the reference emulator and three faulty vehicles side by side.

Four short certifications (the same clause selection, time scale 25; see
``tests/test_certify_vehicle_mutants.py``) write real results directories; the matrix of them
must agree, cell by cell, with each run's ``results.json``, and link each cell to that clause in
that run's report. The pure renderer is also checked for labels and escaping.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from html.parser import HTMLParser

import pytest

from helmcheck.clauses import catalogue
from helmcheck.certify.vehicle.runner import Options, certify
from helmcheck.reports.matrix import MatrixRun, column_label, columns, render_matrix_html, render_matrix_markdown
from helmcheck.reports.results import add_clause, finish, new_results
from helmcheck.reports.view import VERDICT_LABEL
from tests.faulty_vehicles import EMU_PROFILE, MUTANTS, make_core, serve

FAULTY = ("wrong-err-number", "lowercase-checksum-out", "servo-timeout-ignored")
K = 25.0
HOSTILE = "<script>alert(1)</script>"


class Cells(HTMLParser):
    """Verdict cells (clause, verdict, link) per row, and the column headings."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.rows: dict[str, list[tuple[str, str | None]]] = {}
        self.headings: list[str] = []
        self.tags: list[tuple[str, dict]] = []
        self._cell: dict | None = None
        self._heading: list[str] | None = None

    def handle_starttag(self, tag, attrs):
        a = {k: v or "" for k, v in attrs}
        self.tags.append((tag, a))
        if tag == "td" and "data-clause" in a:
            self._cell = {"clause": a["data-clause"], "verdict": a["data-verdict"], "href": None}
            self.rows.setdefault(a["data-clause"], []).append(None)  # placeholder, filled at </td>
        elif tag == "a" and self._cell is not None:
            self._cell["href"] = a.get("href")
        elif tag == "th" and a.get("class") == "col":
            self._heading = []

    def handle_endtag(self, tag):
        if tag == "td" and self._cell is not None:
            self.rows[self._cell["clause"]][-1] = (self._cell["verdict"], self._cell["href"])
            self._cell = None
        elif tag == "div" and self._heading is not None:
            self.headings.append("".join(self._heading).strip())
            self._heading = None

    def handle_data(self, data):
        if self._heading is not None:
            self._heading.append(data)


#: The module-scoped run below is made once: all of this module's tests go to one worker.
pytestmark = pytest.mark.xdist_group("test_matrix")


@pytest.fixture(scope="module")
def run_dirs(tmp_path_factory):
    root = tmp_path_factory.mktemp("matrix")
    mutants = {m.name: m for m in MUTANTS}
    select = sorted({c for name in FAULTY for c in mutants[name].select})
    dirs = []
    for name in ("emulator", *FAULTY):
        m = mutants.get(name)
        with serve(lambda start: make_core(m, K, start)) as port:
            out = certify(Options(port=port, profile=EMU_PROFILE.replace(time_scale=K), time_scale=K,
                                  report_dir=root / "runs" / name, select=select, examples=0, progress=False,
                                  seed=1))
        assert out.verdict == ("pass" if m is None else "fail"), (name, out.reason)
        dirs.append(root / "runs" / name)
    return root, dirs


def test_matrix_of_the_emulator_and_three_faulty_vehicles_agrees_with_every_run(run_dirs):
    root, dirs = run_dirs
    out = root / "overview"
    proc = subprocess.run([sys.executable, "-m", "helmcheck", "matrix", *map(str, dirs), "--out", str(out)],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["wrote", str(out / "matrix.html"), "wrote", str(out / "matrix.md")]
    html = (out / "matrix.html").read_text()
    page = Cells()
    page.feed(html)
    assert list(page.rows) == list(catalogue())  # every clause, in profile order
    for col, d in enumerate(dirs):
        results = json.loads((d / "results.json").read_text())
        by_id = {c["id"]: c["verdict"] for c in results["clauses"]}
        for cid, cells in page.rows.items():
            verdict, href = cells[col]
            assert verdict == by_id.get(cid, "absent"), (d.name, cid)
            if cid in by_id:
                target, _, anchor = href.partition("#")
                assert anchor == f"clause-{cid}"
                assert (out / target).resolve() == (d / "report.html").resolve()
                assert f'id="clause-{cid}"' in (d / "report.html").read_text()
    fails = {d.name: [cid for cid, cells in page.rows.items() if cells[i][0] == "fail"] for i, d in enumerate(dirs)}
    mutants = {m.name: m for m in MUTANTS}
    assert fails["emulator"] == []
    for name in FAULTY:
        assert mutants[name].clause in fails[name]
    labels = page.headings
    assert len(labels) == 4 and len(set(labels)) == 4
    assert all(d.name in label for d, label in zip(dirs, labels))  # no identity declared: the directory
    # self-contained: no script, nothing fetched
    assert "<script" not in html.lower()
    assert not [a for t, a in page.tags if t in ("link", "img", "iframe") or "src" in a]
    assert all(not a.get("href", "").startswith(("http:", "https:", "//")) for _, a in page.tags)

    md = (out / "matrix.md").read_text().splitlines()
    for cid in catalogue():
        row = next(line for line in md if line.startswith(f"| {cid} ("))
        cells = [c.strip() for c in row.strip("|").split("|")][1:]
        for cell, d in zip(cells, dirs):
            results = json.loads((d / "results.json").read_text())
            verdict = {c["id"]: c["verdict"] for c in results["clauses"]}.get(cid)
            if verdict is None:
                assert cell == "—"
            else:
                rel = os.path.relpath(d / "report.html", out)
                assert cell == f"[{VERDICT_LABEL[verdict]}](<{rel}#clause-{cid}>)", cell


def test_unreadable_directory_is_one_line_and_exit_2(tmp_path, run_dirs):
    _, dirs = run_dirs
    bad = tmp_path / "nothing-here"
    bad.mkdir()
    proc = subprocess.run([sys.executable, "-m", "helmcheck", "matrix", str(dirs[0]), str(bad),
                           "--out", str(tmp_path / "o")], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and str(bad / "results.json") in proc.stderr
    assert not (tmp_path / "o" / "matrix.html").exists()


def _results(identity=None, implementation=None, started="2026-11-20T08:00:00Z", verdict="pass") -> dict:
    r = new_results("vehicle", started=started, implementation=implementation)
    if identity is not None:
        r["identity"] = identity
    add_clause(r, "RH-SRV-4", verdict, f"why {HOSTILE}")
    finish(r, finished=started)
    return r


def test_column_labels_prefer_identity_then_the_declared_vehicle_then_the_directory():
    assert column_label(_results(identity={"implementation": "UVC", "version": "3.3.1", "serial": "x"})) == "UVC 3.3.1"
    assert column_label(_results(identity={"name": "pHelmIvP"})) == "pHelmIvP"
    assert column_label(_results(implementation={"vehicle_name": "IVER3-3071", "uvc_version": "5.1"})) \
        == "IVER3-3071 5.1"
    assert column_label(_results(), "reports/uvc-nightly/") == "uvc-nightly"
    cols = columns([MatrixRun(_results(), source="a/same"), MatrixRun(_results(), source="b/same")])
    assert [c.label for c in cols] == ["same (2026-11-20) [a/same]", "same (2026-11-20) [b/same]"]


def test_everything_from_a_results_file_is_escaped():
    r = _results(identity={"implementation": HOSTILE, "version": "1|2 `x` [y](z)"}, verdict="fail")
    runs = [MatrixRun(r, href=f'runs/"{HOSTILE}"/report.html', source=HOSTILE)]
    html = render_matrix_html(runs, title=HOSTILE)
    assert HOSTILE not in html and "&lt;script&gt;" in html
    assert 'href="runs/%22%3Cscript%3Ealert%281%29%3C/script%3E%22/report.html#clause-RH-SRV-4"' in html
    assert 'title="why &lt;script&gt;alert(1)&lt;/script&gt;"' in html
    md = render_matrix_markdown(runs, title=HOSTILE)
    assert HOSTILE not in md and "1\\|2 \\`x\\` \\[y\\](z)" in md
    header = md.splitlines()[2]
    assert len(re.findall(r"(?<!\\)\|", header)) == 3  # the label's pipe is escaped: still two columns
