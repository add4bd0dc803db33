"""Variational equations of the DOP853 quaternion integrator: the STM and the moment-ratio sensitivities.

The state and parameters are those of ``docs/conventions.md`` ("State transition matrices"): the local
state x = (δθ, ω) with q = q_ref ⊗ exp(δθ/2), and p = (A/C, B/C) at fixed C. Along the trajectory of
the one set of equations (:func:`spinorbit.core.dynamics.equations.rhs_into`) the linearised equations are

    δθ̇ = δω − ω × δθ                                 (from q̇ = ½ q ⊗ (0, ω))
    δω̇x = ((B − C)/A) (ωz δωy + ωy δωz − δT_yz), cyclic in (x, y, z) with (A, B, C)

with the degree-2 tidal tensor T = Σ_k (3 μ_k / R_k⁵) r_k r_kᵀ of the perturbers (body-frame
positions r_k): the degree-2 torque is N_x = (C − B) T_yz (cyclic), so Euler's equations read
ω̇x = (B − C)(ωy ωz − T_yz)/A. A body rotation δθ moves a fixed inertial position by δr = r × δθ,
so δT = Σ 3μ/R⁵ (δr rᵀ + r δrᵀ) (R is unchanged). The parameter forcing is the derivative of
those ω̇ with respect to A = p₁ C and B = p₂ C.

Φ (36 numbers, row-major) and Ψ (12) ride along with (q, ω) in one 55-component DOP853 state, under
the same error control: each variational component gets the absolute tolerance rtol × (its row's
scale / its column's scale), with scale 1 for δθ and the parameters and |ω₀| for ω, so the step
size also keeps the STM accurate (tests/test_stm.py measures it against central differences).

Scope: rigid bodies whose figure is of degree 2 (``n_max`` = 2 in the model: the torque is then the
moments' own, and its derivatives above are complete). Degree-3/4 figures and the lunar interior
are refused with a clear error.
"""

import math

import numpy as np

from spinorbit.core.dynamics.equations import MODEL_PERTURBERS, STATE_SIZE, body_frame_xyz, rhs_into
from spinorbit.core.dynamics.validation import (
    check_step_budget,
    validate_output_times,
    validate_sampled_span,
    validate_state,
)
from spinorbit.core.integrators.dop853 import (
    DEFAULT_MAX_STEPS,
    dop853_integrate,
    never_singular,
    raise_for_engine_status,
    stats_record,
)
from spinorbit.core.integrators.quaternion import (
    default_atol,
    minimum_steps,
    renormalise_after_step,
    renormalise_output,
)
from spinorbit.core.jit import jit
from spinorbit.core.model.gravity_field import BODY_A, BODY_B, BODY_C, BODY_NMAX, FIG_THERMAL
from spinorbit.core.model.lunar_interior import has_interior
from spinorbit.core.model.perturbers import PERTURBER_ROW, perturber_position_xyz

LOCAL_SIZE = 6
PARAMETER_SIZE = 2
#: Offsets of Φ (6 × 6, row-major) and Ψ (6 × 2, row-major) in the augmented state.
Y_PHI = STATE_SIZE
Y_PSI = Y_PHI + LOCAL_SIZE * LOCAL_SIZE
AUGMENTED_SIZE = Y_PSI + LOCAL_SIZE * PARAMETER_SIZE


@jit(inline="always")
def weighted_body_position(t, q0, q1, q2, q3, model, k):
    """(x, y, z, 3μ/R⁵) of perturber k: its body-frame position and the weight of its tidal tensor."""
    row = MODEL_PERTURBERS + 1 + k * PERTURBER_ROW
    ix, iy, iz = perturber_position_xyz(t, model, row)
    x, y, z = body_frame_xyz(q0, q1, q2, q3, ix, iy, iz)
    rr = x * x + y * y + z * z
    return x, y, z, 3.0 * model[row + 1] / (rr * rr * math.sqrt(rr))


@jit(inline="always")
def tidal_tensor(t, q0, q1, q2, q3, model):
    """(T_xx, T_yy, T_zz, T_yz, T_zx, T_xy) of T = Σ 3μ/R⁵ r rᵀ over the perturbers (body frame)."""
    txx = tyy = tzz = tyz = tzx = txy = 0.0
    for k in range(int(model[MODEL_PERTURBERS])):
        x, y, z, w = weighted_body_position(t, q0, q1, q2, q3, model, k)
        txx += w * x * x
        tyy += w * y * y
        tzz += w * z * z
        tyz += w * y * z
        tzx += w * z * x
        txy += w * x * y
    return txx, tyy, tzz, tyz, tzx, txy


@jit(inline="always")
def tidal_variation(t, q0, q1, q2, q3, model, j):
    """(δT_yz, δT_zx, δT_xy) for a unit body rotation δθ = e_j (δr = r × e_j)."""
    dyz = dzx = dxy = 0.0
    for k in range(int(model[MODEL_PERTURBERS])):
        x, y, z, w = weighted_body_position(t, q0, q1, q2, q3, model, k)
        if j == 0:  # r × e_x = (0, z, −y)
            dx, dy, dz = 0.0, z, -y
        elif j == 1:  # r × e_y = (−z, 0, x)
            dx, dy, dz = -z, 0.0, x
        else:  # r × e_z = (y, −x, 0)
            dx, dy, dz = y, -x, 0.0
        dyz += w * (dy * z + y * dz)
        dzx += w * (dz * x + z * dx)
        dxy += w * (dx * y + x * dy)
    return dyz, dzx, dxy


@jit
def variational_rhs_into(t, y, model, dy):
    """d/dt of (q, ω, Φ, Ψ): the equations of motion and their linearisation (module docstring)."""
    rhs_into(t, y, model, dy)
    a_mom, b_mom, c_mom = model[BODY_A], model[BODY_B], model[BODY_C]
    q0, q1, q2, q3 = y[0], y[1], y[2], y[3]
    wx, wy, wz = y[4], y[5], y[6]
    has_torque = model[MODEL_PERTURBERS] > 0.0
    txx = tyy = tzz = tyz = tzx = txy = 0.0
    if has_torque:
        txx, tyy, tzz, tyz, tzx, txy = tidal_tensor(t, q0, q1, q2, q3, model)
    kx, ky, kz = (b_mom - c_mom) / a_mom, (c_mom - a_mom) / b_mom, (a_mom - b_mom) / c_mom
    # ∂ω̇/∂δθ: 3 × 3, from the tidal tensor's variation
    dtheta = np.zeros((3, 3))
    if has_torque:
        for j in range(3):
            dyz, dzx, dxy = tidal_variation(t, q0, q1, q2, q3, model, j)
            dtheta[0, j] = -kx * dyz
            dtheta[1, j] = -ky * dzx
            dtheta[2, j] = -kz * dxy
    # columns of Φ, then of Ψ: the same linear operator, Ψ with the parameter forcing added
    for col in range(LOCAL_SIZE + PARAMETER_SIZE):
        if col < LOCAL_SIZE:
            base, stride, c = Y_PHI, LOCAL_SIZE, col
        else:
            base, stride, c = Y_PSI, PARAMETER_SIZE, col - LOCAL_SIZE
        ax, ay, az = y[base + 0 * stride + c], y[base + 1 * stride + c], y[base + 2 * stride + c]
        bx, by, bz = y[base + 3 * stride + c], y[base + 4 * stride + c], y[base + 5 * stride + c]
        dy[base + 0 * stride + c] = bx - (wy * az - wz * ay)
        dy[base + 1 * stride + c] = by - (wz * ax - wx * az)
        dy[base + 2 * stride + c] = bz - (wx * ay - wy * ax)
        dy[base + 3 * stride + c] = kx * (wz * by + wy * bz) + dtheta[0, 0] * ax + dtheta[0, 1] * ay + dtheta[0, 2] * az
        dy[base + 4 * stride + c] = ky * (wx * bz + wz * bx) + dtheta[1, 0] * ax + dtheta[1, 1] * ay + dtheta[1, 2] * az
        dy[base + 5 * stride + c] = kz * (wy * bx + wx * by) + dtheta[2, 0] * ax + dtheta[2, 1] * ay + dtheta[2, 2] * az
    # parameter forcing: ω̇x = (B − C)(ωyωz − T_yz)/A etc., A = p₁C, B = p₂C
    ex, ey, ez = wy * wz - tyz, wz * wx - tzx, wx * wy - txy
    dy[Y_PSI + 3 * PARAMETER_SIZE + 0] += -c_mom * (b_mom - c_mom) * ex / (a_mom * a_mom)
    dy[Y_PSI + 4 * PARAMETER_SIZE + 0] += -c_mom * ey / b_mom
    dy[Y_PSI + 5 * PARAMETER_SIZE + 0] += ez
    dy[Y_PSI + 3 * PARAMETER_SIZE + 1] += c_mom * ex / a_mom
    dy[Y_PSI + 4 * PARAMETER_SIZE + 1] += -c_mom * (c_mom - a_mom) * ey / (b_mom * b_mom)
    dy[Y_PSI + 5 * PARAMETER_SIZE + 1] += -ez


@jit
def integrate_variational_kernel(y0, t0, t_out, model, rtol, atol, max_steps, first_step):
    """DOP853 on the 55-component augmented state (q, ω, Φ, Ψ); returns (ys (n, 55), stats)."""
    ys, stats, _, _ = dop853_integrate(variational_rhs_into, model, never_singular, renormalise_after_step,
                                       renormalise_output, y0, t0, t_out, rtol, atol, max_steps, False,
                                       first_step, 0.0)
    return ys, stats


def variational_atol(y0, rtol):
    """Absolute tolerances of the augmented state: the state's own, then rtol × row scale / column scale."""
    spin = max(float(np.linalg.norm(y0[4:7])), 1e-300)
    local_scale = np.array([1.0, 1.0, 1.0, spin, spin, spin])
    phi = rtol * local_scale[:, None] / local_scale[None, :]
    psi = rtol * np.repeat(local_scale[:, None], PARAMETER_SIZE, axis=1)
    return np.concatenate([default_atol(y0[:STATE_SIZE], rtol), phi.ravel(), psi.ravel()])


def check_degree_two_rigid_model(model):
    """Refuse models whose torque the variational equations do not linearise (degree > 2, interior, thermal)."""
    if has_interior(model):
        raise ValueError("the variational equations cover rigid bodies only; got a model with a lunar interior "
                         "block. Integrate the Moon with integrate_quaternion and difference it instead.")
    if model[FIG_THERMAL] > 0.0:  # the recoil's torque is not linearised: its sensitivities would be missing
        raise ValueError("the variational equations linearise the gravity torque only; got a model with a thermal "
                         "(YORP) block. Build the model without thermal=, or difference integrate_quaternion instead.")
    if int(model[BODY_NMAX]) != 2 and model[MODEL_PERTURBERS] > 0.0:
        raise ValueError(f"the variational equations linearise the degree-2 torque only; got a figure of degree "
                         f"{int(model[BODY_NMAX])}. Build the model without Stokes coefficients of degree 3–4.")


def integrate_variational(y0, t0, t_out, model, rtol=1e-10, max_steps=DEFAULT_MAX_STEPS, first_step=0.0,
                          return_stats=False):
    """Integrate (q, ω) with DOP853 together with its STM Φ and its sensitivities Ψ to (A/C, B/C).

    Parameters
    ----------
    y0 : array_like (7,)
        (q, ω): scalar-first quaternion (principal axes → inertial, normalised here) and body angular
        velocity on the principal axes (rad per time unit of the model).
    t0 : float
        Initial time.
    t_out : array_like (n,)
        Output times, strictly monotone away from t0.
    model : ndarray
        :func:`spinorbit.core.dynamics.equations.make_model` with a degree-2 figure.
    rtol : float
        Relative tolerance of the whole augmented state (tolerances: module docstring).
    max_steps, first_step, return_stats
        As in :func:`spinorbit.core.integrators.quaternion.integrate_quaternion`.

    Returns
    -------
    ys : (n, 7) ndarray
        (q, ω) at t_out.
    phi : (n, 6, 6) ndarray
        ∂(δθ, ω)(t)/∂(δθ, ω)(t0) (``docs/conventions.md``).
    psi : (n, 6, 2) ndarray
        ∂(δθ, ω)(t)/∂(A/C, B/C) at fixed C and fixed initial state.
    stats : dict, optional
    """
    model = np.ascontiguousarray(model, dtype=float)
    check_degree_two_rigid_model(model)
    state = validate_state(y0, STATE_SIZE)
    t0 = float(t0)
    t_out = validate_output_times(t0, t_out)
    if not (np.isfinite(rtol) and 1e-15 <= rtol < 1.0):
        raise ValueError(f"rtol: expected 1e-15 ≤ rtol < 1, got {rtol!r}; try 1e-10.")
    validate_sampled_span(model, t0, t_out)
    check_step_budget("integrate_variational", minimum_steps(state, t0, t_out[-1], rtol), max_steps,
                      "shorten the span or loosen rtol")
    y_aug = np.zeros(AUGMENTED_SIZE)
    y_aug[:STATE_SIZE] = state
    y_aug[Y_PHI:Y_PSI] = np.eye(LOCAL_SIZE).ravel()
    ys, stats = integrate_variational_kernel(y_aug, t0, t_out, model, float(rtol), variational_atol(state, rtol),
                                             int(max_steps), float(first_step))
    raise_for_engine_status(stats)
    phi = ys[:, Y_PHI:Y_PSI].reshape(-1, LOCAL_SIZE, LOCAL_SIZE)
    psi = ys[:, Y_PSI:].reshape(-1, LOCAL_SIZE, PARAMETER_SIZE)
    out = (ys[:, :STATE_SIZE].copy(), phi.copy(), psi.copy())
    return out + (stats_record(stats),) if return_stats else out
