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

- model ``"de421"`` (:func:`compare_interior_with_de421`): DE421's own lunar rotation model —
  mantle with tidal and rotational distortion (k2M, TAUM), fluid core with its own angular velocity
  (IFAC, COBLAT, KVC), Earth J2 acting on the lunar figure — driven one-way by DE421's orbits and
  started from DE421's published initial conditions (JDEPOC; ``spinorbit.core.model.lunar_interior``).

Units: au (DE421), TDB days since J2000, masses GM/G ("AU", "day", "Msun"), ω in rad/day.

Past the size rule (docs/architecture.md) as one concept: the three Moon models, each run and
compared with DE421 by one entry point (:func:`compare_model_with_de421`) that the CLI, the
examples, the benchmarks and the Moon table share; the route pieces live elsewhere (orbits:
``coupling.rebound``, outputs: ``long_run`` and ``dense_output``, sampling: ``sampling``).
"""

from __future__ import annotations

import functools
import time as _time
from dataclasses import dataclass

import numpy as np
from astropy.time import Time

from spinorbit.core.dynamics.equations import MODEL_PERTURBERS
from spinorbit.core.model.gravity_field import make_body
from spinorbit.core.integrators.quaternion import integrate_quaternion
from spinorbit.core.model.lunar_interior import make_interior_block
from spinorbit.core.model.perturbers import pack_perturbers
from spinorbit.core.math.rotations import (
    quat_to_attitude,
    quat_to_attitude_many,
)
from spinorbit.ephemeris import (
    DE421_SPAN_JD_TDB,
    EphemerisRangeError,
    de421_constants,
    earth_from_moon_au,
    moon_libration_angles_raw,
    moon_orientation_raw,
)
from spinorbit.lunar_librations import euler313_from_attitudes, physical_librations
from spinorbit.time import J2000_JD_TDB, tdb_day_and_fraction, time_from_tdb_days
from spinorbit.coupling.sampling import de421_orbit, remembering, sample_from_ephemeris, sample_relative_states
from spinorbit.coupling.dense_output import quaternion_product, rotation_at
from spinorbit.coupling.lunar_core import cached_core_state, core_key

__all__ = [
    "ARCSEC_PER_RAD",
    "DEFAULT_TOLERANCE",
    "MOON_MODELS",
    "RIGID_MODELS",
    "LibrationComparison",
    "MIN_STEP_DAYS",
    "OutputStepError",
    "check_run",
    "comparison_table",
    "moon_librations",
    "compare_interior_with_de421",
    "compare_model_with_de421",
    "compare_with_de421",
    "core_angular_velocity",
    "interior_model",
    "moon_at_de421",
    "moon_figure",
]

#: Models of the rigid route (REBOUND, :func:`moon_at_de421`).
RIGID_MODELS = ("rigid", "core-corrected")
#: Every model :func:`compare_model_with_de421` runs; "de421" is the mantle-and-core model.
MOON_MODELS = ("de421",) + RIGID_MODELS
ARCSEC_PER_RAD = 180.0 * 3600.0 / np.pi
#: BS tolerance (eps_abs = eps_rel) for the lunar runs: ephemeris-grade orbits at an O(1) state
#: (q, ω ≈ 0.23 rad/day, positions ≲ 40 au); the tolerance scan is in docs/coupling.md.
DEFAULT_TOLERANCE = 1e-13
#: Perturbers that see the lunar field's degrees 3–4 by default; for the Sun the degree-3 torque is
#: (R_Moon/1 au) ~ 1e-5 of its degree-2 torque, for the planets less (measurements: docs/coupling.md).
FULL_FIELD_PERTURBERS = ("Earth",)
#: Margin kept from both ends of DE421's span (days): the "de421" model samples DE421's orbits one
#: day beyond its run on each side (the tidal delay τ_M = 0.096 d looks back; the interpolation
#: grids need a node past the end).
RANGE_MARGIN_DAYS = 1.0
#: Finest output spacing (one minute). Every output time stops REBOUND's BS (natural step ≈ 5 d on
#: the rigid route); over a minute DE421's librations and the models' differences from them
#: (≥ 1e-4″) change by < 1e-5″, so a finer spacing multiplies cost and rows and resolves nothing.
MIN_STEP_DAYS = 1.0 / 1440.0


class OutputStepError(ValueError):
    """An output spacing the Moon models do not support (not positive, finer than a minute, or longer
    than the span)."""


def _iso_tdb(day: float) -> str:
    """The date as ISO text, or as a Julian date where ERFA has no calendar date for it (far past 9999)."""
    if not -2.0e6 < day < 2.9e6:  # about the years -3500 .. 9900, well inside ERFA's calendar
        return f"JD {day + J2000_JD_TDB:.6g}"
    return time_from_tdb_days(day).tdb.iso


def check_run(model: str, start_day: float, span_days: float, step_days: float, names=None) -> None:
    """Check a Moon run before any work; raise one specific error whose message says what to do.

    Parameters
    ----------
    model : str
        One of :data:`MOON_MODELS`.
    start_day, span_days, step_days : float
        Start (TDB days since J2000), span and output spacing (days).
    names : dict, optional
        The caller's names of the arguments, by "model", "start", "span", "step" (the command line's
        ``--span``), so that its messages are written with them (default: the names above).

    Raises
    ------
    ValueError
        Unknown model, or a span that is not a positive finite number of days.
    EphemerisRangeError
        A start outside DE421's span, or a run that ends past it (both ends are compared with DE421).
    OutputStepError
        A spacing that is not positive, finer than :data:`MIN_STEP_DAYS` or longer than the span.
    """
    name = {key: key for key in ("model", "start", "span", "step")} | dict(names or {})
    if model not in MOON_MODELS:
        raise ValueError(f"{name['model']}: expected one of {MOON_MODELS}, got {model!r}.")
    first = DE421_SPAN_JD_TDB[0] - J2000_JD_TDB + RANGE_MARGIN_DAYS
    last = DE421_SPAN_JD_TDB[1] - J2000_JD_TDB - RANGE_MARGIN_DAYS
    if not (np.isfinite(start_day) and first <= start_day <= last):
        shown = _iso_tdb(start_day) if np.isfinite(start_day) else repr(start_day)
        raise EphemerisRangeError(
            f"{name['start']}: expected a date between {_iso_tdb(first)} and {_iso_tdb(last)} TDB (DE421's span less "
            f"{RANGE_MARGIN_DAYS:g} d at each end), got {shown}; choose a start inside it.")
    if not (np.isfinite(span_days) and span_days > 0.0):
        raise ValueError(f"{name['span']}: expected a positive number of days, got {float(span_days)!r} d.")
    if start_day + span_days > last:
        raise EphemerisRangeError(
            f"{name['span']}: a run of {span_days:g} d from {_iso_tdb(start_day)} TDB ends at {_iso_tdb(start_day + span_days)}, "
            f"past DE421's last usable date {_iso_tdb(last)} TDB; shorten the span to at most "
            f"{last - start_day:.1f} d or start earlier.")
    if not (np.isfinite(step_days) and MIN_STEP_DAYS * (1.0 - 1e-9) <= step_days <= span_days):
        raise OutputStepError(
            f"{name['step']}: expected an output spacing from 1 min ({MIN_STEP_DAYS:.6g} d) up to the span "
            f"({span_days:g} d), got {float(step_days)!r} d; the models resolve nothing finer than a minute.")


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
    if model not in RIGID_MODELS:
        raise ValueError(f"model: expected one of {RIGID_MODELS}, got {model!r}.")
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
                  bodies=None, perturbers=None, tolerance: float = DEFAULT_TOLERANCE,
                  full_field_perturbers=FULL_FIELD_PERTURBERS, spin_offset=None):
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
        Bodies in the simulation (``simulation_from_de421``; default its ``DEFAULT_BODIES``).
    perturbers : sequence of str, optional
        Particles torquing the lunar figure; default all others (Sun, planets, Earth).
    tolerance : float
        BS eps_abs = eps_rel.
    full_field_perturbers : sequence of str or None
        Perturbers that see degrees 3..``degree``; the others see degree 2 only. None: all see the
        full field.
    spin_offset : array_like, shape (3,), optional
        Added to DE421's mantle angular velocity (rad/day, mantle axes): a small kick that excites
        the free modes (:mod:`spinorbit.coupling.lunar_free_modes`).

    Returns
    -------
    CoupledRigidBody
    """
    # REBOUND and the coupled body load here, not with this module: the "de421" model needs neither.
    from spinorbit.coupling.rebound import DEFAULT_BODIES, simulation_from_de421
    from spinorbit.coupling.rigid_body import CoupledRigidBody

    epoch = Time(2451545.0, format="jd", scale="tdb") if epoch is None else epoch
    sim = simulation_from_de421(epoch, DEFAULT_BODIES if bodies is None else bodies, integrator="bs")
    sim.integrator.eps_abs = tolerance
    sim.integrator.eps_rel = tolerance
    day, fraction = tdb_day_and_fraction(epoch)
    quaternion, omega = moon_orientation_raw(day, fraction)
    moon = sim.particles["Moon"]
    figure = moon_figure(moon.m, model, degree)
    if spin_offset is not None:
        omega = omega + np.asarray(spin_offset, dtype=float)
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
        3-1-3 libration angles (φ, θ, ψ), ICRF → mantle (rad). DE421's as its series give them (ψ
        grows by 2π a sidereal month); the model's on the same branch, each angle within π of
        DE421's, so ``angles_model - angles_de421`` is the small difference.
    librations_model, librations_de421 : ndarray, shape (n, 3)
        Physical librations (τ, ρ, Iσ) in arcsec (:mod:`spinorbit.lunar_librations`).
    wall_seconds : float
        Wall time of the integration only.
    sampling_seconds : float
        Wall time spent sampling DE421's orbits before the integration ("de421" model; 0 otherwise).
    """

    times: np.ndarray
    attitude_difference_arcsec: np.ndarray
    body_difference_arcsec: np.ndarray
    angles_model: np.ndarray
    angles_de421: np.ndarray
    librations_model: np.ndarray
    librations_de421: np.ndarray
    wall_seconds: float
    sampling_seconds: float = 0.0

    @property
    def max_difference_arcsec(self) -> float:
        return float(np.max(self.attitude_difference_arcsec))


def _euler313_near(attitudes, reference_angles):
    """3-1-3 angles of ``attitudes`` on the branch of ``reference_angles`` (each within π of it)."""
    angles = euler313_from_attitudes(attitudes)
    return reference_angles + np.remainder(angles - reference_angles + np.pi, 2.0 * np.pi) - np.pi


def compare_with_de421(moon, span_days: float, step_days: float = 1.0,
                       progress=None, schedule=None, resume=None, settings=None,
                       cut_steps: bool = False) -> LibrationComparison:
    """Integrate ``moon`` over ``span_days`` and compare its attitude with DE421 every ``step_days``.

    By default BS takes its natural steps (≈ 6 d), the outputs interpolated from the step ends
    relative to DE421's attitude (:mod:`spinorbit.coupling.dense_output`). With ``cut_steps`` or
    checkpoints (a resumed run must take the same chunks) each output time ends a chunk instead.

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
        Checkpoints (:func:`spinorbit.coupling.long_run.integrate_to_outputs`): each output time
        is a chunk; an interrupted run resumed from its checkpoint ends with the same bits.
    cut_steps : bool
        End a chunk at each output time even without checkpoints (the former, slower route).

    Returns
    -------
    LibrationComparison
    """
    from spinorbit.coupling.long_run import integrate_step_ends, integrate_to_outputs

    times = _output_times(moon.sim.t, span_days, step_days)
    if cut_steps or schedule is not None or resume is not None or times.size < 2:
        _, quaternions, wall = integrate_to_outputs(moon, times, lambda body: body.quaternion, 4, schedule=schedule,
                                                    resume=resume, settings=settings, progress=progress)
        return _comparison(times, quaternions, wall)
    node_times, node_states, wall = integrate_step_ends(moon, times[-1], times=times, progress=progress)
    quaternions, reference = rotation_at(times, node_times, node_states, _de421_orientation)
    return _comparison(times, quaternions, wall, reference=reference)


def _de421_orientation(times):
    """DE421's mantle (q, ω) at float TDB days since J2000 (two-float form for jplephem)."""
    days = np.round(times)
    return moon_orientation_raw(days, times - days)


def _output_times(start, span_days, step_days):
    count = int(np.floor(span_days / step_days + 1e-9)) + 1
    return start + step_days * np.arange(count)


def _comparison(times, quaternions, wall, reference=None):
    """The model's attitudes against DE421's at the same times (``reference``: DE421's q, if known)."""
    days = np.round(times)
    if reference is None:
        reference, _ = _de421_orientation(times)
    # δq = conj(q_DE421) ⊗ q_model: the model frame seen from the DE421 frame (mantle axes).
    delta = quaternion_product(reference * np.array([1.0, -1.0, -1.0, -1.0]), quaternions)
    w, vec = delta[:, 0], delta[:, 1:]
    angle = 2.0 * np.arctan2(np.linalg.norm(vec, axis=1), np.abs(w))
    body_vector = 2.0 * vec * np.sign(w)[:, None]
    angles_de421 = moon_libration_angles_raw(days, times - days)[0]
    attitudes = quat_to_attitude_many(np.ascontiguousarray(quaternions))
    attitudes_de421 = quat_to_attitude_many(np.ascontiguousarray(reference))
    return LibrationComparison(
        times=times,
        attitude_difference_arcsec=angle * ARCSEC_PER_RAD,
        body_difference_arcsec=body_vector * ARCSEC_PER_RAD,
        angles_model=_euler313_near(attitudes, angles_de421),
        angles_de421=angles_de421,
        librations_model=physical_librations(times, attitudes) * ARCSEC_PER_RAD,
        librations_de421=physical_librations(times, attitudes_de421) * ARCSEC_PER_RAD,
        wall_seconds=wall,
    )


# ------------------------------------------------------------------------------------------------
# DE421's own model: mantle + fluid core + tides, driven by DE421's orbits (one-way).

#: Bodies torquing the lunar figure in the "de421" model. Earth first (it raises the tide and carries
#: J2), the Sun second (it also acts on the distortion ΔI); the planets act on the undistorted figure.
#: Mercury, Uranus, Neptune: (μ/r³) below 1e-9 of the Earth's, left out.
INTERIOR_PERTURBERS = ("earth", "sun", "venus", "mars", "jupiter", "saturn")
#: Relative interpolation error of the sampled DE421 positions: tighter changes nothing at 1e-5″ and
#: the sampling is the dominant cost (measurements: docs/coupling.md).
INTERIOR_SAMPLE_TOLERANCE = 1e-9
#: Interpolation error for the Sun and the planets: their torques on the Moon are ≤ 1/180 of the
#: Earth's (μ/r³), so 1e-7 on them is ≤ 2e-9 of the total torque, the Earth's share at 1e-9.
DISTANT_SAMPLE_TOLERANCE = 1e-7
#: DOP853 local tolerance for the "de421" model; 1e-11 … 1e-13 agree to 1e-5″ over 5 years.
INTERIOR_RTOL = 1e-12
#: Lunar mean motion n (rad/day) in the rotational-distortion term: 2π per sidereal month
#: (27.321582 d). It only sets the constant part of ΔI already contained in the published moments.
LUNAR_MEAN_MOTION = 2.0 * np.pi / 27.321582


def interior_model(start_day, end_day, perturbers=INTERIOR_PERTURBERS,
                   sample_tolerance=INTERIOR_SAMPLE_TOLERANCE):
    """The dynamics model array of DE421's lunar rotation model, orbits sampled from DE421.

    Parameters
    ----------
    start_day, end_day : float
        TDB days since J2000 the run will cover (the samples start one day earlier, for the tidal
        delay τ_M).
    perturbers : sequence of str
        DE421 bodies torquing the figure; must start with ("earth", "sun").
    sample_tolerance : float
        Relative interpolation error of the perturber positions (``one_way`` module docstring).

    Returns
    -------
    ndarray
        [figure (DE421 total moments, degrees 2–4), sampled perturbers, interior block]; integrate
        a 10-component state (q, ω, ω_c) with :func:`spinorbit.core.integrators.quaternion.integrate_quaternion`.
    """
    perturbers = tuple(p.lower() for p in perturbers)
    if perturbers[:2] != ("earth", "sun"):
        raise ValueError(f"perturbers: expected the Earth and the Sun first, got {perturbers!r}.")
    constants = de421_constants()
    gravitational_constant = constants.gm["sun"]  # G in (au, day, Msun): GM_Sun / M_Sun
    # One grid per perturber: seen from the Moon the Earth's direction turns in a month, the Sun's
    # and the planets' in a year or more, so their grids are much coarser than a shared one would be.
    # The Earth (the finest grid) straight from DE421's geocentric Moon series.
    start, end = time_from_tdb_days(start_day - 1.0), time_from_tdb_days(end_day + 1.0)

    def earth(days):
        whole = np.round(days)
        position, velocity = earth_from_moon_au(whole, days - whole)
        return np.concatenate([position, velocity], axis=1)[:, None, :]

    sources = [sample_relative_states(earth, ("earth",), start, end, sample_tolerance).sources()[0]]
    distant = max(sample_tolerance, DISTANT_SAMPLE_TOLERANCE)
    moon = remembering(de421_orbit("moon"))  # the distant perturbers' pilots share their times
    sources += [sample_from_ephemeris(moon, start, end, (name,), tolerance=distant).sources()[0]
                for name in perturbers[1:]]
    figure = moon_figure(constants.gm["moon"] / gravitational_constant, "rigid", 4)
    body = np.concatenate([figure, pack_perturbers(sources, base=MODEL_PERTURBERS)])
    polar = figure[2]  # C_T, Msun·au²
    interior = make_interior_block(
        earth_row=MODEL_PERTURBERS + 1, gravitational_constant=gravitational_constant,
        love_number=constants.moon_k2, time_delay=constants.moon_tidal_delay_days,
        radius=constants.moon_radius_km / constants.au_km, mean_motion=LUNAR_MEAN_MOTION,
        core_polar_moment=constants.moon_core_over_total_moment * polar,
        core_flattening=constants.moon_core_oblateness,
        friction=constants.moon_core_friction_per_day * polar,
        earth_j2=constants.earth_j2, earth_radius=constants.earth_radius_km / constants.au_km,
        distortion_rows=2)
    return np.concatenate([body, interior])


def _epoch_day():
    return de421_constants().moon_epoch_jd_tdb - J2000_JD_TDB


def _epoch_state():
    """DE421's initial conditions at JDEPOC: (q, ω_mantle, ω_core on mantle axes)."""
    constants = de421_constants()
    epoch = _epoch_day()
    whole = np.round(epoch)
    quaternion, _ = moon_orientation_raw(whole, epoch - whole)
    return np.concatenate([quaternion, constants.moon_omega_at_epoch, constants.core_omega_at_epoch])


@functools.lru_cache(maxsize=8)
def core_angular_velocity(day: float) -> tuple:
    """The fluid core's angular velocity on DE421's mantle axes at ``day`` (rad/day).

    DE421 publishes it at JDEPOC (1969-06-28, header OMGCX…OMGCZ) only; elsewhere it is
    :func:`carry_core_angular_velocity`, computed once per date (:mod:`spinorbit.coupling.lunar_core`).
    """
    if day == _epoch_day():
        return tuple(_epoch_state()[7:])
    return cached_core_state(core_state_key(day), lambda: carry_core_angular_velocity(day))


def core_state_key(day: float) -> dict:
    """Every input of :func:`carry_core_angular_velocity` at ``day`` (the key of its cached value)."""
    return core_key(day, rtol=INTERIOR_RTOL, perturbers=list(INTERIOR_PERTURBERS), mean_motion=LUNAR_MEAN_MOTION,
                    sample_tolerance=INTERIOR_SAMPLE_TOLERANCE, distant_sample_tolerance=DISTANT_SAMPLE_TOLERANCE)


def carry_core_angular_velocity(day: float) -> tuple:
    """The core's angular velocity at ``day``, carried by this model from DE421's mantle and core at JDEPOC
    and put on DE421's mantle axes at ``day`` (through ICRF): DE421's core to 0.001″ (rad/day; seconds)."""
    epoch = _epoch_day()
    state = _epoch_state()
    model = interior_model(min(epoch, day), max(epoch, day))
    final = integrate_quaternion(state, epoch, np.array([day]), model, rtol=INTERIOR_RTOL)[-1]
    to_icrf = quat_to_attitude(np.ascontiguousarray(final[:4])).T
    whole = np.round(day)
    reference, _ = moon_orientation_raw(whole, day - whole)
    to_reference = quat_to_attitude(np.ascontiguousarray(reference))
    return tuple(to_reference @ (to_icrf @ final[7:]))


def compare_interior_with_de421(span_days: float, step_days: float = 1.0, start_day: float = 0.0,
                                rtol: float = INTERIOR_RTOL, progress=None, spin_offset=None) -> LibrationComparison:
    """Run DE421's lunar rotation model from ``start_day`` and compare with DE421's librations.

    The mantle starts from DE421's librations at ``start_day`` (its header values at JDEPOC), the core
    from :func:`core_angular_velocity`. ``wall_seconds`` is the integration alone; sampling DE421's
    orbits is timed separately in ``sampling_seconds``.

    Parameters
    ----------
    span_days, step_days : float
        Span and comparison spacing (days, TDB).
    start_day : float
        TDB days since J2000 (default J2000.0).
    rtol : float
        DOP853 local tolerance.
    progress : callable, optional
        Called once with the number of output times when done (the run is one compiled call).
    spin_offset : array_like, shape (3,), optional
        Added to the mantle's starting angular velocity (rad/day, mantle axes), as in
        :func:`moon_at_de421`.

    Returns
    -------
    LibrationComparison
    """
    times = _output_times(float(start_day), span_days, step_days)
    whole = np.round(start_day)
    quaternion, omega = moon_orientation_raw(whole, start_day - whole)
    if spin_offset is not None:
        omega = omega + np.asarray(spin_offset, dtype=float)
    state = np.concatenate([quaternion, omega, core_angular_velocity(float(start_day))])
    begin = _time.perf_counter()
    model = interior_model(times[0], times[-1])
    sampling = _time.perf_counter() - begin
    begin = _time.perf_counter()
    states = integrate_quaternion(state, times[0], times[1:], model, rtol=rtol)
    wall = _time.perf_counter() - begin
    if progress is not None:
        progress(times.size)
    comparison = _comparison(times, np.vstack([quaternion, states[:, :4]]), wall)
    comparison.sampling_seconds = sampling
    return comparison


def compare_model_with_de421(model: str, span_days: float, step_days: float = 1.0, coupled: bool = True,
                             progress=None, schedule=None, resume=None, settings=None,
                             start_day: float = 0.0, cut_steps: bool = False) -> LibrationComparison:
    """Any of :data:`MOON_MODELS` from ``start_day`` against DE421 (the CLI's and the example's entry point).

    The input is checked first (:func:`check_run`). "de421" starts from DE421's mantle at
    ``start_day`` and the core carried there (:func:`core_angular_velocity`); the rigid models from
    DE421's attitude and rates and the orbits at ``start_day``. ``coupled`` applies to the rigid
    models (REBOUND); "de421" is always driven by DE421's orbits. ``schedule``, ``resume`` and
    ``settings`` (checkpoints, as in :func:`compare_with_de421`) and ``cut_steps`` apply to the rigid
    models only: the "de421" model runs in a few hundredths of a second per simulated year and has none.
    """
    check_run(model, float(start_day), float(span_days), float(step_days))
    if model == "de421":
        if schedule is not None or resume is not None:
            raise ValueError("checkpoints apply to the REBOUND-coupled models ('rigid', 'core-corrected'); "
                             "the 'de421' model needs none: drop schedule/resume.")
        return compare_interior_with_de421(span_days, step_days, start_day=start_day, progress=progress)
    moon = moon_at_de421(epoch=time_from_tdb_days(float(start_day)), model=model, coupled=coupled)
    return compare_with_de421(moon, span_days, step_days, progress=progress,
                              schedule=schedule, resume=resume, settings=settings, cut_steps=cut_steps)


#: One line per column of :func:`comparison_table` (also written to ``table.meta['columns']``).
TABLE_COLUMNS = {
    "time": "TDB epoch of the row",
    "phi": "model's 3-1-3 angle phi, ICRF -> mantle, R = R3(psi) R1(theta) R3(phi) (rad)",
    "theta": "model's 3-1-3 angle theta (rad)",
    "psi": "model's 3-1-3 angle psi, on DE421's branch (within pi of psi_de421) (rad)",
    "tau": "model's physical libration in longitude, phi + psi - pi - L, ecliptic of date (arcsec)",
    "rho": "model's physical libration in latitude, theta - I (arcsec)",
    "I_sigma": "model's physical libration in node, I (phi - Omega - pi) (arcsec)",
    "attitude_difference": "rotation angle from DE421's mantle frame to the model's (arcsec)",
    "difference_x": "that rotation as a small vector, component on DE421's mantle x axis (arcsec)",
    "difference_y": "component on DE421's mantle y axis (arcsec)",
    "difference_z": "component on DE421's mantle z axis (arcsec)",
}
_ANGLE_NAMES = ("phi", "theta", "psi")
_LIBRATION_NAMES = ("tau", "rho", "I_sigma")


def comparison_table(comparison: LibrationComparison, model: str, coupled: bool):
    """The Moon table of a :class:`LibrationComparison` as an astropy ``QTable`` (the one output schema).

    Columns: ``time`` (``Time``, TDB), the model's ``phi, theta, psi`` (rad) and ``tau, rho, I_sigma``
    (arcsec), DE421's values of the same six suffixed ``_de421``, then ``attitude_difference`` and
    ``difference_x/y/z`` (arcsec; :data:`TABLE_COLUMNS` says what each is). ``meta``: ``epoch``
    (ISO, TDB), ``frame`` ("ICRF"), ``model``, ``coupled``, ``spinorbit_version``, ``reference``,
    ``conventions``, ``columns``, ``wall_seconds``, ``sampling_seconds``.
    """
    import astropy.units as u
    from astropy.table import QTable

    from spinorbit import __version__
    from spinorbit.state_table import time_column  # here: it imports astropy.coordinates, a run needs neither

    columns = dict(TABLE_COLUMNS)
    for name in _ANGLE_NAMES + _LIBRATION_NAMES:
        columns[f"{name}_de421"] = f"DE421's {name}" + (" (rad)" if name in _ANGLE_NAMES else " (arcsec)")
    table = QTable(meta={
        "epoch": _iso_tdb(float(comparison.times[0])),
        "frame": "ICRF",
        "model": f"spinorbit moon, model {model}",
        "coupled": bool(coupled),
        "spinorbit_version": __version__,
        "reference": "DE421 lunar librations (de421 package via jplephem)",
        "conventions": "docs/conventions.md: Euler angles; Physical librations",
        "wall_seconds": float(comparison.wall_seconds),
        "sampling_seconds": float(comparison.sampling_seconds),
    })
    table["time"] = time_column(comparison.times)
    for suffix, angles, librations in (("", comparison.angles_model, comparison.librations_model),
                                       ("_de421", comparison.angles_de421, comparison.librations_de421)):
        for i, name in enumerate(_ANGLE_NAMES):
            table[name + suffix] = np.asarray(angles[:, i]) * u.rad
        for i, name in enumerate(_LIBRATION_NAMES):
            table[name + suffix] = librations[:, i] * u.arcsec
    table["attitude_difference"] = comparison.attitude_difference_arcsec * u.arcsec
    for i, axis in enumerate("xyz"):
        table[f"difference_{axis}"] = comparison.body_difference_arcsec[:, i] * u.arcsec
    order = ["time"] + [n + s for s in ("", "_de421") for n in _ANGLE_NAMES + _LIBRATION_NAMES]
    table = table[order + ["attitude_difference", "difference_x", "difference_y", "difference_z"]]
    table.meta["columns"] = {name: columns[name] for name in table.colnames}
    return table


def _days_of(value, name: str, default_unit=None) -> float:
    """A time span Quantity (or plain days) as float days; TypeError naming ``name`` otherwise."""
    import astropy.units as u

    if isinstance(value, u.Quantity):
        if value.unit.physical_type != "time" or not value.isscalar:
            raise TypeError(f"{name}: expected a scalar time Quantity such as 1 * u.yr, got {value!r}.")
        return float(value.to_value(u.day))
    if isinstance(value, (int, float, np.floating, np.integer)) and not isinstance(value, bool):
        return float(value)
    raise TypeError(f"{name}: expected a time Quantity (e.g. 20 * u.yr) or float days, got {type(value).__name__}.")


def moon_librations(model: str = "de421", start=None, span=365.25, step=1.0, coupled: bool = True,
                    progress=None):
    """Run one Moon model from any date in DE421's span and return the Moon table (``QTable``).

    Parameters
    ----------
    model : {"de421", "rigid", "core-corrected"}
        See the module docstring.
    start : astropy.time.Time, optional
        First row (default J2000.0 TDB); any scale convertible to TDB.
    span, step : Quantity or float
        Length of the run and output spacing (time Quantities, or float days).
    coupled : bool
        Rigid models: fully coupled (default) or one-way.
    progress : callable, optional
        Called with the number of output times done.

    Returns
    -------
    astropy.table.QTable
        :func:`comparison_table`.

    Raises
    ------
    TypeError
        ``start`` not a ``Time``; ``span``/``step`` not time Quantities or numbers.
    ValueError, EphemerisRangeError, OutputStepError
        As :func:`check_run`, before any work.
    """
    if start is None:
        start_day = 0.0
    elif isinstance(start, Time) and start.isscalar:
        day, fraction = tdb_day_and_fraction(start)
        start_day = float(day) + float(fraction)
    else:
        raise TypeError(f"start: expected a scalar astropy Time, got {type(start).__name__} ({start!r}).")
    span_days, step_days = _days_of(span, "span"), _days_of(step, "step")
    comparison = compare_model_with_de421(model, span_days, step_days, coupled=coupled, progress=progress,
                                          start_day=start_day)
    return comparison_table(comparison, model, coupled and model != "de421")
