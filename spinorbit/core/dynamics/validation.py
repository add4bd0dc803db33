"""Checks every integrator's Python wrapper makes before compiled code runs.

A compiled loop cannot raise a helpful error (``spinorbit.core.jit``: error_model="numpy"), so bad
input is refused here, in one place, with a message naming what was expected and what arrived.
"""

import math

import numpy as np

from spinorbit.core.errors import WorkLimitError, require_finite

from spinorbit.core.dynamics.equations import MODEL_PERTURBERS, STATE_SIZE
from spinorbit.core.model.perturbers import sampled_span

__all__ = ["MAX_OUTPUT_ROWS", "check_step_budget", "rotation_turns", "validate_fixed_steps", "validate_output_times",
           "validate_sampled_span", "validate_state"]

#: Most output times one integrator call returns: 7 float64 per row, so 5e7 rows are 2.8 GB. More is
#: refused before the run (WorkLimitError); give fewer times, or run in chunks (spinorbit.runs.resumable).
MAX_OUTPUT_ROWS = 50_000_000


def validate_output_times(t0, t_out):
    """Check output times and return them as a 1-d float array.

    Every integrator's Python wrapper calls this before compiled code runs: the times must be finite,
    non-empty and strictly monotone away from ``t0`` (forward or backward), the last one not ``t0``.

    Raises
    ------
    ValueError
        Empty, non-finite, unsorted or repeated output times.
    """
    t_out = np.atleast_1d(np.asarray(t_out, dtype=float))
    if t_out.size > MAX_OUTPUT_ROWS:
        raise WorkLimitError(f"t_out: {t_out.size} output times would return {t_out.size} rows, more than "
                             f"MAX_OUTPUT_ROWS = {MAX_OUTPUT_ROWS}; give fewer output times or run in chunks "
                             "(spinorbit.runs.resumable.integrate_resumable).")
    if t_out.ndim != 1 or t_out.size == 0:
        raise ValueError(f"t_out: expected a non-empty 1-d array of output times, got shape {t_out.shape}.")
    require_finite("t0", float(t0), "a finite start time")
    require_finite("t_out", t_out, "finite output times")
    if not (np.isfinite(t0) and np.all(np.isfinite(t_out))):
        raise ValueError("t0/t_out: expected finite times, got NaN or inf.")
    span = np.concatenate([[t0], t_out])
    steps = np.diff(span)
    forward = np.all(steps[1:] > 0) and steps[0] >= 0
    backward = np.all(steps[1:] < 0) and steps[0] <= 0
    if not (forward or backward) or t_out[-1] == t0:
        raise ValueError(
            "t_out: expected output times strictly increasing (or strictly decreasing) away from "
            f"t0={t0!r}, got {t_out[:6].tolist()}{'…' if t_out.size > 6 else ''}; sort them and drop "
            "duplicates."
        )
    return t_out


def validate_sampled_span(model, t0, t_out):
    """Refuse a run that leaves the time span on which the model's sampled perturbers are defined.

    Called by every integrator's Python wrapper, so a sampled perturber is never asked outside its
    samples (which would give NaN positions deep inside a compiled loop).
    """
    lo, hi = sampled_span(model, MODEL_PERTURBERS)
    t_min, t_max = min(t0, t_out.min()), max(t0, t_out.max())
    if t_min < lo or t_max > hi:
        raise ValueError(
            f"t_out: the run spans [{t_min!r}, {t_max!r}] but sampled perturbers are defined only on "
            f"[{lo!r}, {hi!r}]; extend the samples or shorten the run."
        )


def validate_state(y0, size=STATE_SIZE):
    """Check an initial state (q, ω[, ω_c]) and return it as a float array with q normalised.

    ``size`` is 7 (rigid body) or 10 (mantle and core, :func:`lunar_rhs_into`).

    Raises
    ------
    ValueError
        Wrong shape, NaN/inf, or a zero quaternion.
    """
    y0 = np.asarray(y0, dtype=float)
    if y0.shape != (size,):
        what = "(q0, q1, q2, q3, ωx, ωy, ωz)" if size == STATE_SIZE else "(q0..q3, ωx, ωy, ωz, ω_cx, ω_cy, ω_cz)"
        raise ValueError(f"y0: expected {size} numbers {what}, got shape {y0.shape}.")
    require_finite("y0", y0, f"{size} finite numbers (q, ω)")
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


def rotation_turns(y0, t0, t_end) -> float:
    """Rotations of the body over the run at its initial spin: |ω| |t_end − t0| / 2π (ω = y0[4:7])."""
    return float(np.linalg.norm(y0[4:7])) * abs(float(t_end) - float(t0)) / (2.0 * math.pi)


def check_step_budget(name, estimate, max_steps, knobs):
    """Refuse, before any step, a run estimated to need more than ``max_steps`` steps.

    Parameters
    ----------
    name : str
        The integrator, for the message.
    estimate : float
        Its estimate of the steps (a lower bound for the adaptive integrators, exact for the
        fixed-step ones).
    max_steps : int
        The caller's cap (``max_steps=``).
    knobs : str
        What else the caller can change (span, rtol, step).

    Raises
    ------
    ValueError
        ``max_steps`` is not a positive whole number.
    WorkLimitError
        ``estimate`` > ``max_steps``.
    """
    if isinstance(max_steps, bool) or not isinstance(max_steps, (int, np.integer)) or max_steps < 1:
        raise ValueError(f"max_steps: expected a positive whole number of steps, got {max_steps!r}.")
    if not estimate <= max_steps:
        raise WorkLimitError(
            f"{name}: this run needs about {estimate:.3g} steps (estimated before starting), more than "
            f"max_steps = {max_steps}; raise max_steps, or {knobs}."
        )


def validate_fixed_steps(name, t0, t1, n_steps, max_steps):
    """Check (t0, t1, n_steps) of a fixed-step integrator; return them as (float, float, int).

    Raises
    ------
    NonFiniteError
        t0 or t1 is NaN or inf.
    ValueError
        n_steps is not a positive whole number, or t1 = t0.
    WorkLimitError
        n_steps > max_steps.
    """
    require_finite("t0", float(t0), "a finite start time")
    require_finite("t1", float(t1), "a finite end time")
    if isinstance(n_steps, bool) or not float(n_steps).is_integer() or int(n_steps) < 1:
        raise ValueError(f"n_steps: expected a positive whole number of steps, got {n_steps!r}.")
    if float(t1) == float(t0):
        raise ValueError(f"t1: expected an end time other than t0 = {float(t0)!r}.")
    check_step_budget(name, int(n_steps), max_steps, "take fewer steps")
    return float(t0), float(t1), int(n_steps)
