"""Adaptive DOP853 integration of the Euler-parameter equations, entirely in numba.

Method (Fukushima 2008b, AJ 135, 2298): integrate the quaternion q and the body angular velocity ω
(:mod:`spinorbit.core.dynamics.equations`) with a general high-order explicit method and **renormalise q after
every accepted step**. The attitude is never singular (no Euler-angle or Andoyer singularity), which
makes this the robust default.

Why DOP853 (Dormand & Prince's 8(5,3) pair, Hairer, Nørsett & Wanner, Solving ODEs I, §II.10):

- the rotational problem is smooth and non-stiff, and the accuracies asked for (1e-8 … 1e-14 rad)
  are where an 8th-order method takes long steps; Verner's 9(8) pairs gain little at double precision
  and cost 16 stages;
- its error estimator (a 5th- and a 3rd-order embedded solution combined) is robust when the step is
  far from the asymptotic regime;
- it has a 7th-order continuous extension (3 extra stages only on steps that contain output times), so
  output at requested times does not shorten the steps;
- it is scipy's ``DOP853`` with the same coefficients (``_dop853_tableau.py``) and the same
  error norm, so the work-precision comparison against scipy measures the implementation, not the
  method.

Error control: on an accepted step, sqrt(mean_i (err_i / sc_i)²) ≤ 1 with
sc_i = atol_i + rtol · max(|y_i|, |y_new,i|) over all seven components (q, ω), err being the combined
5th/3rd-order estimate of scipy/Hairer. This controls the *local* error per step; the global attitude
error grows with the number of steps (roughly linearly in time for this problem, faster where the
motion is chaotic), so a requested rtol is not a promised final accuracy: the benchmark
(``docs/performance.md``) shows the measured global error against rtol.

Quaternion renormalisation after each step: the exact flow keeps |q| = 1; the numerical one drifts by
the local error. Renormalising removes that drift component without changing the attitude (the RHS
already depends on q only through q/|q|, :func:`dynamics.body_frame_position`), and the FSAL derivative
is rescaled accordingly (q̇ is linear in q, ω̇ independent of |q|), so no extra RHS call is needed.
"""

import math

import numpy as np

from spinorbit.core.integrators.dop853_tableau import A as _A_FULL
from spinorbit.core.integrators.dop853_tableau import C as _C_FULL
from spinorbit.core.integrators.dop853_tableau import D as _D_FULL
from spinorbit.core.integrators.dop853_tableau import E3 as _E3
from spinorbit.core.integrators.dop853_tableau import E5 as _E5
from spinorbit.core.integrators.dop853_tableau import N_STAGES
from spinorbit.core.jit import jit
from spinorbit.core.dynamics.equations import STATE_SIZE, rhs_into
from spinorbit.core.dynamics.validation import validate_output_times, validate_sampled_span, validate_state
from spinorbit.core.model.lunar_interior import INTERIOR_STATE_SIZE, has_interior

_A = np.ascontiguousarray(_A_FULL)
_C = np.ascontiguousarray(_C_FULL)
_B = np.ascontiguousarray(_A_FULL[N_STAGES, :N_STAGES])
_D = np.ascontiguousarray(_D_FULL)
_E3C = np.ascontiguousarray(_E3)
_E5C = np.ascontiguousarray(_E5)

#: Step-size controller constants (Hairer's DOP853 / scipy): safety factor on the predicted step,
#: and bounds on the step ratio that keep the controller stable after rejections and near events.
SAFETY = 0.9
MIN_FACTOR = 0.2
MAX_FACTOR = 10.0
#: Exponent of the error norm: the estimator's order is 7, so the step scales like err^(−1/8).
ERROR_EXPONENT = -1.0 / 8.0
#: Default cap on the number of steps: a run stops with STATUS_MAX_STEPS rather than loop forever.
DEFAULT_MAX_STEPS = 100_000_000

#: Floor of an error scale: a component that is exactly 0 with atol = 0 must not divide by zero.
_TINY_SCALE = 1e-300

STATUS_SUCCESS = 0
STATUS_MAX_STEPS = 1
STATUS_STEP_TOO_SMALL = 2
STATUS_NOT_FINITE = 3

# Index of each counter in the stats array returned by the kernels.
STAT_ACCEPTED, STAT_REJECTED, STAT_RHS_CALLS, STAT_STATUS = 0, 1, 2, 3


@jit
def _rk_step(t, y, f0, h, model, k, y_new, tmp):
    """Stages 1..12 of DOP853 from (t, y) with f0 = f(t, y); 8th-order result into y_new.

    k has 16 rows: row 0 = f0, rows 1..11 the stages, row 12 f(t+h, y_new) (FSAL). tmp is scratch.
    The stage sums run over j outside, components inside (contiguous rows of k) and skip the
    tableau's zeros (a third of the entries below the diagonal).
    """
    n = y.shape[0]
    for i in range(n):
        k[0, i] = f0[i]
    for s in range(1, N_STAGES):
        for i in range(n):
            tmp[i] = 0.0
        for j in range(s):
            a = _A[s, j] * h
            if a != 0.0:
                for i in range(n):
                    tmp[i] += a * k[j, i]
        for i in range(n):
            tmp[i] += y[i]
        rhs_into(t + _C[s] * h, tmp, model, k[s])
    for i in range(n):
        y_new[i] = 0.0
    for j in range(N_STAGES):
        b = _B[j] * h
        if b != 0.0:
            for i in range(n):
                y_new[i] += b * k[j, i]
    for i in range(n):
        y_new[i] += y[i]
    rhs_into(t + h, y_new, model, k[N_STAGES])


@jit
def _error_norm(k, h, y, y_new, rtol, atol):
    """scipy/Hairer DOP853 error norm (combined 5th- and 3rd-order estimates), RMS over components."""
    n = y.shape[0]
    err5 = 0.0
    err3 = 0.0
    for i in range(n):
        scale = max(atol[i] + rtol * max(abs(y[i]), abs(y_new[i])), _TINY_SCALE)
        e5 = 0.0
        e3 = 0.0
        for j in range(N_STAGES + 1):
            e5 += _E5C[j] * k[j, i]
            e3 += _E3C[j] * k[j, i]
        e5 /= scale
        e3 /= scale
        err5 += e5 * e5
        err3 += e3 * e3
    if err5 == 0.0 and err3 == 0.0:
        return 0.0
    denom = err5 + 0.01 * err3
    return abs(h) * err5 / math.sqrt(denom * n)


@jit
def _extra_stage_input(y, h, k, s, tmp):
    """State at which DOP853's stage s is evaluated: y + h Σ_j A[s, j] k_j (RHS-independent)."""
    for i in range(y.shape[0]):
        acc = 0.0
        for j in range(s):
            acc += _A[s, j] * k[j, i]
        tmp[i] = y[i] + h * acc


@jit
def _dense_rows(y, y_new, f_new, h, k, coeffs):
    """The 7 coefficient rows of DOP853's continuous extension from the 16 stages (scipy's F).

    Independent of the right-hand side, so every DOP853 driver in the package shares it.
    """
    for i in range(y.shape[0]):
        delta = y_new[i] - y[i]
        coeffs[0, i] = delta
        coeffs[1, i] = h * k[0, i] - delta
        coeffs[2, i] = 2.0 * delta - h * (f_new[i] + k[0, i])
        for r in range(4):
            acc = 0.0
            for j in range(16):
                acc += _D[r, j] * k[j, i]
            coeffs[3 + r, i] = h * acc


@jit
def _dense_polynomial(coeffs, y, x, out):
    """Evaluate the continuous extension at x = (t − t_old)/h ∈ [0, 1] (RHS-independent)."""
    for i in range(y.shape[0]):
        acc = 0.0
        for r in range(6, -1, -1):
            acc += coeffs[r, i]
            if (6 - r) % 2 == 0:
                acc *= x
            else:
                acc *= 1.0 - x
        out[i] = y[i] + acc


@jit
def _dense_coefficients(t, y, y_new, f_new, h, model, k, coeffs):
    """Extra stages 13..15 of the quaternion RHS, then the continuous-extension rows."""
    tmp = np.empty(y.shape[0])
    for s in range(N_STAGES + 1, 16):
        _extra_stage_input(y, h, k, s, tmp)
        rhs_into(t + _C[s] * h, tmp, model, k[s])
    _dense_rows(y, y_new, f_new, h, k, coeffs)


@jit
def _dense_evaluate(coeffs, y, x, out):
    """Evaluate the continuous extension at x and renormalise q."""
    _dense_polynomial(coeffs, y, x, out)
    _normalize_quaternion_part(out)


@jit
def _normalize_quaternion_part(y):
    """Divide y[0:4] by its norm; return the norm (for rescaling q̇)."""
    norm = math.sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2] + y[3] * y[3])
    for i in range(4):
        y[i] /= norm
    return norm


@jit
def _initial_step(t0, y0, f0, direction, rtol, atol, model):
    """Hairer's starting-step heuristic (Solving ODEs I, §II.4), as in scipy's select_initial_step."""
    n = y0.shape[0]
    d0 = 0.0
    d1 = 0.0
    for i in range(n):
        sc = max(atol[i] + abs(y0[i]) * rtol, _TINY_SCALE)
        d0 += (y0[i] / sc) ** 2
        d1 += (f0[i] / sc) ** 2
    d0 = math.sqrt(d0 / n)
    d1 = math.sqrt(d1 / n)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    y1 = y0 + direction * h0 * f0
    f1 = np.empty(n)
    rhs_into(t0 + direction * h0, y1, model, f1)
    d2 = 0.0
    for i in range(n):
        sc = max(atol[i] + abs(y0[i]) * rtol, _TINY_SCALE)
        d2 += ((f1[i] - f0[i]) / sc) ** 2
    d2 = math.sqrt(d2 / n) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / 8.0)
    return min(100.0 * h0, h1)


@jit
def integrate_dop853_kernel(y0, t0, t_out, model, rtol, atol, max_steps, hit_output_times, first_step):
    """Adaptive DOP853 from (t0, y0) with output at the increasing (or decreasing) times ``t_out``.

    Parameters
    ----------
    y0 : ndarray (7,)
        Initial state (q normalised by the caller).
    t0 : float
        Initial time.
    t_out : ndarray (n,)
        Output times, strictly monotone, all on one side of t0 (the direction of integration).
    model : ndarray
        The model array of :mod:`spinorbit.core.dynamics.equations`.
    rtol : float
        Relative tolerance (> 0).
    atol : ndarray (7,)
        Absolute tolerances per component (≥ 0).
    max_steps : int
        Cap on accepted + rejected steps.
    hit_output_times : bool
        True: shorten steps to land exactly on every output time (8th-order outputs, more steps);
        False: take free steps and use the 7th-order continuous extension at the output times.
    first_step : float
        Initial step size (> 0) or 0 to choose it automatically.

    Returns
    -------
    ys : ndarray (n, 7)
        States at t_out (q renormalised).
    stats : ndarray (4,) int64
        [accepted steps, rejected steps, RHS calls, status] (STATUS_* constants).
    """
    n = y0.shape[0]
    n_out = t_out.shape[0]
    ys = np.full((n_out, n), np.nan)
    stats = np.zeros(4, dtype=np.int64)
    k = np.zeros((16, n))
    coeffs = np.zeros((7, n))
    y = y0.copy()
    y_new = np.empty(n)
    scratch = np.empty(n)
    f = np.empty(n)
    f_new = np.empty(n)
    t_end = t_out[n_out - 1]
    direction = 1.0 if t_end >= t0 else -1.0
    rhs_into(t0, y, model, f)
    stats[STAT_RHS_CALLS] += 1
    if first_step > 0.0:
        h_abs = first_step
    else:
        h_abs = _initial_step(t0, y, f, direction, rtol, atol, model)
        stats[STAT_RHS_CALLS] += 1
    if not (math.isfinite(h_abs) and h_abs > 0.0):
        stats[STAT_STATUS] = STATUS_NOT_FINITE
        return ys, stats
    t = t0
    i_out = 0
    # Outputs at t0 itself.
    while i_out < n_out and t_out[i_out] == t0:
        ys[i_out] = y
        i_out += 1
    steps = 0
    while i_out < n_out:
        if steps >= max_steps:
            stats[STAT_STATUS] = STATUS_MAX_STEPS
            return ys, stats
        target = t_out[i_out] if hit_output_times else t_end
        min_step = 10.0 * abs(np.nextafter(t, t + direction) - t)
        if h_abs < min_step:
            h_abs = min_step
        accepted = False
        rejected = False
        while not accepted:
            if steps >= max_steps:
                stats[STAT_STATUS] = STATUS_MAX_STEPS
                return ys, stats
            if not (h_abs >= min_step):  # also catches NaN
                stats[STAT_STATUS] = STATUS_STEP_TOO_SMALL
                return ys, stats
            h = direction * h_abs
            t_new = t + h
            if direction * (t_new - target) > 0.0:
                t_new = target
            h = t_new - t
            h_abs = abs(h)
            _rk_step(t, y, f, h, model, k, y_new, scratch)
            stats[STAT_RHS_CALLS] += N_STAGES
            steps += 1
            err = _error_norm(k, h, y, y_new, rtol, atol)
            if not math.isfinite(err):
                # A NaN state (e.g. a sampled perturber asked outside its span): shrink, then give up.
                if h_abs <= min_step:
                    stats[STAT_STATUS] = STATUS_NOT_FINITE
                    return ys, stats
                h_abs *= MIN_FACTOR
                rejected = True
                stats[STAT_REJECTED] += 1
                continue
            if err < 1.0:
                factor = MAX_FACTOR if err == 0.0 else min(MAX_FACTOR, SAFETY * err ** ERROR_EXPONENT)
                if rejected:
                    factor = min(1.0, factor)
                h_abs *= factor
                accepted = True
            else:
                h_abs *= max(MIN_FACTOR, SAFETY * err ** ERROR_EXPONENT)
                rejected = True
                stats[STAT_REJECTED] += 1
        stats[STAT_ACCEPTED] += 1
        for i in range(n):
            f_new[i] = k[N_STAGES, i]
        # Outputs inside (t, t_new]: dense output (built from the unnormalised end point, which is
        # what the stages are consistent with), or the step end itself.
        dense_ready = False
        while i_out < n_out and direction * (t_out[i_out] - t_new) <= 0.0:
            if t_out[i_out] == t_new:
                ys[i_out] = y_new
                _normalize_quaternion_part(ys[i_out])
            else:
                if not dense_ready:
                    _dense_coefficients(t, y, y_new, f_new, h, model, k, coeffs)
                    stats[STAT_RHS_CALLS] += 3
                    dense_ready = True
                _dense_evaluate(coeffs, y, (t_out[i_out] - t) / h, ys[i_out])
            i_out += 1
        # Renormalise q (Fukushima 2008b) and rescale the FSAL q̇ consistently.
        norm = _normalize_quaternion_part(y_new)
        for i in range(4):
            f_new[i] /= norm
        t = t_new
        for i in range(n):
            y[i] = y_new[i]
            f[i] = f_new[i]
    stats[STAT_STATUS] = STATUS_SUCCESS
    return ys, stats


@jit
def integrate_fixed_step_kernel(y0, t0, t1, n_steps, model):
    """n_steps equal DOP853 steps (8th-order solution, q renormalised each step) → y(t1).

    For measuring the order of convergence; no error control.
    """
    n = y0.shape[0]
    k = np.zeros((16, n))
    y = y0.copy()
    y_new = np.empty(n)
    f = np.empty(n)
    h = (t1 - t0) / n_steps
    t = t0
    rhs_into(t, y, model, f)
    scratch = np.empty(n)
    for step in range(n_steps):
        _rk_step(t, y, f, h, model, k, y_new, scratch)
        norm = _normalize_quaternion_part(y_new)
        for i in range(n):
            y[i] = y_new[i]
            f[i] = k[N_STAGES, i]
        for i in range(4):
            f[i] /= norm
        t = t0 + (step + 1) * h
    return y


# ---------------------------------------------------------------------------------------------
# Python front end: validation only, then one call into the kernel.


class IntegrationError(RuntimeError):
    """The kernel stopped before the last output time (step cap, step underflow, non-finite state)."""


_STATUS_MESSAGES = {
    STATUS_MAX_STEPS: "reached max_steps; raise max_steps or loosen rtol",
    STATUS_STEP_TOO_SMALL: "the step size underflowed; the solution may be singular (e.g. a perturber "
    "passing through the body)",
    STATUS_NOT_FINITE: "the state became NaN/inf; check that sampled perturbers cover the whole time span",
}


def default_atol(y0, rtol):
    """atol = rtol × (1, 1, 1, 1, |ω₀|, |ω₀|, |ω₀|[, |ω₀|, |ω₀|, |ω₀|]): each component's natural scale.

    Quaternion components are O(1) but pass through zero twice a turn, so a purely relative test would
    demand absurd accuracy near the zeros; the ω components (and a core's ω_c) share the scale |ω₀|.
    """
    scale = np.ones(y0.shape[0])
    scale[4:] = max(float(np.linalg.norm(y0[4:])), 1e-300)
    return rtol * scale


def _validate_tolerances(rtol, atol, size=STATE_SIZE):
    if not (np.isfinite(rtol) and rtol > 0):
        raise ValueError(f"rtol: expected a relative tolerance > 0, got {rtol!r}; try 1e-10.")
    if rtol < 1e-15:
        raise ValueError(f"rtol: expected rtol ≥ 1e-15 (double precision cannot do better), got {rtol!r}.")
    atol = np.asarray(atol, dtype=float)
    if atol.shape not in ((), (1,), (size,)):
        raise ValueError(
            f"atol: expected a scalar or {size} values (one per state component), got shape {atol.shape}; "
            "pass one number for all components or one per component."
        )
    atol = np.broadcast_to(atol, (size,)).copy()
    if not np.all(np.isfinite(atol)) or np.any(atol < 0):
        raise ValueError(f"atol: expected absolute tolerances ≥ 0 (scalar or {size} values), got {atol.tolist()}.")
    return float(rtol), atol


def integrate_quaternion(y0, t0, t_out, model, rtol=1e-10, atol=None, max_steps=DEFAULT_MAX_STEPS,
                         hit_output_times=False, first_step=0.0, return_stats=False):
    """Integrate the rotational equations of motion with adaptive DOP853 and renormalised q.

    Parameters
    ----------
    y0 : array_like (7,) or (10,)
        Initial state (q0, q1, q2, q3, ωx, ωy, ωz): scalar-first quaternion (normalised here) and
        body angular velocity (rad/time unit); with a model that ends with an interior block
        (:mod:`spinorbit.core.model.lunar_interior`), also the core's ω_c on the body axes.
    t0 : float
        Initial time (time unit of the model, e.g. days).
    t_out : array_like (n,)
        Output times, strictly monotone away from t0.
    model : ndarray
        From :func:`spinorbit.core.dynamics.equations.make_model`.
    rtol : float
        Relative local error tolerance, 1e-15 ≤ rtol.
    atol : float or array_like (7,), optional
        Absolute local error tolerance per component (same units as the components); default
        :func:`default_atol` (rtol times each component's natural scale).
    max_steps : int
        Cap on the number of steps.
    hit_output_times : bool
        Land steps exactly on the output times instead of using the continuous extension.
    first_step : float
        Initial step (time unit); 0 chooses it automatically.
    return_stats : bool
        Also return a dict of step counts.

    Returns
    -------
    ys : ndarray (n, 7)
        States at t_out.
    stats : dict, optional
        ``accepted``, ``rejected``, ``rhs_calls``.

    Raises
    ------
    ValueError
        Bad state, times or tolerances, or output times outside the span of a sampled perturber.
    IntegrationError
        The kernel stopped early (see the message).
    """
    model = np.ascontiguousarray(model, dtype=float)
    y0 = validate_state(y0, INTERIOR_STATE_SIZE if has_interior(model) else STATE_SIZE)
    t0 = float(t0)
    t_out = validate_output_times(t0, t_out)
    rtol, atol = _validate_tolerances(rtol, default_atol(y0, rtol) if atol is None else atol, y0.shape[0])
    validate_sampled_span(model, t0, t_out)
    ys, stats = integrate_dop853_kernel(y0, t0, t_out, model, rtol, atol, int(max_steps),
                                        bool(hit_output_times), float(first_step))
    status = int(stats[STAT_STATUS])
    if status != STATUS_SUCCESS:
        raise IntegrationError(f"integration stopped at step {int(stats[0] + stats[1])}: {_STATUS_MESSAGES[status]}.")
    if return_stats:
        return ys, {"accepted": int(stats[0]), "rejected": int(stats[1]), "rhs_calls": int(stats[2])}
    return ys


def integrate_fixed_step(y0, t0, t1, n_steps, model):
    """y(t1) after ``n_steps`` equal DOP853 steps (order measurements; no error control)."""
    y0 = validate_state(y0)
    if int(n_steps) < 1:
        raise ValueError(f"n_steps: expected a positive number of steps, got {n_steps!r}.")
    return integrate_fixed_step_kernel(y0, float(t0), float(t1), int(n_steps), model)
