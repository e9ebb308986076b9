"""Shared pytest setup: hypothesis profiles and the repository root on sys.path.

``make test`` does not depend on chance: the default profile is derandomised (the examples are
a function of the test alone) and keeps no example database between runs. ``make fuzz``
(``HYPOTHESIS_PROFILE=fuzz``, never run by CI) runs the same property tests with random seeds,
a database, and :data:`FUZZ_FACTOR` times the examples each test asks for.
"""

import os
import sys
from pathlib import Path

from hypothesis import HealthCheck, settings

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

FUZZ_FACTOR = 20
_QUIET = [HealthCheck.too_slow]

settings.register_profile("default", deadline=None, max_examples=100, derandomize=True, database=None,
                          suppress_health_check=_QUIET)
settings.register_profile("ci", parent=settings.get_profile("default"))
settings.register_profile("fuzz", deadline=None, max_examples=100 * FUZZ_FACTOR, derandomize=False,
                          print_blob=True, suppress_health_check=_QUIET + [HealthCheck.filter_too_much])
settings.register_profile("thorough", deadline=None, max_examples=2000,
                          suppress_health_check=_QUIET)
PROFILE = os.environ.get("HYPOTHESIS_PROFILE", "default")
settings.load_profile(PROFILE)


def pytest_collection_modifyitems(config, items):  # noqa: ARG001 - pytest hook signature
    """Under ``fuzz``, scale every property test's own ``max_examples`` and drop its
    ``derandomize``, so tests that fix their example count get more examples too."""
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
