"""Peer of the binary propagator: the order-2 full two-body problem written directly in heyoka.

Nothing of spinorbit.core.binary is used: the mutual potential is written as point mass plus each
body's MacCullagh term (the classical second-order full two-body potential, e.g. Scheeres 2009,
CeMDA 104, 103, eq. 24 truncated at order 2),

    U = G m_A m_B / R + G m_B (tr I_A − 3 r̂_Aᵀ I_A r̂_A) / 2R³ + G m_A (tr I_B − 3 r̂_Bᵀ I_B r̂_B) / 2R³,

with r_A = M(q_A)ᵀ R and r_B = M(q_B)ᵀ R. The force on B is heyoka's symbolic ∂U/∂R; the torques are
the closed forms N_A = (3 G m_B/R⁵) r_A × I_A r_A and N_B = (3 G m_A/R⁵) r_B × I_B r_B on each body's
axes (the MacCullagh torque is even in r). Principal (diagonal) inertia tensors.

heyoka's error control scales by the largest state component, so the equations are written in
units of the initial separation R₀, the total mass M and 1/n₀ = √(R₀³/G M): every component is
then of order one. :func:`propagate` converts in and out (SI states of the package's layout).
"""

from __future__ import annotations

import functools
import math

import numpy as np


def _equations():
    import heyoka as hy

    names = ["x", "y", "z", "vx", "vy", "vz", "a0", "a1", "a2", "a3", "ax", "ay", "az",
             "b0", "b1", "b2", "b3", "bx", "by", "bz"]
    v = dict(zip(names, hy.make_vars(*names)))
    # Parameters: m_A, m_B (in M), then A, B, C of each body (in M R₀²); G = 1 in these units.
    m_a, m_b = hy.par[0], hy.par[1]
    moments_a = [hy.par[2], hy.par[3], hy.par[4]]
    moments_b = [hy.par[5], hy.par[6], hy.par[7]]

    def matrix(q0, q1, q2, q3):  # body → inertial, unit q assumed (heyoka keeps |q| = 1 to its tolerance)
        return [[1 - 2 * (q2 * q2 + q3 * q3), 2 * (q1 * q2 - q0 * q3), 2 * (q1 * q3 + q0 * q2)],
                [2 * (q1 * q2 + q0 * q3), 1 - 2 * (q1 * q1 + q3 * q3), 2 * (q2 * q3 - q0 * q1)],
                [2 * (q1 * q3 - q0 * q2), 2 * (q2 * q3 + q0 * q1), 1 - 2 * (q1 * q1 + q2 * q2)]]

    position = [v["x"], v["y"], v["z"]]
    r2 = position[0] ** 2 + position[1] ** 2 + position[2] ** 2
    r = hy.sqrt(r2)
    m_qa = matrix(v["a0"], v["a1"], v["a2"], v["a3"])
    m_qb = matrix(v["b0"], v["b1"], v["b2"], v["b3"])
    r_a = [sum(m_qa[i][k] * position[i] for i in range(3)) for k in range(3)]
    r_b = [sum(m_qb[i][k] * position[i] for i in range(3)) for k in range(3)]

    def maccullagh(moments, rb):
        trace = moments[0] + moments[1] + moments[2]
        quadratic = moments[0] * rb[0] ** 2 + moments[1] * rb[1] ** 2 + moments[2] * rb[2] ** 2
        return (trace - 3 * quadratic / r2) / (2 * r2 * r)

    potential = m_a * m_b / r + m_b * maccullagh(moments_a, r_a) + m_a * maccullagh(moments_b, r_b)
    inverse_reduced = 1 / m_a + 1 / m_b
    equations = [(position[i], v[n]) for i, n in enumerate(("vx", "vy", "vz"))]
    equations += [(v[n], inverse_reduced * hy.diff(potential, position[i])) for i, n in enumerate(("vx", "vy", "vz"))]

    def rotation(prefix, moments, rb, other_mass):
        q0, q1, q2, q3 = (v[f"{prefix}{k}"] for k in range(4))
        wx, wy, wz = (v[f"{prefix}{k}"] for k in ("x", "y", "z"))
        scale = 3 * other_mass / (r2 * r2 * r)
        ir = [moments[k] * rb[k] for k in range(3)]
        torque = [scale * (rb[1] * ir[2] - rb[2] * ir[1]), scale * (rb[2] * ir[0] - rb[0] * ir[2]),
                  scale * (rb[0] * ir[1] - rb[1] * ir[0])]
        w = [wx, wy, wz]
        lw = [moments[k] * w[k] for k in range(3)]
        gyro = [lw[1] * wz - lw[2] * wy, lw[2] * wx - lw[0] * wz, lw[0] * wy - lw[1] * wx]
        return [
            (q0, 0.5 * (-q1 * wx - q2 * wy - q3 * wz)),
            (q1, 0.5 * (q0 * wx + q2 * wz - q3 * wy)),
            (q2, 0.5 * (q0 * wy - q1 * wz + q3 * wx)),
            (q3, 0.5 * (q0 * wz + q1 * wy - q2 * wx)),
            (wx, (gyro[0] + torque[0]) / moments[0]),
            (wy, (gyro[1] + torque[1]) / moments[1]),
            (wz, (gyro[2] + torque[2]) / moments[2]),
        ]

    equations += rotation("a", moments_a, r_a, m_b)
    equations += rotation("b", moments_b, r_b, m_a)
    return equations


@functools.lru_cache(maxsize=None)
def integrator(tol: float, compact_mode: bool = True, fp_type: str = "double"):
    """A compiled heyoka integrator of the order-2 binary (double or long double), reused across calls."""
    import heyoka as hy

    dtype = np.longdouble if fp_type == "longdouble" else np.float64
    state = np.zeros(20, dtype=dtype)
    state[0] = 1.0
    state[6] = state[13] = 1.0
    return hy.taylor_adaptive(_equations(), state, pars=np.ones(8, dtype=dtype), tol=dtype(tol),
                              compact_mode=compact_mode, fp_type=dtype)


def scales(masses, r0, g):
    """(length, time, mass) units of the heyoka formulation: R₀, 1/n₀, M."""
    total = sum(masses)
    return r0, math.sqrt(r0 ** 3 / (g * total)), total


def set_state(ta, y_si, masses, moments_a, moments_b, g, dtype=np.float64):
    """Load the package's SI state and the bodies into heyoka; returns the (length, time) units."""
    length, time, mass = scales(masses, float(np.linalg.norm(y_si[:3])), g)
    y = np.array(y_si, dtype=dtype)
    y[0:3] /= length
    y[3:6] *= time / length
    y[10:13] *= time
    y[17:20] *= time
    ta.state[:] = y
    ta.time = dtype(0.0)
    ta.pars[:] = np.concatenate([[masses[0] / mass, masses[1] / mass], np.asarray(moments_a) / (mass * length ** 2),
                                 np.asarray(moments_b) / (mass * length ** 2)]).astype(dtype)
    return length, time


def to_si(rows, length, time):
    out = np.array(rows, dtype=float)
    out[..., 0:3] *= length
    out[..., 3:6] *= length / time
    out[..., 10:13] /= time
    out[..., 17:20] /= time
    return out


def propagate(y_si, times_s, masses, moments_a, moments_b, g, tol=1e-15, compact_mode=True, fp_type="double"):
    """States (n, 20) SI at ``times_s`` (increasing, > 0) from the SI state ``y_si``, quaternions renormalised.

    With ``fp_type="longdouble"`` the run is in x86 extended precision (ε ≈ 1.1e-19) and the result is
    rounded to double at the end: a reference for double-precision runs.
    """
    dtype = np.longdouble if fp_type == "longdouble" else np.float64
    ta = integrator(tol, compact_mode, fp_type)
    length, time = set_state(ta, y_si, masses, moments_a, moments_b, g, dtype)
    grid = np.concatenate(([0.0], np.asarray(times_s, dtype=float) / time)).astype(dtype)
    out = ta.propagate_grid(grid)[-1][1:].astype(np.float64)
    out = to_si(out, length, time)
    for offset in (6, 13):
        out[:, offset:offset + 4] /= np.linalg.norm(out[:, offset:offset + 4], axis=1, keepdims=True)
    return out
