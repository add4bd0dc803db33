"""The perturbers of a scene sampled relative to the body, and the samples shared within one plan or run.

A scene's perturbers come from DE421 or a user ephemeris (:func:`sample_perturbers` with source
"de421" or "ephemeris"), a REBOUND run ("rebound") or user :class:`~spinorbit.scene.EphemerisPerturber`
s ("user"), all onto the adaptive Hermite grid of :mod:`spinorbit.coupling.sampling`.
:class:`SharedSamples` keeps what one :meth:`~spinorbit.scene.Scene.plan` or
:meth:`~spinorbit.scene.Scene.run` (or the bodies of one orbit, :mod:`spinorbit.scene.many`) has
sampled, so that the survey and the run pay each sampling once.
"""

from __future__ import annotations

import numpy as np

from spinorbit.time import time_from_tdb_days

__all__ = ["NoSamples", "SharedSamples", "body_orbit", "grid_of_samples", "sample_perturbers", "subset_samples"]


def sample_perturbers(orbit, moving, epoch_day, end_day, source, names, tolerance):
    """Sample ``names`` relative to the body from ``source`` over ``epoch_day`` … ``end_day`` (TDB days).

    Parameters
    ----------
    orbit : Orbit or None
        The scene's orbit (the body's, and where DE421 or REBOUND perturbers are).
    moving : sequence of EphemerisPerturber
        The scene's user ephemerides (source "user").
    epoch_day, end_day : float
        TDB days since J2000.
    source : {"de421", "ephemeris", "rebound", "user"}
    names : sequence of str
    tolerance : float
        Relative interpolation error of the samples.

    Returns
    -------
    spinorbit.coupling.sampling.SampledPerturbers
    """
    from spinorbit.coupling import sampling

    start, end = time_from_tdb_days(epoch_day), time_from_tdb_days(end_day)
    if source == "user":
        return _sample_user(orbit, moving, start, end, names, tolerance)
    if source == "rebound":
        return sampling.sample_from_rebound(orbit.simulation, orbit.name, start, end, names, tolerance=tolerance)
    function = sampling.de421_orbit(orbit.name) if source == "de421" else orbit.function
    return sampling.sample_from_ephemeris(function, start, end, names, tolerance=tolerance)


def _sample_user(orbit, moving, start, end, names, tolerance):
    """Sample the EphemerisPerturbers ``names`` relative to the body (same grid and checks as DE421's)."""
    from spinorbit.coupling import sampling

    chosen = [next(p for p in moving if p.name == name) for name in names]
    body = body_orbit(orbit) if any(not p.relative for p in chosen) else None

    def provider(days):
        out = np.empty((days.size, len(chosen), 6))
        centre = None if body is None else np.concatenate([np.asarray(a, dtype=float) for a in body(days)], axis=1)
        for i, perturber in enumerate(chosen):
            out[:, i] = perturber.states(days) - (0.0 if perturber.relative else centre)
        return out

    return sampling.sample_states(provider, names, [p.gm_au3_day2 for p in chosen], start, end, tolerance)


def body_orbit(orbit):
    """The body's barycentric orbit as a callable days -> (positions, velocities), au and au/day."""
    from spinorbit.coupling import sampling

    if orbit.kind == "de421":
        return sampling.de421_orbit(orbit.name)
    if orbit.kind == "rebound":
        return sampling.rebound_orbit(orbit.simulation, orbit.name)
    return orbit.function


def grid_of_samples(samples, tolerance):
    """:func:`spinorbit.coupling.sampling.a_priori_grid` of ``samples`` over their own span at ``tolerance``: the
    grid a sampling of their orbits at that tolerance starts from (the planner counts its knots)."""
    from spinorbit.coupling.sampling import a_priori_grid

    return a_priori_grid(samples.days, samples.states, samples.days[0], samples.days[-1], tolerance)


def subset_samples(samples, names):
    """The columns of ``names`` of a SampledPerturbers (same grid, same error estimates per perturber)."""
    from spinorbit.coupling.sampling import SampledPerturbers

    index = [samples.names.index(n) for n in names]
    return SampledPerturbers(tuple(names), samples.gm[index], samples.days, samples.states[:, index],
                             samples.tolerance, samples.midpoint_error[index], samples.passes,
                             {n: samples.closest[n] for n in names if n in samples.closest})


class SharedSamples:
    """Samples already taken, by (source, tolerance): a request for some of their perturbers reuses them.

    ``memo`` (optional, a dict the caller keeps across several SharedSamples of scenes with the same
    orbit, span and ephemerides) answers a request it holds *exactly* (same source, tolerance and
    names in the same order) and is given every new sampling. A sampling is a pure function of that
    request, so a hit there is the bits a fresh sampling would give: what a SharedSamples returns
    does not depend on what the memo saw before (the ensemble's chunks share one sampling per worker
    process this way, and the table does not depend on which worker ran which chunk).
    """

    def __init__(self, memo=None):
        self._taken = []
        self._memo = memo
        self._grids = {}

    def grid_of(self, samples, tolerance):
        """:func:`grid_of_samples` of ``samples``, computed once per samples object and tolerance.

        The grid is a pure function of the samples' arrays and the tolerance, so a kept one is the bits
        a fresh one gives. It is keyed by the samples *object* (held with the grid, so its id is not
        reused while the entry lives) and kept here, and in the memo when the samples are the memo's
        own (then later chunks of this process reuse it too).
        """
        key = ("a priori grid", id(samples), tolerance)
        in_memo = self._memo is not None and any(kept is samples for kept in self._memo.values())
        store = self._memo if in_memo else self._grids
        hit = store.get(key)
        if hit is not None and hit[0] is samples:
            return hit[1]
        grid = grid_of_samples(samples, tolerance)
        store[key] = (samples, grid)
        return grid

    def find(self, source, names, tolerance):
        """The samples of ``names`` from ``source`` at ``tolerance`` if taken already (their columns), else None."""
        for taken_source, taken_tolerance, taken in self._taken:
            if taken_source == source and taken_tolerance == tolerance and set(names) <= set(taken.names):
                return taken if tuple(names) == taken.names else subset_samples(taken, names)
        remembered = None if self._memo is None else self._memo.get((source, tolerance, tuple(names)))
        if remembered is not None:
            self._taken.append((source, tolerance, remembered))
        return remembered

    def add(self, source, tolerance, samples):
        """Keep ``samples`` for later requests (and in the memo, by the exact request)."""
        self._taken.append((source, tolerance, samples))
        if self._memo is not None:
            self._memo[(source, tolerance, tuple(samples.names))] = samples


class NoSamples:
    """Stand-in for SampledPerturbers when no sampled perturber is kept (the span's two ends, no sources)."""

    names = ()
    tolerance = 0.0
    passes = 0
    midpoint_error = np.zeros(0)

    def __init__(self, start, end):
        self.days = np.array([start, end])
        self.span = (start, end)

    def sources(self):
        return []
