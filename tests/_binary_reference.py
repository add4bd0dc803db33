"""Independent references for the binary tests: the exact exterior potential of a homogeneous
ellipsoid, and the mutual potential of two ellipsoids by Gauss quadrature over the second one.

Nothing here uses the inertia-integral expansion. The ellipsoid's exterior potential is the classical
closed form (Chandrasekhar 1969, *Ellipsoidal Figures of Equilibrium*, §3, eq. 3.39; MacMillan 1930)

    U(x)/G = (3m/4) ∫_λ^∞ (1 − Σ x_i²/(a_i² + u)) du / √((a² + u)(b² + u)(c² + u))
           = (3m/2) [R_F(a²+λ, b²+λ, c²+λ) − ⅓ Σ_i x_i² R_D(a_j²+λ, a_k²+λ, a_i²+λ)]

with λ the largest root of Σ x_i²/(a_i² + λ) = 1 and Carlson's R_F, R_D (scipy.special.elliprf,
elliprd; the two integrals are 2 R_F and (2/3) R_D, DLMF 19.16.1–2). The mutual potential is the
integral of that over the second body, with Gauss–Legendre nodes in r (weight r²) and cos θ and
equal steps in φ (exact for trigonometric polynomials), on the ellipsoid's polar map.
"""

from __future__ import annotations

import numpy as np
from scipy.special import elliprd, elliprf


def confocal_lambda(points, semi_axes):
    """λ(x) of each exterior point (rows of ``points``): the largest root of f(λ) = Σ x_i²/(a_i² + λ) − 1.

    f is convex and decreasing for λ > −min a_i², so Newton's method from λ = 0 (where f > 0 outside
    the body) approaches the root monotonically from below; it stops when λ no longer increases.
    """
    x2 = np.asarray(points, dtype=float) ** 2
    a2 = np.asarray(semi_axes, dtype=float) ** 2
    if np.any(np.sum(x2 / a2, axis=1) <= 1.0):
        raise ValueError("a quadrature point is not outside the ellipsoid: the exterior formula does not hold")
    lam = np.zeros(len(x2))
    for _ in range(200):
        d = a2[None, :] + lam[:, None]
        f = np.sum(x2 / d, axis=1) - 1.0
        slope = -np.sum(x2 / d ** 2, axis=1)
        new = np.maximum(lam - f / slope, lam)
        if np.all(new == lam):
            break
        lam = new
    return lam


def ellipsoid_exterior_force_function(points, mass, semi_axes, g=1.0):
    """G ∫ dm/|x − ρ| of a homogeneous ellipsoid at exterior points (N, 3) on its principal axes."""
    points = np.atleast_2d(np.asarray(points, dtype=float))
    a2 = np.asarray(semi_axes, dtype=float) ** 2
    lam = confocal_lambda(points, semi_axes)
    s = a2[None, :] + lam[:, None]
    rf = elliprf(s[:, 0], s[:, 1], s[:, 2])
    rd = (points[:, 0] ** 2 * elliprd(s[:, 1], s[:, 2], s[:, 0])
          + points[:, 1] ** 2 * elliprd(s[:, 0], s[:, 2], s[:, 1])
          + points[:, 2] ** 2 * elliprd(s[:, 0], s[:, 1], s[:, 2]))
    return 1.5 * g * mass * (rf - rd / 3.0)


def ellipsoid_quadrature(mass, semi_axes, n_radial=12, n_polar=16, n_azimuth=32):
    """Nodes (N, 3) on the principal axes and mass weights (N,) integrating exactly over a homogeneous
    ellipsoid every polynomial of degree < min(2 n_radial − 2, 2 n_polar, n_azimuth)."""
    r, wr = np.polynomial.legendre.leggauss(n_radial)
    r = 0.5 * (r + 1.0)
    wr = 0.5 * wr * r * r
    mu, wmu = np.polynomial.legendre.leggauss(n_polar)
    phi = 2.0 * np.pi * np.arange(n_azimuth) / n_azimuth
    wphi = np.full(n_azimuth, 2.0 * np.pi / n_azimuth)
    rr, mm, pp = np.meshgrid(r, mu, phi, indexing="ij")
    ww = wr[:, None, None] * wmu[None, :, None] * wphi[None, None, :]
    sin_t = np.sqrt(1.0 - mm * mm)
    unit = np.stack([rr * sin_t * np.cos(pp), rr * sin_t * np.sin(pp), rr * mm], axis=-1).reshape(-1, 3)
    weights = ww.ravel() / (4.0 * np.pi / 3.0) * mass
    return unit * np.asarray(semi_axes, dtype=float), weights


def mutual_force_function(separation_a, rotation_b_to_a, mass_a, axes_a, mass_b, axes_b, g=1.0, **nodes):
    """G ∫∫ dm_A dm_B / |R + C ρ_B − ρ_A| of two homogeneous ellipsoids by quadrature over B of A's exact field.

    ``separation_a`` is R on A's axes, ``rotation_b_to_a`` the matrix C (v_A = C v_B).
    """
    points, weights = ellipsoid_quadrature(mass_b, axes_b, **nodes)
    field_points = np.asarray(separation_a, dtype=float)[None, :] + points @ np.asarray(rotation_b_to_a).T
    return float(np.sum(weights * ellipsoid_exterior_force_function(field_points, mass_a, axes_a, g)))
