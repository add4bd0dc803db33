"""What a rotation fit is fitted to: attitudes, axis directions, spin rates and periods at epochs.

Each observation carries an astropy ``Time`` epoch and Quantity values and uncertainties, and turns a
model state (q, ω on the principal axes, the moments) into whitened residuals r = (model − observed)/σ
together with their derivatives with respect to the local state (δθ, ω) (``docs/conventions.md``,
"State transition matrices") and, where the observable itself depends on them, to the moment ratios
(A/C, B/C). Vectors are given in the user's body axes of the :class:`spinorbit.RigidBody`; the
principal-axis rotation ``to_principal`` is applied here.

=====================  ==========  =====================================================================
observation            residuals   model
=====================  ==========  =====================================================================
AttitudeObservation    3           log(q_model⁻¹ ⊗ q_obs) / σ, the body-frame rotation vector between them
AxisObservation        2           the inertial direction of a body axis, its offset from the observed
                                   direction on two tangent axes, / σ
SpinRateObservation    1           (|ω| − rate) / σ
PeriodObservation      1           (P − period) / σ, P = P_ψ ("rotation") or P_φ ("precession") of the
                                   osculating free motion at the epoch (Pravec et al. 2005 convention)
=====================  ==========  =====================================================================

The periods' gradient with respect to ω and the moment ratios is a central difference of their closed
form (complete elliptic integrals, :func:`spinorbit.core.free_motion.summary.periods`), step 1e-6
relative: a ~1e-10 relative error in a gradient, far below what a fit needs; everything else is
analytic.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from astropy import units as u
from astropy.time import Time

from spinorbit.core.elements.canonical import inertia_constants, motion_from_momentum
from spinorbit.core.free_motion.summary import periods
from spinorbit.core.math.rotations import attitude_to_quat, quat_conjugate, quat_multiply, quat_to_attitude
from spinorbit.fit.errors import InvalidObservationError
from spinorbit.quantities import require_quantity

PERIOD_KINDS = ("rotation", "precession")
#: Relative step of the central difference of the closed-form periods.
PERIOD_STEP = 1e-6


def _epoch(epoch, name):
    if not isinstance(epoch, Time) or not epoch.isscalar:
        raise InvalidObservationError(f"{name}.epoch: expected one astropy Time, such as Time('1992-12-02', "
                                      f"scale='tdb'); got {epoch!r}.")
    return epoch


def _positive(value, unit, name, example):
    require_quantity(name, value, unit, example or f"1 * u.Unit('{u.Unit(unit).to_string()}')")
    try:
        number = u.Quantity(value).to_value(unit)
    except (u.UnitsError, TypeError) as error:
        raise InvalidObservationError(f"{name}: expected a Quantity in {unit} (e.g. {example}); got {value!r} "
                                      f"({error}).") from None
    if np.ndim(number) != 0 or not math.isfinite(float(number)) or float(number) <= 0.0:
        raise InvalidObservationError(f"{name}: expected one finite positive Quantity (e.g. {example}); got {value!r}.")
    return float(number)


def _unit_vector(value, name):
    vector = np.asarray(value, dtype=float)
    if vector.shape != (3,) or not np.all(np.isfinite(vector)) or not np.linalg.norm(vector) > 0:
        raise InvalidObservationError(f"{name}: expected a finite non-zero 3-vector, got {value!r}.")
    return vector / np.linalg.norm(vector)


def rotation_vector(q):
    """The rotation vector of a unit quaternion (the shorter way round: q and −q alike)."""
    q = q if q[0] >= 0 else -q
    s = float(np.linalg.norm(q[1:]))
    if s == 0.0:
        return np.zeros(3)
    return 2.0 * math.atan2(s, q[0]) * q[1:] / s


def rotation_quaternion(v):
    """exp(v/2): the unit quaternion of the rotation vector v (scalar first)."""
    angle = float(np.linalg.norm(v))
    if angle == 0.0:
        return np.array([1.0, 0.0, 0.0, 0.0])
    return np.concatenate([[math.cos(angle / 2)], math.sin(angle / 2) * np.asarray(v) / angle])


def cross_matrix(v):
    """[v]×, the matrix of v × ·."""
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def inverse_left_jacobian(v):
    """J_l(v)⁻¹ of SO(3): log(exp(δ) exp(v)) = v + J_l(v)⁻¹ δ + O(δ²)."""
    angle = float(np.linalg.norm(v))
    k = cross_matrix(v)
    if angle < 1e-6:
        return np.eye(3) - 0.5 * k + k @ k / 12.0
    coefficient = 1.0 / angle**2 - (1.0 + math.cos(angle)) / (2.0 * angle * math.sin(angle))
    return np.eye(3) - 0.5 * k + coefficient * k @ k


def right_jacobian(v):
    """J_r(v) of SO(3): exp(v + δ) = exp(v) exp(J_r(v) δ) + O(δ²)."""
    angle = float(np.linalg.norm(v))
    k = cross_matrix(v)
    if angle < 1e-6:
        return np.eye(3) - 0.5 * k + k @ k / 6.0
    return np.eye(3) - (1.0 - math.cos(angle)) / angle**2 * k + (angle - math.sin(angle)) / angle**3 * k @ k


@dataclass(frozen=True)
class AttitudeObservation:
    """A measured attitude (e.g. a radar shape-model fit) at an epoch.

    Parameters
    ----------
    epoch : Time
    quaternion : (4,) array_like
        Scalar first, user body axes → inertial (as :attr:`spinorbit.RotationState.quaternion`).
    sigma : Quantity
        1-σ uncertainty of the rotation angle about each axis (angle, e.g. ``2 * u.deg``).
    """

    epoch: Time
    quaternion: object
    sigma: u.Quantity

    size = 3

    def __post_init__(self):
        _epoch(self.epoch, "AttitudeObservation")
        q = np.asarray(self.quaternion, dtype=float)
        if q.shape != (4,) or not np.all(np.isfinite(q)) or abs(np.linalg.norm(q) - 1.0) > 1e-6:
            raise InvalidObservationError(f"AttitudeObservation.quaternion: expected a unit quaternion (w, x, y, z), "
                                          f"got {self.quaternion!r}; normalise it.")
        _positive(self.sigma, u.rad, "AttitudeObservation.sigma", "2 * u.deg")

    def principal_quaternion(self, to_principal):
        """The observed attitude with the principal axes as body axes."""
        return attitude_to_quat(np.ascontiguousarray(to_principal @ quat_to_attitude(np.asarray(self.quaternion, float))))

    def residuals(self, q, omega, moments, to_principal):
        """(r (3,), ∂r/∂(δθ, ω) (3, 6), ∂r/∂p (3, 2)) at the model state (principal axes)."""
        sigma = _positive(self.sigma, u.rad, "sigma", "2 * u.deg")
        error = rotation_vector(quat_multiply(quat_conjugate(q), self.principal_quaternion(to_principal)))
        d_state = np.zeros((3, 6))
        d_state[:, :3] = -inverse_left_jacobian(error) / sigma
        return error / sigma, d_state, np.zeros((3, 2))


@dataclass(frozen=True)
class AxisObservation:
    """The measured inertial direction of one body axis (a spin pole, a long axis) at an epoch.

    Parameters
    ----------
    epoch : Time
    body_axis : (3,) array_like
        The axis in the user's body axes (normalised here).
    direction : (3,) array_like
        Its observed direction in the inertial frame of the fit (normalised here).
    sigma : Quantity
        1-σ angular uncertainty on each of the two tangent directions.
    """

    epoch: Time
    body_axis: object
    direction: object
    sigma: u.Quantity

    size = 2

    def __post_init__(self):
        _epoch(self.epoch, "AxisObservation")
        _unit_vector(self.body_axis, "AxisObservation.body_axis")
        _unit_vector(self.direction, "AxisObservation.direction")
        _positive(self.sigma, u.rad, "AxisObservation.sigma", "1 * u.deg")

    def tangent_basis(self):
        d = _unit_vector(self.direction, "direction")
        helper = np.eye(3)[int(np.argmin(np.abs(d)))]
        e1 = np.cross(d, helper)
        e1 /= np.linalg.norm(e1)
        return np.vstack([e1, np.cross(d, e1)])

    def residuals(self, q, omega, moments, to_principal):
        sigma = _positive(self.sigma, u.rad, "sigma", "1 * u.deg")
        axis = to_principal @ _unit_vector(self.body_axis, "body_axis")
        attitude = quat_to_attitude(np.asarray(q, float))
        model = attitude.T @ axis
        basis = self.tangent_basis()
        d_state = np.zeros((2, 6))
        d_state[:, :3] = -basis @ attitude.T @ cross_matrix(axis) / sigma
        return basis @ model / sigma, d_state, np.zeros((2, 2))


@dataclass(frozen=True)
class SpinRateObservation:
    """A spin rate |ω| at an epoch (e.g. from a lightcurve's dominant frequency)."""

    epoch: Time
    rate: u.Quantity
    sigma: u.Quantity

    size = 1

    def __post_init__(self):
        _epoch(self.epoch, "SpinRateObservation")
        _positive(self.rate, u.rad / u.day, "SpinRateObservation.rate", "105 * u.deg / u.day")
        _positive(self.sigma, u.rad / u.day, "SpinRateObservation.sigma", "0.5 * u.deg / u.day")

    def residuals(self, q, omega, moments, to_principal):
        sigma = _positive(self.sigma, u.rad / u.day, "sigma", "")
        rate = np.linalg.norm(omega)
        d_state = np.zeros((1, 6))
        d_state[0, 3:] = omega / rate / sigma
        observed = _positive(self.rate, u.rad / u.day, "rate", "")
        return np.array([(rate - observed) / sigma]), d_state, np.zeros((1, 2))


def free_periods(omega, ratios, big_c):
    """(P_ψ, P_φ) in days of the free motion through ω (rad/day, principal axes) with (A/C, B/C)."""
    moments = np.array([ratios[0] * big_c, ratios[1] * big_c, big_c])
    momentum = moments * omega
    mo, _ = motion_from_momentum(momentum[0], momentum[1], momentum[2], inertia_constants(*moments))
    return np.array(periods(mo, *momentum, *moments))


@dataclass(frozen=True)
class PeriodObservation:
    """A rotation (P_ψ) or precession (P_φ) period at an epoch, Pravec et al. (2005) convention."""

    epoch: Time
    kind: str
    period: u.Quantity
    sigma: u.Quantity

    size = 1

    def __post_init__(self):
        _epoch(self.epoch, "PeriodObservation")
        if self.kind not in PERIOD_KINDS:
            raise InvalidObservationError(f"PeriodObservation.kind: expected one of {PERIOD_KINDS}, got {self.kind!r}.")
        _positive(self.period, u.day, "PeriodObservation.period", "5.41 * u.day")
        _positive(self.sigma, u.day, "PeriodObservation.sigma", "0.01 * u.day")

    def residuals(self, q, omega, moments, to_principal):
        sigma = _positive(self.sigma, u.day, "sigma", "")
        which = PERIOD_KINDS.index(self.kind)
        big_c = moments[2]
        ratios = np.array([moments[0] / big_c, moments[1] / big_c])
        value = free_periods(omega, ratios, big_c)[which]
        if not math.isfinite(value):
            raise InvalidObservationError(
                f"PeriodObservation: the model state has no finite {self.kind} period (a separatrix or permanent "
                "rotation), so this period cannot be fitted there; start from a first guess in the observed mode.")
        gradient = np.zeros(5)
        for k in range(5):
            step = np.zeros(5)
            base = omega[k] if k < 3 else ratios[k - 3]
            step[k] = PERIOD_STEP * max(abs(base), 1e-3 * np.linalg.norm(omega) if k < 3 else 1e-3)
            plus = free_periods(omega + step[:3], ratios + step[3:], big_c)[which]
            minus = free_periods(omega - step[:3], ratios - step[3:], big_c)[which]
            gradient[k] = (plus - minus) / (2.0 * step[k])
        d_state = np.zeros((1, 6))
        d_state[0, 3:] = gradient[:3] / sigma
        observed = _positive(self.period, u.day, "period", "")
        return np.array([(value - observed) / sigma]), d_state, gradient[None, 3:] / sigma


OBSERVATION_TYPES = (AttitudeObservation, AxisObservation, SpinRateObservation, PeriodObservation)
