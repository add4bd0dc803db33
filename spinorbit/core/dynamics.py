"""THE equations of motion of a perturbed rigid body in Euler parameters + body angular velocity.

State y = (q0, q1, q2, q3, ωx, ωy, ωz): q the scalar-first unit quaternion (body → inertial,
``docs/conventions.md``), ω the body-frame angular velocity (rad/time) on the principal axes with
moments A ≤ B ≤ C::

    q̇ = ½ q ⊗ (0, ω)
    I ω̇ = Iω × ω + N,   N = Σ_perturbers (∂U/∂r) × r     (gravity_field.py for U and the sign)

r is the perturber's position in the body frame, r = R r_inertial with R = M(q)ᵀ. Every back end
(the numba integrator, scipy's ``solve_ivp`` through :func:`scipy_rhs`, the benchmark peers) calls
:func:`rhs`; nothing else defines the dynamics.

**The model** is one plain tuple of arrays (numba caches functions of tuples; jitclasses cannot be
cached)::

    model = (body, stokes_c, stokes_s, kinds, mus, params, sample_t, sample_xv)

``body, stokes_c, stokes_s`` from :func:`gravity_field.make_body`; the rest from
:func:`perturbers.pack_perturbers`. Build it with :func:`make_model`. Any other integrator (the
canonical-element equations, a splitting scheme) takes the same tuple and calls
:func:`total_torque` / :func:`force_function`.

Energy: with time-independent perturbers, E = T − U (T = ½ ωᵀ I ω) is conserved, because
dT/dt = ω·N and dU/dt = (∂U/∂r)·(−ω × r) = ω·N (tested).
"""

import math

import numpy as np

from ._jit import jit
from .gravity_field import BODY_A, BODY_B, BODY_C, figure_force_function_and_gradient, make_body, torque_from_gradient
from .perturbers import pack_perturbers, perturber_position

STATE_SIZE = 7

# Positions of the arrays inside the model tuple.
MODEL_BODY, MODEL_STOKES_C, MODEL_STOKES_S = 0, 1, 2
MODEL_KINDS, MODEL_MUS, MODEL_PARAMS, MODEL_SAMPLE_T, MODEL_SAMPLE_XV = 3, 4, 5, 6, 7


def make_model(moments, sources=(), mass=0.0, reference_radius=1.0, stokes_c=None, stokes_s=None,
               normalized=False):
    """Build the model tuple from a body description and a list of perturber sources.

    Parameters
    ----------
    moments, mass, reference_radius, stokes_c, stokes_s, normalized
        As in :func:`spinorbit.core.gravity_field.make_body`.
    sources : sequence
        Perturber sources from :mod:`spinorbit.core.perturbers` (may be empty: torque-free).

    Returns
    -------
    tuple
        ``(body, stokes_c, stokes_s, kinds, mus, params, sample_t, sample_xv)``.
    """
    body, c, s = make_body(moments, mass, reference_radius, stokes_c, stokes_s, normalized)
    return (body, c, s) + tuple(pack_perturbers(sources))


@jit
def body_frame_position(q, r_inertial):
    """r_body = M(q)ᵀ r_inertial for a quaternion of any non-zero norm (divides by |q|²).

    Dividing by |q|² makes the right-hand side well defined at the RK stages, where q is off the unit
    sphere by the local error; the integrator renormalises after each step.
    """
    w, x, y, z = q[0], q[1], q[2], q[3]
    inv = 1.0 / (w * w + x * x + y * y + z * z)
    rx, ry, rz = r_inertial[0], r_inertial[1], r_inertial[2]
    out = np.empty(3)
    out[0] = inv * ((w * w + x * x - y * y - z * z) * rx + 2.0 * (x * y + w * z) * ry + 2.0 * (x * z - w * y) * rz)
    out[1] = inv * (2.0 * (x * y - w * z) * rx + (w * w - x * x + y * y - z * z) * ry + 2.0 * (y * z + w * x) * rz)
    out[2] = inv * (2.0 * (x * z + w * y) * rx + 2.0 * (y * z - w * x) * ry + (w * w - x * x - y * y + z * z) * rz)
    return out


@jit
def total_force_function_and_torque(t, q, model):
    """U (energy) and body-frame torque N (energy) summed over all perturbers at time t, attitude q."""
    body, stokes_c, stokes_s = model[0], model[1], model[2]
    kinds, mus, params, sample_t, sample_xv = model[3], model[4], model[5], model[6], model[7]
    u = 0.0
    torque = np.zeros(3)
    for k in range(kinds.shape[0]):
        r_inertial = perturber_position(t, k, kinds, params, sample_t, sample_xv)
        r = body_frame_position(q, r_inertial)
        u_k, grad = figure_force_function_and_gradient(r, mus[k], body, stokes_c, stokes_s)
        u += u_k
        torque += torque_from_gradient(r, grad)
    return u, torque


@jit
def total_torque(t, q, model):
    """Body-frame torque N(t, q) of all perturbers (energy units)."""
    return total_force_function_and_torque(t, q, model)[1]


@jit
def force_function(t, q, model):
    """Force function U(t, q) of all perturbers (energy units; U = −potential energy)."""
    return total_force_function_and_torque(t, q, model)[0]


@jit
def rhs_into(t, y, model, dy):
    """Write dy/dt into ``dy`` (no allocation of the result; the integrator's inner call)."""
    body = model[0]
    a_mom, b_mom, c_mom = body[BODY_A], body[BODY_B], body[BODY_C]
    q = y[0:4]
    wx, wy, wz = y[4], y[5], y[6]
    if model[3].shape[0] > 0:
        torque = total_torque(t, q, model)
        nx, ny, nz = torque[0], torque[1], torque[2]
    else:
        nx = ny = nz = 0.0
    # q̇ = ½ q ⊗ (0, ω)
    dy[0] = 0.5 * (-q[1] * wx - q[2] * wy - q[3] * wz)
    dy[1] = 0.5 * (q[0] * wx + q[2] * wz - q[3] * wy)
    dy[2] = 0.5 * (q[0] * wy - q[1] * wz + q[3] * wx)
    dy[3] = 0.5 * (q[0] * wz + q[1] * wy - q[2] * wx)
    # Euler: A ω̇x = (B − C) ωy ωz + Nx, cyclic.
    dy[4] = ((b_mom - c_mom) * wy * wz + nx) / a_mom
    dy[5] = ((c_mom - a_mom) * wz * wx + ny) / b_mom
    dy[6] = ((a_mom - b_mom) * wx * wy + nz) / c_mom


@jit
def rhs(t, y, model):
    """dy/dt of the state y = (q, ω) at time t: the one definition of the dynamics."""
    dy = np.empty(STATE_SIZE)
    rhs_into(t, y, model, dy)
    return dy


@jit
def kinetic_energy(y, model):
    """T = ½ ωᵀ I ω (energy)."""
    body = model[0]
    return 0.5 * (body[BODY_A] * y[4] ** 2 + body[BODY_B] * y[5] ** 2 + body[BODY_C] * y[6] ** 2)


@jit
def total_energy(t, y, model):
    """E = T − U (energy), conserved when the perturbers are at rest."""
    return kinetic_energy(y, model) - force_function(t, y[0:4], model)


@jit
def inertial_angular_momentum(y, model):
    """Angular momentum M(q) I ω in the inertial frame (mass·length²/time)."""
    body = model[0]
    q = y[0:4]
    w, x, yy, z = q[0], q[1], q[2], q[3]
    inv = 1.0 / (w * w + x * x + yy * yy + z * z)
    lx, ly, lz = body[BODY_A] * y[4], body[BODY_B] * y[5], body[BODY_C] * y[6]
    out = np.empty(3)
    out[0] = inv * ((w * w + x * x - yy * yy - z * z) * lx + 2.0 * (x * yy - w * z) * ly + 2.0 * (x * z + w * yy) * lz)
    out[1] = inv * (2.0 * (x * yy + w * z) * lx + (w * w - x * x + yy * yy - z * z) * ly + 2.0 * (yy * z - w * x) * lz)
    out[2] = inv * (2.0 * (x * z - w * yy) * lx + 2.0 * (yy * z + w * x) * ly + (w * w - x * x - yy * yy + z * z) * lz)
    return out


def scipy_rhs(model):
    """A ``fun(t, y)`` for ``scipy.integrate.solve_ivp`` that calls the compiled :func:`rhs`.

    The Python-level call per evaluation is what scipy's solvers cost anyway; the dynamics are the
    same compiled definition the numba integrator uses.
    """

    def fun(t, y):
        return rhs(float(t), np.ascontiguousarray(y, dtype=float), model)

    return fun


def validate_state(y0):
    """Check an initial state (q, ω) and return it as a float array with q normalised.

    Raises
    ------
    ValueError
        Wrong shape, NaN/inf, or a zero quaternion.
    """
    y0 = np.asarray(y0, dtype=float)
    if y0.shape != (STATE_SIZE,):
        raise ValueError(
            f"y0: expected 7 numbers (q0, q1, q2, q3, ωx, ωy, ωz), got shape {y0.shape}."
        )
    if not np.all(np.isfinite(y0)):
        raise ValueError(f"y0: expected finite numbers, got {y0.tolist()}; check the initial state for NaN/inf.")
    norm = math.sqrt(float(np.dot(y0[:4], y0[:4])))
    if norm < 1e-150:
        raise ValueError(
            f"y0: expected a non-zero quaternion in y0[0:4], got {y0[:4].tolist()}; "
            "use (1, 0, 0, 0) for the identity attitude."
        )
    y0 = y0.copy()
    y0[:4] /= norm
    return y0
