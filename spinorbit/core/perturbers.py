"""Where the perturbing point masses are: numba-evaluable position sources.

**Body-centric convention.** Every source returns the position (and velocity) of a perturber
*relative to the rotating body's centre of mass*, in the inertial frame (the same frame the
quaternion q refers to). For a Sun–asteroid pair described by the asteroid's heliocentric elements,
pass ``sign=-1`` to :func:`kepler_source` (the Sun is at minus the asteroid's heliocentric position).

A set of perturbers is carried as plain arrays (numba cannot cache jitclasses)::

    kinds   int64 (k,)        KIND_KEPLER, KIND_SAMPLED or KIND_FIXED
    mus     float (k,)        G M_p of each perturber (length³/time²)
    params  float (k, PARAM_SIZE)   per-kind parameters, see the KIND_* constants
    sample_t   float (N,)     sample times of all sampled sources, concatenated
    sample_xv  float (N, 6)   positions and velocities at those times

Build them with :func:`kepler_source`, :func:`sampled_source`, :func:`sampled_source_from_callable`,
:func:`fixed_source` and :func:`pack_perturbers`.

Kinds:

- ``KIND_KEPLER`` params = [μ_orbit, a, e, i, Ω, ω, M₀, t₀, sign]: a two-body orbit of the relative
  position (a < 0 and e > 1 for a hyperbola, angles in radians, M₀ the mean anomaly at t₀). Kepler's
  equation is solved by Newton's method safeguarded by bisection on a bracket that always contains
  the root, so it converges for every e ≠ 1 (parabolas are rejected by the builder).
- ``KIND_SAMPLED`` params = [first index, count]: piecewise cubic Hermite interpolation of positions
  and velocities. The interpolation error on an interval of length h is at most
  h⁴/384 · max|x⁽⁴⁾| (position); for a Keplerian orbit sampled n_s times per orbit near a circular
  orbit of radius a this is about a (2π/n_s)⁴/384. Outside the sampled span the kernel returns NaN;
  the public integrator checks the span before it starts.
- ``KIND_FIXED`` params = [x, y, z]: a perturber at rest (used for the energy-balance test).
"""

import math

import numpy as np

from ._jit import jit

KIND_KEPLER = 0
KIND_SAMPLED = 1
KIND_FIXED = 2
PARAM_SIZE = 9

#: Relative convergence threshold of the Kepler solver: a few ulps of the anomaly.
KEPLER_TOLERANCE = 4.0 * np.finfo(float).eps
#: Iteration cap; safeguarded Newton needs < 10 in practice, bisection alone < 110 in double.
KEPLER_MAX_ITERATIONS = 200


@jit
def _x_minus_sin(x):
    """x − sin x without cancellation for small |x| (series to x¹⁵, error < ε for |x| < 0.5)."""
    if abs(x) >= 0.5:
        return x - math.sin(x)
    x2 = x * x
    term = x * x2 / 6.0
    total = term
    for k in range(2, 8):
        term *= -x2 / ((2 * k) * (2 * k + 1))
        total += term
    return total


@jit
def _sinh_minus_x(x):
    """sinh x − x without cancellation for small |x| (series, error < ε for |x| < 0.5)."""
    if abs(x) >= 0.5:
        return math.sinh(x) - x
    x2 = x * x
    term = x * x2 / 6.0
    total = term
    for k in range(2, 8):
        term *= x2 / ((2 * k) * (2 * k + 1))
        total += term
    return total


@jit
def solve_kepler_elliptic(mean_anomaly, e):
    """Eccentric anomaly E with E − e sin E = M, 0 ≤ e < 1 (radians).

    M is reduced to [−π, π]; the root lies in [M − e, M + e] (since |E − M| = e|sin E| ≤ e) and
    f(E) = E − e sin E − M is monotone, so Newton steps are kept inside a shrinking bracket and
    replaced by bisection when they leave it: convergence for every e < 1, including e → 1, M → 0.
    The returned E is continuous with the unreduced M (the reduction's multiple of 2π is added back).
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
    for _ in range(KEPLER_MAX_ITERATIONS):
        # E − e sin E = (1 − e)E + e(E − sin E): no cancellation near e → 1, E → 0.
        f = (1.0 - e) * x + e * _x_minus_sin(x) - m
        if f > 0.0:
            hi = x
        else:
            lo = x
        fp = (1.0 - e) + e * 2.0 * math.sin(0.5 * x) ** 2  # 1 − e cos E, accurately
        x_new = x - f / fp if fp > 0.0 else 0.5 * (lo + hi)
        if not (lo <= x_new <= hi):
            x_new = 0.5 * (lo + hi)
        if abs(x_new - x) <= KEPLER_TOLERANCE * max(1.0, abs(x_new)):
            x = x_new
            break
        x = x_new
    return x + turns * two_pi


@jit
def solve_kepler_hyperbolic(mean_anomaly, e):
    """Hyperbolic anomaly H with e sinh H − H = M, e > 1.

    For M > 0 the root lies in [asinh(M/e), asinh(M/(e − 1))] (from sinh H ≥ H ≥ 0); the function
    is monotone, so safeguarded Newton as in :func:`solve_kepler_elliptic` converges for all e > 1.
    """
    m = abs(mean_anomaly)
    sgn = 1.0 if mean_anomaly >= 0.0 else -1.0
    if m == 0.0:
        return 0.0
    lo = math.asinh(m / e)
    hi = math.asinh(m / (e - 1.0))
    x = lo
    for _ in range(KEPLER_MAX_ITERATIONS):
        # e sinh H − H = (e − 1)H + e(sinh H − H): no cancellation near e → 1, H → 0.
        f = (e - 1.0) * x + e * _sinh_minus_x(x) - m
        if f > 0.0:
            hi = x
        else:
            lo = x
        fp = (e - 1.0) + e * 2.0 * math.sinh(0.5 * x) ** 2  # e cosh H − 1, accurately
        x_new = x - f / fp
        if not (lo <= x_new <= hi):
            x_new = 0.5 * (lo + hi)
        if abs(x_new - x) <= KEPLER_TOLERANCE * max(1.0, abs(x_new)):
            x = x_new
            break
        x = x_new
    return sgn * x


@jit
def kepler_state(t, params):
    """Position and velocity (inertial) of a KIND_KEPLER source at time t → (6,) array."""
    mu, a, e = params[0], params[1], params[2]
    inc, node, argp, m0, t0, sign = params[3], params[4], params[5], params[6], params[7], params[8]
    if e < 1.0:
        n = math.sqrt(mu / (a * a * a))
        big_e = solve_kepler_elliptic(m0 + n * (t - t0), e)
        ce, se = math.cos(big_e), math.sin(big_e)
        root = math.sqrt((1.0 - e) * (1.0 + e))
        rate = n / (1.0 - e * ce)  # dE/dt
        px = a * (ce - e)
        py = a * root * se
        vx = -a * se * rate
        vy = a * root * ce * rate
    else:
        abs_a = -a
        n = math.sqrt(mu / (abs_a * abs_a * abs_a))
        big_h = solve_kepler_hyperbolic(m0 + n * (t - t0), e)
        ch, sh = math.cosh(big_h), math.sinh(big_h)
        root = math.sqrt((e - 1.0) * (e + 1.0))
        rate = n / (e * ch - 1.0)  # dH/dt
        px = abs_a * (e - ch)
        py = abs_a * root * sh
        vx = -abs_a * sh * rate
        vy = abs_a * root * ch * rate
    # Perifocal → inertial: R3(−Ω) R1(−i) R3(−ω) (active rotations).
    cw, sw = math.cos(argp), math.sin(argp)
    cn, sn = math.cos(node), math.sin(node)
    ci, si = math.cos(inc), math.sin(inc)
    p1 = cn * cw - sn * sw * ci
    p2 = sn * cw + cn * sw * ci
    p3 = sw * si
    q1 = -cn * sw - sn * cw * ci
    q2 = -sn * sw + cn * cw * ci
    q3 = cw * si
    out = np.empty(6)
    out[0] = sign * (p1 * px + q1 * py)
    out[1] = sign * (p2 * px + q2 * py)
    out[2] = sign * (p3 * px + q3 * py)
    out[3] = sign * (p1 * vx + q1 * vy)
    out[4] = sign * (p2 * vx + q2 * vy)
    out[5] = sign * (p3 * vx + q3 * vy)
    return out


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
    # Binary search for the interval [times[i], times[i+1]] containing t.
    lo = 0
    hi = n - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if times[mid] <= t:
            lo = mid
        else:
            hi = mid
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


@jit
def perturber_state(t, index, kinds, params, sample_t, sample_xv):
    """Position and velocity (6,) of perturber ``index`` relative to the body, inertial frame."""
    kind = kinds[index]
    p = params[index]
    if kind == KIND_KEPLER:
        return kepler_state(t, p)
    if kind == KIND_SAMPLED:
        first = int(p[0])
        count = int(p[1])
        return hermite_state(t, sample_t[first:first + count], sample_xv[first:first + count])
    out = np.zeros(6)
    out[0] = p[0]
    out[1] = p[1]
    out[2] = p[2]
    return out


@jit
def perturber_position(t, index, kinds, params, sample_t, sample_xv):
    """Position (3,) of perturber ``index`` relative to the body (inertial frame)."""
    return perturber_state(t, index, kinds, params, sample_t, sample_xv)[:3]


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
    params = np.zeros(9)
    params[:] = [mu_orbit, a, e, inc, node, argp, mean_anomaly, epoch, sign]
    return _Source(KIND_KEPLER, float(mu), params)


def fixed_source(mu, position):
    """A perturber at rest at ``position`` (inertial, relative to the body; length)."""
    _check_mu(mu)
    position = np.asarray(position, dtype=float)
    if position.shape != (3,) or not np.all(np.isfinite(position)) or not np.any(position):
        raise ValueError(f"position: expected a finite non-zero 3-vector, got {position!r}.")
    params = np.zeros(9)
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
        if arr.shape != (times.size, 3) or not np.all(np.isfinite(arr)):
            raise ValueError(f"{name}: expected finite values of shape ({times.size}, 3), got {arr.shape}.")
    xv = np.hstack([positions, velocities])
    return _Source(KIND_SAMPLED, float(mu), np.zeros(9), times.copy(), xv)


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


def pack_perturbers(sources):
    """Pack a list of sources into (kinds, mus, params, sample_t, sample_xv) for the kernels."""
    sources = list(sources)
    k = len(sources)
    kinds = np.zeros(k, dtype=np.int64)
    mus = np.zeros(k)
    params = np.zeros((k, PARAM_SIZE))
    times, xvs = [], []
    offset = 0
    for i, src in enumerate(sources):
        if not isinstance(src, _Source):
            raise ValueError(
                f"sources[{i}]: expected a source from kepler_source / sampled_source / fixed_source, "
                f"got {type(src).__name__}."
            )
        kinds[i] = src.kind
        mus[i] = src.mu
        params[i] = src.params
        if src.kind == KIND_SAMPLED:
            params[i, 0] = offset
            params[i, 1] = src.times.size
            times.append(src.times)
            xvs.append(src.xv)
            offset += src.times.size
    sample_t = np.concatenate(times) if times else np.zeros(1)
    sample_xv = np.vstack(xvs) if xvs else np.zeros((1, 6))
    return kinds, mus, params, sample_t, sample_xv


def sampled_span(kinds, params, sample_t):
    """(start, end) of the time span on which every sampled source is defined (±inf if none)."""
    start, end = -np.inf, np.inf
    for kind, p in zip(kinds, params):
        if kind == KIND_SAMPLED:
            first, count = int(p[0]), int(p[1])
            start = max(start, sample_t[first])
            end = min(end, sample_t[first + count - 1])
    return start, end
