"""Batch adaptive Taylor integration: many members in W lanes, each lane its own order, step and time.

The Taylor counterpart of :mod:`spinorbit.core.integrators.batch_quaternion` (issue 18's batch mode):
a member's result must not depend on its lane-mates, so every lane keeps its own time, order (from
its own tol), step, previous step, orbit-series orders and step count, and runs **the same arithmetic,
in the same order, as the scalar kernel** :func:`spinorbit.core.integrators.taylor.integrate_taylor_kernel`
with the one output time ``t_end``. A member's end state is therefore the scalar integrator's to the
last bit (``tests/test_batch_taylor.py`` checks bit identity for members with different moments,
states and tolerances, in any lane and any lane count).

**One definition.** The coefficients come from the package's one set of recurrences,
:func:`~spinorbit.core.integrators.taylor_recurrences.taylor_coefficients_into` (and the perturbers'
seeding, the norms, the convergence radius, the step rule and Horner's evaluation are the scalar
driver's own functions), called per lane on that lane's slice of the series array
``s[lane, row, order]``. The lanes are therefore *interleaved*, not vectorised: the Cauchy products
of one lane are the scalar loops. Vectorising them across lanes needs the recurrences written with
the lane index innermost, ``s[row, order, lane]``; a second hand-written copy of the recurrences is
what the project's rules forbid, and generating both from one description would rewrite the scalar
recurrences (``docs/performance.md``, the batch section, measures what that leaves: the floor is the
scalar step's cost per lane-step).

Lanes are refilled: the N members queue behind the W lanes, and a lane whose member finished (or
stopped) takes the next member, so lanes idle only at the end of the queue. A lane that stops
(non-finite state, step underflow, step cap) records its status and NaN states for its member and is
refilled; the other lanes never see its numbers.

Only the end state of each member is returned (the ensemble's need); output at intermediate times is
the scalar integrator's job.
"""

import math

import numpy as np

from spinorbit.core.dynamics.equations import MODEL_PERTURBERS, STATE_SIZE
from spinorbit.core.dynamics.validation import check_step_budget, validate_sampled_span
from spinorbit.core.integrators.batch_quaternion import DEFAULT_LANES, MAX_LANES, per_member, validated_members
from spinorbit.core.integrators.dop853 import (
    DEFAULT_MAX_STEPS,
    STATUS_MAX_STEPS,
    STATUS_NOT_FINITE,
    STATUS_SUCCESS,
)
from spinorbit.core.integrators.quaternion import normalize_quaternion_part
from spinorbit.core.integrators.taylor import (
    DEFAULT_ORDER_FACTOR,
    KEPLER_RESEED_INTERVAL,
    ORBIT_TOLERANCE_FRACTION,
    STAT_ORBIT_ORDER_SUM,
    STAT_ORDER_SUM,
    STAT_STATUS,
    STAT_STEPS,
    STEP_GROWTH,
    TAYLOR_STEPS_PER_TURN,
    convergence_radius,
    fallback_reason,
    first_step_bound,
    next_step,
    step_factor_of,
    taylor_order,
    validate_order_factor,
    validate_tolerance,
)
from spinorbit.core.integrators.taylor_recurrences import (
    orbit_radius,
    scaled_norm,
    seed_perturbers,
    series_array,
    state_at,
    taylor_coefficients_into,
)
from spinorbit.core.jit import jit
from spinorbit.core.model.gravity_field import BODY_NMAX, FIG_THERMAL
from spinorbit.core.model.perturbers import sampled_span

__all__ = ["batch_taylor_kernel", "integrate_taylor_batch"]


@jit
def batch_taylor_kernel(y0s, t0s, t_ends, models, tols, order_factor, max_steps, lanes):
    """Adaptive Taylor integration of every member from (t0s[m], y0s[m]) to t_ends[m], ``lanes`` at a time.

    Parameters
    ----------
    y0s, t0s, t_ends, models, max_steps, lanes
        As :func:`~spinorbit.core.integrators.batch_quaternion.batch_dop853_kernel`'s (models: Taylor
        recurrences only, degree ≤ 2, no thermal block).
    tols : ndarray (N,)
        Local error tolerances (each member's order is :func:`taylor_order` of its own tol).
    order_factor : float
        Multiplies heyoka's order, in [1, 2].

    Returns
    -------
    ys : ndarray (N, 7)
        End states (q renormalised); NaN for a member that stopped.
    stats : ndarray (N, 4) int64
        Per member [steps, Σ order, Σ orbit-series orders, status], as the scalar kernel's stats.
    """
    n_members, n = y0s.shape
    ys = np.full((n_members, n), np.nan)
    stats = np.zeros((n_members, 4), dtype=np.int64)
    n_pert_max = 0
    order_max = 2
    for m in range(n_members):
        n_pert_max = max(n_pert_max, int(models[m, MODEL_PERTURBERS]))
        order_max = max(order_max, taylor_order(tols[m], order_factor))
    columns = series_array(n_pert_max, order_max).shape[1]
    s = np.zeros((lanes, order_max + 1, columns))  # each lane's series array, contiguous for the scalar functions
    y = np.zeros((lanes, n))
    orbit_orders = np.zeros((lanes, max(n_pert_max, 1)), dtype=np.int64)
    member = np.full(lanes, -1, dtype=np.int64)
    order = np.zeros(lanes, dtype=np.int64)
    n_pert = np.zeros(lanes, dtype=np.int64)
    t = np.zeros(lanes)
    t_end = np.zeros(lanes)
    direction = np.ones(lanes)
    step_factor = np.zeros(lanes)
    orbit_tol = np.zeros(lanes)
    h_prev = np.zeros(lanes)
    h_last = np.zeros(lanes)
    steps = np.zeros(lanes, dtype=np.int64)
    active = np.zeros(lanes, dtype=np.bool_)
    queue = 0
    while True:
        # Refill idle lanes: the scalar kernel's start on the next member.
        for lane in range(lanes):
            if not active[lane] and queue < n_members:
                m = queue
                queue += 1
                for i in range(n):
                    y[lane, i] = y0s[m, i]
                normalize_quaternion_part(y[lane])
                order[lane] = taylor_order(tols[m], order_factor)
                n_pert[lane] = int(models[m, MODEL_PERTURBERS])
                t[lane] = t0s[m]
                t_end[lane] = t_ends[m]
                direction[lane] = 1.0 if t_ends[m] >= t0s[m] else -1.0
                step_factor[lane] = step_factor_of(order[lane], order_factor, tols[m])
                orbit_tol[lane] = ORBIT_TOLERANCE_FRACTION * tols[m]
                for p in range(orbit_orders.shape[1]):
                    orbit_orders[lane, p] = 0
                s[lane, :, :] = 0.0
                h_prev[lane] = first_step_bound(y[lane])
                h_last[lane] = 0.0
                steps[lane] = 0
                member[lane] = m
                active[lane] = True
        any_active = False
        for lane in range(lanes):
            if not active[lane]:
                continue
            any_active = True
            m = member[lane]
            if steps[lane] >= max_steps:
                stats[m, STAT_STATUS] = STATUS_MAX_STEPS
                active[lane] = False
                continue
            _lane_step(lane, m, models[m], s[lane], y[lane], orbit_orders[lane], order[lane], n_pert[lane],
                       t, t_end, direction, step_factor, orbit_tol, h_prev, h_last, steps, active, ys, stats)
        if not any_active and queue >= n_members:
            break
    return ys, stats


@jit
def _lane_step(lane, m, model, s, y, orbit_orders, order, n_pert, t, t_end, direction, step_factor, orbit_tol,
               h_prev, h_last, steps, active, ys, stats):
    """One step of one lane: the body of :func:`~spinorbit.core.integrators.taylor.integrate_taylor_kernel`'s
    loop for the single output time t_end, on that lane's slices (same calls, same order, same bits)."""
    n = STATE_SIZE
    for i in range(n):
        s[0, i] = y[i]
    exact = steps[lane] % KEPLER_RESEED_INTERVAL == 0
    t_stop = seed_perturbers(t[lane], model, s, n_pert, t_end[lane], direction[lane], h_last[lane], orbit_orders,
                             exact)
    w_norm = math.sqrt(y[4] * y[4] + y[5] * y[5] + y[6] * y[6])
    w_scale = max(w_norm, 1e-300)
    h_cap = STEP_GROWTH * h_prev[lane]
    taylor_coefficients_into(t[lane], model, s, n_pert, order, h_cap, orbit_tol[lane], orbit_orders)
    n_last = scaled_norm(s, order, w_scale)
    n_prev = scaled_norm(s, order - 1, w_scale)
    rho = convergence_radius(n_prev, n_last, order)
    if n_pert > 0:
        rho = min(rho, orbit_radius(s, n_pert, orbit_orders, order))
    t_new, h, status = next_step(t[lane], rho, step_factor[lane], h_cap, direction[lane], t_stop)
    if status != STATUS_SUCCESS:
        stats[m, STAT_STATUS] = status
        active[lane] = False
        return
    steps[lane] += 1
    stats[m, STAT_STEPS] += 1
    stats[m, STAT_ORDER_SUM] += order
    for p in range(n_pert):
        stats[m, STAT_ORBIT_ORDER_SUM] += orbit_orders[p]
    if direction[lane] * (t_end[lane] - t_new) <= 0.0:
        # The last step: the scalar kernel's output at t_end (Horner at t_end − t, q renormalised), which is
        # also the state it checks for finiteness (t_new = t_end, so h = t_end − t).
        state_at(s, order, t_end[lane] - t[lane], ys[m])
        normalize_quaternion_part(ys[m])
        for i in range(n):
            if not math.isfinite(ys[m, i]):
                stats[m, STAT_STATUS] = STATUS_NOT_FINITE
                for j in range(n):
                    ys[m, j] = np.nan
                active[lane] = False
                return
        stats[m, STAT_STATUS] = STATUS_SUCCESS
        active[lane] = False
        return
    state_at(s, order, h, y)
    normalize_quaternion_part(y)
    for i in range(n):
        if not math.isfinite(y[i]):
            stats[m, STAT_STATUS] = STATUS_NOT_FINITE
            active[lane] = False
            return
    h_last[lane] = h
    if t_new != t_stop or abs(h) >= h_prev[lane]:
        h_prev[lane] = abs(h)
    t[lane] = t_new


# ---------------------------------------------------------------------------------------------
# Python front end: validation only (the DOP853 batch's and the scalar Taylor's checks), then one call.


def integrate_taylor_batch(y0s, t0, t_end, models, tol=1e-10, order_factor=DEFAULT_ORDER_FACTOR,
                           max_steps=DEFAULT_MAX_STEPS, lanes=DEFAULT_LANES):
    """End states of N members integrated with the adaptive Taylor method, ``lanes`` members at a time.

    Each member gets exactly what :func:`~spinorbit.core.integrators.taylor.integrate_taylor` gives it
    for ``t_out = [t_end]`` (the same bits), whatever its lane-mates are. The calling convention is
    :func:`~spinorbit.core.integrators.batch_quaternion.integrate_quaternion_batch`'s, with ``tol``
    (and ``order_factor``) for its ``rtol`` and ``atol``.

    Parameters
    ----------
    y0s, t0, t_end
        As :func:`~spinorbit.core.integrators.batch_quaternion.integrate_quaternion_batch`'s: states (N, 7)
        (q, ω in rad per time unit), start and end times (one for all or one per member, t_end ≠ t0).
    models : array_like (N, M), a sequence of N equal-length model arrays, or one model (1-d) for all
        Rigid bodies with degree-2 figures only: the Taylor recurrences have no degree-3/4 or thermal
        terms (use ``integrate_quaternion_batch`` for those).
    tol : float or array_like (N,)
        Local error tolerance per member, 1e-16 ≤ tol (as ``integrate_taylor``'s).
    order_factor : float
        Multiplies heyoka's order ⌈−ln(tol)/2 + 1⌉, in [1, 2].
    max_steps, lanes : int
        Cap on each member's steps (refused before the run if a member's lower bound exceeds it), and
        the members advanced together, 1 … 64.

    Returns
    -------
    ys : ndarray (N, 7)
        End states; NaN rows for members that stopped (see ``stats['status']``).
    stats : dict of ndarrays (N,)
        ``steps``, ``order`` (each member's Taylor order), ``mean_orbit_order`` (orbit-series order per
        step, summed over perturbers), ``status`` (0 success, else the
        :data:`~spinorbit.core.integrators.dop853.STATUS_MESSAGES` code), and ``accepted`` (= steps) and
        ``rejected`` (zeros: a Taylor step is never rejected), so that
        :func:`~spinorbit.core.integrators.batch_quaternion.raise_for_batch_status` reads it as the DOP853
        batch's. A member that stops does not stop the others.

    Raises
    ------
    ValueError
        Bad states (:class:`~spinorbit.core.errors.NonFiniteError` for NaN/inf), times, tolerances,
        order factor, models (lengths, an interior block, terms without a Taylor recurrence) or lanes,
        before any integration; :class:`~spinorbit.core.errors.WorkLimitError` for a run whose step
        estimate exceeds ``max_steps``.
    """
    y0s, t0s, t_ends, models = validated_members(y0s, t0, t_end, models, lanes)
    n = y0s.shape[0]
    fallback = (models[:, BODY_NMAX] > 2) | (models[:, FIG_THERMAL] > 0.0)  # _needs_fallback of every member
    if np.any(fallback):
        m = int(np.flatnonzero(fallback)[0])
        raise ValueError(f"models: member {m} has {fallback_reason(models[m])}, for which there is no Taylor "
                         "recurrence; integrate these members with integrate_quaternion_batch.")
    tols = per_member("tol", tol, n, "tolerance")
    unique_tols, first = np.unique(tols, return_index=True)
    for m in np.sort(first):  # integrate_taylor's check of each distinct tol, in member order
        try:
            validate_tolerance(float(tols[m]))
        except ValueError as error:
            raise ValueError(f"{error} (member {int(m)})") from None
    order_factor = validate_order_factor(order_factor)
    _validate_sampled_spans(models, t0s, t_ends)
    turns = np.linalg.norm(y0s[:, 4:], axis=1) * np.abs(t_ends - t0s) / (2.0 * math.pi)  # rotation_turns of each
    check_step_budget("integrate_taylor_batch", float(turns.max()) * TAYLOR_STEPS_PER_TURN, max_steps,
                      "shorten the span")
    ys, stats = batch_taylor_kernel(y0s, t0s, t_ends, models, tols, order_factor, int(max_steps), int(lanes))
    steps = stats[:, STAT_STEPS].copy()
    orders = dict((value, taylor_order(float(value), order_factor)) for value in unique_tols)
    return ys, {"steps": steps, "accepted": steps.copy(), "rejected": np.zeros(n, dtype=np.int64),
                "order": np.array([orders[value] for value in tols.tolist()], dtype=np.int64),
                "mean_orbit_order": stats[:, STAT_ORBIT_ORDER_SUM] / np.maximum(steps, 1),
                "status": stats[:, STAT_STATUS].copy()}


def _validate_sampled_spans(models, t0s, t_ends):
    """validate_sampled_span of every member, the perturbers' span computed once for the members that share
    the first member's perturber block (the common case: one sampling, each member its own moments)."""
    shared = np.all(models[:, MODEL_PERTURBERS:] == models[0, MODEL_PERTURBERS:], axis=1)
    lo, hi = sampled_span(models[0], MODEL_PERTURBERS)
    outside = shared & ((np.minimum(t0s, t_ends) < lo) | (np.maximum(t0s, t_ends) > hi))
    for m in np.flatnonzero(outside | ~shared):
        validate_sampled_span(models[m], t0s[m], t_ends[m:m + 1])  # raises with the member's own span
