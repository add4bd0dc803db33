"""The one DOP853 engine: Dormand & Prince's 8(5,3) pair with dense output, in numba.

Hairer, Nørsett & Wanner, Solving ODEs I, §II.10 (the method, its error estimator and its 7th-order
continuous extension), with scipy's ``DOP853`` coefficients (:mod:`.dop853_tableau`) and error norm,
so a comparison against scipy measures the implementation, not the method. Every DOP853 propagator of
the package is a thin user of this module: the quaternion equations (:mod:`.quaternion`), the
canonical elements (:mod:`~spinorbit.core.integrators.elements`) and the mean elements
(:mod:`spinorbit.core.averaging.propagate`, fixed steps). The pieces, as in hapsira's numba DOP853:

- :func:`dop853_stages` — stages 1..11 and the 8th-order solution, for a right-hand side given as an
  argument; :func:`dop853_step` adds stage 0 (a step without FSAL, for fixed-step users);
- :func:`error_norm` — the combined 5th/3rd-order estimate, RMS over components;
- :func:`dense_coefficients`, :func:`dense_polynomial` — the continuous extension;
- :func:`accepted_step_factor`, :func:`rejected_step_factor` — the step-size controller, plain
  (β = 0) or PI (β > 0, Hairer's ``BETA``);
- :func:`initial_step` — Hairer's starting-step heuristic;
- :func:`dop853_integrate` — the adaptive loop with output at given times (landing on them or dense
  output), and :func:`dop853_fixed_steps` — equal steps for order measurements.

**The right-hand side and the hooks.** ``rhs(t, y, params, out)`` writes dy/dt into ``out`` and
returns an *info* value (None, or e.g. the singularity distances of the canonical elements);
``params`` is whatever the propagator needs (a model array, a tuple). What really differs between
the propagators is a hook, not a copy of the loop:

- ``status_of(info)`` → ``STATUS_SUCCESS`` or the propagator's own stop code (singular sets);
- ``after_accept(params, t, y, f, info)`` → ``(info, rhs_calls)``: the change of representation
  after an accepted step, in place on the state y and its derivative f (renormalise q; move whole
  periods of s into z and re-evaluate f);
- ``finish_output(row)``: in place on an output row (renormalise q).

**numba.** A function that takes the right-hand side or a hook as an argument is
``inline="always"``: numba inlines it into the propagator's kernel at the IR level, so the RHS is a
direct call (specialised per function, no indirect call) and the kernel, which names its RHS as a
global, is cached like any other. Without inlining numba refuses to cache a kernel that passes a
jitted function as a value ("dynamic globals"), and a kernel called from Python with a dispatcher
argument misses the cache in every new process (both checked with numba 0.68). The pieces that do
not see the RHS are ordinary cached functions. Being inlined, the engine is compiled into each
user's cache entry: after editing this module, clear the numba cache.
"""

import math

import numpy as np

from spinorbit.core.integrators.dop853_tableau import A as _A_FULL
from spinorbit.core.integrators.dop853_tableau import C as _C_FULL
from spinorbit.core.integrators.dop853_tableau import D as _D_FULL
from spinorbit.core.integrators.dop853_tableau import E3 as _E3_FULL
from spinorbit.core.integrators.dop853_tableau import E5 as _E5_FULL
from spinorbit.core.integrators.dop853_tableau import INTERPOLATOR_POWER, N_STAGES, N_STAGES_EXTENDED
from spinorbit.core.jit import jit

# Contiguous copies of the tableau: numba freezes them into the compiled code as constants.
A = np.array(_A_FULL, order="C")
B = np.array(_A_FULL[N_STAGES, :N_STAGES], order="C")
C = np.array(_C_FULL, order="C")
D = np.array(_D_FULL, order="C")
E3 = np.array(_E3_FULL, order="C")
E5 = np.array(_E5_FULL, order="C")

#: Step-size controller constants (Hairer's DOP853 / scipy): safety factor on the predicted step,
#: and bounds on the step ratio that keep the controller stable after rejections and near events.
SAFETY = 0.9
MIN_FACTOR = 0.2
MAX_FACTOR = 10.0
#: Exponent of the error norm: the estimator's order is 7, so the step scales like err^(−1/8).
ERROR_EXPONENT = -1.0 / 8.0
#: Hairer's lower bound on the remembered error of the PI controller (FACOLD = 1e-4).
PREVIOUS_ERROR_FLOOR = 1e-4
#: Default cap on the number of steps: a run stops with STATUS_MAX_STEPS rather than loop forever.
DEFAULT_MAX_STEPS = 100_000_000

#: Floor of an error scale: a component that is exactly 0 with atol = 0 must not divide by zero.
TINY_SCALE = 1e-300

STATUS_SUCCESS = 0
STATUS_MAX_STEPS = 1
STATUS_STEP_TOO_SMALL = 2
STATUS_NOT_FINITE = 3

# Index of each counter in the stats array returned by the adaptive loop.
STAT_ACCEPTED, STAT_REJECTED, STAT_RHS_CALLS, STAT_STATUS = 0, 1, 2, 3
STATS_SIZE = 4

#: What the engine's own stop codes mean, for the propagators' error messages.
STATUS_MESSAGES = {
    STATUS_MAX_STEPS: "reached max_steps; raise max_steps or loosen rtol",
    STATUS_STEP_TOO_SMALL: "the step size underflowed; the solution may be singular (e.g. a perturber "
    "passing through the body)",
    STATUS_NOT_FINITE: "the state became NaN/inf; check that sampled perturbers cover the whole time span",
}


class IntegrationError(RuntimeError):
    """The kernel stopped before the last output time (step cap, step underflow, non-finite state)."""


def raise_for_engine_status(stats):
    """Raise :class:`IntegrationError` for an engine stop code in ``stats`` (after the caller's own codes)."""
    status = int(stats[STAT_STATUS])
    if status != STATUS_SUCCESS:
        steps = int(stats[STAT_ACCEPTED] + stats[STAT_REJECTED])
        raise IntegrationError(f"integration stopped at step {steps}: {STATUS_MESSAGES[status]}.")


def stats_record(stats):
    """The stats array of :func:`dop853_integrate` as the wrappers' ``return_stats`` dict."""
    return {"accepted": int(stats[STAT_ACCEPTED]), "rejected": int(stats[STAT_REJECTED]),
            "rhs_calls": int(stats[STAT_RHS_CALLS])}


# ---------------------------------------------------------------------------------------------
# Stages and the step


@jit(inline="always")
def stage_input(y, h, k, s, out):
    """out = y + h Σ_{j<s} A[s, j] k_j, the state at which stage s is evaluated (s = 12: the 8th-order
    solution, A[12, :12] being B).

    The sum runs over j outside, components inside (contiguous rows of k) and skips the tableau's
    zeros (a third of the entries below the diagonal).
    """
    n = y.shape[0]
    a = A[s, 0] * h  # never a zero of the tableau; 0.0 + keeps the sign of zero of a sum started at 0
    for i in range(n):
        out[i] = 0.0 + a * k[0, i]
    for j in range(1, s):
        a = A[s, j] * h
        if a != 0.0:
            for i in range(n):
                out[i] += a * k[j, i]
    for i in range(n):
        out[i] += y[i]


@jit(inline="always")
def dop853_stages(rhs, params, t, y, h, k, tmp, y_new):
    """Stages 1..11 from (t, y) with k[0] = f(t, y) set by the caller; the 8th-order result into y_new.

    k has N_STAGES_EXTENDED rows (the dense output's extra stages go to rows 13..15); tmp is
    scratch of y's size. The caller evaluates f(t + h, y_new) (FSAL) if it needs it.
    """
    for s in range(1, N_STAGES):
        stage_input(y, h, k, s, tmp)
        rhs(t + C[s] * h, tmp, params, k[s])
    stage_input(y, h, k, N_STAGES, y_new)  # row 12 of A is B: the 8th-order solution


@jit(inline="always")
def dop853_step(rhs, params, t, y, h, k, tmp, y_new):
    """One DOP853 step of size h from (t, y), stage 0 included, without error control or FSAL.

    For users that change the state between steps (the mean elements), so f(t + h, y_new) is not
    the next step's first stage.
    """
    rhs(t, y, params, k[0])
    dop853_stages(rhs, params, t, y, h, k, tmp, y_new)


@jit
def dop853_scratch(n):
    """(k, tmp, y_new) of :func:`dop853_step` for a state of n components (allocate once per run)."""
    return np.zeros((N_STAGES_EXTENDED, n)), np.empty(n), np.empty(n)


@jit(inline="always")
def landing_step(h, remaining):
    """A fixed-step user's step h shortened to land on an output ``remaining`` away.

    In one step if within 1 % of a full step, else never leaving a sliver shorter than half a step.
    """
    if remaining <= 1.01 * h:
        return remaining
    if remaining < 1.5 * h:
        return 0.5 * remaining
    return h


# ---------------------------------------------------------------------------------------------
# Error estimate, dense output, step-size control


@jit
def error_norm(k, h, y, y_new, rtol, atol):
    """scipy/Hairer DOP853 error norm (combined 5th- and 3rd-order estimates), RMS over components.

    Scale sc_i = atol_i + rtol · max(|y_i|, |y_new,i|); an accepted step has a norm ≤ 1.
    """
    n = y.shape[0]
    err5 = 0.0
    err3 = 0.0
    for i in range(n):
        scale = max(atol[i] + rtol * max(abs(y[i]), abs(y_new[i])), TINY_SCALE)
        e5 = 0.0
        e3 = 0.0
        for j in range(N_STAGES + 1):
            e5 += E5[j] * k[j, i]
            e3 += E3[j] * k[j, i]
        e5 /= scale
        e3 /= scale
        err5 += e5 * e5
        err3 += e3 * e3
    if err5 == 0.0 and err3 == 0.0:
        return 0.0
    denom = err5 + 0.01 * err3
    return abs(h) * err5 / math.sqrt(denom * n)


@jit
def accepted_step_factor(err, previous_error, beta):
    """Growth of the step after an accepted step with error norm err < 1.

    β = 0: the plain controller SAFETY · err^(−1/8). β > 0: the PI ("stabilised") controller of
    Hairer's DOP853 (Solving ODEs I, §IV.2), SAFETY · err^(−1/8 + 0.2 β) · previous_error^β, whose
    memory of the previous accepted error damps the oscillation of the step that causes rejections.
    """
    if err == 0.0:
        return MAX_FACTOR
    if beta == 0.0:
        return min(MAX_FACTOR, SAFETY * err ** ERROR_EXPONENT)
    return min(MAX_FACTOR, SAFETY * err ** (ERROR_EXPONENT + 0.2 * beta) * previous_error ** beta)


@jit
def rejected_step_factor(err):
    """Shrink factor of the step after a rejected step (error norm err ≥ 1)."""
    return max(MIN_FACTOR, SAFETY * err ** ERROR_EXPONENT)


@jit
def dense_rows(y, y_new, f_new, h, k, coeffs):
    """The 7 coefficient rows of DOP853's continuous extension from the 16 stages (scipy's F)."""
    for i in range(y.shape[0]):
        delta = y_new[i] - y[i]
        coeffs[0, i] = delta
        coeffs[1, i] = h * k[0, i] - delta
        coeffs[2, i] = 2.0 * delta - h * (f_new[i] + k[0, i])
        for r in range(INTERPOLATOR_POWER - 3):
            acc = 0.0
            for j in range(N_STAGES_EXTENDED):
                acc += D[r, j] * k[j, i]
            coeffs[3 + r, i] = h * acc


@jit(inline="always")
def dense_coefficients(rhs, params, t, y, y_new, f_new, h, k, tmp, coeffs):
    """Extra stages 13..15 of the step (t, y) → (t + h, y_new), then the continuous-extension rows."""
    for s in range(N_STAGES + 1, N_STAGES_EXTENDED):
        stage_input(y, h, k, s, tmp)
        rhs(t + C[s] * h, tmp, params, k[s])
    dense_rows(y, y_new, f_new, h, k, coeffs)


@jit
def dense_polynomial(coeffs, y, x, out):
    """Evaluate the continuous extension at x = (t − t_old)/h ∈ [0, 1] into out."""
    for i in range(y.shape[0]):
        acc = 0.0
        for r in range(INTERPOLATOR_POWER - 1, -1, -1):
            acc += coeffs[r, i]
            if (INTERPOLATOR_POWER - 1 - r) % 2 == 0:
                acc *= x
            else:
                acc *= 1.0 - x
        out[i] = y[i] + acc


@jit(inline="always")
def initial_step(rhs, params, t0, y0, f0, direction, rtol, atol):
    """Hairer's starting-step heuristic (Solving ODEs I, §II.4), as in scipy's select_initial_step.

    Costs one RHS call.
    """
    n = y0.shape[0]
    d0 = 0.0
    d1 = 0.0
    for i in range(n):
        sc = max(atol[i] + abs(y0[i]) * rtol, TINY_SCALE)
        d0 += (y0[i] / sc) ** 2
        d1 += (f0[i] / sc) ** 2
    d0 = math.sqrt(d0 / n)
    d1 = math.sqrt(d1 / n)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    y1 = y0 + direction * h0 * f0
    f1 = np.empty(n)
    rhs(t0 + direction * h0, y1, params, f1)
    d2 = 0.0
    for i in range(n):
        sc = max(atol[i] + abs(y0[i]) * rtol, TINY_SCALE)
        d2 += ((f1[i] - f0[i]) / sc) ** 2
    d2 = math.sqrt(d2 / n) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / 8.0)
    return min(100.0 * h0, h1)


# ---------------------------------------------------------------------------------------------
# Hooks of a propagator with nothing to add


@jit
def never_singular(info):
    """``status_of`` of a right-hand side without singular sets."""
    return STATUS_SUCCESS


@jit
def keep_representation(params, t, y, f, info):
    """``after_accept`` of a state that needs no change of representation."""
    return info, 0


@jit
def output_as_is(row):
    """``finish_output`` that leaves the output row as the polynomial gives it."""


# ---------------------------------------------------------------------------------------------
# Drivers


@jit(inline="always")
def dop853_integrate(rhs, params, status_of, after_accept, finish_output, y0, t0, t_out, rtol, atol,
                     max_steps, hit_output_times, first_step, beta):
    """Adaptive DOP853 from (t0, y0) with output at the increasing (or decreasing) times ``t_out``.

    Parameters
    ----------
    rhs, params, status_of, after_accept, finish_output
        The right-hand side and the hooks (module docstring).
    y0 : ndarray (n,)
        Initial state.
    t0 : float
        Initial time.
    t_out : ndarray (n_out,)
        Output times, strictly monotone, all on one side of t0 (the direction of integration).
    rtol : float
        Relative tolerance (≥ 0; 0 for a purely absolute test).
    atol : ndarray (n,)
        Absolute tolerances per component (≥ 0, > 0 where rtol = 0).
    max_steps : int
        Cap on accepted + rejected steps.
    hit_output_times : bool
        True: shorten steps to land exactly on every output time (8th-order outputs, more steps);
        False: take free steps and use the 7th-order continuous extension at the output times.
    first_step : float
        Initial step size (> 0) or 0 to choose it automatically.
    beta : float
        β of the step-size controller (:func:`accepted_step_factor`; 0 = plain).

    Returns
    -------
    ys : ndarray (n_out, n)
        States at t_out (``finish_output`` applied; NaN after a stop; the outputs at t0 itself are
        y0 as given).
    stats : ndarray (4,) int64
        [accepted steps, rejected steps, RHS calls, status] (STATUS_* constants or the code of
        ``status_of``).
    t_stop : float
        Time of the last accepted step.
    y_stop : ndarray (n,)
        State at ``t_stop`` (after ``after_accept``).

    The run stops early, with ``status_of``'s code, when that code is not STATUS_SUCCESS at the start
    or at the end of an accepted step before the last output.
    """
    n = y0.shape[0]
    n_out = t_out.shape[0]
    ys = np.full((n_out, n), np.nan)
    stats = np.zeros(STATS_SIZE, dtype=np.int64)
    k = np.zeros((N_STAGES_EXTENDED, n))
    coeffs = np.zeros((INTERPOLATOR_POWER, n))
    y = y0.copy()
    y_new = np.empty(n)
    scratch = np.empty(n)
    f = np.empty(n)
    f_new = np.empty(n)
    t_end = t_out[n_out - 1]
    direction = 1.0 if t_end >= t0 else -1.0
    info = rhs(t0, y, params, f)
    stats[STAT_RHS_CALLS] += 1
    t = t0
    status = status_of(info)
    if status != STATUS_SUCCESS:
        stats[STAT_STATUS] = status
        return ys, stats, t, y
    if first_step > 0.0:
        h_abs = first_step
    else:
        h_abs = initial_step(rhs, params, t0, y, f, direction, rtol, atol)
        stats[STAT_RHS_CALLS] += 1
    if not (math.isfinite(h_abs) and h_abs > 0.0):
        stats[STAT_STATUS] = STATUS_NOT_FINITE
        return ys, stats, t, y
    i_out = 0
    while i_out < n_out and t_out[i_out] == t0:
        for i in range(n):  # element by element: a row assignment compiles numba's shape-error formatting
            ys[i_out, i] = y[i]
        i_out += 1
    steps = 0
    previous_error = PREVIOUS_ERROR_FLOOR
    while i_out < n_out:
        target = t_out[i_out] if hit_output_times else t_end
        min_step = 10.0 * abs(np.nextafter(t, t + direction) - t)
        if h_abs < min_step:
            h_abs = min_step
        accepted = False
        rejected = False
        while not accepted:
            if steps >= max_steps:
                stats[STAT_STATUS] = STATUS_MAX_STEPS
                return ys, stats, t, y
            if not (h_abs >= min_step):  # also catches NaN
                stats[STAT_STATUS] = STATUS_STEP_TOO_SMALL
                return ys, stats, t, y
            h = direction * h_abs
            t_new = t + h
            if direction * (t_new - target) > 0.0:
                t_new = target
            h = t_new - t
            h_abs = abs(h)
            for i in range(n):
                k[0, i] = f[i]
            dop853_stages(rhs, params, t, y, h, k, scratch, y_new)
            info = rhs(t + h, y_new, params, k[N_STAGES])
            stats[STAT_RHS_CALLS] += N_STAGES
            steps += 1
            err = error_norm(k, h, y, y_new, rtol, atol)
            if not math.isfinite(err):
                # A NaN state (e.g. a sampled perturber asked outside its span): shrink, then give up.
                if h_abs <= min_step:
                    stats[STAT_STATUS] = STATUS_NOT_FINITE
                    return ys, stats, t, y
                h_abs *= MIN_FACTOR
                rejected = True
                stats[STAT_REJECTED] += 1
                continue
            if err < 1.0:
                factor = accepted_step_factor(err, previous_error, beta)
                previous_error = max(err, PREVIOUS_ERROR_FLOOR)
                if rejected:
                    factor = min(1.0, factor)
                h_abs *= factor
                accepted = True
            else:
                h_abs *= rejected_step_factor(err)
                rejected = True
                stats[STAT_REJECTED] += 1
        stats[STAT_ACCEPTED] += 1
        for i in range(n):
            f_new[i] = k[N_STAGES, i]
        # Outputs inside (t, t_new]: the step end itself, or the dense output (built from the end
        # point the stages are consistent with, before after_accept changes its representation).
        dense_ready = False
        while i_out < n_out and direction * (t_out[i_out] - t_new) <= 0.0:
            if t_out[i_out] == t_new:
                for i in range(n):
                    ys[i_out, i] = y_new[i]
            else:
                if not dense_ready:
                    dense_coefficients(rhs, params, t, y, y_new, f_new, h, k, scratch, coeffs)
                    stats[STAT_RHS_CALLS] += N_STAGES_EXTENDED - N_STAGES - 1
                    dense_ready = True
                dense_polynomial(coeffs, y, (t_out[i_out] - t) / h, ys[i_out])
            finish_output(ys[i_out])
            i_out += 1
        info, calls = after_accept(params, t_new, y_new, f_new, info)
        stats[STAT_RHS_CALLS] += calls
        t = t_new
        for i in range(n):
            y[i] = y_new[i]
            f[i] = f_new[i]
        status = status_of(info)
        if status != STATUS_SUCCESS and i_out < n_out:
            stats[STAT_STATUS] = status
            return ys, stats, t, y
    stats[STAT_STATUS] = STATUS_SUCCESS
    return ys, stats, t, y


@jit(inline="always")
def dop853_fixed_steps(rhs, params, status_of, after_accept, y0, t0, t1, n_steps):
    """n_steps equal DOP853 steps from (t0, y0) to t1, no error control (order measurements).

    ``after_accept`` runs after every step (FSAL derivative included); the run stops at the first
    state whose ``status_of`` is not STATUS_SUCCESS. Returns (y(t1) or the state before the stop,
    status).
    """
    n = y0.shape[0]
    k = np.zeros((N_STAGES_EXTENDED, n))
    y = y0.copy()
    y_new = np.empty(n)
    scratch = np.empty(n)
    f = np.empty(n)
    h = (t1 - t0) / n_steps
    status = status_of(rhs(t0, y, params, f))
    if status != STATUS_SUCCESS:
        return y, status
    for step in range(n_steps):
        t = t0 + step * h
        for i in range(n):
            k[0, i] = f[i]
        dop853_stages(rhs, params, t, y, h, k, scratch, y_new)
        info = rhs(t + h, y_new, params, k[N_STAGES])
        status = status_of(info)
        if status != STATUS_SUCCESS:
            return y, status
        for i in range(n):
            f[i] = k[N_STAGES, i]
        after_accept(params, t + h, y_new, f, info)
        for i in range(n):
            y[i] = y_new[i]
    return y, STATUS_SUCCESS
