"""Shared pytest setup: hypothesis profiles, the repository root on sys.path, and the check
that no process helmcheck started (``--exec``) outlives the test session."""

import os
import sys
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

settings.register_profile("default", deadline=None, max_examples=100,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("ci", deadline=None, max_examples=100, derandomize=True,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("thorough", deadline=None, max_examples=2000,
                          suppress_health_check=[HealthCheck.too_slow])
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci" if os.environ.get("CI") else "default"))

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
