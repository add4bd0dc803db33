"""The Moon's physical libration, integrated with the orbits from DE421 and compared with DE421.

Initial state at an epoch (default J2000): positions and velocities of the Sun, planets, Earth and
Moon from DE421 (``simulation_from_de421``), the mantle attitude and angular velocity from DE421's
libration angles (``moon_orientation``). Orbits: point masses + EIH 1PN + Earth J2 (the adapter's
compiled force), plus the lunar figure's back-reaction (fully coupled). Figure (``docs/coupling.md``):

- degree 2 from the moments: (A, B, C)/MR² from DE421's LBET = (C−A)/B, LGAM = (B−A)/C and
  C/MR² = 4·C22M/LGAM (``DE421Constants.moon_moments_over_mr2``); M = GM_Moon/G, R = AM;
- degrees 3 and 4 from DE421's unnormalised J3M, C31M…S33M, J4M, C41M…S44M (C_n0 = −J_n);
- model ``"rigid"``: the whole Moon rotates as one body (the published total moments);
  model ``"core-corrected"``: DE421's fluid core does not follow the mantle, so the mantle's
  Euler equations use I − C_core·1, C_core = IFAC·C (core taken as spherical: its oblateness
  COBLAT = 3.8e-4 and the core–mantle friction KVC are left out). Removing a spherical part leaves
  the degree-2 field (MacCullagh) unchanged, so U and the moments stay consistent.

Units: au (DE421), TDB days since J2000, masses GM/G ("AU", "day", "Msun"), ω in rad/day.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from astropy.time import Time

from ..core.gravity_field import make_body
from ..core.rotations import attitude_to_euler313, quat_to_attitude_many
from ..ephemeris import de421_constants, moon_libration_angles_raw, moon_orientation_raw
from ..time import tdb_day_and_fraction
from .chunked_run import integrate_to_outputs
from .rebound_adapter import DEFAULT_BODIES, simulation_from_de421
from .rigid_body import CoupledRigidBody

__all__ = ["MOON_MODELS", "moon_figure", "moon_at_de421", "LibrationComparison", "compare_with_de421",
           "ARCSEC_PER_RAD", "DEFAULT_TOLERANCE"]

MOON_MODELS = ("rigid", "core-corrected")
ARCSEC_PER_RAD = 180.0 * 3600.0 / np.pi
#: BS tolerance (eps_abs = eps_rel) for the lunar runs: the shared note measured 1e-13 for
#: ephemeris-grade orbits; the state is O(1) (q, ω ≈ 0.23 rad/day, positions ≲ 40 au).
DEFAULT_TOLERANCE = 1e-13
#: Perturbers that see the lunar field's degrees 3–4 by default. For the Sun the degree-3 torque is
#: (R_Moon/1 au) ~ 1e-5 of its degree-2 torque; for the planets less. Measured: limiting degrees 3–4
#: to Earth changes the 1-year comparison by < 0.001″ and halves the wall time (docs/coupling.md).
FULL_FIELD_PERTURBERS = ("Earth",)


def moon_figure(moon_mass: float, model: str = "rigid", degree: int = 4) -> np.ndarray:
    """The Moon's figure array in ("AU", "day", "Msun") units from the DE421 constants.

    Parameters
    ----------
    moon_mass : float
        GM_Moon/G in simulation mass units (the REBOUND particle's ``m``).
    model : {"rigid", "core-corrected"}
        See the module docstring.
    degree : {2, 3, 4}
        Highest degree of the lunar field.

    Returns
    -------
    ndarray
        ``gravity_field.make_body`` array: moments in Msun·au², reference radius AM in au.
    """
    if model not in MOON_MODELS:
        raise ValueError(f"model: expected one of {MOON_MODELS}, got {model!r}.")
    if degree not in (2, 3, 4):
        raise ValueError(f"degree: expected 2, 3 or 4, got {degree!r}.")
    constants = de421_constants()
    radius = constants.moon_radius_km / constants.au_km
    moments = np.array(constants.moon_moments_over_mr2) * moon_mass * radius**2
    if model == "core-corrected":
        moments = moments - constants.moon_core_over_total_moment * moments[2]
    c = np.zeros((5, 5))
    s = np.zeros((5, 5))
    if degree >= 3:
        c[3, 0] = -constants.moon_j3
        for m in (1, 2, 3):
            c[3, m] = constants.moon_degree3[f"C3{m}M"]
            s[3, m] = constants.moon_degree3[f"S3{m}M"]
    if degree >= 4:
        c[4, 0] = -constants.moon_j4
        for m in (1, 2, 3, 4):
            c[4, m] = constants.moon_degree4[f"C4{m}M"]
            s[4, m] = constants.moon_degree4[f"S4{m}M"]
    return make_body(moments, mass=moon_mass, reference_radius=radius, stokes_c=c, stokes_s=s)


def moon_at_de421(epoch=None, model: str = "rigid", degree: int = 4, coupled: bool = True,
                  bodies=DEFAULT_BODIES, perturbers=None, tolerance: float = DEFAULT_TOLERANCE,
                  full_field_perturbers=FULL_FIELD_PERTURBERS):
    """A DE421 simulation with the Moon's rotation attached (BS, EIH + Earth J2 on the orbits).

    Parameters
    ----------
    epoch : astropy.time.Time, optional
        Start (default J2000.0 TDB).
    model, degree
        As in :func:`moon_figure`.
    coupled : bool
        Fully coupled (default) or one-way.
    bodies : sequence of str
        Bodies in the simulation (``simulation_from_de421``).
    perturbers : sequence of str, optional
        Particles torquing the lunar figure; default all others (Sun, planets, Earth).
    tolerance : float
        BS eps_abs = eps_rel.
    full_field_perturbers : sequence of str or None
        Perturbers that see degrees 3..``degree``; the others see degree 2 only. None: all see the
        full field.

    Returns
    -------
    CoupledRigidBody
    """
    epoch = Time(2451545.0, format="jd", scale="tdb") if epoch is None else epoch
    sim = simulation_from_de421(epoch, bodies, integrator="bs")
    sim.integrator.eps_abs = tolerance
    sim.integrator.eps_rel = tolerance
    day, fraction = tdb_day_and_fraction(epoch)
    quaternion, omega = moon_orientation_raw(day, fraction)
    moon = sim.particles["Moon"]
    figure = moon_figure(moon.m, model, degree)
    state = np.concatenate([quaternion, omega])
    if perturbers is None:
        perturbers = [p.name for p in sim.particles if p.name != "Moon"]
    degrees = None
    if full_field_perturbers is not None:
        wanted = {name.capitalize() for name in full_field_perturbers}
        degrees = [degree if name.capitalize() in wanted else 2 for name in perturbers]
    return CoupledRigidBody(sim, "Moon", figure, state, perturbers=perturbers, coupled=coupled,
                            earth_j2=True, gr=True, perturber_degrees=degrees)


@dataclass
class LibrationComparison:
    """Model vs DE421 at the output times.

    Attributes
    ----------
    times : ndarray, TDB days since J2000
    attitude_difference_arcsec : ndarray
        Rotation angle between the model's and DE421's mantle frames (arcsec).
    body_difference_arcsec : ndarray, shape (n, 3)
        The same difference as a small rotation vector on the DE421 mantle axes (arcsec).
    angles_model, angles_de421 : ndarray, shape (n, 3)
        3-1-3 libration angles (φ, θ, ψ), ICRF → mantle (rad; ψ unwrapped).
    wall_seconds : float
        Wall time of the integration only.
    """

    times: np.ndarray
    attitude_difference_arcsec: np.ndarray
    body_difference_arcsec: np.ndarray
    angles_model: np.ndarray
    angles_de421: np.ndarray
    wall_seconds: float

    @property
    def max_difference_arcsec(self) -> float:
        return float(np.max(self.attitude_difference_arcsec))


def _euler313_many(quaternions):
    attitudes = quat_to_attitude_many(np.ascontiguousarray(quaternions))
    angles = np.array([attitude_to_euler313(r) for r in attitudes])
    angles[:, 2] = np.unwrap(angles[:, 2])
    angles[:, 0] = np.unwrap(angles[:, 0])
    return angles


def compare_with_de421(moon: CoupledRigidBody, span_days: float, step_days: float = 1.0,
                       progress=None, schedule=None, resume=None, settings=None) -> LibrationComparison:
    """Integrate ``moon`` over ``span_days`` and compare its attitude with DE421 every ``step_days``.

    Parameters
    ----------
    moon : CoupledRigidBody
        From :func:`moon_at_de421` (its ``sim.t`` is the start; when resuming, build it with the
        same arguments: the checkpoint then replaces its state).
    span_days, step_days : float
        Span and output spacing (days, TDB).
    progress : callable, optional
        Called with the number of output times done.
    schedule, resume, settings
        Checkpoints (:func:`spinorbit.coupling.chunked_run.integrate_to_outputs`): each output time
        is a chunk; an interrupted run resumed from its checkpoint ends with the same bits.

    Returns
    -------
    LibrationComparison
    """
    start = moon.sim.t
    count = int(np.floor(span_days / step_days + 1e-9)) + 1
    times = start + step_days * np.arange(count)
    _, quaternions, wall = integrate_to_outputs(moon, times, lambda body: body.quaternion, 4, schedule=schedule,
                                                resume=resume, settings=settings, progress=progress)
    days = np.round(times)
    reference, _ = moon_orientation_raw(days, times - days)
    # δq = conj(q_DE421) ⊗ q_model: the model frame seen from the DE421 frame (mantle axes).
    w = np.einsum("ij,ij->i", reference, quaternions)
    vec = (reference[:, :1] * quaternions[:, 1:] - quaternions[:, :1] * reference[:, 1:]
           - np.cross(reference[:, 1:], quaternions[:, 1:]))
    angle = 2.0 * np.arctan2(np.linalg.norm(vec, axis=1), np.abs(w))
    body_vector = 2.0 * vec * np.sign(w)[:, None]
    angles_de421 = moon_libration_angles_raw(days, times - days)[0]
    return LibrationComparison(
        times=times,
        attitude_difference_arcsec=angle * ARCSEC_PER_RAD,
        body_difference_arcsec=body_vector * ARCSEC_PER_RAD,
        angles_model=_euler313_many(quaternions),
        angles_de421=angles_de421,
        wall_seconds=wall,
    )
