"""Where the perturbing point masses are: numba-evaluable position sources.

**Body-centric convention.** Every source returns the position (and velocity) of a perturber
*relative to the rotating body's centre of mass*, in the inertial frame (the same frame the
quaternion q refers to). For a Sun–asteroid pair described by the asteroid's heliocentric elements,
pass ``sign=-1`` to :func:`kepler_source` (the Sun is at minus the asteroid's heliocentric position).

A set of perturbers is carried as one flat float64 array block (numba cannot cache jitclasses, and a
single array keeps reference counting off the hot path)::

    [k, row_0, …, row_{k−1}, sample data…]     row = [kind, μ = G M_p, params (PARAM_SIZE)]

Build it with :func:`kepler_source`, :func:`sampled_source`, :func:`sampled_source_from_callable`,
:func:`fixed_source` and :func:`pack_perturbers`.

Kinds:

- ``KIND_KEPLER`` params = [μ_orbit, a, e, i, Ω, ω, M₀, t₀, sign, n, √|1−e²|, sign·P, sign·Q]: a two-body orbit of the relative
  position (a < 0 and e > 1 for a hyperbola, angles in radians, M₀ the mean anomaly at t₀). Kepler's
  equation is solved by Newton's method safeguarded by bisection on a bracket that always contains
  the root, so it converges for every e ≠ 1 (parabolas are rejected by the builder).
- ``KIND_SAMPLED`` params = [index of the first time, count, index of the first x]: piecewise cubic Hermite interpolation of positions
  and velocities. The interpolation error on an interval of length h is at most
  h⁴/384 · max|x⁽⁴⁾| (position); for a Keplerian orbit sampled n_s times per orbit near a circular
  orbit of radius a this is about a (2π/n_s)⁴/384. Outside the sampled span the kernel returns NaN;
  the public integrator checks the span before it starts.
- ``KIND_FIXED`` params = [x, y, z]: a perturber at rest (used for the energy-balance test).
"""

import math

import numpy as np

from spinorbit.core.errors import require_finite
from spinorbit.core.jit import jit

KIND_KEPLER = 0
KIND_SAMPLED = 1
KIND_FIXED = 2
# Layout of a KIND_KEPLER parameter row (derived quantities precomputed by kepler_source).
K_MU, K_A, K_E, K_INC, K_NODE, K_ARGP, K_M0, K_T0, K_SIGN, K_MEAN_MOTION, K_ROOT = range(11)
K_P = 11  # sign·P (3 values): perifocal x unit vector in the inertial frame
K_Q = 14  # sign·Q (3 values): perifocal y unit vector
PARAM_SIZE = 17
PERTURBER_ROW = 2 + PARAM_SIZE  # [kind, μ, params]

#: Relative convergence threshold of the Kepler solver: a few ulps of the anomaly.
KEPLER_TOLERANCE = 4.0 * np.finfo(float).eps
#: Iteration cap; safeguarded Newton needs < 10 in practice, bisection alone < 110 in double.
KEPLER_MAX_ITERATIONS = 200


@jit
def _odd_series_tail(x, sign):
    """Σ_{k≥1} sign^(k+1) x^(2k+1)/(2k+1)!: x − sin x (sign = −1) or sinh x − x (sign = +1).

    The series to x¹⁵ is below ε relative for |x| < 0.5, where the direct difference would cancel.
    """
    x2 = x * x
    term = x * x2 / 6.0
    total = term
    for k in range(2, 8):
        term *= sign * x2 / ((2 * k) * (2 * k + 1))
        total += term
    return total


@jit
def _x_minus_sin(x):
    """x − sin x without cancellation for small |x| (series to x¹⁵, error < ε for |x| < 0.5)."""
    if abs(x) >= 0.5:
        return x - math.sin(x)
    return _odd_series_tail(x, -1.0)


@jit
def _sinh_minus_x(x):
    """sinh x − x without cancellation for small |x| (series, error < ε for |x| < 0.5)."""
    if abs(x) >= 0.5:
        return math.sinh(x) - x
    return _odd_series_tail(x, 1.0)


#: Halley correction below which the iteration stops and sin E, cos E are updated by their Taylor
#: series to second order instead of being recomputed: Halley converges cubically, so the root's
#: remaining error is ~ this³ = 1e-18, and the neglected third-order trig term is ~ this³/6.
KEPLER_FINAL_STEP = 1e-6

# What one safeguarded Halley step of a Kepler solver leaves to do.
STEP_CONTINUE, STEP_FINAL, STEP_CONVERGED = 0, 1, 2


@jit(inline="always")
def _bracketed_halley(x, f, fp, fpp, lo, hi):
    """One Halley step for the root of a monotone increasing f, kept inside the bracket [lo, hi].

    Returns (lo, hi, x_new, dx, what): the bracket shrunk by the sign of f, the next iterate (Halley's
    x − dx, or the bisection when it leaves the bracket) and what the solver does next:
    ``STEP_FINAL`` (|dx| < KEPLER_FINAL_STEP inside the bracket: the caller applies x − dx to the
    trig functions by their Taylor series), ``STEP_CONVERGED`` (the bracket is a few ulps wide) or
    ``STEP_CONTINUE``. fp only steers the iteration; its rounding does not limit the root.
    """
    if f > 0.0:
        hi = x
    else:
        lo = x
    dx = f / (fp - 0.5 * f * fpp / fp) if fp > 0.0 else np.inf
    if abs(dx) <= KEPLER_FINAL_STEP * max(1.0, abs(x)) and lo <= x - dx <= hi:
        return lo, hi, x - dx, dx, STEP_FINAL
    x_new = x - dx
    if not (lo <= x_new <= hi):
        x_new = 0.5 * (lo + hi)
    if hi - lo <= KEPLER_TOLERANCE * max(1.0, abs(x_new)):
        return lo, hi, x_new, dx, STEP_CONVERGED
    return lo, hi, x_new, dx, STEP_CONTINUE


@jit
def solve_kepler_elliptic_sincos(mean_anomaly, e):
    """(E, sin E, cos E) with E − e sin E = M, 0 ≤ e < 1 (radians).

    M is reduced to [−π, π]; the root lies in [M − e, M + e] (since |E − M| = e|sin E| ≤ e) and
    f(E) = E − e sin E − M is monotone, so Newton steps are kept inside a shrinking bracket and
    replaced by bisection when they leave it: convergence for every e < 1, including e → 1, M → 0.
    f is evaluated as (1 − e)E + e(E − sin E) with a series for E − sin E near 0 (no cancellation).
    Once the Newton correction δ is below KEPLER_FINAL_STEP the last update is applied to E, sin E and
    cos E to first order (error ~δ² ≤ 1e-18), which saves one iteration and a sin/cos pair per call.
    E is continuous with the unreduced M (the reduction's multiple of 2π is added back).
    """
    two_pi = 2.0 * math.pi
    turns = math.floor((mean_anomaly + math.pi) / two_pi)
    m = mean_anomaly - turns * two_pi
    lo = m - e
    hi = m + e
    # Starting guess of Danby (1987): good for all e.
    x = m + 0.85 * e * (1.0 if math.sin(m) >= 0.0 else -1.0)
    if x <= lo or x >= hi:
        x = 0.5 * (lo + hi)
    sx = math.sin(x)
    cx = math.cos(x)
    for _ in range(KEPLER_MAX_ITERATIONS):
        if abs(x) < 0.5:
            f = (1.0 - e) * x + e * _x_minus_sin(x) - m
        else:
            f = x - e * sx - m
        lo, hi, x_new, dx, what = _bracketed_halley(x, f, 1.0 - e * cx, e * sx, lo, hi)
        if what == STEP_FINAL:
            half_dx2 = 0.5 * dx * dx
            return x_new + turns * two_pi, sx - cx * dx - sx * half_dx2, cx + sx * dx - cx * half_dx2
        x = x_new
        if what == STEP_CONVERGED:
            break
        sx = math.sin(x)
        cx = math.cos(x)
    return x + turns * two_pi, math.sin(x), math.cos(x)


@jit
def solve_kepler_elliptic(mean_anomaly, e):
    """Eccentric anomaly E with E − e sin E = M, 0 ≤ e < 1 (see :func:`solve_kepler_elliptic_sincos`)."""
    return solve_kepler_elliptic_sincos(mean_anomaly, e)[0]


@jit
def solve_kepler_hyperbolic_sinhcosh(mean_anomaly, e):
    """(H, sinh H, cosh H) with e sinh H − H = M, e > 1.

    For M > 0 the root lies in [asinh(M/e), asinh(M/(e − 1))] (from sinh H ≥ H ≥ 0); the function is
    monotone, so Halley steps kept inside the shrinking bracket (bisection when they leave it) converge
    for all e > 1. f = (e − 1)H + e(sinh H − H) with a series near 0 (no cancellation as e → 1). As in
    the elliptic solver, the last small correction δ < KEPLER_FINAL_STEP updates sinh and cosh by their
    second-order Taylor series instead of recomputing them.
    """
    m = abs(mean_anomaly)
    sgn = 1.0 if mean_anomaly >= 0.0 else -1.0
    if m == 0.0:
        return 0.0, 0.0, 1.0
    lo = math.asinh(m / e)
    hi = math.asinh(m / (e - 1.0))
    x = lo
    sh = math.sinh(x)
    ch = math.cosh(x)
    for _ in range(KEPLER_MAX_ITERATIONS):
        if x < 0.5:
            f = (e - 1.0) * x + e * _sinh_minus_x(x) - m
        else:
            f = e * sh - x - m
        lo, hi, x_new, dx, what = _bracketed_halley(x, f, e * ch - 1.0, e * sh, lo, hi)
        if what == STEP_FINAL:
            half_dx2 = 0.5 * dx * dx
            return sgn * x_new, sgn * (sh - ch * dx + sh * half_dx2), ch - sh * dx + ch * half_dx2
        x = x_new
        if what == STEP_CONVERGED:
            break
        sh = math.sinh(x)
        ch = math.cosh(x)
    return sgn * x, sgn * math.sinh(x), math.cosh(x)


@jit
def solve_kepler_hyperbolic(mean_anomaly, e):
    """Hyperbolic anomaly H with e sinh H − H = M, e > 1 (see :func:`solve_kepler_hyperbolic_sinhcosh`)."""
    return solve_kepler_hyperbolic_sinhcosh(mean_anomaly, e)[0]


@jit
def kepler_perifocal(t, a, e, m0, t0, n, root):
    """Perifocal position (px, py) and velocity (vx, vy) on a Kepler orbit at time t (floats only)."""
    if e < 1.0:
        _, se, ce = solve_kepler_elliptic_sincos(m0 + n * (t - t0), e)
        rate = n / (1.0 - e * ce)  # dE/dt
        return a * (ce - e), a * root * se, -a * se * rate, a * root * ce * rate
    abs_a = -a
    _, sh, ch = solve_kepler_hyperbolic_sinhcosh(m0 + n * (t - t0), e)
    rate = n / (e * ch - 1.0)  # dH/dt
    return abs_a * (e - ch), abs_a * root * sh, -abs_a * sh * rate, abs_a * root * ch * rate


# inline="always": functions on the RHS hot path are inlined at numba-IR level so that the model array
# does not cross a call boundary per evaluation (each crossing costs atomic reference-count updates,
# more than the arithmetic of a torque-free RHS).
@jit(inline="always")
def kepler_position_xyz(t, arr, off):
    """Inertial position (x, y, z) of the KIND_KEPLER parameter row ``arr[off:off+PARAM_SIZE]``.

    Three floats, no allocation. Position = sign (P px + Q py) with the perifocal unit vectors P, Q
    precomputed by :func:`kepler_source` (the orientation angles cost no trigonometry per call).
    """
    px, py, _, _ = kepler_perifocal(t, arr[off + K_A], arr[off + K_E], arr[off + K_M0], arr[off + K_T0],
                                     arr[off + K_MEAN_MOTION], arr[off + K_ROOT])
    return (arr[off + K_P] * px + arr[off + K_Q] * py,
            arr[off + K_P + 1] * px + arr[off + K_Q + 1] * py,
            arr[off + K_P + 2] * px + arr[off + K_Q + 2] * py)


@jit
def kepler_state(t, params):
    """Position and velocity (inertial) of a KIND_KEPLER parameter row at t → (6,) array."""
    px, py, vx, vy = kepler_perifocal(t, params[K_A], params[K_E], params[K_M0], params[K_T0],
                                       params[K_MEAN_MOTION], params[K_ROOT])
    out = np.empty(6)
    for k in range(3):
        out[k] = params[K_P + k] * px + params[K_Q + k] * py
        out[3 + k] = params[K_P + k] * vx + params[K_Q + k] * vy
    return out


@jit
def find_interval(t, arr, first, count):
    """Index lo (absolute) with arr[lo] ≤ t ≤ arr[lo+1] inside the sorted block [first, first+count)."""
    lo = first
    hi = first + count - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if arr[mid] <= t:
            lo = mid
        else:
            hi = mid
    return lo


@jit(inline="always")
def _hermite_locate(t, arr, first, count, xv_first):
    """(h, s, i0, i1) of the sample interval containing t: its length, t's position in it ∈ [0, 1]
    and the offsets of its two (position, velocity) rows. h and s are NaN outside the span, so every
    weighted sum formed from them is NaN too."""
    if not (arr[first] <= t <= arr[first + count - 1]):
        return np.nan, np.nan, xv_first, xv_first
    lo = find_interval(t, arr, first, count)
    h = arr[lo + 1] - arr[lo]
    i0 = xv_first + 6 * (lo - first)
    return h, (t - arr[lo]) / h, i0, i0 + 6


@jit(inline="always")
def _hermite_combine(arr, i0, i1, a, b, c, d):
    """a·p0 + b·v0 + c·p1 + d·v1 for x, y, z (p, v the interval's end-point positions and velocities)."""
    return (a * arr[i0] + b * arr[i0 + 3] + c * arr[i1] + d * arr[i1 + 3],
            a * arr[i0 + 1] + b * arr[i0 + 4] + c * arr[i1 + 1] + d * arr[i1 + 4],
            a * arr[i0 + 2] + b * arr[i0 + 5] + c * arr[i1 + 2] + d * arr[i1 + 5])


@jit(inline="always")
def hermite_position_xyz(t, arr, first, count, xv_first):
    """Cubic Hermite position (x, y, z) from a flat array: sample times at arr[first:first+count],
    positions and velocities (6 per sample, row-major) from arr[xv_first]. NaN outside the span."""
    h, s, i0, i1 = _hermite_locate(t, arr, first, count, xv_first)
    s2 = s * s
    s3 = s2 * s
    return _hermite_combine(arr, i0, i1, 2.0 * s3 - 3.0 * s2 + 1.0, (s3 - 2.0 * s2 + s) * h,
                            -2.0 * s3 + 3.0 * s2, (s3 - s2) * h)


@jit(inline="always")
def hermite_velocity_xyz(t, arr, first, count, xv_first):
    """Derivative of :func:`hermite_position_xyz` (the interpolant's velocity, O(h³)); NaN outside."""
    h, s, i0, i1 = _hermite_locate(t, arr, first, count, xv_first)
    s2 = s * s
    d00 = (6.0 * s2 - 6.0 * s) / h
    return _hermite_combine(arr, i0, i1, d00, 3.0 * s2 - 4.0 * s + 1.0, -d00, 3.0 * s2 - 2.0 * s)


@jit(inline="always")
def sampled_velocity_xyz(t, arr, row):
    """Velocity (inertial) of the sampled perturber whose row starts at arr[row]; allocation-free."""
    off = row + 2
    return hermite_velocity_xyz(t, arr, int(arr[off]), int(arr[off + 1]), int(arr[off + 2]))


@jit
def hermite_state(t, times, xv):
    """Cubic Hermite interpolation of positions and velocities sampled at sorted ``times`` → (6,).

    NaN outside [times[0], times[-1]]. Position: the cubic Hermite interpolant; velocity: its
    derivative (one order less accurate, O(h³)).
    """
    n = times.shape[0]
    out = np.empty(6)
    if not (times[0] <= t <= times[n - 1]):
        out[:] = np.nan
        return out
    lo = find_interval(t, times, 0, n)  # [times[lo], times[lo + 1]] contains t
    hi = lo + 1
    h = times[hi] - times[lo]
    s = (t - times[lo]) / h
    s2 = s * s
    s3 = s2 * s
    h00 = 2.0 * s3 - 3.0 * s2 + 1.0
    h10 = s3 - 2.0 * s2 + s
    h01 = -2.0 * s3 + 3.0 * s2
    h11 = s3 - s2
    d00 = (6.0 * s2 - 6.0 * s) / h
    d10 = 3.0 * s2 - 4.0 * s + 1.0
    d01 = (-6.0 * s2 + 6.0 * s) / h
    d11 = 3.0 * s2 - 2.0 * s
    for k in range(3):
        p0, p1 = xv[lo, k], xv[hi, k]
        v0, v1 = xv[lo, 3 + k], xv[hi, 3 + k]
        out[k] = h00 * p0 + h10 * h * v0 + h01 * p1 + h11 * h * v1
        out[3 + k] = d00 * p0 + d10 * v0 + d01 * p1 + d11 * v1
    return out


@jit(inline="always")
def perturber_position_xyz(t, arr, row):
    """Position (x, y, z) relative to the body (inertial) of the perturber whose row starts at arr[row].

    A row is [kind, μ, params…] (PERTURBER_ROW floats); no allocation: the RHS hot path.
    """
    kind = int(arr[row])
    off = row + 2
    if kind == KIND_KEPLER:
        return kepler_position_xyz(t, arr, off)
    if kind == KIND_SAMPLED:
        return hermite_position_xyz(t, arr, int(arr[off]), int(arr[off + 1]), int(arr[off + 2]))
    return arr[off], arr[off + 1], arr[off + 2]


@jit
def perturber_state(t, arr, row):
    """Position and velocity (6,) of the perturber whose row starts at arr[row] (tests, diagnostics)."""
    kind = int(arr[row])
    off = row + 2
    if kind == KIND_KEPLER:
        return kepler_state(t, arr[off:off + PARAM_SIZE])
    if kind == KIND_SAMPLED:
        first, count, xv_first = int(arr[off]), int(arr[off + 1]), int(arr[off + 2])
        times = arr[first:first + count].copy()
        xv = arr[xv_first:xv_first + 6 * count].copy().reshape((count, 6))
        return hermite_state(t, times, xv)
    out = np.zeros(6)
    out[0] = arr[off]
    out[1] = arr[off + 1]
    out[2] = arr[off + 2]
    return out


# ---------------------------------------------------------------------------------------------
# Builders (plain Python; validate, then produce the arrays).


class _Source:
    """One perturber before packing: kind, μ, params and (for sampled sources) its samples."""

    __slots__ = ("kind", "mu", "params", "times", "xv")

    def __init__(self, kind, mu, params, times=None, xv=None):
        self.kind, self.mu, self.params, self.times, self.xv = kind, mu, params, times, xv

    def __repr__(self):
        names = {KIND_KEPLER: "kepler", KIND_SAMPLED: "sampled", KIND_FIXED: "fixed"}
        return f"<perturber source {names[self.kind]} mu={self.mu:g}>"


def _check_mu(mu):
    require_finite("mu", mu, "G·M of the perturber > 0 (length³/time²)")
    if not (np.isfinite(mu) and mu > 0):
        raise ValueError(f"mu: expected G·M of the perturber > 0 (length³/time²), got {mu!r}.")


def kepler_source(mu, a, e, inc, node, argp, mean_anomaly, epoch=0.0, mu_orbit=None, sign=1.0):
    """A perturber on a Keplerian orbit relative to the body.

    Parameters
    ----------
    mu : float
        G M_p of the perturber: the strength of its torque (length³/time²).
    a : float
        Semi-major axis (length); negative for a hyperbola.
    e : float
        Eccentricity, ≥ 0 and ≠ 1 (e > 1 needs a < 0).
    inc, node, argp : float
        Inclination, longitude of the ascending node, argument of pericentre (radians).
    mean_anomaly : float
        Mean anomaly at ``epoch`` (radians); for a hyperbola the hyperbolic mean anomaly
        (negative before pericentre).
    epoch : float
        Time of ``mean_anomaly`` (time unit of the run).
    mu_orbit : float, optional
        G (M_p + m_b) of the relative orbit; defaults to ``mu`` (body mass negligible).
    sign : float
        +1: the elements describe the perturber relative to the body; −1: they describe the body
        relative to the perturber (e.g. an asteroid's heliocentric elements with the Sun as perturber).
    """
    _check_mu(mu)
    mu_orbit = mu if mu_orbit is None else mu_orbit
    _check_mu(mu_orbit)
    values = np.array([a, e, inc, node, argp, mean_anomaly, epoch], dtype=float)
    require_finite("Kepler elements", values)
    if not np.all(np.isfinite(values)):
        raise ValueError(f"Kepler elements: expected finite numbers, got {values!r}.")
    if e < 0 or abs(e - 1.0) < 1e-12:
        raise ValueError(
            f"e: expected 0 ≤ e < 1 (ellipse) or e > 1 (hyperbola), got {e!r}; "
            "parabolic orbits are not supported, perturb e slightly."
        )
    if (e < 1 and a <= 0) or (e > 1 and a >= 0):
        raise ValueError(f"a: expected a > 0 for e < 1 and a < 0 for e > 1, got a={a!r}, e={e!r}.")
    if sign not in (1.0, -1.0):
        raise ValueError(f"sign: expected +1 or −1, got {sign!r}.")
    params = np.zeros(PARAM_SIZE)
    params[:9] = [mu_orbit, a, e, inc, node, argp, mean_anomaly, epoch, sign]
    params[K_MEAN_MOTION] = math.sqrt(mu_orbit / abs(a) ** 3)
    params[K_ROOT] = math.sqrt(abs((1.0 - e) * (1.0 + e)))
    # Perifocal → inertial: R3(−Ω) R1(−i) R3(−ω) (active rotations); columns P and Q.
    cw, sw, cn, sn, ci, si = (math.cos(argp), math.sin(argp), math.cos(node), math.sin(node),
                              math.cos(inc), math.sin(inc))
    params[K_P:K_P + 3] = sign * np.array([cn * cw - sn * sw * ci, sn * cw + cn * sw * ci, sw * si])
    params[K_Q:K_Q + 3] = sign * np.array([-cn * sw - sn * cw * ci, -sn * sw + cn * cw * ci, cw * si])
    return _Source(KIND_KEPLER, float(mu), params)


def fixed_source(mu, position):
    """A perturber at rest at ``position`` (inertial, relative to the body; length)."""
    _check_mu(mu)
    position = np.asarray(position, dtype=float)
    require_finite("position", position, "a finite non-zero 3-vector")
    if position.shape != (3,) or not np.all(np.isfinite(position)) or not np.any(position):
        raise ValueError(f"position: expected a finite non-zero 3-vector, got {position!r}.")
    params = np.zeros(PARAM_SIZE)
    params[:3] = position
    return _Source(KIND_FIXED, float(mu), params)


def sampled_source(mu, times, positions, velocities):
    """A perturber given by samples, interpolated by piecewise cubic Hermite polynomials.

    Parameters
    ----------
    mu : float
        G M_p (length³/time²).
    times : array_like, shape (N,)
        Strictly increasing sample times, N ≥ 2.
    positions, velocities : array_like, shape (N, 3)
        Perturber relative to the body, inertial frame (length, length/time).
    """
    _check_mu(mu)
    times = np.asarray(times, dtype=float)
    positions = np.asarray(positions, dtype=float)
    velocities = np.asarray(velocities, dtype=float)
    if times.ndim != 1 or times.size < 2 or not np.all(np.diff(times) > 0):
        raise ValueError(
            f"times: expected ≥ 2 strictly increasing sample times, got shape {times.shape}; sort them."
        )
    for name, arr in (("positions", positions), ("velocities", velocities)):
        require_finite(name, arr, "finite sampled values")
        if arr.shape != (times.size, 3) or not np.all(np.isfinite(arr)):
            raise ValueError(f"{name}: expected finite values of shape ({times.size}, 3), got {arr.shape}.")
    xv = np.hstack([positions, velocities])
    return _Source(KIND_SAMPLED, float(mu), np.zeros(PARAM_SIZE), times.copy(), xv)


#: Step of the central difference used when a callable gives no velocity, as a fraction of the
#: grid spacing: small enough that the O(δ⁴) truncation is below the Hermite error, large enough
#: that rounding (≈ ε|x|/δ) stays negligible.
FINITE_DIFFERENCE_FRACTION = 1e-2


def sampled_source_from_callable(mu, position_function, times, velocity_function=None):
    """Sample a Python callable onto a grid once, then interpolate it in numba (Hermite).

    Parameters
    ----------
    mu : float
        G M_p (length³/time²).
    position_function : callable
        ``f(t) -> (3,)`` position relative to the body, inertial frame.
    times : array_like
        Sample grid (strictly increasing). Choose the spacing from the Hermite error bound in the
        module docstring.
    velocity_function : callable, optional
        ``g(t) -> (3,)``; if absent the velocity is the 4-point central difference of f with step
        FINITE_DIFFERENCE_FRACTION × local spacing.
    """
    times = np.asarray(times, dtype=float)
    if times.ndim != 1 or times.size < 2 or not np.all(np.diff(times) > 0):
        raise ValueError(f"times: expected ≥ 2 strictly increasing sample times, got shape {times.shape}.")
    positions = np.array([np.asarray(position_function(t), dtype=float) for t in times])
    if velocity_function is not None:
        velocities = np.array([np.asarray(velocity_function(t), dtype=float) for t in times])
    else:
        spacing = np.gradient(times) * FINITE_DIFFERENCE_FRACTION
        velocities = np.empty_like(positions)
        for i, (t, d) in enumerate(zip(times, spacing)):
            f = [np.asarray(position_function(t + k * d), dtype=float) for k in (-2, -1, 1, 2)]
            velocities[i] = (f[0] - 8 * f[1] + 8 * f[2] - f[3]) / (12 * d)
    return sampled_source(mu, times, positions, velocities)


def pack_perturbers(sources, base=0):
    """Pack sources into one flat float array, to be placed at offset ``base`` of a model array.

    Layout: [k, row₀, …, row_{k−1}, samples…] with rows of PERTURBER_ROW = 2 + PARAM_SIZE floats
    [kind, μ, params]. A sampled source's params hold absolute indices (counting from the start of
    the model array) of its times and of its (count, 6) position/velocity block.
    """
    sources = list(sources)
    k = len(sources)
    rows = np.zeros((k, PERTURBER_ROW))
    tail = []
    offset = base + 1 + k * PERTURBER_ROW
    for i, src in enumerate(sources):
        if not isinstance(src, _Source):
            raise ValueError(
                f"sources[{i}]: expected a source from kepler_source / sampled_source / fixed_source, "
                f"got {type(src).__name__}."
            )
        rows[i, 0] = src.kind
        rows[i, 1] = src.mu
        rows[i, 2:] = src.params
        if src.kind == KIND_SAMPLED:
            count = src.times.size
            rows[i, 2] = offset
            rows[i, 3] = count
            rows[i, 4] = offset + count
            tail.extend([src.times, src.xv.ravel()])
            offset += 7 * count
    return np.concatenate([[float(k)], rows.ravel()] + tail)


def sampled_span(arr, base=0):
    """(start, end) of the time span on which every sampled source in the block at ``base`` is defined."""
    start, end = -np.inf, np.inf
    for i in range(int(arr[base])):
        row = base + 1 + i * PERTURBER_ROW
        if int(arr[row]) == KIND_SAMPLED:
            first, count = int(arr[row + 2]), int(arr[row + 3])
            start = max(start, arr[first])
            end = min(end, arr[first + count - 1])
    return start, end
