"""Checks every integrator's Python wrapper makes before compiled code runs.

A compiled loop cannot raise a helpful error (``spinorbit.core.jit``: error_model="numpy"), so bad
input is refused here, in one place, with a message naming what was expected and what arrived.
"""

import math

import numpy as np

from spinorbit.core.errors import require_finite

from spinorbit.core.dynamics.equations import MODEL_PERTURBERS, STATE_SIZE
from spinorbit.core.model.perturbers import sampled_span

__all__ = ["validate_output_times", "validate_sampled_span", "validate_state"]


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
