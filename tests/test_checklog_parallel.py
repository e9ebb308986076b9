"""``check_log(role="both")`` with the backseat role judged in a second process
(:mod:`helmcheck.checklog.sidejob`): the verdicts are the same either way, the
automatic choice (``parallel=None``), :class:`SideJob` itself, the in-process fallback when the
side job is lost, and a file that changes while it is checked.

Every side job here is a real ``python -c`` process; the monkeypatched ``SideJob`` classes are
thin subclasses of the real one that record what happened (and, for the fallback and the
changed-file tests, interfere with the real process or its answer).
"""

from __future__ import annotations

import importlib.util
import json
import os
import pkgutil
import shutil
import signal
import time
from pathlib import Path

import pytest

import helmcheck
from helmcheck.checklog import checker
from helmcheck.checklog.sidejob import SideJob, SideJobLost, cores
from helmcheck.profile import DEFAULT
from tests.processes import descendants

ROOT = Path(__file__).resolve().parent.parent
LOGS = Path(__file__).parent / "fixtures" / "logs"
PROFILE = DEFAULT.replace(fault_injection="oxflt")  # as tests/test_checklog.py
FIXTURES = sorted(LOGS.glob("*.log")) + sorted(p for p in (LOGS / "socat").iterdir() if p.is_file())
#: what check_log returns that must not depend on where the backseat role was judged
COMPARED = ("clauses", "stats", "findings", "sha256", "timeline", "events", "format", "role",
            "one_direction", "resolution", "time_scale", "notes", "meta")
CHILD_CMD = "from helmcheck.checklog.sidejob import child"


def _bench():
    spec = importlib.util.spec_from_file_location("check_log_bench", ROOT / "benchmarks" / "check_log_bench.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)  # type: ignore[union-attr]
    return mod


def summary(out) -> dict:
    return {k: json.dumps(getattr(out, k), sort_keys=True, default=str) for k in COMPARED}


def verdicts(out) -> dict:
    return {c["id"]: c["verdict"] for c in out.clauses}


def side_children() -> list:
    """Live side-job processes below this one."""
    return [(pid, cmd) for pid, cmd in descendants() if CHILD_CMD in cmd]


# --------------------------------------------------------------------------- fixtures

class Recorder:
    """What the recording SideJob classes saw: every job made, and what each result() did."""

    def __init__(self):
        self.jobs: list = []
        self.results: list = []  # "ok" or the exception's class name, one per result() call

    def __len__(self):
        return len(self.jobs)


@pytest.fixture(autouse=True)
def no_side_job_left_behind():
    """Every test ends with no side-job process of its own still running (conftest's session
    check sees only ``--exec`` processes, which carry ``HELMCHECK_PORT``)."""
    before = {pid for pid, _ in side_children()}
    yield
    left = [(pid, cmd) for pid, cmd in side_children() if pid not in before]
    for pid, _ in left:
        try:
            os.kill(pid, signal.SIGKILL)
        except OSError:
            pass
    assert not left, f"side jobs survived the test: {left}"


@pytest.fixture
def recorder(monkeypatch):
    """``checker.SideJob`` replaced by a real SideJob that records itself and its result."""
    rec = Recorder()

    class Recording(SideJob):
        def __init__(self, fn, *args):
            super().__init__(fn, *args)
            rec.jobs.append(self)

        def result(self):
            try:
                value = super().result()
            except Exception as e:
                rec.results.append(type(e).__name__)
                raise
            rec.results.append("ok")
            return value

    monkeypatch.setattr(checker, "SideJob", Recording)
    return rec


@pytest.fixture
def jobs():
    """SideJobs a test starts directly; stopped at the end whatever happened."""
    made: list = []
    yield made
    for j in made:
        j.stop()


def copy_fixture(src: Path, tmp_path: Path) -> Path:
    """A private copy, so that a fixture rewritten meanwhile (test_fixtures_are_current under
    xdist) cannot make the two processes read different bytes."""
    dst = tmp_path / src.name
    shutil.copyfile(src, dst)
    return dst


def both_ways(path: Path, recorder: Recorder, **kw):
    """(in-process outcome, parallel outcome); the parallel one must really have used one side
    job that answered."""
    serial = checker.check_log(path, role="both", parallel=False, **kw)
    assert len(recorder) == 0
    par = checker.check_log(path, role="both", parallel=True, **kw)
    assert len(recorder) == 1 and recorder.results == ["ok"], recorder.results
    assert recorder.jobs[0]._proc.poll() is not None
    return serial, par


@pytest.fixture(scope="module")
def generated(tmp_path_factory) -> tuple[Path, Path]:
    """A ~20,000-line conforming session (the benchmark's generator) and a copy with a backseat
    flood: one ``$OMS`` line repeated 1,000 times at the same instant (20 kB in no time, over
    the 11,520 B/s budget at 115200 baud: RH-BS-4)."""
    d = tmp_path_factory.mktemp("generated")
    clean = d / "clean.log"
    n = _bench().generate(clean, 20_000)
    assert n >= 20_000
    lines = clean.read_bytes().splitlines(keepends=True)
    i = next(k for k in range(1000, len(lines)) if b" > $OMS," in lines[k])
    flood = d / "flood.log"
    flood.write_bytes(b"".join(lines[:i + 1] + [lines[i]] * 1000 + lines[i + 1:]))
    return clean, flood


# --------------------------------------------------------------------------- 1. same verdicts

@pytest.mark.parametrize("src", FIXTURES, ids=[str(p.relative_to(LOGS)) for p in FIXTURES])
def test_parallel_gives_the_in_process_verdicts_on_every_fixture(src, tmp_path, recorder):
    path = copy_fixture(src, tmp_path)
    outcomes = {}
    for parallel in (False, True):
        try:
            outcomes[parallel] = checker.check_log(path, profile=PROFILE, role="both", parallel=parallel)
        except checker.LogFormatError as e:
            outcomes[parallel] = e
    rejected = {p: isinstance(o, checker.LogFormatError) for p, o in outcomes.items()}
    assert rejected[False] == rejected[True], outcomes
    if rejected[False]:  # README, manifest, record.sh, the gzipped emulator logs
        assert not src.name.endswith(".log"), outcomes[False]
        assert "not a helmcheck wire log" in str(outcomes[True])
        assert len(recorder) == 0  # the format is known before a side job is started
        return
    assert src.name.endswith(".log")
    assert len(recorder) == 1 and recorder.results == ["ok"]
    assert summary(outcomes[True]) == summary(outcomes[False])
    ids = [c["id"] for c in outcomes[True].clauses]
    assert any(i.startswith("RH-BS-") for i in ids) and any(not i.startswith("RH-BS-") for i in ids)


def test_backseat_faults_fixture_is_not_all_pass_in_either_mode(tmp_path, recorder):
    """The equality above covers a log whose backseat clauses fail (not only clean ones)."""
    serial, par = both_ways(copy_fixture(LOGS / "backseat_faults.log", tmp_path), recorder, profile=PROFILE)
    for out in (serial, par):
        v = verdicts(out)
        assert v["RH-BS-1"] == "fail" and v["RH-BS-3"] == "fail" and v["RH-BS-5"] == "non-strict"
    assert summary(par) == summary(serial)


def test_parallel_gives_the_in_process_verdicts_on_a_long_generated_log(generated, recorder):
    clean, _ = generated
    serial, par = both_ways(clean, recorder)
    assert summary(par) == summary(serial)
    assert serial.stats["records"] >= 20_000
    assert {v for v in verdicts(par).values()} <= {"pass", "not-tested"}
    assert verdicts(par)["RH-BS-4"] == "pass"


def test_parallel_gives_the_in_process_verdicts_on_a_backseat_flood(generated, recorder):
    clean, flood = generated
    serial, par = both_ways(flood, recorder)
    assert summary(par) == summary(serial)
    for out in (serial, par):
        bs4 = next(c for c in out.clauses if c["id"] == "RH-BS-4")
        assert bs4["verdict"] == "fail", bs4
        assert bs4["lines"], bs4
    assert serial.sha256 != checker.check_log(clean, role="both", parallel=False).sha256


# --------------------------------------------------------------------------- 2. automatic choice

@pytest.mark.parametrize("threshold,ncores,role,expect_side", [
    (0, 2, "both", True),
    ("size", 2, "both", True),  # at exactly PARALLEL_BYTES: parallel
    ("size+1", 2, "both", False),
    (10 ** 15, 2, "both", False),
    (0, 1, "both", False),  # one core: never
    (0, 2, "vehicle", False),  # one role: nothing to split
    (0, 2, "backseat", False),
])
def test_parallel_none_decides_by_size_cores_and_role(threshold, ncores, role, expect_side, tmp_path,
                                                      recorder, monkeypatch):
    path = copy_fixture(LOGS / "backseat_faults.log", tmp_path)
    size = path.stat().st_size
    threshold = {"size": size, "size+1": size + 1}.get(threshold, threshold)
    expected = checker.check_log(path, profile=PROFILE, role=role, parallel=False)
    assert len(recorder) == 0
    monkeypatch.setattr(checker, "PARALLEL_BYTES", threshold)
    monkeypatch.setattr(checker, "cores", lambda: ncores)
    out = checker.check_log(path, profile=PROFILE, role=role)  # parallel=None
    assert len(recorder) == (1 if expect_side else 0)
    if expect_side:
        assert recorder.results == ["ok"]
    assert summary(out) == summary(expected)


def test_parallel_none_on_this_machine(tmp_path, recorder, monkeypatch):
    """Unpatched cores(): above the threshold a side job runs exactly when there is a second core."""
    path = copy_fixture(LOGS / "nominal.log", tmp_path)
    monkeypatch.setattr(checker, "PARALLEL_BYTES", 0)
    checker.check_log(path, profile=PROFILE, role="both")
    assert len(recorder) == (1 if cores() > 1 else 0)


def test_the_default_threshold_keeps_small_logs_in_process(tmp_path, recorder, monkeypatch):
    path = copy_fixture(LOGS / "nominal.log", tmp_path)
    assert path.stat().st_size < checker.PARALLEL_BYTES
    monkeypatch.setattr(checker, "cores", lambda: 64)
    checker.check_log(path, profile=PROFILE, role="both")
    assert len(recorder) == 0


@pytest.mark.parametrize("parallel,role,ncores,expect_side", [
    (True, "both", 1, True),  # asked for explicitly: the core count does not matter
    (True, "vehicle", 2, False),
    (True, "backseat", 2, False),
    (False, "both", 2, False),
])
def test_an_explicit_parallel_flag(parallel, role, ncores, expect_side, tmp_path, recorder, monkeypatch):
    path = copy_fixture(LOGS / "vehicle_faults.log", tmp_path)
    expected = checker.check_log(path, profile=PROFILE, role=role, parallel=False)
    monkeypatch.setattr(checker, "PARALLEL_BYTES", 0)
    monkeypatch.setattr(checker, "cores", lambda: ncores)
    out = checker.check_log(path, profile=PROFILE, role=role, parallel=parallel)
    assert len(recorder) == (1 if expect_side else 0)
    assert summary(out) == summary(expected)


# --------------------------------------------------------------------------- 3. SideJob

def test_sidejob_returns_the_value(jobs):
    jobs.append(SideJob(int, "12"))
    assert jobs[-1].result() == 12
    jobs.append(SideJob(pkgutil.resolve_name, "helmcheck:__file__"))  # the same package, imported there
    assert jobs[-1].result() == helmcheck.__file__


def test_sidejob_ignores_a_helmcheck_in_the_working_directory(jobs, tmp_path, monkeypatch):
    """The child imports the caller's package, not a ``helmcheck`` folder where it was started."""
    fake = tmp_path / "helmcheck"
    fake.mkdir()
    (fake / "__init__.py").write_text("raise ImportError('a shadow helmcheck was imported')\n")
    monkeypatch.chdir(tmp_path)
    jobs.append(SideJob(pkgutil.resolve_name, "helmcheck:__file__"))
    assert jobs[-1].result() == helmcheck.__file__


def test_sidejob_output_printed_by_the_function_does_not_spoil_the_answer(jobs):
    jobs.append(SideJob(print, "hello from the side job"))
    assert jobs[-1].result() is None


def test_sidejob_runs_in_another_process_and_session(jobs):
    jobs.append(SideJob(os.getpid))
    pid = jobs[-1].result()
    assert isinstance(pid, int) and pid != os.getpid() and pid == jobs[-1]._proc.pid
    jobs.append(SideJob(os.getsid, 0))
    sid = jobs[-1].result()
    assert sid == jobs[-1]._proc.pid and sid != os.getsid(0)  # a session of its own (Ctrl-C)


def test_sidejob_raises_the_child_exception(jobs):
    jobs.append(SideJob(int, "x"))
    with pytest.raises(ValueError, match=r"invalid literal for int\(\) with base 10: 'x'"):
        jobs[-1].result()
    assert jobs[-1]._proc.returncode == 0  # the child answered; it did not crash


def test_sidejob_unpicklable_answer_is_lost_with_its_text(jobs):
    jobs.append(SideJob(pkgutil.resolve_name, "helmcheck"))  # a module: it cannot travel back
    with pytest.raises(SideJobLost, match=r"the second process failed: <module 'helmcheck'.*cannot pickle"):
        jobs[-1].result()


def test_sidejob_child_that_dies_without_answering_is_lost(jobs):
    jobs.append(SideJob(os._exit, 3))
    with pytest.raises(SideJobLost, match=r"exit code 3"):
        jobs[-1].result()
    assert jobs[-1]._proc.returncode == 3


def test_sidejob_killed_child_is_lost(jobs):
    jobs.append(SideJob(time.sleep, 60))
    os.kill(jobs[-1]._proc.pid, signal.SIGKILL)
    t0 = time.monotonic()
    with pytest.raises(SideJobLost, match=r"exit code -9"):
        jobs[-1].result()
    assert time.monotonic() - t0 < 5


def test_sidejob_stop_ends_a_long_running_child_promptly(jobs):
    job = SideJob(time.sleep, 60)
    jobs.append(job)
    pid = job._proc.pid
    assert job._proc.poll() is None
    deadline = time.monotonic() + 10  # between fork and exec the child still shows the parent's command line
    while not any(p == pid for p, _ in side_children()):
        assert time.monotonic() < deadline, "the side job never showed as a child"
        time.sleep(0.01)
    t0 = time.monotonic()
    job.stop()
    assert time.monotonic() - t0 < 5
    assert job._proc.poll() is not None
    assert job._proc.stdout.closed and job._proc.stderr.closed
    assert not any(p == pid for p, _ in side_children())
    job.stop()  # a second stop is harmless


def test_sidejob_stop_after_result_is_harmless(jobs):
    job = SideJob(int, "7")
    jobs.append(job)
    assert job.result() == 7
    job.stop()
    assert job._proc.returncode == 0


# --------------------------------------------------------------------------- 4. fallback

def test_lost_side_job_falls_back_to_judging_in_process(tmp_path, monkeypatch):
    path = copy_fixture(LOGS / "backseat_faults.log", tmp_path)
    expected = checker.check_log(path, profile=PROFILE, role="both", parallel=False)
    made = []

    class Lost(SideJob):
        def __init__(self, fn, *args):
            super().__init__(fn, *args)
            made.append(self)

        def result(self):
            SideJob.stop(self)
            raise SideJobLost("the second process ended without a result (test)")

    monkeypatch.setattr(checker, "SideJob", Lost)
    out = checker.check_log(path, profile=PROFILE, role="both", parallel=True)
    assert len(made) == 1 and made[0]._proc.poll() is not None
    assert summary(out) == summary(expected)
    assert verdicts(out)["RH-BS-1"] == "fail"  # the backseat role was judged after all


def test_killed_side_job_falls_back_to_judging_in_process(generated, recorder, monkeypatch):
    """The child really dies (SIGKILL at once): the real result() raises SideJobLost."""
    _, flood = generated
    expected = checker.check_log(flood, role="both", parallel=False)
    base = checker.SideJob  # the recording class

    class Killed(base):
        def __init__(self, fn, *args):
            super().__init__(fn, *args)
            os.kill(self._proc.pid, signal.SIGKILL)

    monkeypatch.setattr(checker, "SideJob", Killed)
    out = checker.check_log(flood, role="both", parallel=True)
    assert len(recorder) == 1 and recorder.results == ["SideJobLost"]
    assert summary(out) == summary(expected)
    assert verdicts(out)["RH-BS-4"] == "fail"


def test_an_error_in_the_caller_stops_the_side_job(generated, recorder):
    """The caller leaves early (here its progress callback raises, as Ctrl-C would): the side
    job, still judging the long log, is ended at once rather than left to run."""
    _, flood = generated

    def progress(n):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        checker.check_log(flood, role="both", parallel=True, progress=progress)
    assert len(recorder) == 1 and recorder.results == []
    assert recorder.jobs[0]._proc.poll() is not None  # killed, not still running


# --------------------------------------------------------------------------- 5. file changed

def test_a_side_job_that_read_other_bytes_is_an_error(tmp_path, monkeypatch):
    path = copy_fixture(LOGS / "nominal.log", tmp_path)
    made = []

    class OtherBytes(SideJob):
        def __init__(self, fn, *args):
            super().__init__(fn, *args)
            made.append(self)

        def result(self):
            entries, sha = super().result()
            assert len(sha) == 64 and sha != "0" * 64
            return entries, "0" * 64

    monkeypatch.setattr(checker, "SideJob", OtherBytes)
    with pytest.raises(checker.LogFormatError, match="changed"):
        checker.check_log(path, profile=PROFILE, role="both", parallel=True)
    assert len(made) == 1 and made[0]._proc.poll() is not None


def _replace_before_start(path: Path, new: bytes, kill: bool = False):
    """A SideJob that, before its child starts, puts a new file at ``path`` (a new inode: the
    caller keeps reading the old one through its open file) — optionally killing the child."""

    class Replacing(SideJob):
        made: list = []

        def __init__(self, fn, *args):
            tmp = path.with_suffix(".new")
            tmp.write_bytes(new)
            os.replace(tmp, path)
            super().__init__(fn, *args)
            Replacing.made.append(self)
            if kill:
                os.kill(self._proc.pid, signal.SIGKILL)

    return Replacing


@pytest.mark.parametrize("kill", [False, True], ids=["side-job-reads-it", "fallback-reads-it"])
def test_a_file_replaced_during_the_check_is_an_error(kill, tmp_path, monkeypatch):
    """Really different bytes: the side job (or, when it is lost, the in-process fallback)
    opens the path again and reads other bytes than the caller (one byte of the last record
    changed, and a line appended)."""
    path = copy_fixture(LOGS / "nominal.log", tmp_path)
    old = path.read_bytes()
    changed = old[:-4] + bytes([old[-4] ^ 1]) + old[-3:] + old.splitlines(keepends=True)[-1]
    cls = _replace_before_start(path, changed, kill=kill)
    monkeypatch.setattr(checker, "SideJob", cls)
    with pytest.raises(checker.LogFormatError, match="changed while it was being checked"):
        checker.check_log(path, profile=PROFILE, role="both", parallel=True)
    assert len(cls.made) == 1 and cls.made[0]._proc.poll() is not None
    assert path.read_bytes() == changed
    checker.check_log(path, profile=PROFILE, role="both", parallel=False)  # the new file itself is fine


@pytest.mark.parametrize("parallel", [False, True], ids=["in-process", "side-job"])
def test_a_log_still_being_written_is_judged_as_it_was_when_the_check_began(parallel, tmp_path, monkeypatch):
    """A capture that grows while it is checked (same file, more records appended after the
    check opened it) is judged up to the size it had then, the same in one process or two."""
    path = copy_fixture(LOGS / "nominal.log", tmp_path)
    before = path.read_bytes()
    lines = before.splitlines(keepends=True)
    appended = b"".join(lines[-40:]) + b"12.5 > $OMS,180,3,20,2,10*00\n"
    original = tmp_path / "original.log"
    original.write_bytes(before)

    grown = []
    real_head = checker._head

    def head_then_grow(f, p, size):  # the check has taken the size: now the log grows
        got = real_head(f, p, size)
        if p == path and not grown:
            with open(path, "ab") as w:
                w.write(appended)
            grown.append(True)
        return got

    monkeypatch.setattr(checker, "_head", head_then_grow)
    out = checker.check_log(path, profile=PROFILE, role="both", parallel=parallel)
    assert grown and path.read_bytes() == before + appended
    want = checker.check_log(original, profile=PROFILE, role="both", parallel=False)
    assert out.sha256 == want.sha256 and out.stats == want.stats
    assert summary(out)["clauses"] == summary(want)["clauses"]


def test_a_file_replaced_by_another_format_is_an_error(tmp_path, monkeypatch):
    """The side job's own format check: a wire log replaced by a socat capture."""
    path = copy_fixture(LOGS / "nominal.log", tmp_path)
    cls = _replace_before_start(path, (LOGS / "socat_x.log").read_bytes())
    monkeypatch.setattr(checker, "SideJob", cls)
    with pytest.raises(checker.LogFormatError, match="changed while it was being checked"):
        checker.check_log(path, profile=PROFILE, role="both", parallel=True)
    assert len(cls.made) == 1 and cls.made[0]._proc.poll() is not None
