"""Shared test configuration.

Hypothesis profiles: ``default`` keeps the default run short; ``thorough`` (``--hypothesis-profile
thorough``) draws many more points for validation runs. Randomness is always seeded.
"""

from hypothesis import HealthCheck, settings

settings.register_profile(
    "default",
    max_examples=200,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.register_profile("thorough", max_examples=5000, deadline=None, derandomize=True)
settings.load_profile("default")


def pytest_configure(config):
    """Carried lunar core states (``spinorbit.coupling.lunar_core``) go to a cache of this test run only,
    so the suite neither reads nor fills the user's ``~/.cache/spinorbit``. The cold-compile notice is
    silenced (``SPINORBIT_COMPILE_NOTICE=0``): on a cold cache it would add a line to the stderr that many
    tests check holds exactly one error line; tests/test_outputs.py checks the notice itself."""
    import os
    import tempfile

    os.environ["SPINORBIT_COMPILE_NOTICE"] = "0"

    if "SPINORBIT_CACHE_DIR" not in os.environ:
        config._spinorbit_cache = os.environ["SPINORBIT_CACHE_DIR"] = tempfile.mkdtemp(prefix="spinorbit-test-cache-")


def pytest_unconfigure(config):
    import shutil

    if getattr(config, "_spinorbit_cache", None):
        shutil.rmtree(config._spinorbit_cache, ignore_errors=True)
