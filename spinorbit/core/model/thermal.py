"""Sunlight's recoil on a shape: Rubincam's zero-conductivity Lambertian force and torque (YORP, Yarkovsky).

Model (Rubincam 2000, Icarus 148, 2, "Radiative spin-up and spin-down of small asteroids"): each facet
k (outward unit normal n_k, area A_k, centroid r_k from the centre of mass) re-emits at once, as a
Lambertian emitter, the sunlight it absorbs, and scatters the rest as a Lambertian reflector; both
recoils push along −n_k with 2/3 of the intercepted momentum flux. With ŝ the unit vector from the
body to the Sun in the body frame, d the heliocentric distance and P(d) = (2/3)(Φ₀/c)(d₀/d)² the
recoil pressure (Φ₀ the solar flux at d₀)::

    F(ŝ, d) = −P(d) Σ_k A_k max(0, n_k·ŝ) n_k
    T(ŝ, d) = −P(d) Σ_k A_k max(0, n_k·ŝ) (r_k × n_k)

Without self-shadowing the sum is exact for convex shapes. With it (:mod:`spinorbit.core.model.shadowing`)
each facet counts only its lit share; the incident momentum's own torque is left out, as in
the YORP literature (it has no mean effect on a convex body, Rubincam 2000 §2). Zero conductivity
makes the emission instantaneous, so the force has no diurnal lag: its Yarkovsky drift of the
semi-major axis vanishes and finite conductivity (the linear theory) is needed for da/dt.

**Compact representation.** The clamped cosine has the Funk–Hecke expansion
max(0, n·ŝ) = Σ_l λ_l Σ_m Y_lm(n) Y_lm(ŝ), λ_l = 2π ∫₀¹ t P_l(t) dt, which is zero for odd l ≥ 3.
So T(ŝ) = −P Σ_lm g_lm Y_lm(ŝ) with g_lm = λ_l Σ_k A_k Y_lm(n_k) (r_k × n_k), and likewise F; the
coefficients are exact sums over the facets, no quadrature. Y_lm are the orthonormal real spherical
harmonics (∫ Y² dΩ = 1) in the geodesy convention of :mod:`spinorbit.core.model.gravity_field`
(latitude from the body's x–y plane, no Condon–Shortley phase). Truncated at degree L, the error of
the instantaneous torque falls as L^(−3/2) or faster (the kink of the clamped cosine); the spin- and
orbit-averaged torques, which YORP's evolution needs, are carried almost entirely by l ≤ 4.

**The thermal block** (float64, at absolute offset ``base`` of an array, usually the model array)::

    block[base + TH_DEGREE]       L
    block[base + TH_SUN_ROW]      absolute index of the Sun's perturber row in the model (−1: none)
    block[base + TH_PRESSURE]     P(d₀) in the caller's force / length² unit
    block[base + TH_DISTANCE]     d₀, the distance of P(d₀), in the model's length unit
    block[base + TH_ALL_DEGREES]  1 when odd degrees ≥ 3 carry terms (a shadowed fit), 0 when they are zero
    block[base + TH_FACETS]       m, the number of facets in the facet table at the block's end
    block[base + TH_DIRECT]       1: the torque and force are the facet sum itself, 0: the harmonics
    block[base + TH_RECURRENCE …]      the Legendre recurrence coefficients (2l − 1)/(l − m), then (l + m − 1)/(l − m),
                                  (L + 1)² values each
    then, per harmonic, N_lm g_lm for the torque (3 values) and for the force (3 values), with
    N_lm the normalisation of Y_lm = N_lm P_lm(sin φ) (cos, sin) mλ
    then the facet table (:func:`facet_table_offset`): FACET_WIDTH rows n_x, n_y, n_z, A, and A (r × n)
    x, y, z, each of TH_FACETS values (the facet count rounded up to a multiple of eight with zero facets,
    so that the sums run eight facets to a register, :mod:`spinorbit.core.math.lanes`)

The facet table is the surface the coefficients were made from. It is what the exact averages of
:mod:`spinorbit.core.averaging.recoil_orbit_mean` sum, and, with ``TH_DIRECT``, what every evaluation
sums instead of the harmonics: exact for a convex shape at every Sun direction, at the cost of one pass
over the facets (docs/thermal.md times both).

Harmonics are indexed l² (order 0), l² + 2m − 1 (cos mλ) and l² + 2m (sin mλ), m = 1..l.

**With self-shadowing** Funk–Hecke no longer applies: a facet's lit share depends on the whole
surface. The coefficients are then the projections g_lm = ∫ T(ŝ) Y_lm(ŝ) dΩ of the shadowed facet
sum, by a product rule over the Sun's directions (Gauss–Legendre in sin φ, equal steps in λ), and
odd degrees no longer vanish. The shadows are baked in at this precompute; an evaluation's cost is
that of a block of the same degree with all degrees present. A shadow's edge makes T(ŝ) kinked
(its derivative jumps where a facet's lit share starts to fall), so the truncation error falls as a
power of L, not geometrically (docs/thermal.md measures it).
"""

import math

import numpy as np
from numpy.polynomial import legendre

from spinorbit.core.jit import jit
from spinorbit.core.math.lanes import WIDTH, broadcast, lane_of, load_lanes, select
from spinorbit.core.model.polyhedron import regular_solid_harmonics
from spinorbit.core.model.shadowing import shadowed_recoil_sums

__all__ = [
    "TH_DEGREE", "TH_SUN_ROW", "TH_PRESSURE", "TH_DISTANCE", "TH_ALL_DEGREES", "TH_RECURRENCE", "MAX_THERMAL_DEGREE",
    "clamped_cosine_coefficient", "harmonic_count", "real_harmonics", "pack_thermal", "thermal_block_size",
    "facet_force_torque", "thermal_force_torque_xyz", "facet_sum_xyz", "recoil_pressure", "sun_direction_grid",
    "default_shadow_grid", "TH_FACETS", "TH_DIRECT", "FACET_WIDTH", "facet_table_offset",
    "padded_facet_count", "lane_sums6", "FACET_NX", "FACET_NY", "FACET_NZ", "FACET_AREA", "FACET_ARM_X", "FACET_ARM_Y",
    "FACET_ARM_Z",
]

TH_DEGREE, TH_SUN_ROW, TH_PRESSURE, TH_DISTANCE, TH_ALL_DEGREES, TH_FACETS, TH_DIRECT = range(7)
TH_RECURRENCE = 7
#: Values per facet in the block's facet table: n (3), A, A (r × n) (3), one row of each.
FACET_WIDTH = 7
FACET_NX, FACET_NY, FACET_NZ, FACET_AREA, FACET_ARM_X, FACET_ARM_Y, FACET_ARM_Z = range(FACET_WIDTH)
#: Highest degree of the representation: P_LL grows like (2L − 1)!!, far from overflow at 40.
MAX_THERMAL_DEGREE = 40
#: Speed of light (m/s, exact, SI) and the nominal total solar irradiance at 1 au (W/m², IAU 2015
#: Resolution B3, Prša et al. 2016, AJ 152, 41).
SPEED_OF_LIGHT = 299792458.0
SOLAR_IRRADIANCE_1AU = 1361.0


def recoil_pressure(efficiency=1.0):
    """P(1 au) = (2/3) η Φ₀ / c in N/m² (Pa): the Lambertian recoil pressure of a facet facing the Sun.

    η = 1 when all the light is re-emitted or scattered as by a Lambertian surface; η = 1 − A with
    a Bond albedo A whose reflected part is not Lambertian.
    """
    return 2.0 / 3.0 * efficiency * SOLAR_IRRADIANCE_1AU / SPEED_OF_LIGHT


def clamped_cosine_coefficient(degree):
    """λ_l = 2π ∫₀¹ t P_l(t) dt, the Funk–Hecke eigenvalue of max(0, cos γ) (π, 2π/3, π/4, 0, −π/24, …)."""
    poly = legendre.Legendre.basis(degree) * legendre.Legendre([0.0, 1.0])
    antiderivative = poly.integ()
    if degree >= 3 and degree % 2:
        return 0.0  # t P_l(t) is even and integrates to zero over (−1, 1): exactly, not to rounding
    return 2.0 * math.pi * float(antiderivative(1.0) - antiderivative(0.0))


def harmonic_count(degree_max):
    """(L + 1)²: the number of real harmonics up to degree L."""
    return (degree_max + 1) ** 2


def padded_facet_count(facets):
    """Facets rounded up to whole registers of :data:`spinorbit.core.math.lanes.WIDTH` (the table's row length)."""
    return -(-int(facets) // WIDTH) * WIDTH


def thermal_block_size(degree_max, facets=0):
    """Floats in a thermal block of degree L with ``facets`` facets: header, recurrences, six coefficients
    per harmonic, the facet table."""
    return TH_RECURRENCE + 8 * harmonic_count(degree_max) + FACET_WIDTH * padded_facet_count(facets)


@jit(inline="always")
def facet_table_offset(block, base):
    """Index of the facet table's first value in ``block`` (its layout in the module docstring)."""
    degree_max = int(block[base + TH_DEGREE])
    return base + TH_RECURRENCE + 8 * (degree_max + 1) * (degree_max + 1)


def default_shadow_grid(degree_max):
    """Latitudes of the default Sun-direction grid of a shadowed fit of degree L: 2(L + 1), at least 8.

    The product rule then integrates degree ≤ 4L + 3 exactly, more than the L + L a degree-L fit of a
    degree-L field needs; the kinked shadowed torque's higher harmonics alias into the fit, but
    doubling the grid again changed the fit's error by less than a tenth of the truncation error
    (docs/thermal.md measures both).
    """
    return max(8, 2 * (int(degree_max) + 1))


def sun_direction_grid(latitudes):
    """Product rule on the sphere: Gauss–Legendre in sin φ (``latitudes`` nodes) × 2·latitudes equal steps in λ.

    Returns
    -------
    directions : ndarray (2 n², 3)
        Unit vectors.
    weights : ndarray (2 n²,)
        Quadrature weights summing to 4π; exact for spherical harmonics of degree ≤ 2n − 1 (Gauss–Legendre
        integrates polynomials of degree 2n − 1 in sin φ, and 2n equal steps integrate cos mλ, sin mλ
        exactly for m < 2n).
    """
    if not (isinstance(latitudes, (int, np.integer)) and latitudes >= 2):
        raise ValueError(f"shadow_grid: expected an integer ≥ 2 (Gauss–Legendre latitudes); got {latitudes!r}.")
    z, w = legendre.leggauss(int(latitudes))
    longitudes = 2.0 * math.pi * np.arange(2 * latitudes) / (2 * latitudes)
    rho = np.sqrt(1.0 - z * z)
    directions = np.stack([np.outer(rho, np.cos(longitudes)), np.outer(rho, np.sin(longitudes)),
                           np.outer(z, np.ones_like(longitudes))], axis=-1).reshape(-1, 3)
    weights = np.outer(w, np.full(longitudes.size, 2.0 * math.pi / longitudes.size)).ravel()
    return directions, weights


def _norms(degree_max):
    out = np.empty(harmonic_count(degree_max))
    for n in range(degree_max + 1):
        for m in range(n + 1):
            value = math.sqrt((2.0 - (m == 0)) * (2 * n + 1) / (4.0 * math.pi)
                              * math.factorial(n - m) / math.factorial(n + m))
            if m == 0:
                out[n * n] = value
            else:
                out[n * n + 2 * m - 1] = out[n * n + 2 * m] = value
    return out


def real_harmonics(directions, degree_max):
    """Orthonormal real harmonics Y_lm at unit ``directions`` (k, 3): an array (k, (L + 1)²)."""
    cos_part, sin_part = regular_solid_harmonics(np.asarray(directions, dtype=float), degree_max)
    norms = _norms(degree_max)
    out = np.empty((np.asarray(directions).shape[0], harmonic_count(degree_max)))
    for n in range(degree_max + 1):
        out[:, n * n] = cos_part[n, 0]
        for m in range(1, n + 1):
            out[:, n * n + 2 * m - 1] = cos_part[n, m]
            out[:, n * n + 2 * m] = sin_part[n, m]
    return out * norms


def pack_thermal(normals, areas, centroids, degree_max, pressure, distance, sun_row=-1, *, shadowing=None,
                 shadow_grid=None, direct=False):
    """The thermal block of a shape: the compact representation of F(ŝ) and T(ŝ).

    Parameters
    ----------
    normals, areas, centroids : ndarray (m, 3), (m,), (m, 3)
        Facets (:func:`spinorbit.core.model.polyhedron.face_geometry`), centroids from the centre of
        mass on the principal axes (length L).
    degree_max : int
        L, 0..MAX_THERMAL_DEGREE.
    pressure : float
        P(d₀), the recoil pressure at ``distance`` (force / L², with the areas' L).
    distance : float
        d₀ (the model's length unit).
    sun_row : int
        Absolute index of the Sun's perturber row in the model array (set by ``make_model``).
    shadowing : ShadowGeometry, optional
        The same surface (:func:`spinorbit.core.model.shadowing.shadow_geometry`, vertices from the
        centre of mass on the principal axes, length L): fit the shadowed sums over the Sun's
        directions. A convex surface is never shadowed, and its block is the unshadowed one, bit
        for bit.
    shadow_grid : int, optional
        Latitudes of the fit's direction grid (:func:`sun_direction_grid`); default
        :func:`default_shadow_grid`.
    direct : bool
        Evaluate the facet sum itself instead of the harmonics (``TH_DIRECT``). Not with shadows:
        the shadows exist only as the fit.

    Returns
    -------
    ndarray
        The block (module docstring); torque = −P Σ g Y in force·L, force in force.
    """
    if not (isinstance(degree_max, (int, np.integer)) and 0 <= degree_max <= MAX_THERMAL_DEGREE):
        raise ValueError(f"degree_max: expected an integer 0..{MAX_THERMAL_DEGREE}; got {degree_max!r}.")
    if not (pressure > 0 and distance > 0 and math.isfinite(pressure) and math.isfinite(distance)):
        raise ValueError(f"pressure and distance: expected positive finite numbers; got {pressure!r}, {distance!r}.")
    count = harmonic_count(degree_max)
    shadowed = shadowing is not None and not shadowing.convex
    if direct and shadowed:
        raise ValueError("direct: the facet sum without shadows cannot stand for a shadowed surface (its shadows "
                         "exist only as the fit); give direct=False, or self_shadowing=False for the facet sum.")
    if shadowed:
        if shadowing.faces.shape[0] != np.asarray(areas).shape[0]:
            raise ValueError(f"shadowing: expected the geometry of the same {np.asarray(areas).shape[0]} facets; got "
                             f"{shadowing.faces.shape[0]}. Build it from the vertices the facets came from.")
        directions, weights = sun_direction_grid(default_shadow_grid(degree_max) if shadow_grid is None
                                                 else shadow_grid)
        force, torque = shadowed_recoil_sums(shadowing, directions)
        projector = real_harmonics(directions, degree_max) * weights[:, None]  # (k, count): ∫ · Y_lm dΩ
        coefficients = np.concatenate([projector.T @ torque, projector.T @ force], axis=1)
        all_degrees = 1.0
    else:
        lam = np.empty(count)
        for n in range(degree_max + 1):
            lam[n * n:(n + 1) ** 2] = 0.0 if n >= 3 and n % 2 else clamped_cosine_coefficient(n)
        weights = real_harmonics(normals, degree_max) * areas[:, None] * lam  # (m, count)
        coefficients = np.concatenate([weights.T @ np.cross(centroids, normals), weights.T @ normals], axis=1)
        all_degrees = 0.0
    coefficients *= _norms(degree_max)[:, None]  # the kernel sums unnormalised harmonics
    rec_a, rec_b = np.zeros(count), np.zeros(count)
    for n in range(1, degree_max + 1):
        for m in range(n):
            k = n * n + 2 * m - 1 if m > 0 else n * n
            rec_a[k] = (2.0 * n - 1.0) / (n - m)
            rec_b[k] = (n + m - 1.0) / (n - m)
    padded = padded_facet_count(np.asarray(areas).shape[0])
    header = np.array([float(degree_max), float(sun_row), float(pressure), float(distance), all_degrees,
                       float(padded), 1.0 if direct else 0.0])
    facets = np.zeros((FACET_WIDTH, padded))  # zero facets pad the rows: no area, no arm, never lit
    facets[:, :areas.shape[0]] = np.column_stack([normals, areas, areas[:, None] * np.cross(centroids, normals)]).T
    return np.concatenate([header, rec_a, rec_b, coefficients.ravel(), facets.ravel()])


def facet_force_torque(normals, areas, centroids, sun_direction):
    """F/P and T/P by the direct facet sum (geometry only: multiply by −P(d) for the force and torque).

    Returns
    -------
    force, torque : ndarray (3,)
        Σ A max(0, n·ŝ) n (L²) and Σ A max(0, n·ŝ)(r × n) (L³).
    """
    s = np.asarray(sun_direction, dtype=float)
    lit = np.maximum(normals @ (s / np.linalg.norm(s)), 0.0) * areas
    return lit @ normals, lit @ np.cross(centroids, normals)


@jit
def thermal_force_torque_xyz(sx, sy, sz, distance, block, base):
    """(Fx, Fy, Fz, Tx, Ty, Tz): the recoil force and torque for the Sun at body-frame direction (sx, sy, sz).

    (sx, sy, sz) need not be unit; ``distance`` is the heliocentric distance in the block's d₀ unit.
    Allocation-free: the unnormalised harmonics are generated order by order with the Legendre
    recurrences (their coefficients precomputed in the block, the normalisation folded into the
    torque and force coefficients) and summed on the fly; odd degrees ≥ 3 carry no term (λ_l = 0)
    unless the block is a shadowed fit (``TH_ALL_DEGREES``).
    """
    degree_max = int(block[base + TH_DEGREE])
    odd_degrees = block[base + TH_ALL_DEGREES] != 0.0
    count = (degree_max + 1) * (degree_max + 1)
    rec_a = base + TH_RECURRENCE
    rec_b = rec_a + count
    coef = rec_b + count
    inv = 1.0 / math.sqrt(sx * sx + sy * sy + sz * sz)
    x, y, z = sx * inv, sy * inv, sz * inv
    ratio = block[base + TH_DISTANCE] / distance
    scale = -block[base + TH_PRESSURE] * ratio * ratio
    if block[base + TH_DIRECT] != 0.0:
        fx, fy, fz, tx, ty, tz = facet_sum_xyz(x, y, z, block, base)
        return scale * fx, scale * fy, scale * fz, scale * tx, scale * ty, scale * tz
    fx = fy = fz = tx = ty = tz = 0.0
    mm_re, mm_im = 1.0, 0.0  # P_mm (cos φ)^m (cos, sin) mλ = (2m − 1)!! Re, Im (x + iy)^m
    for m in range(degree_max + 1):
        if m > 0:
            factor = 2.0 * m - 1.0
            mm_re, mm_im = factor * (x * mm_re - y * mm_im), factor * (x * mm_im + y * mm_re)
        prev_re, prev_im = 0.0, 0.0
        cur_re, cur_im = mm_re, mm_im
        for n in range(m, degree_max + 1):
            k = n * n + 2 * m - 1 if m > 0 else n * n
            if n > m:
                a, b = block[rec_a + k] * z, block[rec_b + k]
                prev_re, prev_im, cur_re, cur_im = cur_re, cur_im, a * cur_re - b * prev_re, a * cur_im - b * prev_im
            if n >= 3 and n % 2 == 1 and not odd_degrees:
                continue
            for part in range(2 if m > 0 else 1):  # cos mλ, then sin mλ (the next harmonic's row)
                value = cur_re if part == 0 else cur_im
                row = coef + 6 * (k + part)
                tx += block[row] * value
                ty += block[row + 1] * value
                tz += block[row + 2] * value
                fx += block[row + 3] * value
                fy += block[row + 4] * value
                fz += block[row + 5] * value
    return scale * fx, scale * fy, scale * fz, scale * tx, scale * ty, scale * tz


@jit
def facet_sum_xyz(x, y, z, block, base):
    """Σ A max(0, n·ŝ) n and Σ A max(0, n·ŝ)(r × n) over the block's facet table, ŝ = (x, y, z) a unit vector.

    The direct sum of the module docstring without −P(d): the exact recoil of a convex surface. Eight
    facets per register; each lane's arithmetic is the scalar IEEE operation, the eight partial sums
    are added at the end.
    """
    table = facet_table_offset(block, base)
    count = int(block[base + TH_FACETS])
    sx, sy, sz, zero = broadcast(x), broadcast(y), broadcast(z), broadcast(0.0)
    fx = fy = fz = tx = ty = tz = zero
    for k in range(0, count, WIDTH):
        nx = load_lanes(block, table + FACET_NX * count + k)
        ny = load_lanes(block, table + FACET_NY * count + k)
        nz = load_lanes(block, table + FACET_NZ * count + k)
        cosine = nx * sx + ny * sy + nz * sz
        cosine = select(cosine > zero, cosine, zero)
        lit = cosine * load_lanes(block, table + FACET_AREA * count + k)
        fx = fx + lit * nx
        fy = fy + lit * ny
        fz = fz + lit * nz
        tx = tx + cosine * load_lanes(block, table + FACET_ARM_X * count + k)
        ty = ty + cosine * load_lanes(block, table + FACET_ARM_Y * count + k)
        tz = tz + cosine * load_lanes(block, table + FACET_ARM_Z * count + k)
    return lane_sums6(fx, fy, fz, tx, ty, tz)


@jit(inline="always")
def lane_sums6(a, b, c, d, e, f):
    """The sums over the lanes of six Lanes values, lane 0 first."""
    sa = sb = sc = sd = se = sf = 0.0
    for i in range(WIDTH):
        va, vb, vc, vd, ve, vf = lane_of((a, b, c, d, e, f), i)
        sa += va
        sb += vb
        sc += vc
        sd += vd
        se += ve
        sf += vf
    return sa, sb, sc, sd, se, sf
