"""Adaptive DOP853 propagation of the full two-body problem, both quaternions renormalised.

The package's one DOP853 engine (:mod:`spinorbit.core.integrators.dop853`) takes the binary's
right-hand side :func:`spinorbit.core.binary.equations.binary_rhs_into` as it stands: the engine is
written for any ``rhs(t, y, params, out)``, and the binary needs only its own hooks, as the
quaternion propagator does (:mod:`spinorbit.core.integrators.quaternion`):

- after an accepted step, q_A and q_B are renormalised and their FSAL rates rescaled (q̇ is linear
  in q and ω̇, R̈ see only q/|q|), Fukushima 2008b;
- the RHS returns the distance above contact; ``status_of`` turns a negative one into
  :data:`STATUS_CONTACT`, and the front end raises :class:`~.errors.ContactError` with the time.

Tolerance: the error norm is the engine's (RMS over the 20 components of err_i / sc_i, sc_i =
atol_i + rtol · |y_i|); :func:`default_atol` gives each block its natural scale so that one rtol
means the same relative accuracy for the orbit and both spins.
"""

import math

import numpy as np

from spinorbit.core.binary.equations import (
    BINARY_STATE_SIZE,
    M_CONTACT,
    M_G,
    M_MASS_A,
    M_MASS_B,
    M_ORDER,
    OMEGA_A,
    OMEGA_B,
    POSITION,
    QUAT_A,
    QUAT_B,
    SCRATCH_SIZE,
    VELOCITY,
    binary_rhs_into,
    with_sun,
)
from spinorbit.core.binary.errors import ContactError, UnsupportedOrderError
from spinorbit.core.binary.monomials import MAX_ORDER
from spinorbit.core.dynamics.validation import check_step_budget, validate_output_times
from spinorbit.core.errors import require_finite
from spinorbit.core.integrators.dop853 import (
    DEFAULT_MAX_STEPS,
    STAT_ACCEPTED,
    STAT_REJECTED,
    STAT_STATUS,
    STATUS_SUCCESS,
    dop853_fixed_steps,
    dop853_integrate,
    raise_for_engine_status,
    stats_record,
)
from spinorbit.core.jit import jit

#: Stop code of a run whose separation fell below the contact distance (beside the engine's codes).
STATUS_CONTACT = 20


@jit
def contact_status(info):
    """``status_of`` of the binary: STATUS_CONTACT when the separation is below the contact distance."""
    if info < 0.0:
        return STATUS_CONTACT
    return STATUS_SUCCESS


@jit(inline="always")
def normalize_block(y, offset):
    norm = math.sqrt(y[offset] ** 2 + y[offset + 1] ** 2 + y[offset + 2] ** 2 + y[offset + 3] ** 2)
    for i in range(4):
        y[offset + i] /= norm
    return norm


@jit
def renormalise_both(params, t, y, f, info):
    """After an accepted step: |q_A| = |q_B| = 1, and the FSAL q̇ rescaled with them (no extra RHS call)."""
    for offset in (QUAT_A, QUAT_B):
        norm = normalize_block(y, offset)
        for i in range(4):
            f[offset + i] /= norm
    return info, 0


@jit
def renormalise_output(row):
    """Unit quaternions in every output row."""
    normalize_block(row, QUAT_A)
    normalize_block(row, QUAT_B)


@jit
def binary_kernel(y0, t0, t_out, model, rtol, atol, max_steps):
    """Adaptive DOP853 on the binary equations: (states at t_out, stats, t of the last accepted step)."""
    params = (model, np.zeros(SCRATCH_SIZE))
    ys, stats, t_stop, _ = dop853_integrate(binary_rhs_into, params, contact_status, renormalise_both,
                                            renormalise_output, y0, t0, t_out, rtol, atol, max_steps,
                                            False, 0.0, 0.0)
    return ys, stats, t_stop


@jit
def binary_fixed_step_kernel(y0, t0, t1, n_steps, model):
    """n_steps equal DOP853 steps (order measurements and equal-work benchmarks); (y(t1), status)."""
    params = (model, np.zeros(SCRATCH_SIZE))
    return dop853_fixed_steps(binary_rhs_into, params, contact_status, renormalise_both, y0, t0, t1, n_steps)


def check_order(order, supported=MAX_ORDER):
    """The expansion order as an int, or :class:`UnsupportedOrderError`."""
    if isinstance(order, bool) or not isinstance(order, (int, np.integer)) or not 0 <= order <= supported:
        raise UnsupportedOrderError(
            f"order: expected a whole number 0 ≤ order ≤ {supported} (the inertia-integral tables go to "
            f"degree {supported}), got {order!r}; use order={min(supported, 4)} for the degree-4 shapes, or 2 "
            "for point mass + inertia tensors.")
    return int(order)


def check_separation(distance, contact_distance, where="the initial state"):
    """Refuse a separation at or inside the contact distance (:class:`ContactError`)."""
    if not distance > contact_distance:
        raise ContactError(
            f"separation: expected more than the contact distance {contact_distance:.6g} (the sum of the two "
            f"circumscribing radii, below which the mutual-potential series diverges), got {distance:.6g} at "
            f"{where}; place the bodies farther apart (the bodies overlap or touch).")


def validate_binary_state(y0, model):
    """The state as a float (20,) array with unit quaternions; refuses NaN, zero quaternions and contact."""
    y = np.array(y0, dtype=float).ravel()
    if y.shape != (BINARY_STATE_SIZE,):
        raise ValueError(f"y0: expected {BINARY_STATE_SIZE} numbers (R, Ṙ, q_A, ω_A, q_B, ω_B), got shape "
                         f"{np.shape(y0)}; see docs/conventions.md, 'The binary'.")
    require_finite("y0", y, "a finite binary state")
    for name, offset in (("q_A", QUAT_A), ("q_B", QUAT_B)):
        norm = float(np.linalg.norm(y[offset:offset + 4]))
        if norm == 0.0:
            raise ValueError(f"y0: expected a non-zero quaternion {name}, got (0, 0, 0, 0); use (1, 0, 0, 0) "
                             "for the body axes on the inertial axes.")
        y[offset:offset + 4] /= norm
    check_separation(float(np.linalg.norm(y[POSITION:POSITION + 3])), float(model[M_CONTACT]))
    return y


def default_atol(y0, rtol, model):
    """rtol × each block's natural scale: |R|, n|R|, 1 for the quaternions, max(|ω_X|, n) for the spins.

    n = √(G(m_A + m_B)/|R|³) is the Keplerian mean motion at the initial separation, the rate of the
    orbit whatever the initial velocity (a state at rest has a scale too).
    """
    r = float(np.linalg.norm(y0[POSITION:POSITION + 3]))
    mean_motion = math.sqrt(model[M_G] * (model[M_MASS_A] + model[M_MASS_B]) / r ** 3)
    scale = np.ones(BINARY_STATE_SIZE)
    scale[POSITION:POSITION + 3] = r
    scale[VELOCITY:VELOCITY + 3] = max(float(np.linalg.norm(y0[VELOCITY:VELOCITY + 3])), mean_motion * r)
    scale[OMEGA_A:OMEGA_A + 3] = max(float(np.linalg.norm(y0[OMEGA_A:OMEGA_A + 3])), mean_motion)
    scale[OMEGA_B:OMEGA_B + 3] = max(float(np.linalg.norm(y0[OMEGA_B:OMEGA_B + 3])), mean_motion)
    return rtol * scale


#: Fewest steps per turn of the faster of the orbit and the two spins at rtol, as c · rtol^(−1/8),
#: a lower bound of the same form as the quaternion propagator's (c = 0.3 there).
STEPS_PER_TURN_COEFFICIENT = 0.3


def minimum_steps(y0, t0, t_end, rtol):
    """A lower bound on the steps: turns of the fastest of orbit (|Ṙ|/|R|) and spins × 0.3 · rtol^(−1/8)."""
    r = np.linalg.norm(y0[POSITION:POSITION + 3])
    rates = (np.linalg.norm(y0[VELOCITY:VELOCITY + 3]) / r, np.linalg.norm(y0[OMEGA_A:OMEGA_A + 3]),
             np.linalg.norm(y0[OMEGA_B:OMEGA_B + 3]))
    turns = max(rates) * abs(t_end - t0) / (2.0 * math.pi)
    return turns * STEPS_PER_TURN_COEFFICIENT * rtol ** (-1.0 / 8.0)


def propagate_binary(y0, t0, t_out, model, rtol=1e-12, atol=None, max_steps=DEFAULT_MAX_STEPS, return_stats=False,
                     sun=None):
    """Integrate the full two-body problem with adaptive DOP853, output at ``t_out``.

    Parameters
    ----------
    y0 : array_like (20,)
        (R, Ṙ, q_A, ω_A, q_B, ω_B) in the units of the model (e.g. m, m/s, rad/s), layout of
        :mod:`spinorbit.core.binary.equations`; quaternions are normalised here.
    t0 : float
        Initial time (time unit of G, e.g. s).
    t_out : array_like (n,)
        Output times, strictly monotone away from t0.
    model : ndarray
        :func:`spinorbit.core.binary.equations.make_binary_model`.
    rtol : float
        Relative local error tolerance, 1e-15 ≤ rtol.
    atol : array_like (20,), optional
        Absolute tolerances; default :func:`default_atol`.
    max_steps : int
        Cap on the steps (refused before the run when the lower bound :func:`minimum_steps` exceeds it).
    return_stats : bool
        Also return a dict of step counts.
    sun : perturber source, optional
        The Sun relative to the barycentre on a Keplerian orbit (:func:`spinorbit.core.model.perturbers.
        kepler_source`, ``sign=-1`` with the barycentre's heliocentric elements; epoch in the run's time):
        adds the solar tide and both gravity-gradient torques (:func:`.equations.with_sun`). None: the
        isolated pair (or the model's own Sun block, if it has one switched on).

    Returns
    -------
    ys : ndarray (n, 20)
    stats : dict, optional

    Raises
    ------
    UnsupportedOrderError
        The model's order is outside the tables.
    ContactError
        The separation is inside the contact distance at the start, or reaches it (the message gives the time).
    IntegrationError
        The engine stopped early (step cap, step underflow, non-finite state).
    """
    model = np.ascontiguousarray(model if sun is None else with_sun(model, sun), dtype=float)
    check_order(int(model[M_ORDER]))
    y0 = validate_binary_state(y0, model)
    t0 = float(t0)
    require_finite("t0", t0, "a finite start time")
    t_out = validate_output_times(t0, t_out)
    if not (np.isfinite(rtol) and 1e-15 <= rtol < 1.0):
        raise ValueError(f"rtol: expected 1e-15 ≤ rtol < 1 (double precision cannot do better than 1e-15), got "
                         f"{rtol!r}; try 1e-12.")
    atol = default_atol(y0, rtol, model) if atol is None else np.broadcast_to(np.asarray(atol, dtype=float),
                                                                       (BINARY_STATE_SIZE,)).copy()
    require_finite("atol", atol, "finite absolute tolerances ≥ 0")
    check_step_budget("propagate_binary", minimum_steps(y0, t0, t_out[-1], rtol), max_steps,
                      "shorten the span or loosen rtol")
    ys, stats, t_stop = binary_kernel(y0, t0, t_out, model, float(rtol), atol, int(max_steps))
    if int(stats[STAT_STATUS]) == STATUS_CONTACT:
        steps = int(stats[STAT_ACCEPTED] + stats[STAT_REJECTED])
        raise ContactError(
            f"separation: expected more than the contact distance {model[M_CONTACT]:.6g} throughout, but it was "
            f"reached at t = {t_stop:.9g} (step {steps}); the bodies collide on this orbit, so no mutual-potential "
            "series holds there; lower the impulse or start farther apart.")
    raise_for_engine_status(stats)
    if return_stats:
        return ys, stats_record(stats)
    return ys
