"""Adaptive DOP853 integration of Fukushima's canonical elements (S, Z, H; s, z, h), in numba.

Paper: T. Fukushima, "Canonical elements of rotational motion", eq. (11):

    dS/dt = ∂U/∂s,  dZ/dt = ∂U/∂z,  dH/dt = ∂U/∂h,
    ds/dt = a S − ∂U/∂S,  dz/dt = −∂U/∂Z,  dh/dt = −∂U/∂H,

with ∂U/∂(elements) from the torque and the Jacobian of section 4
(:mod:`spinorbit.core.elements.equations`). Torque-free, only s moves (s = s0 + a S t), so the elements
change only as fast as the torque: the steps are set by the perturber, not by the rotation. That is
where this integrator should beat the quaternion one (weakly perturbed tumblers); each RHS call costs
a backward map, a torque and a Jacobian, so it loses where the torque is strong or fast
(``docs/elements_integrator.md`` has measurements).

Design choices
--------------
* **Signed S** carries the sense of rotation (S < 0: about −C in SAM, −A in LAM; the working frame
  is turned by π about B), as in the paper-named API of :mod:`spinorbit.core.elements.canonical`. The two
  exact-separatrix arcs that need the other flips are refused (they are on the singular set anyway).
* **Reference frame of H, h**: the inertial frame, unless the initial angular momentum is within
  ``AUTO_REFERENCE_MIN_SIN_I`` of its z axis, then the inertial frame turned by 90° about x (the
  "auto" rule of :mod:`spinorbit.state`). Fixed for the run.
* **Error control is absolute on every component**: atol = rtol × (G₀, G₀, G₀, s_scale, 1, 1), with
  s_scale = a |S₀| / |ω₀| (dimensionless, O(1): s = ∫ a S dt is in rad, and this is its change while
  the body turns by one radian, so an error of rtol·s_scale in s is an attitude error of about rtol
  rad). A relative test on s would loosen as s grows secularly (s ≈ a S t), letting the phase error
  grow with time; on S, Z, H (bounded by G) relative and absolute are the same.
* **s is kept within half a period of 0**: after every accepted step whole periods P of the free
  motion are removed from s and the matching advance of g is added to z
  (:func:`spinorbit.core.elements.equations.reduce_phase`, a canonical symmetry of the backward map, so
  the motion is unchanged). s itself is integrated (not s − a S t: S is not constant), and stays
  small, so its rounding does not grow with the span either. Without the shift ∂(l, g)/∂(S, Z),
  hence the RHS of s and z, carry terms proportional to s and the steps shrink as the run goes on
  (``docs/elements_integrator.md``). Element outputs are in the shifted representation.
* **Singular sets are detected, not crossed**: at the end of each accepted step the RHS reports
  1 − m (or 1 − μ), sin J, sin I, the sine of the angle of M from the A axis and, for an exactly
  symmetric body, the sine of its angle from the equal-moment plane (permanent rotations); below the
  ``MIN_*`` constants the run stops with :class:`ElementsSingularityError` naming the set and the
  time. Bodies too nearly spherical for the tolerance are refused up front
  (``MIN_ASPHERICITY_PER_RTOL``). The automatic hand-over to the
  quaternion integrator there (and back) is :mod:`spinorbit.core.integrators.handover`.
* **Driver**: the package's one DOP853 engine (:mod:`spinorbit.core.integrators.dop853`) with the
  element RHS, a purely absolute error test, the PI step-size controller (``STEP_BETA``), the
  phase reduction as its after-step hook and the singular sets as its stop codes.
"""

import math

import numpy as np

from spinorbit.core.dynamics.validation import (
    validate_fixed_steps,
    validate_output_times,
    validate_sampled_span,
    validate_state,
)
from spinorbit.core.elements.canonical import FLIP_A, FLIP_B, FLIP_C, MODE_UNIFORM, elements_from_state, inertia_constants
from spinorbit.core.elements.equations import attitude_and_momentum, elements_rhs_into, inertial_quaternion, reduce_phase
from spinorbit.core.errors import SingularElementsError
from spinorbit.core.integrators.dop853 import (
    DEFAULT_MAX_STEPS,
    STAT_STATUS,
    STATUS_SUCCESS,
    dop853_fixed_steps,
    dop853_integrate,
    output_as_is,
    raise_for_engine_status,
    stats_record,
)
from spinorbit.core.jit import jit
from spinorbit.core.math.rotations import quat_to_attitude, rot1
from spinorbit.core.model.gravity_field import BODY_A, BODY_B, BODY_C

ELEMENT_SIZE = 6
#: Layout of a signed element vector: the actions (S, Z, H), then their angles (s, z, h).
ACTION_S, ACTION_Z, ACTION_H, ANGLE_S, ANGLE_Z, ANGLE_H = range(ELEMENT_SIZE)

#: Stop before the separatrix: below this 1 − m (SAM) or 1 − μ (LAM) the elliptic period grows like
#: log(1/(1 − m)) and the Jacobian's d-derivatives like 1/(1 − m) (∂m/∂d), so the steps shrink and
#: the elements' advantage is gone; the crossing itself changes the mode, which this driver does not do.
MIN_SEPARATRIX_DISTANCE = 1e-4
#: Stop near spin about ±C: ds/dt and ∂U/∂L grow like 1/sin J there (polar-coordinate singularity).
MIN_SIN_J = 1e-3
#: Stop near spin about ±A (LAM's centre, S → Z): the Jacobian's 1/√(a − d) terms overflow there.
MIN_SIN_J_A = 1e-3
#: Stop near the reference z axis: dh/dt grows like 1/sin I (the node is undefined at I = 0).
MIN_SIN_I = 1e-3
#: Stop near a permanent rotation of an exactly symmetric body (M within angle P of the equal-moment
#: plane: B = C, or A = B): the gap of the motion to it, (a − c) sin² P, is resolved by (S, Z) only to
#: ≈ ε d, so the phase the elements carry is wrong by ≈ ε / sin² P, whatever rtol; 1e-2 is where
#: that error reaches quaternion DOP853's own at rtol 1e-12 (``docs/elements_integrator.md``,
#: ``benchmarks/accuracy_symmetric_permanent.py``). A fixed value like the other thresholds (the
#: kernel sees atol, not rtol); at rtol < 1e-12 the elements near it are less accurate than rtol asks.
MIN_SIN_P = 1e-2
#: Refuse bodies closer to a sphere than (C − A)/C < MIN_ASPHERICITY_PER_RTOL × rtol: S lies in
#: [√(A/C) Z, Z], an interval of relative width ≈ (C − A)/(2C), and the step error test allows
#: rtol·G in S; below this ratio S (hence the energy, the mode parameter and the period) is not
#: located within its interval to 1 %, and the run returns an attitude that is wrong by O(1) rad
#: without any warning (``docs/elements_integrator.md``).
MIN_ASPHERICITY_PER_RTOL = 200.0
#: Same rule and value as spinorbit.state.AUTO_REFERENCE_MIN_SIN_I: if the initial sin I is below
#: this, H and h are referred to the inertial frame turned by 90° about x.
AUTO_REFERENCE_MIN_SIN_I = 0.1

#: β of the PI step-size controller (Hairer, Solving ODEs I, §IV.2 / DOP853's BETA; 0 = the plain
#: controller of integrate_quaternion). See docs/elements_integrator.md for the measured effect.
STEP_BETA = 0.04

STATUS_SEPARATRIX = 10
STATUS_SPIN_ABOUT_C = 11
STATUS_REFERENCE_POLE = 12
STATUS_SPIN_ABOUT_A = 13
STATUS_SYMMETRIC_PERMANENT = 14


@jit
def _rhs(t, y, params, out):
    """Paper eq. (11) in the engine's form; returns the singularity distances at (t, y)."""
    model, frame, ic, _ = params
    return elements_rhs_into(t, y, model, frame, ic, out)


@jit
def _reduce_phase_after_step(params, t, y, f, distances):
    """Whole periods out of s (same motion, new representation), whose derivative is then re-evaluated."""
    model, frame, ic, reduce_phases = params
    if reduce_phases and reduce_phase(y, ic) != 0.0:
        return elements_rhs_into(t, y, model, frame, ic, f), 1
    return distances, 0


@jit
def _singular_status(distances):
    sep, sin_j, sin_i, sin_j_a, sin_p = distances
    if not (sep >= MIN_SEPARATRIX_DISTANCE):
        return STATUS_SEPARATRIX
    if not (sin_p >= MIN_SIN_P):
        return STATUS_SYMMETRIC_PERMANENT
    if not (sin_j >= MIN_SIN_J):
        return STATUS_SPIN_ABOUT_C
    if not (sin_j_a >= MIN_SIN_J_A):
        return STATUS_SPIN_ABOUT_A
    if not (sin_i >= MIN_SIN_I):
        return STATUS_REFERENCE_POLE
    return STATUS_SUCCESS


@jit
def _state_at(elements, frame, ic, big_a, big_b, big_c, out):
    """(q, ω) of signed elements: backward map, reference → inertial, ω = M / (A, B, C)."""
    attitude, momentum = attitude_and_momentum(elements, ic)
    q = inertial_quaternion(attitude, frame)
    for i in range(4):
        out[i] = q[i]
    out[4] = momentum[0] / big_a
    out[5] = momentum[1] / big_b
    out[6] = momentum[2] / big_c


@jit
def integrate_elements_kernel(el0, t0, t_out, model, frame, atol, max_steps, first_step, reduce_phases):
    """Adaptive DOP853 on the signed elements with output at ``t_out``.

    Parameters
    ----------
    el0 : (6,) ndarray
        Initial signed elements (S, Z, H, s, z, h).
    t0 : float
    t_out : (n,) ndarray
        Strictly monotone output times on one side of t0.
    model : ndarray
    frame : (3, 3) ndarray
        Inertial → reference rotation of H, h.
    atol : (6,) ndarray
        Absolute tolerances (> 0); the error test is purely absolute (module docstring).
    max_steps : int
    first_step : float
        > 0, or 0 for automatic.
    reduce_phases : bool
        Keep s within half a period of 0 (:func:`spinorbit.core.elements.equations.reduce_phase`).

    Returns
    -------
    states : (n, 7) ndarray
        (q, ω) at t_out (NaN after a stop).
    elements : (n, 6) ndarray
        Signed elements at t_out.
    stats : (4,) int64
        [accepted, rejected, RHS calls, status].
    t_stop : float
        Time of the last accepted step.
    el_stop : (6,) ndarray
        Signed elements at ``t_stop`` (where a hand-over to the quaternion integrator starts).
    """
    big_a, big_b, big_c = model[BODY_A], model[BODY_B], model[BODY_C]
    ic = inertia_constants(big_a, big_b, big_c)
    # Purely absolute error test (rtol = 0) and the PI controller.
    els, stats, t_stop, el_stop = dop853_integrate(_rhs, (model, frame, ic, reduce_phases), _singular_status,
                                                   _reduce_phase_after_step, output_as_is, el0, t0, t_out, 0.0,
                                                   atol, max_steps, False, first_step, STEP_BETA)
    states = np.full((t_out.shape[0], 7), np.nan)
    for i in range(t_out.shape[0]):
        if not math.isnan(els[i, 0]):
            _state_at(els[i], frame, ic, big_a, big_b, big_c, states[i])
    return states, els, stats, t_stop, el_stop


# ---------------------------------------------------------------------------------------------
# Python front end


class ElementsSingularityError(SingularElementsError):
    """The run approached a singular set of the canonical elements and stopped there.

    Attributes ``t_stop`` (time of the last accepted step), ``kind`` ("separatrix", "spin about C",
    "spin about A", "symmetric permanent rotation", "reference pole") and ``y_stop`` (the state (q, ω) at ``t_stop``, from the backward map of the elements
    there); continue from there with :func:`integrate_quaternion`, or let
    :func:`spinorbit.core.integrators.handover.integrate_with_handover` do it.
    """

    def __init__(self, message, t_stop, kind, y_stop=None):
        super().__init__(message)
        self.t_stop = t_stop
        self.kind = kind
        self.y_stop = y_stop


#: Singular-set stop codes of the kernel → (kind, why), for the errors and the hand-over's switches.
SINGULAR_SETS = {
    STATUS_SEPARATRIX: ("separatrix", f"1 − m (or 1 − μ) fell below MIN_SEPARATRIX_DISTANCE = {MIN_SEPARATRIX_DISTANCE:g}"),
    STATUS_SPIN_ABOUT_C: ("spin about C", f"sin J fell below MIN_SIN_J = {MIN_SIN_J:g} (spin about ±C)"),
    STATUS_SPIN_ABOUT_A: ("spin about A", f"the angle of M from the A axis fell below MIN_SIN_J_A = {MIN_SIN_J_A:g} "
                          "(spin about ±A)"),
    STATUS_SYMMETRIC_PERMANENT: ("symmetric permanent rotation", f"the angle of M from the equal-moment plane of "
                                 f"the symmetric body fell below MIN_SIN_P = {MIN_SIN_P:g} (next to a permanent "
                                 "rotation, whose gap the elements resolve only to ε)"),
    STATUS_REFERENCE_POLE: ("reference pole", f"sin I fell below MIN_SIN_I = {MIN_SIN_I:g} (angular momentum "
                            "along the reference z axis)"),
}

def reference_frame_for(y0, moments):
    """Inertial → reference rotation of H, h for an initial state (the "auto" rule, module docstring)."""
    attitude = quat_to_attitude(np.ascontiguousarray(y0[:4]))
    momentum_inertial = attitude.T @ (np.asarray(moments) * y0[4:])
    g = float(np.linalg.norm(momentum_inertial))
    if math.hypot(momentum_inertial[0], momentum_inertial[1]) < AUTO_REFERENCE_MIN_SIN_I * g:
        return np.ascontiguousarray(rot1(math.pi / 2))
    return np.eye(3)


def check_resolvable_body(moments, rtol):
    """Raise SingularElementsError if the body is too nearly spherical for the elements at ``rtol``.

    See ``MIN_ASPHERICITY_PER_RTOL``.
    """
    asphericity = (moments[2] - moments[0]) / moments[2]
    if not asphericity >= MIN_ASPHERICITY_PER_RTOL * rtol:
        raise SingularElementsError(
            f"model: the body is spherical to (C − A)/C = {asphericity:.3g}, below "
            f"{MIN_ASPHERICITY_PER_RTOL:g} × rtol = {MIN_ASPHERICITY_PER_RTOL * rtol:.3g}: the elements cannot "
            "resolve its energy at this tolerance; use integrate_quaternion (or integrate_with_handover)."
        )


def elements_of_state(y0, model, frame):
    """Signed canonical elements (S, Z, H, s, z, h) of a state (q, ω) in the reference frame ``frame``.

    Raises
    ------
    SingularElementsError
        Permanent rotation (no finite elements) or an exact-separatrix arc the sign of S cannot carry.
    """
    moments = np.array([model[BODY_A], model[BODY_B], model[BODY_C]])
    ic = inertia_constants(*moments)
    attitude = quat_to_attitude(np.ascontiguousarray(y0[:4]))
    momentum = moments * y0[4:]
    elements, flip, mode = elements_from_state(np.ascontiguousarray(attitude @ frame.T), momentum, ic)
    if mode == MODE_UNIFORM:
        raise SingularElementsError(
            "y0: a permanent rotation (spin about a principal axis) has no finite canonical elements; "
            "use integrate_quaternion."
        )
    if flip in (FLIP_A, FLIP_C):
        raise SingularElementsError("y0: the state is exactly on the separatrix; use integrate_quaternion.")
    if flip == FLIP_B:
        elements[0], elements[3] = -elements[0], -elements[3]
    return elements


def default_element_atol(elements, y0, moments, rtol):
    """Absolute tolerances rtol × (G, G, G, a|S|/|ω|, 1, 1) (module docstring: why absolute, why s_scale)."""
    big_g = abs(elements[1])
    omega = max(float(np.linalg.norm(y0[4:])), 1e-300)
    s_scale = abs(elements[0]) / moments[0] / omega
    return rtol * np.array([big_g, big_g, big_g, max(s_scale, 1e-300), 1.0, 1.0])


def integrate_elements(y0, t0, t_out, model, rtol=1e-10, atol=None, max_steps=DEFAULT_MAX_STEPS,
                       first_step=0.0, reduce_phases=True, return_stats=False, return_elements=False):
    """Integrate the rotation through the canonical elements (paper eq. 11) with adaptive DOP853.

    Same state layout as :func:`spinorbit.core.integrators.quaternion.integrate_quaternion`, so the two
    can be swapped.

    Parameters
    ----------
    y0 : array_like (7,)
        Initial (q0, q1, q2, q3, ωx, ωy, ωz): scalar-first quaternion (body → inertial, normalised
        here) and body angular velocity (rad per time unit).
    t0 : float
        Initial time (model time unit).
    t_out : array_like (n,)
        Output times, strictly monotone away from t0.
    model : ndarray
        :func:`spinorbit.core.dynamics.equations.make_model`.
    rtol : float
        Tolerance, 1e-15 ≤ rtol; the per-step error test is absolute with the scales of
        :func:`default_element_atol`.
    atol : float or array_like (6,), optional
        Absolute tolerances on (S, Z, H, s, z, h), in (momentum, momentum, momentum, rad, rad, rad)
        (s = ∫ a S dt is an angle-like variable, not 2π-periodic). Default
        :func:`default_element_atol`; when given, it replaces the scales derived from rtol.
    max_steps : int
    first_step : float
        Initial step (time unit), 0 = automatic.
    reduce_phases : bool
        Shift s by whole periods back towards 0 after each step (compensated in z; same motion). Off
        only to measure what it buys: the RHS of s and z then grows with the number of turns.
    return_stats : bool
        Also return ``accepted``, ``rejected``, ``rhs_calls`` and the reference ``frame``.
    return_elements : bool
        Also return the signed elements at t_out, (n, 6).

    Returns
    -------
    ys : (n, 7) ndarray
        States (q, ω) at t_out.
    elements : (n, 6) ndarray, optional
    stats : dict, optional

    Raises
    ------
    ValueError
        Bad y0, times, tolerances; sampled perturbers not covering the run.
    SingularElementsError
        y0 is a permanent rotation or on the separatrix, or the body is too nearly spherical for rtol
        (:func:`check_resolvable_body`).
    ElementsSingularityError
        The run approached the separatrix, spin about C or A, a permanent rotation of a symmetric body, or the
        reference pole (``t_stop``, ``kind``).
    IntegrationError
        Step cap, step underflow, non-finite state.
    """
    states, els, stats, t_stop, y_stop, frame = run_elements(y0, t0, t_out, model, rtol, atol, max_steps,
                                                             first_step, reduce_phases)
    status = int(stats[STAT_STATUS])
    if status in SINGULAR_SETS:
        kind, why = SINGULAR_SETS[status]
        raise ElementsSingularityError(
            f"integrate_elements stopped at t = {t_stop!r}: {why}; continue from there with "
            "integrate_quaternion.", t_stop, kind, y_stop)
    raise_for_engine_status(stats)
    out = [states]
    if return_elements:
        out.append(els)
    if return_stats:
        out.append({**stats_record(stats), "frame": frame})
    return out[0] if len(out) == 1 else tuple(out)


def run_elements(y0, t0, t_out, model, rtol=1e-10, atol=None, max_steps=DEFAULT_MAX_STEPS, first_step=0.0,
                 reduce_phases=True):
    """Validate, then run the element kernel; a singular stop is returned, not raised.

    Parameters are those of :func:`integrate_elements`.

    Returns
    -------
    states : (n, 7) ndarray
        (q, ω) at t_out, NaN after a stop.
    elements : (n, 6) ndarray
    stats : (4,) int64 ndarray
        [accepted, rejected, RHS calls, status] (``STATUS_*`` of this module and of
        :mod:`spinorbit.core.integrators.quaternion`).
    t_stop : float
        Time of the last accepted step.
    y_stop : (7,) ndarray
        (q, ω) at ``t_stop`` from the backward map of the elements there.
    frame : (3, 3) ndarray
        Inertial → reference rotation of H, h used for the run.
    """
    y0 = validate_state(y0)
    t0 = float(t0)
    t_out = validate_output_times(t0, t_out)
    if not (np.isfinite(rtol) and rtol > 0):
        raise ValueError(f"rtol: expected a relative tolerance > 0, got {rtol!r}; try 1e-10.")
    if rtol < 1e-15:
        raise ValueError(f"rtol: expected rtol ≥ 1e-15 (double precision cannot do better), got {rtol!r}.")
    model = np.ascontiguousarray(model, dtype=float)
    validate_sampled_span(model, t0, t_out)
    moments = np.array([model[BODY_A], model[BODY_B], model[BODY_C]])
    check_resolvable_body(moments, rtol)
    frame = reference_frame_for(y0, moments)
    el0 = elements_of_state(y0, model, frame)
    if atol is None:
        atol = default_element_atol(el0, y0, moments, float(rtol))
    atol = np.asarray(atol, dtype=float)
    if atol.shape not in ((), (ELEMENT_SIZE,)):
        raise ValueError(f"atol: expected a scalar or 6 values for (S, Z, H, s, z, h), got shape {atol.shape}.")
    atol = np.broadcast_to(atol, (ELEMENT_SIZE,)).copy()
    if not np.all(np.isfinite(atol)) or np.any(atol <= 0):
        raise ValueError(f"atol: expected absolute tolerances > 0 (scalar or 6 values), got {atol.tolist()}.")
    states, els, stats, t_stop, el_stop = integrate_elements_kernel(el0, t0, t_out, model, frame, atol,
                                                                    int(max_steps), float(first_step),
                                                                    bool(reduce_phases))
    y_stop = np.empty(7)
    _state_at(el_stop, frame, inertia_constants(*moments), *moments, y_stop)
    return states, els, stats, t_stop, y_stop, frame


@jit
def integrate_elements_fixed_step_kernel(el0, t0, t1, n_steps, model, frame):
    """n_steps equal DOP853 steps on the signed elements (no error control) → (q, ω) at t1.

    For measuring the order of convergence of the element integrator (the adaptive kernel has no
    fixed-step mode). NaN if a step meets an element singularity.
    """
    big_a, big_b, big_c = model[BODY_A], model[BODY_B], model[BODY_C]
    ic = inertia_constants(big_a, big_b, big_c)
    y, status = dop853_fixed_steps(_rhs, (model, frame, ic, False), _singular_status, _reduce_phase_after_step,
                                   el0, t0, t1, n_steps)
    out = np.full(7, np.nan)
    if status == STATUS_SUCCESS:
        _state_at(y, frame, ic, big_a, big_b, big_c, out)
    return out


def integrate_elements_fixed_step(y0, t0, t1, n_steps, model, max_steps=DEFAULT_MAX_STEPS):
    """(q, ω) at t1 after ``n_steps`` equal DOP853 steps on the canonical elements (order measurements).

    Parameters as :func:`integrate_elements`; no error control, phases not reduced (a short span).
    ``n_steps`` above ``max_steps`` is refused before the first step (WorkLimitError).
    """
    y0 = validate_state(y0)
    t0, t1, n_steps = validate_fixed_steps("integrate_elements_fixed_step", t0, t1, n_steps, max_steps)
    model = np.ascontiguousarray(model, dtype=float)
    moments = np.array([model[BODY_A], model[BODY_B], model[BODY_C]])
    frame = reference_frame_for(y0, moments)
    el0 = elements_of_state(y0, model, frame)
    return integrate_elements_fixed_step_kernel(el0, t0, t1, n_steps, model, frame)
