"""A numerical reference for the diurnal Yarkovsky force: the 1-D heat equation by finite differences in depth.

The independent check of :mod:`spinorbit.core.model.yarkovsky` in its plane-parallel limit (radius ≫
penetration depth, κ₁ = κ₂ = κ₃ = 1/2): a sphere spinning about its orbit normal (obliquity 0) on a
circular orbit, each surface element a half-space heated by max(0, cos φ cos h) at latitude φ and
hour angle h = ωt. In units of the penetration depth l = √(K/(ρcω)), of 1/ω and of the subsolar
temperature T* (εσT*⁴ = αE*) the problem has one parameter, Θ::

    ∂u/∂t = ∂²u/∂z²,    u⁴ − Θ ∂u/∂z = max(0, cos φ cos t)  at z = 0,    ∂u/∂z = 0  at the bottom.

With ``linear=True`` the emission u⁴ is replaced by its tangent at the isothermal mean temperature of
the linear theory, u_av = 2^(−1/2) (4u_av⁴ = 1: a sphere's mean absorbed flux is a quarter of the
subsolar one), so the solver solves the linear theory's own problem by a different method;
``linear=False`` keeps u⁴ and each latitude its own mean temperature.

The recoil of the emission, −(2/3)(εσT⁴/c) n̂ dA, integrated over the sphere gives the along-track
force; in the linear theory's form it is (4/9)αΦ times −W, so the returned number is that W,
comparable with :func:`spinorbit.core.model.yarkovsky.thermal_response` at R′ → ∞:
W = −(3/2π) ∫∫ u⁴ sin h cos²φ dφ dh over the last period.

Scheme: uniform cells in depth, Crank–Nicolson in time, the emission linearised about the previous
step (the surface row is the only one that changes, so the matrix is a fixed inverse plus a rank-one
Sherman–Morrison update per step); Gauss–Legendre in latitude. The error is second order in the
cell size (measured in docs/thermal.md). From the start (each latitude at its radiative-equilibrium
mean temperature) the run settles in a few rotations at Θ ≲ 3 and in about Θ rotations above, where
the column's mean temperature relaxes slowly; the returned change over the last rotation shows it.
"""

import math

import numpy as np

__all__ = ["diurnal_recoil_fd", "ISOTHERMAL_MEAN_TEMPERATURE"]

#: The linear theory's mean temperature in units of T*: εσT_av⁴ = αE*/4.
ISOTHERMAL_MEAN_TEMPERATURE = 2.0**-0.5


def _conduction_matrix(cells, depth):
    """Heat capacities of the nodes (half cells at both ends) and the conduction matrix, zero flux at the bottom."""
    step = depth / cells
    nodes = cells + 1
    capacity = np.full(nodes, step)
    capacity[0] = capacity[-1] = step / 2.0
    conduction = np.zeros((nodes, nodes))
    index = np.arange(cells)
    conduction[index, index] -= 1.0 / step
    conduction[index + 1, index + 1] -= 1.0 / step
    conduction[index, index + 1] += 1.0 / step
    conduction[index + 1, index] += 1.0 / step
    return capacity, conduction


def diurnal_recoil_fd(theta, linear=False, depth=12.0, cells=120, steps=512, periods=8, latitudes=12):
    """W of the diurnal recoil from the finite-difference heat equation, and its change over the last period.

    Parameters
    ----------
    theta : float
        The thermal parameter Θ > 0.
    linear : bool
        Linearise the emission about the isothermal mean temperature (the linear theory's problem).
    depth : float
        Depth of the column in penetration depths (the wave falls as exp(−z/√2): 12 → 2e−4).
    cells, steps, periods, latitudes : int
        Cells in depth, time steps per rotation, rotations run, Gauss–Legendre nodes per hemisphere.

    Returns
    -------
    (float, float)
        W over the last rotation, and W(last) − W(the one before): how far from periodic the run is.
    """
    if not theta > 0.0 or not math.isfinite(theta):
        raise ValueError(f"theta: expected a finite thermal parameter Θ > 0; got {theta!r}.")
    capacity, conduction = _conduction_matrix(int(cells), float(depth))
    time_step = 2.0 * math.pi / steps
    nodes, weights = np.polynomial.legendre.leggauss(int(latitudes))
    latitude = (nodes + 1.0) * math.pi / 4.0
    weight = weights * math.pi / 2.0  # (π/4 for the interval) × 2 for the mirror hemisphere
    cos_latitude = np.cos(latitude)
    explicit = np.diag(capacity / time_step) + 0.5 * conduction
    implicit_inverse = np.linalg.inv(np.diag(capacity / time_step) - 0.5 * conduction)
    surface_column = implicit_inverse[:, 0]
    mean = ISOTHERMAL_MEAN_TEMPERATURE
    if linear:
        temperature = np.full((cells + 1, latitudes), mean)
    else:
        temperature = np.tile((cos_latitude / math.pi) ** 0.25, (cells + 1, 1))

    def emission(surface):
        return mean**4 + 4.0 * mean**3 * (surface - mean) if linear else surface**4

    history = []
    for _ in range(int(periods)):
        integral = 0.0
        for step in range(int(steps)):
            hour, next_hour = step * time_step, (step + 1) * time_step
            surface = temperature[0]
            slope = np.full(latitudes, 4.0 * mean**3) if linear else 4.0 * surface**3
            intercept = emission(surface) - slope * surface  # emission(u) ≈ intercept + slope u
            heating = np.maximum(0.0, cos_latitude * math.cos(hour))
            next_heating = np.maximum(0.0, cos_latitude * math.cos(next_hour))
            rhs = explicit @ temperature
            rhs[0] += 0.5 * (heating - emission(surface)) / theta + 0.5 * (next_heating - intercept) / theta
            coupling = 0.5 * slope / theta  # the new emission's implicit half on the surface row
            solved = implicit_inverse @ rhs
            temperature = solved - np.outer(surface_column, coupling * solved[0] / (1.0 + coupling * surface_column[0]))
            integral += time_step * math.sin(next_hour) * (emission(temperature[0]) @ (weight * cos_latitude**2))
        history.append(-3.0 / (2.0 * math.pi) * integral)
    change = history[-1] - history[-2] if len(history) > 1 else math.nan
    return history[-1], change
