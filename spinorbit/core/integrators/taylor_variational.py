"""Variational equations of the Taylor integrator: the STM and the moment-ratio sensitivities by recurrences.

The state, the parameters and the linearised equations are those of
:mod:`spinorbit.core.integrators.variational` (``docs/conventions.md``, "State transition matrices"):
x = (δθ, ω) with q = q_ref ⊗ exp(δθ/2), p = (A/C, B/C) at fixed C, and

    δθ̇ = δω − ω × δθ,   δω̇ = K(ω) δω + D(T) δθ,   Ψ̇ = J Ψ + F(ω, T)

where T = Σ 3μ/R⁵ r rᵀ is the degree-2 tidal tensor in the body frame. For a body rotation δθ = e_j a
fixed inertial position moves by δr = r × e_j, so δT = T E_j − E_j T (E_j = [e_j]×): the variation of
T is linear in T itself, and D(T) is linear in T's six components.

Instead of integrating these at stages, their Taylor coefficients are generated order by order
(Jorba & Zou 2005, Exp. Math. 14, 99), like the state's in
:mod:`spinorbit.core.integrators.taylor_recurrences`. The system is linear in (Φ, Ψ) with coefficients
J(t) that are polynomials in the series of ω and T, so with the state's series known

    Φ^[k+1] = (1/(k+1)) Σ_{j≤k} J^[j] Φ^[k−j],   Ψ^[k+1] = (1/(k+1)) (Σ_{j≤k} J^[j] Ψ^[k−j] + F^[k]).

T's series is built from the rows the state's recurrence already fills: each perturber's body-frame
ρ = |r|⁻⁵ᐟ² r_body, whose pair products are |r|⁻⁵ r rᵀ (the |r|⁻⁵ᐟ² comes from the truncated orbit
series, as in the state's torque).

The driver is the Taylor integrator's rule (order and step of heyoka, Biscani & Izzo 2021), with one
addition: the radius of convergence is also estimated from the last two orders of (Φ, Ψ), each relative
to its order-0 size, so the step keeps the STM's series converged too. (Φ, Ψ) share the state's
singularities in complex time, so this rarely shortens the step.

Scope: rigid bodies with a degree-2 torque (as the DOP853 variational equations); degree-3/4 figures
with perturbers and the lunar interior are refused.
"""

import math

import numpy as np

from spinorbit.core.dynamics.equations import MODEL_PERTURBERS, STATE_SIZE
from spinorbit.core.dynamics.validation import (
    check_step_budget,
    rotation_turns,
    validate_output_times,
    validate_sampled_span,
    validate_state,
)
from spinorbit.core.integrators.dop853 import (
    DEFAULT_MAX_STEPS,
    STATUS_MAX_STEPS,
    STATUS_MESSAGES,
    STATUS_NOT_FINITE,
    STATUS_SUCCESS,
    IntegrationError,
)
from spinorbit.core.integrators.quaternion import normalize_quaternion_part
from spinorbit.core.integrators.taylor import (
    KEPLER_RESEED_INTERVAL,
    ORBIT_TOLERANCE_FRACTION,
    STAT_ORDER_SUM,
    STAT_STATUS,
    STAT_STEPS,
    STEP_GROWTH,
    TAYLOR_STEPS_PER_TURN,
    first_step_bound,
    next_step,
    step_factor_of,
    taylor_order,
)
from spinorbit.core.integrators.taylor_recurrences import (
    OMEGA_COLUMN,
    PERTURBER_BLOCK_COLUMNS,
    SCALED_BODY_POSITION_OFFSET,
    SERIES_HEAD_COLUMNS,
    horner,
    orbit_radius,
    scaled_norm,
    seed_perturbers,
    series_array,
    state_at,
    taylor_coefficients_into,
)
from spinorbit.core.integrators.variational import (
    LOCAL_SIZE,
    PARAMETER_SIZE,
    check_degree_two_rigid_model,
)
from spinorbit.core.jit import jit
from spinorbit.core.model.gravity_field import BODY_A, BODY_B, BODY_C
from spinorbit.core.model.perturbers import PERTURBER_ROW

#: Rows of the variational series: Φ (6 × 6, row-major), then Ψ (6 × 2, row-major).
V_PHI = 0
V_PSI = LOCAL_SIZE * LOCAL_SIZE
VARIATIONAL_SIZE = V_PSI + LOCAL_SIZE * PARAMETER_SIZE
#: Rows of the tidal tensor's series, and the pairs of body-frame coordinates each one multiplies.
T_XX, T_YY, T_ZZ, T_YZ, T_ZX, T_XY = 0, 1, 2, 3, 4, 5
TIDAL_PAIRS = ((0, 0), (1, 1), (2, 2), (1, 2), (2, 0), (0, 1))
_W0 = OMEGA_COLUMN  # ω's first column in the state's series


@jit
def tidal_series_into(model, s, n_pert, order, tidal):
    """Orders 0..order−1 of T = Σ 3μ |r|⁻⁵ r rᵀ (body frame) from the filled state series ``s``.

    ``tidal`` (6 × ≥ order) receives the rows T_XX … T_XY, as Σ 3μ ρ ρᵀ of each perturber's body-frame
    ρ = |r|⁻⁵ᐟ² r_body, which the state's recurrence fills (its torque is made of the same products).
    """
    for c in range(6):
        for k in range(order):
            tidal[c, k] = 0.0
    for p in range(n_pert):
        three_mu = 3.0 * model[MODEL_PERTURBERS + 1 + p * PERTURBER_ROW + 1]
        rb = SERIES_HEAD_COLUMNS + p * PERTURBER_BLOCK_COLUMNS + SCALED_BODY_POSITION_OFFSET
        for c in range(6):
            a, b = TIDAL_PAIRS[c]
            for k in range(order):
                acc = 0.0
                for j in range(k + 1):
                    acc += s[j, rb + a] * s[k - j, rb + b]
                tidal[c, k] += three_mu * acc


@jit
def variational_series_into(model, s, tidal, v, order):
    """Orders 1..order of (Φ, Ψ) in ``v`` (48 × order+1) from v[:, 0] and the state's and T's series."""
    a_mom, b_mom, c_mom = model[BODY_A], model[BODY_B], model[BODY_C]
    kx, ky, kz = (b_mom - c_mom) / a_mom, (c_mom - a_mom) / b_mom, (a_mom - b_mom) / c_mom
    for k in range(order):
        for col in range(LOCAL_SIZE + PARAMETER_SIZE):
            if col < LOCAL_SIZE:
                base, stride, c = V_PHI, LOCAL_SIZE, col
            else:
                base, stride, c = V_PSI, PARAMETER_SIZE, col - LOCAL_SIZE
            r0, r1, r2 = base + c, base + stride + c, base + 2 * stride + c
            r3, r4, r5 = base + 3 * stride + c, base + 4 * stride + c, base + 5 * stride + c
            dax = v[r3, k]  # δθ̇ = δω − ω × δθ: the δω term has only order 0 in J
            day = v[r4, k]
            daz = v[r5, k]
            dbx = 0.0
            dby = 0.0
            dbz = 0.0
            for j in range(k + 1):
                wx, wy, wz = s[j, _W0], s[j, _W0 + 1], s[j, _W0 + 2]
                txx, tyy, tzz = tidal[T_XX, j], tidal[T_YY, j], tidal[T_ZZ, j]
                tyz, tzx, txy = tidal[T_YZ, j], tidal[T_ZX, j], tidal[T_XY, j]
                ax, ay, az = v[r0, k - j], v[r1, k - j], v[r2, k - j]
                bx, by, bz = v[r3, k - j], v[r4, k - j], v[r5, k - j]
                dax -= wy * az - wz * ay
                day -= wz * ax - wx * az
                daz -= wx * ay - wy * ax
                # δT_yz, δT_zx, δT_xy for δθ = (ax, ay, az): columns e_x, e_y, e_z of δT = T E_j − E_j T
                dyz = (tzz - tyy) * ax + txy * ay - tzx * az
                dzx = -txy * ax + (txx - tzz) * ay + tyz * az
                dxy = tzx * ax - tyz * ay + (tyy - txx) * az
                dbx += kx * (wz * by + wy * bz - dyz)
                dby += ky * (wx * bz + wz * bx - dzx)
                dbz += kz * (wy * bx + wx * by - dxy)
            if col >= LOCAL_SIZE:
                # parameter forcing of ω̇x = (B − C)(ωyωz − T_yz)/A (cyclic), A = p₁C, B = p₂C: order k of e
                ex = -tidal[T_YZ, k]
                ey = -tidal[T_ZX, k]
                ez = -tidal[T_XY, k]
                for j in range(k + 1):
                    ex += s[j, _W0 + 1] * s[k - j, _W0 + 2]
                    ey += s[j, _W0 + 2] * s[k - j, _W0]
                    ez += s[j, _W0] * s[k - j, _W0 + 1]
                if c == 0:
                    dbx += -c_mom * (b_mom - c_mom) * ex / (a_mom * a_mom)
                    dby += -c_mom * ey / b_mom
                    dbz += ez
                else:
                    dbx += c_mom * ex / a_mom
                    dby += -c_mom * (c_mom - a_mom) * ey / (b_mom * b_mom)
                    dbz += -ez
            inv = 1.0 / (k + 1)
            v[r0, k + 1] = dax * inv
            v[r1, k + 1] = day * inv
            v[r2, k + 1] = daz * inv
            v[r3, k + 1] = dbx * inv
            v[r4, k + 1] = dby * inv
            v[r5, k + 1] = dbz * inv


@jit
def _variational_norm(v, k):
    """max |v^[k]| over (Φ, Ψ)."""
    norm = 0.0
    for i in range(VARIATIONAL_SIZE):
        norm = max(norm, abs(v[i, k]))
    return norm


@jit
def integrate_taylor_variational_kernel(y0, t0, t_out, model, tol, max_steps):
    """Adaptive Taylor integration of (q, ω, Φ, Ψ) from (t0, y0, I, 0); output at the monotone ``t_out``.

    Returns
    -------
    ys : ndarray (n, 7)
        States at t_out (q renormalised).
    vs : ndarray (n, 48)
        (Φ row-major, Ψ row-major) at t_out.
    stats : ndarray (4,) int64
        [steps, Σ order, 0, status] (the Taylor integrator's layout).
    """
    n = STATE_SIZE
    n_out = t_out.shape[0]
    ys = np.full((n_out, n), np.nan)
    vs = np.full((n_out, VARIATIONAL_SIZE), np.nan)
    stats = np.zeros(4, dtype=np.int64)
    n_pert = int(model[MODEL_PERTURBERS])
    order = taylor_order(tol, 1.0)
    s = series_array(n_pert, order)
    v = np.zeros((VARIATIONAL_SIZE, order + 1))
    tidal = np.zeros((6, order + 1))
    y = y0.copy()
    normalize_quaternion_part(y)
    var = np.zeros(VARIATIONAL_SIZE)
    for i in range(LOCAL_SIZE):
        var[V_PHI + i * LOCAL_SIZE + i] = 1.0
    t_end = t_out[n_out - 1]
    direction = 1.0 if t_end >= t0 else -1.0
    step_factor = step_factor_of(order, 1.0, tol)
    orbit_orders = np.zeros(max(n_pert, 1), dtype=np.int64)
    orbit_tol = ORBIT_TOLERANCE_FRACTION * tol
    h_prev = first_step_bound(y)
    h_last = 0.0
    t = t0
    i_out = 0
    while i_out < n_out and t_out[i_out] == t0:
        ys[i_out] = y
        vs[i_out] = var
        i_out += 1
    steps = 0
    while i_out < n_out:
        if steps >= max_steps:
            stats[STAT_STATUS] = STATUS_MAX_STEPS
            return ys, vs, stats
        for i in range(n):
            s[0, i] = y[i]
        for i in range(VARIATIONAL_SIZE):
            v[i, 0] = var[i]
        exact = steps % KEPLER_RESEED_INTERVAL == 0
        t_stop = seed_perturbers(t, model, s, n_pert, t_end, direction, h_last, orbit_orders, exact)
        w_scale = max(math.sqrt(y[4] * y[4] + y[5] * y[5] + y[6] * y[6]), 1e-300)
        h_cap = STEP_GROWTH * h_prev
        taylor_coefficients_into(t, model, s, n_pert, order, h_cap, orbit_tol, orbit_orders)
        tidal_series_into(model, s, n_pert, order, tidal)
        variational_series_into(model, s, tidal, v, order)
        rho = np.inf
        for k in (order - 1, order):
            n_k = scaled_norm(s, k, w_scale)
            if n_k > 0.0:
                rho = min(rho, n_k ** (-1.0 / k))
            n_var = _variational_norm(v, k) / max(_variational_norm(v, 0), 1.0)
            if n_var > 0.0:
                rho = min(rho, n_var ** (-1.0 / k))
        if n_pert > 0:
            rho = min(rho, orbit_radius(s, n_pert, orbit_orders, order))
        t_new, h, status = next_step(t, rho, step_factor, h_cap, direction, t_stop)
        if status != STATUS_SUCCESS:
            stats[STAT_STATUS] = status
            return ys, vs, stats
        steps += 1
        stats[STAT_STEPS] += 1
        stats[STAT_ORDER_SUM] += order
        while i_out < n_out and direction * (t_out[i_out] - t_new) <= 0.0:
            state_at(s, order, t_out[i_out] - t, ys[i_out])
            normalize_quaternion_part(ys[i_out])
            horner(v, VARIATIONAL_SIZE, order, t_out[i_out] - t, vs[i_out])
            i_out += 1
        state_at(s, order, h, y)
        normalize_quaternion_part(y)
        horner(v, VARIATIONAL_SIZE, order, h, var)
        for i in range(n):
            if not math.isfinite(y[i]):
                stats[STAT_STATUS] = STATUS_NOT_FINITE
                return ys, vs, stats
        for i in range(VARIATIONAL_SIZE):
            if not math.isfinite(var[i]):
                stats[STAT_STATUS] = STATUS_NOT_FINITE
                return ys, vs, stats
        h_last = h
        if t_new != t_stop or abs(h) >= h_prev:
            h_prev = abs(h)
        t = t_new
    stats[STAT_STATUS] = STATUS_SUCCESS
    return ys, vs, stats


def integrate_taylor_variational(y0, t0, t_out, model, tol=1e-10, max_steps=DEFAULT_MAX_STEPS,
                                 return_stats=False):
    """Integrate (q, ω) with the adaptive Taylor method together with its STM Φ and sensitivities Ψ.

    Parameters
    ----------
    y0, t0, t_out
        As in :func:`spinorbit.core.integrators.variational.integrate_variational`.
    model : ndarray
        :func:`spinorbit.core.dynamics.equations.make_model`; any perturbers act through the degree-2
        torque (a degree-3/4 figure with perturbers, or a lunar interior, is refused).
    tol : float
        Local tolerance of :func:`spinorbit.core.integrators.taylor.integrate_taylor` (its order rule,
        ``order_factor`` 1), 1e-16 ≤ tol < 1.
    max_steps : int
        Cap on the number of steps (refused up front when the rotations alone exceed it).
    return_stats : bool
        Also return ``{"steps": …, "order": …}``.

    Returns
    -------
    ys, phi, psi : ndarray
        (q, ω) (n, 7), Φ (n, 6, 6) and Ψ (n, 6, 2) at t_out, as from
        :func:`spinorbit.core.integrators.variational.integrate_variational`.
    stats : dict, optional

    Raises
    ------
    ValueError
        Bad state, times or tolerance, a model outside the scope above, or output times outside a
        sampled perturber's span.
    IntegrationError
        The kernel stopped early (see the message).
    """
    model = np.ascontiguousarray(model, dtype=float)
    check_degree_two_rigid_model(model)
    state = validate_state(y0, STATE_SIZE)
    t0 = float(t0)
    t_out = validate_output_times(t0, t_out)
    if not (isinstance(tol, (int, float, np.floating)) and np.isfinite(tol) and 1e-16 <= tol < 1.0):
        raise ValueError(f"tol: expected 1e-16 ≤ tol < 1, got {tol!r}; try 1e-10.")
    validate_sampled_span(model, t0, t_out)
    check_step_budget("integrate_taylor_variational", rotation_turns(state, t0, t_out[-1]) * TAYLOR_STEPS_PER_TURN,
                      max_steps, "shorten the span")
    ys, vs, stats = integrate_taylor_variational_kernel(state, t0, t_out, model, float(tol), int(max_steps))
    status = int(stats[STAT_STATUS])
    if status != STATUS_SUCCESS:
        raise IntegrationError(f"integrate_taylor_variational stopped at step {int(stats[STAT_STEPS])}: "
                               f"{STATUS_MESSAGES[status]}.")
    phi = vs[:, V_PHI:V_PSI].reshape(-1, LOCAL_SIZE, LOCAL_SIZE).copy()
    psi = vs[:, V_PSI:].reshape(-1, LOCAL_SIZE, PARAMETER_SIZE).copy()
    if return_stats:
        return ys, phi, psi, {"steps": int(stats[STAT_STEPS]), "order": taylor_order(float(tol), 1.0)}
    return ys, phi, psi
