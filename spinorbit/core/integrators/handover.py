"""Canonical elements with an automatic hand-over to the quaternion integrator near singular sets.

The elements (S, Z, H; s, z, h) are singular at the separatrix (1 − m → 0: the period and ∂m/∂d
diverge, and the mode changes across it), at spin about ±C (sin J → 0) or ±A (the centres of the
SAM and LAM elements), next to the permanent rotations of an exactly symmetric body (M in its
equal-moment plane, sin P → 0: the gap to them is resolved only to ε) and with the angular momentum
along the reference z axis (sin I → 0), and they
cannot resolve a body spherical to better than ~200 rtol; :func:`spinorbit.core.integrators.elements.integrate_elements`
detects these and stops (its ``MIN_*`` constants). The non-singular quaternion equations
(:mod:`spinorbit.core.dynamics.equations`) have none of them. This driver runs the elements while they are
well defined and the quaternion DOP853 through the passage:

1. elements until the kernel reports a singular set at the end of an accepted step (time t_s);
2. the state (q, ω) at t_s from the backward map (eqs. 7–8) of the elements there; DOP853 on the
   quaternion equations from it, in probes of ``check_interval``;
3. after each probe the distances (1 − m, sin J, sin I, sin J_A, sin P) of the state are measured, with the reference
   frame the elements would use (the "auto" rule of ``reference_frame_for``, so the reference pole is
   left by turning the frame, not by waiting); when every distance is ``RESUME_MARGIN`` times its stop
   threshold, the forward map (eq. 4) gives new elements and step 1 resumes.

The margin makes the switch hysteretic: a trajectory lingering near a threshold does not flip-flop
between the integrators. Both maps are the existing exact ones, so a switch costs one rounding of
the state (≈ ε, far below any tolerance ≥ 1e-15 the integrators accept).

Every switch is returned as a :class:`Switch` (time, integrator taken over, reason).

The alternation itself (:func:`alternate_stretches`: run one integrator until it asks to hand over,
then the other) and the fallback stretch (:func:`quaternion_chunk`) are shared with the averaged
propagator's hand-over to the full integration (:mod:`spinorbit.core.averaging.propagate`).
"""

import math
from typing import NamedTuple

import numpy as np

from spinorbit.core.elements.canonical import inertia_constants, motion_from_momentum
from spinorbit.core.dynamics.validation import validate_state
from spinorbit.core.elements.equations import singularity_distances_of_motion
from spinorbit.core.errors import SingularElementsError
from spinorbit.core.model.gravity_field import BODY_A, BODY_B, BODY_C
from spinorbit.core.integrators.elements import (
    MIN_ASPHERICITY_PER_RTOL,
    MIN_SEPARATRIX_DISTANCE,
    MIN_SIN_I,
    MIN_SIN_J,
    MIN_SIN_J_A,
    MIN_SIN_P,
    SINGULAR_SETS,
    STATUS_SUCCESS,
    reference_frame_for,
    run_elements,
)
from spinorbit.core.integrators.dop853 import DEFAULT_MAX_STEPS, STAT_STATUS, STATUS_MESSAGES, IntegrationError
from spinorbit.core.integrators.quaternion import integrate_quaternion
from spinorbit.core.dynamics.validation import validate_output_times
from spinorbit.core.math.rotations import quat_to_attitude

#: Resume the elements only when every singularity distance is this many times its stop threshold
#: (hysteresis: 1 − m ≥ 1e-3, sin J ≥ 1e-2, sin I ≥ 1e-2, sin P ≥ 0.1 with the default thresholds).
RESUME_MARGIN = 10.0
#: Default probe length of a quaternion stretch, in turns of the body (2π/|ω| at the switch): short
#: enough to hand back soon after the passage, long enough that the DOP853 restarts cost little.
CHECK_TURNS = 4.0

ELEMENTS = "elements"
QUATERNION = "quaternion"


class Switch(NamedTuple):
    """One hand-over: at time ``t`` the integrator ``to`` took over, because of ``reason``.

    ``reason`` is a singular set for a switch to the quaternion integrator ("separatrix", "spin
    about C", "spin about A", "symmetric permanent rotation" (M next to the equal-moment plane of a
    symmetric body), "reference pole", "permanent rotation", or "nearly spherical body":
    then for the whole run), "safely away" for a switch back.
    """

    t: float
    to: str
    reason: str


def singularity_distances_of_state(y, moments):
    """(1 − m or 1 − μ, sin J, sin I, sin J_A, sin P) of a state (q, ω), sin I in the frame the elements would use.

    As :func:`spinorbit.core.elements.equations.singularity_distances`; sin J_A is the sine of the angle of
    M from the A axis (spin about ±A, the centre of the LAM elements), sin P that of M from the
    equal-moment plane of an exactly symmetric body (1 for a triaxial one).

    Parameters
    ----------
    y : (7,) ndarray
        Unit quaternion (body → inertial) and body angular velocity.
    moments : (3,) ndarray
        A ≤ B ≤ C.

    Returns
    -------
    tuple of 5 floats
        0 for the separatrix distance of a permanent rotation (no elements), as in the kernel.
    """
    ic = inertia_constants(*moments)
    momentum = np.asarray(moments) * y[4:]
    attitude = quat_to_attitude(np.ascontiguousarray(y[:4])) @ reference_frame_for(y, moments).T
    mo, _ = motion_from_momentum(momentum[0], momentum[1], momentum[2], ic)
    return singularity_distances_of_motion(mo, np.ascontiguousarray(attitude), momentum, ic)


def _singular_reason(distances, margin):
    """The first singular set closer than ``margin`` × its threshold, or None."""
    sep, sin_j, sin_i, sin_j_a, sin_p = distances
    if not sep >= margin * MIN_SEPARATRIX_DISTANCE:
        return "separatrix" if sep > 0.0 else "permanent rotation"
    if not sin_p >= margin * MIN_SIN_P:
        return "symmetric permanent rotation"
    if not sin_j >= margin * MIN_SIN_J:
        return "spin about C"
    if not sin_j_a >= margin * MIN_SIN_J_A:
        return "spin about A"
    if not sin_i >= margin * MIN_SIN_I:
        return "reference pole"
    return None


def integrate_with_handover(y0, t0, t_out, model, rtol=1e-10, check_interval=None, resume_margin=RESUME_MARGIN,
                            max_steps=DEFAULT_MAX_STEPS):
    """Integrate with the canonical elements, handing over to quaternion DOP853 near singular sets.

    Parameters
    ----------
    y0, t0, t_out, model
        As in :func:`spinorbit.core.integrators.elements.integrate_elements`: initial (q, ω) (scalar-first
        quaternion body → inertial, body angular velocity in rad per time unit), initial time,
        strictly monotone output times, model array with A ≤ B ≤ C.
    rtol : float
        Tolerance of both integrators (their own error scales: :func:`.integrate_elements.default_element_atol`
        and :func:`.integrate_quaternion.default_atol`), 1e-15 ≤ rtol.
    check_interval : float, optional
        Length (time unit) of each quaternion probe between checks for a switch back; default
        ``CHECK_TURNS`` turns at the spin rate of the state where the quaternion stretch starts.
    resume_margin : float
        Switch back when every singularity distance is ≥ this × its stop threshold (≥ 1).
    max_steps : int
        Step cap of each segment.

    Returns
    -------
    ys : (n, 7) ndarray
        States (q, ω) at t_out.
    switches : list of :class:`Switch`
        The hand-overs in time order; a start in the quaternion integrator (y0 near a singular set)
        is the first entry, at t0.

    Raises
    ------
    ValueError
        Bad y0, times, tolerances, margin or interval.
    IntegrationError
        Step cap, step underflow or non-finite state in either integrator.
    """
    y = validate_state(y0)
    t = float(t0)
    t_out = validate_output_times(t, t_out)
    model = np.ascontiguousarray(model, dtype=float)
    moments = np.array([model[BODY_A], model[BODY_B], model[BODY_C]])
    if not (math.isfinite(rtol) and rtol >= 1e-15):
        raise ValueError(f"rtol: expected a relative tolerance ≥ 1e-15, got {rtol!r}; try 1e-10.")
    if not (math.isfinite(resume_margin) and resume_margin >= 1.0):
        raise ValueError(f"resume_margin: expected a factor ≥ 1 on the stop thresholds, got {resume_margin!r}; "
                         f"try the default {RESUME_MARGIN:g}.")
    if check_interval is not None and not (math.isfinite(check_interval) and check_interval > 0.0):
        raise ValueError(f"check_interval: expected a probe length > 0 (time unit), got {check_interval!r}.")
    direction = 1.0 if t_out[-1] > t else -1.0
    ys = np.full((t_out.size, 7), np.nan)
    # A body too nearly spherical for the elements at rtol: the quaternions integrate the whole run.
    resolvable = (moments[2] - moments[0]) / moments[2] >= MIN_ASPHERICITY_PER_RTOL * rtol

    def elements_stretch(t, y, i_out):
        return _elements_stretch(y, t, t_out, i_out, model, rtol, max_steps, ys)

    def quaternion_stretch(t, y, i_out):
        probe = check_interval if resolvable else math.inf
        i_out, t, y = _quaternion_probe(y, t, t_out, i_out, model, rtol, max_steps, direction, probe, ys)
        safe = resolvable and _singular_reason(singularity_distances_of_state(y, moments), resume_margin) is None
        return i_out, t, y, "safely away" if safe else None

    start = (_singular_reason(singularity_distances_of_state(y, moments), resume_margin) if resolvable
             else "nearly spherical body")
    switches = alternate_stretches(t, y, t_out.size, (elements_stretch, quaternion_stretch), (ELEMENTS, QUATERNION),
                                   start)
    return ys, switches


def alternate_stretches(t, state, n_out, stretches, names, start_reason=None):
    """The one hand-over mechanism: run stretches of a primary integrator and a fallback, switching on request.

    Used by :func:`integrate_with_handover` (canonical elements ↔ quaternion DOP853) and by
    :func:`spinorbit.core.averaging.propagate.propagate_averaged` (mean elements ↔ the full
    integration).

    Parameters
    ----------
    t : float
        Initial time.
    state : object
        Whatever the stretches pass each other (a state (q, ω), or a pair with the mean elements).
    n_out : int
        Number of output times; the run ends when a stretch has written the last one.
    stretches : (callable, callable)
        The primary's and the fallback's ``stretch(t, state, i_out) -> (i_out, t, state, switch)``:
        integrate from (t, state) writing outputs i_out, … (the caller's arrays), stop where the
        integrator should hand over (or after a probe), and return the outputs reached, the time and
        state there and the reason to switch to the other integrator (None: keep going).
    names : (str, str)
        Names of the two integrators, for the :class:`Switch` records.
    start_reason : str, optional
        Start in the fallback for this reason (the primary is not valid at ``t``).

    Returns
    -------
    list of :class:`Switch`
        The hand-overs in time order (a start in the fallback first, at ``t``).
    """
    switches = []
    current = 0
    if start_reason is not None:
        current = 1
        switches.append(Switch(t, names[current], start_reason))
    i_out = 0
    while i_out < n_out:
        i_out, t, state, switch = stretches[current](t, state, i_out)
        if switch is not None and i_out < n_out:
            current = 1 - current
            switches.append(Switch(t, names[current], switch))
    return switches


def _elements_stretch(y, t, t_out, i_out, model, rtol, max_steps, ys):
    """Elements from (t, y) towards the remaining outputs; returns (i_out, t, y, reason or None)."""
    try:
        states, _, stats, t_stop, y_stop, _ = run_elements(y, t, t_out[i_out:], model, rtol, max_steps=max_steps)
    except SingularElementsError:
        # exactly on the separatrix or a permanent rotation: below every threshold anyway
        return i_out, t, y, "separatrix"
    status = int(stats[STAT_STATUS])
    done = np.isfinite(states[:, 0])
    n_done = int(done.sum())
    ys[i_out:i_out + n_done] = states[:n_done]
    i_out += n_done
    if status == STATUS_SUCCESS:
        return i_out, t_stop, y_stop, None
    if status in SINGULAR_SETS:
        return i_out, t_stop, y_stop, SINGULAR_SETS[status][0]
    raise IntegrationError(f"elements stretch from t = {t!r} stopped: {STATUS_MESSAGES[status]}.")


def quaternion_chunk(y, t, t_out, i_out, interval, direction, model, rtol, max_steps=DEFAULT_MAX_STEPS):
    """Quaternion DOP853 from (t, y) over ``interval`` (clipped to the last output), the fallback stretch of both
    hand-overs.

    Returns
    -------
    (n, states, t_end, y_end)
        The number n of outputs t_out[i_out:] inside (t, t_end], the states there (n, 7), the time
        reached and the state there.
    """
    t_end = t + direction * interval
    if direction * (t_end - t_out[-1]) >= 0.0:
        t_end = t_out[-1]
    if t_end == t:  # a chunk shorter than the spacing of doubles at t: go to the next output
        t_end = t_out[i_out]
    inside = t_out[i_out:][direction * (t_out[i_out:] - t_end) <= 0.0]
    times = inside if inside.size and inside[-1] == t_end else np.append(inside, t_end)
    states = integrate_quaternion(y, t, times, model, rtol=rtol, max_steps=max_steps)
    return inside.size, states[:inside.size], t_end, states[-1]


def _quaternion_probe(y, t, t_out, i_out, model, rtol, max_steps, direction, check_interval, ys):
    """DOP853 from (t, y) over one probe; writes the outputs inside it. Returns (i_out, t, y)."""
    if check_interval is None:
        check_interval = CHECK_TURNS * 2.0 * math.pi / max(float(np.linalg.norm(y[4:])), 1e-300)
    n, states, t_check, y_check = quaternion_chunk(y, t, t_out, i_out, check_interval, direction, model, rtol,
                                                   max_steps)
    ys[i_out:i_out + n] = states
    return i_out + n, t_check, y_check
