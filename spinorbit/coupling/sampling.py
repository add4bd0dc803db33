"""Perturbers sampled for the one-way coupling: adaptive cubic-Hermite grids from DE421 or REBOUND.

The rotating body's translational motion and its perturbers' positions come from outside (DE421 for
the planets, a user ephemeris or a REBOUND run for the body). They are sampled once, onto an
adaptive time grid, into cubic-Hermite :func:`spinorbit.core.model.perturbers.sampled_source` s,
which :func:`spinorbit.coupling.one_way.propagate_one_way` hands to the rotation integrators.

Sampling and its error estimate
-------------------------------
Piecewise cubic Hermite interpolation of positions *and* velocities has, on an interval of length h,
the error x(t) − p(t) = x⁗(ξ)/4! · s²(1 − s)² h⁴ (s ∈ [0, 1] the position in the interval), whose
kernel is largest at the midpoint: ≤ h⁴/384 · max|x⁗|. Two steps choose the grid:

1. **A priori** (pilot run): the local time scale of every perturber's relative motion,
   τ = |r|/|v| (r, v relative to the body), sets the step h = τ · (384 ε)^(1/4). For a circular
   orbit τ = 1/n and x⁗ = n⁴ r exactly, so this h gives a relative midpoint error of exactly ε; on
   a hyperbolic flyby τ shrinks to (perigee distance)/(perigee speed), so the grid tightens
   automatically around close encounters (≈ 4 min for Apophis in 2029 at ε = 1e-10, which the
   check below refines to 1.2 min: near perigee x⁗ exceeds r/τ⁴).
2. **A posteriori** (check and refine): the true states at every interval's midpoint are computed
   together with the grid, in one provider call (the ephemeris, or one REBOUND run through grid and
   midpoints), and compared with the interpolant there.
   The midpoint error is the error estimate of the interval (the kernel's maximum, exact when x⁗ is
   nearly constant over the interval, which it is once h ≪ τ). Intervals whose relative midpoint
   error exceeds ε for any perturber are bisected — the midpoint, whose true state is known, becomes
   a sample — and the next pass re-evaluates the refined grid and all its midpoints.

The relative error ε is on |r| because the degree-2 torque is ∝ μ/|r|³: a relative position error ε
gives a relative torque error ≲ 3ε. ``SampledPerturbers.midpoint_error`` reports the measured
maximum per perturber; ``tests/test_asteroids.py`` checks it against the true error of a Kepler orbit.

Frames, units, time
-------------------
ICRF axes; positions in au_DE421, velocities in au/day, GM in au³/day² (DE421's, REBOUND's
("AU", "day", "Msun") units); time in TDB days since J2000 (``docs/conventions.md``).
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass, field

import numpy as np
from astropy.time import Time

from spinorbit.core.model.perturbers import sampled_source
from spinorbit.ephemeris import DE421_SPAN_JD_TDB, EphemerisRangeError, barycentric_state_au, de421_constants, resolve_body
from spinorbit.time import J2000_JD_TDB, tdb_days

__all__ = [
    "DEFAULT_PERTURBERS",
    "DEFAULT_SAMPLE_TOLERANCE",
    "SampledPerturbers",
    "SamplingError",
    "a_priori_grid",
    "sample_from_ephemeris",
    "sample_from_rebound",
    "sample_relative_states",
    "sample_states",
    "de421_orbit",
    "de421_state",
    "rebound_orbit",
]

#: Perturbers by default: the Sun (the secular torque), Earth and Moon (close encounters of NEAs).
#: Jupiter's torque on a near-Earth asteroid is ≈ 1e-5 of the Sun's (μ/r³) and is left out.
DEFAULT_PERTURBERS = ("sun", "earth", "moon")
#: Relative position error allowed for the interpolated perturbers (module docstring). 1e-10 keeps
#: the relative torque error (≲ 3e-10) at the rotation integrator's default local tolerance; the
#: grid spacing scales only as ε^(1/4), so asking this much costs ≈ 1.8× the samples of 1e-9.
DEFAULT_SAMPLE_TOLERANCE = 1e-10
#: Pilot-run spacing (days): only used to estimate the time scale τ(t); the a posteriori check
#: catches an encounter the pilot samples too coarsely (it then needs more refinement passes).
PILOT_SPACING_DAYS = 0.25
#: Upper bound on a sample spacing (days), so a distant, slow perturber is still sampled.
MAX_SPACING_DAYS = 10.0
#: Refinement passes before giving up (each halves the failing intervals; the a priori grid is
#: usually within a factor 2 of the needed spacing, so 1–3 passes suffice).
MAX_REFINEMENT_PASSES = 8


class SamplingError(RuntimeError):
    """The adaptive sampler could not reach the requested interpolation tolerance."""


@dataclass
class SampledPerturbers:
    """Perturber states relative to the rotating body on an adaptive grid, ready for the model.

    Attributes
    ----------
    names : tuple of str
        Perturber names (DE421 / REBOUND names, lower case).
    gm : ndarray (k,)
        G·M of each perturber, au³/day².
    days : ndarray (n,)
        Sample times, TDB days since J2000.
    states : ndarray (n, k, 6)
        Position (au) and velocity (au/day) of each perturber minus the body's, ICRF.
    tolerance : float
        Requested relative midpoint error.
    midpoint_error : ndarray (k,)
        Largest measured relative midpoint error per perturber over all final intervals (the
        interpolation-error estimate; module docstring).
    passes : int
        Number of provider calls (pilot + checks); for REBOUND, full re-integrations.
    """

    names: tuple
    gm: np.ndarray
    days: np.ndarray
    states: np.ndarray
    tolerance: float
    midpoint_error: np.ndarray
    passes: int = 0
    closest: dict = field(default_factory=dict)

    def sources(self):
        """One :func:`~spinorbit.core.model.perturbers.sampled_source` per perturber."""
        return [sampled_source(mu, self.days, self.states[:, i, :3], self.states[:, i, 3:])
                for i, mu in enumerate(self.gm)]

    def interpolate(self, days):
        """Hermite-interpolated relative positions (n, k, 3) at ``days`` (vectorised, for checks)."""
        return _hermite_positions(self.days, self.states, np.asarray(days, dtype=float))

    @property
    def span(self):
        """(first, last) sample time, TDB days since J2000."""
        return float(self.days[0]), float(self.days[-1])


def _hermite_positions(grid, states, days):
    index = np.clip(np.searchsorted(grid, days, side="right") - 1, 0, grid.size - 2)
    h = (grid[index + 1] - grid[index])[:, None, None]
    s = ((days - grid[index]) / h[:, 0, 0])[:, None, None]
    p0, v0 = states[index, :, :3], states[index, :, 3:]
    p1, v1 = states[index + 1, :, :3], states[index + 1, :, 3:]
    s2, s3 = s * s, s * s * s
    return ((2 * s3 - 3 * s2 + 1) * p0 + (s3 - 2 * s2 + s) * h * v0 + (-2 * s3 + 3 * s2) * p1
            + (s3 - s2) * h * v1)


def _midpoint_errors(grid, states, mid_states):
    """Relative error (n−1, k) of the Hermite interpolant at interval midpoints: at s = ½ it is
    (p0 + p1)/2 + h (v0 − v1)/8."""
    h = np.diff(grid)[:, None, None]
    interp = 0.5 * (states[:-1, :, :3] + states[1:, :, :3]) + h * (states[:-1, :, 3:] - states[1:, :, 3:]) / 8
    truth = mid_states[:, :, :3]
    return np.linalg.norm(interp - truth, axis=2) / np.linalg.norm(truth, axis=2)


def _scalar_interp(xp, fp):
    """``x -> float(np.interp(x, xp, fp))`` with the same arithmetic, bit for bit, at a fraction of
    its per-call cost (the grid loop calls it once per sample, thousands of times)."""
    xs, fs = np.asarray(xp, dtype=float).tolist(), np.asarray(fp, dtype=float).tolist()
    last = len(xs) - 1

    def interpolate(x):
        if x <= xs[0]:
            return fs[0]
        if x >= xs[last]:
            return fs[last]
        j = bisect.bisect_right(xs, x) - 1  # xs[j] <= x < xs[j + 1]
        if xs[j] == x:
            return fs[j]
        slope = (fs[j + 1] - fs[j]) / (xs[j + 1] - xs[j])  # numpy's compiled_interp formula
        return slope * (x - xs[j]) + fs[j]

    return interpolate


def a_priori_grid(pilot_days, pilot_states, start, end, tolerance):
    """Grid with spacing τ(t)·(384 ε)^(1/4), τ = min over perturbers of |r|/|v| (module docstring)."""
    r = np.linalg.norm(pilot_states[:, :, :3], axis=2)
    v = np.linalg.norm(pilot_states[:, :, 3:], axis=2)
    tau = np.min(r / np.maximum(v, 1e-300), axis=1)
    # Each pilot τ replaced by the smallest of it and its neighbours: linear interpolation between
    # pilot samples then never exceeds the local minimum an encounter between them would have.
    tau = np.minimum(tau, np.minimum(np.r_[tau[0], tau[:-1]], np.r_[tau[1:], tau[-1]]))
    fraction = (384.0 * tolerance) ** 0.25
    grid = [start]
    t = start
    interpolate = _scalar_interp(pilot_days, tau)
    while t < end:
        h = min(fraction * interpolate(t), MAX_SPACING_DAYS)
        t = min(t + h, end)
        if end - t < 0.25 * h:  # no sliver at the end: it would cost a sample for nothing
            t = end
        grid.append(t)
    return np.array(grid)


def _adaptive_samples(provider, start, end, tolerance):
    """Run the pilot, the a priori grid and the midpoint refinement against ``provider``."""
    if not (np.isfinite(tolerance) and 1e-14 <= tolerance < 1e-2):
        raise ValueError(f"tolerance: expected a relative interpolation error in [1e-14, 1e-2), got {tolerance!r}.")
    if not end > start:
        raise ValueError(f"the sample span must have end > start (TDB days), got [{start!r}, {end!r}].")
    pilot = np.linspace(start, end, max(3, int(math.ceil((end - start) / PILOT_SPACING_DAYS)) + 1))
    grid = a_priori_grid(pilot, provider(pilot), start, end, tolerance)
    passes = 1
    while True:
        # Grid and midpoints in one provider call: a REBOUND run's trajectory depends on its output
        # times (IAS15 cuts a step at each), so two runs would disagree by more than the tolerance.
        mids = 0.5 * (grid[:-1] + grid[1:])
        both = provider(np.concatenate([grid, mids])[np.argsort(np.concatenate([grid, mids]), kind="stable")])
        passes += 1
        states, mid_states = both[0::2], both[1::2]  # sorted grid and midpoints alternate
        errors = _midpoint_errors(grid, states, mid_states)  # (n−1, k)
        worst = errors.max(axis=1)
        if not np.any(worst > tolerance):
            break
        if passes >= MAX_REFINEMENT_PASSES + 1:
            raise SamplingError(
                f"interpolation error {worst.max():.2e} still above tolerance {tolerance:.1e} after "
                f"{passes} passes ({grid.size} samples); loosen the tolerance or check the orbit for a "
                "collision (|r| → 0)."
            )
        # Bisect the failing intervals: their midpoints become samples.
        grid = np.sort(np.concatenate([grid, mids[worst > tolerance]]))
    closest = {}
    for i in range(states.shape[1]):
        distance = np.linalg.norm(states[:, i, :3], axis=1)
        j = int(np.argmin(distance))
        closest[i] = (float(grid[j]), float(distance[j]))
    return grid, states, errors.max(axis=0), passes, closest


def _perturber_names(perturbers):
    names = tuple(resolve_body(p) for p in perturbers)  # UnknownBodyError for a bad name
    if not names:
        raise ValueError("perturbers: expected at least one body name, e.g. ('sun', 'earth').")
    return names


def _check_de421_span(start, end):
    lo, hi = (jd - J2000_JD_TDB for jd in DE421_SPAN_JD_TDB)
    if start < lo or end > hi:
        raise EphemerisRangeError(
            f"sample span [{start + J2000_JD_TDB:.1f}, {end + J2000_JD_TDB:.1f}] JD TDB leaves DE421's span "
            f"JD {DE421_SPAN_JD_TDB[0]}–{DE421_SPAN_JD_TDB[1]} TDB (1899-12-04 to 2200-02-01)."
        )


def de421_state(name, days):
    """DE421 barycentric state (au_DE421, au/day; ICRF) of ``name`` at float TDB days since J2000.

    The days reach jplephem as (whole days, fraction): a float JD near 2.45e6 resolves only 40 µs,
    whose position noise would read as interpolation error at the default tolerance.

    Parameters
    ----------
    name : str
        A DE421 body (:data:`spinorbit.ephemeris.KNOWN_BODIES`).
    days : array_like
        TDB days since J2000.

    Returns
    -------
    positions, velocities : ndarray, shape (..., 3)
        au_DE421 and au/day.
    """
    days = np.asarray(days, dtype=float)
    whole = np.round(days)
    return barycentric_state_au(name, whole, days - whole)  # days − whole is exact in float


def de421_orbit(name):
    """The barycentric orbit of a DE421 body as a callable ``days -> (positions, velocities)``.

    For tests and for rotating bodies that DE421 carries (the Moon): au_DE421 and au/day, ICRF.
    """
    name = resolve_body(name)

    def orbit(days):
        return de421_state(name, days)

    return orbit


def remembering(orbit):
    """``orbit`` (days -> (positions, velocities)) returning its earlier result for the same days.

    The "de421" Moon model samples each distant perturber on its own grids, but all start from the
    same pilot times: the Moon's barycentric state there (two Chebyshev series) is evaluated once.
    """
    seen = {}

    def remembered(days):
        days = np.asarray(days, dtype=float)
        key = days.tobytes()
        if key not in seen:
            seen[key] = orbit(days)
        return seen[key]

    return remembered


def _as_days_span(start, end):
    if not isinstance(start, Time) or not isinstance(end, Time):
        raise TypeError("start and end must be astropy Time objects (any scale convertible to TDB).")
    (d0, r0), (d1, r1) = tdb_days(start), tdb_days(end)
    return float(d0 + r0), float(d1 + r1)


def sample_from_ephemeris(body_orbit, start, end, perturbers=DEFAULT_PERTURBERS,
                          tolerance=DEFAULT_SAMPLE_TOLERANCE):
    """Sample DE421 perturbers relative to a body whose orbit is a callable.

    Parameters
    ----------
    body_orbit : callable
        ``body_orbit(days) -> (positions (n, 3), velocities (n, 3))``: barycentric ICRF state of the
        rotating body in au_DE421 and au/day at TDB days since J2000 (vectorised over ``days``).
        E.g. :func:`de421_orbit`, or a REBOUND particle's through :func:`rebound_orbit`.
    start, end : astropy.time.Time
        Span to cover (end > start).
    perturbers : sequence of str
        DE421 names (:data:`spinorbit.ephemeris.KNOWN_BODIES`).
    tolerance : float
        Relative interpolation error ε of every perturber position (module docstring).

    Returns
    -------
    SampledPerturbers

    Raises
    ------
    spinorbit.ephemeris.UnknownBodyError
        A perturber name DE421 does not have.
    spinorbit.ephemeris.EphemerisRangeError
        The span leaves DE421.
    SamplingError
        The tolerance could not be reached.
    """
    names = _perturber_names(perturbers)

    def provider(days):
        body_r, body_v = (np.asarray(a, dtype=float) for a in body_orbit(days))
        out = np.empty((days.size, len(names), 6))
        for i, name in enumerate(names):
            r, v = de421_state(name, days)
            out[:, i, :3] = r - body_r
            out[:, i, 3:] = v - body_v
        return out

    return sample_relative_states(provider, names, start, end, tolerance)


def sample_relative_states(provider, perturbers, start, end, tolerance=DEFAULT_SAMPLE_TOLERANCE):
    """Sample DE421 perturbers given directly as states relative to the body (adaptive grid).

    Parameters
    ----------
    provider : callable
        ``provider(days) -> (n, k, 6)``: positions (au) and velocities (au/day) of the k perturbers
        relative to the body at sorted TDB days since J2000. For the Earth seen from the Moon, e.g.,
        minus DE421's geocentric Moon series (one series instead of four).
    perturbers : sequence of str
        The k DE421 names (their GMs are DE421's).
    start, end : astropy.time.Time
    tolerance : float
        Relative interpolation error ε (module docstring).

    Returns
    -------
    SampledPerturbers
    """
    names = _perturber_names(perturbers)
    start_day, end_day = _as_days_span(start, end)
    _check_de421_span(start_day, end_day)
    return sample_states(provider, names, [de421_constants().gm[n] for n in names], start, end, tolerance)


def sample_states(provider, names, gm, start, end, tolerance=DEFAULT_SAMPLE_TOLERANCE):
    """Sample any perturbers given as states relative to the body (adaptive grid, module docstring).

    Parameters
    ----------
    provider : callable
        ``provider(days) -> (n, k, 6)``: positions (au) and velocities (au/day) relative to the body
        at sorted TDB days since J2000.
    names : sequence of str
        The k perturbers' names.
    gm : sequence of float
        Their G·M, au³/day².
    start, end : astropy.time.Time
    tolerance : float
        Relative interpolation error ε.

    Returns
    -------
    SampledPerturbers
    """
    names = tuple(names)
    start_day, end_day = _as_days_span(start, end)
    grid, states, error, passes, closest = _adaptive_samples(provider, start_day, end_day, tolerance)
    return SampledPerturbers(names, np.asarray(gm, dtype=float), grid, states, tolerance, error, passes,
                             {names[i]: c for i, c in closest.items()})


def rebound_orbit(sim, body):
    """The barycentric orbit of a REBOUND particle as a callable for :func:`sample_from_ephemeris`.

    Route (a) with a REBOUND-integrated body and the perturbers straight from DE421. Each call
    rebuilds the simulation from a copy of its present state (``sim`` is not modified) and integrates
    it through the requested times (``exact_finish_time``), so the sampler gets the smooth
    trajectory, not an interpolant of it. The frame is REBOUND's: a simulation from
    :func:`~spinorbit.coupling.rebound.simulation.simulation_from_de421` is barycentric ICRF to the
    centre-of-mass shift of the bodies left out (metres); but the perturber vectors then mix DE421
    planets with a body integrated among REBOUND's planets, whose drift from DE421 (metres to
    kilometres over decades: ``docs/ephemeris.md``) enters them. Route (b),
    :func:`sample_from_rebound`, takes both from the same run and has no such mixing.

    Returns
    -------
    callable
        ``days -> (positions (n, 3), velocities (n, 3))``, au and au/day.
    """
    from spinorbit.coupling.rebound import (  # only REBOUND samplers need it
        SimulationSnapshot,
        body_index,
        integrate_interruptibly,
    )

    centre = body_index(sim, body)
    snapshot = SimulationSnapshot.of(sim)

    def orbit(days):
        days = np.atleast_1d(np.asarray(days, dtype=float))
        order = np.argsort(days, kind="stable")
        run = snapshot.build()
        out = np.empty((days.size, 6))
        xyz, vel = np.zeros((run.N, 3)), np.zeros((run.N, 3))
        for j in order:
            integrate_interruptibly(run, days[j])
            run.serialize_particle_data(xyz=xyz, vxvyvz=vel)
            out[j, :3], out[j, 3:] = xyz[centre], vel[centre]
        return out[:, :3], out[:, 3:]

    return orbit


def sample_from_rebound(sim, body, start, end, perturbers=DEFAULT_PERTURBERS,
                        tolerance=DEFAULT_SAMPLE_TOLERANCE):
    """Sample perturbers relative to ``body`` from a REBOUND simulation (IAS15, exact_finish_time).

    The simulation is not modified: its state is copied (REBOUND's binary: integrator and its
    settings included), and every pass rebuilds it from the copy, integrates it to ``start``
    (backwards if ``sim.t`` is later) and then forwards through the sorted sample times with
    ``exact_finish_time = 1``. Extra forces installed by
    :func:`~spinorbit.coupling.rebound.extra_forces.install_extra_forces` (also when folded into an
    attached rigid body's force) are reinstalled on each copy; other forces are refused
    (``ForceInstallError``), since a copy would run without them.

    Parameters
    ----------
    sim : rebound.Simulation
        In ("AU", "day", "Msun") units, ``t`` in TDB days since J2000, ICRF axes, named particles
        (e.g. :func:`~spinorbit.coupling.rebound.simulation.simulation_from_de421` plus the asteroid).
    body : str
        Name of the rotating body's particle.
    start, end : astropy.time.Time
    perturbers : sequence of str
        Particle names (case-insensitive).
    tolerance : float
        Relative interpolation error ε (module docstring).

    Returns
    -------
    SampledPerturbers

    Raises
    ------
    spinorbit.coupling.rebound.simulation.MissingBodyError
        ``body`` or a perturber is not in the simulation.
    spinorbit.coupling.rebound.extra_forces.ForceInstallError
        ``sim`` has forces spinorbit did not install (they would be missing from the copies).
    SamplingError
    """
    if not perturbers:
        raise ValueError("perturbers: expected at least one particle name.")
    from spinorbit.coupling.rebound import (  # only REBOUND samplers need it
        SimulationSnapshot,
        body_index,
        integrate_interruptibly,
    )

    centre = body_index(sim, body)
    indices = [body_index(sim, p) for p in perturbers]
    names = tuple(sim.particles[i].name.lower() for i in indices)
    gm = np.array([sim.particles[i].m * sim.G for i in indices])
    _as_days_span(start, end)  # TypeError for a bad span before the simulation is copied
    snapshot = SimulationSnapshot.of(sim)

    def provider(days):
        run = snapshot.build()
        integrate_interruptibly(run, days[0])
        out = np.empty((days.size, len(indices), 6))
        xyz, vel = np.zeros((run.N, 3)), np.zeros((run.N, 3))
        for j, t in enumerate(days):
            integrate_interruptibly(run, t)
            run.serialize_particle_data(xyz=xyz, vxvyvz=vel)
            out[j, :, :3] = xyz[indices] - xyz[centre]
            out[j, :, 3:] = vel[indices] - vel[centre]
        return out

    return sample_states(provider, names, gm, start, end, tolerance)
