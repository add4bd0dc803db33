"""STM of the averaged propagator: ∂(mean elements at t)/∂(mean elements at t₀) by variational equations, and the osculating one.

The mean equations with the closed-form degree-2 ⟨U⟩ (:func:`spinorbit.core.averaging.mean_equations.degree2_mean_rhs`)
do not depend on the angles s and z, and S, Z are constant in the mean. So with x = (S, Z, H, s, z, h)

    Φ̇ = J(t, x) Φ,   J = ∂ẋ/∂x,   Φ(t₀) = 1,

with the columns of J in s and z zero and its rows in S and Z zero. The four live columns (S, Z, H, h)
are central differences of the closed-form right-hand side (relative step :data:`ACTION_STEP` in S, Z,
with the polhode constants Q, ∂Q/∂S recomputed there; :data:`ANGLE_STEP` in H/Z and h). Why differences
and not second derivatives written out: ∂Q/∂S is itself a difference of polhode quadratures, so its
derivative has no closed form here. Their error, ~1e-9 relative in Φ (the
measured agreement with differences of the propagator is in ``docs/fitting.md``), is far below the
first-order theory's own error ~ε² (ε ≳ 1e-3 where averaging pays).

(x, Φ) are stepped by the mean propagator's fixed-step 8th-order Runge–Kutta in time, with its step rule
(:func:`spinorbit.core.averaging.propagate.mean_elements_kernel`) and its validity check; s is left
unreduced on the way and reduced at each output by :func:`spinorbit.core.elements.equations.reduce_phase`,
whose shift of N periods, s → s − N P(S, Z), z → z + N Δg(S, Z), adds N ∂(P, Δg)/∂(S, Z) to the
rows of s and z (a central difference of the shift at fixed N).

The osculating elements' STM (:func:`osculating_elements_stm`) chains Φ with the Jacobians of the
short-period maps at both ends (explicit maps, by central differences).

Scope: the degree-2 closed form (figures of degree 2), without hand-over: a run that meets an invalid
stretch is refused. Not covered: sensitivities to the moment ratios.
"""

import math

import numpy as np

from spinorbit.core.averaging.mean_equations import (
    degree2_mean_rhs,
    mean_constants,
    moments_of,
)
from spinorbit.core.averaging.propagate import (
    INVALID_PERTURBATION,
    INVALID_RESONANCE,
    INVALID_SEPARATRIX,
    MAX_PERTURBATION,
    MIN_FREQUENCY_RATIO,
    MIN_SEPARATRIX_DISTANCE,
    RADIAL_STEP_FRACTION,
    STEPS_PER_TURN,
    VALID,
    checked_max_step,
    free_motion_numbers,
    perturber_numbers,
    validity_code,
)
from spinorbit.core.averaging.short_period import mean_to_osculating, osculating_to_mean
from spinorbit.core.dynamics.validation import (
    validate_output_times,
    validate_sampled_span,
)
from spinorbit.core.elements.canonical import inertia_constants
from spinorbit.core.elements.equations import reduce_phase
from spinorbit.core.integrators.dop853 import (
    DEFAULT_MAX_STEPS,
    dop853_scratch,
    dop853_step,
    landing_step,
)
from spinorbit.core.integrators.elements import (
    ACTION_H,
    ACTION_S,
    ACTION_Z,
    ANGLE_H,
    ANGLE_S,
    ANGLE_Z,
    ELEMENT_SIZE,
)
from spinorbit.core.jit import jit
from spinorbit.core.model.gravity_field import BODY_NMAX, FIG_THERMAL

#: Relative step of the central differences of the right-hand side in S and Z. Measured in the
#: Apophis-like test scene: Φ(s, S) changes by 2.5e-8 relative from 1e-4 to 1e-5 and by 2e-10 from 1e-5
#: to 1e-6 (truncation ∝ step²; the rounding of ∂Q/∂S, a difference with step 1e-6, enters only the
#: torque's small share).
ACTION_STEP = 1e-5
#: Relative step of the central difference of the reduction's shift N (P, Δg) in S and Z. Near the
#: separatrix P curves strongly; measured in the Apophis-like test scene, Φ(s, S) ≈ −1965 moves by 3e-5
#: from 1e-6 to 1e-7 (truncation) and by 3e-6 from 1e-7 to 1e-8 (rounding takes over): ~2e-9 relative.
REDUCTION_STEP = 1e-7
#: Step of the central differences in H (relative to Z) and in h (rad): truncation and rounding ~1e-10.
ANGLE_STEP = 1e-5
#: Rows of the augmented state: the elements, then Φ (6 × 6, row-major).
Y_PHI = ELEMENT_SIZE
AUGMENTED_SIZE = ELEMENT_SIZE + ELEMENT_SIZE * ELEMENT_SIZE
_WHY = {INVALID_RESONANCE: "resonance / fast perturber", INVALID_PERTURBATION: "strong perturbation",
        INVALID_SEPARATRIX: "near the separatrix"}


@jit
def _jacobian_column(t, el, c, step, mc_plus, mc_minus, model, frame, orbit_averaged, jac, work, f_plus, f_minus):
    """jac[:, c] = (f(el + step e_c) − f(el − step e_c)) / 2 step, with the polhode constants given."""
    for i in range(ELEMENT_SIZE):
        work[i] = el[i]
    work[c] = el[c] + step
    degree2_mean_rhs(t, work, mc_plus, model, frame, orbit_averaged, f_plus)
    work[c] = el[c] - step
    degree2_mean_rhs(t, work, mc_minus, model, frame, orbit_averaged, f_minus)
    for i in range(ELEMENT_SIZE):
        jac[i, c] = (f_plus[i] - f_minus[i]) / (2.0 * step)


@jit
def mean_variational_rhs(t, y, params, dy):
    """d/dt of (x, Φ): the mean equations and Φ̇ = J Φ (module docstring)."""
    mc, mc_s, mc_z, steps, model, frame, orbit_averaged = params
    el = y[:ELEMENT_SIZE]
    degree2_mean_rhs(t, el, mc, model, frame, orbit_averaged, dy[:ELEMENT_SIZE])
    jac = np.zeros((ELEMENT_SIZE, ELEMENT_SIZE))
    work = np.empty(ELEMENT_SIZE)
    f_plus = np.empty(ELEMENT_SIZE)
    f_minus = np.empty(ELEMENT_SIZE)
    _jacobian_column(t, el, ACTION_S, steps[0], mc_s[0], mc_s[1], model, frame, orbit_averaged, jac, work, f_plus,
                     f_minus)
    _jacobian_column(t, el, ACTION_Z, steps[1], mc_z[0], mc_z[1], model, frame, orbit_averaged, jac, work, f_plus,
                     f_minus)
    _jacobian_column(t, el, ACTION_H, steps[2], mc, mc, model, frame, orbit_averaged, jac, work, f_plus, f_minus)
    _jacobian_column(t, el, ANGLE_H, steps[3], mc, mc, model, frame, orbit_averaged, jac, work, f_plus, f_minus)
    for i in range(ELEMENT_SIZE):
        for j in range(ELEMENT_SIZE):
            acc = 0.0
            for m in range(ELEMENT_SIZE):
                acc += jac[i, m] * y[Y_PHI + m * ELEMENT_SIZE + j]
            dy[Y_PHI + i * ELEMENT_SIZE + j] = acc


@jit
def mean_variational_kernel(y0, t0, t_out, max_step, steps_per_turn, params, model, free, thresholds, out):
    """Step (x, Φ) from t0 to each t_out[i] (rows of ``out``), s unreduced; the mean propagator's step rule.

    Returns (outputs written, time reached, INVALID_* code or VALID, steps).
    """
    y = y0.copy()
    t = t0
    k, tmp, y_new = dop853_scratch(y0.size)
    steps = 0
    for i in range(t_out.shape[0]):
        target = t_out[i]
        direction = 1.0 if target > t else -1.0
        while t != target:
            code = validity_code(t, model, free, thresholds)
            if code != VALID:
                return i, t, code, steps
            rate, _, radial_time = perturber_numbers(t, model)
            h = max_step
            if rate > 0.0 and steps_per_turn > 0.0:
                h = min(h, 2.0 * math.pi / (steps_per_turn * rate), RADIAL_STEP_FRACTION * radial_time)
            remaining = abs(target - t)
            h = landing_step(h, remaining)
            dop853_step(mean_variational_rhs, params, t, y, direction * h, k, tmp, y_new)
            t = target if h == remaining else t + direction * h
            for c in range(y.size):
                y[c] = y_new[c]
            steps += 1
        for c in range(y.size):
            out[i, c] = y[c]
    return t_out.shape[0], t, VALID, steps


def _wrapped(delta):
    return delta - 2.0 * math.pi * np.rint(delta / (2.0 * math.pi))


def element_map_jacobian(function, elements, relative_step):
    """∂function(x)/∂x at x = ``elements`` by central differences, for a map between element sets.

    Steps: ``relative_step`` × Z in (S, Z, H), ``relative_step`` rad in (s, z, h); differences of z, h
    are taken mod 2π. A map whose reduction of s changes inside ±step (a jump of a whole period)
    is refused rather than differenced across the jump.
    """
    elements = np.asarray(elements, dtype=float)
    jac = np.empty((ELEMENT_SIZE, ELEMENT_SIZE))
    for c in range(ELEMENT_SIZE):
        step = relative_step * (abs(elements[ACTION_Z]) if c < ANGLE_S else 1.0)
        plus, minus = elements.copy(), elements.copy()
        plus[c] += step
        minus[c] -= step
        diff = np.asarray(function(plus), dtype=float) - np.asarray(function(minus), dtype=float)
        diff[ANGLE_Z:] = _wrapped(diff[ANGLE_Z:])
        if not np.all(np.abs(diff) < 1e3 * step):
            raise ValueError("the reduction of s jumps by a period within the difference step at this point; "
                             "move the time or the state slightly.")
        jac[:, c] = diff / (2.0 * step)
    return jac


def _reduced_with_jacobian(elements, ic):
    """(reduced elements, R = ∂reduced/∂unreduced) of :func:`reduce_phase` at its own number of periods."""
    reduced = elements.copy()
    periods = reduce_phase(reduced, ic)
    jac = np.eye(ELEMENT_SIZE)
    if periods == 0.0:
        return reduced, jac
    for c in (ACTION_S, ACTION_Z):
        step = REDUCTION_STEP * abs(elements[ACTION_Z])
        shifted = []
        for sign in (1.0, -1.0):
            work = elements.copy()
            work[c] += sign * step
            if reduce_phase(work, ic) != periods:
                raise ValueError("the reduction of s is at a half-period boundary at this output; move the "
                                 "output time slightly.")
            shifted.append(work)
        jac[ANGLE_S, c] = (shifted[0][ANGLE_S] - shifted[1][ANGLE_S]) / (2.0 * step)
        jac[ANGLE_Z, c] = _wrapped(shifted[0][ANGLE_Z] - shifted[1][ANGLE_Z]) / (2.0 * step)
    return reduced, jac


def mean_elements_stm(mean0, t0, t_out, model, frame, orbit_averaged=False, max_step=None,
                      steps_per_turn=STEPS_PER_TURN, min_frequency_ratio=MIN_FREQUENCY_RATIO,
                      max_perturbation=MAX_PERTURBATION, min_separatrix_distance=MIN_SEPARATRIX_DISTANCE,
                      max_steps=DEFAULT_MAX_STEPS):
    """Mean elements at t_out and their STM ∂x(t)/∂x(t₀), x = (S, Z, H, s, z, h) signed, in ``frame``.

    Parameters
    ----------
    mean0 : array_like (6,)
        Mean elements at t0 (as ``AveragedResult.mean_elements`` or ``propagate_averaged(mean0=…)``).
    t0, t_out
        Initial time and output times (strictly monotone away from t0), time unit of the model.
    model : ndarray
        :func:`spinorbit.core.dynamics.equations.make_model` with a degree-2 figure.
    frame : (3, 3) array_like
        Inertial → reference rotation of (H, h) (``AveragedResult.frame``).
    orbit_averaged, max_step, steps_per_turn, min_frequency_ratio, max_perturbation, min_separatrix_distance, max_steps
        As in :func:`spinorbit.core.averaging.propagate.propagate_averaged` (stepping in time; the step
        rule and defaults of its time-stepped kernel).

    Returns
    -------
    mean : (n, 6) ndarray
        Mean elements at t_out, s reduced as in ``propagate_averaged``.
    phi : (n, 6, 6) ndarray
        ∂mean(t)/∂mean(t0) (module docstring).

    Raises
    ------
    ValueError
        Bad elements, frame or times, a figure of degree > 2, or a stretch where averaging is invalid
        (no hand-over here: integrate that stretch with ``integrate_variational``).
    """
    mean0 = np.asarray(mean0, dtype=float)
    if mean0.shape != (ELEMENT_SIZE,) or not np.all(np.isfinite(mean0)):
        raise ValueError(f"mean0: expected 6 finite mean elements (S, Z, H, s, z, h), got {mean0!r}.")
    frame = np.ascontiguousarray(frame, dtype=float)
    if frame.shape != (3, 3) or not np.allclose(frame @ frame.T, np.eye(3), atol=1e-12):
        raise ValueError("frame: expected a 3 × 3 rotation matrix (AveragedResult.frame).")
    model = np.ascontiguousarray(model, dtype=float)
    if model[FIG_THERMAL] > 0.0:  # as in propagate_averaged: the mean equations hold S and Z constant
        raise ValueError("mean_elements_stm averages conservative torques only; got a model with a thermal (YORP) "
                         "block. Build the model without thermal=.")
    if model[BODY_NMAX] > 2:
        raise ValueError(f"mean_elements_stm needs the degree-2 closed form; got a figure of degree "
                         f"{int(model[BODY_NMAX])}. Build the model without Stokes coefficients of degree 3–4.")
    t0 = float(t0)
    t_out = validate_output_times(t0, t_out)
    validate_sampled_span(model, t0, t_out)
    max_step = checked_max_step("mean_elements_stm", t0, t_out, max_step, orbit_averaged, max_steps)
    moments = moments_of(model)
    ic = inertia_constants(*moments)
    big_s, big_z = mean0[ACTION_S], mean0[ACTION_Z]
    steps = np.array([ACTION_STEP * abs(big_s), ACTION_STEP * abs(big_z), ANGLE_STEP * abs(big_z), ANGLE_STEP])
    mc = mean_constants(big_s, big_z, ic, moments)
    mc_s = np.array([mean_constants(big_s + d, big_z, ic, moments) for d in (steps[0], -steps[0])])
    mc_z = np.array([mean_constants(big_s, big_z + d, ic, moments) for d in (steps[1], -steps[1])])
    thresholds = np.array([min_frequency_ratio, max_perturbation, min_separatrix_distance], dtype=float)
    y0 = np.zeros(AUGMENTED_SIZE)
    y0[:ELEMENT_SIZE] = mean0
    y0[Y_PHI:] = np.eye(ELEMENT_SIZE).ravel()
    out = np.full((t_out.size, AUGMENTED_SIZE), np.nan)
    params = (mc, mc_s, mc_z, steps, model, frame, bool(orbit_averaged))
    written, t_stop, code, _ = mean_variational_kernel(y0, t0, t_out, float(max_step),
                                                       0.0 if orbit_averaged else float(steps_per_turn), params,
                                                       model, free_motion_numbers(mean0, ic), thresholds, out)
    if code != VALID:
        raise ValueError(f"averaging is invalid at t = {float(t_stop)!r} ({_WHY[code]}); the averaged STM has no "
                         "hand-over: integrate that stretch with integrate_variational.")
    mean = np.empty((t_out.size, ELEMENT_SIZE))
    phi = np.empty((t_out.size, ELEMENT_SIZE, ELEMENT_SIZE))
    for i in range(written):
        mean[i], reduction = _reduced_with_jacobian(out[i, :ELEMENT_SIZE], ic)
        phi[i] = reduction @ out[i, Y_PHI:].reshape(ELEMENT_SIZE, ELEMENT_SIZE)
    return mean, phi


#: Relative step of the central differences of the short-period map and its inverse. The map drops
#: harmonics below HARMONIC_NOISE = 1e-11 (``short_period.py``), so its Jacobian errs by ~1e-11/step
#: = 1e-6 absolute on entries ~1; the first-order theory itself errs by ~ε² ≳ 1e-6.
SHORT_PERIOD_STEP = 1e-5


def osculating_elements_stm(osc0, t0, t_out, model, frame, **options):
    """Osculating elements at t_out and ∂osc(t)/∂osc(t0) of the averaged propagator, through its short-period map.

    osc(t) = mean_to_osculating(t, x(t)), x(t0) = osculating_to_mean(t0, osc0), as in
    :func:`spinorbit.core.averaging.propagate.propagate_averaged`, so the STM is
    M(t) Φ(t) ∂x(t0)/∂osc0, with Φ from :func:`mean_elements_stm` and the two Jacobians of the
    short-period maps by central differences (:data:`SHORT_PERIOD_STEP`: they are explicit maps, not
    flows, so a difference has no error growth with t).

    Parameters
    ----------
    osc0 : array_like (6,)
        Osculating elements at t0 in ``frame`` (e.g. ``elements_of_state(y0, model, frame)``).
    t0, t_out, model, frame, options
        As in :func:`mean_elements_stm`.

    Returns
    -------
    osc : (n, 6) ndarray
        Osculating elements at t_out.
    phi : (n, 6, 6) ndarray
        ∂osc(t)/∂osc(t0).
    """
    osc0 = np.asarray(osc0, dtype=float)
    if osc0.shape != (ELEMENT_SIZE,) or not np.all(np.isfinite(osc0)):
        raise ValueError(f"osc0: expected 6 finite osculating elements (S, Z, H, s, z, h), got {osc0!r}.")
    model = np.ascontiguousarray(model, dtype=float)
    frame = np.ascontiguousarray(frame, dtype=float)
    ic = inertia_constants(*moments_of(model))
    t0 = float(t0)
    mean0 = osculating_to_mean(t0, osc0, model, frame, ic)
    into_mean = element_map_jacobian(lambda x: osculating_to_mean(t0, x, model, frame, ic), osc0, SHORT_PERIOD_STEP)
    mean, phi = mean_elements_stm(mean0, t0, t_out, model, frame, **options)
    t_out = validate_output_times(t0, t_out)
    osc = np.empty_like(mean)
    phi_osc = np.empty_like(phi)
    for i, t in enumerate(t_out):
        osc[i] = mean_to_osculating(float(t), mean[i], model, frame, ic)
        out_of_mean = element_map_jacobian(lambda x, t=float(t): mean_to_osculating(t, x, model, frame, ic), mean[i],
                                           SHORT_PERIOD_STEP)
        phi_osc[i] = out_of_mean @ phi[i] @ into_mean
    return osc, phi_osc
