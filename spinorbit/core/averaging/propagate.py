"""Semi-analytic propagation of mean canonical elements, with hand-over to the full integrator.

The mean equations (:mod:`spinorbit.core.averaging.mean_equations`) have no rotation time scale left: S and Z are
constant, (H, h) and the slow phases move at the torque's rate, so they are stepped on the orbital
time scale by a fixed-step 8th-order Runge–Kutta (the DOP853 tableau without error control; steps
land on the output times). With one perturber on an elliptic Kepler orbit (a heliocentric body and
the Sun) the independent variable is the perturber's true anomaly f
(:func:`mean_elements_anomaly_kernel`): in f the torque is a trigonometric polynomial, the position
needs no Kepler solve, and equal steps in f follow the perihelion passage; otherwise time, with the
step set by the perturbers' angular rate (:func:`mean_elements_kernel`). The osculating state is recovered at each output by the first-order
short-period corrections (:mod:`spinorbit.core.averaging.short_period`).

Validity (checked at every step, :func:`validity_code`); averaging is refused where:

* **resonance** — a fast frequency Ω_jk = jω_s + kω_g (|j| ≤ 2, |k| ≤ 2, not both 0; ω_s the body
  phase rate, ω_g the mean precession rate) is less than ``min_frequency_ratio`` times the fastest
  angular rate |r × v|/r² of a perturber's direction. Synchronous rotation (ω_g ≈ n) and close
  encounters (the perturber's direction sweeps as fast as the body turns) both land here, as do
  internal near-commensurabilities jω_s + kω_g ≈ 0 (small divisors of the short-period terms).
* **strong perturbation** — ε = Σ 3μ/r³ · (C − A)/(C Ω_min²) above ``max_perturbation``: the
  torque's frequency² relative to the slowest fast frequency²; first-order theory errs by ~ε².
* **separatrix** — 1 − m (or 1 − μ) below ``min_separatrix_distance``: the polhode period diverges.

There the run hands over to :func:`spinorbit.core.integrators.quaternion.integrate_quaternion`
(osculating state from the mean one), continues in chunks of ``handover_chunk`` until the check
passes again, and hands back (mean elements from the osculating ones), through the package's one
hand-over mechanism (:func:`spinorbit.core.integrators.handover.alternate_stretches`, which also
serves the canonical elements ↔ quaternion hand-over). A hand-over that starts at the initial time
continues from the given osculating state itself, not from a reconstruction.
"""

import math

import numpy as np

from spinorbit.core.integrators.dop853 import DEFAULT_MAX_STEPS, dop853_scratch, dop853_step, landing_step
from spinorbit.core.jit import jit
from spinorbit.core.averaging.mean_equations import (
    MC_A,
    anomaly_position_xyz,
    degree2_mean_rhs,
    degree2_mean_rhs_anomaly,
    fast_frequencies,
    mean_constants,
    moments_of,
    torus_frequencies,
    torus_mean_rhs,
)
from spinorbit.core.elements.canonical import (
    MO_MODE,
    MO_PARAM_C,
    MODE_UNIFORM,
    inertia_constants,
    motion_from_elements,
)
from spinorbit.core.dynamics.equations import MODEL_PERTURBERS
from spinorbit.core.dynamics.validation import check_step_budget, validate_sampled_span, validate_state
from spinorbit.core.elements.equations import attitude_and_momentum, inertial_quaternion, reduce_phase
from spinorbit.core.model.gravity_field import BODY_NMAX, FIG_THERMAL
from spinorbit.core.integrators.elements import (
    ACTION_S,
    ACTION_Z,
    ANGLE_S,
    ANGLE_Z,
    ELEMENT_SIZE,
    elements_of_state,
    reference_frame_for,
)
from spinorbit.core.integrators.handover import alternate_stretches, quaternion_chunk
from spinorbit.core.dynamics.validation import validate_output_times
from spinorbit.core.model.perturbers import (
    K_E,
    K_M0,
    K_MEAN_MOTION,
    K_T0,
    KIND_KEPLER,
    PERTURBER_ROW,
    perturber_state,
    solve_kepler_elliptic,
)
from spinorbit.core.averaging.short_period import mean_to_osculating, osculating_to_mean

#: Steps of the mean equations per 2π/n, n the fastest angular rate of a perturber's direction at
#: the step's start (the time-stepped kernel: several or non-elliptic perturbers, quadrature,
#: hand-back after a flyby): a stepping error far below the averaging error of the scenes measured
#: (``docs/averaged.md``, "Stepping").
STEPS_PER_TURN = 12.0
#: Steps per 2π of the perturber's true anomaly (:func:`mean_elements_anomaly_kernel`, one elliptic
#: perturber): the stepping error stays ≥ 5000× below the first-order theory's own error over the
#: span, and both scale with the torque (stepping ∝ ε, theory ∝ ε²), so the margin holds down to
#: ~100× weaker torques (``docs/averaged.md``).
STEPS_PER_ANOMALY_TURN = 8.0
#: Largest step as a fraction of the radial time r/|ṙ| of a perturber not on an elliptic orbit: on a
#: near-radial approach (a flyby) the rate n grows like 1/r², which the n-limit alone would step over.
RADIAL_STEP_FRACTION = 0.1

#: Default validity thresholds (module docstring). 5: the first-order theory's neglected terms are
#: ~ (n/Ω)²; Toutatis' slowest combination ω_s − ω_g is ~9× its perihelion rate, so 5 keeps it.
MIN_FREQUENCY_RATIO = 5.0
MAX_PERTURBATION = 0.05
MIN_SEPARATRIX_DISTANCE = 1e-3

# Right-hand-side choices of the mean equations (RHS_DEGREE2_ANOMALY: d/df, f the true anomaly).
RHS_DEGREE2, RHS_DEGREE2_ORBIT_AVERAGED, RHS_QUADRATURE, RHS_DEGREE2_ANOMALY = 0, 1, 2, 3
#: Torus grid of the quadrature right-hand side (points in s, in z; z > degree 4).
QUADRATURE_POINTS_S, QUADRATURE_POINTS_Z = 24, 9

VALID, INVALID_RESONANCE, INVALID_PERTURBATION, INVALID_SEPARATRIX = 0, 1, 2, 3
_WHY = {INVALID_RESONANCE: "resonance / fast perturber (a fast frequency is close to the perturber's rate)",
        INVALID_PERTURBATION: "strong perturbation (ε above max_perturbation)",
        INVALID_SEPARATRIX: "near the separatrix"}


# Layout of the array of :func:`free_motion_numbers`.
FREE_OMEGA_MIN, FREE_ASYMMETRY, FREE_SEPARATRIX, FREE_PERIOD, FREE_ADVANCE_G = range(5)
FREE_SIZE = 5


@jit
def free_motion_numbers(elements, ic):
    """(Ω_min, (C − A)/C, 1 − m, P, Δg) of the free motion of the elements' (S, Z): the slowest fast
    frequency min |jω_s + kω_g| over |j|, |k| ≤ 2 (not both 0), the asymmetry, the separatrix
    distance, the period of s and the advance of g over it. Constant along a mean run (S and Z
    are)."""
    omega_s, omega_g = fast_frequencies(elements, ic)
    omega_min = np.inf
    for j in range(3):
        for k in range(-2, 3):
            if j == 0 and k <= 0:
                continue
            omega_min = min(omega_min, abs(j * omega_s + k * omega_g))
    big_s, big_z = elements[ACTION_S], elements[ACTION_Z]
    mo = motion_from_elements(abs(big_s), big_z, ic)
    sep = 0.0 if mo[MO_MODE] == MODE_UNIFORM else mo[MO_PARAM_C]
    period, nu, _ = torus_frequencies(big_s, big_z, ic)
    a, _, _, _, _, a_minus_c = ic
    free = np.empty(FREE_SIZE)
    free[FREE_OMEGA_MIN] = omega_min
    free[FREE_ASYMMETRY] = a_minus_c / a  # (a − c)/a = 1 − A/C = (C − A)/C
    free[FREE_SEPARATRIX] = sep
    free[FREE_PERIOD] = period
    free[FREE_ADVANCE_G] = nu * period
    return free


@jit
def perturber_numbers(t, model):
    """(fastest angular rate |r × v|/r² of a perturber's direction, Σ 3μ/r³, shortest radial time
    r/|ṙ| of a perturber not on an elliptic Kepler orbit) at time t."""
    rate_max = 0.0
    strength = 0.0
    radial_time = np.inf
    for p in range(int(model[MODEL_PERTURBERS])):
        row = MODEL_PERTURBERS + 1 + p * PERTURBER_ROW
        x, y, z, vx, vy, vz = perturber_state(t, model, row)
        r2 = x * x + y * y + z * z
        cx = y * vz - z * vy
        cy = z * vx - x * vz
        cz = x * vy - y * vx
        rate_max = max(rate_max, math.sqrt(cx * cx + cy * cy + cz * cz) / r2)
        strength += 3.0 * model[row + 1] / r2 ** 1.5
        r_dot = abs(x * vx + y * vy + z * vz)  # r·v = r ṙ
        bound = model[row] == KIND_KEPLER and model[row + 2 + K_E] < 1.0
        if r_dot > 0.0 and not bound:  # elliptic orbits: the angular-rate limit is enough
            radial_time = min(radial_time, r2 / r_dot)
    return rate_max, strength, radial_time


@jit
def validity_numbers(t, model, free):
    """(Ω_min/n_max, ε, 1 − m) at time t; ``free`` from :func:`free_motion_numbers`."""
    rate_max, strength, _ = perturber_numbers(t, model)
    omega_min = free[FREE_OMEGA_MIN]
    ratio = omega_min / rate_max if rate_max > 0.0 else np.inf
    return ratio, strength * free[FREE_ASYMMETRY] / (omega_min * omega_min), free[FREE_SEPARATRIX]


@jit
def validity_code(t, model, free, thresholds):
    """VALID or the INVALID_* reason; thresholds = (min ratio, max ε, min separatrix distance)."""
    rate_max, strength, _ = perturber_numbers(t, model)
    return _validity_from_numbers(rate_max, strength, free, thresholds)


@jit
def _validity_from_numbers(rate_max, strength, free, thresholds):
    omega_min = free[FREE_OMEGA_MIN]
    ratio = omega_min / rate_max if rate_max > 0.0 else np.inf
    eps = strength * free[FREE_ASYMMETRY] / (omega_min * omega_min)
    min_ratio, max_eps, min_separatrix = thresholds
    if not (free[FREE_SEPARATRIX] >= min_separatrix):
        return INVALID_SEPARATRIX
    if not (ratio >= min_ratio):
        return INVALID_RESONANCE
    if not (eps <= max_eps):
        return INVALID_PERTURBATION
    return VALID


@jit(inline="always")
def _rhs(t, y, params, dy):
    """The mean equations in the engine's form; params = (mc, model, frame, ic, RHS_* kind)."""
    mc, model, frame, ic, kind = params
    if kind == RHS_DEGREE2_ANOMALY:
        degree2_mean_rhs_anomaly(t, y, mc, model, frame, dy)
    elif kind == RHS_QUADRATURE:
        torus_mean_rhs(t, y, model, frame, ic, QUADRATURE_POINTS_S, QUADRATURE_POINTS_Z, dy)
    else:
        degree2_mean_rhs(t, y, mc, model, frame, kind == RHS_DEGREE2_ORBIT_AVERAGED, dy)


@jit
def _shift_phase(y, period, advance_g):
    """:func:`spinorbit.core.elements.equations.reduce_phase` with the period P and advance Δg of the
    (constant) mean S, Z supplied: whole periods out of the working s, Δg each into z."""
    sign = 1.0 if y[ACTION_S] >= 0.0 else -1.0
    periods = np.rint(sign * y[ANGLE_S] / period)
    if periods != 0.0:
        y[ANGLE_S] -= sign * periods * period
        z = y[ANGLE_Z] + periods * advance_g
        y[ANGLE_Z] = z - 2.0 * math.pi * np.rint(z / (2.0 * math.pi))


@jit(inline="always")
def _accept_step(y, y_new, free):
    """y ← y_new, whole periods of s moved into z (``free`` from :func:`free_motion_numbers`)."""
    for c in range(ELEMENT_SIZE):
        y[c] = y_new[c]
    _shift_phase(y, free[FREE_PERIOD], free[FREE_ADVANCE_G])


@jit
def _write_output(row, y, ic):
    """One output row: y in one representation (|κ s| ≤ 2K, :func:`reduce_phase`)."""
    for c in range(ELEMENT_SIZE):
        row[c] = y[c]
    reduce_phase(row, ic)


@jit
def mean_elements_kernel(el0, t0, t_out, max_step, steps_per_turn, mc, model, frame, ic, kind, thresholds, free,
                         out):
    """Step the mean elements from (t0, el0) to each t_out[i] (rows of ``out``).

    The step is the smallest of ``max_step``, 2π/(steps_per_turn · n) with n the fastest angular
    rate of a perturber's direction at the step's start, RADIAL_STEP_FRACTION · r/|ṙ| (so a flyby is
    approached in steps that shrink with the distance, and its start is not stepped over), and the
    distance to the next output. The validity check (:func:`validity_code` with
    ``free`` = :func:`free_motion_numbers`) runs before every step; on failure the run stops there.

    Returns (number of outputs written, time reached, elements there, INVALID_* code or VALID, steps).
    """
    y = el0.copy()
    t = t0
    k, tmp, y_new = dop853_scratch(ELEMENT_SIZE)
    steps = 0
    for i in range(t_out.shape[0]):
        target = t_out[i]
        direction = 1.0 if target > t else -1.0
        while t != target:
            rate, strength, radial_time = perturber_numbers(t, model)
            code = _validity_from_numbers(rate, strength, free, thresholds)
            if code != VALID:
                return i, t, y, code, steps
            h = max_step
            if rate > 0.0 and steps_per_turn > 0.0:
                h = min(h, 2.0 * math.pi / (steps_per_turn * rate), RADIAL_STEP_FRACTION * radial_time)
            remaining = abs(target - t)
            h = landing_step(h, remaining)
            dop853_step(_rhs, (mc, model, frame, ic, kind), t, y, direction * h, k, tmp, y_new)
            t = target if h == remaining else t + direction * h
            _accept_step(y, y_new, free)
            steps += 1
        _write_output(out[i], y, ic)
    return t_out.shape[0], t, y, VALID, steps


@jit
def true_anomaly_of_time(t, model, par):
    """True anomaly f (rad, unwrapped: continuous in t) at time t of the elliptic KIND_KEPLER row with
    parameters at model[par:]: M → E (Kepler's equation) → f = 2 atan(√((1 + e)/(1 − e)) tan(E/2))."""
    ecc = model[par + K_E]
    big_e = solve_kepler_elliptic(model[par + K_M0] + model[par + K_MEAN_MOTION] * (t - model[par + K_T0]), ecc)
    turns = math.floor((big_e + math.pi) / (2.0 * math.pi))
    half = 0.5 * (big_e - 2.0 * math.pi * turns)
    return 2.0 * math.atan2(math.sqrt(1.0 + ecc) * math.sin(half), math.sqrt(1.0 - ecc) * math.cos(half)) \
        + 2.0 * math.pi * turns


@jit
def time_of_true_anomaly(f, model, par):
    """Inverse of :func:`true_anomaly_of_time`, closed form: f → E → M = E − e sin E → t."""
    ecc = model[par + K_E]
    turns = math.floor((f + math.pi) / (2.0 * math.pi))
    half = 0.5 * (f - 2.0 * math.pi * turns)
    big_e = 2.0 * math.atan2(math.sqrt(1.0 - ecc) * math.sin(half), math.sqrt(1.0 + ecc) * math.cos(half))
    mean_anomaly = big_e - ecc * math.sin(big_e) + 2.0 * math.pi * turns
    return model[par + K_T0] + (mean_anomaly - model[par + K_M0]) / model[par + K_MEAN_MOTION]


def steps_in_anomaly(model, kind):
    """Whether the mean equations can be stepped in the perturber's true anomaly: one perturber, on
    an elliptic Kepler orbit, with the (not orbit-averaged) degree-2 closed form."""
    row = MODEL_PERTURBERS + 1
    return (kind == RHS_DEGREE2 and int(model[MODEL_PERTURBERS]) == 1 and model[row] == KIND_KEPLER
            and model[row + 2 + K_E] < 1.0)


@jit
def mean_elements_anomaly_kernel(el0, t0, t_out, max_step, steps_per_turn, mc, model, frame, ic, thresholds,
                                 free, out):
    """:func:`mean_elements_kernel` for one perturber on an elliptic Kepler orbit, stepped in its true
    anomaly f (:func:`spinorbit.core.averaging.mean_equations.degree2_mean_rhs_anomaly`; :func:`steps_in_anomaly`).

    Steps of 2π/steps_per_turn in f (at most ``max_step`` · df/dt in time), landing on the anomalies
    of the output times. In f the torque is a trigonometric polynomial, smooth through perihelion,
    and the perturber's position costs one cos/sin, no Kepler solve. The free rate of s, a S
    (constant: S is constant in the mean), is added exactly as a S Δt, with t(f) in closed form
    (:func:`time_of_true_anomaly`), so the body phase carries no stepping error from it. The
    validity check runs before every step with the closed-form rate df/dt = n a² √(1 − e²)/r² and
    strength 3μ/r³ (a bound orbit has no radial-time limit). Same returns as
    :func:`mean_elements_kernel`.
    """
    row = MODEL_PERTURBERS + 1
    par = row + 2
    mu = model[row + 1]
    y = el0.copy()
    t = t0
    f = true_anomaly_of_time(t0, model, par)
    free_rate = mc[MC_A] * el0[ACTION_S]  # ds/dt of the free motion
    k, tmp, y_new = dop853_scratch(ELEMENT_SIZE)
    steps = 0
    for i in range(t_out.shape[0]):
        target = t_out[i]
        f_target = true_anomaly_of_time(target, model, par)
        direction = 1.0 if target > t else -1.0
        while t != target:
            ix, iy, iz, dt_df = anomaly_position_xyz(f, model, par)
            r2 = ix * ix + iy * iy + iz * iz
            code = _validity_from_numbers(1.0 / dt_df, 3.0 * mu / r2 ** 1.5, free, thresholds)
            if code != VALID:
                return i, t, y, code, steps
            h = min(2.0 * math.pi / steps_per_turn, max_step / dt_df)
            remaining = abs(f_target - f)
            h = landing_step(h, remaining)
            dop853_step(_rhs, (mc, model, frame, ic, RHS_DEGREE2_ANOMALY), f, y, direction * h, k, tmp, y_new)
            if h == remaining:
                f, t_new = f_target, target
            else:
                f += direction * h
                t_new = time_of_true_anomaly(f, model, par)
            y_new[ANGLE_S] += free_rate * (t_new - t)
            t = t_new
            _accept_step(y, y_new, free)
            steps += 1
        _write_output(out[i], y, ic)
    return t_out.shape[0], t, y, VALID, steps


def averaging_frame(y0, model):
    """Inertial → reference rotation for (H, h) over a long averaged run.

    The mean angular momentum precesses on a cone about the first perturber's orbit normal n (the
    doubly averaged motion), so its angle to n stays about constant. The reference z axis is n when
    that angle is between 45° and 135°, else a unit vector perpendicular to n: either way sin I stays
    ≥ ~0.7 over the cone, far from the singular set sin I = 0 of (H, h). Without an orbiting
    perturber, :func:`spinorbit.core.integrators.elements.reference_frame_for`.
    """
    moments = moments_of(model)
    if int(model[MODEL_PERTURBERS]) == 0:
        return reference_frame_for(y0, moments)
    xv = perturber_state(0.0, model, MODEL_PERTURBERS + 1)
    frame = _averaging_axes(xv, np.ascontiguousarray(y0, dtype=float), moments)
    if frame is None:
        return reference_frame_for(y0, moments)
    return frame


@jit
def _unit_cross(a, b):
    """a × b / |a × b| (3,)."""
    out = np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])
    return out / math.sqrt(out[0] ** 2 + out[1] ** 2 + out[2] ** 2)


@jit
def _averaging_axes(xv, y0, moments):
    """The rows (ex, ey, axis) of :func:`averaging_frame` from the first perturber's state xv (6,)
    and y0 = (q, ω); None where the orbit normal is undefined (compiled: it is part of every run's
    fixed cost)."""
    nx = xv[1] * xv[5] - xv[2] * xv[4]
    ny = xv[2] * xv[3] - xv[0] * xv[5]
    nz = xv[0] * xv[4] - xv[1] * xv[3]
    size = math.sqrt(nx * nx + ny * ny + nz * nz)
    if not size > 0.0:
        return None
    normal = np.array([nx, ny, nz]) / size
    q_size = math.sqrt(y0[0] ** 2 + y0[1] ** 2 + y0[2] ** 2 + y0[3] ** 2)
    w, x, y, z = y0[0] / q_size, y0[1] / q_size, y0[2] / q_size, y0[3] / q_size
    mx, my, mz = moments[0] * y0[4], moments[1] * y0[5], moments[2] * y0[6]
    spin = np.array([(w * w + x * x - y * y - z * z) * mx + 2 * (x * y - w * z) * my + 2 * (x * z + w * y) * mz,
                     2 * (x * y + w * z) * mx + (w * w - x * x + y * y - z * z) * my + 2 * (y * z - w * x) * mz,
                     2 * (x * z - w * y) * mx + 2 * (y * z + w * x) * my + (w * w - x * x - y * y + z * z) * mz])
    spin /= math.sqrt(spin[0] ** 2 + spin[1] ** 2 + spin[2] ** 2)
    if abs(spin[0] * normal[0] + spin[1] * normal[1] + spin[2] * normal[2]) < math.sqrt(0.5):
        axis = normal
    else:
        axis = _unit_cross(normal, spin)
    ex = _unit_cross(np.array([0.0, 0.0, 1.0]) if abs(axis[2]) < 0.9 else np.array([1.0, 0.0, 0.0]), axis)
    ey = _unit_cross(axis, ex)
    out = np.empty((3, 3))
    out[0], out[1], out[2] = ex, ey, axis
    return out


def state_of_elements(elements, frame, moments):
    """(q, ω) (7,) of signed elements referred to ``frame``."""
    ic = inertia_constants(*moments)
    attitude, momentum = attitude_and_momentum(np.ascontiguousarray(elements, dtype=float), ic)
    q = inertial_quaternion(attitude, frame)
    return np.concatenate([q, momentum / moments])


class AveragedResult:
    """Output of :func:`propagate_averaged`.

    Attributes
    ----------
    t : (n,) ndarray
        Output times.
    mean_elements : (n, 6) ndarray
        Mean signed (S, Z, H, s, z, h) in the reference ``frame`` (s reduced to one period).
    states : (n, 7) ndarray or None
        Osculating (q, ω) from mean + short-period corrections (or the full integrator's state inside
        a hand-over), when ``osculating=True``.
    segments : list of (t_start, t_end, kind, reason)
        kind "averaged" or "full"; reason the validity failure that started a "full" segment.
    frame : (3, 3) ndarray
        Inertial → reference rotation of H, h.
    steps : int
        Steps of the mean equations.
    """

    def __init__(self, t, mean_elements, states, segments, frame, steps):
        self.t, self.mean_elements, self.states = t, mean_elements, states
        self.segments, self.frame, self.steps = segments, frame, steps


def checked_max_step(name, t0, t_out, max_step, orbit_averaged, max_steps):
    """The mean equations' largest step (default: the span, span/64 orbit-averaged), checked, and the run
    refused before its first step when span / max_step (a lower bound on the steps) exceeds max_steps."""
    span = abs(t_out[-1] - t0)
    if max_step is None:
        max_step = span / 64.0 if orbit_averaged else span
    if not (math.isfinite(max_step) and max_step > 0.0):
        raise ValueError(f"max_step: expected a finite step > 0 (time unit of the model), got {max_step!r}.")
    # a lower bound (the orbital rate only shortens the steps), known before the first step
    check_step_budget(name, span / max_step, max_steps, "raise max_step or shorten the span")
    return float(max_step)


def propagate_averaged(y0, t0, t_out, model, max_step=None, orbit_averaged=False, quadrature=None,
                       osculating=False, hand_over=True, min_frequency_ratio=MIN_FREQUENCY_RATIO,
                       max_perturbation=MAX_PERTURBATION, min_separatrix_distance=MIN_SEPARATRIX_DISTANCE,
                       handover_chunk=None, rtol=1e-12, frame=None, mean0=None, anomaly=None,
                       steps_per_turn=None, max_steps=DEFAULT_MAX_STEPS):
    """Propagate the rotation through mean canonical elements (averaged over the free rotation).

    Parameters
    ----------
    y0 : array_like (7,)
        Osculating initial (q, ω), as for :func:`spinorbit.core.integrators.quaternion.integrate_quaternion`.
    t0 : float
        Initial time (model unit).
    t_out : array_like (n,)
        Output times, strictly monotone away from t0.
    model : ndarray
        :func:`spinorbit.core.dynamics.equations.make_model`.
    max_step : float, optional
        Largest step of the mean equations (time unit); the step is also at most
        2π/(steps_per_turn · n), n the perturbers' fastest angular rate at the step's start (not
        when orbit-averaged; in true anomaly: 2π/steps_per_turn in f). Default: the span (span/64
        when orbit-averaged).
    orbit_averaged : bool
        Average over each perturber's Keplerian orbit as well (doubly averaged; elliptic Kepler
        perturbers only, others are used at their instantaneous position).
    quadrature : bool, optional
        Mean right-hand side by torus quadrature of eq. (11) (any force function, degrees 2–4;
        ~10³ force evaluations per call). Default: the degree-2 closed form when the figure has
        degree 2 only, else quadrature.
    osculating : bool
        Also return osculating states (short-period corrections at every output).
    hand_over : bool
        Hand over to the full integrator where averaging is invalid (else raise ValueError there).
    min_frequency_ratio, max_perturbation, min_separatrix_distance : float
        Validity thresholds (module docstring).
    handover_chunk : float, optional
        Length of the full-integration chunks between validity checks (default: the longer of the
        two fundamental periods 2π/ω_s, 2π/ω_g of the free motion; a check costs one conversion).
    rtol : float
        Tolerance of the full integrator in hand-overs.
    frame : (3, 3) ndarray, optional
        Inertial → reference rotation of H, h (default :func:`averaging_frame`).
    mean0 : array_like (6,), optional
        Mean initial elements in ``frame`` (skips the osculating → mean conversion of y0).
    anomaly : bool, optional
        Step in the perturber's true anomaly (:func:`mean_elements_anomaly_kernel`). Default: when
        :func:`steps_in_anomaly` allows it (one elliptic Kepler perturber, degree-2 closed form, not
        orbit-averaged); True where it does not raises ValueError.
    steps_per_turn : float, optional
        Steps per 2π of true anomaly (default STEPS_PER_ANOMALY_TURN) or, stepping in time, per
        2π/n (default STEPS_PER_TURN). Ignored when orbit-averaged.
    max_steps : int
        Cap on the steps of the mean equations: a run needing more than it by the estimate
        span / max_step (a lower bound) is refused before the first step (WorkLimitError).

    Returns
    -------
    AveragedResult
    """
    y0 = validate_state(y0)
    t0 = float(t0)
    t_out = validate_output_times(t0, t_out)
    model = np.ascontiguousarray(model, dtype=float)
    validate_sampled_span(model, t0, t_out)
    if model[FIG_THERMAL] > 0.0:  # its mean equations hold S and Z constant, which sunlight's recoil does not
        raise ValueError("model: propagate_averaged averages conservative torques only (its mean S and Z are constant); "
                         "sunlight's recoil changes them. Use spinorbit.core.averaging.thermal_mean."
                         "propagate_mean_thermal for the mean YORP evolution, or a full integrator.")
    max_step = checked_max_step("propagate_averaged", t0, t_out, max_step, orbit_averaged, max_steps)
    moments = moments_of(model)
    ic = inertia_constants(*moments)
    if frame is None:
        frame = averaging_frame(y0, model)
    frame = np.ascontiguousarray(frame, dtype=float)
    if quadrature is None:
        quadrature = model[BODY_NMAX] > 2
    if quadrature and orbit_averaged:
        raise ValueError("orbit_averaged=True needs the degree-2 closed form; pass quadrature=False "
                         "(or drop orbit_averaged for a figure of degree 3–4).")
    kind = RHS_QUADRATURE if quadrature else (RHS_DEGREE2_ORBIT_AVERAGED if orbit_averaged else RHS_DEGREE2)
    thresholds = np.array([min_frequency_ratio, max_perturbation, min_separatrix_distance])
    if mean0 is None:
        mean = osculating_to_mean(t0, elements_of_state(y0, model, frame), model, frame, ic)
    else:
        mean = np.array(mean0, dtype=float)
    possible = steps_in_anomaly(model, kind)
    if anomaly and not possible:
        raise ValueError("anomaly=True needs one perturber on an elliptic Kepler orbit and the degree-2 closed "
                         "form without orbit averaging; pass anomaly=None to step in time.")
    anomaly = possible if anomaly is None else bool(anomaly)
    if steps_per_turn is None:
        steps_per_turn = STEPS_PER_ANOMALY_TURN if anomaly else STEPS_PER_TURN
    if not steps_per_turn > 0.0:
        raise ValueError(f"steps_per_turn must be > 0, got {steps_per_turn!r}.")
    # Orbit-averaged: the right-hand side has no orbital time scale left; only max_step limits.
    steps_per_turn = 0.0 if orbit_averaged else float(steps_per_turn)
    omega_s, omega_g = fast_frequencies(mean, ic)
    if handover_chunk is None:
        handover_chunk = 2.0 * math.pi / min(abs(omega_s), abs(omega_g))
    direction = 1.0 if t_out[-1] > t0 else -1.0
    out_mean = np.full((t_out.size, ELEMENT_SIZE), np.nan)
    out_state = np.full((t_out.size, 7), np.nan) if osculating else None
    segments = []
    steps = 0
    reason = ""  # why the current full segment started

    def averaged_stretch(t, state, done):
        """Mean elements from t until averaging is invalid; state = (exact osculating state at t or None, mean)."""
        nonlocal steps, reason
        exact, mean = state
        mc = mean_constants(mean[ACTION_S], mean[ACTION_Z], ic, moments)
        if anomaly:
            written, t_stop, y_stop, code, n_steps = mean_elements_anomaly_kernel(
                mean, t, t_out[done:], float(max_step), steps_per_turn, mc, model, frame, ic, thresholds,
                free_motion_numbers(mean, ic), out_mean[done:])
        else:
            written, t_stop, y_stop, code, n_steps = mean_elements_kernel(
                mean, t, t_out[done:], float(max_step), steps_per_turn, mc, model, frame, ic, kind, thresholds,
                free_motion_numbers(mean, ic), out_mean[done:])
        steps += n_steps
        if osculating:
            for i in range(done, done + written):
                osc = mean_to_osculating(t_out[i], out_mean[i], model, frame, ic)
                out_state[i] = state_of_elements(osc, frame, moments)
        segments.append((t, float(t_stop) if code != VALID else float(t_out[-1]), "averaged", ""))
        done += written
        if code == VALID:
            return done, float(t_out[-1]), state, None
        if not hand_over:
            raise ValueError(f"averaging is invalid at t = {t_stop!r}: {_WHY[code]}; allow hand_over=True "
                             "or integrate this stretch with integrate_quaternion.")
        if float(t_stop) == t:
            y = exact  # invalid where the segment starts: continue from the exact state
        else:
            t = float(t_stop)
            y = state_of_elements(mean_to_osculating(t, y_stop, model, frame, ic), frame, moments)
        reason = _WHY[code]
        return done, t, (y, None), reason

    def full_chunk(t, state, done):
        """The full integration over one chunk; hands back with the mean elements where averaging is valid."""
        y, _ = state
        n, ys, t_end, y_end = quaternion_chunk(y, t, t_out, done, handover_chunk, direction, model, rtol)
        for i in range(n):
            el = elements_of_state(ys[i], model, frame)
            out_mean[done + i] = osculating_to_mean(float(t_out[done + i]), el, model, frame, ic)
            if osculating:
                out_state[done + i] = ys[i]
        done += n
        segments.append((t, float(t_end), "full", reason))
        if done < t_out.size:
            el = elements_of_state(y_end, model, frame)
            if validity_code(t_end, model, free_motion_numbers(el, ic), thresholds) == VALID:
                return done, float(t_end), (y_end, osculating_to_mean(t_end, el, model, frame, ic)), "valid again"
        return done, float(t_end), (y_end, None), None

    # Full integration in chunks where the averaged theory fails, until it is valid again.
    alternate_stretches(t0, (y0, mean), t_out.size, (averaged_stretch, full_chunk), ("averaged", "full"))
    return AveragedResult(t_out, out_mean, out_state, segments, frame, steps)
