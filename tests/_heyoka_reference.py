"""Independent reference for the torque-free tests and benchmark: heyoka's Taylor integrator.

The equations are the quaternion kinematics and Euler's equations in the body frame,
q̇ = ½ q ⊗ (0, ω), Ṁ = M × ω, ω = (a M_x, b M_y, c M_z) with a = 1/A etc. — nothing of the
canonical elements. In long double (64-bit mantissa on x86_64, ε ≈ 1.1e-19) at tolerance 1e-19
the reference is ~3 digits better than a double-precision result, which is what the comparison
at 1e-12 rad needs. The inverse moments are runtime parameters, so one compiled integrator serves
every body.
"""

from __future__ import annotations

import functools

import numpy as np

# Long-double tolerance: at the long-double unit roundoff, so the reference error stays well below
# the double-precision errors being measured.
REFERENCE_TOLERANCE = 1e-19


def _equations():
    import heyoka as hy

    qw, qx, qy, qz, mx, my, mz = hy.make_vars("qw", "qx", "qy", "qz", "mx", "my", "mz")
    a, b, c = hy.par[0], hy.par[1], hy.par[2]
    wx, wy, wz = a * mx, b * my, c * mz
    return [
        (qw, 0.5 * (-qx * wx - qy * wy - qz * wz)),
        (qx, 0.5 * (qw * wx + qy * wz - qz * wy)),
        (qy, 0.5 * (qw * wy - qx * wz + qz * wx)),
        (qz, 0.5 * (qw * wz + qx * wy - qy * wx)),
        (mx, my * wz - mz * wy),
        (my, mz * wx - mx * wz),
        (mz, mx * wy - my * wx),
    ]


@functools.lru_cache(maxsize=None)
def integrator(fp_type: str = "longdouble", tol: float = REFERENCE_TOLERANCE):
    """A compiled heyoka integrator (compact mode: compiles in seconds), reused across calls."""
    import heyoka as hy

    dtype = np.longdouble if fp_type == "longdouble" else np.float64
    state = np.zeros(7, dtype=dtype)
    state[0] = 1
    return hy.taylor_adaptive(
        _equations(),
        state,
        pars=np.ones(3, dtype=dtype),
        tol=dtype(tol),
        compact_mode=True,
        fp_type=dtype,
    )


def propagate(quaternion, momentum, moments, times, fp_type="longdouble", tol=REFERENCE_TOLERANCE):
    """Reference (q, M) at ``times`` (increasing, ≥ 0) from one state: ((T, 4), (T, 3)) long doubles."""
    ta = integrator(fp_type, tol)
    dtype = np.longdouble if fp_type == "longdouble" else np.float64
    ta.time = dtype(0)
    ta.state[:4] = np.asarray(quaternion, dtype=dtype)
    ta.state[4:] = np.asarray(momentum, dtype=dtype)
    ta.pars[:] = 1 / np.asarray(moments, dtype=dtype)
    grid = np.concatenate(([dtype(0)], np.asarray(times, dtype=dtype)))  # the grid starts at t = 0
    out = ta.propagate_grid(grid)[-1][1:]
    return out[:, :4], out[:, 4:]


def rotation_angle(q_ref, q):
    """Angle (rad) of the rotation between attitudes q_ref and q, rows of scalar-first quaternions."""
    q_ref = np.asarray(q_ref, dtype=np.longdouble)
    q_ref = q_ref / np.linalg.norm(q_ref.astype(np.float64), axis=-1, keepdims=True)
    q = np.asarray(q, dtype=np.longdouble)
    dot = np.abs(np.sum(q_ref * q, axis=-1))
    # |vector part of q_ref* ⊗ q| without cancellation: ‖q_ref·(q·q_ref) − q‖ form
    w = q_ref[..., 0:1] * q[..., 1:] - q[..., 0:1] * q_ref[..., 1:] - np.cross(q_ref[..., 1:], q[..., 1:])
    return (2.0 * np.arctan2(np.linalg.norm(w.astype(np.float64), axis=-1), dot.astype(np.float64)))
