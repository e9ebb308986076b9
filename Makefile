# helmcheck — every target creates .venv itself and installs from pyproject.toml.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python

# Every Python process the suite starts (the CLI, emulators, backseats, vehicles) imports helmcheck;
# where the environment sets PYTHONDONTWRITEBYTECODE, each would compile it from source again (about
# 0.7 s of CPU each). The targets here let Python keep its bytecode (__pycache__/, ignored by git).
unexport PYTHONDONTWRITEBYTECODE
STAMP  := $(VENV)/.installed

.PHONY: demo example-report test fuzz bench docs clean explore-reach matrix help-examples durations

#: The property tests, for `make fuzz`.
FUZZ_TESTS := tests/test_grammar_fastpath.py tests/test_grammar_framer.py tests/test_grammar_roundtrip.py \
              tests/test_model_observe.py tests/test_model_stateful.py tests/test_reports_results.py \
              tests/test_certify_backseat_judge.py tests/test_cli_contracts.py tests/test_emulator_freedoms.py

# Says what it does (pip is quiet for half a minute). The editable install of this flat layout
# is setuptools' import-hook kind, which ends with an informational "Editable installation"
# notice ("careful with folders named like the package in your working directory": here that
# folder is the package itself); pip shows it as a boxed BuildBackendWarning, so it is filtered
# by its message. Every other warning still shows.
$(STAMP): pyproject.toml
	@echo "setting up $(VENV)/ (once, about a minute): a virtual environment for helmcheck"
	@$(PYTHON) -m venv $(VENV)
	@echo "  installing helmcheck from this checkout (editable: your edits run at once) with its test and docs tools"
	@PYTHONWARNINGS='ignore:Editable installation' $(PY) -m pip install --quiet --disable-pip-version-check -e '.[test]'
	@touch $(STAMP)
	@echo "$(VENV)/ is ready"

# Certifies the built-in emulator into demo-out/ (ignored by git: the checkout stays clean).
demo: $(STAMP)
	$(PY) -m helmcheck.demo

# Regenerates the example report committed under reports/demo/ (the same run as make demo).
example-report: $(STAMP)
	$(PY) -m helmcheck.demo --out reports/demo

# The suite mostly waits on ptys and scaled time, so it runs on more workers than cores.
TEST_WORKERS ?= 7

test: $(STAMP)
	$(PY) -m pytest -n $(TEST_WORKERS) --dist loadgroup

# make test, recording each test's wall time into tests/durations.json: make test starts the
# longest first (tests/conftest.py). Run it after adding or moving slow tests, on a quiet machine.
durations: $(STAMP)
	HELMCHECK_DURATIONS=$(CURDIR)/tests/durations.json $(PY) -m pytest -n $(TEST_WORKERS) --dist loadgroup

# Not run by CI: the same property tests with random seeds and 20 times the examples
# (tests/conftest.py, profile "fuzz"). A failure prints the blob that reproduces it.
fuzz: $(STAMP)
	HYPOTHESIS_PROFILE=fuzz $(PY) -m pytest $(FUZZ_TESTS)

# Not run by CI (about 45 minutes): the exploration alone against every faulty vehicle of the
# suite (tests/test_explore_reach.py, benchmarks/explore_reach.py).
explore-reach: $(STAMP)
	HELMCHECK_REACH=1 $(PY) -m pytest -q tests/test_explore_reach.py

# Not run by CI (about two and a half hours on two cores: 75 minutes, the third vehicle's faults
# certified whole 45 more, the exploration alone against them 40 more; the line-fault grid alone 6
# minutes): the slow-line grid — every case on the reference and
# every faulty vehicle over lines in virtual time (time scales 1-40, replies 3 ms-0.9 s, 9600-115200
# baud, the timing freedoms at their bounds), and whole certifications on real ptys of the emulator
# at each line-timing freedom's bound at x5, x20 and x40 and of the independent simulator behind a
# slow line (tests/test_line_budget.py, tests/test_slow_line.py); and ports unplugged mid-run: the
# independent simulator certified whole behind a 5 s cut, cuts in a case and in the exploration, a
# backseat device and a monitored side that never come back (tests/test_unplugged.py); the
# emulator, the independent simulator and the example backseat behind every line fault, and every
# faulty vehicle behind light damage (tests/test_bad_line.py); the independent simulator's own
# missions at x5 and two exploration findings replayed (make test's budget keeps x20 and one replay);
# backseats certified at x1 as their users would (about 70 s): the real-time backseat on 19200 and
# 115200 baud, the example backseat (tests/test_certify_backseat_realtime.py; make test: x10);
# the emulator under every reading of the readings table (tests/test_readings.py); and the third
# vehicle (../shared/third-party/vehicle3) on its own default line (tests/test_vehicle3.py) and each
# of its 36 single faults certified whole at x20 on the fast line, each FAILing its own clause (or the
# clause the traceability table books its reading on), the three timing faults at the time scale
# --precision nominal picks (tests/test_vehicle3_mutants.py, about 45 minutes more);
# and the exploration alone against each of those 36 faults (tests/test_explore_vehicle3.py,
# benchmarks/explore_reach.py --families vehicle3: about 40 minutes, its timing faults at the time
# scale --precision nominal names); every faulty vehicle of the suite at both its time scales (make
# test: one each, tests/test_certify_vehicle_mutants.py), every explicit example of the freedoms and
# two drawn ones (make test: one per kind of freedom, tests/test_emulator_freedoms.py); the
# independent simulator's own mission rule as the trigger and every other of its faulty variants
# (make test: the third vehicle's, every third variant); the third vehicle's whole certificate under its
# own mission rule (make test: its lockout clauses); ACKs 2.5 s late live, one re-run of two
# reproducing an exploration finding, Ctrl-C of a two-job check-log (make test: their neighbours);
# the README's backseat and ci journeys run twice (make test: once; sign's runs twice).
matrix: $(STAMP)
	HELMCHECK_MATRIX=1 $(PY) -m pytest -n 2 tests/test_line_budget.py tests/test_slow_line.py tests/test_unplugged.py tests/test_bad_line.py tests/test_third_party_vehicle.py tests/test_explore_replays.py tests/test_vehicle3.py tests/test_readings.py tests/test_certify_backseat_realtime.py tests/test_vehicle3_mutants.py tests/test_explore_vehicle3.py tests/test_emulator_freedoms.py tests/test_certify_vehicle_mutants.py tests/test_ack_window_bounds.py tests/test_explore_rules.py tests/test_checklog_fleet.py tests/test_readme_walkthroughs.py

# Not run by CI (several minutes): every --help example, the slow ones and those that need a
# vehicle too (run against the emulator on their port); make test runs the others.
help-examples: $(STAMP)
	HELMCHECK_HELP_EXAMPLES=1 $(PY) -m pytest -q -n 2 tests/test_cli_help.py

bench: $(STAMP)
	$(PY) benchmarks/run_all.py

# The generated pages (helmcheck docs), then the site from docs/ into site/ (not tracked), strict:
# a broken link or anchor fails. Open site/index.html.
docs: $(STAMP)
	$(PY) -m helmcheck docs
	NO_MKDOCS_2_WARNING=1 $(PY) -m mkdocs build --strict --quiet
	@echo "site: site/index.html"

clean:
	rm -rf $(VENV) .pytest_cache .hypothesis site demo-out
