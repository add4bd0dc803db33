"""Rotation states: attitude and spin of a rigid body, with the canonical elements and the exact free motion.

Attitudes are given and returned in the user's body axes (see :class:`spinorbit.RigidBody`); the
core works in principal axes A ≤ B ≤ C. Spins are Quantities (rad/s, deg/day, …); a bare number is
refused, never read in the core's rad/day (``docs/conventions.md``, "Units"). A state made from a published form (:meth:`RotationState.from_pole`,
:meth:`RotationState.from_tumbling`) knows its epoch. Conventions: ``docs/conventions.md``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from astropy import units as u
from astropy.time import Time

from spinorbit import pole as _pole
from spinorbit import spin_forms as _spin_forms
from spinorbit.body import RigidBody
from spinorbit.quantities import value_in
from spinorbit.core.elements import andoyer as _andoyer
from spinorbit.core.elements import canonical as _canonical
from spinorbit.core.free_motion import summary as _summary
from spinorbit.core.math import rotations as _rotations
from spinorbit.core.free_motion import flow as _torque_free
from spinorbit.core.errors import NonFiniteError, SingularElementsError, SpinorbitError

__all__ = ["RotationState", "CanonicalElements", "InvalidStateError", "NonFiniteStateError", "MAX_FLOW_PHASE"]

RAD_PER_DAY = u.rad / u.day
# A quaternion further than this from unit norm is refused rather than silently normalized: it is
# more likely a wrong input (a vector, a scalar-last quaternion scaled by hand) than rounding.
QUATERNION_NORM_TOLERANCE = 1e-6
# Rotation matrices must be orthonormal to this level (rows of a rounded matrix typed from a paper
# are good to ~1e-9; anything worse is not a rotation).
MATRIX_ORTHONORMALITY_TOLERANCE = 1e-9
# The Andoyer angles h, I are referred to a frame whose z axis is at least this far (sin I) from the
# angular momentum; closer than that, "auto" turns the reference frame by 90° about x (I = 0 is a
# singular set of the elements).
AUTO_REFERENCE_MIN_SIN_I = 0.1

MODE_NAMES = {
    _canonical.MODE_SAM: "SAM",
    _canonical.MODE_LAM: "LAM",
    _canonical.MODE_UNIFORM: "permanent rotation",
    _summary.MODE_SEPARATRIX: "separatrix",
}


#: Range of G (momentum units) that :meth:`RotationState.from_andoyer` accepts: the maps square the
#: momentum components, which under/overflows in float64 beyond ~1e±154.
ANDOYER_G_RANGE = (1e-150, 1e150)


#: Largest phase (rad) of the free flow that :meth:`RotationState.propagate_torque_free` evaluates: the
#: fastest angular rate of the motion, G/A, times the largest |dt|. Below it the flow is exact for the
#: double inputs (≤ 4e-16 rad against mpmath at 40+ digits up to 6.6e15 rad, tests/stress/test_degenerate.py);
#: at 6.6e17 rad the double-double reduction by the period rounds and the attitude is O(1) wrong. Past
#: 1e15 rad one ulp of dt already moves the attitude by ≥ 0.1 rad, so nothing of value is refused.
MAX_FLOW_PHASE = 1e15


class InvalidStateError(SpinorbitError, ValueError):
    """The attitude or spin given cannot describe a rotation state, or this state has no such property."""


class NonFiniteStateError(InvalidStateError, NonFiniteError):
    """NaN or ±inf in the attitude, the spin, the Euler angles or the time offsets."""


def _unresolved_gap_message(big_s, big_z, moments, what):
    """Why (S, Z) of an axisymmetric body within rounding of a permanent rotation are refused."""
    big_a, big_b, big_c = moments
    equal = "B = C" if big_b == big_c else "A = B"
    return (
        f"{what}: the body is axisymmetric ({equal}) and the spin is within rounding of its permanent rotation "
        f"perpendicular to the symmetry axis (S = {big_s!r}, Z = {big_z!r}): S and Z "
        "cannot resolve the gap d − c (B = C) or a − d (A = B) that sets the rate of the elliptic argument, so the "
        "canonical elements carry no phase there (spinorbit.core.elements.canonical.symmetric_gap_resolved). "
        "propagate_torque_free still works (regular precession in closed form); use the attitude and spin directly."
    )


def _as_quaternion(q) -> np.ndarray:
    q = np.asarray(q, dtype=float)
    if q.shape != (4,):
        raise InvalidStateError(f"a quaternion has 4 components (w, x, y, z), scalar first; got shape {q.shape}.")
    if not np.all(np.isfinite(q)):
        raise NonFiniteStateError(f"quaternion components must be finite; got {q.tolist()}.")
    # |q| of components beyond ~1e154 would overflow (a warning, then inf): such q are refused anyway.
    norm = float(np.linalg.norm(q)) if np.abs(q).max() <= 2.0 else float(np.abs(q).max())
    if abs(norm - 1.0) > QUATERNION_NORM_TOLERANCE:
        raise InvalidStateError(
            f"attitude quaternions must have unit norm; got |q| = {norm!r}. Normalize it (q / |q|) if that is "
            "what you meant; spinorbit does not guess."
        )
    return q / norm


def _as_rotation_matrix(matrix) -> np.ndarray:
    m = np.asarray(matrix, dtype=float)
    if m.shape != (3, 3):
        raise InvalidStateError(f"an attitude matrix is 3×3; got shape {m.shape}.")
    if not np.all(np.isfinite(m)):
        raise NonFiniteStateError(f"attitude matrix entries must be finite; got {m.tolist()}.")
    if np.abs(m).max() > 2.0:  # a rotation's entries are ≤ 1; R Rᵀ of huge entries would overflow
        raise InvalidStateError(
            f"the attitude matrix is not a rotation (largest entry {np.abs(m).max():.6g}, a rotation's are ≤ 1); "
            "give an orthonormal matrix with determinant +1 (inertial → body)."
        )
    error = float(np.abs(m @ m.T - np.eye(3)).max())
    if error > MATRIX_ORTHONORMALITY_TOLERANCE or np.linalg.det(m) < 0:
        raise InvalidStateError(
            f"the attitude matrix is not a rotation (|R Rᵀ − 1| = {error:.2e}, det = {np.linalg.det(m):.6f}); "
            "give an orthonormal matrix with determinant +1 (inertial → body)."
        )
    return m


def _as_angular_velocity(omega, name="angular_velocity") -> np.ndarray:
    # a Quantity of an angle per time: bare numbers and frequencies refused (docs/conventions.md, "Units")
    values = np.asarray(value_in(name, omega, RAD_PER_DAY, "[0.1, 0, 0.3] * u.rad / u.day", finite=False),
                        dtype=float)
    if values.shape != (3,):
        raise InvalidStateError(f"the angular velocity is a 3-vector in body axes; got shape {values.shape}.")
    if not np.all(np.isfinite(values)):
        raise NonFiniteStateError(f"angular velocity components must be finite; got {values.tolist()}.")
    return values


@dataclass(frozen=True)
class CanonicalElements:
    """Fukushima's canonical elements of one state (paper eqs. 4–8).

    S, Z, H are in the body's moment unit × rad/day; s is in day × (moment unit × rad/day)⁻¹… i.e.
    ds/dt = a S with a = 1/A; z, h in radians. ``flip`` is the body-frame turn that puts the state on
    the paper's branch (``spinorbit.core.elements.canonical.FLIP_*``); ``reference`` the passive rotation from
    the inertial frame to the frame of H and h.
    """

    S: float
    Z: float
    H: float
    s: float
    z: float
    h: float
    flip: int
    mode: str
    reference: np.ndarray


class RotationState:
    """Attitude and spin of a rigid body at one instant.

    Parameters
    ----------
    body : RigidBody
    quaternion : array_like, shape (4,)
        Unit quaternion (w, x, y, z), scalar first, taking inertial axes to the user's body axes
        (v_inertial = M(q) v_body).
    angular_velocity : Quantity, shape (3,)
        Body angular velocity in the user's body axes, an angle per time (``[0, 0, 3] * u.rad / u.day``,
        ``u.deg / u.hour``, ``u.cycle / u.day``; a bare number or a frequency such as ``u.Hz`` is refused).
    epoch : astropy.time.Time, optional
        The instant of this attitude and spin (scalar); None (default) when the state is not tied to
        one. A :class:`spinorbit.Scene` takes it as its epoch.

    Notes
    -----
    Use :meth:`from_matrix`, :meth:`from_euler313` or :meth:`from_angular_momentum` for other inputs,
    and :meth:`from_pole` or :meth:`from_tumbling` for the published forms. States are immutable:
    :meth:`with_epoch` returns a copy tied to another epoch.
    """

    def __init__(self, body: RigidBody, quaternion, angular_velocity, epoch=None):
        if not isinstance(body, RigidBody):
            raise TypeError(f"body must be a spinorbit.RigidBody; got {type(body).__name__}.")
        if epoch is not None and not (isinstance(epoch, Time) and epoch.isscalar):
            raise InvalidStateError(f"epoch expects a scalar astropy Time or None; got {epoch!r}.")
        self._body = body
        self._epoch = epoch
        self._q = _as_quaternion(quaternion)
        self._omega = _as_angular_velocity(angular_velocity)
        with np.errstate(over="ignore"):
            momentum = body.moment_values * self._omega
        if not np.all(np.isfinite(momentum)):
            raise InvalidStateError(
                f"the angular momentum I ω overflows float64 (moments {body.moment_values.tolist()} × spin "
                f"{self._omega.tolist()} rad/day); give the moments and the spin in units nearer 1."
            )

    # -- constructors --------------------------------------------------------------------------
    @classmethod
    def from_matrix(cls, body, attitude_matrix, angular_velocity, epoch=None):
        """From an attitude matrix R (inertial → user body axes)."""
        return cls(body, _rotations.attitude_to_quat(_as_rotation_matrix(attitude_matrix)), angular_velocity, epoch)

    @classmethod
    def from_euler313(cls, body, phi, theta, psi, angular_velocity, epoch=None):
        """From passive 3-1-3 Euler angles (angle Quantities): R = R3(ψ) R1(θ) R3(φ)."""
        angles = [value_in(name, a, u.rad, "30 * u.deg", shape=(), finite=False)
                  for name, a in (("phi", phi), ("theta", theta), ("psi", psi))]
        if not all(math.isfinite(a) for a in angles):
            raise NonFiniteStateError(f"Euler angles must be finite; got phi, theta, psi = {angles}.")
        return cls.from_matrix(body, _rotations.euler313_to_attitude(*angles), angular_velocity, epoch)

    @classmethod
    def from_angular_momentum(cls, body, quaternion, angular_momentum, epoch=None):
        """From the body angular momentum (user axes, a Quantity in the body's moment unit × an angle per
        time, such as kg m² rad/day; rad/day for moments given as ratios) instead of the angular velocity:
        ω = I⁻¹ M."""
        momentum_unit = body.moment_unit * RAD_PER_DAY
        example = f"[0.1, 0, 0.3] * u.Unit('{momentum_unit.to_string()}')"
        values = value_in("angular_momentum", angular_momentum, momentum_unit, example, finite=False)
        return cls(body, quaternion, np.asarray(values, dtype=float) / body.moment_values * RAD_PER_DAY, epoch)

    @classmethod
    def from_pole(cls, body, pole_lon, pole_lat, period, epoch, phase=0 * u.deg, frame="ecliptic", axes=None):
        """A principal-axis rotator as DAMIT publishes it: pole (λ, β), sidereal period P, epoch t0, angle φ0.

        r_ecl = R_z(λ) R_y(90° − β) R_z(φ0 + 2π (t − t0)/P) r_ast (Ďurech et al. 2010): the body spins at 2π/P
        about its axis of largest moment; the state is at t0 = ``epoch`` (its :attr:`epoch`). ``pole_lon``,
        ``pole_lat`` and ``phase`` are angles, ``period`` a time; ``frame`` "ecliptic" (J2000, IAU 2006) or
        "icrf" (RA, Dec); ``axes`` which user axes are DAMIT's x, y, z (None: the largest moment on z). The
        quaternion has w ≥ 0.
        Definitions: ``docs/conventions.md``, "Published spin forms"; :func:`spinorbit.spin_forms.pole_attitude`.
        """
        attitude, omega, _ = _spin_forms.pole_attitude(body, pole_lon, pole_lat, period, phase, frame, axes)
        return cls(body, _spin_forms.attitude_quaternion(attitude), omega * RAD_PER_DAY, _spin_forms.check_epoch(epoch))

    @classmethod
    def from_sbpy(cls, body, phys, epoch, row=0, phase=0 * u.deg, axes=None):
        """:meth:`from_pole` of the pole and rotation period in a row of an ``sbpy.data.Phys`` (the fields it reads:
        :mod:`spinorbit.sbpy_tables`); ``epoch``, ``phase`` and ``axes`` as in :meth:`from_pole`."""
        from spinorbit.sbpy_tables import pole_arguments

        lon, lat, period, frame = pole_arguments(phys, row)
        return cls.from_pole(body, lon, lat, period, epoch, phase=phase, frame=frame, axes=axes)

    @classmethod
    def from_tumbling(cls, body, p_psi, p_phi, momentum_lon, momentum_lat, phi0, theta0, psi0, epoch, mode=None,
                      frame="ecliptic", axes=None, theta_tolerance=_spin_forms.THETA0_TOLERANCE):
        """A tumbler as Pravec et al. (2005, 2014) publish it: P_ψ, P_φ, (λ_L, β_L), (φ0, θ0, ψ0) at an epoch.

        r_ecl = R_z(λ_L) R_y(90° − β_L) R_z(φ) R_x(θ) R_z(ψ) r_ast (Kaasalainen 2001): z-x-z Euler angles of the
        body axes (moments I1, I2, I3 of ``body`` on x, y, z; z the largest moment in SAM, the smallest in LAM)
        in the frame of the angular momentum. |L| and the energy are solved from the periods (times) and the
        moments; θ0 follows from ψ0 and is checked against ``theta0`` within ``theta_tolerance`` (None: the
        branch θ0 < 90°). ``mode`` None reads SAM/LAM from the body's z axis; ``frame`` and ``axes`` as in
        :meth:`from_pole`. Definitions: ``docs/conventions.md``; :func:`spinorbit.spin_forms.tumbling_attitude`.
        """
        attitude, omega, _, _ = _spin_forms.tumbling_attitude(
            body, p_psi, p_phi, momentum_lon, momentum_lat, phi0, theta0, psi0, mode, frame, axes, theta_tolerance)
        return cls(body, _spin_forms.attitude_quaternion(attitude), omega * RAD_PER_DAY, _spin_forms.check_epoch(epoch))

    def with_epoch(self, epoch) -> "RotationState":
        """The same attitude and spin tied to ``epoch`` (a scalar Time, or None to untie it)."""
        return RotationState(self._body, self._q, self._omega * RAD_PER_DAY, epoch)

    def pole(self, frame="ecliptic", max_wobble=_spin_forms.PA_MAX_WOBBLE, axes=None):
        """(λ, β, P, φ0 at :attr:`epoch`, …) of this state, the inverse of :meth:`from_pole`.

        Returns a :class:`spinorbit.spin_forms.PoleSolution` (P is :attr:`sidereal_period`); raises
        SpinFormError when the rotation axis is more than ``max_wobble`` (an angle) from the momentum, or the
        :attr:`wobble_amplitude` exceeds it (with the default, exactly the states :meth:`rotation_class` calls
        "PA" about their largest moment).
        """
        return _spin_forms.PoleSolution(**_spin_forms.pole_of(self.attitude_matrix, self._omega, self._body, frame,
                                                              max_wobble, axes), epoch=self._epoch)

    def tumbling_parameters(self, frame="ecliptic", axes=None):
        """(P_ψ, P_φ, λ_L, β_L, φ0, θ0, ψ0, I1/I3, I2/I3, mode, …) at :attr:`epoch`, the inverse of :meth:`from_tumbling`.

        Returns a :class:`spinorbit.spin_forms.TumblingParameters`; raises SpinFormError for a permanent
        rotation or the separatrix (no finite P_ψ, P_φ: :meth:`pole`).
        """
        return _spin_forms.TumblingParameters(**_spin_forms.tumbling_of(self.attitude_matrix, self._omega, self._body,
                                                                        frame, axes), epoch=self._epoch)

    # -- what users read -----------------------------------------------------------------------
    @property
    def body(self) -> RigidBody:
        return self._body

    @property
    def epoch(self) -> Time | None:
        """The instant of this state (astropy Time), or None when it was made without one."""
        return self._epoch

    @property
    def quaternion(self) -> np.ndarray:
        """(w, x, y, z), scalar first, user body axes → inertial."""
        return self._q.copy()

    @property
    def attitude_matrix(self) -> np.ndarray:
        """R, inertial → user body axes."""
        return _rotations.quat_to_attitude(self._q)

    @property
    def angular_velocity(self) -> u.Quantity:
        """Body angular velocity in the user's body axes (rad/day)."""
        return self._omega * RAD_PER_DAY

    @property
    def angular_velocity_rad_per_day(self) -> np.ndarray:
        """:attr:`angular_velocity`'s values in rad/day as plain floats (a copy): the same numbers without
        building a Quantity (~5 µs), for code that reads many states (the ensemble's batch route)."""
        return self._omega.copy()

    @property
    def angular_momentum(self) -> u.Quantity:
        """Body angular momentum I ω in the user's body axes (moment unit × rad/day)."""
        return self._body.moment_values * self._omega * (self._body.moment_unit * RAD_PER_DAY)

    @property
    def angular_momentum_direction(self) -> np.ndarray:
        """Unit vector of the angular momentum in the inertial frame (fixed in free rotation)."""
        self._rotating_momentum()
        inertial = self.attitude_matrix.T @ (self._body.moment_values * self._omega)
        return inertial / np.linalg.norm(inertial)

    # -- principal-axis view used by the core ---------------------------------------------------
    def principal_attitude_and_momentum(self) -> tuple[np.ndarray, np.ndarray]:
        """(R_p, M_p): inertial → principal-axis attitude matrix and body angular momentum on the
        principal axes (A ≤ B ≤ C), in :attr:`RigidBody.moment_unit` · rad/day, as plain floats."""
        p = self._body.to_principal
        attitude = p @ self.attitude_matrix
        momentum = p @ (self._body.moment_values * self._omega)
        return attitude, momentum

    def core_state(self) -> np.ndarray:
        """The state vector the core integrates: y = (q, ω), shape (7,), plain floats.

        q is the scalar-first quaternion principal axes → inertial frame, ω the angular velocity on
        the principal axes in rad/day (``docs/conventions.md``). This is the one way from a
        :class:`RotationState` to the arrays of :mod:`spinorbit.core`.
        """
        p = self._body.to_principal
        attitude = p @ self.attitude_matrix
        return np.concatenate([_rotations.attitude_to_quat(np.ascontiguousarray(attitude)), p @ self._omega])

    def _rotating_momentum(self) -> np.ndarray:
        """The principal-axis momentum, checked once for every property that describes the rotation.

        Raises InvalidStateError for zero spin (no mode, periods, E/E0, direction or elements) and for
        G = |M| outside :data:`ANDOYER_G_RANGE`, where the squares of the momentum in the maps under-
        or overflow (the properties would be NaN).
        """
        _, momentum = self.principal_attitude_and_momentum()
        if not np.any(momentum):
            raise InvalidStateError("the body is not rotating (zero spin): it has no rotation mode, periods, E/E0, "
                                    "momentum direction or elements. Give a non-zero angular velocity.")
        big_g = float(np.sqrt(np.sum((momentum / np.abs(momentum).max()) ** 2)) * np.abs(momentum).max())
        if not ANDOYER_G_RANGE[0] <= big_g <= ANDOYER_G_RANGE[1]:
            raise InvalidStateError(
                f"the angular momentum |I ω| = {big_g!r} (moment unit × rad/day) is outside [{ANDOYER_G_RANGE[0]:g}, "
                f"{ANDOYER_G_RANGE[1]:g}], where its square under- or overflows in float64; give the moments and the "
                "spin in units that bring it nearer 1 (e.g. moment ratios, rad/day)."
            )
        return momentum

    def _motion(self):
        big_a, big_b, big_c = self._body.principal_moments
        ic = _canonical.inertia_constants(big_a, big_b, big_c)
        momentum = self._rotating_momentum()
        mo, flip = _canonical.motion_from_momentum(momentum[0], momentum[1], momentum[2], ic)
        return mo, flip, momentum, (big_a, big_b, big_c)

    @property
    def mode(self) -> str:
        """'SAM' (short-axis mode, about C), 'LAM' (long-axis mode, about A), 'separatrix' or 'permanent rotation'
        (momentum exactly along A, B or C)."""
        mo, _, _, _ = self._motion()
        return MODE_NAMES[_summary.mode_code(mo)]

    @property
    def sense(self) -> str:
        """'+C' / '−C' in SAM, '+A' / '−A' in LAM: the sign of the momentum on the circulation axis."""
        mo, _, momentum, _ = self._motion()
        if mo[_canonical.MO_MODE] == _canonical.MODE_LAM:
            return "+A" if momentum[0] > 0 else "-A"
        return "+C" if momentum[2] >= 0 else "-C"

    @property
    def wobble_amplitude(self) -> u.Quantity:
        """The wobble amplitude (deg): the largest angle over the torque-free motion between the angular
        momentum and the circulation axis (C, the largest moment, in SAM; A, the smallest, in LAM).

        sin²θ_max = (M_y² + M_x² B(C − A)/(A(C − B)))/G² in SAM, (M_y² + M_z² B(C − A)/(C(B − A)))/G² in LAM
        (principal axes A ≤ B ≤ C; ``spinorbit.core.free_motion.wobble``); 0 for a permanent rotation, 90 on the
        separatrix. A constant of the free motion, the osculating value of a torqued one.
        ``docs/conventions.md``, "Wobble and rotation class".
        """
        self._rotating_momentum()  # refuses zero spin and unrepresentable momenta, as every motion property
        return _spin_forms.wobble_amplitude_deg(self._omega, self._body) * u.deg

    def rotation_class(self, threshold=_spin_forms.PA_MAX_WOBBLE) -> str:
        """"PA" (principal-axis rotator) when :attr:`wobble_amplitude` ≤ ``threshold`` (an angle in [0°, 90°)),
        else the non-principal-axis mode: "SAM", "LAM" or "separatrix".

        The default, 1° (:data:`spinorbit.spin_forms.PA_MAX_WOBBLE`), is about where a wobble becomes detectable
        in lightcurves (Pravec et al. 2005 call a rotation NPA only then; ``docs/design.md``, "PA or NPA"). A PA
        state is reported by its pole and :attr:`sidereal_period` (:meth:`pole`), an NPA one by P_ψ, P_φ
        (:meth:`tumbling_parameters`).
        """
        amplitude = self.wobble_amplitude.to_value(u.deg)
        return str(_spin_forms.rotation_classes(np.array([amplitude]), np.array([self.mode]), threshold)[0])

    @property
    def energy_ratio(self) -> float:
        """E/E0 = 2 T C / G²: kinetic energy over that of rotation about C with the same momentum.

        1 for principal-axis rotation about C; C/A for rotation about A; C/B on the separatrix.
        """
        momentum = self._rotating_momentum()
        return float(_summary.energy_ratio(*momentum, *self._body.principal_moments))

    @property
    def periods(self) -> tuple[u.Quantity, u.Quantity]:
        """(P_ψ, P_φ): rotation and precession periods in the tumbling-asteroid convention (Pravec et al. 2005).

        P_ψ = 4K/ν is the period of the body momentum's circulation (SAM: about C; LAM: about A), with
        ν the rate of the elliptic argument. P_φ is the mean precession period about the momentum of
        the circulation axis: in SAM the C axis, whose azimuth follows g, so P_φ = 2π/⟨ġ⟩ with
        ⟨ġ⟩ = c G + PN_COEFF · Π(n|p)/K(p) · ν (eq. 7 averaged over a period); in LAM the long axis A,
        which gains one turn less per polhode period: P_φ = 2π/(⟨ġ⟩ − 2π/P_ψ). Checked: the Takahashi
        et al. (2013) Toutatis state gives 5.369 d / 7.412 d (tests/test_state.py). Both are
        infinite on the separatrix; a permanent rotation (momentum exactly along A, B or C) has P_ψ = ∞
        and P_φ = 2π/|ω|. Just off the A or C axis they are the small-wobble limits instead (about C:
        P_ψ → 2π/ν₀, P_φ → 2π/(|ω| + ν₀), ν₀ = G√((a−c)(b−c))); :attr:`sidereal_period` is the
        continuous one.
        """
        mo, _, momentum, moments = self._motion()
        rotation, precession = _summary.periods(mo, *momentum, *moments)  # the one definition (core)
        if math.isnan(rotation) or math.isnan(precession):  # inf is a period (separatrix); NaN never is
            raise InvalidStateError(f"the periods of this state are not computable in float64 (G = "
                                    f"{float(mo[_canonical.MO_G])!r}); express the moments and spin nearer 1.")
        return rotation * u.day, precession * u.day

    @property
    def sidereal_period(self) -> u.Quantity:
        """Sidereal rotation period (day): 2π/|ω| for a permanent rotation (momentum along A, B or C).

        For a tumbler, 2π over the mean rate at which the body turns about its angular momentum: in
        SAM 1/(1/P_φ − 1/P_ψ), in LAM 1/(1/P_φ + 1/P_ψ) — the lightcurve combination frequency that
        becomes the rotation frequency as the wobble vanishes, so it is continuous as the state
        approaches the A or C axis, where P_ψ and P_φ jump to (∞, 2π/|ω|) by their definition; on the
        separatrix 2π B/G. ``docs/conventions.md`` ("Periods").
        """
        mo, _, momentum, moments = self._motion()
        return _summary.sidereal_period(mo, *momentum, *moments) * u.day

    @property
    def pole_icrf(self) -> tuple[u.Quantity, u.Quantity]:
        """(RA, Dec) of the angular momentum in ICRF (deg): the spin pole (``spinorbit.pole``)."""
        ra, dec, _, _ = _pole.pole_angles_deg(self.angular_momentum_direction)
        return ra[0] * u.deg, dec[0] * u.deg

    @property
    def pole_ecliptic(self) -> tuple[u.Quantity, u.Quantity]:
        """(λ, β) of the angular momentum in ecliptic J2000 (deg; IAU 2006 obliquity, frame bias included)."""
        _, _, lon, lat = _pole.pole_angles_deg(self.angular_momentum_direction)
        return lon[0] * u.deg, lat[0] * u.deg

    def obliquity(self, orbit_normal) -> u.Quantity:
        """Angle (deg) between the angular momentum and ``orbit_normal``, the normal of the orbit plane.

        Parameters
        ----------
        orbit_normal : array_like or Quantity, shape (3,)
            ICRF components of the orbit's angular momentum r × v (any length; heliocentric for the
            obliquity to the orbit about the Sun). :func:`spinorbit.pole.orbit_normals` makes it
            from a position and velocity.
        """
        values = orbit_normal.value if isinstance(orbit_normal, u.Quantity) else orbit_normal
        normal = np.reshape(np.asarray(values, dtype=float), (1, -1))
        return _pole.obliquity_deg(self.angular_momentum_direction, normal)[0] * u.deg

    def _reference_frame(self, reference) -> np.ndarray:
        """Passive rotation inertial → frame of the Andoyer angles h, I (see :meth:`canonical_elements`)."""
        if isinstance(reference, str):
            if reference not in ("auto", "inertial"):
                raise ValueError(f"reference must be 'auto', 'inertial' or a 3×3 rotation; got {reference!r}.")
            direction = self.angular_momentum_direction
            if reference == "auto" and math.hypot(direction[0], direction[1]) < AUTO_REFERENCE_MIN_SIN_I:
                return _rotations.rot1(math.pi / 2)
            return np.eye(3)
        return _as_rotation_matrix(reference)

    def andoyer_variables(self, reference="auto") -> tuple[u.Quantity, ...]:
        """Andoyer variables (L, G, H, l, g, h) in principal axes (A ≤ B ≤ C), paper section 3.

        Quantities: the momenta L, G, H in the body's moment unit × rad/day (rad/day for moments given
        as ratios), the angles l, g, h in radians. ``reference`` as in :meth:`canonical_elements`. At
        J = 0 (spin exactly about C) only l + g is defined; the split follows
        ``spinorbit.core.elements.andoyer.andoyer_from_attitude``.
        """
        self._rotating_momentum()
        frame = self._reference_frame(reference)
        attitude, momentum = self.principal_attitude_and_momentum()
        values = _andoyer.andoyer_from_attitude(attitude @ frame.T, momentum)
        momentum_unit = self._body.moment_unit * RAD_PER_DAY
        return tuple(float(x) * (momentum_unit if k < 3 else u.rad) for k, x in enumerate(values))

    @classmethod
    def from_andoyer(cls, body: RigidBody, big_l, big_g, big_h, l, g, h, reference=None) -> "RotationState":
        """The state of Andoyer variables in principal axes (inverse of :meth:`andoyer_variables`).

        ``big_l``, ``big_g``, ``big_h`` are Quantities in the body's moment unit × an angle per time (rad/day
        for moments given as ratios), ``l``, ``g``, ``h`` angles. ``reference`` is the passive rotation
        inertial → frame of h and I (identity by default).
        """
        momentum_unit = body.moment_unit * RAD_PER_DAY
        example = f"1.0 * u.Unit('{momentum_unit.to_string()}')"
        momenta = [value_in(name, value, momentum_unit, example, shape=(), finite=False)
                   for name, value in (("big_l", big_l), ("big_g", big_g), ("big_h", big_h))]
        angles = [value_in(name, value, u.rad, "0.3 * u.rad", shape=(), finite=False)
                  for name, value in (("l", l), ("g", g), ("h", h))]
        values = np.array(momenta + angles, dtype=float)
        big_l, big_g, big_h = momenta
        if not np.all(np.isfinite(values)) or big_g <= 0 or abs(big_l) > big_g or abs(big_h) > big_g:
            raise InvalidStateError(
                f"Andoyer variables need finite values with G > 0 and |L|, |H| ≤ G; got L={big_l!r}, G={big_g!r}, "
                f"H={big_h!r}."
            )
        if not ANDOYER_G_RANGE[0] <= big_g <= ANDOYER_G_RANGE[1]:
            raise InvalidStateError(
                f"G = {big_g!r} is outside [{ANDOYER_G_RANGE[0]:g}, {ANDOYER_G_RANGE[1]:g}], where squares of the "
                "momentum components under- or overflow; express the momentum in other units."
            )
        frame = np.eye(3) if reference is None else _as_rotation_matrix(reference)
        attitude_ref, momentum = _andoyer.attitude_from_andoyer(*values)
        p = body.to_principal
        return cls.from_matrix(body, p.T @ attitude_ref @ frame, (p.T @ momentum) / body.moment_values * RAD_PER_DAY)

    def canonical_elements(self, reference="auto") -> CanonicalElements:
        """Fukushima's canonical elements (paper eq. 4) of this state.

        Parameters
        ----------
        reference : {"auto", "inertial"} or (3, 3) array
            Frame of H and h. "inertial" uses the inertial frame as is; "auto" does too unless the
            angular momentum is within asin(0.1) ≈ 5.7° of its z axis (near the Andoyer I = 0
            singularity), in which case it uses the frame turned by 90° about x. A matrix gives the
            passive rotation inertial → reference frame.

        Raises
        ------
        SingularElementsError
            For permanent rotations, which have no finite elements.
        """
        mo, _, _, moments = self._motion()
        if mo[_canonical.MO_MODE] == _canonical.MODE_UNIFORM:
            raise SingularElementsError(
                "this state is a permanent rotation (spin about a principal axis that makes s infinite): it has no "
                "finite canonical elements. propagate_torque_free still works (uniform rotation)."
            )
        attitude, momentum = self.principal_attitude_and_momentum()
        frame = self._reference_frame(reference)
        ic = _canonical.inertia_constants(*moments)
        if not _canonical.symmetric_gap_resolved(mo[_canonical.MO_S], mo[_canonical.MO_G], ic):
            raise SingularElementsError(_unresolved_gap_message(
                float(mo[_canonical.MO_S]), float(mo[_canonical.MO_G]), moments, "this state"))
        elements, flip, mode = _canonical.elements_from_state(attitude @ frame.T, momentum, ic)
        return CanonicalElements(*(float(x) for x in elements), flip=int(flip), mode=MODE_NAMES[mode], reference=frame)

    @classmethod
    def from_canonical_elements(cls, body: RigidBody, elements: CanonicalElements) -> "RotationState":
        """The state of given canonical elements (paper eqs. 7–8), in the elements' reference frame."""
        ic = _canonical.inertia_constants(*body.principal_moments)
        mo = _canonical.motion_from_elements(abs(elements.S), elements.Z, ic)
        if mo[_canonical.MO_MODE] == _canonical.MODE_UNIFORM or not _canonical.symmetric_gap_resolved(
                abs(elements.S), elements.Z, ic):
            raise SingularElementsError(_unresolved_gap_message(
                elements.S, elements.Z, body.principal_moments, "these elements"))
        values = np.array([elements.S, elements.Z, elements.H, elements.s, elements.z, elements.h])
        attitude_ref, momentum = _canonical.state_from_elements(values, elements.flip, ic)
        p = body.to_principal
        attitude_user = p.T @ attitude_ref @ elements.reference
        return cls.from_matrix(body, attitude_user, (p.T @ momentum) / body.moment_values * RAD_PER_DAY)

    def principal_flow_start(self, horizon_days: float) -> tuple[np.ndarray, np.ndarray]:
        """(principal quaternion, principal momentum) that the exact free flow starts from, checked for a
        flow reaching ``horizon_days`` (the largest |dt|, days): what :meth:`propagate_torque_free` and the
        planner's vectorised sensitivities (:mod:`spinorbit.scene.bounds`) both start from.

        Raises InvalidStateError when the flow would leave its domain (the fastest angle beyond
        :data:`MAX_FLOW_PHASE`) or the momentum is outside :data:`ANDOYER_G_RANGE`. At rest the flow is the
        constant state (exact) and nothing is checked.
        """
        attitude, momentum = self.principal_attitude_and_momentum()
        if np.any(momentum):
            momentum = self._rotating_momentum()
            phase = float(np.linalg.norm(momentum)) / self._body.principal_moments[0] * horizon_days
            if not phase <= MAX_FLOW_PHASE:
                raise InvalidStateError(
                    f"dt up to {horizon_days!r} d is beyond the free flow's domain: the fastest angle "
                    f"of this motion turns by {phase:.3g} rad > {MAX_FLOW_PHASE:g} rad, where one ulp of dt already "
                    "moves the attitude by more than 0.1 rad. Propagate from a later state, or shorten dt."
                )
        return _rotations.attitude_to_quat(attitude), momentum

    def propagate_torque_free(self, dt, closed_forms=True) -> tuple[np.ndarray, u.Quantity]:
        """Exact torque-free motion (paper eq. 12) at times ``dt`` after this state.

        Parameters
        ----------
        dt : Quantity
            Time offsets (a time Quantity such as ``[0, 1, 2] * u.day``), scalar or 1-D.
        closed_forms : bool
            True (default): a body with two exactly equal moments takes the regular precession in
            closed form (``spinorbit.core.free_motion.regular_precession``, trig only); False: the elliptic flow
            at parameter 0 (same result to ~1e-15 rad, for comparisons).

        Returns
        -------
        quaternions : ndarray, shape (N, 4)
            Scalar-first quaternions, user body axes → inertial.
        angular_velocity : Quantity, shape (N, 3)
            Body angular velocity in user axes (rad/day).
        """
        times = value_in("dt", dt, u.day, "[0, 1, 2] * u.day", finite=False)
        times = np.atleast_1d(np.asarray(times, dtype=float))
        if times.ndim != 1:
            raise ValueError(f"dt must be a scalar or 1-D array of time offsets; got shape {times.shape}.")
        if not np.all(np.isfinite(times)):
            first = float(times[~np.isfinite(times)][0])
            raise NonFiniteStateError(f"dt must hold finite time offsets; got {first!r} among {times.size} values.")
        principal_q0, momentum = self.principal_flow_start(float(np.abs(times).max()))
        p = self._body.to_principal
        principal_q, principal_m = _torque_free.torque_free_states(
            principal_q0, momentum, *self._body.principal_moments, times, closed_forms=closed_forms,
        )
        # v_inertial = M(q_p) v_principal = M(q_p) P v_user, so q_user = q_p ⊗ q(P).
        p0, p1, p2, p3 = _rotations.matrix_to_quat(np.ascontiguousarray(p))
        right_product = np.array([[p0, -p1, -p2, -p3], [p1, p0, p3, -p2], [p2, -p3, p0, p1], [p3, p2, -p1, p0]])
        quaternions = principal_q @ right_product.T  # row-wise q ⊗ q(P), no Python loop over times
        body_momentum = principal_m @ p  # Pᵀ M_p for every row
        return quaternions, (body_momentum / self._body.moment_values) * RAD_PER_DAY

    def __repr__(self):
        omega = ", ".join(f"{w:.6g}" for w in self._omega)
        q = ", ".join(f"{c:.6g}" for c in self._q)
        epoch = "" if self._epoch is None else f", epoch={self._epoch.tdb.isot} TDB"
        return f"RotationState(q=({q}), ω=({omega}) rad/day{epoch})"
