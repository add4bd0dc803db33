"""Batch DOP853 of the quaternion equations: many members in W lanes, each lane its own step control.

The ensemble's batch mode (issue 18; the lead's batch design, item 7): a member's result must not
depend on its lane-mates, so every lane keeps its own time, step size, error test, rejection state
and step count, and runs **the same arithmetic, in the same order, as the scalar kernel**
:func:`spinorbit.core.integrators.quaternion.integrate_dop853_kernel` (plain controller, q
renormalised after every accepted step, landing on the end time). A member's end state is therefore
the scalar integrator's to the last bit (``tests/test_batch_quaternion.py`` checks bit identity).

Layout: the stages are ``k[stage, component, lane]`` and the states ``y[component, lane]``, so the
stage sums (:func:`stage_input_lanes`) and the error norm (:func:`error_norm_lanes`) run with the
lane index innermost, where LLVM can vectorise them. The right-hand side is the package's one
:func:`spinorbit.core.dynamics.equations.rhs_into`, called per lane on a contiguous copy of the
lane's stage state (each lane may have its own model array: its own moments, its own perturber
samples).

Lanes are refilled: the N members queue behind the W lanes, and a lane whose member finished (or
stopped) takes the next member at the next trial step, so lanes idle only at the end of the queue. A
lane that stops (non-finite state, step underflow, step cap) records its status and NaN states for
its member and is refilled; the other lanes never see its numbers.

Only the end state of each member is returned (the ensemble's need); output at intermediate times is
the scalar integrator's job.
"""

import math

import numpy as np

from spinorbit.core.dynamics.equations import STATE_SIZE, rhs_into
from spinorbit.core.dynamics.validation import check_step_budget, validate_sampled_span
from spinorbit.core.errors import require_finite
from spinorbit.core.integrators.dop853 import (
    C,
    DEFAULT_MAX_STEPS,
    E3,
    E5,
    MIN_FACTOR,
    N_STAGES,
    PREVIOUS_ERROR_FLOOR,
    STAT_ACCEPTED,
    STAT_REJECTED,
    STAT_RHS_CALLS,
    STAT_STATUS,
    STATS_SIZE,
    STATUS_MAX_STEPS,
    STATUS_MESSAGES,
    STATUS_NOT_FINITE,
    STATUS_STEP_TOO_SMALL,
    STATUS_SUCCESS,
    TINY_SCALE,
    A,
    accepted_step_factor,
    initial_step,
    rejected_step_factor,
)
from spinorbit.core.integrators.quaternion import QUATERNION_SIZE, STEPS_PER_TURN_COEFFICIENT
from spinorbit.core.jit import jit
from spinorbit.core.model.lunar_interior import has_interior

#: Default number of lanes: 4 doubles fill one AVX2 register (heyoka's recommended SIMD size here).
DEFAULT_LANES = 4
#: More lanes than this buys no vector width on any current CPU and only grows the scratch arrays.
MAX_LANES = 64


@jit
def stage_input_lanes(y, h, k, s, active, out):
    """out[:, l] = y[:, l] + h_l Σ_{j<s} A[s, j] k[j, :, l] for every lane: the scalar
    :func:`~spinorbit.core.integrators.dop853.stage_input` per lane, in its order (so the same bits).

    Idle lanes (``active`` False) have h = 0 and stale numbers; their results are never read.
    """
    n, lanes = y.shape
    for i in range(n):
        for lane in range(lanes):
            out[i, lane] = 0.0 + (A[s, 0] * h[lane]) * k[0, i, lane]
    for j in range(1, s):
        if A[s, j] != 0.0:
            for i in range(n):
                for lane in range(lanes):
                    out[i, lane] += (A[s, j] * h[lane]) * k[j, i, lane]
    for i in range(n):
        for lane in range(lanes):
            out[i, lane] += y[i, lane]


@jit
def error_norm_lanes(k, h, y, y_new, rtol, atol, err5, err3, out):
    """The scalar :func:`~spinorbit.core.integrators.dop853.error_norm` of every lane into ``out``
    (per-lane rtol (lanes,) and atol (component, lane)); the same sums in the same order."""
    n, lanes = y.shape
    for lane in range(lanes):
        err5[lane] = 0.0
        err3[lane] = 0.0
    for i in range(n):
        for lane in range(lanes):
            scale = max(atol[i, lane] + rtol[lane] * max(abs(y[i, lane]), abs(y_new[i, lane])), TINY_SCALE)
            e5 = 0.0
            e3 = 0.0
            for j in range(N_STAGES + 1):
                e5 += E5[j] * k[j, i, lane]
                e3 += E3[j] * k[j, i, lane]
            e5 /= scale
            e3 /= scale
            err5[lane] += e5 * e5
            err3[lane] += e3 * e3
    for lane in range(lanes):
        if err5[lane] == 0.0 and err3[lane] == 0.0:
            out[lane] = 0.0
        else:
            out[lane] = abs(h[lane]) * err5[lane] / math.sqrt((err5[lane] + 0.01 * err3[lane]) * n)


@jit(inline="always")
def _lane_rhs(t, states, lane, model, y_lane, f_lane, out, s):
    """k[s, :, lane] = f(t, states[:, lane]) through the scalar rhs_into on contiguous copies."""
    n = states.shape[0]
    for i in range(n):
        y_lane[i] = states[i, lane]
    rhs_into(t, y_lane, model, f_lane)
    for i in range(n):
        out[s, i, lane] = f_lane[i]


@jit
def _normalise_lane(y, lane):
    """Divide y[0:4, lane] by its norm (the scalar normalize_quaternion_part's arithmetic); return the norm."""
    norm = math.sqrt(y[0, lane] * y[0, lane] + y[1, lane] * y[1, lane] + y[2, lane] * y[2, lane]
                     + y[3, lane] * y[3, lane])
    for i in range(QUATERNION_SIZE):
        y[i, lane] /= norm
    return norm


@jit
def batch_dop853_kernel(y0s, t0s, t_ends, models, rtols, atols, max_steps, lanes):
    """Adaptive DOP853 of every member from (t0s[m], y0s[m]) to t_ends[m], ``lanes`` members at a time.

    Parameters
    ----------
    y0s : ndarray (N, 7)
        Initial states (q normalised by the caller).
    t0s, t_ends : ndarray (N,)
        Start and end times (t_end ≠ t0; either direction).
    models : ndarray (N, M)
        Each member's model array (:func:`spinorbit.core.dynamics.equations.make_model`), one row each.
    rtols : ndarray (N,)
        Relative tolerances.
    atols : ndarray (N, 7)
        Absolute tolerances.
    max_steps : int
        Cap on each member's accepted + rejected steps.
    lanes : int
        Members advanced together.

    Returns
    -------
    ys : ndarray (N, 7)
        End states (q renormalised); NaN for a member that stopped.
    stats : ndarray (N, 4) int64
        Per member [accepted, rejected, RHS calls, status], as the scalar kernel's stats.
    """
    n_members, n = y0s.shape
    ys = np.full((n_members, n), np.nan)
    stats = np.zeros((n_members, STATS_SIZE), dtype=np.int64)
    k = np.zeros((N_STAGES + 1, n, lanes))
    y = np.zeros((n, lanes))
    y_new = np.zeros((n, lanes))
    tmp = np.zeros((n, lanes))
    atol = np.zeros((n, lanes))
    rtol = np.ones(lanes)
    h = np.zeros(lanes)
    h_abs = np.zeros(lanes)
    t = np.zeros(lanes)
    t_end = np.zeros(lanes)
    t_trial = np.zeros(lanes)  # the trial step's end time, kept: t + (t_new − t) need not be t_new
    direction = np.ones(lanes)
    min_step = np.zeros(lanes)
    previous_error = np.zeros(lanes)
    err = np.zeros(lanes)
    err5 = np.zeros(lanes)
    err3 = np.zeros(lanes)
    steps = np.zeros(lanes, dtype=np.int64)
    member = np.full(lanes, -1, dtype=np.int64)
    new_step = np.zeros(lanes, dtype=np.bool_)
    rejected = np.zeros(lanes, dtype=np.bool_)
    active = np.zeros(lanes, dtype=np.bool_)
    y_lane = np.empty(n)
    f_lane = np.empty(n)
    queue = 0
    while True:
        # Refill idle lanes: the scalar kernel's start (f(t0), Hairer's first step) on the new member.
        for lane in range(lanes):
            while not active[lane] and queue < n_members:
                m = queue
                queue += 1
                model = models[m]
                rhs_into(t0s[m], y0s[m], model, f_lane)
                direction[lane] = 1.0 if t_ends[m] >= t0s[m] else -1.0
                h0 = initial_step(rhs_into, model, t0s[m], y0s[m], f_lane, direction[lane], rtols[m], atols[m])
                stats[m, STAT_RHS_CALLS] = 2
                if not (math.isfinite(h0) and h0 > 0.0):
                    stats[m, STAT_STATUS] = STATUS_NOT_FINITE
                    continue
                for i in range(n):
                    y[i, lane] = y0s[m, i]
                    k[0, i, lane] = f_lane[i]
                    atol[i, lane] = atols[m, i]
                rtol[lane] = rtols[m]
                t[lane] = t0s[m]
                t_end[lane] = t_ends[m]
                h_abs[lane] = h0
                previous_error[lane] = PREVIOUS_ERROR_FLOOR
                steps[lane] = 0
                member[lane] = m
                new_step[lane] = True
                active[lane] = True
        any_active = False
        # Each lane's trial step: the scalar kernel's checks and its step clipped to the end time.
        for lane in range(lanes):
            h[lane] = 0.0
            if not active[lane]:
                continue
            m = member[lane]
            if new_step[lane]:
                min_step[lane] = 10.0 * abs(np.nextafter(t[lane], t[lane] + direction[lane]) - t[lane])
                if h_abs[lane] < min_step[lane]:
                    h_abs[lane] = min_step[lane]
                rejected[lane] = False
                new_step[lane] = False
            if steps[lane] >= max_steps:
                stats[m, STAT_STATUS] = STATUS_MAX_STEPS
                active[lane] = False
                continue
            if not (h_abs[lane] >= min_step[lane]):
                stats[m, STAT_STATUS] = STATUS_STEP_TOO_SMALL
                active[lane] = False
                continue
            t_new = t[lane] + direction[lane] * h_abs[lane]
            if direction[lane] * (t_new - t_end[lane]) > 0.0:
                t_new = t_end[lane]
            t_trial[lane] = t_new
            h[lane] = t_new - t[lane]
            h_abs[lane] = abs(h[lane])
            any_active = True
        if not any_active:
            if queue >= n_members:
                break
            continue
        for s in range(1, N_STAGES):
            stage_input_lanes(y, h, k, s, active, tmp)
            for lane in range(lanes):
                if active[lane]:
                    _lane_rhs(t[lane] + C[s] * h[lane], tmp, lane, models[member[lane]], y_lane, f_lane, k, s)
        stage_input_lanes(y, h, k, N_STAGES, active, y_new)  # row 12 of A is B: the 8th-order solution
        for lane in range(lanes):
            if active[lane]:
                _lane_rhs(t[lane] + h[lane], y_new, lane, models[member[lane]], y_lane, f_lane, k, N_STAGES)
        error_norm_lanes(k, h, y, y_new, rtol, atol, err5, err3, err)
        # Each lane's error test and step-size control, the scalar kernel's branch by branch.
        for lane in range(lanes):
            if not active[lane]:
                continue
            m = member[lane]
            stats[m, STAT_RHS_CALLS] += N_STAGES
            steps[lane] += 1
            e = err[lane]
            if not math.isfinite(e):
                if h_abs[lane] <= min_step[lane]:
                    stats[m, STAT_STATUS] = STATUS_NOT_FINITE
                    active[lane] = False
                    continue
                h_abs[lane] *= MIN_FACTOR
                rejected[lane] = True
                stats[m, STAT_REJECTED] += 1
                continue
            if e >= 1.0:
                h_abs[lane] *= rejected_step_factor(e)
                rejected[lane] = True
                stats[m, STAT_REJECTED] += 1
                continue
            factor = accepted_step_factor(e, previous_error[lane], 0.0)
            previous_error[lane] = max(e, PREVIOUS_ERROR_FLOOR)
            if rejected[lane]:
                factor = min(1.0, factor)
            h_abs[lane] *= factor
            stats[m, STAT_ACCEPTED] += 1
            t_new = t_trial[lane]
            if t_new == t_end[lane]:  # the last step lands on the end time (clipped above)
                for i in range(n):
                    ys[m, i] = y_new[i, lane]
                norm = math.sqrt(ys[m, 0] * ys[m, 0] + ys[m, 1] * ys[m, 1] + ys[m, 2] * ys[m, 2]
                                 + ys[m, 3] * ys[m, 3])
                for i in range(QUATERNION_SIZE):
                    ys[m, i] /= norm
                stats[m, STAT_STATUS] = STATUS_SUCCESS
                active[lane] = False
                continue
            # Fukushima 2008b: renormalise q, rescale the FSAL q̇ (the scalar after-step hook).
            norm = _normalise_lane(y_new, lane)
            for i in range(n):
                y[i, lane] = y_new[i, lane]
                k[0, i, lane] = k[N_STAGES, i, lane]
            for i in range(QUATERNION_SIZE):
                k[0, i, lane] /= norm
            t[lane] = t_new
            new_step[lane] = True
    return ys, stats


# ---------------------------------------------------------------------------------------------
# Python front end: validation only, then one call into the kernel.


def per_member(name, value, n, what):
    """A scalar or N values as a float array (N,), or a ValueError naming the argument."""
    array = np.asarray(value, dtype=float)
    if array.ndim == 0:
        return np.full(n, float(array))
    if array.shape != (n,):
        raise ValueError(f"{name}: expected one {what} or {n} of them (one per member), got shape {array.shape}.")
    return array.copy()


def integrate_quaternion_batch(y0s, t0, t_end, models, rtol=1e-10, atol=None, max_steps=DEFAULT_MAX_STEPS,
                               lanes=DEFAULT_LANES):
    """End states of N members integrated with adaptive DOP853, ``lanes`` members at a time.

    Each member gets exactly what :func:`~spinorbit.core.integrators.quaternion.integrate_quaternion`
    gives it for ``t_out = [t_end]`` (the same bits), whatever its lane-mates are.

    Parameters
    ----------
    y0s : array_like (N, 7)
        Initial states (q, ω) (q normalised here), body angular velocity in rad per time unit.
    t0, t_end : float or array_like (N,)
        Start and end times (time unit of the models), one for all or one per member; t_end ≠ t0.
    models : array_like (N, M) or a sequence of N model arrays of equal length
        Each member's model (:func:`~spinorbit.core.dynamics.equations.make_model`), or one model
        (1-d) for all members. Rigid-body models only (no interior block).
    rtol : float or array_like (N,)
        Relative local error tolerance per member, ≥ 1e-15.
    atol : None, float, (7,) or (N, 7)
        Absolute tolerances; default each member's :func:`default_atol`.
    max_steps : int
        Cap on each member's steps (refused before the run if a member's lower bound exceeds it).
    lanes : int
        Members advanced together, 1 … 64.

    Returns
    -------
    ys : ndarray (N, 7)
        End states; NaN rows for members that stopped (see ``stats['status']``).
    stats : dict of ndarrays (N,)
        ``accepted``, ``rejected``, ``rhs_calls`` and ``status`` (0 success, else the
        :data:`~spinorbit.core.integrators.dop853.STATUS_MESSAGES` code), per member. A member that
        stops does not stop the others; :func:`raise_for_batch_status` turns stops into an error.

    Raises
    ------
    ValueError
        Bad states, times, tolerances, models or lanes (before any integration).
    """
    y0s, t0s, t_ends, models = validated_members(y0s, t0, t_end, models, lanes)
    n = y0s.shape[0]
    rtols = _validated_rtols(per_member("rtol", rtol, n, "relative tolerance"))
    spin = np.array([float(np.linalg.norm(row[4:])) for row in y0s])  # default_atol's and rotation_turns' |ω|
    atols = _validated_atols(atol, rtols, spin)
    for m in range(n):
        validate_sampled_span(models[m], t0s[m], t_ends[m:m + 1])
    # minimum_steps of every member at once; the worst one against the budget
    estimates = spin * np.abs(t_ends - t0s) / (2.0 * math.pi) * STEPS_PER_TURN_COEFFICIENT * rtols ** (-1.0 / 8.0)
    check_step_budget("integrate_quaternion_batch", float(estimates.max()), max_steps,
                      "shorten the span or loosen rtol")
    ys, stats = batch_dop853_kernel(y0s, t0s, t_ends, models, rtols, atols, int(max_steps), int(lanes))
    return ys, {"accepted": stats[:, STAT_ACCEPTED].copy(), "rejected": stats[:, STAT_REJECTED].copy(),
                "rhs_calls": stats[:, STAT_RHS_CALLS].copy(), "status": stats[:, STAT_STATUS].copy()}


def validated_members(y0s, t0, t_end, models, lanes):
    """The checks every batch integrator makes of its members, in this order: (y0s with q normalised as
    :func:`validate_state` does it, t0s, t_ends, models as one (N, M) array), or a ValueError saying what
    is wrong (NonFiniteError for NaN/inf states)."""
    y0s = np.asarray(y0s, dtype=float)
    if y0s.ndim != 2 or y0s.shape[1] != STATE_SIZE or y0s.shape[0] == 0:
        raise ValueError(f"y0s: expected an (N, {STATE_SIZE}) array of states (q, ω), one row per member, "
                         f"got shape {y0s.shape}.")
    n = y0s.shape[0]
    y0s = _validated_states(y0s)
    if isinstance(lanes, bool) or not isinstance(lanes, (int, np.integer)) or not 1 <= lanes <= MAX_LANES:
        raise ValueError(f"lanes: expected a whole number of lanes from 1 to {MAX_LANES}, got {lanes!r}.")
    t0s = per_member("t0", t0, n, "start time")
    t_ends = per_member("t_end", t_end, n, "end time")
    if not (np.all(np.isfinite(t0s)) and np.all(np.isfinite(t_ends))):
        raise ValueError("t0/t_end: expected finite times, got NaN or inf.")
    if np.any(t_ends == t0s):
        bad = int(np.flatnonzero(t_ends == t0s)[0])
        raise ValueError(f"t_end: expected an end time other than t0 for every member; member {bad} has "
                         f"t0 = t_end = {float(t0s[bad])!r}.")
    models = _stack_models(models, n)
    return y0s, t0s, t_ends, models


def _validated_states(y0s):
    """The states with q normalised exactly as :func:`validate_state` does it, checked all at once."""
    require_finite("y0s", y0s, "finite states (q, ω)")
    norms = np.array([math.sqrt(float(np.dot(q, q))) for q in y0s[:, :QUATERNION_SIZE]])  # validate_state's sum
    if np.any(norms < 1e-150):
        bad = int(np.flatnonzero(norms < 1e-150)[0])
        raise ValueError(f"y0s: expected a non-zero quaternion in every row's first 4 numbers; member {bad} has "
                         f"{y0s[bad, :QUATERNION_SIZE].tolist()}; use (1, 0, 0, 0) for the identity attitude.")
    y0s = y0s.copy()
    y0s[:, :QUATERNION_SIZE] /= norms[:, None]
    return y0s


def _validated_rtols(rtols):
    """validate_tolerances' checks of rtol, for every member, naming the first bad one."""
    bad = ~(np.isfinite(rtols) & (rtols > 0))
    if np.any(bad):
        m = int(np.flatnonzero(bad)[0])
        raise ValueError(f"rtol: expected a relative tolerance > 0, got {float(rtols[m])!r} for member {m}; try 1e-10.")
    if np.any(rtols < 1e-15):
        m = int(np.flatnonzero(rtols < 1e-15)[0])
        raise ValueError(f"rtol: expected rtol ≥ 1e-15 (double precision cannot do better), got {float(rtols[m])!r} "
                         f"for member {m}.")
    return rtols


def _validated_atols(atol, rtols, spin):
    """(N, 7) absolute tolerances: each member's default_atol (its bits), or the given ones checked."""
    n = rtols.shape[0]
    if atol is None:
        scale = np.ones((n, STATE_SIZE))
        scale[:, QUATERNION_SIZE:] = np.maximum(spin, 1e-300)[:, None]
        return rtols[:, None] * scale
    atol = np.asarray(atol, dtype=float)
    if atol.shape not in ((), (1,), (STATE_SIZE,), (n, STATE_SIZE)):
        raise ValueError(f"atol: expected a scalar, {STATE_SIZE} values or an (N, {STATE_SIZE}) array with "
                         f"N = {n}, got shape {atol.shape}.")
    atols = np.broadcast_to(atol, (n, STATE_SIZE)).copy()
    if not np.all(np.isfinite(atols)) or np.any(atols < 0):
        raise ValueError(f"atol: expected absolute tolerances ≥ 0 (scalar, {STATE_SIZE} values or one row per "
                         f"member), got {atol.tolist()}.")
    return atols


def _stack_models(models, n):
    """The members' models as one (N, M) float array, or a ValueError saying what is wrong."""
    if isinstance(models, np.ndarray) and models.ndim == 2 and models.shape[0] == n:
        stacked = np.ascontiguousarray(models, dtype=float)  # stacked already (the ensemble's groups): no copy
    else:
        if isinstance(models, np.ndarray) and models.ndim == 1 or (
                not isinstance(models, np.ndarray) and len(models) > 0 and np.ndim(models[0]) == 0):
            models = [np.asarray(models, dtype=float)] * n
        models = list(models)
        if len(models) != n:
            raise ValueError(f"models: expected one model per member ({n}) or one for all, got {len(models)}.")
        sizes = {np.asarray(model).size for model in models}
        if len(sizes) != 1:
            raise ValueError(f"models: expected model arrays of one length (the same perturber layout), got lengths "
                             f"{sorted(sizes)}; build the members' models from the same kinds of sources.")
        stacked = np.ascontiguousarray(np.array([np.asarray(model, dtype=float).ravel() for model in models]))
    for m, model in enumerate(stacked):
        if has_interior(model):
            raise ValueError(f"models: member {m} has a mantle-and-core interior block; the batch integrator "
                             "runs rigid bodies (7 components) only, use integrate_quaternion for it.")
    return stacked


def raise_for_batch_status(stats):
    """Raise :class:`~spinorbit.core.integrators.dop853.IntegrationError` naming every member that stopped."""
    from spinorbit.core.integrators.dop853 import IntegrationError

    stopped = np.flatnonzero(stats["status"] != STATUS_SUCCESS)
    if stopped.size:
        first = int(stopped[0])
        raise IntegrationError(f"{stopped.size} member(s) stopped, first member {first} after "
                               f"{int(stats['accepted'][first] + stats['rejected'][first])} steps: "
                               f"{STATUS_MESSAGES[int(stats['status'][first])]} (members {stopped[:10].tolist()}).")
