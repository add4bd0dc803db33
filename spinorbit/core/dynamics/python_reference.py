"""A pure-Python transcription of :func:`spinorbit.core.dynamics.equations.rhs`, for baselines only.

Benchmarks compare the package with peers that must not use compiled code (scipy's ``solve_ivp``
with a right-hand side in plain Python and numpy, the baseline the performance goals name). This
module is the one place such a right-hand side is written: the same equations as
:mod:`spinorbit.core.dynamics.equations`, term for term and in the same order of operations, on the
same state y = (q0, q1, q2, q3, ωx, ωy, ωz) and the same flat model array (:func:`make_model`).
No numba, no package kernel is called; ``tests/test_python_reference.py`` holds it to
:func:`~spinorbit.core.dynamics.equations.rhs` on random states.

Covered (every feature of the rigid-body model):

- the figure: degree 2 from the moments (MacCullagh) and Stokes degrees 3..n_max by Cunningham's
  recursion (:mod:`spinorbit.core.model.gravity_field`), torque N = (∂U/∂r) × r of the field without
  its monopole;
- the perturbers (:mod:`spinorbit.core.model.perturbers`): Kepler orbits, elliptic and hyperbolic
  (the same safeguarded Halley solvers), cubic Hermite samples (NaN outside their span) and fixed
  positions; torque-free when the model has none;
- the body frame r_b = M(q)ᵀ r / |q|², the quaternion kinematics and Euler's equations.

Not covered: the 10-component lunar mantle-and-core state (:func:`equations.lunar_rhs_into`);
:func:`make_rhs` refuses a model that carries an interior block's state.

The model is read once, in :func:`make_rhs`, into Python floats and closures, as a hand-written
Python right-hand side would hold its constants; each call then does only the arithmetic.
"""

import bisect
import math

import numpy as np

from spinorbit.core.dynamics.equations import MODEL_PERTURBERS, STATE_SIZE
from spinorbit.core.model.gravity_field import (
    BODY_A,
    BODY_B,
    BODY_C,
    BODY_MASS,
    BODY_NMAX,
    BODY_RADIUS,
    FIG_STOKES_C,
    FIG_STOKES_S,
    FIG_THERMAL,
    STOKES_SIZE,
)
from spinorbit.core.model.perturbers import (
    K_A,
    K_E,
    K_M0,
    K_MEAN_MOTION,
    K_P,
    K_Q,
    K_ROOT,
    K_T0,
    KEPLER_FINAL_STEP,
    KEPLER_MAX_ITERATIONS,
    KEPLER_TOLERANCE,
    KIND_FIXED,
    KIND_KEPLER,
    KIND_SAMPLED,
    PERTURBER_ROW,
)

#: Terms of the series of x − sin x and sinh x − x near 0 (as in the compiled Kepler solvers).
_SERIES_TERMS = 8
_SERIES_RANGE = 0.5


def _x_minus_sin(x):
    """x − sin x without cancellation for |x| < 0.5 (series), as the compiled solver evaluates it."""
    if abs(x) >= _SERIES_RANGE:
        return x - math.sin(x)
    x2 = x * x
    term = x * x2 / 6.0
    total = term
    for k in range(2, _SERIES_TERMS):
        term *= -x2 / ((2 * k) * (2 * k + 1))
        total += term
    return total


def _sinh_minus_x(x):
    """sinh x − x without cancellation for |x| < 0.5 (series)."""
    if abs(x) >= _SERIES_RANGE:
        return math.sinh(x) - x
    x2 = x * x
    term = x * x2 / 6.0
    total = term
    for k in range(2, _SERIES_TERMS):
        term *= x2 / ((2 * k) * (2 * k + 1))
        total += term
    return total


def _bracketed_halley(f, fp, fpp, x, lo, hi):
    """One step of the safeguarded iteration: (Halley correction dx, new bracket lo, hi, next iterate,
    whether the bracket has shrunk to KEPLER_TOLERANCE). f is increasing, so its sign moves one end."""
    if f > 0.0:
        hi = x
    else:
        lo = x
    dx = f / (fp - 0.5 * f * fpp / fp) if fp > 0.0 else math.inf
    x_next = x - dx
    if not (lo <= x_next <= hi):
        x_next = 0.5 * (lo + hi)
    return dx, lo, hi, x_next, hi - lo <= KEPLER_TOLERANCE * max(1.0, abs(x_next))


def elliptic_anomaly_sincos(mean_anomaly, e):
    """(sin E, cos E) with E − e sin E = M, 0 ≤ e < 1: the bracketed Halley iteration of
    :func:`spinorbit.core.model.perturbers.solve_kepler_elliptic_sincos`."""
    two_pi = 2.0 * math.pi
    turns = math.floor((mean_anomaly + math.pi) / two_pi)
    m = mean_anomaly - turns * two_pi
    lo, hi = m - e, m + e
    x = m + 0.85 * e * (1.0 if math.sin(m) >= 0.0 else -1.0)
    if x <= lo or x >= hi:
        x = 0.5 * (lo + hi)
    sx, cx = math.sin(x), math.cos(x)
    for _ in range(KEPLER_MAX_ITERATIONS):
        f = (1.0 - e) * x + e * _x_minus_sin(x) - m if abs(x) < _SERIES_RANGE else x - e * sx - m
        dx, lo, hi, x_next, converged = _bracketed_halley(f, 1.0 - e * cx, e * sx, x, lo, hi)
        if abs(dx) <= KEPLER_FINAL_STEP * max(1.0, abs(x)) and lo <= x - dx <= hi:
            half_dx2 = 0.5 * dx * dx
            return sx - cx * dx - sx * half_dx2, cx + sx * dx - cx * half_dx2
        x = x_next
        if converged:
            break
        sx, cx = math.sin(x), math.cos(x)
    return math.sin(x), math.cos(x)


def hyperbolic_anomaly_sinhcosh(mean_anomaly, e):
    """(sinh H, cosh H) with e sinh H − H = M, e > 1: the iteration of
    :func:`spinorbit.core.model.perturbers.solve_kepler_hyperbolic_sinhcosh`."""
    m = abs(mean_anomaly)
    sgn = 1.0 if mean_anomaly >= 0.0 else -1.0
    if m == 0.0:
        return 0.0, 1.0
    lo, hi = math.asinh(m / e), math.asinh(m / (e - 1.0))
    x = lo
    sh, ch = math.sinh(x), math.cosh(x)
    for _ in range(KEPLER_MAX_ITERATIONS):
        f = (e - 1.0) * x + e * _sinh_minus_x(x) - m if x < _SERIES_RANGE else e * sh - x - m
        dx, lo, hi, x_next, converged = _bracketed_halley(f, e * ch - 1.0, e * sh, x, lo, hi)
        if abs(dx) <= KEPLER_FINAL_STEP * max(1.0, abs(x)) and lo <= x - dx <= hi:
            half_dx2 = 0.5 * dx * dx
            return sgn * (sh - ch * dx + sh * half_dx2), ch - sh * dx + ch * half_dx2
        x = x_next
        if converged:
            break
        sh, ch = math.sinh(x), math.cosh(x)
    return sgn * math.sinh(x), math.cosh(x)


def _kepler_position(params):
    """position(t) of a KIND_KEPLER row: sign (P px + Q py) from the perifocal position."""
    a, e, m0, t0, n, root = (float(params[k]) for k in (K_A, K_E, K_M0, K_T0, K_MEAN_MOTION, K_ROOT))
    px_, py_, pz_ = (float(v) for v in params[K_P:K_P + 3])
    qx_, qy_, qz_ = (float(v) for v in params[K_Q:K_Q + 3])
    elliptic = e < 1.0

    def position(t):
        if elliptic:
            se, ce = elliptic_anomaly_sincos(m0 + n * (t - t0), e)
            u, v = a * (ce - e), a * root * se
        else:
            sh, ch = hyperbolic_anomaly_sinhcosh(m0 + n * (t - t0), e)
            u, v = -a * (e - ch), -a * root * sh
        return px_ * u + qx_ * v, py_ * u + qy_ * v, pz_ * u + qz_ * v

    return position


def _sampled_position(model, first, count, xv_first):
    """position(t) of a KIND_SAMPLED row: cubic Hermite interpolation, NaN outside the samples."""
    times = [float(v) for v in model[first:first + count]]
    samples = [tuple(float(v) for v in row) for row in np.reshape(model[xv_first:xv_first + 6 * count], (count, 6))]
    start, end, last_interval = times[0], times[-1], count - 2

    def position(t):
        if not (start <= t <= end):
            return math.nan, math.nan, math.nan
        lo = min(bisect.bisect_right(times, t) - 1, last_interval)
        h = times[lo + 1] - times[lo]
        s = (t - times[lo]) / h
        s2 = s * s
        s3 = s2 * s
        a, b, c, d = 2.0 * s3 - 3.0 * s2 + 1.0, (s3 - 2.0 * s2 + s) * h, -2.0 * s3 + 3.0 * s2, (s3 - s2) * h
        x0, y0, z0, vx0, vy0, vz0 = samples[lo]
        x1, y1, z1, vx1, vy1, vz1 = samples[lo + 1]
        return (a * x0 + b * vx0 + c * x1 + d * vx1, a * y0 + b * vy0 + c * y1 + d * vy1,
                a * z0 + b * vz0 + c * z1 + d * vz1)

    return position


def _fixed_position(params):
    fixed = (float(params[0]), float(params[1]), float(params[2]))
    return lambda t: fixed


def _perturbers(model):
    """[(μ, position(t))] of the model's perturber block."""
    out = []
    for k in range(int(model[MODEL_PERTURBERS])):
        row = MODEL_PERTURBERS + 1 + k * PERTURBER_ROW
        kind, mu, params = int(model[row]), float(model[row + 1]), model[row + 2:row + PERTURBER_ROW]
        if kind == KIND_KEPLER:
            out.append((mu, _kepler_position(params)))
        elif kind == KIND_SAMPLED:
            out.append((mu, _sampled_position(model, int(params[0]), int(params[1]), int(params[2]))))
        elif kind == KIND_FIXED:
            out.append((mu, _fixed_position(params)))
        else:
            raise ValueError(f"model: unknown perturber kind {kind} in row {k}.")
    return out


def _stokes_gradient(x, y, z, mu, mass, radius, stokes, n_max):
    """∂U/∂r of the Stokes terms of degrees 3..n_max (Cunningham's V_nm, W_nm; Montenbruck & Gill
    eqs. 3.29–3.33), as :func:`spinorbit.core.model.gravity_field.stokes_force_function_and_gradient`."""
    size = n_max + 2
    rr = x * x + y * y + z * z
    x0, y0, z0 = radius * x / rr, radius * y / rr, radius * z / rr
    rho = radius * radius / rr
    v = [[0.0] * size for _ in range(size)]
    w = [[0.0] * size for _ in range(size)]
    v[0][0] = radius / math.sqrt(rr)
    for m in range(size):
        if m > 0:
            v[m][m] = (2 * m - 1) * (x0 * v[m - 1][m - 1] - y0 * w[m - 1][m - 1])
            w[m][m] = (2 * m - 1) * (x0 * w[m - 1][m - 1] + y0 * v[m - 1][m - 1])
        if m + 1 < size:
            v[m + 1][m] = (2 * m + 1) * z0 * v[m][m]
            w[m + 1][m] = (2 * m + 1) * z0 * w[m][m]
        for n in range(m + 2, size):
            v[n][m] = ((2 * n - 1) * z0 * v[n - 1][m] - (n + m - 1) * rho * v[n - 2][m]) / (n - m)
            w[n][m] = ((2 * n - 1) * z0 * w[n - 1][m] - (n + m - 1) * rho * w[n - 2][m]) / (n - m)
    gx = gy = gz = 0.0
    for n, m, c, s in stokes:
        if n > n_max:
            continue
        if m == 0:
            gx -= c * v[n + 1][1]
            gy -= c * w[n + 1][1]
        else:
            fac = (n - m + 2) * (n - m + 1)
            gx += 0.5 * ((-c * v[n + 1][m + 1] - s * w[n + 1][m + 1]) + fac * (c * v[n + 1][m - 1] + s * w[n + 1][m - 1]))
            gy += 0.5 * ((-c * w[n + 1][m + 1] + s * v[n + 1][m + 1]) + fac * (-c * w[n + 1][m - 1] + s * v[n + 1][m - 1]))
        gz += (n - m + 1) * (-c * v[n + 1][m] - s * w[n + 1][m])
    scale = mu * mass / radius / radius
    return scale * gx, scale * gy, scale * gz


def make_rhs(model):
    """``fun(t, y) -> dy/dt`` (ndarray (7,)) in plain Python for a rigid-body model array.

    Parameters
    ----------
    model : ndarray
        From :func:`spinorbit.core.dynamics.equations.make_model` (time unit of the run, energy units).

    Returns
    -------
    fun : callable
        ``fun(t, y)`` with y = (q, ω) (7 floats, q need not be unit); usable as scipy's ``fun``.
    """
    model = np.asarray(model, dtype=float)
    if model[FIG_THERMAL] > 0.0:
        raise ValueError("model: the pure-Python baseline has no transcription of the thermal (YORP) block; "
                         "use the compiled rhs (spinorbit.core.dynamics.equations.rhs) for this model.")
    a_mom, b_mom, c_mom = float(model[BODY_A]), float(model[BODY_B]), float(model[BODY_C])
    trace = a_mom + b_mom + c_mom
    mass, radius, n_max = float(model[BODY_MASS]), float(model[BODY_RADIUS]), int(model[BODY_NMAX])
    stokes = [(n, m, float(model[FIG_STOKES_C + n * STOKES_SIZE + m]), float(model[FIG_STOKES_S + n * STOKES_SIZE + m]))
              for n in range(3, n_max + 1) for m in range(n + 1)]
    stokes = [term for term in stokes if term[2] != 0.0 or term[3] != 0.0]
    perturbers = _perturbers(model)

    def fun(t, y):
        if len(y) != STATE_SIZE:
            raise ValueError(f"y: the pure-Python reference covers the {STATE_SIZE}-component rigid body, "
                             f"got {len(y)} components (the lunar interior is compiled only).")
        q0, q1, q2, q3, wx, wy, wz = (float(v) for v in y)
        nx = ny = nz = 0.0
        if perturbers:
            inv = 1.0 / (q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3)
            # r_body = M(q)ᵀ r_inertial / |q|² (equations.body_frame_xyz)
            m00, m01, m02 = q0 * q0 + q1 * q1 - q2 * q2 - q3 * q3, 2.0 * (q1 * q2 + q0 * q3), 2.0 * (q1 * q3 - q0 * q2)
            m10, m11, m12 = 2.0 * (q1 * q2 - q0 * q3), q0 * q0 - q1 * q1 + q2 * q2 - q3 * q3, 2.0 * (q2 * q3 + q0 * q1)
            m20, m21, m22 = 2.0 * (q1 * q3 + q0 * q2), 2.0 * (q2 * q3 - q0 * q1), q0 * q0 - q1 * q1 - q2 * q2 + q3 * q3
            for mu, position in perturbers:
                rx, ry, rz = position(t)
                x = inv * (m00 * rx + m01 * ry + m02 * rz)
                yb = inv * (m10 * rx + m11 * ry + m12 * rz)
                z = inv * (m20 * rx + m21 * ry + m22 * rz)
                # ∂U/∂r of degrees 2..n_max (gravity_field.figure_field_to_degree_xyz)
                rr = x * x + yb * yb + z * z
                inv_r5 = 1.0 / (rr * math.sqrt(rr)) / rr
                ix, iy, iz = a_mom * x, b_mom * yb, c_mom * z
                radial = -1.5 * mu * trace * inv_r5 + 7.5 * mu * (x * ix + yb * iy + z * iz) * inv_r5 / rr
                k = -3.0 * mu * inv_r5
                gx, gy, gz = radial * x + k * ix, radial * yb + k * iy, radial * z + k * iz
                if stokes:
                    sx, sy, sz = _stokes_gradient(x, yb, z, mu, mass, radius, stokes, n_max)
                    gx, gy, gz = gx + sx, gy + sy, gz + sz
                # N = (∂U/∂r) × r
                nx += gy * z - gz * yb
                ny += gz * x - gx * z
                nz += gx * yb - gy * x
        return np.array([0.5 * (-q1 * wx - q2 * wy - q3 * wz), 0.5 * (q0 * wx + q2 * wz - q3 * wy),
                         0.5 * (q0 * wy - q1 * wz + q3 * wx), 0.5 * (q0 * wz + q1 * wy - q2 * wx),
                         ((b_mom - c_mom) * wy * wz + nx) / a_mom, ((c_mom - a_mom) * wz * wx + ny) / b_mom,
                         ((a_mom - b_mom) * wx * wy + nz) / c_mom])

    return fun


def rhs(t, y, model):
    """dy/dt of y = (q, ω) at time t: :func:`make_rhs` for one call (the model is read each time)."""
    return make_rhs(model)(t, y)
