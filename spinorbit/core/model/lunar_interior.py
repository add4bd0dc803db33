"""A deformable mantle around a fluid core: the DE4xx lunar rotation model's extra physics.

The JPL ephemerides since DE403 integrate the Moon as an elastic, dissipative mantle around a fluid
core (Williams, Boggs & Folkner 2008, JPL IOM 335-JW,DB,WF-20080314-001 for DE421; the same
equations are printed in Folkner et al. 2014, IPN PR 42-196, §III for DE430/431 and in Park et al.
2021, AJ 161, 105 for DE440). In the mantle (principal-axis) frame, with ω the mantle and ω_c the
core angular velocity::

    d(I_m ω)/dt + ω × I_m ω = N_figure + N_figure-figure + N_cmb                     (mantle)
    I_c ω̇_c + ω × I_c ω_c  = −N_cmb                                                  (core)
    N_cmb = k_v (ω_c − ω) + (C_c − A_c)(ẑ·ω_c)(ẑ × ω_c)                              (CMB)

- I_c = diag(A_c, A_c, C_c): the core's moments, C_c = (C_c/C_T)·C_T, A_c = C_c (1 − f_c) with f_c
  the core–mantle-boundary flattening; the CMB is fixed in the mantle, so I_c is constant there.
- I_m = I_T − I_c + ΔI(t): the mantle's tensor. I_T = diag(A_T, B_T, C_T) is the undistorted whole
  Moon (the published moments), and ΔI the tidal and rotational distortion, delayed by τ_M::

      ΔI = −k₂ M_E R⁵/r'⁵ (r' r'ᵀ − r'²/3 · 1) + k₂ R⁵/(3G) (ω' ω'ᵀ − ω'²/3 · 1 − diag(−n², −n², 2n²)/3)

  with r' the Earth's position in the mantle frame and ω' the mantle angular velocity, both at
  t − τ_M, and n the lunar mean motion (the rotational term is counted from the mean spin n ẑ, whose
  flattening is already in the published moments).
- N_figure: the point-mass torques of the perturbers on the whole Moon's figure I_T + ΔI (degree 2)
  and degrees 3–4 (:mod:`spinorbit.core.model.gravity_field`).
- N_figure-figure: the Earth's J₂ field acting on the lunar degree-2 figure,
  N_i = −ε_ijk (I H)_jk, H the Hessian of the Earth's J₂ force function at the Moon (derived in
  ``docs/coupling.md``; for a point mass this formula gives the MacCullagh torque (3μ/r⁵) r × I r).

This module holds the pieces that act on vectors already expressed on the mantle axes; the
assembly into the right-hand side is :func:`spinorbit.core.dynamics.equations.lunar_rhs_into`.

The parameters travel as one float64 block appended to the dynamics model array (the kernels find it
at ``len(model) − INTERIOR_SIZE``); :func:`make_interior_block` builds it. Units are the model's:
length, mass (= GM/G) and time of the figure, e.g. au, Msun, day with G = k².
"""

import math

import numpy as np

from spinorbit.core.jit import jit

# Layout of the interior block (float64), named offsets.
(IN_MARKER, IN_EARTH_ROW, IN_G, IN_K2, IN_TAU, IN_RADIUS, IN_MEAN_MOTION, IN_CORE_A, IN_CORE_C, IN_KV,
 IN_EARTH_J2R2, IN_POLE_X, IN_POLE_Y, IN_POLE_Z, IN_DISTORTION_ROWS, IN_SIZE_CHECK) = range(16)
INTERIOR_SIZE = 16
#: A value no other model array has at this place: marks a model that carries an interior block.
INTERIOR_MARKER = -271828.0
#: State of the mantle-and-core model: quaternion (4), mantle ω (3), core ω_c on the mantle axes (3).
INTERIOR_STATE_SIZE = 10
# Offsets of a symmetric 3×3 matrix (inertia, ΔI, a Hessian) stored as its 6 unique entries.
SYM_XX, SYM_YY, SYM_ZZ, SYM_XY, SYM_XZ, SYM_YZ = range(6)


def make_interior_block(earth_row, gravitational_constant, love_number, time_delay, radius, mean_motion,
                        core_polar_moment, core_flattening, friction, earth_j2=0.0, earth_radius=0.0,
                        earth_pole=(0.0, 0.0, 1.0), distortion_rows=1):
    """The interior parameter block (append it to a dynamics model array).

    Parameters
    ----------
    earth_row : int
        Absolute offset, in the model array, of the perturber row of the body raising the tide and
        carrying J₂ (the Earth).
    gravitational_constant : float
        G in the model's units (length³ mass⁻¹ time⁻²), to turn GM into M in ΔI.
    love_number, time_delay : float
        k₂ of the Moon and its tidal delay τ_M (time unit).
    radius : float
        R of the ΔI formula (the lunar reference radius, length).
    mean_motion : float
        n, the lunar mean motion (rad per time unit).
    core_polar_moment, core_flattening : float
        C_c (mass·length²) and f_c = (C_c − A_c)/C_c.
    friction : float
        k_v (mass·length²/time).
    earth_j2, earth_radius : float
        J₂ and reference radius of the Earth for the figure–figure torque (0: left out).
    earth_pole : array_like (3,)
        Unit vector of the Earth's figure axis, inertial frame.
    distortion_rows : int
        The first ``distortion_rows`` perturbers (from ``earth_row`` on) feel the distortion ΔI.
    """
    values = np.array([love_number, time_delay, radius, mean_motion, core_polar_moment, friction,
                       gravitational_constant], dtype=float)
    if not np.all(np.isfinite(values)) or np.any(values < 0) or values[-1] == 0:
        raise ValueError(f"interior parameters: expected finite, non-negative k2, tau, R, n, C_c, k_v and "
                         f"G > 0; got {values.tolist()}.")
    if not 0.0 <= core_flattening < 1.0:
        raise ValueError(f"core_flattening: expected 0 ≤ f_c < 1, got {core_flattening!r}.")
    pole = np.asarray(earth_pole, dtype=float)
    if pole.shape != (3,) or abs(np.linalg.norm(pole) - 1.0) > 1e-9:
        raise ValueError(f"earth_pole: expected a unit 3-vector, got {earth_pole!r}.")
    block = np.zeros(INTERIOR_SIZE)
    block[IN_MARKER] = INTERIOR_MARKER
    block[IN_EARTH_ROW] = earth_row
    block[IN_G] = gravitational_constant
    block[IN_K2] = love_number
    block[IN_TAU] = time_delay
    block[IN_RADIUS] = radius
    block[IN_MEAN_MOTION] = mean_motion
    block[IN_CORE_C] = core_polar_moment
    block[IN_CORE_A] = core_polar_moment * (1.0 - core_flattening)
    block[IN_KV] = friction
    block[IN_EARTH_J2R2] = earth_j2 * earth_radius**2
    block[IN_POLE_X:IN_POLE_Z + 1] = pole
    block[IN_DISTORTION_ROWS] = distortion_rows
    block[IN_SIZE_CHECK] = INTERIOR_SIZE
    return block


def has_interior(model):
    """True if ``model`` ends with an interior block."""
    return (model.size > INTERIOR_SIZE and model[-INTERIOR_SIZE + IN_MARKER] == INTERIOR_MARKER
            and model[-1] == INTERIOR_SIZE)


@jit(inline="always")
def rotate_about(wx, wy, wz, angle_per_rate, vx, vy, vz):
    """v rotated actively by the angle |w|·``angle_per_rate`` about w (Rodrigues).

    With w the body angular velocity and ``angle_per_rate`` = τ, this turns the body components of an
    inertially fixed vector at t into its components at t − τ (body components obey v̇ = −w × v).
    """
    rate = math.sqrt(wx * wx + wy * wy + wz * wz)
    if rate == 0.0:
        return vx, vy, vz
    ax, ay, az = wx / rate, wy / rate, wz / rate
    angle = rate * angle_per_rate
    c, s = math.cos(angle), math.sin(angle)
    dot = (ax * vx + ay * vy + az * vz) * (1.0 - c)
    return (vx * c + (ay * vz - az * vy) * s + ax * dot,
            vy * c + (az * vx - ax * vz) * s + ay * dot,
            vz * c + (ax * vy - ay * vx) * s + az * dot)


@jit
def distortion(block, rx, ry, rz, vx, vy, vz, mu_earth, wx, wy, wz, ax, ay, az, out, rate):
    """ΔI (6 unique entries xx, yy, zz, xy, xz, yz) and its time derivative.

    r, v: the Earth's delayed position and velocity on the delayed mantle axes (v the derivative of
    those body components); w, a: the delayed mantle angular velocity and its derivative. ``out`` and
    ``rate`` receive ΔI and dΔI/dt.
    """
    k2 = block[IN_K2]
    r5 = block[IN_RADIUS] ** 5
    rr = rx * rx + ry * ry + rz * rz
    tide = -k2 * (mu_earth / block[IN_G]) * r5 / (rr * rr * math.sqrt(rr))
    third = rr / 3.0
    rv = rx * vx + ry * vy + rz * vz
    # d/dt of tide·(r rᵀ − r²/3): the factor r⁻⁵ contributes −5 (r·v)/r² times the bracket.
    dtide = -5.0 * rv / rr
    spin = k2 * r5 / (3.0 * block[IN_G])
    n2 = block[IN_MEAN_MOTION] ** 2
    ww = wx * wx + wy * wy + wz * wz
    wa = wx * ax + wy * ay + wz * az
    bxx, byy, bzz = rx * rx - third, ry * ry - third, rz * rz - third
    bxy, bxz, byz = rx * ry, rx * rz, ry * rz
    out[SYM_XX] = tide * bxx + spin * (wx * wx - (ww - n2) / 3.0)
    out[SYM_YY] = tide * byy + spin * (wy * wy - (ww - n2) / 3.0)
    out[SYM_ZZ] = tide * bzz + spin * (wz * wz - (ww + 2.0 * n2) / 3.0)
    out[SYM_XY] = tide * bxy + spin * wx * wy
    out[SYM_XZ] = tide * bxz + spin * wx * wz
    out[SYM_YZ] = tide * byz + spin * wy * wz
    dthird = 2.0 * rv / 3.0
    rate[SYM_XX] = tide * (dtide * bxx + 2.0 * rx * vx - dthird) + spin * (2.0 * wx * ax - 2.0 * wa / 3.0)
    rate[SYM_YY] = tide * (dtide * byy + 2.0 * ry * vy - dthird) + spin * (2.0 * wy * ay - 2.0 * wa / 3.0)
    rate[SYM_ZZ] = tide * (dtide * bzz + 2.0 * rz * vz - dthird) + spin * (2.0 * wz * az - 2.0 * wa / 3.0)
    rate[SYM_XY] = tide * (dtide * bxy + rx * vy + vx * ry) + spin * (wx * ay + ax * wy)
    rate[SYM_XZ] = tide * (dtide * bxz + rx * vz + vx * rz) + spin * (wx * az + ax * wz)
    rate[SYM_YZ] = tide * (dtide * byz + ry * vz + vy * rz) + spin * (wy * az + ay * wz)


@jit(inline="always")
def symmetric_times(m, x, y, z):
    """M v for a symmetric M given as (xx, yy, zz, xy, xz, yz)."""
    mxx, myy, mzz, mxy, mxz, myz = m[SYM_XX], m[SYM_YY], m[SYM_ZZ], m[SYM_XY], m[SYM_XZ], m[SYM_YZ]
    return (mxx * x + mxy * y + mxz * z,
            mxy * x + myy * y + myz * z,
            mxz * x + myz * y + mzz * z)


@jit(inline="always")
def symmetric_solve(m, bx, by, bz):
    """M⁻¹ b for a symmetric positive-definite 3×3 M given as (xx, yy, zz, xy, xz, yz) (Cramer)."""
    mxx, myy, mzz, mxy, mxz, myz = m[SYM_XX], m[SYM_YY], m[SYM_ZZ], m[SYM_XY], m[SYM_XZ], m[SYM_YZ]
    c00 = myy * mzz - myz * myz
    c01 = mxz * myz - mxy * mzz
    c02 = mxy * myz - mxz * myy
    c11 = mxx * mzz - mxz * mxz
    c12 = mxy * mxz - mxx * myz
    c22 = mxx * myy - mxy * mxy
    inv_det = 1.0 / (mxx * c00 + mxy * c01 + mxz * c02)
    return ((c00 * bx + c01 * by + c02 * bz) * inv_det,
            (c01 * bx + c11 * by + c12 * bz) * inv_det,
            (c02 * bx + c12 * by + c22 * bz) * inv_det)


@jit(inline="always")
def point_mass_torque(m, mu, x, y, z):
    """(3μ/r⁵) r × (M r): the degree-2 torque of a point mass at r on a body of inertia M."""
    rr = x * x + y * y + z * z
    k = 3.0 * mu / (rr * rr * math.sqrt(rr))
    ix, iy, iz = symmetric_times(m, x, y, z)
    return k * (y * iz - z * iy), k * (z * ix - x * iz), k * (x * iy - y * ix)


@jit
def j2_hessian(block, mu_earth, sx, sy, sz, px, py, pz, h):
    """Hessian (xx, yy, zz, xy, xz, yz) of the Earth's J₂ force function at s (Earth → Moon).

    U = −μ J₂ R_E² (3 (s·p)² − s²)/(2 s⁵), p the Earth's pole, all on one set of axes (the mantle's
    here). Writing g = (s·p)²/s⁵ and f = 1/s³, U = −μ J₂ R_E² (3g/2 − f/2) and
    ∂²g = 2 p pᵀ/s⁵ − 10 c (p sᵀ + s pᵀ)/s⁷ − 5 c² 1/s⁷ + 35 c² s sᵀ/s⁹ (c = s·p),
    ∂²f = −3·1/s⁵ + 15 s sᵀ/s⁷. The result is trace-free (tested).
    """
    k = -mu_earth * block[IN_EARTH_J2R2]
    ss = sx * sx + sy * sy + sz * sz
    inv5 = 1.0 / (ss * ss * math.sqrt(ss))
    inv7 = inv5 / ss
    inv9 = inv7 / ss
    c = sx * px + sy * py + sz * pz
    s = (sx, sy, sz)
    p = (px, py, pz)
    pairs = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))  # (row, column) of each SYM_* offset
    for n in range(6):
        i, j = pairs[n]
        delta = 1.0 if i == j else 0.0
        g = (2.0 * p[i] * p[j] * inv5 - 10.0 * c * (p[i] * s[j] + s[i] * p[j]) * inv7
             - 5.0 * c * c * delta * inv7 + 35.0 * c * c * s[i] * s[j] * inv9)
        f = -3.0 * delta * inv5 + 15.0 * s[i] * s[j] * inv7
        h[n] = k * (1.5 * g - 0.5 * f)


@jit(inline="always")
def figure_figure_torque(m, h):
    """N_i = −ε_ijk (M H)_jk for symmetric M and H (6-entry forms): the torque of a field with
    Hessian H on a body of inertia M."""
    # (MH)_jk = Σ_l M_jl H_lk with the 6-entry layout (xx, yy, zz, xy, xz, yz).
    mxx, myy, mzz, mxy, mxz, myz = m[SYM_XX], m[SYM_YY], m[SYM_ZZ], m[SYM_XY], m[SYM_XZ], m[SYM_YZ]
    hxx, hyy, hzz, hxy, hxz, hyz = h[SYM_XX], h[SYM_YY], h[SYM_ZZ], h[SYM_XY], h[SYM_XZ], h[SYM_YZ]
    mh_yz = mxy * hxz + myy * hyz + myz * hzz
    mh_zy = mxz * hxy + myz * hyy + mzz * hyz
    mh_zx = mxz * hxx + myz * hxy + mzz * hxz
    mh_xz = mxx * hxz + mxy * hyz + mxz * hzz
    mh_xy = mxx * hxy + mxy * hyy + mxz * hyz
    mh_yx = mxy * hxx + myy * hxy + myz * hxz
    return -(mh_yz - mh_zy), -(mh_zx - mh_xz), -(mh_xy - mh_yx)


@jit(inline="always")
def core_mantle_torque(block, wx, wy, wz, cx, cy, cz):
    """N_cmb = k_v (ω_c − ω) + (C_c − A_c)(ẑ·ω_c)(ẑ × ω_c): the core's torque on the mantle."""
    kv = block[IN_KV]
    oblate = (block[IN_CORE_C] - block[IN_CORE_A]) * cz
    return kv * (cx - wx) - oblate * cy, kv * (cy - wy) + oblate * cx, kv * (cz - wz)
