"""A Hyperion-like chaotic tumbler: the scene, its Lyapunov time and forward–backward return errors.

Scene (a documented variant of Wisdom, Peale & Mignard 1984, Icarus 58, 137): principal moments
(A, B, C) = (0.60, 0.86, 1.00), so (B − A)/C = 0.26 and ω₀² = 3(B − A)/C = 0.78 as in their Hyperion
model; Saturn a point mass on a Keplerian orbit with e = 0.1, a = 1, G M = 1 (mean motion n = 1,
orbital period 2π; the body's own mass is negligible). Unlike their planar one-degree-of-freedom
model, the full 3-D rotation is integrated: the spin starts at 1.5 n nearly along C (0.03 n and
0.02 n on A and B), with C tilted 0.01 rad from the orbit normal, and the attitude instability of the
chaotic zone tips it out of the plane within a few orbits.

Sensitivity is measured two ways:

* the **Lyapunov time** T_L from two nearby states (Benettin et al. 1980: renormalise their
  separation to δ₀ after every orbit and average the log growth), with the quaternion DOP853 at
  rtol 1e-13;
* the **return error** of a forward–backward run (forward T, then backward T from the end state,
  distance to the start), for each integrator. Errors committed along the way are amplified by up to
  exp(T/T_L), so the return error ≈ ε · exp(T/T_L) with ε the per-run error of the method
  (≈ its tolerance for DOP853, rounding for a symmetric splitting, which is time-reversible).
"""

from __future__ import annotations

import math

import numpy as np

from spinorbit.core.dynamics.equations import make_model
from spinorbit.core.integrators.handover import integrate_with_handover
from spinorbit.core.integrators.quaternion import integrate_quaternion
from spinorbit.core.integrators.splitting import integrate_splitting
from spinorbit.core.model.perturbers import kepler_source
from spinorbit.core.math.rotations import rotation_angle_between_many

MOMENTS = (0.60, 0.86, 1.00)
ECCENTRICITY = 0.1
ORBIT = 2.0 * math.pi  # orbital period (n = 1)
TILT = 0.01  # rad, C axis from the orbit normal at t = 0
OMEGA0 = (0.03, 0.02, 1.5)  # body angular velocity at t = 0, in units of n


def model():
    """Model array: the body and Saturn (G M = 1, a = 1, e = 0.1, pericentre at t = 0, orbit in xy)."""
    return make_model(MOMENTS, [kepler_source(1.0, 1.0, ECCENTRICITY, 0.0, 0.0, 0.0, 0.0)])


def initial_state():
    q = np.array([math.cos(TILT / 2), math.sin(TILT / 2), 0.0, 0.0])
    return np.r_[q, OMEGA0]


def distance(y, z):
    """Rotation angle between the attitudes (rad) + |Δω| / n: one number for a state difference."""
    angle = rotation_angle_between_many(np.ascontiguousarray(y[None, :4]), np.ascontiguousarray(z[None, :4]))[0]
    return float(angle) + float(np.linalg.norm(y[4:] - z[4:]))


def lyapunov_time(n_orbits, offset, rtol=1e-13, m=None, y0=None):
    """T_L = 1/λ (time unit) from two states ``offset`` apart, renormalised once per orbit.

    Parameters
    ----------
    n_orbits : int
        Number of renormalisations (orbits averaged over).
    offset : (7,) ndarray
        Initial separation of the second state (its ``distance`` is δ₀, kept after each orbit).
    """
    m = model() if m is None else m
    ya = initial_state() if y0 is None else np.array(y0, float)
    yb = ya + offset
    yb[:4] /= np.linalg.norm(yb[:4])
    d0 = distance(ya, yb)
    log_growth, t = 0.0, 0.0
    for _ in range(n_orbits):
        a = integrate_quaternion(ya, t, [t + ORBIT], m, rtol=rtol)[0]
        b = integrate_quaternion(yb, t, [t + ORBIT], m, rtol=rtol)[0]
        if a[:4] @ b[:4] < 0:  # same rotation, other sign of q
            b[:4] = -b[:4]
        d = distance(a, b)
        log_growth += math.log(d / d0)
        yb = a + (b - a) * (d0 / d)
        yb[:4] /= np.linalg.norm(yb[:4])
        ya, t = a, t + ORBIT
    return t / log_growth


INTEGRATORS = {
    "DOP853 (quaternion)": lambda y, t0, t1, m, rtol: integrate_quaternion(y, t0, [t1], m, rtol=rtol)[0],
    "elements (hand-over)": lambda y, t0, t1, m, rtol: integrate_with_handover(y, t0, [t1], m, rtol=rtol)[0][0],
    # a fixed step (100 per orbit, ≈ 70 per turn at 1.5 n); rtol is not used
    "SABA3 splitting": lambda y, t0, t1, m, rtol: integrate_splitting(y, t0, [t1], m, ORBIT / 100, "saba3")[0],
}


def return_error(name, span, rtol=1e-12, m=None):
    """Distance between the start and the end of a run forward ``span`` then backward ``span``."""
    m = model() if m is None else m
    run = INTEGRATORS[name]
    y0 = initial_state()
    forward = run(y0, 0.0, span, m, rtol)
    back = run(forward, span, 0.0, m, rtol)
    return distance(back, y0)


def exponential_fit(spans, errors):
    """Least-squares fit log(error) = log(ε) + T/τ; returns (ε, τ)."""
    slope, intercept = np.polyfit(np.asarray(spans), np.log(np.asarray(errors)), 1)
    return math.exp(intercept), 1.0 / slope
