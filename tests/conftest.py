"""Shared test configuration.

Hypothesis profiles: ``default`` keeps the default run short; ``thorough`` (``--hypothesis-profile
thorough``) draws many more points for validation runs. Randomness is always seeded.
"""

import pytest
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


@pytest.fixture(scope="session")
def dask_client():
    """A Dask ``LocalCluster`` of two single-threaded worker processes and its Client, for the whole run
    (``tests/test_ensemble.py``, ``tests/test_orbit_pickling.py``; started only if a test asks for it)."""
    distributed = pytest.importorskip("distributed")
    import dask

    # a task on a worker that dies fails at once (KilledWorker) instead of being retried: the resume test
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0")
        client = distributed.Client(cluster)
        try:
            yield client
        finally:
            client.close()
            cluster.close()
