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
