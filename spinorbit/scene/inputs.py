"""What a scene is given, checked: the orbit, the perturbers, the times, the tolerance and the options.

:class:`FixedPerturber` and :class:`EphemerisPerturber` (user point masses), and the checks
:class:`~spinorbit.scene.Scene` runs on its arguments, each raising :class:`SceneError` with what was
expected and what arrived. The body's mass in the orbit model and the figure's size are read here too
(:func:`gm_in_orbit_model`, :func:`moments_per_mass`): the back-reaction bound needs them.
:class:`Orbit` (where the body's orbit and its perturbers' positions come from) lives in
:mod:`spinorbit.scene.orbit` and is re-exported here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from astropy import units as u
from astropy.time import Time

from spinorbit.core.errors import require_finite
from spinorbit.quantities import require_quantity
from spinorbit.scene.errors import SceneError
from spinorbit.scene.orbit import Orbit
from spinorbit.state import RotationState
from spinorbit.time import tdb_days

__all__ = ["INTEGRATORS", "MASS_MISMATCH", "QUANTITIES", "EphemerisPerturber", "FixedPerturber",
           "EPOCH_MATCH_TOLERANCE", "as_angle", "check_gm", "gm_in_orbit_model", "moments_per_mass", "resolve_epoch",
           "resolve_perturbers",
           "tdb_day_array", "validate_options", "validate_perturbers", "validate_state", "validate_times"]

#: Quantities a scene can ask for.
QUANTITIES = ("attitude", "omega", "periods")
#: Integrators a Scene accepts ("auto": the planner chooses between "taylor" and "quaternion").
INTEGRATORS = ("auto", "quaternion", "elements", "taylor")
#: Largest relative difference allowed between the body's mass (RigidBody.mass) and its mass in the
#: orbit model (G is known to 2e-5 and DE421's GMs come with their own rounding).
MASS_MISMATCH = 1e-2
#: Largest difference (days) between a Scene's epoch and its state's own epoch that counts as the same instant: an
#: instant on two time scales converts with ~1e-14 d of rounding (astropy's two-double Time), and a state cannot
#: be tied to a time any finer; 1 µs is far below both and far above them.
EPOCH_MATCH_TOLERANCE = 1e-6 / 86400.0
#: Units and physical types of the checks, built once: composing ``u.au**3 / u.day**2`` or reading a
#: composed unit's physical type costs ~25 µs a time, more than the rest of a perturber's check.
_AU3_PER_DAY2 = u.au**3 / u.day**2
_GM_TYPE = (u.m**3 / u.s**2).physical_type
_ANGLE = u.get_physical_type("angle")


def check_gm(kind, name, gm):
    """G·M of a user perturber in au³/day², or SceneError naming it (QuantityInputError for a bare number)."""
    require_quantity("gm", gm, _AU3_PER_DAY2, "3.986e14 * u.m**3 / u.s**2")
    if not isinstance(gm, u.Quantity) or gm.unit.physical_type != _GM_TYPE:
        raise SceneError(f"{kind} {name!r}: gm expects a Quantity in length³/time² such as 3.986e14 m3/s2; "
                         f"got {gm!r}.")
    value = gm.to_value(_AU3_PER_DAY2)
    require_finite(f"{kind} {name!r}: gm", value, "a finite G·M > 0 such as 3.986e14 m3/s2")
    if np.ndim(value) != 0 or not value > 0:
        raise SceneError(f"{kind} {name!r}: gm expects one positive G·M such as 3.986e14 m3/s2; got {gm!r}.")
    return float(value)


@dataclass(frozen=True)
class FixedPerturber:
    """A point mass at a fixed ICRF position relative to the body (a user position).

    Parameters
    ----------
    name : str
    gm : Quantity
        G·M (any unit of length³/time²).
    position : Quantity, shape (3,)
        Relative to the body's centre, ICRF axes (any length unit).
    """

    name: str
    gm: u.Quantity
    position: u.Quantity

    def __post_init__(self):
        check_gm("FixedPerturber", self.name, self.gm)
        position = self.position
        require_quantity("position", position, u.au, "[1, 0, 0] * u.au")
        if isinstance(position, u.Quantity):
            require_finite(f"FixedPerturber {self.name!r}: position", position.value, "a finite 3-vector")
        if (not isinstance(position, u.Quantity) or position.unit.physical_type != "length"
                or position.shape != (3,) or not np.all(np.isfinite(position.value)) or not np.any(position.value)):
            raise SceneError(f"FixedPerturber {self.name!r}: position expects a finite, non-zero length "
                             f"Quantity of shape (3,) such as [1, 0, 0] * u.au; got {position!r}.")

    @property
    def gm_au3_day2(self):
        return check_gm("FixedPerturber", self.name, self.gm)

    @property
    def position_au(self):
        return self.position.to_value(u.au).astype(float)


@dataclass(frozen=True)
class EphemerisPerturber:
    """A point mass moving on a user ephemeris (like :meth:`Orbit.ephemeris`, for a perturber).

    It goes through the planner like a DE421 body: surveyed, bounded, dropped or kept, and sampled
    onto the same adaptive Hermite grid (:func:`spinorbit.coupling.sampling.sample_states`).

    Parameters
    ----------
    name : str
    gm : Quantity
        G·M (any unit of length³/time²).
    function : callable
        ``function(days) -> (positions (n, 3) au, velocities (n, 3) au/day)`` at TDB days since J2000
        (vectorised over ``days``), ICRF axes.
    relative : bool
        True: the states are relative to the rotating body's centre (no orbit of the body needed);
        False (default): barycentric, and the scene's ``orbit`` gives the body's.
    """

    name: str
    gm: u.Quantity
    function: object
    relative: bool = False

    def __post_init__(self):
        check_gm("EphemerisPerturber", self.name, self.gm)
        if not callable(self.function):
            raise SceneError(f"EphemerisPerturber {self.name!r}: function expects a callable days -> (positions, "
                             f"velocities); got {type(self.function).__name__}.")
        if not isinstance(self.relative, bool):
            raise SceneError(f"EphemerisPerturber {self.name!r}: relative expects True or False; got {self.relative!r}.")

    @property
    def gm_au3_day2(self):
        return check_gm("EphemerisPerturber", self.name, self.gm)

    def states(self, days):
        """(n, 6) positions and velocities at ``days``; SceneError if the function returns other shapes."""
        try:
            positions, velocities = (np.asarray(a, dtype=float) for a in self.function(days))
        except (TypeError, ValueError) as error:
            raise SceneError(f"EphemerisPerturber {self.name!r}: function expects to return (positions, velocities) "
                             f"as arrays of shape ({days.size}, 3); calling it failed: {error}") from None
        if positions.shape != (days.size, 3) or velocities.shape != (days.size, 3):
            raise SceneError(f"EphemerisPerturber {self.name!r}: function expects to return (positions, velocities) "
                             f"of shape ({days.size}, 3) each for {days.size} times; got {positions.shape} and "
                             f"{velocities.shape}.")
        if not (np.all(np.isfinite(positions)) and np.all(np.isfinite(velocities))):
            raise SceneError(f"EphemerisPerturber {self.name!r}: function returned NaN or inf.")
        return np.concatenate([positions, velocities], axis=1)


def as_angle(tolerance):
    """An attitude tolerance (angle Quantity) in rad, between 1e-12 and 0.1 rad, or SceneError (QuantityInputError
    for a bare number)."""
    require_quantity("tolerance", tolerance, u.rad, "1 * u.arcsec")
    if not isinstance(tolerance, u.Quantity) or tolerance.unit.physical_type != _ANGLE or not tolerance.isscalar:
        raise SceneError(f"tolerance expects an angle Quantity such as 1 * u.arcsec or 1e-6 * u.rad; got {tolerance!r}.")
    value = float(tolerance.to_value(u.rad))
    if not (math.isfinite(value) and 1e-12 <= value <= 0.1):
        raise SceneError(f"tolerance expects an attitude angle between 1e-12 rad and 0.1 rad (2e-7 to 2e4 arcsec); "
                         f"got {tolerance!r}.")
    return value


def tdb_day_array(time):
    """TDB days since J2000 of a Time (scalar or array) as a 1-d float array."""
    whole, rest = tdb_days(time)
    if isinstance(whole, float):  # a scalar Time (tdb_days gives Python floats): the same sum, no array casts
        return np.array([whole + rest])
    return np.atleast_1d(np.asarray(whole, dtype=float) + np.asarray(rest, dtype=float))


def resolve_epoch(state, epoch, times):
    """The epoch of a Scene: ``epoch``, or the state's own (:attr:`RotationState.epoch`) when it has one.

    Raises SceneError when neither gives one, when ``times`` is missing, or when both are given and are not the
    same instant (within :data:`EPOCH_MATCH_TOLERANCE`): the state belongs to its epoch, and a Scene that moved
    it to another would describe a different motion.
    """
    own = getattr(state, "epoch", None)
    if times is None:
        raise SceneError("times expects the output times (an astropy Time); got none. Scene(state, times=...) when "
                         "the state carries its epoch, Scene(state, epoch, times) otherwise.")
    if epoch is None:
        if own is None:
            raise SceneError("epoch expects the time of the state (an astropy Time): this state carries none (states "
                             "made by from_pole, from_tumbling or with_epoch do). Give Scene(state, epoch, times).")
        return own
    if own is not None and isinstance(epoch, Time) and epoch.isscalar:
        gap = float(np.sum(np.subtract(tdb_days(epoch), tdb_days(own))))
        if not abs(gap) <= EPOCH_MATCH_TOLERANCE:
            raise SceneError(
                f"epoch {epoch.tdb.isot} TDB is not the state's own epoch {own.tdb.isot} TDB ({gap:+.9g} d apart): the "
                "state belongs to its epoch. Leave epoch out (Scene(state, times=...)), or give the state at that "
                "epoch (state.with_epoch(epoch) if its attitude and spin are meant for it).")
    return epoch


def validate_times(epoch, times, either_side=False):
    """(epoch_day, output_days, end_only) of a scalar epoch and output times strictly increasing after it
    (or, with ``either_side``, on either side of it: :mod:`spinorbit.scene.epochs`)."""
    if not isinstance(epoch, Time) or not epoch.isscalar:
        raise SceneError(f"epoch expects a scalar astropy Time; got {epoch!r}.")
    if not isinstance(times, Time):
        raise SceneError(f"times expects an astropy Time (scalar for the end only, or an array); got "
                         f"{type(times).__name__}.")
    end_only = times.isscalar or times.size == 1
    epoch_day = float(tdb_day_array(epoch)[0])
    output_days = tdb_day_array(times)
    if output_days.size > 1 and not np.all(np.diff(output_days) > 0):  # one time is increasing (np.diff: ~4 µs)
        raise SceneError("times expects strictly increasing output times.")
    if not np.all(np.isfinite(output_days)):
        raise SceneError("times expects finite output times.")
    if not either_side and not output_days[0] > epoch_day:
        raise SceneError(f"times expects output times after the epoch; the first is "
                         f"{output_days[0] - epoch_day:+.6g} d from it. Give later times or an earlier epoch.")
    return epoch_day, output_days, end_only


def validate_options(tolerance, quantities, integrator, sample_tolerance):
    """(tolerance_rad, quantities) after checking the tolerance, the quantities, the integrator and the sample tolerance."""
    tolerance_rad = as_angle(tolerance)
    unknown = [q for q in quantities if q not in QUANTITIES]
    if unknown or not quantities:
        raise SceneError(f"quantities expects some of {QUANTITIES}; got {tuple(quantities)!r}.")
    if integrator not in INTEGRATORS:
        raise SceneError(f"integrator expects one of {INTEGRATORS}; got {integrator!r}.")
    if not (isinstance(sample_tolerance, float) and 1e-14 <= sample_tolerance < 1e-2):
        raise SceneError(f"sample_tolerance expects a float in [1e-14, 1e-2); got {sample_tolerance!r}.")
    return tolerance_rad, tuple(quantities)


def validate_perturbers(perturbers, orbit):
    """(named, fixed, moving): the resolved body names, the FixedPerturbers and the EphemerisPerturbers.

    Raises SceneError for an orbit that is not an :class:`Orbit`, perturbers of another kind, perturbers
    that need the body's orbit without one, the rotating body among them, or a body listed twice.
    """
    if orbit is not None and not isinstance(orbit, Orbit):
        raise SceneError(f"orbit expects a spinorbit.scene.Orbit (Orbit.de421, Orbit.ephemeris, Orbit.rebound); "
                         f"got {type(orbit).__name__}.")
    if isinstance(perturbers, str):  # iterating it would read 'sun' as the bodies 's', 'u', 'n'
        raise SceneError(f"perturbers expects a sequence of body names such as ('sun', 'earth'); got the string "
                         f"{perturbers!r}. Write a sequence, even of one name: ({perturbers!r},).")
    fixed = tuple(p for p in perturbers if isinstance(p, FixedPerturber))
    moving = tuple(p for p in perturbers if isinstance(p, EphemerisPerturber))
    named = [p for p in perturbers if not isinstance(p, (FixedPerturber, EphemerisPerturber))]
    bad = [p for p in named if not isinstance(p, str)]
    if bad:
        raise SceneError(f"perturbers expects body names (str), FixedPerturber or EphemerisPerturber; got "
                         f"{bad[0]!r}.")
    barycentric = [p.name for p in moving if not p.relative]
    if barycentric and orbit is None:
        raise SceneError(f"perturbers {barycentric} are barycentric EphemerisPerturbers and need the body's orbit: "
                         "give orbit=Orbit.de421(...), Orbit.ephemeris(...) or Orbit.rebound(...), or "
                         "relative=True.")
    if named and orbit is None:
        raise SceneError(f"perturbers {named} need the body's orbit: give orbit=Orbit.de421(...), "
                         "Orbit.ephemeris(...) or Orbit.rebound(...).")
    named = tuple(resolve_perturbers(orbit, named))
    everyone = [*named, *(p.name for p in fixed), *(p.name for p in moving)]
    if len(set(everyone)) != len(everyone):
        raise SceneError(f"perturbers lists a body twice: {everyone}.")
    return named, fixed, moving


def resolve_perturbers(orbit, names):
    """The perturbers' names as the orbit model knows them (REBOUND particle names, DE421 bodies)."""
    if orbit is not None and orbit.kind == "rebound":
        from spinorbit.coupling.rebound import MissingBodyError, body_index

        sim = orbit.simulation
        try:
            return [sim.particles[body_index(sim, n)].name.lower() for n in names]
        except MissingBodyError as error:
            raise SceneError(f"perturbers: {error}") from None
    from spinorbit.ephemeris import resolve_body

    resolved = [resolve_body(n) for n in names]  # UnknownBodyError names the known bodies
    if orbit is not None and orbit.name in resolved:
        raise SceneError(f"perturbers includes the rotating body itself ({orbit.name!r}).")
    return resolved


def gm_in_orbit_model(orbit):
    """The body's G·M (au³/day²) in the orbit model: 0 for a test particle or a given ephemeris."""
    if orbit is None or orbit.kind in ("ephemeris", "kepler"):
        return 0.0
    if orbit.kind == "rebound":
        from spinorbit.coupling.rebound import body_index

        sim = orbit.simulation
        return float(sim.particles[body_index(sim, orbit.name)].m * sim.G)
    from spinorbit.ephemeris import de421_constants

    return float(de421_constants().gm[orbit.name])


def moments_per_mass(body, orbit):
    """(A, B, C)/M in au² when ``body`` has moments in kg m² and a mass, else None.

    The back-reaction needs the figure's absolute size; moment *ratios* do not give it. The mass
    must agree with the body's mass in the orbit model (to :data:`MASS_MISMATCH`).
    """
    from astropy import constants

    if body.mass is None or body.moment_unit.physical_type != "moment of inertia":
        return None
    per_mass = (np.array(body.principal_moments) * body.moment_unit / body.mass).to_value(u.au**2)
    model = gm_in_orbit_model(orbit)
    given = float((constants.G * body.mass).to_value(_AU3_PER_DAY2))
    if model > 0.0 and abs(given / model - 1.0) > MASS_MISMATCH:
        raise SceneError(
            f"the body's mass {body.mass:.6g} (G·M = {given:.6g} au³/day²) differs from its mass in the orbit model "
            f"(G·M = {model:.6g} au³/day², '{orbit.name}') by {abs(given / model - 1.0):.2%}; expected them "
            f"to agree within {MASS_MISMATCH:.0%}. Give RigidBody the orbit model's mass (or fix the particle's m).")
    return tuple(float(v) for v in per_mass)


def validate_state(state):
    """``state`` itself, or SceneError when it is not a :class:`~spinorbit.RotationState`."""
    if not isinstance(state, RotationState):
        raise SceneError(f"state expects a spinorbit.RotationState; got {type(state).__name__}.")
    return state
