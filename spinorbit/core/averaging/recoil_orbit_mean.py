"""Sunlight's recoil averaged over the Sun's Kepler orbit exactly, facet by facet, and then over the rotation.

The mean YORP torque is a small remainder of large facet terms, so truncating the recoil's harmonic
representation (:mod:`spinorbit.core.model.thermal`) at degree 8 moves it by tens of per cent of itself
(docs/thermal.md). This module averages the facet sum itself, with no representation.

**The orbit average in closed form.** At a frozen attitude the Sun runs round a great circle of the body's
sky, the plane normal to the orbit normal w (body frame). Over a Kepler orbit the recoil's (d₀/r)² and
the time spent per angle cancel: r² dν/dt = √(μ a (1 − e²)), so the time average of (d₀/r)² g(ν) is
(d₀/a)² / √(1 − e²) times the plain average of g over the true anomaly ν. And over the great circle the
clipped cosine of a facet averages to its projection on the orbit plane::

    ⟨max(0, n·ŝ(ν))⟩_ν = |n − (n·w) w| / π = √(1 − (n·w)²) / π,

since n·ŝ(ν) = |P n| cos(ν − ν₀). So the orbit-averaged torque on the frozen body is exactly

    ⟨T⟩_orbit = −P(d₀) (d₀/a)² / (π √(1 − e²)) Σ_k √(1 − (n_k·w)²) A_k (r_k × n_k)

(eccentricity and perihelion enter only through a²√(1 − e²), as Scheeres 2007, Icarus 188, 430, found
for the zero-conductivity YORP; facet by facet it is the annual mean insolation of Ward 1974,
J. Geophys. Res. 79, 3375).
The first-order average over the orbit and the rotation together does not depend on their order, so
the remaining average over the rotation (the torus of the free motion, or the phase of a principal-axis
rotation) takes this smooth function of the attitude: √(1 − x²) has a branch point only where a facet's
normal points along ±w, so the trapezoidal rule over the rotation converges geometrically but for the
few facets whose normal sweeps close to the orbit pole (their terms converge as the square of the
spacing). docs/thermal.md and tests/test_yorp_mean.py measure the convergence against the brute-force
average of the facet sum over the rotation phase and the mean anomaly (tests/_yorp_reference.py).

Not with self-shadowing: a shadowed facet's lit share depends on the whole surface and the Sun's
direction, so the great-circle average is no longer a facet's own; shadowed blocks keep their fit.
"""

import math

import numpy as np

from spinorbit.core.jit import jit
from spinorbit.core.model.perturbers import K_A, K_P, K_Q, K_ROOT
from spinorbit.core.math.lanes import WIDTH, broadcast, load_lanes, select
from spinorbit.core.model.thermal import (FACET_ARM_X, FACET_ARM_Y, FACET_ARM_Z, FACET_NX, FACET_NY, FACET_NZ,
                                          TH_ALL_DEGREES, TH_DISTANCE, TH_FACETS, TH_PRESSURE, facet_table_offset,
                                          lane_sums6)

__all__ = ["orbit_mean_facet_sum_xyz", "orbit_mean_scale", "orbit_normal", "spin_mean_torque",
           "MEAN_SPIN_PHASES", "check_exact_average"]

#: Rotation phases of :func:`spin_mean_torque` by default: on Gaussian random spheres σ = 0.1–0.3
#: 64 phases leave at most ~2e-4 of each component, 128 ~4e-5 (docs/thermal.md, the convergence table).
MEAN_SPIN_PHASES = 128


def check_exact_average(block, base=0):
    """Refuse a block the exact average cannot take: one without facets or with shadows (ValueError)."""
    if int(block[base + TH_FACETS]) <= 0:
        raise ValueError("thermal block: expected the facet table (pack_thermal stores it); this block has none. "
                         "Rebuild it with spinorbit.shape.thermal_block.")
    if block[base + TH_ALL_DEGREES] != 0.0:
        raise ValueError("thermal block: the exact orbit average is a facet's own only without shadows; this block "
                         "is a shadowed fit. Average it with the representation (mean_thermal_rates) instead.")


@jit
def orbit_mean_facet_sum_xyz(wx, wy, wz, block, base):
    """Σ_k √(1 − (n_k·w)²) A_k (r_k × n_k) over the block's facets: π × the orbit mean of the clipped-cosine sum.

    ``w`` = (wx, wy, wz) is the orbit normal in the body frame (unit). Multiply by
    :func:`orbit_mean_scale` for the orbit-averaged torque (module docstring). Eight facets per register
    (:func:`spinorbit.core.model.thermal.facet_sum_xyz`).
    """
    table = facet_table_offset(block, base)
    count = int(block[base + TH_FACETS])
    vx, vy, vz, zero, one = broadcast(wx), broadcast(wy), broadcast(wz), broadcast(0.0), broadcast(1.0)
    tx = ty = tz = zero
    for k in range(0, count, WIDTH):
        x = (load_lanes(block, table + FACET_NX * count + k) * vx + load_lanes(block, table + FACET_NY * count + k) * vy
             + load_lanes(block, table + FACET_NZ * count + k) * vz)
        squared = one - x * x
        projection = math.sqrt(select(squared > zero, squared, zero))  # |n| = 1 to rounding: never below 0 by more
        tx = tx + projection * load_lanes(block, table + FACET_ARM_X * count + k)
        ty = ty + projection * load_lanes(block, table + FACET_ARM_Y * count + k)
        tz = tz + projection * load_lanes(block, table + FACET_ARM_Z * count + k)
    sx, sy, sz, _, _, _ = lane_sums6(tx, ty, tz, zero, zero, zero)
    return sx, sy, sz


@jit
def orbit_mean_scale(block, base, semi_major_axis, root_one_minus_e2):
    """−P(d₀) (d₀/a)² / (π √(1 − e²)): the factor of :func:`orbit_mean_facet_sum_xyz` for the mean torque."""
    ratio = block[base + TH_DISTANCE] / semi_major_axis
    return -block[base + TH_PRESSURE] * ratio * ratio / (math.pi * root_one_minus_e2)


@jit
def orbit_normal(model, row):
    """(unit orbit normal (3,), a, √(1 − e²)) of the Kepler perturber row at ``row`` of a model array.

    The normal is P × Q of the row's perifocal vectors; their common sign (body relative to the Sun or
    the Sun relative to the body) cancels, and the average of √(1 − (n·w)²) does not see w's sign.
    """
    p = model[row + 2 + K_P:row + 2 + K_P + 3]
    q = model[row + 2 + K_Q:row + 2 + K_Q + 3]
    w = np.array([p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0]])
    w /= math.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
    return w, model[row + 2 + K_A], model[row + 2 + K_ROOT]


@jit
def _spin_mean(block, base, basis, obliquity, n_phase):
    # Spin frame: z along the spin axis, W = (0, sin ε, cos ε). basis rows: the spin frame's axes in the body
    # frame. At phase φ the body is turned by R_z(φ), so the orbit normal in the body is basisᵀ R_z(φ)ᵀ W.
    sw, cw = math.sin(obliquity), math.cos(obliquity)
    out = np.zeros(3)
    for j in range(n_phase):
        phi = 2.0 * math.pi * j / n_phase
        c, s = math.cos(phi), math.sin(phi)
        rx, ry, rz = s * sw, c * sw, cw  # R_z(φ)ᵀ (0, sin ε, cos ε)
        wx = basis[0, 0] * rx + basis[1, 0] * ry + basis[2, 0] * rz
        wy = basis[0, 1] * rx + basis[1, 1] * ry + basis[2, 1] * rz
        wz = basis[0, 2] * rx + basis[1, 2] * ry + basis[2, 2] * rz
        tx, ty, tz = orbit_mean_facet_sum_xyz(wx, wy, wz, block, base)
        ux = basis[0, 0] * tx + basis[0, 1] * ty + basis[0, 2] * tz  # body → co-rotating spin frame
        uy = basis[1, 0] * tx + basis[1, 1] * ty + basis[1, 2] * tz
        uz = basis[2, 0] * tx + basis[2, 1] * ty + basis[2, 2] * tz
        out[0] += c * ux - s * uy  # → inertial spin frame, R_z(φ)
        out[1] += s * ux + c * uy
        out[2] += uz
    return out / n_phase


def spin_mean_torque(block, spin_axis, obliquity, semi_major_axis, eccentricity=0.0, n_phase=MEAN_SPIN_PHASES,
                     base=0):
    """Mean recoil torque on a principal-axis rotator: the orbit average exact, the rotation phase by trapezoids.

    Parameters
    ----------
    block : ndarray
        An unshadowed thermal block with its facet table (:func:`spinorbit.core.model.thermal.pack_thermal`).
    spin_axis : array_like (3,)
        The rotation axis in the body frame (a principal axis for a rotation that lasts).
    obliquity : float
        Angle between the spin axis and the orbit normal (rad).
    semi_major_axis : float
        a, in the block's distance unit.
    eccentricity : float
        e, 0 ≤ e < 1.
    n_phase : int
        Rotation phases of the trapezoidal rule (:data:`MEAN_SPIN_PHASES`).

    Returns
    -------
    ndarray (3,)
        The mean torque in the spin frame (block's torque unit): z along the spin axis (changes the spin
        rate), y in the plane of the spin axis and the orbit normal W = (0, sin ε, cos ε) (changes the
        obliquity), x = y × z (precesses the axis about W).
    """
    check_exact_average(block, base)
    if not (0.0 <= eccentricity < 1.0 and semi_major_axis > 0.0):
        raise ValueError(f"orbit: expected a > 0 and 0 ≤ e < 1; got a = {semi_major_axis!r}, e = {eccentricity!r}.")
    if not (isinstance(n_phase, (int, np.integer)) and n_phase >= 1):
        raise ValueError(f"n_phase: expected a positive number of rotation phases; got {n_phase!r}.")
    z = np.asarray(spin_axis, dtype=float)
    if z.shape != (3,) or not np.all(np.isfinite(z)) or not np.linalg.norm(z) > 0.0:
        raise ValueError(f"spin_axis: expected a non-zero finite body-frame 3-vector; got {spin_axis!r}.")
    z = z / np.linalg.norm(z)
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    basis = np.array([x, np.cross(z, x), z])
    scale = orbit_mean_scale(block, base, float(semi_major_axis), math.sqrt((1.0 - eccentricity) * (1.0 + eccentricity)))
    return scale * _spin_mean(np.ascontiguousarray(block, dtype=float), int(base), basis, float(obliquity), int(n_phase))
