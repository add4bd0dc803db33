"""Closed forms of the disk-integrated brightness of ellipsoids and spheres (the facet sum's references).

An ellipsoid x²/a² + y²/b² + z²/c² = 1 is the unit sphere mapped by D = diag(a, b, c): the point
x = D y has the outward normal D⁻¹y / |D⁻¹y| and the area element dA = abc |D⁻¹y| dΩ_y. With
w = D⁻¹ô and v = D⁻¹ŝ (the body-frame observer and Sun directions; |w| = S, |v| = S☉ in Muinonen &
Lumme's notation), μ = w·y/|D⁻¹y| and μ₀ = v·y/|D⁻¹y|, and the region where both are positive is
a lune of the y sphere between the great circles w·y = 0 and v·y = 0.

**Lommel–Seeliger ellipsoid, any geometry** (Muinonen & Lumme 2015, A&A 584, A23): in
μ μ₀/(μ + μ₀) dA the factor |D⁻¹y| cancels, leaving abc (w·y)(v·y)/((w + v)·y) dΩ. In photometric
coordinates on the y sphere (latitude β from the plane of w and v, longitude λ from w) the β
integral gives π/2, and with w + v = S_α (cos, sin) at the angle λ′ from w::

    L_LS = (π/2) abc (S S☉ / S_α) J,    S_α = |w + v| = √(S² + S☉² + 2 S S☉ cos α′),
    J = (cos λ′ + cos γ) cos(λ′ − γ) + (sin γ − sin λ′) sin(γ − λ′)
        − sin λ′ sin γ ln[cot(λ′/2) cot(γ/2)],

where α′ is the angle between w and v, tan λ′ = S☉ sin α′ / (S + S☉ cos α′) and γ = α′ − λ′. For a
sphere (λ′ = γ = α/2) this is the Lommel–Seeliger phase integral π/2 [1 − sin(α/2) tan(α/2) ln cot(α/4)]
per unit radius squared.

**Lambertian ellipsoid at opposition** (ŝ = ô): μ² dA = abc (w·y)²/|D⁻¹y| dΩ is even in y, so its
integral over the visible hemisphere is half that over the sphere. Carlson's R_F is the sphere mean
of Q^(−1/2), Q = Σ x_i y_i² (DLMF §19.23), and R_G that of Q^(1/2); the mean of y_i² Q^(−1/2) is
2 ∂R_G/∂x_i = [R_F − x_i R_D(x_j, x_k, x_i)/3]/2 (the three sum to R_F, as Σ y_i² = 1). These
give, with x_i = 1/a_i²::

    L_L(opposition) = π abc Σ_i (ô_i/a_i)² [R_F(x₁, x₂, x₃) − x_i R_D(x_j, x_k, x_i)/3].

For the unit sphere this is 2π/3, the Lambert phase integral (2/3)[sin α + (π − α) cos α] at α = 0.

Both closed forms are checked against 2-D quadratures of the surface integral in mpmath
(``tests/test_photometry_brightness.py``).
"""

import math

import numpy as np

from spinorbit.core.jit import jit
from spinorbit.core.math.carlson import rd, rf

__all__ = ["lommel_seeliger_ellipsoid", "lambert_ellipsoid_at_opposition", "lommel_seeliger_sphere",
           "lambert_sphere"]


@jit
def _lommel_seeliger_one(a, b, c, sx, sy, sz, ox, oy, oz):
    wx, wy, wz = ox / a, oy / b, oz / c
    vx, vy, vz = sx / a, sy / b, sz / c
    big_s = math.sqrt(wx * wx + wy * wy + wz * wz)
    big_s_sun = math.sqrt(vx * vx + vy * vy + vz * vz)
    # α′ from atan2 of |w × v| and w·v: accurate at 0 and π, where an arccos loses half the digits.
    cx, cy, cz = wy * vz - wz * vy, wz * vx - wx * vz, wx * vy - wy * vx
    alpha = math.atan2(math.sqrt(cx * cx + cy * cy + cz * cz), wx * vx + wy * vy + wz * vz)
    lam = math.atan2(big_s_sun * math.sin(alpha), big_s + big_s_sun * math.cos(alpha))
    if alpha >= math.pi:
        return 0.0  # w and v opposite: the lune is empty
    gam = max(alpha - lam, 0.0)  # 0 ≤ λ′ ≤ α′; rounding must not make γ negative
    s_alpha = math.hypot(big_s + big_s_sun * math.cos(alpha), big_s_sun * math.sin(alpha))
    j = (math.cos(lam) + math.cos(gam)) * math.cos(lam - gam) + (math.sin(gam) - math.sin(lam)) * math.sin(gam - lam)
    if lam > 0.0 and gam > 0.0:  # sin λ′ ln cot(λ′/2) → 0 as λ′ → 0, and so for γ
        j -= math.sin(lam) * math.sin(gam) * math.log(1.0 / (math.tan(0.5 * lam) * math.tan(0.5 * gam)))
    return 0.5 * math.pi * a * b * c * big_s * big_s_sun / s_alpha * j


@jit
def _lommel_seeliger_into(a, b, c, sun, observer, out):
    for i in range(out.shape[0]):
        out[i] = _lommel_seeliger_one(a, b, c, sun[i, 0], sun[i, 1], sun[i, 2], observer[i, 0], observer[i, 1],
                                      observer[i, 2])


def lommel_seeliger_ellipsoid(semi_axes, sun_directions, observer_directions):
    """∫ μ μ₀/(μ + μ₀) dA over the lit, visible part of an ellipsoid (module docstring; exact).

    Parameters
    ----------
    semi_axes : array_like (3,)
        a, b, c along the body axes x, y, z (any length unit; L has its square).
    sun_directions, observer_directions : ndarray (n, 3)
        Body-frame unit vectors to the Sun and to the observer.

    Returns
    -------
    ndarray (n,)
    """
    a, b, c = (float(x) for x in semi_axes)
    sun = np.ascontiguousarray(sun_directions, dtype=float)
    observer = np.ascontiguousarray(observer_directions, dtype=float)
    out = np.empty(sun.shape[0])
    _lommel_seeliger_into(a, b, c, sun, observer, out)
    return out


@jit
def _lambert_opposition_into(a, b, c, observer, out):
    x1, x2, x3 = 1.0 / (a * a), 1.0 / (b * b), 1.0 / (c * c)
    r_f = rf(x1, x2, x3)
    # The mean of y_i² Q^(-1/2) over the sphere, times two (module docstring).
    m1 = r_f - x1 * rd(x2, x3, x1) / 3.0
    m2 = r_f - x2 * rd(x3, x1, x2) / 3.0
    m3 = r_f - x3 * rd(x1, x2, x3) / 3.0
    for i in range(out.shape[0]):
        w1, w2, w3 = observer[i, 0] / a, observer[i, 1] / b, observer[i, 2] / c
        out[i] = math.pi * a * b * c * (w1 * w1 * m1 + w2 * w2 * m2 + w3 * w3 * m3)


def lambert_ellipsoid_at_opposition(semi_axes, observer_directions):
    """∫ μ² dA over the visible half of an ellipsoid seen from the Sun's direction (module docstring; exact).

    Parameters
    ----------
    semi_axes : array_like (3,)
        a, b, c (any length unit).
    observer_directions : ndarray (n, 3)
        Body-frame unit vectors to the observer, which is also the Sun's direction.

    Returns
    -------
    ndarray (n,)
    """
    a, b, c = (float(x) for x in semi_axes)
    observer = np.ascontiguousarray(observer_directions, dtype=float)
    out = np.empty(observer.shape[0])
    _lambert_opposition_into(a, b, c, observer, out)
    return out


def lommel_seeliger_sphere(phase_angle):
    """The Lommel–Seeliger sphere's brightness per unit radius²: (π/2)[1 − sin(α/2) tan(α/2) ln cot(α/4)].

    Parameters
    ----------
    phase_angle : array_like
        α in radians, 0 ≤ α ≤ π (0 at π, where nothing lit is seen).
    """
    alpha = np.asarray(phase_angle, dtype=float)
    half = 0.5 * alpha
    with np.errstate(divide="ignore", invalid="ignore"):
        log_term = np.where(alpha > 0.0, np.sin(half) * np.tan(half) * np.log(1.0 / np.tan(0.5 * half)), 0.0)
    return np.where(alpha < math.pi, 0.5 * math.pi * (1.0 - log_term), 0.0)


def lambert_sphere(phase_angle):
    """The Lambert sphere's brightness per unit radius²: (2/3)[sin α + (π − α) cos α] (α in radians, 0..π)."""
    alpha = np.asarray(phase_angle, dtype=float)
    return (2.0 / 3.0) * (np.sin(alpha) + (math.pi - alpha) * np.cos(alpha))
