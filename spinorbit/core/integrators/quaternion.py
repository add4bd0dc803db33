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
- it is scipy's ``DOP853`` with the same coefficients (:mod:`.dop853_tableau`) and the same
  error norm, so the work-precision comparison against scipy measures the implementation, not the
  method.

The loop is the package's one DOP853 engine (:mod:`.dop853`) with :func:`rhs_into`, the plain
step-size controller and the renormalisation below as its after-step and output hooks.

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

from spinorbit.core.dynamics.equations import STATE_SIZE, lunar_rhs_into, rhs_into
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
    IntegrationError,  # noqa: F401  (raised through raise_for_engine_status; importable from here as before)
    dop853_fixed_steps,
    dop853_integrate,
    never_singular,
    raise_for_engine_status,
    stats_record,
)
# The stats layout and stop codes of integrate_dop853_kernel, importable from here as before the engine.
from spinorbit.core.integrators.dop853 import STAT_ACCEPTED, STAT_REJECTED, STAT_RHS_CALLS  # noqa: F401
from spinorbit.core.integrators.dop853 import STATUS_MAX_STEPS, STATUS_NOT_FINITE, STATUS_STEP_TOO_SMALL  # noqa: F401
from spinorbit.core.jit import jit
from spinorbit.core.model.lunar_interior import INTERIOR_STATE_SIZE, has_interior

#: q occupies the first four components of the state (scalar first).
QUATERNION_SIZE = 4


@jit
def normalize_quaternion_part(y):
    """Divide y[0:4] by its norm in place; return the norm (for rescaling q̇)."""
    norm = math.sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2] + y[3] * y[3])
    for i in range(QUATERNION_SIZE):
        y[i] /= norm
    return norm


@jit
def _renormalise_after_step(model, t, y, f, info):
    """Fukushima 2008b: renormalise q, and rescale the FSAL q̇ consistently (q̇ is linear in q)."""
    norm = normalize_quaternion_part(y)
    for i in range(QUATERNION_SIZE):
        f[i] /= norm
    return info, 0


@jit
def _renormalise_output(row):
    normalize_quaternion_part(row)


# The same hooks for other DOP853 users whose state starts with (q, ω) (the variational equations).
renormalise_after_step = _renormalise_after_step
renormalise_output = _renormalise_output


@jit
def integrate_dop853_kernel(y0, t0, t_out, model, rtol, atol, max_steps, hit_output_times, first_step):
    """Adaptive DOP853 on the quaternion equations from (t0, y0), output at the monotone ``t_out``.

    :func:`spinorbit.core.integrators.dop853.dop853_integrate` with :func:`rhs_into`, the plain
    step-size controller and q renormalised after every accepted step and at every output.

    Parameters
    ----------
    y0 : ndarray (7,) or (10,)
        Initial state (q normalised by the caller).
    t0 : float
        Initial time.
    t_out : ndarray (n,)
        Output times, strictly monotone, all on one side of t0.
    model : ndarray
        The model array of :mod:`spinorbit.core.dynamics.equations`.
    rtol : float
        Relative tolerance (> 0).
    atol : ndarray (7,)
        Absolute tolerances per component (≥ 0).
    max_steps : int
        Cap on accepted + rejected steps.
    hit_output_times : bool
        Land steps exactly on every output time instead of using the continuous extension.
    first_step : float
        Initial step size (> 0) or 0 to choose it automatically.

    Returns
    -------
    ys : ndarray (n, 7)
        States at t_out (q renormalised).
    stats : ndarray (4,) int64
        [accepted steps, rejected steps, RHS calls, status] (STATUS_* constants).
    """
    ys, stats, _, _ = dop853_integrate(rhs_into, model, never_singular, _renormalise_after_step, _renormalise_output,
                                       y0, t0, t_out, rtol, atol, max_steps, hit_output_times, first_step, 0.0)
    return ys, stats


@jit
def integrate_dop853_lunar_kernel(y0, t0, t_out, model, rtol, atol, max_steps, hit_output_times, first_step):
    """:func:`integrate_dop853_kernel` for the mantle-and-core model (10-component state) alone.

    The same engine and hooks with :func:`lunar_rhs_into` as the right-hand side, which
    :func:`rhs_into` would call for this state anyway. Why a kernel of its own: the engine inlines its
    right-hand side at every call site (five), and :func:`rhs_into` carries the rigid body's whole
    torque (Kepler and sampled perturbers, thermal recoil) for the 7-component state, which a lunar run
    never takes. Compiling those five dead copies was most of a first ``spinorbit moon``'s compile
    time; here ``lunar_rhs_into`` is one compiled function that the five sites call. Same arithmetic,
    same results to the bit.
    """
    ys, stats, _, _ = dop853_integrate(lunar_rhs_into, model, never_singular, _renormalise_after_step,
                                       _renormalise_output, y0, t0, t_out, rtol, atol, max_steps, hit_output_times,
                                       first_step, 0.0)
    return ys, stats


@jit
def integrate_fixed_step_kernel(y0, t0, t1, n_steps, model):
    """n_steps equal DOP853 steps (8th-order solution, q renormalised each step) → y(t1).

    For measuring the order of convergence; no error control.
    """
    y, _ = dop853_fixed_steps(rhs_into, model, never_singular, _renormalise_after_step, y0, t0, t1, n_steps)
    return y


# ---------------------------------------------------------------------------------------------
# Python front end: validation only, then one call into the kernel.


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

#: The tolerance check under its public name, for the batch integrator (:mod:`.batch_quaternion`).
validate_tolerances = _validate_tolerances


#: Fewest DOP853 steps per rotation at rtol, as c · rtol^(−1/8): measured 0.46 · rtol^(−1/8) or more on
#: free rotations of four bodies, three spins, rtol 1e-3 … 1e-14 (1.1 steps per turn at 1e-3, 26 at
#: 1e-14); c = 0.3 keeps the estimate below every run measured, so only runs that cannot fit are refused.
STEPS_PER_TURN_COEFFICIENT = 0.3


def minimum_steps(y0, t0, t_end, rtol) -> float:
    """A lower bound on the DOP853 steps from t0 to t_end: rotations × 0.3 · rtol^(−1/8)."""
    return rotation_turns(y0, t0, t_end) * STEPS_PER_TURN_COEFFICIENT * rtol ** (-1.0 / 8.0)


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
        Cap on the number of steps. A run whose estimate (:func:`minimum_steps`, a lower bound)
        exceeds it is refused before the first step; the kernel also stops at it.
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
    check_step_budget("integrate_quaternion", minimum_steps(y0, t0, t_out[-1], rtol), max_steps,
                      "shorten the span or loosen rtol")
    kernel = integrate_dop853_lunar_kernel if y0.shape[0] == INTERIOR_STATE_SIZE else integrate_dop853_kernel
    ys, stats = kernel(y0, t0, t_out, model, rtol, atol, int(max_steps), bool(hit_output_times), float(first_step))
    raise_for_engine_status(stats)
    if return_stats:
        return ys, stats_record(stats)
    return ys


def integrate_fixed_step(y0, t0, t1, n_steps, model, max_steps=DEFAULT_MAX_STEPS):
    """y(t1) after ``n_steps`` equal DOP853 steps (order measurements; no error control).

    ``n_steps`` above ``max_steps`` is refused before the first step (WorkLimitError).
    """
    y0 = validate_state(y0)
    t0, t1, n_steps = validate_fixed_steps("integrate_fixed_step", t0, t1, n_steps, max_steps)
    return integrate_fixed_step_kernel(y0, t0, t1, n_steps, model)
