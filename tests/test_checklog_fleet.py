"""``helmcheck check-log DIR|GLOB…``: whole archives, each command a real ``helmcheck`` process.

An archive of the fixture logs (clean, faulty, a socat capture under another name, a nested
folder, a file that is no log, a file that cannot be read) is checked as a whole: per-file
verdicts as ``check-log FILE`` gives them, the summary, the exit status of docs/contracts.md;
the cache (a second run judges nothing; ``--force``, a changed log or profile judges again);
``--jobs 2`` and a Dask ``LocalCluster`` started here give the bytes ``--jobs 1`` gives; usage
errors are one line and 64; Ctrl-C leaves the finished files and a partial summary.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
LOGS = ROOT / "tests" / "fixtures" / "logs"
#: the run's clock in results.json: the only bytes two checks of the same log may differ in
CLOCK = re.compile(rb'"(started|finished)": "[^"]*"|"(duration_s|check_seconds)": (null|[-+0-9.eE]+)')
CLOCKED = {"report.html", "report.md", "junit.xml"}  #: renderings of results.json, clock included

pytestmark = pytest.mark.xdist_group("checklog_fleet")


def helmcheck(*argv, cwd: Path, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "helmcheck", *map(str, argv)], cwd=cwd, capture_output=True,
                          text=True, timeout=timeout)


def one_line(err: str) -> str:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("helmcheck check-log: "), err
    assert "Traceback" not in err
    return lines[0]


@pytest.fixture
def archive(tmp_path: Path) -> Path:
    """clean, faulty (two, one nested deeper), a socat capture named .txt, a note, a dangling link."""
    a = tmp_path / "archive"
    (a / "vehicle-7" / "2026-11-02").mkdir(parents=True)
    shutil.copy(LOGS / "nominal.log", a / "nominal.log")
    shutil.copy(LOGS / "vehicle_faults.log", a / "vehicle-7" / "faults.log")
    shutil.copy(LOGS / "backseat_faults.log", a / "vehicle-7" / "2026-11-02" / "bs.log")
    shutil.copy(LOGS / "socat_v.log", a / "vehicle-7" / "capture.txt")
    (a / "vehicle-7" / "notes.md").write_text("# dive notes\nnothing to judge here\n")
    (a / "gone.log").symlink_to(a / "moved-away.log")
    return a


def summary(out: Path) -> dict:
    return json.loads((out / "summary.json").read_text())


def by_path(doc: dict) -> dict:
    return {f["path"]: f for f in doc["files"]}


LOGS_IN_ARCHIVE = ["nominal.log", "vehicle-7/2026-11-02/bs.log", "vehicle-7/capture.txt", "vehicle-7/faults.log"]


def test_mixed_archive_verdicts_summary_and_exit(archive: Path, tmp_path: Path):
    out = tmp_path / "out"
    done = helmcheck("check-log", archive, "--report-dir", out, "--jobs", "1", cwd=tmp_path)
    doc = summary(out)
    files = by_path(doc)
    assert sorted(files) == sorted(LOGS_IN_ARCHIVE + ["gone.log"])
    # every log's verdicts are those `check-log FILE` gives it alone, in its mirrored directory
    for rel in LOGS_IN_ARCHIVE:
        single = tmp_path / "single" / rel
        alone = helmcheck("check-log", archive / rel, "--report-dir", single, cwd=tmp_path)
        res = json.loads((single / "results.json").read_text())
        mine = json.loads((out / rel / "results.json").read_text())
        assert mine["verdict"] == res["verdict"] == files[rel]["verdict"], rel
        assert {c["id"]: c["verdict"] for c in mine["clauses"]} == {c["id"]: c["verdict"] for c in res["clauses"]}
        assert files[rel]["status"] == "judged" and files[rel]["exit_code"] == alone.returncode
        assert (out / rel / "report.html").is_file() and (out / rel / "check-key.json").is_file()
    assert files["nominal.log"]["verdict"] == "pass"
    assert files["vehicle-7/faults.log"]["verdict"] == "fail"
    assert "RH-ACK-3" in files["vehicle-7/faults.log"]["failed"]
    assert json.loads((out / "vehicle-7/capture.txt/results.json").read_text())["log"]["format"] == "socat-v"
    # the unreadable file is in the summary, counted 2; the note is skipped with its reason
    assert files["gone.log"]["status"] == "unreadable" and files["gone.log"]["exit_code"] == 2
    assert "gone.log" in done.stdout
    assert [s["path"] for s in doc["skipped"]] == ["vehicle-7/notes.md"]
    assert "not a log" in doc["skipped"][0]["reason"]
    # exit: the worst over the files, a failure (1) over the unreadable file (2)
    assert done.returncode == 1 == doc["exit_code"], done.stderr
    assert doc["counts"]["fail"] == 2 and doc["counts"]["pass"] >= 1 and doc["counts"]["unreadable"] == 1
    assert doc["clauses"]["RH-ACK-3"]["fail"] == 1
    assert done.stdout.strip().splitlines()[-1] == doc["verdict_line"] and doc["verdict_line"].startswith("FAIL")
    md = (out / "summary.md").read_text()
    assert "## Clauses × files" in md and "helmcheck archive check" in md
    assert "| RH-ACK-3 (MUST) |" in md  # the matrix view, helmcheck matrix's own
    html = (out / "matrix.html").read_text()
    assert html.count('<th class="col"') == 4 and 'href="vehicle-7/faults.log/report.html#clause-RH-ACK-3"' in html


def test_unreadable_file_alone_keeps_the_run_from_exit_0(archive: Path, tmp_path: Path):
    for p in list(archive.rglob("*")):
        if p.name not in ("nominal.log", "gone.log") and (p.is_file() or p.is_symlink()):
            p.unlink()
    done = helmcheck("check-log", archive, "--report-dir", tmp_path / "out", "--jobs", "1", cwd=tmp_path)
    assert done.returncode == 2, done.stdout + done.stderr
    doc = summary(tmp_path / "out")
    assert doc["exit_code"] == 2 and doc["counts"]["pass"] == 1 and doc["counts"]["unreadable"] == 1
    assert doc["verdict_line"].startswith("INCONCLUSIVE")


def _stamps(out: Path) -> dict:
    return {str(p.relative_to(out)): (p.stat().st_ino, p.stat().st_mtime_ns)
            for p in sorted(out.rglob("*")) if p.is_file() and p.parent != out}


def test_second_run_judges_nothing_force_and_changes_judge_again(archive: Path, tmp_path: Path):
    out = tmp_path / "out"
    first = helmcheck("check-log", archive, "--report-dir", out, "--jobs", "2", cwd=tmp_path)
    assert first.returncode == 1
    before = _stamps(out)
    time.sleep(0.05)
    again = helmcheck("check-log", archive, "--report-dir", out, "--jobs", "2", cwd=tmp_path)
    assert again.returncode == 1 and _stamps(out) == before  # not one results file rewritten
    doc = summary(out)
    assert {f["status"] for f in doc["files"] if f["path"] != "gone.log"} == {"cached"}
    assert doc["counts"]["judged"] == 0 and doc["counts"]["cached"] == 4 and "4 cached" in again.stdout
    assert by_path(doc)["vehicle-7/faults.log"]["verdict"] == "fail"  # a cached file keeps its verdict
    # a changed log is judged again, the others stay cached
    with open(archive / "nominal.log", "a") as f:
        f.write("# appended later\n")
    helmcheck("check-log", archive, "--report-dir", out, cwd=tmp_path)
    doc = summary(out)
    assert {f["path"]: f["status"] for f in doc["files"]}["nominal.log"] == "judged"
    assert doc["counts"]["judged"] == 1 and doc["counts"]["cached"] == 3
    # another profile changes every key
    prof = tmp_path / "p.toml"
    prof.write_text('fault_injection = "oxflt"\nlockout_s = 25.0\n')
    helmcheck("check-log", archive, "--report-dir", out, "--profile", prof, cwd=tmp_path)
    assert summary(out)["counts"]["judged"] == 4
    # --force judges every log again: new files
    stamps = _stamps(out)
    forced = helmcheck("check-log", archive, "--report-dir", out, "--profile", prof, "--force", cwd=tmp_path)
    assert forced.returncode == 1 and summary(out)["counts"]["judged"] == 4
    now = _stamps(out)
    for rel in LOGS_IN_ARCHIVE:
        assert now[f"{rel}/results.json"] != stamps[f"{rel}/results.json"]


def _tree(out: Path) -> dict:
    """Every per-file result, the run's clock taken out of results.json; the renderings of
    results.json (which show that clock) are compared through it."""
    tree = {}
    for p in sorted(out.rglob("*")):
        if not p.is_file() or p.parent == out or p.name in CLOCKED:
            continue
        data = p.read_bytes()
        tree[str(p.relative_to(out))] = CLOCK.sub(b"<clock>", data) if p.name == "results.json" else data
    return tree


def test_jobs_and_local_cluster_give_the_bytes_of_jobs_1(archive: Path, tmp_path: Path):
    distributed = pytest.importorskip("distributed")
    runs = {}
    for name, opts in (("one", ["--jobs", "1"]), ("two", ["--jobs", "2"])):
        done = helmcheck("check-log", archive, "--report-dir", tmp_path / name, *opts, cwd=tmp_path)
        assert done.returncode == 1, done.stderr
        runs[name] = _tree(tmp_path / name)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  host="127.0.0.1") as cluster:
        done = helmcheck("check-log", archive, "--report-dir", tmp_path / "cluster", "--cluster",
                         cluster.scheduler_address, cwd=tmp_path)
    assert done.returncode == 1, done.stdout + done.stderr
    runs["cluster"] = _tree(tmp_path / "cluster")
    assert sorted(runs["one"]) == sorted(runs["two"]) == sorted(runs["cluster"])
    assert {k for k in runs["one"] if k.endswith("results.json")} == {f"{r}/results.json" for r in LOGS_IN_ARCHIVE}
    for key, data in runs["one"].items():
        assert runs["two"][key] == data, key
        assert runs["cluster"][key] == data, key
    assert summary(tmp_path / "cluster")["options"]["engine"].startswith("cluster tcp://127.0.0.1:")
    one, cl = by_path(summary(tmp_path / "one")), by_path(summary(tmp_path / "cluster"))
    assert {k: v.get("verdict") for k, v in one.items()} == {k: v.get("verdict") for k, v in cl.items()}


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.parametrize("argv, says", [
    (["--cluster", "http://example.org:8786"], "not a scheduler address"),
    (["--cluster", "tcp://no-port-here"], "not a scheduler address"),
    (["--jobs", "0"], "--jobs must be at least 1"),
    (["--jobs", "2", "--cluster", "tcp://127.0.0.1:8786"], "exclude each other"),
    (["--time-scale", "0"], "--time-scale must be positive"),
])
def test_usage_errors_are_one_line_and_64(archive: Path, tmp_path: Path, argv, says):
    done = helmcheck("check-log", archive, "--report-dir", tmp_path / "out", *argv, cwd=tmp_path)
    assert done.returncode == 64 and says in one_line(done.stderr)
    assert not (tmp_path / "out").exists()


def test_arguments_naming_nothing_are_64(tmp_path: Path):
    (tmp_path / "empty").mkdir()
    (tmp_path / "empty" / "readme.txt").write_text("no log\n")
    for argv, says in ((["missing-dir/", "--jobs", "1"], "No such file"), (["missing-dir/"], "no such file"), (["*.nolog"], "matches nothing"),
                       (["empty"], "no log found in empty (1 file(s) skipped")):
        done = helmcheck("check-log", *argv, "--report-dir", tmp_path / "out", cwd=tmp_path)
        assert done.returncode == 64 and says in one_line(done.stderr), argv


def test_report_dir_holding_something_else_is_refused(archive: Path, tmp_path: Path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "thesis.tex").write_text("mine\n")
    done = helmcheck("check-log", archive, "--report-dir", out, cwd=tmp_path)
    assert done.returncode == 64 and "holds no earlier archive check" in one_line(done.stderr)
    assert (out / "thesis.tex").read_text() == "mine\n" and len(list(out.iterdir())) == 1


def test_cluster_without_the_extra_names_it(archive: Path, tmp_path: Path):
    """An interpreter where ``import distributed`` fails, as on an install without the extra."""
    code = ("import sys; sys.modules['distributed'] = None\n"
            "from helmcheck.cli import main\n"
            f"sys.exit(main(['check-log', {str(archive)!r}, '--cluster', 'tcp://127.0.0.1:8786']))")
    done = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=60)
    line = one_line(done.stderr)
    assert done.returncode == 64 and "helmcheck[cluster]" in line


def test_cluster_nobody_listens_is_64(archive: Path, tmp_path: Path):
    pytest.importorskip("distributed")
    done = helmcheck("check-log", archive, "--report-dir", tmp_path / "out", "--cluster",
                     f"tcp://127.0.0.1:{_free_port()}", cwd=tmp_path, timeout=120)
    assert done.returncode == 64 and "cannot connect to the scheduler" in one_line(done.stderr)


def _running(word: str) -> list[str]:
    """Processes whose command line names ``word`` (a forked worker keeps its parent's)."""
    found = []
    for d in Path("/proc").iterdir():
        try:
            cmd = (d / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
        except OSError:
            continue
        if d.name.isdigit() and word in cmd:
            found.append(f"{d.name} {cmd}")
    return found


@pytest.mark.parametrize("jobs", ["1", pytest.param("2", marks=pytest.mark.skipif(
    os.environ.get("HELMCHECK_MATRIX") != "1", reason="make matrix's (HELMCHECK_MATRIX=1): make test's budget"))])
def test_ctrl_c_keeps_finished_files_and_writes_a_partial_summary(tmp_path: Path, jobs: str):
    a = tmp_path / "archive"
    a.mkdir()
    for i in range(8):  # the longest fixture capture, eight times: long enough to interrupt
        shutil.copy(LOGS / "socat" / "backseat_vx.log", a / f"s{i}.log")
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "helmcheck", "check-log", str(a), "--report-dir", str(out),
                             "--jobs", jobs, "--progress"], cwd=tmp_path, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    first = proc.stderr.readline()  # one progress line per finished file (stderr is no terminal)
    assert first.startswith("files 1/8"), first
    proc.send_signal(signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=120)
    doc = summary(out)
    assert doc["partial"] is True and "interrupted" in doc["partial_reason"]
    judged = [f for f in doc["files"] if f["status"] == "judged"]
    left = [f for f in doc["files"] if f["status"] == "not-judged"]
    assert 1 <= len(judged) < 8 and len(judged) + len(left) == 8
    for f in judged:
        assert (out / f["path"] / "check-key.json").is_file()
    late = [f for f in left if (out / f["path"] / "check-key.json").exists()]  # finished as the run stopped
    assert all(f["message"].startswith("finished as the run was interrupted") for f in late), late
    assert proc.returncode == doc["exit_code"] == 2, stdout + stderr
    assert "partial" in stdout.splitlines()[-1]
    assert _running(str(a)) == []  # no worker left behind
    # the next run judges only what was left
    helmcheck("check-log", a, "--report-dir", out, "--jobs", "2", cwd=tmp_path)
    doc = summary(out)
    assert doc["partial"] is False and doc["counts"]["cached"] == len(judged) + len(late)
    assert doc["counts"]["judged"] == len(left) - len(late)
