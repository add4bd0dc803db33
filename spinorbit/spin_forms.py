"""Spin states as astronomers publish them, both ways: a pole and a period, or a tumbler's periods and Euler angles.

Two forms (definitions and sources: ``docs/conventions.md``, "Published spin forms"):

- **Principal-axis rotator** (DAMIT; Kaasalainen et al. 2001, Icarus 153, 37; Ďurech et al. 2010, A&A 513,
  A46): ecliptic pole (λ, β), sidereal period P, epoch t0 and rotation angle φ0, with
  r_ecl = R_z(λ) R_y(90° − β) R_z(φ0 + 2π (t − t0)/P) r_ast (active rotations). The body spins about its
  axis of largest moment.
- **Tumbler** (Kaasalainen 2001, A&A 376, 302; Pravec et al. 2005, Icarus 173, 108): P_ψ, P_φ, the
  angular momentum's direction (λ_L, β_L), the z-x-z Euler angles (φ0, θ0, ψ0) of the body axes in the
  frame whose z axis is the angular momentum, r_ecl = R_z(λ_L) R_y(90° − β_L) R_z(φ) R_x(θ) R_z(ψ) r_ast,
  and the moment ratios I1/I3, I2/I3 (z the axis the momentum circulates about: the largest moment in SAM,
  the smallest in LAM).

The body frame of both forms is the user's body frame of :class:`spinorbit.RigidBody` (the frame the
published moments, or the shape model, are given in), relabelled cyclically when its z axis is not
the rotation axis (``axes``: which user axes play x, y, z; "xyz" when none is needed). This module turns
either form into an attitude matrix and a body angular velocity and back; :class:`spinorbit.RotationState`
wraps them (``from_pole``, ``from_tumbling``, ``pole``, ``tumbling_parameters``). Arguments with a
dimension must carry a unit (``docs/conventions.md``, "Units").
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from astropy import units as u
from astropy.time import Time

from spinorbit.body import RigidBody
from spinorbit.core.elements.canonical import MODE_LAM, MODE_SAM
from spinorbit.core.errors import SpinorbitError
from spinorbit.core.free_motion import from_periods
from spinorbit.core.free_motion.summary import MODE_SEPARATRIX, motion_summary
from spinorbit.core.free_motion.wobble import wobble_amplitude
from spinorbit.core.elements.canonical import MODE_UNIFORM
from spinorbit.core.math.rotations import attitude_to_euler313, attitude_to_quat, euler313_to_attitude, rot3
from spinorbit.frames import icrf_to_ecliptic_matrix
from spinorbit.quantities import value_in

__all__ = ["PoleSolution", "SpinFormError", "TumblingParameters", "FRAMES", "CYCLIC_AXES", "PA_MAX_WOBBLE",
           "ROTATION_CLASSES", "THETA0_TOLERANCE", "attitude_quaternion", "rotation_classes", "wobble_amplitude_deg",
           "wobble_threshold_deg", "check_epoch", "momentum_frame", "pole_attitude", "tumbling_attitude", "pole_of", "tumbling_of"]

#: Frames of the published angles: "ecliptic" (ecliptic and equinox J2000, IAU 2006 obliquity with the frame
#: bias, as every spin pole in spinorbit: docs/conventions.md) and "icrf" (then λ, β are RA, Dec).
FRAMES = ("ecliptic", "icrf")
#: The relabellings of the user's body axes that keep the frame right-handed: which user axes play x, y, z.
CYCLIC_AXES = ("xyz", "yzx", "zxy")
#: Default threshold of the rotation class (:func:`rotation_classes`, ``RotationState.rotation_class``) and of
#: :meth:`RotationState.pole`: a state whose wobble amplitude (the largest nutation angle of its circulation axis
#: about the angular momentum over the free motion, :func:`wobble_amplitude_deg`) is at most this is a
#: principal-axis rotator (PA), reported by a pole and one sidereal period. Pravec et al. (2005) call a rotation
#: NPA only when its second period is detected in the lightcurve; a wobble below ~1° changes the aspect of the body
#: by less than 1°, which moves a lightcurve by less than the 0.01–0.02 mag errors of dense photometry
#: (docs/design.md, "PA or NPA"). Every table, CLI command and scene file takes another value.
PA_MAX_WOBBLE = 1.0 * u.deg
#: The values of a rotation class: principal-axis, or the non-principal-axis mode of the motion.
ROTATION_CLASSES = ("PA", "SAM", "LAM", "separatrix")
#: How far a published θ0 may be from the nutation angle that (P_ψ, P_φ, ψ0, I1/I3, I2/I3) imply (θ0 is not
#: independent of them): published angles are rounded to 0.1°–1° and the periods to 3–5 digits, which
#: moves the implied θ by up to a few tenths of a degree (docs/conventions.md, "Published spin forms").
THETA0_TOLERANCE = 1.0 * u.deg
HOUR_PER_DAY = 24.0
_MODE_NAMES = {MODE_SAM: "SAM", MODE_LAM: "LAM"}


class SpinFormError(SpinorbitError, ValueError):
    """A published spin form that describes no rotation of this body, or a state without that form."""


@dataclass(frozen=True)
class PoleSolution:
    """A principal-axis rotator as DAMIT publishes it (:meth:`spinorbit.RotationState.pole`).

    Attributes
    ----------
    pole_lon, pole_lat : Quantity
        λ, β of the angular momentum (deg) in ``frame`` (RA, Dec for "icrf"); λ in [0°, 360°).
    period : Quantity
        Sidereal rotation period P (h): :attr:`spinorbit.RotationState.sidereal_period`.
    phase : Quantity
        φ0 (deg, [0°, 360°)) at ``epoch``: the rotation angle of the body's x axis about the pole, zero when
        the x axis lies in the plane of the pole and the frame's z axis, on the side away from that z axis.
    epoch : Time or None
        The state's epoch.
    frame : str
    wobble : Quantity
        Angle (deg) between the angular momentum and the rotation axis at ``epoch``: 0 for a state made by
        ``from_pole``. Its largest value over the free motion is the state's ``wobble_amplitude``.
    axes : str
        Which user body axes are DAMIT's x, y, z (:data:`CYCLIC_AXES`).
    """

    pole_lon: u.Quantity
    pole_lat: u.Quantity
    period: u.Quantity
    phase: u.Quantity
    epoch: Time | None
    frame: str
    wobble: u.Quantity
    axes: str

    def arguments(self) -> dict:
        """Keyword arguments of :meth:`spinorbit.RotationState.from_pole` that make this state again."""
        return dict(pole_lon=self.pole_lon, pole_lat=self.pole_lat, period=self.period, epoch=self.epoch,
                    phase=self.phase, frame=self.frame, axes=self.axes)


@dataclass(frozen=True)
class TumblingParameters:
    """A tumbler as Pravec et al. (2005, 2014) publish it (:meth:`spinorbit.RotationState.tumbling_parameters`).

    Attributes
    ----------
    p_psi, p_phi : Quantity
        Rotation and precession periods P_ψ, P_φ (h): :attr:`spinorbit.RotationState.periods`.
    momentum_lon, momentum_lat : Quantity
        λ_L, β_L of the angular momentum (deg) in ``frame``.
    phi0, theta0, psi0 : Quantity
        z-x-z Euler angles (deg) of the body axes in the frame of the angular momentum at ``epoch``;
        φ0, ψ0 in [0°, 360°), θ0 in [0°, 180°].
    i1_i3, i2_i3 : float
        Moment ratios of the body axes x, y to z (after ``axes``).
    mode : str
        "SAM" or "LAM".
    epoch : Time or None
    frame : str
    axes : str
        Which user body axes are the x, y, z of the Euler angles (:data:`CYCLIC_AXES`).
    """

    p_psi: u.Quantity
    p_phi: u.Quantity
    momentum_lon: u.Quantity
    momentum_lat: u.Quantity
    phi0: u.Quantity
    theta0: u.Quantity
    psi0: u.Quantity
    i1_i3: float
    i2_i3: float
    mode: str
    epoch: Time | None
    frame: str
    axes: str

    def arguments(self) -> dict:
        """Keyword arguments of :meth:`spinorbit.RotationState.from_tumbling` that make this state again."""
        return dict(p_psi=self.p_psi, p_phi=self.p_phi, momentum_lon=self.momentum_lon,
                    momentum_lat=self.momentum_lat, phi0=self.phi0, theta0=self.theta0, psi0=self.psi0,
                    epoch=self.epoch, mode=self.mode, frame=self.frame, axes=self.axes)


# -- pieces shared by both forms ---------------------------------------------------------------------
def _frame_matrix(frame) -> np.ndarray:
    """F with v_frame = F v_icrf."""
    if frame not in FRAMES:
        raise SpinFormError(f"frame expects one of {FRAMES}; got {frame!r}.")
    return icrf_to_ecliptic_matrix() if frame == "ecliptic" else np.eye(3)


def momentum_frame(lon: float, lat: float) -> np.ndarray:
    """N = R2(90° − β) R3(λ), passive (radians): frame → the frame whose z axis points to (λ, β).

    Its rows are x_L = (sin β cos λ, sin β sin λ, −cos β), y_L = (−sin λ, cos λ, 0) (the ascending node of
    the plane ⟂ z_L on the frame's x-y plane) and z_L = (cos β cos λ, cos β sin λ, sin β): the transpose of
    DAMIT's active R_z(λ) R_y(90° − β).
    """
    cl, sl, cb, sb = math.cos(lon), math.sin(lon), math.cos(lat), math.sin(lat)
    return np.array([[sb * cl, sb * sl, -cb], [-sl, cl, 0.0], [cb * cl, cb * sl, sb]])


def _relabelling(axes) -> np.ndarray:
    """Q with v_relabelled = Q v_user (rows: the user axes that play x, y, z)."""
    if axes not in CYCLIC_AXES:
        raise SpinFormError(f"axes expects one of {CYCLIC_AXES} (the user body axes that play x, y, z, keeping the "
                            f"frame right-handed); got {axes!r}.")
    return np.eye(3)[["xyz".index(name) for name in axes]]


def _axes_with_z(body: RigidBody, pick) -> str:
    """The cyclic relabelling whose z is the user axis ``pick`` chooses among the moments ("xyz" if z is one)."""
    moments = body.moment_values
    wanted = pick(moments)
    if moments[2] == wanted:
        return "xyz"
    return "yzx" if moments[0] == wanted else "zxy"


def _angle(name, value, example, shape=()):
    return value_in(name, value, u.rad, example, shape=shape)


def check_epoch(epoch):
    """``epoch`` if it is a scalar astropy Time, else SpinFormError."""
    if not isinstance(epoch, Time) or not epoch.isscalar:
        raise SpinFormError(f"epoch expects a scalar astropy Time (the instant of the published angles); got "
                            f"{epoch!r}.")
    return epoch


def _direction(name_lon, lon, name_lat, lat):
    lon_rad = _angle(name_lon, lon, "250 * u.deg")
    lat_rad = _angle(name_lat, lat, "-75 * u.deg")
    if not abs(lat_rad) <= math.pi / 2 * (1 + 1e-15):
        raise SpinFormError(f"{name_lat} expects a latitude in [-90°, 90°]; got {lat!s}.")
    return lon_rad, max(-math.pi / 2, min(math.pi / 2, lat_rad))


def _period_days(name, value):
    days = value_in(name, value, u.day, "8 * u.hour", shape=())
    if not days > 0:
        raise SpinFormError(f"{name} expects a positive period such as 8 * u.hour; got {value!s}.")
    return days


def attitude_quaternion(attitude) -> np.ndarray:
    """The quaternion (w ≥ 0) of attitude matrix R (inertial → body): the sign the published forms give."""
    q = attitude_to_quat(np.ascontiguousarray(attitude, dtype=float))
    return -q if q[0] < 0 else q


def _user_attitude(relabelled_attitude, axes):
    """R_user←icrf of R_relabelled←icrf."""
    return _relabelling(axes).T @ relabelled_attitude


# -- principal-axis rotators -------------------------------------------------------------------------
def pole_attitude(body, pole_lon, pole_lat, period, phase, frame="ecliptic", axes=None):
    """(attitude matrix inertial (ICRF) → user axes, body angular velocity in user axes (rad/day), axes).

    The DAMIT form (module docstring) at its epoch: R = R3(φ0) N(λ, β) F, spin 2π/P about the axis of the
    largest moment (DAMIT's z; ``axes`` None picks the relabelling that makes it z).
    """
    lon, lat = _direction("pole_lon", pole_lon, "pole_lat", pole_lat)
    days = _period_days("period", period)
    angle = _angle("phase", phase, "0 * u.deg")
    axes = _axes_with_z(body, np.max) if axes is None else axes
    q = _relabelling(axes)
    moments = q @ body.moment_values
    if moments[2] < moments.max():
        raise SpinFormError(f"axes={axes!r} puts the moment {moments[2]:g} on DAMIT's z, the rotation axis, but a "
                            f"principal-axis rotator spins about its largest moment ({moments.max():g}); give axes=None.")
    attitude = rot3(angle) @ momentum_frame(lon, lat) @ _frame_matrix(frame)
    omega = q.T @ np.array([0.0, 0.0, 2.0 * math.pi / days])
    return _user_attitude(attitude, axes), omega, axes


def _momentum_direction(attitude, omega, body, frame):
    """(λ, β) in radians of the angular momentum of (R, ω) in ``frame``, and the ICRF unit vector."""
    momentum = body.moment_values * np.asarray(omega, dtype=float)
    if not np.any(momentum):
        raise SpinFormError("the body is not rotating (zero spin): it has no pole or periods.")
    inertial = attitude.T @ momentum
    unit = inertial / np.linalg.norm(inertial)
    x, y, z = _frame_matrix(frame) @ unit
    return math.atan2(y, x) % (2 * math.pi), math.atan2(z, math.hypot(x, y)), unit


def _summary(attitude, omega, body):
    """core motion_summary (mode, E/E0, P_ψ, P_φ, P_sid in days) of the state's principal momentum."""
    principal = body.to_principal @ (body.moment_values * np.asarray(omega, dtype=float))
    return motion_summary(*(float(m) for m in principal), *body.principal_moments)


# -- which form: principal-axis or tumbling -----------------------------------------------------------
def wobble_amplitude_deg(omega, body) -> float:
    """The wobble amplitude (deg) of body angular velocity ``omega`` (user axes, rad/day) of ``body``.

    The largest angle between the circulation axis (C in SAM, A in LAM) and the angular momentum over the
    torque-free motion through this state (:mod:`spinorbit.core.free_motion.wobble`): 0 for a permanent
    rotation, 90 on the separatrix.
    """
    principal = body.to_principal @ (body.moment_values * np.asarray(omega, dtype=float))
    if not np.any(principal):
        raise SpinFormError("the body is not rotating (zero spin): it has no wobble or rotation class.")
    return math.degrees(wobble_amplitude(*(float(m) for m in principal), *body.principal_moments))


def wobble_threshold_deg(threshold, name="threshold") -> float:
    """``threshold`` (an angle) in degrees, checked to lie in [0°, 90°): at 90° even the separatrix would be PA."""
    degrees = value_in(name, threshold, u.deg, "1 * u.deg", shape=())
    if not 0.0 <= degrees < 90.0:
        raise SpinFormError(f"{name} expects a wobble amplitude in [0°, 90°) below which a rotation is principal-axis "
                            f"(default {PA_MAX_WOBBLE}); got {threshold!s}.")
    return degrees


def rotation_classes(amplitudes_deg, modes, threshold=PA_MAX_WOBBLE) -> np.ndarray:
    """"PA" where the wobble amplitude (deg) is at most ``threshold``, else the motion's mode ("SAM", "LAM", "separatrix").

    ``modes`` are the mode names of ``RotationState.mode`` (a permanent rotation has amplitude 0 and is "PA"
    at every threshold). Arrays of one shape; returns a str array of that shape.
    """
    limit = wobble_threshold_deg(threshold)
    amplitudes = np.asarray(amplitudes_deg, dtype=float)
    modes = np.asarray(modes)
    if amplitudes.shape != modes.shape:
        raise SpinFormError(f"amplitudes_deg and modes must have one shape; got {amplitudes.shape} and {modes.shape}.")
    classes = np.where(amplitudes <= limit, "PA", modes).astype(f"<U{len('separatrix')}")
    unknown = set(np.unique(classes).tolist()) - set(ROTATION_CLASSES)
    if unknown:
        raise SpinFormError(f"a state with wobble amplitude above {limit}° has mode {sorted(unknown)}, not one of "
                            f"{ROTATION_CLASSES[1:]}: the amplitudes and the modes do not belong together.")
    return classes


def pole_of(attitude, omega, body, frame="ecliptic", max_wobble=PA_MAX_WOBBLE, axes=None) -> dict:
    """The DAMIT form of (R, ω): the fields of :class:`PoleSolution` but ``epoch``.

    Raises :class:`SpinFormError` when the rotation axis (largest moment, DAMIT's z) is further than
    ``max_wobble`` from the angular momentum now, or the motion's wobble amplitude (:func:`wobble_amplitude_deg`)
    exceeds it: that state tumbles, and :func:`tumbling_of` describes it. ``wobble`` is the angle now.
    """
    limit = value_in("max_wobble", max_wobble, u.rad, "1 * u.deg", shape=())
    lon, lat, _ = _momentum_direction(attitude, omega, body, frame)
    axes = _axes_with_z(body, np.max) if axes is None else axes
    in_momentum_frame = _relabelling(axes) @ attitude @ _frame_matrix(frame).T @ momentum_frame(lon, lat).T
    wobble = math.atan2(math.hypot(in_momentum_frame[0, 2], in_momentum_frame[1, 2]), in_momentum_frame[2, 2])
    amplitude = math.radians(wobble_amplitude_deg(omega, body))
    if not max(wobble, amplitude) <= limit:
        raise SpinFormError(
            f"the rotation axis ({axes[2]}, largest moment) is {math.degrees(wobble):.6g}° from the angular momentum, "
            f"and the motion's wobble amplitude is {math.degrees(amplitude):.6g}°; more than max_wobble = "
            f"{max_wobble!s}: the state tumbles and a pole and one period would drop its wobble. Use "
            "state.tumbling_parameters(), or pass a larger max_wobble.")
    r = in_momentum_frame
    phase = math.atan2(r[0, 1] - r[1, 0], r[0, 0] + r[1, 1]) % (2 * math.pi)  # φ + ψ of the 3-1-3 angles
    sidereal_days = _summary(attitude, omega, body)[4]
    return dict(pole_lon=math.degrees(lon) * u.deg, pole_lat=math.degrees(lat) * u.deg,
                period=sidereal_days * HOUR_PER_DAY * u.hour, phase=math.degrees(phase) * u.deg, frame=frame,
                wobble=math.degrees(wobble) * u.deg, axes=axes)


# -- tumblers ----------------------------------------------------------------------------------------
def _mode_code(mode, body, axes):
    if mode in ("SAM", "LAM"):
        return MODE_SAM if mode == "SAM" else MODE_LAM
    if mode is not None:
        raise SpinFormError(f"mode expects 'SAM', 'LAM' or None (from the body's z axis); got {mode!r}.")
    moments = _relabelling(axes or "xyz") @ body.moment_values
    if moments[2] > max(moments[:2]):
        return MODE_SAM
    if moments[2] < min(moments[:2]):
        return MODE_LAM
    raise SpinFormError(f"mode=None reads the mode from the body's z axis (largest moment: SAM, smallest: LAM), but "
                        f"its moment {moments[2]:g} is the intermediate one of {moments.tolist()}; give mode='SAM' or "
                        "'LAM'.")


def _circulation_axes(body, code, axes):
    """The relabelling whose z is the circulation axis of mode ``code``, checked."""
    pick = np.max if code == MODE_SAM else np.min
    if axes is None:
        axes = _axes_with_z(body, pick)
    moments = _relabelling(axes) @ body.moment_values
    if moments[2] != pick(moments):
        raise SpinFormError(
            f"axes={axes!r} puts the moment {moments[2]:g} on z, but in {_MODE_NAMES[code]} the Euler angles' z axis is "
            f"the one the angular momentum circulates about, the {'largest' if code == MODE_SAM else 'smallest'} moment "
            f"({pick(moments):g}); give axes=None.")
    return axes, moments


def tumbling_attitude(body, p_psi, p_phi, momentum_lon, momentum_lat, phi0, theta0, psi0, mode=None,
                      frame="ecliptic", axes=None, theta_tolerance=THETA0_TOLERANCE):
    """(attitude matrix ICRF → user axes, body angular velocity in user axes (rad/day), axes, mode name).

    The periods fix the motion's shape μ and |L| (:func:`spinorbit.core.free_motion.from_periods.motion_of_periods`);
    ψ0 then fixes θ0 on the branch ``theta0`` is on (θ0 < 90°: the momentum on +z; None: that branch),
    and ``theta0`` must be within ``theta_tolerance`` of it. R = R3(ψ0) R1(θ0) R3(φ0) N(λ_L, β_L) F.
    """
    code = _mode_code(mode, body, axes)
    axes, moments = _circulation_axes(body, code, axes)
    days_psi, days_phi = _period_days("p_psi", p_psi), _period_days("p_phi", p_phi)
    lon, lat = _direction("momentum_lon", momentum_lon, "momentum_lat", momentum_lat)
    phi, psi = _angle("phi0", phi0, "10 * u.deg"), _angle("psi0", psi0, "20 * u.deg")
    big_a, big_b, big_c = body.principal_moments
    try:
        mu, big_g = from_periods.motion_of_periods(days_psi, days_phi, code, big_a, big_b, big_c)
    except ValueError as error:
        raise SpinFormError(f"p_psi = {p_psi!s}, p_phi = {p_phi!s}: {error} Check the periods, the moment ratios and "
                            "the mode.") from None
    sine = math.sqrt(from_periods.nutation_sine_squared(mu, psi, *moments, big_b))
    theta = math.asin(min(sine, 1.0))
    limit = value_in("theta_tolerance", theta_tolerance, u.rad, "1 * u.deg", shape=())  # checked even if unused
    if theta0 is not None:
        given = _angle("theta0", theta0, "30 * u.deg")
        if not 0.0 <= given <= math.pi:
            raise SpinFormError(f"theta0 expects an angle in [0°, 180°]; got {theta0!s}.")
        theta = theta if given <= math.pi / 2 else math.pi - theta
        if not abs(given - theta) <= limit:
            raise SpinFormError(
                f"theta0 = {theta0!s} is not the nutation angle of this motion at psi0 = {psi0!s}: the periods and the "
                f"moment ratios fix it to {math.degrees(theta):.8g}° (θ0 is not independent of P_psi, P_phi, psi0 and "
                f"I1/I3, I2/I3; Kaasalainen 2001), {math.degrees(abs(given - theta)):.3g}° away, more than "
                f"theta_tolerance = {theta_tolerance!s}. Give theta0 = {math.degrees(theta):.8g} deg, theta0=None "
                "(the branch θ0 < 90°), or check the published values.")
    attitude = euler313_to_attitude(phi, theta, psi) @ momentum_frame(lon, lat) @ _frame_matrix(frame)
    momentum = big_g * np.array([math.sin(theta) * math.sin(psi), math.sin(theta) * math.cos(psi), math.cos(theta)])
    q = _relabelling(axes)
    return _user_attitude(attitude, axes), q.T @ (momentum / moments), axes, _MODE_NAMES[code]


def tumbling_of(attitude, omega, body, frame="ecliptic", axes=None) -> dict:
    """The Pravec/Kaasalainen form of (R, ω): the fields of :class:`TumblingParameters` but ``epoch``.

    Raises :class:`SpinFormError` for a permanent rotation or the separatrix (no P_ψ, P_φ: use :func:`pole_of`).
    """
    code, _, days_psi, days_phi, _ = _summary(attitude, omega, body)
    if code in (MODE_UNIFORM, MODE_SEPARATRIX):
        what = "a permanent rotation" if code == MODE_UNIFORM else "on the separatrix"
        raise SpinFormError(f"this state is {what}: it has no finite P_psi, P_phi and no tumbling form. "
                            "Use state.pole() for a principal-axis rotator.")
    axes, moments = _circulation_axes(body, code, axes)
    lon, lat, _ = _momentum_direction(attitude, omega, body, frame)
    in_momentum_frame = _relabelling(axes) @ attitude @ _frame_matrix(frame).T @ momentum_frame(lon, lat).T
    phi, theta, psi = attitude_to_euler313(np.ascontiguousarray(in_momentum_frame))
    degrees = [math.degrees(a) for a in (lon, lat, phi % (2 * math.pi), theta, psi % (2 * math.pi))]
    hours = [p * HOUR_PER_DAY * u.hour for p in (days_psi, days_phi)]
    return dict(p_psi=hours[0], p_phi=hours[1], momentum_lon=degrees[0] * u.deg, momentum_lat=degrees[1] * u.deg,
                phi0=degrees[2] * u.deg, theta0=degrees[3] * u.deg, psi0=degrees[4] * u.deg,
                i1_i3=float(moments[0] / moments[2]), i2_i3=float(moments[1] / moments[2]), mode=_MODE_NAMES[code],
                frame=frame, axes=axes)
