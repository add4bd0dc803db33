"""Adaptive Taylor-series integration of the Euler-parameter equations, entirely in numba.

The equations are those of :mod:`spinorbit.core.dynamics.equations` (q̇ = ½ q ⊗ (0, ω), I ω̇ = Iω × ω + N) with
the degree-2 (MacCullagh) torque of point masses, N = (3μ/R⁵) r × (I r) (``gravity_field.py``,
``docs/torques.md``). Instead of evaluating the right-hand side at stages, the Taylor coefficients
y^[k] = y⁽ᵏ⁾(t)/k! of the solution are generated order by order by automatic differentiation
(Jorba & Zou 2005, Exp. Math. 14, 99; the recurrences, the series array and the perturbers' series
are :mod:`spinorbit.core.integrators.taylor_recurrences`). This module is the driver: the order, the
step, the re-seeding of Keplerian perturbers and the output.

**Order and step (heyoka's rule, Biscani & Izzo 2021, MNRAS 504, 2614, after Jorba & Zou).** Order
p = ⌈−ln(tol)/2 + 1⌉ (× ``order_factor``); after the expansion the step is
h = ρ · exp(−2) · exp(−0.7/(p − 1)), with ρ = min((1/‖y^[p−1]‖)^{1/(p−1)}, (1/‖y^[p]‖)^{1/p}) the
radius of convergence estimated from the last two coefficients, ‖·‖ the max norm over the scaled
components (q by 1, ω by |ω|: a relative test per group, as spinorbit's DOP853 default atol), and
the same estimate from a Keplerian perturber's orbit series (position by |r|, velocity by |v|), so a
fast flyby also limits the step. With ``order_factor > 1`` the order is raised and the step
taken from the tolerance directly, h = ρ tol^{1/p} exp(−0.7/(p − 1)) (fewer, longer steps, larger
errors at the same tol, no better per unit of accuracy, so the default is 1). There are no
rejected steps: the series at t is valid for any h below ρ, so h is chosen after it is computed.

Dense output: the Taylor polynomial evaluated (Horner) at the requested times inside each step,
q renormalised. Error control is local (per step) as in every adaptive method: the global attitude
error grows with the number of steps; ``docs/performance.md`` shows it against tol.
"""

import math
import warnings

import numpy as np

from spinorbit.core.dynamics.equations import MODEL_PERTURBERS, STATE_SIZE
from spinorbit.core.dynamics.validation import (
    check_step_budget,
    rotation_turns,
    validate_fixed_steps,
    validate_output_times,
    validate_sampled_span,
    validate_state,
)
from spinorbit.core.integrators.dop853 import (
    DEFAULT_MAX_STEPS,
    STATUS_MAX_STEPS,
    STATUS_NOT_FINITE,
    STATUS_STEP_TOO_SMALL,
    STATUS_SUCCESS,
    IntegrationError,
)
from spinorbit.core.integrators.quaternion import integrate_quaternion, normalize_quaternion_part
from spinorbit.core.integrators.taylor_recurrences import (
    MAX_ORDER,
    orbit_radius,
    scaled_norm,
    seed_perturbers,
    series_array,
    state_at,
    taylor_coefficients_into,
)
from spinorbit.core.integrators.taylor_recurrences import taylor_series  # noqa: F401 (part of this integrator's API)
from spinorbit.core.jit import jit
from spinorbit.core.model.gravity_field import BODY_NMAX, FIG_THERMAL

#: Largest growth of the step from one step to the next: bounds the step for which the orbit series'
#: order m is chosen (see the module docstring).
STEP_GROWTH = 1.5
#: An orbit series stops when two consecutive terms at the largest step are below this × tol relative
#: to |r| and |v|: the torque's relative error is then ~1e-2 tol times a factor of order 1, and it
#: enters ω multiplied by the (small) torque.
ORBIT_TOLERANCE_FRACTION = 1e-2
#: A Kepler perturber is re-seeded from the exact Kepler solution every this many steps and advanced
#: by its own Taylor polynomial in between (each advance is exact to ORBIT_TOLERANCE_FRACTION × tol
#: relative, so 16 of them add < 2e-1 tol relative to the position, a 1e-1 tol relative torque error
#: times the torque's small weight in ω), and most steps skip the Kepler solve.
KEPLER_RESEED_INTERVAL = 16
STAT_STEPS, STAT_ORDER_SUM, STAT_ORBIT_ORDER_SUM, STAT_STATUS = 0, 1, 2, 3


class TaylorFallbackWarning(UserWarning):
    """The model needs a term the Taylor recurrences do not have (degree ≥ 3 field): DOP853 was used."""


@jit
def taylor_order(tol, order_factor):
    """Order p = ⌈(−ln tol / 2 + 1) · order_factor⌉ (heyoka's rule at order_factor = 1), 2 ≤ p ≤ MAX_ORDER."""
    p = int(math.ceil((-math.log(tol) / 2.0 + 1.0) * order_factor))  # noqa: RUF046 (numba int)
    return min(max(p, 2), MAX_ORDER)


@jit
def convergence_radius(n_prev, n_last, order):
    """min(n_prev^(−1/(order−1)), n_last^(−1/order)), inf for zero norms, with one power function where one suffices.

    The second radius is computed only when the first does not already bound it: ρ_prev < ρ_last ⟺
    n_prev · ρ_last^(order−1) > 1, a product of integer powers (a power function costs ~20 ns, a
    few % of a step).
    """
    if n_last > 0.0:
        rho = n_last ** (-1.0 / order)
        if n_prev > 0.0:
            bound = n_prev
            for _ in range(order - 1):
                bound *= rho
            if bound > 1.0:
                rho = n_prev ** (-1.0 / (order - 1))
        return rho
    if n_prev > 0.0:
        return n_prev ** (-1.0 / (order - 1))
    return np.inf


@jit
def step_factor_of(order, order_factor, tol):
    """The safety factor on the convergence radius: heyoka's (order_factor = 1), or tol^(1/p) for raised orders."""
    if order_factor == 1.0:
        return math.exp(-2.0) * math.exp(-0.7 / (order - 1))
    return tol ** (1.0 / order) * math.exp(-0.7 / (order - 1))


@jit
def first_step_bound(y):
    """The step the first one may grow from: 1/(e² |ω|), a fraction of a rotation."""
    w_norm = math.sqrt(y[4] * y[4] + y[5] * y[5] + y[6] * y[6])
    return 1.0 / (math.e * math.e * max(w_norm, 1e-300))


@jit
def next_step(t, rho, step_factor, h_cap, direction, t_stop):
    """(t_new, h, status) of the step from t with convergence radius rho, capped at h_cap and at t_stop.

    status is STATUS_SUCCESS, or STATUS_NOT_FINITE (no finite radius) or STATUS_STEP_TOO_SMALL (a step
    of at most 10 ulp of t), in which case no step is taken.
    """
    h_abs = min(rho * step_factor, h_cap)
    if not math.isfinite(h_abs) or h_abs <= 0.0:
        if math.isinf(rho) and math.isfinite(h_cap):
            h_abs = h_cap  # exactly polynomial solution (e.g. at rest)
        else:
            return t, 0.0, STATUS_NOT_FINITE
    t_new = t + direction * h_abs
    if direction * (t_new - t_stop) > 0.0:
        t_new = t_stop
    h = t_new - t
    if not (abs(h) > 10.0 * abs(np.nextafter(t, t + direction) - t)):
        return t, h, STATUS_STEP_TOO_SMALL
    return t_new, h, STATUS_SUCCESS


@jit
def integrate_taylor_kernel(y0, t0, t_out, model, tol, order_factor, max_steps):
    """Adaptive Taylor integration from (t0, y0) with output at the monotone times ``t_out``.

    Returns
    -------
    ys : ndarray (n, 7)
        States at t_out (q renormalised).
    stats : ndarray (4,) int64
        [steps, Σ order, Σ orbit-series orders over perturbers, status].
    """
    n = STATE_SIZE
    n_out = t_out.shape[0]
    ys = np.full((n_out, n), np.nan)
    stats = np.zeros(4, dtype=np.int64)
    n_pert = int(model[MODEL_PERTURBERS])
    order = taylor_order(tol, order_factor)
    s = series_array(n_pert, order)
    y = y0.copy()
    normalize_quaternion_part(y)
    t_end = t_out[n_out - 1]
    direction = 1.0 if t_end >= t0 else -1.0
    step_factor = step_factor_of(order, order_factor, tol)
    orbit_orders = np.zeros(max(n_pert, 1), dtype=np.int64)
    orbit_tol = ORBIT_TOLERANCE_FRACTION * tol
    h_prev = first_step_bound(y)
    h_last = 0.0
    t = t0
    i_out = 0
    while i_out < n_out and t_out[i_out] == t0:
        ys[i_out] = y
        i_out += 1
    steps = 0
    while i_out < n_out:
        if steps >= max_steps:
            stats[STAT_STATUS] = STATUS_MAX_STEPS
            return ys, stats
        for i in range(n):
            s[0, i] = y[i]
        exact = steps % KEPLER_RESEED_INTERVAL == 0
        t_stop = seed_perturbers(t, model, s, n_pert, t_end, direction, h_last, orbit_orders, exact)
        w_norm = math.sqrt(y[4] * y[4] + y[5] * y[5] + y[6] * y[6])
        w_scale = max(w_norm, 1e-300)
        h_cap = STEP_GROWTH * h_prev
        taylor_coefficients_into(t, model, s, n_pert, order, h_cap, orbit_tol, orbit_orders)
        n_last = scaled_norm(s, order, w_scale)
        n_prev = scaled_norm(s, order - 1, w_scale)
        rho = convergence_radius(n_prev, n_last, order)
        if n_pert > 0:
            rho = min(rho, orbit_radius(s, n_pert, orbit_orders, order))
        t_new, h, status = next_step(t, rho, step_factor, h_cap, direction, t_stop)
        if status != STATUS_SUCCESS:
            stats[STAT_STATUS] = status
            return ys, stats
        steps += 1
        stats[STAT_STEPS] += 1
        stats[STAT_ORDER_SUM] += order
        for p in range(n_pert):
            stats[STAT_ORBIT_ORDER_SUM] += orbit_orders[p]
        while i_out < n_out and direction * (t_out[i_out] - t_new) <= 0.0:
            state_at(s, order, t_out[i_out] - t, ys[i_out])
            normalize_quaternion_part(ys[i_out])
            i_out += 1
        state_at(s, order, h, y)
        normalize_quaternion_part(y)
        for i in range(n):
            if not math.isfinite(y[i]):
                stats[STAT_STATUS] = STATUS_NOT_FINITE
                return ys, stats
        h_last = h
        if t_new != t_stop or abs(h) >= h_prev:
            h_prev = abs(h)
        t = t_new
    stats[STAT_STATUS] = STATUS_SUCCESS
    return ys, stats


@jit
def integrate_taylor_fixed_kernel(y0, t0, t1, n_steps, model, order):
    """n_steps equal Taylor steps of the given order (full torque series, q renormalised) → y(t1).

    For measuring the order of convergence: the local error is O(h^(order+1)), the global O(h^order).
    """
    n_pert = int(model[MODEL_PERTURBERS])
    s = series_array(n_pert, order)
    orbit_orders = np.zeros(max(n_pert, 1), dtype=np.int64)
    y = y0.copy()
    normalize_quaternion_part(y)
    h = (t1 - t0) / n_steps
    for step in range(n_steps):
        t = t0 + step * h
        for i in range(STATE_SIZE):
            s[0, i] = y[i]
        seed_perturbers(t, model, s, n_pert, t1, 1.0 if h > 0.0 else -1.0, h, orbit_orders, True)
        taylor_coefficients_into(t, model, s, n_pert, order, 0.0, 0.0, orbit_orders)
        state_at(s, order, h, y)
        normalize_quaternion_part(y)
    return y


# ---------------------------------------------------------------------------------------------
# Python front end: validation only, then one call into the kernel.

_STATUS_MESSAGES = {
    STATUS_MAX_STEPS: "reached max_steps; raise max_steps",
    STATUS_STEP_TOO_SMALL: "the step size underflowed; the solution may be singular (e.g. a perturber "
    "passing through the body)",
    STATUS_NOT_FINITE: "the state or its Taylor series became NaN/inf; check that sampled perturbers cover "
    "the whole time span",
}


def _validate_tolerance(tol):
    if not (isinstance(tol, (int, float, np.floating)) and np.isfinite(tol) and tol > 0):
        raise ValueError(f"tol: expected a tolerance > 0, got {tol!r}; try 1e-10.")
    if tol < 1e-16:
        raise ValueError(f"tol: expected tol ≥ 1e-16 (double precision cannot do better), got {tol!r}.")
    return float(tol)


def _validate_order_factor(order_factor):
    if not (np.isfinite(order_factor) and 1.0 <= order_factor <= 2.0):
        raise ValueError(f"order_factor: expected a number in [1, 2] (1 = heyoka's order), got {order_factor!r}.")
    return float(order_factor)


def _needs_fallback(model):
    return int(model[BODY_NMAX]) > 2 or model[FIG_THERMAL] > 0.0  # no recurrence for either


def _fallback_reason(model):
    if model[FIG_THERMAL] > 0.0:
        return "a thermal (YORP) block"
    return f"degree-{int(model[BODY_NMAX])} Stokes terms"


# The same checks under public names, for the batch Taylor integrator (batch_taylor.py), which makes them per member.
validate_tolerance = _validate_tolerance
validate_order_factor = _validate_order_factor
fallback_reason = _fallback_reason


#: Default raise of the order over heyoka's rule: higher orders take fewer steps but give larger errors
#: at the same tol, for the same CPU per unit of accuracy (measured in scenes (a) and (b)).
DEFAULT_ORDER_FACTOR = 1.0


#: Fewest Taylor steps per rotation: measured 3.4 or more (tol 1e-14) to 12 (tol 1e-3) on the free
#: rotations of integrate_quaternion's STEPS_PER_TURN_COEFFICIENT; 1 keeps the estimate a lower bound.
TAYLOR_STEPS_PER_TURN = 1.0


def integrate_taylor(y0, t0, t_out, model, tol=1e-10, order_factor=DEFAULT_ORDER_FACTOR,
                     max_steps=DEFAULT_MAX_STEPS, return_stats=False):
    """Integrate the rotational equations of motion with an adaptive Taylor method and renormalised q.

    Parameters
    ----------
    y0 : array_like (7,)
        Initial state (q0, q1, q2, q3, ωx, ωy, ωz): scalar-first quaternion (normalised here) and
        body angular velocity (rad/time unit).
    t0 : float
        Initial time (time unit of the model).
    t_out : array_like (n,)
        Output times, strictly monotone away from t0.
    model : ndarray
        From :func:`spinorbit.core.dynamics.equations.make_model`. A figure with degree-3/4 Stokes terms is
        integrated by :func:`spinorbit.core.integrators.quaternion.integrate_quaternion` instead
        (``rtol = tol``), with a :class:`TaylorFallbackWarning`.
    tol : float
        Local error tolerance per step, relative per component group (q by 1, ω by |ω|);
        1e-16 ≤ tol.
    order_factor : float
        Multiplies heyoka's order ⌈−ln(tol)/2 + 1⌉, in [1, 2] (module docstring).
    max_steps : int
        Cap on the number of steps. A run whose estimate (rotations × :data:`TAYLOR_STEPS_PER_TURN`,
        a lower bound) exceeds it is refused before the first step; the kernel also stops at it.
    return_stats : bool
        Also return a dict: ``steps``, ``order``, ``mean_orbit_order`` (orbit-series order per step,
        summed over perturbers).

    Returns
    -------
    ys : ndarray (n, 7)
        States at t_out.
    stats : dict, optional

    Raises
    ------
    ValueError
        Bad state, times, tolerance or order factor, or output times outside the span of a sampled
        perturber.
    IntegrationError
        The kernel stopped early (see the message).
    """
    y0 = validate_state(y0)
    t0 = float(t0)
    t_out = validate_output_times(t0, t_out)
    tol = _validate_tolerance(tol)
    order_factor = _validate_order_factor(order_factor)
    model = np.ascontiguousarray(model, dtype=float)
    validate_sampled_span(model, t0, t_out)
    check_step_budget("integrate_taylor", rotation_turns(y0, t0, t_out[-1]) * TAYLOR_STEPS_PER_TURN, max_steps,
                      "shorten the span")
    if _needs_fallback(model):
        warnings.warn(
            f"integrate_taylor: the model has {_fallback_reason(model)}, for which there "
            "is no Taylor recurrence; integrating with DOP853 (integrate_quaternion, rtol = tol) instead.",
            TaylorFallbackWarning, stacklevel=2)
        return integrate_quaternion(y0, t0, t_out, model, rtol=tol, return_stats=return_stats)
    ys, stats = integrate_taylor_kernel(y0, t0, t_out, model, tol, order_factor, int(max_steps))
    status = int(stats[STAT_STATUS])
    if status != STATUS_SUCCESS:
        raise IntegrationError(f"integration stopped at step {int(stats[STAT_STEPS])}: {_STATUS_MESSAGES[status]}.")
    if return_stats:
        steps = max(int(stats[STAT_STEPS]), 1)
        return ys, {"steps": int(stats[STAT_STEPS]), "order": taylor_order(tol, order_factor),
                    "mean_orbit_order": float(stats[STAT_ORBIT_ORDER_SUM]) / steps}
    return ys


def integrate_taylor_fixed_step(y0, t0, t1, n_steps, model, order, max_steps=DEFAULT_MAX_STEPS):
    """y(t1) after ``n_steps`` equal Taylor steps of ``order`` (order measurements; no error control).

    ``n_steps`` above ``max_steps`` is refused before the first step (WorkLimitError).
    """
    y0 = validate_state(y0)
    t0, t1, n_steps = validate_fixed_steps("integrate_taylor_fixed_step", t0, t1, n_steps, max_steps)
    if not (1 <= int(order) <= MAX_ORDER):
        raise ValueError(f"order: expected an order in [1, {MAX_ORDER}], got {order!r}.")
    if _needs_fallback(np.asarray(model)):
        raise ValueError(f"model: the fixed-step Taylor mode has no recurrence for {_fallback_reason(np.asarray(model))}; "
                         "use integrate_fixed_step.")
    return integrate_taylor_fixed_kernel(y0, t0, t1, n_steps,
                                         np.ascontiguousarray(model, dtype=float), int(order))
