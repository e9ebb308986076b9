"""Every command's ``--help``: one style, and every example in it runs as written.

The style (one for every command, ``certify vehicle``/``backseat`` and ``profile init``/``keys``
included): a usage line; a description that is a sentence (capital first, full stop last, no
markup, no exit codes: those have their own section); an ``examples:`` section (the top level's
``typical use:``) and an ``exit status:`` section; the one-line ``help`` of each subcommand is
the text :data:`helmcheck.cli.SUBCOMMANDS` lists.

The examples: every line of a help that runs helmcheck (``helmcheck …``, or a pipe into it;
``\\`` continues a line) is taken as written and

* parsed by the real command line (no usage error), and every file or directory it reads must
  be in the working directory a user would have (:func:`sandbox`: a certification of the
  emulator in ``reports/vehicle`` and an earlier one in ``reports/previous``, a capture, an archive of logs, a profile, a replay file, the
  checkout's ``helmcheck/``, ``tests/`` and ``examples/``) or be written by an example before it in the same
  help;
* run, in a copy of that working directory, with ``bash`` and the virtual environment's
  ``helmcheck`` and ``python3`` first on the PATH (as after ``. .venv/bin/activate``) when it
  needs nothing but this machine: it must not end in a usage error, a tester error or a
  traceback. An example writes its results as on a fresh start (a results directory of the
  working directory's where it writes is removed first, unless an example before it wrote it).
  An example that serves until stopped (``emulate``, ``certify backseat`` waiting for
  a backseat) is started, must print its ``port:`` line, and is stopped with SIGTERM.

Not run by default, and why (each still parsed and its files checked): an example on hardware
(``/dev/ttyUSB0``, a lab address, a cluster), one that needs a vehicle on a port (``/dev/pts/N``:
the emulator an earlier line starts), one that takes more than a few seconds (a certification
that starts its implementation, ``--exec``; a diff with its budget), and ``helmcheck docs``, which rewrites the checkout's
generated files. With ``HELMCHECK_HELP_EXAMPLES=1`` (``make help-examples``) the slow ones run
too, and those that need a vehicle run against the emulator started on their port.
"""

from __future__ import annotations

import argparse
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from helmcheck import cli
from helmcheck.cli import main as cli_main

ROOT = Path(__file__).resolve().parent.parent
VENV_BIN = Path(sys.executable).parent
RUN_ALL = os.environ.get("HELMCHECK_HELP_EXAMPLES") == "1"

#: Every help: the command words before ``--help``.
HELPS = [(), *((name,) for name in cli.SUBCOMMANDS), ("certify", "vehicle"), ("certify", "backseat"),
         ("profile", "init"), ("profile", "keys")]
#: A token that puts an example on hardware or on another machine.
HARDWARE = re.compile(r"^(/dev/tty(USB|S|ACM)\d|socket://10\.|rfc2217://|tcp://HOST|/shared/)")
#: A token that names a vehicle's port the example expects to be there.
VEHICLE_PORT = re.compile(r"^/dev/pts/(N|\d+)$")
#: What a command reads, by argparse dest: each must exist when the example runs.
INPUTS = ("profile", "profile_b", "missions", "files", "file", "directory", "directories", "public_key",
          "sign_key", "compare_dir", "resume")
#: What a command writes, by dest (an example not run leaves these to the next ones).
OUTPUTS = ("report_dir", "out")


# --------------------------------------------------------------------------- the helps

def _parser() -> argparse.ArgumentParser:
    saved = sys.argv[:]
    sys.argv[:] = ["helmcheck"]  # build_parser reads argv to import one command only
    try:
        return cli.build_parser()
    finally:
        sys.argv[:] = saved


def _sub(parser: argparse.ArgumentParser, words) -> argparse.ArgumentParser:
    for w in words:
        action = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
        parser = action.choices[w]
    return parser


def help_text(words) -> str:
    return _sub(_parser(), words).format_help()


def _raw(words) -> str:
    p = _sub(_parser(), words)
    return "\n".join(x for x in (p.description, p.epilog) if x)


def examples(words) -> list[str]:
    """The helmcheck command lines of one help, as written (continuation lines joined, comments
    kept: the shell drops them)."""
    out, pending = [], ""
    for line in _raw(words).splitlines():
        text = line.strip()
        if pending:
            pending += " " + text.rstrip("\\").strip()
            if not text.endswith("\\"):
                out.append(pending)
                pending = ""
            continue
        m = re.match(r"helmcheck (\S+)", text) or re.search(r"\|\s*helmcheck (\S+)", text)
        if m and m.group(1) in cli.SUBCOMMANDS:
            if text.endswith("\\"):
                pending = text.rstrip("\\").strip()
            else:
                out.append(text)
    return out


def _argv(example: str) -> list[str]:
    """The helmcheck arguments of an example (after the pipe, without ``&`` and the comment)."""
    lex = shlex.shlex(example, posix=True, punctuation_chars="|&;")
    lex.whitespace_split = True
    segment: list[str] = []
    for token in lex:
        if token in ("|", "&", ";", "&&", "||"):
            if segment[:1] == ["helmcheck"]:
                break
            segment = []
            continue
        segment.append(token)
    assert segment[:1] == ["helmcheck"], example
    return segment[1:]


# --------------------------------------------------------------------------- style

@pytest.mark.parametrize("words", HELPS, ids=lambda w: " ".join(w) or "helmcheck")
def test_every_help_has_usage_a_description_examples_and_exit_status(words):
    text = help_text(words)
    p = _sub(_parser(), words)
    assert text.startswith("usage: helmcheck"), text[:80]
    desc = (p.description or "").strip().splitlines()[0]
    assert (desc[:1].isupper() or desc.startswith("helmcheck — ")) and desc.endswith("."), desc
    assert "``" not in text and ":mod:" not in text and ":func:" not in text, "markup in the help"
    assert not re.search(r"\bExit \d", p.description or ""), "exit codes belong in the exit status section"
    raw = _raw(words)
    assert re.search(r"^(examples|typical use):$", raw, re.M), f"no examples section in {' '.join(words)}"
    assert re.search(r"^exit status: ", raw, re.M), f"no exit status section in {' '.join(words)}"
    assert examples(words), words


def test_each_subcommand_says_what_it_does_in_the_words_of_the_command_list():
    parser = _parser()
    action = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    said = {c.dest: c.help for c in action._choices_actions}
    assert said == {name: help_ for name, (_, help_) in cli.SUBCOMMANDS.items()}


def test_the_top_level_help_shows_check_log_and_check_logs_help_is_about_logs():
    assert "helmcheck check-log " in help_text(())
    assert "Replay a two-direction capture" not in help_text(("check-log",))
    assert help_text(("check-log",)).count("judged as") >= 1


# --------------------------------------------------------------------------- did you mean, keys

@pytest.mark.parametrize("typed, meant", [("checklog", "check-log"), ("chek-log", "check-log"), ("verfy", "verify"),
                                          ("emulat", "emulate"), ("keys", None)])
def test_a_mistyped_command_names_the_closest_one(typed, meant, capsys):
    assert cli_main([typed]) == 64
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert f"unknown command {typed!r}" in err
    if meant:
        assert f"(did you mean {meant!r}?)" in err, err
    else:
        assert "did you mean" not in err, err
    assert "choose from parse, emulate, certify" in err


def test_a_mistyped_role_and_choice_name_the_closest_one(capsys):
    assert cli_main(["certify", "vehicel"]) == 64
    assert "unknown role 'vehicel' (did you mean 'vehicle'?)" in capsys.readouterr().err
    assert cli_main(["check-log", "x.log", "--role", "backsaet"]) == 64
    assert "(did you mean 'backseat'?)" in capsys.readouterr().err


def test_an_unknown_profile_key_names_the_closest_key_and_where_the_list_is(tmp_path, capsys):
    """Not all 33 keys: the closest one, and the command that lists them all."""
    prof = tmp_path / "p.toml"
    prof.write_text('vehicle_nam = "X"\n')
    assert cli_main(["certify", "vehicle", "--plan", "--profile", str(prof)]) == 64
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert f"{prof}: unknown key 'vehicle_nam' (did you mean 'vehicle_name'?); every key: helmcheck profile keys" in err
    assert "lockout_s" not in err  # the whole list is not there …
    assert cli_main(["profile", "keys"]) == 0  # … but one command away
    listed = capsys.readouterr().out
    from helmcheck.profile import profile_keys
    for f in profile_keys():
        assert re.search(rf"^{re.escape(f.name)}(\.| )", listed, re.M), f.name
    prof.write_text("zzzz = 1\n")
    assert cli_main(["certify", "vehicle", "--plan", "--profile", str(prof)]) == 64
    err = capsys.readouterr().err
    assert "unknown key 'zzzz'; every key: helmcheck profile keys" in err


# --------------------------------------------------------------------------- the examples, run

@pytest.fixture(scope="session")
def sandbox(tmp_path_factory) -> Path:
    """The working directory a user following the help would have (module docstring)."""
    from helmcheck.emulator.process import EmulatorProcess

    d = tmp_path_factory.mktemp("help-sandbox")
    os.symlink(ROOT / "helmcheck", d / "helmcheck")
    os.symlink(ROOT / "tests", d / "tests")
    os.symlink(ROOT / "examples", d / "examples")
    with EmulatorProcess(time_scale=20.0, baud=115200) as emu:
        code = cli_main(["certify", "vehicle", "--port", emu.port, "--time-scale", "20", "--baud", "115200",
                         "--profile", str(ROOT / "helmcheck" / "profiles" / "emulator.toml"), "--select",
                         "RH-ACK-2", "--examples", "0", "--no-progress", "--report-dir", str(d / "reports" / "vehicle")])
    assert code == 0
    shutil.copytree(d / "reports" / "vehicle", d / "reports" / "previous")  # an earlier run
    shutil.copyfile(ROOT / "tests" / "fixtures" / "logs" / "socat_v.log", d / "capture.txt")
    shutil.copytree(ROOT / "helmcheck" / "emulator" / "missions", d / "missions")
    (d / "archive" / "2026-05-01" / "bench").mkdir(parents=True)
    (d / "archive" / "2026-05-02" / "sea").mkdir(parents=True)
    shutil.copyfile(d / "reports" / "vehicle" / "wire.log", d / "archive" / "2026-05-01" / "bench" / "wire.log")
    shutil.copyfile(d / "capture.txt", d / "archive" / "2026-05-02" / "sea" / "capture.log")
    shutil.copyfile(ROOT / "tests" / "fixtures" / "replays" / "third-party-release-to-next-waypoint.json",
                    d / "failing.json")
    assert cli_main(["profile", "init", str(d / "iver3.toml")]) == 0
    return d


def _kind(argv: list[str]) -> tuple[str, str]:
    """How an example is run here: ``(kind, why)``; kind is ``run``, ``serve`` or ``skip``."""
    if any(HARDWARE.match(w) for w in argv):
        return "skip", "on hardware or another machine"
    if argv[:1] == ["docs"] and "--check" not in argv:
        return "skip", "it rewrites the checkout's generated files"
    live = [w for w in argv if VEHICLE_PORT.match(w)] or (argv[:1] == ["monitor"])
    if live:
        return ("live" if RUN_ALL else "skip"), "it needs a vehicle on its port"
    if ("--exec" in argv and argv[:1] == ["certify"]) or argv[:1] == ["diff"]:
        return ("run" if RUN_ALL else "skip"), "it takes more than a few seconds"
    if argv[:2] == ["certify", "backseat"] and "--plan" in argv:
        return "run", ""  # prints the plan and exits: no port
    if argv[:1] == ["emulate"] or (argv[:2] == ["certify", "backseat"] and "--exec" not in argv):
        return "serve", "it serves until stopped"
    return "run", ""


def _paths(ns: argparse.Namespace, names) -> list[str]:
    out = []
    for name in names:
        v = getattr(ns, name, None)
        for x in (v if isinstance(v, list) else [v]):
            if x is not None and str(x) != "-" and not any(c in str(x) for c in "*?["):
                out.append(str(x))
    return out


def _env() -> dict:
    env = dict(os.environ)
    env["PATH"] = f"{VENV_BIN}{os.pathsep}{env.get('PATH', '')}"
    env.pop("COLUMNS", None)
    return env


def _shell(cwd: Path, example: str, timeout: float) -> subprocess.CompletedProcess:
    return subprocess.run(["bash", "-c", example.rstrip(" &")], cwd=cwd, env=_env(), stdin=subprocess.DEVNULL,
                          capture_output=True, text=True, timeout=timeout)


def _serve(cwd: Path, example: str) -> tuple[int, str, str]:
    """Start an example that serves until stopped; its ``port:`` line, then SIGTERM."""
    proc = subprocess.Popen(["bash", "-c", "exec " + example.split("#")[0].strip().rstrip(" &")], cwd=cwd,
                            env=_env(), stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True)
    try:
        first = proc.stdout.readline()  # type: ignore[union-attr]
        time.sleep(0.5)
        proc.send_signal(signal.SIGTERM)
        out, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    return proc.returncode, first + out, err


class _Vehicles:
    """Emulators on the ports live examples name (``HELMCHECK_HELP_EXAMPLES=1``)."""

    def __init__(self):
        self.emus: dict[str, object] = {}

    def port(self, name: str, time_scale: float) -> str:
        """The port of the emulator standing for *name* (a pty placeholder, or a TCP address it
        serves on), started on first use."""
        from helmcheck.emulator.process import EmulatorProcess
        if name not in self.emus:
            where = name if name.startswith("socket://") else "pty"
            self.emus[name] = EmulatorProcess(port=where, time_scale=time_scale).start()
        return self.emus[name].port  # type: ignore[attr-defined]

    def close(self) -> None:
        for emu in self.emus.values():
            emu.stop()  # type: ignore[attr-defined]


@pytest.mark.parametrize("words", HELPS, ids=lambda w: " ".join(w) or "helmcheck")
def test_every_example_in_the_help_runs_as_written(words, sandbox, tmp_path):
    work = tmp_path / "work"
    shutil.copytree(sandbox, work, symlinks=True)
    parser = _parser()
    made: set[str] = set()  #: what examples not run would have written
    written: set[str] = set()  #: what the examples run so far wrote
    vehicles = _Vehicles()
    said = []
    try:
        for example in examples(words):
            argv = _argv(example)
            try:
                ns = parser.parse_args(argv)
            except SystemExit as e:
                pytest.fail(f"{example!r}: not a valid command line (exit {e.code})")
            kind, why = _kind(argv)
            for path in _paths(ns, INPUTS):
                there = (work / path).exists() or Path(path).is_absolute() and Path(path).exists()
                if not there and path.rstrip("/") in made:
                    kind, why = ("skip", f"it reads {path}, which an example not run here writes")
                    continue
                assert there or kind == "skip" and HARDWARE.match(path), \
                    f"{example!r} reads {path}, which neither the working directory nor an example before it has"
            if kind == "skip":
                made.update(p.rstrip("/") for p in _paths(ns, OUTPUTS))
                said.append(f"not run: {example} — {why}")
                continue
            for path in _paths(ns, OUTPUTS):  # an example writing where the working directory has an
                if path not in written and (work / path).is_dir():  # earlier run writes as on a fresh start
                    shutil.rmtree(work / path)
                written.add(path)
            if kind == "serve":
                code, out, err = _serve(work, example)
                assert out.startswith("port: "), (example, out, err)
                assert code in (0, 2), (example, code, err)
            else:
                if kind == "live":
                    k = float(ns.time_scale) if getattr(ns, "time_scale", None) else 20.0
                    example = re.sub(r"/dev/pts/(N|\d+)", lambda m: vehicles.port(m.group(0), k), example)
                    for tcp in re.findall(r"socket://127\.0\.0\.1:[1-9]\d*", example):
                        vehicles.port(tcp, k)
                done = _shell(work, example, timeout=900 if RUN_ALL else 120)
                code, out, err = done.returncode, done.stdout, done.stderr
                assert code in (0, 1, 2), (example, code, out, err)
            assert "Traceback" not in err and "tester error" not in err, (example, err)
            said.append(f"ran: {example} — exit {code}")
    finally:
        vehicles.close()
    print("\n".join(said))
