"""Shared pytest setup: hypothesis profiles and the repository root on sys.path.

``make test`` does not depend on chance: the default profile is derandomised (the examples are
a function of the test alone; :data:`DEFAULT_EXAMPLES` each where a test sets no count) and keeps
no example database between runs. ``make fuzz`` (``HYPOTHESIS_PROFILE=fuzz``, never run by CI)
runs the same property tests with random seeds, a database, and :data:`FUZZ_FACTOR` times the
examples each test asks for (at least 100 × :data:`FUZZ_FACTOR`).

It also checks that no process helmcheck started (``--exec``) outlives the test session, and
that every results directory a test writes verifies (live and offline judging agree): after
each test, the directories under its ``tmp_path`` (:func:`every_run_verifies`); at the end of
the session, every results directory under this worker's base temporary directory —
``tmp_path_factory`` runs of module and session fixtures included (:func:`every_directory_verifies`,
:func:`results_directories`). A directory verified once is not re-judged unless it changed.

``make test`` runs the suite on several workers (pytest-xdist, ``--dist loadgroup``): a module
whose tests share a module-scoped run marks itself ``xdist_group`` so the run happens once, and
the full signed emulator certification (:func:`full_emulator_run`) is shared by the tests of the
group ``full-emulator-run``. The tests that wait longest on scaled time are collected first, each
followed by a few short ones (their wall times measured by ``make durations`` into
``tests/durations.json``), so that the workers start the long waits first and the suite does not
end on one of them, nor on all the CPU-bound short tests at once.
"""

import os
import signal
import sys
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

# A suite started where SIGINT is ignored (a background job of a script: a shell without job control
# ignores it for the commands it runs with &) would hand that on to every program it starts, and the
# tests that interrupt one with SIGINT would see it run on to its end: each test process takes
# Python's own handler back, so the programs it starts get the default again.
if signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)

FUZZ_FACTOR = 20
_QUIET = [HealthCheck.too_slow]

#: Examples a property test without its own count gets in ``make test`` (``make fuzz``: 2000, random).
DEFAULT_EXAMPLES = 50
settings.register_profile("default", deadline=None, max_examples=DEFAULT_EXAMPLES, derandomize=True, database=None,
                          suppress_health_check=_QUIET)
settings.register_profile("ci", parent=settings.get_profile("default"))
settings.register_profile("fuzz", deadline=None, max_examples=100 * FUZZ_FACTOR, derandomize=False,
                          print_blob=True, suppress_health_check=_QUIET + [HealthCheck.filter_too_much])
settings.register_profile("thorough", deadline=None, max_examples=2000,
                          suppress_health_check=_QUIET)
PROFILE = os.environ.get("HYPOTHESIS_PROFILE", "default")
settings.load_profile(PROFILE)


#: Each test's wall time in a full ``make test`` (seconds, those of a second or more), measured
#: by ``make durations`` (``HELMCHECK_DURATIONS=FILE``: :func:`pytest_sessionfinish` writes them).
DURATIONS = ROOT / "tests" / "durations.json"
#: What a test not in :data:`DURATIONS` is taken to last.
UNKNOWN_S = 1.0


def _durations() -> dict:
    try:
        import json
        return json.loads(DURATIONS.read_text())
    except (OSError, ValueError):
        return {}


def _plain(nodeid: str) -> str:
    """A test's id without the ``@group`` suffix ``--dist loadgroup`` gives it."""
    head, _, tail = nodeid.rpartition("@")
    return head if head and not any(c in tail for c in "[]:/") else nodeid


def _group(item) -> str:
    m = item.get_closest_marker("xdist_group")
    return (m.args[0] if m and m.args else m.kwargs.get("name", "")) if m else ""


#: A test (or ``xdist_group``) that lasts this long or more waits on scaled time: these start first …
WAITS_S = 15.0
#: … each followed by this many of the others, longest first: the CPU the waits leave idle goes to
#: the tests that need it, instead of all of those running last, on two cores, after the waits.
BETWEEN = 3


def pytest_collection_modifyitems(config, items):  # noqa: ARG001 - pytest hook signature
    """The order (:data:`DURATIONS`; a ``xdist_group`` counts as its tests' sum, its tests kept
    together): the tests that wait on scaled time longest first, each followed by :data:`BETWEEN`
    of the others, longest first — the long waits start early and the suite's wall time is not
    their tail, and the short tests' CPU work fills the time the waits leave the processors idle.
    Under ``fuzz``, scale every property test's own ``max_examples`` and drop its
    ``derandomize``, so tests that fix their example count get more examples too."""
    known = _durations()
    units: dict = {}  #: a group's tests together, else one test each, in collection order
    for item in items:
        units.setdefault(_group(item) or item.nodeid, []).append(item)
    cost = {k: sum(known.get(_plain(i.nodeid), UNKNOWN_S) for i in v) for k, v in units.items()}
    ranked = sorted(units, key=lambda k: -cost[k])  # stable: collection order among equals
    waits = [k for k in ranked if cost[k] >= WAITS_S]
    rest = [k for k in ranked if cost[k] < WAITS_S]
    out: list = []
    while waits or rest:
        if waits:
            out.append(waits.pop(0))
        out += rest[:BETWEEN]
        del rest[:BETWEEN]
    items[:] = [i for k in out for i in units[k]]
    if PROFILE != "fuzz":
        return
    for item in items:
        fn = getattr(item, "obj", None)
        current = getattr(fn, "_hypothesis_internal_use_settings", None)
        if getattr(fn, "hypothesis", None) is None or current is None:
            continue
        fn._hypothesis_internal_use_settings = settings(
            current, max_examples=max(current.max_examples, 100) * FUZZ_FACTOR, derandomize=False,
            database=settings.get_profile("fuzz").database)


from tests.processes import install_marker, kill, survivors  # noqa: E402

install_marker()


@pytest.fixture(scope="session", autouse=True)
def no_process_left_behind():
    """Fails the session if any process helmcheck started for it is still alive at the end."""
    yield
    left = survivors()
    if left:
        kill(left)
        pytest.fail(f"processes started by helmcheck survived the test session: {left}", pytrace=False)


_WALL: dict = {}


def pytest_runtest_logreport(report):
    """Each test's wall time, setup and teardown included (for ``make durations``)."""
    if os.environ.get("HELMCHECK_DURATIONS"):
        key = _plain(report.nodeid)
        _WALL[key] = _WALL.get(key, 0.0) + report.duration


def pytest_sessionfinish(session):
    """``HELMCHECK_DURATIONS=FILE``: the tests' wall times (a second or more), where the reports
    gather (the controller, under xdist), for :data:`DURATIONS`."""
    out = os.environ.get("HELMCHECK_DURATIONS")
    if not out or os.environ.get("PYTEST_XDIST_WORKER"):
        return
    import json
    Path(out).write_text(json.dumps({k: round(v, 1) for k, v in sorted(_WALL.items()) if v >= 1.0}, indent=0) + "\n")


def pytest_configure(config):
    config.addinivalue_line("markers", "unverifiable: the test's results directories are tampered with on "
                                       "purpose; the agreement check skips them")


#: directories a test tampers with on purpose (``unverifiable``) or whose test failed: not checked
_EXCLUDED: set[Path] = set()
#: directory -> the stamp of its files when it verified (a directory verified once is not re-judged)
_VERIFIED: dict[Path, tuple] = {}


def results_directories(base: Path) -> list[Path]:
    """Every results directory of a run under *base*: a ``results.json`` beside the
    ``profile.toml`` of a certification, a monitored session or a log check (a report fixture
    has none), in a directory no ``unverifiable`` or failed test owns."""
    out = []
    for res in sorted(Path(base).rglob("results.json")):
        d = res.parent
        if (d / "profile.toml").is_file() and not any(d == x or x in d.parents for x in _EXCLUDED):
            out.append(d)
    return out


def _stamp(d: Path) -> tuple:
    return tuple((p.name, p.stat().st_mtime_ns, p.stat().st_size) for p in sorted(d.iterdir()) if p.is_file())


def verify_directories(dirs) -> list[str]:
    """``helmcheck verify`` (unsigned) of each directory: one line per directory that does not verify."""
    from helmcheck.commands.verify_cmd import verify_run

    problems = []
    for d in dirs:
        stamp = _stamp(d)
        if _VERIFIED.get(d) == stamp:
            continue
        got = verify_run(d)
        if got.ok:
            _VERIFIED[d] = stamp
        else:
            problems.append(f"{d}: " + "; ".join(map(str, got.findings[:6])))
    return problems


@pytest.fixture(autouse=True)
def every_run_verifies(request):
    """One judge per role: every results directory a test writes under its ``tmp_path`` is
    re-judged from its ``wire.log`` by the offline observer (``helmcheck verify``), and every
    clause verdict, the run verdict and the certificate flag must follow — live and offline agree."""
    yield
    tmp = request.node.funcargs.get("tmp_path") if hasattr(request.node, "funcargs") else None
    if tmp is None:
        return
    if request.node.get_closest_marker("unverifiable") or (
            hasattr(request.node, "rep_call") and request.node.rep_call.failed):
        _EXCLUDED.add(Path(tmp))
        return
    problems = verify_directories(results_directories(Path(tmp)))
    if problems:
        pytest.fail("live and offline judging disagree:\n" + "\n".join(problems), pytrace=False)


@pytest.fixture(scope="session")
def session_results_directories(tmp_path_factory):
    """A function listing every results directory written so far in this session by this
    worker (under its base temporary directory; pytest-xdist gives each worker its own)."""
    return lambda: results_directories(tmp_path_factory.getbasetemp())


@pytest.fixture(scope="session", autouse=True)
def every_directory_verifies(session_results_directories):
    """At the end of the session, every results directory any test wrote — under ``tmp_path``
    or under ``tmp_path_factory`` (module and session fixtures) — verifies."""
    yield
    problems = verify_directories(session_results_directories())
    if problems:
        pytest.fail("results directories written in this session do not verify:\n" + "\n".join(problems),
                    pytrace=False)


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    rep = outcome.get_result()
    if rep.when == "call":
        item.rep_call = rep


#: Time scale of the shared full certification.
FULL_RUN_K = 25.0


@pytest.fixture(scope="session")
def full_emulator_run(tmp_path_factory):
    """One full, signed certification of the built-in emulator (``helmcheck emulate`` on a pty,
    time scale 25, 5 explored sequences, seed 2), shared by the tests that read it. Returns
    ``(root, exit_code, emulator_alive)``: ``root/full`` is the run, ``root/lab.key``/``.pub`` and
    ``root/other.*`` two key pairs, ``root/emu.toml`` the profile given (the shipped emulator
    profile, ``helmcheck/profiles/emulator.toml``, plus baud and identity); ``emulator_alive`` says the
    emulator was still running when the certification ended."""
    from importlib import resources

    from helmcheck.cli import main as cli_main
    from helmcheck.emulator.process import EmulatorProcess
    from helmcheck.profile import EMULATOR_PROFILE

    root = tmp_path_factory.mktemp("full-run")
    assert cli_main(["keygen", "--out", str(root / "lab")]) == 0
    assert cli_main(["keygen", "--out", str(root / "other")]) == 0
    prof = root / "emu.toml"
    shipped = resources.files("helmcheck").joinpath(EMULATOR_PROFILE).read_text(encoding="utf-8")
    prof.write_text(shipped + 'baud = 115200\nvehicle_serial = "EMU-0001"\nuvc_version = "emulator 0.1.0"\n')
    with EmulatorProcess(time_scale=FULL_RUN_K, baud=115200) as emu:
        code = cli_main(["certify", "vehicle", "--port", emu.port, "--time-scale", str(FULL_RUN_K),
                         "--profile", str(prof), "--examples", "5", "--seed", "2", "--no-progress",
                         "--report-dir", str(root / "full"), "--sign-key", str(root / "lab.key"),
                         "--operator", "J. Doe", "--site", "Bench 2"])
        alive = emu.proc.poll() is None
    return root, code, alive
