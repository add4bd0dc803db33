"""What the batch integrators' tests share: members with their own moments and states under two point
masses on an ellipse and a hyperbola (a close passage), in units where the spin is O(1)."""

from __future__ import annotations

import numpy as np

from spinorbit.core import make_model
from spinorbit.core.dynamics.equations import MODEL_PERTURBERS
from spinorbit.core.model.perturbers import kepler_source

SOURCES = (kepler_source(1e-2, 2.0, 0.3, 0.2, 0.1, 0.4, 0.0), kepler_source(3e-3, -1.5, 1.4, 0.5, 0.3, 0.2, -1.0))


def members(n, seed=1):
    """(y0s (n, 7), n models of random moments, the generator for the caller's further draws)."""
    rng = np.random.default_rng(seed)
    models = [make_model((0.5 + 0.1 * rng.random(), 0.8 + 0.1 * rng.random(), 1.0), SOURCES) for _ in range(n)]
    y0s = np.hstack([rng.normal(size=(n, 4)), 3.0 * rng.normal(size=(n, 3))])
    return y0s, models, rng


def spans(rng, n):
    """(t0s, t_ends) of n members: starts in [-1, 1], spans of 2 to 6 forward or backward."""
    t0s = rng.uniform(-1.0, 1.0, n)
    return t0s, t0s + rng.choice([-1.0, 1.0], n) * rng.uniform(2.0, 6.0, n)


def break_mass(models, m):
    """Give member m a NaN mass of its first perturber (so a NaN torque), in a copy of its model; return it."""
    models[m] = models[m].copy()
    models[m][MODEL_PERTURBERS + 1 + 1] = np.nan  # the first perturber's mu (its row's second entry)
    return models[m]
