"""A run described declaratively, planned cheapest-first within a tolerance, then carried out.

A :class:`Scene` says *what* is wanted — one rotating body's state at an epoch, the perturbers that
may torque it, where the orbits come from, the output times, the quantities and the attitude
tolerance — and :meth:`Scene.plan` decides *how*, each decision with its reason in words and numbers
(``print(scene.plan())``, like a query planner's EXPLAIN). :meth:`Scene.run` carries the plan out and
returns the results with an error estimate. The bounds and the budget are in :mod:`spinorbit.scene.planner`
and ``docs/scenes.md``.

Decisions, cheapest first:

1. **No torque above the tolerance → the exact torque-free solution** (paper eq. 12), no sampling,
   no integration.
2. **Perturbers whose torque over the span cannot move the attitude by more than their share of the
   tolerance → dropped**, with the bound that justified it.
3. **Known orbits → ephemeris**: a body DE421 carries (even when handed over as a REBOUND particle)
   and its perturbers are taken from DE421; a REBOUND (N-body) run only when the body's orbit is
   known through the simulation alone.
4. **Negligible back-reaction → one-way coupling**: the rotation does not act on the orbits. For a
   body with mass in the orbit model whose RigidBody gives moments in kg m² and its mass, the figure's
   force on the orbits is bounded through to the attitude (:func:`spinorbit.scene.planner.back_reaction_bound`);
   within the drop share of the tolerance → one-way, that number in the reason and in the error
   estimate; above it → the **coupled** route: REBOUND's BS with the rotation as a user ODE and the
   figure's back-reaction (:class:`spinorbit.coupling.rigid_body.CoupledRigidBody`, ``coupled=True``).
   The Moon on DE421's orbits needs neither: DE421 integrated its orbit with the lunar figure.
5. **Outputs only at the end → one output time**: the dense interpolant is formed for the last step alone, quantities computed once.
6. **Integrator**: the Taylor method (:mod:`spinorbit.core.integrators.taylor`, the fastest in the
   work-precision scenes of ``docs/performance.md``) while the sampled perturbers' knots, each of
   which ends a Taylor step, are at most as many as the steps the rotation needs; otherwise the
   quaternion DOP853, which steps across them (:meth:`Scene._integrator_choice`). The
   canonical-element integrator is used only when asked for and the state is away from its singular
   sets; otherwise the plan says why not.

Frames and units as in :mod:`spinorbit.coupling.one_way`: the state's attitude is relative to ICRF,
times are astropy Times (TDB inside), distances au, GM au³/day².
"""

from __future__ import annotations

import functools
import math
import time as _time
from dataclasses import dataclass, field

import numpy as np
from astropy import units as u
from astropy.table import QTable
from astropy.time import Time

from spinorbit.core.errors import SpinorbitError
from spinorbit.scene.planner import (
    ARCSEC_PER_RAD,
    DROP_SHARE,
    RTOL_RANGE,
    SURVEY_TOLERANCE,
    Decision,
    PerturberEstimate,
    Plan,
    attitude_sensitivity,
    back_reaction_bound,
    dropped_torque_bound,
    free_motion_bounds,
    initial_rtol,
    max_torque_over_a,
)
from spinorbit.state import RotationState
from spinorbit.state_table import from_principal, table_columns
from spinorbit.time import tdb_days, time_from_tdb_days

__all__ = ["QUANTITIES", "EphemerisPerturber", "FixedPerturber", "Orbit", "PlanError", "Scene", "SceneError",
           "SceneResult"]

#: Quantities a scene can ask for.
QUANTITIES = ("attitude", "omega", "periods")
#: Retries of the integration with a 100× tighter rtol when the a posteriori estimate misses its share.
MAX_RTOL_RETRIES = 2
#: Factor between the run's rtol and the check run's (error estimate = their difference).
CHECK_RTOL_FACTOR = 10.0
#: Near the singular sets of the canonical elements the planner refuses that integrator: 1 − m (or
#: 1 − μ) and sin J below this many times the element integrator's own stop thresholds.
SINGULAR_MARGIN = 100.0
#: BS eps range of the coupled route. Its error control covers the orbits too (positions ~1 au):
#: looser than 1e-10 would put the orbits' error above the one-way sampler's default 1e-10.
COUPLED_EPS_RANGE = (1e-13, 1e-10)
#: Largest relative difference allowed between the body's mass (RigidBody.mass) and its mass in the
#: orbit model (G is known to 2e-5 and DE421's GMs come with their own rounding).
MASS_MISMATCH = 1e-2
#: Integrators a Scene accepts ("auto": the planner chooses between "taylor" and "quaternion").
INTEGRATORS = ("auto", "quaternion", "elements", "taylor")
#: First Taylor tol per unit of the integration share: the Taylor method's global error was 2-60 × tol
#: in work-precision scene (a) (docs/performance.md), so share × 0.3 / 60 puts it where DOP853's first
#: rtol (share / 1000, global ≈ 300 × rtol: planner.RTOL_PER_ERROR) puts DOP853's: at ≤ 0.3 × share.
TAYLOR_TOL_PER_ERROR = 0.3 / 60.0
#: The Taylor route is taken while the sampled perturbers' knots inside the span (each one ends a
#: Taylor step: the Hermite interpolant is not smooth there) are at most this many times the steps the
#: rotation itself needs. Measured (bench_scene_skips run of 2026-12-01, "Taylor against DOP853 by
#: knots" in docs/performance.md; knots/rotation steps as the planner estimates them): the integrators
#: alone at their first tolerances, Taylor/DOP853 CPU 0.75-0.97 up to 0.4, 1.15 at 0.96, 1.7-2.1 at
#: 2.5-3.2, 5.1-12.9 at 7.5-90, the Taylor error ≥ 37× smaller throughout; whole Scene.run 0.53-0.60
#: up to 0.96 (DOP853's a posteriori check asked for its retry at rtol/100 there, the Taylor run's did
#: not), 0.71 at 2.5, 1.07-1.18 at 3.2-7.5, 3.2 at 90 (and 0.88 at 44, the DE421 Moon, whose sampling
#: dominates the run: noise, the row 'DOP853 instead of Taylor' of the same run gave 1.54 the other way).
#: 1.0 is where the integrators alone break even: conservative where DOP853 would retry, ≤ 1.15× lost
#: where it would not.
TAYLOR_KNOT_SHARE = 1.0
#: The rotation steps are counted by a Taylor run of the free motion over at most this many rotations
#: (2π/|ω|), scaled to the span: a few hundred steps, ~0.1 ms.
TAYLOR_PROBE_ROTATIONS = 20.0
#: Sample times of the run against the a priori grid (coupling.sampling.a_priori_grid) of the survey:
#: the refinement passes added 1.41× for DE421's Earth and Sun seen from the Moon (224/159 samples in
#: bench_scene_skips), 1.0-1.1× for a circular relative orbit, 1.9× on the Apophis flyby (1169/625).
SAMPLE_REFINEMENT = 1.4
#: Numbers of docs/performance.md (work_precision run of 2026-11-22), CPU at 1e-10 rad in scene (a).
WORK_PRECISION_MS = {"Taylor": 2.86, "heyoka": 3.68, "DOP853": 11.45, "elements": 74.36}


def _sharing_samples(method):
    """Share perturber samples between the steps of one plan() or run() call, and forget them after
    (a later call samples afresh: a benchmark timing a run must not find the samples of the last)."""

    @functools.wraps(method)
    def wrapper(self, *args, **kwargs):
        owned = self._cache is None
        if owned:
            self._cache = []
        try:
            return method(self, *args, **kwargs)
        finally:
            if owned:
                self._cache = None

    return wrapper


class SceneError(SpinorbitError, ValueError):
    """A scene was described with inputs of the wrong kind or inconsistent with each other."""


class PlanError(SpinorbitError, RuntimeError):
    """No plan reaches the tolerance with the routes a Scene can run (the message says which to use)."""


@dataclass(frozen=True)
class Orbit:
    """Where the rotating body's orbit (and its perturbers' positions) come from.

    Build with :meth:`de421`, :meth:`ephemeris` or :meth:`rebound`.
    """

    kind: str
    name: str
    function: object = None
    simulation: object = None

    @classmethod
    def de421(cls, name):
        """A body DE421 carries (e.g. ``"moon"``); perturbers are DE421 bodies."""
        from spinorbit.ephemeris import resolve_body

        return cls("de421", resolve_body(name))

    @classmethod
    def ephemeris(cls, function, name="body"):
        """A user ephemeris ``function(days) -> (positions (n, 3) au, velocities (n, 3) au/day)``,
        barycentric ICRF at TDB days since J2000; perturbers are DE421 bodies."""
        if not callable(function):
            raise SceneError(f"Orbit.ephemeris expects a callable days -> (positions, velocities); got "
                             f"{type(function).__name__}.")
        return cls("ephemeris", str(name), function=function)

    @classmethod
    def circular(cls, radius, name="circular"):
        """A synthetic user ephemeris: a circle of ``radius`` (length Quantity) about the barycentre in
        the ICRF xy plane, at the Keplerian rate of DE421's GM_Sun, starting on +x at J2000. For
        scenes whose geometry should be simple (tests, benchmarks, tutorials)."""
        from spinorbit.ephemeris import de421_constants

        if not isinstance(radius, u.Quantity) or radius.unit.physical_type != "length" or not radius.value > 0:
            raise SceneError(f"Orbit.circular expects a positive length Quantity such as 2.5 * u.au; got {radius!r}.")
        r = float(radius.to_value(u.au))
        n = math.sqrt(de421_constants().gm["sun"] / r**3)

        def orbit(days):
            days = np.atleast_1d(np.asarray(days, dtype=float))
            c, s, zero = np.cos(n * days), np.sin(n * days), np.zeros(days.shape)
            return r * np.stack([c, s, zero], axis=1), r * n * np.stack([-s, c, zero], axis=1)

        return cls("ephemeris", str(name), function=orbit)

    @classmethod
    def rebound(cls, simulation, particle):
        """A particle of a REBOUND simulation (("AU", "day", "Msun") units, t in TDB days since J2000,
        ICRF); perturbers are particles of the same simulation."""
        from spinorbit.coupling.rebound import body_index

        body_index(simulation, particle)  # MissingBodyError now, not after a survey
        return cls("rebound", str(particle), simulation=simulation)


def _check_gm(kind, name, gm):
    if not isinstance(gm, u.Quantity) or gm.unit.physical_type != (u.m**3 / u.s**2).physical_type:
        raise SceneError(f"{kind} {name!r}: gm expects a Quantity in length³/time² such as 3.986e14 m3/s2; "
                         f"got {gm!r}.")
    return float(gm.to_value(u.au**3 / u.day**2))


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
        _check_gm("FixedPerturber", self.name, self.gm)
        position = self.position
        if (not isinstance(position, u.Quantity) or position.unit.physical_type != "length"
                or position.shape != (3,) or not np.all(np.isfinite(position.value)) or not np.any(position.value)):
            raise SceneError(f"FixedPerturber {self.name!r}: position expects a finite, non-zero length "
                             f"Quantity of shape (3,) such as [1, 0, 0] * u.au; got {position!r}.")

    @property
    def gm_au3_day2(self):
        return _check_gm("FixedPerturber", self.name, self.gm)

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
        _check_gm("EphemerisPerturber", self.name, self.gm)
        if not callable(self.function):
            raise SceneError(f"EphemerisPerturber {self.name!r}: function expects a callable days -> (positions, "
                             f"velocities); got {type(self.function).__name__}.")
        if not isinstance(self.relative, bool):
            raise SceneError(f"EphemerisPerturber {self.name!r}: relative expects True or False; got {self.relative!r}.")

    @property
    def gm_au3_day2(self):
        return _check_gm("EphemerisPerturber", self.name, self.gm)

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


@dataclass
class SceneResult:
    """What :meth:`Scene.run` returns.

    Attributes
    ----------
    table : astropy.table.QTable
        ``time`` (Time, TDB), ``quaternion`` (scalar first, user body axes → ICRF), ``omega``
        (rad/day, user body axes), ``momentum_direction`` (ICRF); with "periods" asked: ``mode``,
        ``energy_ratio``, ``P_psi``, ``P_phi``. Only the quantities asked for are filled in beyond
        time and quaternion. Each row holds what its RotationState would give
        (:func:`spinorbit.state_table.table_columns`, all rows at once); on the torque-free route
        mode, E/E0 and the periods are constants of the motion, taken once from the initial state.
    error_estimate : Quantity
        Attitude error estimate (arcsec): the sum of ``error_parts``.
    error_parts : dict of Quantity
        ``dropped`` (bound of the perturbers the plan left out), ``integration`` (a posteriori: the run
        against one at 10× its rtol or BS eps; conservative), ``sampling`` (3ε × the kept torques'
        worst-attitude bound; 0 on the coupled route, which has no sampling), ``back_reaction`` (bound of the
        figure's force on the orbits that a one-way route leaves out).
    plan : Plan
    wall_seconds : float
        Wall time of :meth:`Scene.run` (it includes planning only when ``run`` planned itself).
    stats : dict
        Integrator and sampler statistics.

    ``tolerance_met`` says whether the error estimate stayed within the scene's tolerance: it can
    exceed it when the integration cannot reach it in double precision (rtol is tightened to 1e-13
    at most) or when the kept torques' sampling share is large over long spans.
    """

    table: QTable
    error_estimate: u.Quantity
    error_parts: dict
    plan: Plan
    wall_seconds: float
    stats: dict = field(default_factory=dict)

    @property
    def tolerance_met(self):
        """True when the error estimate is within the plan's tolerance."""
        return bool(self.error_estimate.to_value(u.rad) <= self.plan.tolerance_rad)


def _as_angle(tolerance):
    if not isinstance(tolerance, u.Quantity) or tolerance.unit.physical_type != "angle" or not tolerance.isscalar:
        raise SceneError(f"tolerance expects an angle Quantity such as 1 * u.arcsec or 1e-6 * u.rad; got {tolerance!r}.")
    value = float(tolerance.to_value(u.rad))
    if not (math.isfinite(value) and 1e-12 <= value <= 0.1):
        raise SceneError(f"tolerance expects an attitude angle between 1e-12 rad and 0.1 rad (2e-7 to 2e4 arcsec); "
                         f"got {tolerance!r}.")
    return value


def _days(time):
    whole, rest = tdb_days(time)
    return np.atleast_1d(np.asarray(whole, dtype=float) + np.asarray(rest, dtype=float))


class Scene:
    """One rotating body, its perturbers, its orbit, output times, quantities and an attitude tolerance.

    Parameters
    ----------
    state : spinorbit.RotationState
        Attitude (relative to ICRF) and spin at ``epoch``. When its RigidBody has moments in kg m²
        and a ``mass`` (which must match the body's mass in the orbit model within 1 %), the planner
        estimates the figure's back-reaction on the orbits and runs the coupled route if needed.
        A sequence or a mapping ``{name: state}`` makes a scene of several bodies
        (:mod:`spinorbit.scene.many`: planned per body, sampled once per shared orbit; names from
        ``RigidBody.name`` or ``body0``, ``body1``…).
    epoch : astropy.time.Time
        Time of ``state`` (scalar).
    times : astropy.time.Time
        Output times, strictly increasing, after ``epoch``; a scalar Time means "the end only".
    perturbers : sequence of str or FixedPerturber
        DE421 body names (``"sun"``, ``"earth"``, ``"jupiter"``…; particle names for a REBOUND orbit)
        and/or :class:`FixedPerturber` s. Empty: torque-free.
    orbit : Orbit or dict, optional
        Needed when any perturber is named; for several bodies, one Orbit for all or
        ``{name: Orbit}``.
    tolerance : Quantity
        Attitude tolerance (angle) of the whole run.
    quantities : sequence of str
        Among :data:`QUANTITIES`.
    integrator : {"auto", "quaternion", "elements", "taylor"}
        "auto" lets the planner choose between the Taylor method and the quaternion DOP853
        (:meth:`_integrator_choice`: Taylor while the sampled perturbers' knots are few against the
        rotation's own steps).
    sample_tolerance : float
        Relative interpolation error of the sampled perturbers in the run.

    Raises
    ------
    SceneError
        Inputs of the wrong kind, times not after the epoch, perturbers without an orbit, …
    """

    def __init__(self, state, epoch, times, perturbers=(), orbit=None, tolerance=1 * u.arcsec,
                 quantities=QUANTITIES, integrator="auto", sample_tolerance=1e-10):
        self.members, self._cache = None, None
        if isinstance(state, (list, tuple, dict)):
            from spinorbit.scene import many as scene_bodies

            def make(member_state, member_orbit):
                return Scene(member_state, epoch, times, perturbers, member_orbit, tolerance, quantities, integrator,
                             sample_tolerance)

            self.members = scene_bodies.members(state, orbit, make)
            self.epoch, self.times, self.tolerance_rad, self.output_days, self.epoch_day = (
                scene_bodies.common_times(self.members))
            return
        if not isinstance(state, RotationState):
            raise SceneError(f"state expects a spinorbit.RotationState; got {type(state).__name__}.")
        if not isinstance(epoch, Time) or not epoch.isscalar:
            raise SceneError(f"epoch expects a scalar astropy Time; got {epoch!r}.")
        if not isinstance(times, Time):
            raise SceneError(f"times expects an astropy Time (scalar for the end only, or an array); got "
                             f"{type(times).__name__}.")
        self.state, self.epoch, self.times = state, epoch, times
        self.end_only = times.isscalar or times.size == 1
        self.epoch_day = float(_days(epoch)[0])
        self.output_days = _days(times)
        if not np.all(np.diff(self.output_days) > 0):
            raise SceneError("times expects strictly increasing output times.")
        if not self.output_days[0] > self.epoch_day:
            raise SceneError(f"times expects output times after the epoch; the first is "
                             f"{self.output_days[0] - self.epoch_day:+.6g} d from it. Give later times or an earlier epoch.")
        self.tolerance_rad = _as_angle(tolerance)
        unknown = [q for q in quantities if q not in QUANTITIES]
        if unknown or not quantities:
            raise SceneError(f"quantities expects some of {QUANTITIES}; got {tuple(quantities)!r}.")
        self.quantities = tuple(quantities)
        if integrator not in INTEGRATORS:
            raise SceneError(f"integrator expects one of {INTEGRATORS}; got {integrator!r}.")
        self.integrator = integrator
        if not (isinstance(sample_tolerance, float) and 1e-14 <= sample_tolerance < 1e-2):
            raise SceneError(f"sample_tolerance expects a float in [1e-14, 1e-2); got {sample_tolerance!r}.")
        self.sample_tolerance = sample_tolerance
        if orbit is not None and not isinstance(orbit, Orbit):
            raise SceneError(f"orbit expects a spinorbit.scene.scene.Orbit (Orbit.de421, Orbit.ephemeris, Orbit.rebound); "
                             f"got {type(orbit).__name__}.")
        self.orbit = orbit
        self.fixed = tuple(p for p in perturbers if isinstance(p, FixedPerturber))
        self.moving = tuple(p for p in perturbers if isinstance(p, EphemerisPerturber))
        named = [p for p in perturbers if not isinstance(p, (FixedPerturber, EphemerisPerturber))]
        bad = [p for p in named if not isinstance(p, str)]
        if bad:
            raise SceneError(f"perturbers expects body names (str), FixedPerturber or EphemerisPerturber; got "
                             f"{bad[0]!r}.")
        barycentric = [p.name for p in self.moving if not p.relative]
        if barycentric and orbit is None:
            raise SceneError(f"perturbers {barycentric} are barycentric EphemerisPerturbers and need the body's orbit: "
                             "give orbit=Orbit.de421(...), Orbit.ephemeris(...) or Orbit.rebound(...), or "
                             "relative=True.")
        if named and orbit is None:
            raise SceneError(f"perturbers {named} need the body's orbit: give orbit=Orbit.de421(...), "
                             "Orbit.ephemeris(...) or Orbit.rebound(...).")
        self.named = tuple(self._resolve(named))
        everyone = [*self.named, *(p.name for p in self.fixed), *(p.name for p in self.moving)]
        if len(set(everyone)) != len(everyone):
            raise SceneError(f"perturbers lists a body twice: {everyone}.")
        self._cache = None  # perturber samples shared within one plan() / run() (see _sharing_samples)
        self.moments_per_mass = self._moments_per_mass()

    def _moments_per_mass(self):
        """(A, B, C)/M in au² when the body's RigidBody has moments in kg m² and a mass, else None.

        The back-reaction needs the figure's absolute size; moment *ratios* do not give it. The mass
        must agree with the body's mass in the orbit model (to :data:`MASS_MISMATCH`).
        """
        from astropy import constants

        body = self.state.body
        if body.mass is None or body.moment_unit.physical_type != "moment of inertia":
            return None
        per_mass = (np.array(body.principal_moments) * body.moment_unit / body.mass).to_value(u.au**2)
        model = self._gm_in_orbit_model()
        given = float((constants.G * body.mass).to_value(u.au**3 / u.day**2))
        if model > 0.0 and abs(given / model - 1.0) > MASS_MISMATCH:
            raise SceneError(
                f"the body's mass {body.mass:.6g} (G·M = {given:.6g} au³/day²) differs from its mass in the orbit model "
                f"(G·M = {model:.6g} au³/day², '{self.orbit.name}') by {abs(given / model - 1.0):.2%}; expected them "
                f"to agree within {MASS_MISMATCH:.0%}. Give RigidBody the orbit model's mass (or fix the particle's m).")
        return tuple(float(v) for v in per_mass)

    def _gm_in_orbit_model(self):
        """The body's G·M (au³/day²) in the orbit model: 0 for a test particle or a given ephemeris."""
        if self.orbit is None or self.orbit.kind == "ephemeris":
            return 0.0
        if self.orbit.kind == "rebound":
            from spinorbit.coupling.rebound import body_index

            sim = self.orbit.simulation
            return float(sim.particles[body_index(sim, self.orbit.name)].m * sim.G)
        from spinorbit.ephemeris import de421_constants

        return float(de421_constants().gm[self.orbit.name])

    def _resolve(self, names):
        if self.orbit is not None and self.orbit.kind == "rebound":
            from spinorbit.coupling.rebound import MissingBodyError, body_index

            sim = self.orbit.simulation
            try:
                return [sim.particles[body_index(sim, n)].name.lower() for n in names]
            except MissingBodyError as error:
                raise SceneError(f"perturbers: {error}") from None
        from spinorbit.ephemeris import resolve_body

        resolved = [resolve_body(n) for n in names]  # UnknownBodyError names the known bodies
        if self.orbit is not None and self.orbit.name in resolved:
            raise SceneError(f"perturbers includes the rotating body itself ({self.orbit.name!r}).")
        return resolved

    @property
    def span_days(self):
        """Days from the epoch to the last output time."""
        return float(self.output_days[-1] - self.epoch_day)

    # ------------------------------------------------------------------------------------------
    # Planning

    def _orbit_source(self, skip, decisions):
        if not self.named:
            return "none"
        kind = self.orbit.kind
        if kind != "rebound":
            decisions.append(Decision("orbits", f"{kind} positions, no N-body integration",
                                      f"the body's orbit is given ({kind}) and the perturbers are DE421 bodies"))
            return kind
        from spinorbit.ephemeris import DE421_SPAN_JD_TDB, KNOWN_BODIES
        from spinorbit.time import J2000_JD_TDB

        lo, hi = (jd - J2000_JD_TDB for jd in DE421_SPAN_JD_TDB)
        inside = lo <= self.epoch_day and self.output_days[-1] <= hi
        known = self.orbit.name.lower() in KNOWN_BODIES and all(n in KNOWN_BODIES for n in self.named)
        if skip and known and inside:
            decisions.append(Decision("orbits", "DE421 positions instead of the REBOUND (N-body) run",
                                      f"'{self.orbit.name}' and every perturber are DE421 bodies and the span lies "
                                      "inside DE421 (1900-2200): the ephemeris is the orbit the N-body run would "
                                      "reproduce (to metres, docs/ephemeris.md)"))
            return "de421"
        why = ("skip=False (reference run)" if not skip else
               f"'{self.orbit.name}' is not a DE421 body: its orbit is known only through the simulation"
               if self.orbit.name.lower() not in KNOWN_BODIES else "a perturber or the span is outside DE421")
        decisions.append(Decision("orbits", "REBOUND (N-body) run, perturbers from the same run", why))
        return "rebound"

    def _sampler(self, source, names, tolerance):
        """Sample ``names`` relative to the body from ``source`` over the epoch…last-output span.

        Within one :meth:`plan` or :meth:`run` (and across the bodies of a scene that share an orbit),
        samples already taken at the same tolerance from the same source are reused.
        """
        if self._cache is not None:
            for cached_source, cached_tolerance, cached in self._cache:
                if cached_source == source and cached_tolerance == tolerance and set(names) <= set(cached.names):
                    return cached if tuple(names) == cached.names else _subset(cached, names)
        samples = self._sample(source, names, tolerance)
        if self._cache is not None:
            self._cache.append((source, tolerance, samples))
        return samples

    def _sample(self, source, names, tolerance):
        from spinorbit.coupling import sampling

        if source == "user":
            return self._sample_user(names, tolerance)

        start = time_from_tdb_days(self.epoch_day)
        end = time_from_tdb_days(self.output_days[-1])
        if source == "rebound":
            return sampling.sample_from_rebound(self.orbit.simulation, self.orbit.name, start, end, names,
                                               tolerance=tolerance)
        orbit = (sampling.de421_orbit(self.orbit.name) if source == "de421" else self.orbit.function)
        return sampling.sample_from_ephemeris(orbit, start, end, names, tolerance=tolerance)

    def _sample_user(self, names, tolerance):
        """Sample the EphemerisPerturbers ``names`` relative to the body (same grid and checks as DE421's)."""
        from spinorbit.coupling import sampling

        chosen = [next(p for p in self.moving if p.name == name) for name in names]
        body = self._body_orbit() if any(not p.relative for p in chosen) else None

        def provider(days):
            out = np.empty((days.size, len(chosen), 6))
            centre = None if body is None else np.concatenate([np.asarray(a, dtype=float) for a in body(days)], axis=1)
            for i, perturber in enumerate(chosen):
                out[:, i] = perturber.states(days) - (0.0 if perturber.relative else centre)
            return out

        return sampling.sample_states(provider, names, [p.gm_au3_day2 for p in chosen],
                                     time_from_tdb_days(self.epoch_day), time_from_tdb_days(self.output_days[-1]),
                                     tolerance)

    def _body_orbit(self):
        """The body's barycentric orbit as a callable days -> (positions, velocities), au and au/day."""
        from spinorbit.coupling import sampling

        if self.orbit.kind == "de421":
            return sampling.de421_orbit(self.orbit.name)
        if self.orbit.kind == "rebound":
            return sampling.rebound_orbit(self.orbit.simulation, self.orbit.name)
        return self.orbit.function

    @_sharing_samples
    def plan(self, skip=True):
        """Decide how to run the scene; ``skip=False`` gives the reference plan (nothing skipped).

        Returns
        -------
        Plan or spinorbit.scene.many.ScenePlans
            ``print(plan)`` lists every decision with its reason; one Plan per body for a scene of
            several bodies.
        """
        if self.members is not None:
            from spinorbit.scene.many import plan_many

            return plan_many(self.members, skip)
        decisions = []
        tolerance = self.tolerance_rad
        moments = self.state.body.principal_moments
        span = self.span_days
        if self.end_only:
            decisions.append(Decision("outputs", "end only: one output time (the dense interpolant is formed for "
                                      "the last step alone), quantities once", "a single output time was asked"))
        else:
            decisions.append(Decision("outputs", f"{self.output_days.size} output times (dense output)",
                                      "several output times were asked"))
        shape = self._shape_decision(skip)
        if not self.named and not self.fixed and not self.moving:
            decisions.append(Decision("route", "exact torque-free solution, no integration",
                                      "the scene has no perturbers: the torque is zero"))
            decisions.append(shape)
            return Plan("torque-free", "none", (), (), {}, "exact", None, self.end_only, tolerance, 1.0, 0.0,
                        not skip, decisions)
        source = self._orbit_source(skip, decisions)
        kappa = attitude_sensitivity(self.state, span)
        momentum = np.linalg.norm(self.state.angular_momentum.value) / moments[0]
        estimates, survey, survey_note = self._survey(source, kappa, momentum, moments, keep=skip)
        samples = survey if self._keeps_survey(source, skip) else None
        total = sum(e.bound_rad for e in estimates.values())
        names = list(estimates)
        if skip and total <= tolerance:
            decisions.append(Decision(
                "route", "exact torque-free solution, no sampling, no integration",
                f"all torques together move the attitude by at most {total * ARCSEC_PER_RAD:.3g} arcsec "
                f"≤ tolerance {tolerance * ARCSEC_PER_RAD:.3g} arcsec ({survey_note})"))
            decisions.append(shape)
            for e in estimates.values():
                e.kept = False
            return Plan("torque-free", source, (), tuple(names), estimates, "exact", None, self.end_only,
                        tolerance, kappa, total, False, decisions)
        route, back_reaction, bound, coupling = self._coupling(skip, source, kappa, momentum, moments, survey)
        dropped, used = [], 0.0
        if skip and route == "one-way":
            for name in sorted(names, key=lambda n: estimates[n].bound_rad):
                if used + estimates[name].bound_rad <= DROP_SHARE * tolerance - back_reaction:
                    used += estimates[name].bound_rad
                    dropped.append(name)
        for name in names:
            e = estimates[name]
            e.kept = name not in dropped
            verdict = "dropped" if name in dropped else "kept"
            why = (f"closest {e.closest_au:.4g} au: leaving it out moves the attitude by at most "
                   f"{e.bound_rad * ARCSEC_PER_RAD:.3g} arcsec")
            if name in dropped:
                why += f" (all dropped together {used * ARCSEC_PER_RAD:.3g} arcsec ≤ {DROP_SHARE:g} × tolerance)"
            elif route == "coupled":
                why = ("the coupled route keeps every perturber (in an N-body run dropping one saves nothing "
                       "measurable, docs/scenes.md); " + why)
            elif skip:
                why += f" > what is left of {DROP_SHARE:g} × tolerance"
            else:
                why = "skip=False (reference run); " + why
            decisions.append(Decision(f"perturber {name}", verdict, why))
        decisions.append(Decision("bound", "per-perturber estimate", survey_note))
        decisions.extend(coupling)
        if route == "coupled":
            eps = float(np.clip(initial_rtol(tolerance), *COUPLED_EPS_RANGE))
            decisions.append(Decision("integrator", f"REBOUND BS, eps {eps:.1e}, rotation as a user ODE (checked a "
                                      f"posteriori against a run at {CHECK_RTOL_FACTOR:g}× eps)",
                                      "BS is the one REBOUND integrator that integrates a user ODE together with the "
                                      "orbits (docs/coupling.md); eps within "
                                      f"{COUPLED_EPS_RANGE[0]:g}…{COUPLED_EPS_RANGE[1]:g} since it controls the orbits too"))
            return Plan("coupled", "rebound", tuple(names), (), estimates, "rebound-bs", eps, self.end_only,
                        tolerance, kappa, 0.0, not skip, decisions, None, 0.0, bound)
        share = tolerance - used - back_reaction
        kept = tuple(n for n in names if n not in dropped)
        integrator, reason = self._integrator_choice(skip, source, kept, share)
        rtol = _first_tolerance(integrator, share)
        what, knob = ("Taylor (core.integrate_taylor)", "tol") if integrator == "taylor" else (
            f"{integrator} DOP853", "rtol")
        decisions.append(Decision("integrator", f"{what}, {knob} {rtol:.1e} (checked a posteriori "
                                  f"against a run at {CHECK_RTOL_FACTOR:g}× {knob})", reason))
        return Plan("one-way", source, kept, tuple(dropped), estimates, integrator, rtol, self.end_only,
                    tolerance, kappa, used, not skip, decisions, samples, back_reaction, bound)

    def _shape_decision(self, skip=True):
        """Which form of the exact free flow the torque-free route runs (the dispatch of ``core.torque_free``).

        ``skip=False`` (the reference plan) runs the elliptic flow for every body, so that the closed
        form's saving and agreement can be measured against it.
        """
        from spinorbit.core.free_motion.regular_precession import NO_SYMMETRY_AXIS, symmetry_axis

        big_a, big_b, big_c = self.state.body.principal_moments
        axis = symmetry_axis(big_a, big_b, big_c)
        if axis != NO_SYMMETRY_AXIS and not skip:
            return Decision("closed form", "elliptic free flow at parameter 0 (closed form not taken)",
                            "skip=False (reference run): two principal moments are equal, but the reference plan "
                            "runs the general elliptic flow")
        if axis != NO_SYMMETRY_AXIS:
            which = "A = B = C, a sphere" if big_a == big_c else (
                "A = B: symmetry axis C" if axis == 2 else "B = C: symmetry axis A")
            return Decision("closed form", "regular precession in closed form (core.regular_precession: two sin/cos "
                            "per output, no elliptic function)",
                            f"two principal moments are exactly equal ({which}): exact, same accuracy as the "
                            "elliptic flow at parameter 0 and cheaper per output (docs/performance.md)")
        mode = self.state.mode
        if mode == "permanent rotation":
            return Decision("closed form", "uniform rotation (no elliptic functions)",
                            "the spin is exactly along the intermediate axis B (a permanent rotation; spin along A or "
                            "C takes the elliptic flow at parameter 0)")
        asymmetry = min(big_b - big_a, big_c - big_b) / big_c
        _, momentum = self.state.principal_attitude_and_momentum()
        wobble = float(min(np.hypot(momentum[0], momentum[1]), np.hypot(momentum[1], momentum[2]))
                       / np.linalg.norm(momentum))
        return Decision("closed form", f"elliptic free flow, {mode} (exact; no approximate form taken)",
                        f"triaxial body (smallest moment gap / C = {asymmetry:.3g}, wobble sin(angle of M from the A or C axis) = {wobble:.3g}): "
                        "Jacobi functions and the secular pn of eq. (12). A regular precession or small-wobble "
                        "approximation would make a phase error that grows with the span and has no tested bound "
                        "here, so it is not used")

    def _survey(self, source, kappa, momentum, moments, keep=True):
        """Per-perturber bounds (planner module docstring) from a survey of the distances.

        ``keep``: for a REBOUND orbit, survey at the run's tolerance so that the run can reuse it
        (:meth:`_keeps_survey`; the reference plan, ``keep=False``, keeps nothing, so a full run pays its
        own sampling). Returns the estimates, the survey of the named perturbers (None without any; the
        back-reaction bound reads the same survey) and what the bound was (the free-motion bound, or why
        the worst-attitude one).
        """
        from spinorbit.core.model.perturbers import fixed_source

        t_end = self.output_days[-1]
        survey = None
        surveys = []
        if self.named:
            # With a REBOUND orbit every sampling pass is an N-body run, whose cost hardly depends on the
            # tolerance (the pilot and the run dominate): survey at the run's tolerance and keep it.
            # With an ephemeris, sampling costs per perturber: survey loosely, sample only the kept.
            keep = self._keeps_survey(source, keep)
            survey = self._sampler(source, self.named, self._survey_tolerance(keep))
            surveys.append(survey)
        if self.moving:  # user ephemerides: like an ephemeris, surveyed loosely, the kept sampled for the run
            surveys.append(self._sampler("user", [p.name for p in self.moving], SURVEY_TOLERANCE))
        # Per perturber: (name, closest, its source, its survey days, |N|_max/A on them).
        rows = []
        for samples in surveys:
            distances = np.linalg.norm(samples.states[:, :, :3], axis=2)
            for i, (name, source) in enumerate(zip(samples.names, samples.sources())):
                rows.append((name, float(distances[:, i].min()), source, samples.days,
                             max_torque_over_a(moments, samples.gm[i], distances[:, i])))
        ends = np.array([self.epoch_day, t_end])
        for fixed in self.fixed:
            r = float(np.linalg.norm(fixed.position_au))
            rows.append((fixed.name, r, fixed_source(fixed.gm_au3_day2, fixed.position_au), ends,
                         max_torque_over_a(moments, fixed.gm_au3_day2, np.array([r, r]))))
        worst = [dropped_torque_bound(days, n, t_end, kappa, momentum) for _, _, _, days, n in rows]
        bounds, note = free_motion_bounds(self.state, self.epoch_day, t_end, [row[2:] for row in rows], worst,
                                          max((s.tolerance for s in surveys), default=0.0), kappa)
        estimates = {name: PerturberEstimate(name, closest, bound, True, w)
                     for (name, closest, *_), bound, w in zip(rows, bounds, worst)}
        return estimates, survey, note

    def _keeps_survey(self, source, skip):
        """Whether the survey is taken at the run's tolerance and kept for it: a planned one-way run on
        a REBOUND orbit (the coupled route samples nothing; the reference run samples for itself)."""
        return skip and source == "rebound" and not self._coupled_runnable()

    def _coupled_runnable(self):
        """The coupled route can run: a REBOUND orbit, a body with mass in it and a figure of known
        size, and every perturber a particle of the simulation."""
        return (self.orbit is not None and self.orbit.kind == "rebound" and not self.fixed and not self.moving
                and self.moments_per_mass is not None and self._gm_in_orbit_model() > 0.0)

    def _survey_tolerance(self, keep):
        """The survey's sampling tolerance: the run's when the survey is kept for the run."""
        return self.sample_tolerance if keep else SURVEY_TOLERANCE

    def _coupling(self, skip, source, kappa, momentum, moments, survey):
        """One-way or fully coupled: (route, back-reaction left out (rad), its bound (rad or None), decisions).

        ``survey`` is the planning survey of the named perturbers (:meth:`_survey`), read here rather
        than sampled again. The bound (:func:`spinorbit.scene.planner.back_reaction_bound`) needs the figure's absolute size and
        the body's mass; a massless body in the orbit model has none to estimate.
        """
        choice = "one-way (the rotation does not act on the orbits)"
        gm_body = self._gm_in_orbit_model()
        if gm_body == 0.0:
            return "one-way", 0.0, None, [Decision(
                "coupling", choice,
                "the body is massless in the orbit model (a test particle or a given ephemeris), so its figure cannot "
                "act on the orbits; for a real small body that force is of relative size (C-A)/(M r²) ~ J2 (R/r)², "
                "≈ 1e-13 for a 300 m asteroid at 1 au (coupling/one_way.py)")]
        if self.moments_per_mass is None:
            return "one-way", 0.0, None, [Decision(
                "coupling", choice + "; back-reaction NOT estimated",
                f"'{self.orbit.name}' has mass in the orbit model but a Scene knows only its moment ratios (give "
                "RigidBody the moments in kg m² and the mass for the estimate); for the Moon the back-reaction was "
                "measured at ≈ 0.1 arcsec over a year (docs/coupling.md: 0.305 one-way vs 0.207 arcsec coupled)")]
        big_a, _, big_c = self.moments_per_mass
        if survey is None:  # no named perturbers surveyed (only user ones): as before, sample the (empty) set
            survey = self._sampler(source, self.named, self._survey_tolerance(self._keeps_survey(source, skip)))
        distances = np.linalg.norm(survey.states[:, :, :3], axis=2)
        bound, displacement = back_reaction_bound(survey.days, distances, survey.gm, gm_body, big_c - big_a, moments,
                                                  self.output_days[-1], kappa, momentum)
        au_km = float((1 * u.au).to_value(u.km))
        numbers = (f"figure (C-A)/M = ({math.sqrt(big_c - big_a) * au_km:.3g} km)², G·M = {gm_body:.3g} au³/day²: "
                   f"the figure's force moves the perturber vectors by at most {float(np.max(displacement)) * au_km:.3g} "
                   f"km and so the attitude by at most {bound * ARCSEC_PER_RAD:.3g} arcsec over the span "
                   "(planner: back-reaction bound)")
        if source == "de421" and self.orbit.name == "moon":
            return "one-way", 0.0, bound, [Decision(
                "coupling", choice + "; the back-reaction is in the ephemeris",
                "DE421 integrated the lunar orbit together with the lunar figure (Williams et al. 2008), so its orbits "
                "already hold what a coupled run adds; " + numbers)]
        share = DROP_SHARE * self.tolerance_rad
        runnable = self._coupled_runnable()
        coupled = "fully coupled: REBOUND with the figure's force on the orbits (CoupledRigidBody, coupled=True)"
        if runnable:
            # Given a REBOUND orbit, the coupled BS run needs no sampling: it measured cheaper than the
            # one-way route in every scene of benchmarks/bench_scene_skips.py, so it is the cheap route.
            why = "skip=False (reference run): nothing left out; " if not skip else (
                "with a REBOUND orbit the coupled run is also the cheaper one (it needs no sampling: 2.0-5.8x "
                "faster than one-way in bench_scene_skips, docs/performance.md) and leaves nothing out; ")
            decisions = [Decision("coupling", coupled, why + numbers)]
            if source != "rebound":
                decisions.append(Decision("orbits", "REBOUND (N-body) run after all",
                                          "the coupled route integrates the orbits with the figure's force on "
                                          "them; the ephemeris does not have it"))
            return "coupled", 0.0, bound, decisions
        if skip and bound <= share:
            return "one-way", bound, bound, [Decision("coupling", choice, f"{numbers} ≤ {DROP_SHARE:g} × tolerance")]
        if not skip:
            return "one-way", bound, bound, [Decision(
                "coupling", choice + "; back-reaction left out (in the error estimate)",
                "skip=False (reference run), but a coupled run needs the orbits as a REBOUND simulation and "
                f"every perturber as one of its particles; {numbers}")]
        user = [p.name for p in (*self.fixed, *self.moving)]
        what = (f"the perturbers {user} are not particles of a REBOUND simulation" if user else
                f"the orbit is {self.orbit.kind!r}, not a REBOUND simulation")
        raise PlanError(
            f"the back-reaction bound {bound * ARCSEC_PER_RAD:.3g} arcsec exceeds {DROP_SHARE:g} × tolerance "
            f"({share * ARCSEC_PER_RAD:.3g} arcsec), so one-way coupling is not within the tolerance; a coupled run "
            f"needs every orbit in one REBOUND simulation, but {what}. Give orbit=Orbit.rebound(sim, "
            f"'{self.orbit.name}') with the body and its perturbers as particles (e.g. from simulation_from_de421), "
            "or loosen the tolerance.")

    def _integrator_choice(self, skip, source, kept, share):
        """The one-way route's integrator and why: (name, reason).

        "auto" takes the Taylor method (:func:`spinorbit.core.integrators.taylor.integrate_taylor`) when
        the sampled perturbers' knots inside the span are at most :data:`TAYLOR_KNOT_SHARE` × the steps
        the rotation needs, else the quaternion DOP853. The one-way model's figure is the principal
        moments alone (degree-2 torques, ``propagate_one_way``), for which the Taylor recurrences exist
        (they have no degree-3/4 terms). Why knots: a Taylor step ends at every sample time (the
        Hermite interpolant is not smooth across it), so the Taylor run takes about rotation steps +
        knots steps, while DOP853 steps across them (:meth:`_taylor_steps`: both counts, estimated).
        The reference plan (``skip=False``) runs the quaternion DOP853, the integrator the other
        routes are checked against, unless another one is asked for.
        """
        measured = ("at 1e-10 rad in work-precision scene (a) (docs/performance.md) the Taylor method took "
                    f"{WORK_PRECISION_MS['Taylor']:g} ms, DOP853 {WORK_PRECISION_MS['DOP853']:g} ms, heyoka "
                    f"{WORK_PRECISION_MS['heyoka']:g} ms and the elements {WORK_PRECISION_MS['elements']:g} ms, "
                    "but a Taylor step ends at every sample time of a sampled perturber")
        if self.integrator == "elements":
            return self._elements_choice()
        if self.integrator == "quaternion":
            return "quaternion", "asked for (non-singular everywhere)"
        if self.integrator == "auto" and not skip:
            return "quaternion", ("skip=False (reference run): the quaternion DOP853, non-singular everywhere and the "
                                  "integrator the planned routes are checked against")
        tol = _first_tolerance("taylor", share)
        steps, knots, probed = self._taylor_steps(source, kept, skip, tol)
        counts = (f"the rotation needs ≈ {steps:.0f} Taylor steps (the free motion at tol {tol:.1e} over "
                  f"{probed:.3g} d of the span's {self.span_days:.4g} d, scaled) and the sampled perturbers add "
                  f"≈ {knots:.0f} knots")
        if self.integrator == "taylor":
            return "taylor", f"asked for; {counts}"
        limit = TAYLOR_KNOT_SHARE * steps
        rule = (f"(Taylor while knots ≤ {TAYLOR_KNOT_SHARE:g} × the rotation steps = {limit:.0f}: at their first "
                "tolerances Taylor/DOP853 CPU was 0.75-1.15 up to 1 ×, 1.7-13 at 2.5-90 ×, bench_scene_skips in "
                "docs/performance.md)")
        if knots <= limit:
            return "taylor", f"{counts} {rule}; {measured}, and here there are few"
        return "quaternion", f"{counts} {rule}; {measured}, and here they dominate: the quaternion DOP853 steps across them"

    def _taylor_steps(self, source, kept, skip, tol):
        """(rotation steps, knots inside the span, probed days) for the Taylor rule.

        Rotation steps: :func:`~spinorbit.core.integrators.taylor.integrate_taylor` on the free motion
        over at most :data:`TAYLOR_PROBE_ROTATIONS` × 2π/|ω|, scaled to the span (the torques are weak
        against the rotation, so they hardly change the steps: 268 free against 275 torqued in
        bench_scene_skips' 'drop perturbers' scene at tol 1e-10). Knots: the sample times the run will
        have strictly inside (epoch, last output): counted for samples the plan keeps for the run,
        otherwise the a priori grid (:func:`spinorbit.coupling.sampling.a_priori_grid`) of the survey's
        states at the run's sample tolerance × :data:`SAMPLE_REFINEMENT`. Perturbers sampled on
        separate grids (DE421/REBOUND bodies and user ephemerides) add their counts.
        """
        from spinorbit.core.dynamics.equations import make_model
        from spinorbit.core.integrators.taylor import integrate_taylor
        from spinorbit.coupling.sampling import a_priori_grid

        free = make_model(self.state.body.principal_moments)  # the figure the one-way run uses
        y0 = self.state.core_state()
        spin = float(np.linalg.norm(y0[4:]))
        probed = self.span_days if spin == 0.0 else min(self.span_days, TAYLOR_PROBE_ROTATIONS * 2 * math.pi / spin)
        _, stats = integrate_taylor(y0, self.epoch_day, [self.epoch_day + probed], free, tol=tol, return_stats=True)
        steps = stats["steps"] * self.span_days / probed
        named = [n for n in kept if n in self.named]
        moving = [p.name for p in self.moving if p.name in kept]
        groups = []
        if named:
            exact = self._keeps_survey(source, skip)  # then the run samples are the survey's (plan.samples)
            groups.append((self._sampler(source, named, self._survey_tolerance(exact)), exact))
        if moving:
            groups.append((self._sampler("user", moving, SURVEY_TOLERANCE), False))
        knots = 0.0
        t0, t1 = self.epoch_day, self.output_days[-1]
        for samples, exact in groups:
            days = samples.days if exact else a_priori_grid(samples.days, samples.states, samples.days[0],
                                                             samples.days[-1], self.sample_tolerance)
            inside = float(np.count_nonzero((days > t0) & (days < t1)))
            knots += inside if exact else SAMPLE_REFINEMENT * inside
        return steps, knots, probed

    def _elements_choice(self):
        """The canonical elements when asked for and the state is away from their singular sets.

        The distances are the integrator's own (:func:`~spinorbit.core.integrators.handover.singularity_distances_of_state`),
        each against :data:`SINGULAR_MARGIN` × its stop threshold, except the equal-moment plane of a
        symmetric body (sin P), held to the hand-over's resume margin: its threshold is 1e-2, so the
        100× margin would refuse every symmetric body.
        """
        from spinorbit.core.integrators.elements import MIN_SEPARATRIX_DISTANCE, MIN_SIN_J, MIN_SIN_J_A, MIN_SIN_P
        from spinorbit.core.integrators.handover import RESUME_MARGIN, singularity_distances_of_state

        moments = np.array(self.state.body.principal_moments)
        separatrix, sin_j, _, sin_j_a, sin_p = singularity_distances_of_state(self.state.core_state(), moments)
        limits = {"1 - m": (abs(separatrix), SINGULAR_MARGIN * MIN_SEPARATRIX_DISTANCE),
                  "sin J": (sin_j, SINGULAR_MARGIN * MIN_SIN_J),
                  "sin J_A": (sin_j_a, SINGULAR_MARGIN * MIN_SIN_J_A),
                  "sin P": (sin_p, RESUME_MARGIN * MIN_SIN_P)}
        numbers = ", ".join(f"{name} = {value:.2g}" for name, (value, _) in limits.items())
        near = [f"{name} < {limit:g}" for name, (value, limit) in limits.items() if not value >= limit]
        if near:
            return "quaternion", (f"elements were asked but the state is near their singular sets ({numbers}; "
                                  f"{', '.join(near)}): the non-singular quaternion integrator is used")
        return "elements", f"asked for; the state is away from the singular sets ({numbers})"

    # ------------------------------------------------------------------------------------------
    # Running

    @_sharing_samples
    def run(self, plan=None, progress=None):
        """Carry out ``plan`` (default: :meth:`plan`) and return a :class:`SceneResult`.

        ``progress``, if given, is called with a fraction in [0, 1] as the run advances. A scene of
        several bodies returns :class:`~spinorbit.scene.many.SceneResults` (one result per body).
        """
        if self.members is not None:
            from spinorbit.scene.many import run_many

            return run_many(self.members, self.plan() if plan is None else plan, progress)
        clock = _time.perf_counter()
        plan = self.plan() if plan is None else plan
        if not isinstance(plan, Plan):
            raise SceneError(f"plan expects a spinorbit.scene.planner.Plan from Scene.plan(); got {type(plan).__name__}.")
        report = progress or (lambda fraction: None)
        report(0.0)
        if plan.route == "torque-free":
            table = self._torque_free_table(closed_forms=not plan.full)
            parts = {"dropped": plan.dropped_bound_rad, "integration": 0.0, "sampling": 0.0}
            stats = {}
        elif plan.route == "coupled":
            table, parts, stats = self._coupled(plan, report)
        else:
            table, parts, stats = self._one_way(plan, report)
        parts.setdefault("back_reaction", plan.back_reaction_rad)
        report(1.0)
        parts_q = {k: (v * u.rad).to(u.arcsec) for k, v in parts.items()}
        total = sum(parts.values()) * u.rad
        table.meta["error_estimate_arcsec"] = float(total.to_value(u.arcsec))
        table.meta["route"] = plan.route
        table.meta["tolerance_met"] = bool(total.to_value(u.rad) <= plan.tolerance_rad)
        return SceneResult(table, total.to(u.arcsec), parts_q, plan, _time.perf_counter() - clock, stats)

    def _times(self):
        return time_from_tdb_days(self.output_days)

    def _torque_free_table(self, closed_forms=True):
        offsets = self.output_days - self.epoch_day
        quaternions, omegas = self.state.propagate_torque_free(offsets, closed_forms=closed_forms)
        # Mode, E/E0 and the periods are constants of the torque-free motion: the initial state's, once.
        return self._table(quaternions, omegas.to_value(u.rad / u.day), motion=self.state)

    def _table(self, quaternions, omegas, motion="rows"):
        """The result table of user-axes rows (quaternions, ω in rad/day), all rows at once."""
        table = QTable()
        table["time"] = self._times()
        for name, column in table_columns(self.state.body, quaternions, omegas, omega="omega" in self.quantities,
                                          motion=motion if "periods" in self.quantities else None).items():
            table[name] = column
        return table

    def _one_way(self, plan, report):
        from spinorbit.core.model.perturbers import fixed_source
        from spinorbit.coupling.one_way import propagate_one_way

        named = tuple(n for n in plan.kept if n in self.named)
        fixed = [fixed_source(p.gm_au3_day2, p.position_au) for p in self.fixed if p.name in plan.kept]
        moving = [p.name for p in self.moving if p.name in plan.kept]
        if moving:
            fixed += self._sampler("user", moving, self.sample_tolerance).sources()
        if named and plan.samples is not None:
            samples = _subset(plan.samples, named)
        else:
            samples = self._sampler(plan.orbit_source, named, self.sample_tolerance) if named else None
        if samples is None:
            samples = _NoSamples(self.epoch_day, self.output_days[-1])
        report(0.3)
        epoch = time_from_tdb_days(self.epoch_day)
        times = self._times()
        rtol = plan.rtol
        share = max(plan.integration_share_rad, 0.0)
        for attempt in range(MAX_RTOL_RETRIES + 1):
            run = propagate_one_way(self.state, epoch, times, samples, rtol=rtol, periods="periods" in self.quantities,
                                    integrator=plan.integrator, extra_sources=fixed)
            check = propagate_one_way(self.state, epoch, times, samples, rtol=min(rtol * CHECK_RTOL_FACTOR, 1e-4),
                                      periods=False, integrator=plan.integrator, extra_sources=fixed)
            integration = float(np.max(_angles(run["quaternion"], check["quaternion"])))
            report(0.3 + 0.7 * (attempt + 1) / (MAX_RTOL_RETRIES + 1))
            if integration <= 0.5 * share or rtol <= 1e-13:
                break
            rtol = max(rtol / 100.0, 1e-13)
        # The sampling error is a torque error of relative size 3ε in no particular direction: it does not
        # share the torque's cancellation, so it is bounded with the worst-attitude bound.
        kept_bound = sum(_worst_attitude(plan.estimates[n]) for n in plan.kept)
        sampling = 3.0 * self.sample_tolerance * kept_bound if named or moving else 0.0
        if "omega" not in self.quantities:
            run.remove_column("omega")
        run.meta["rtol"] = rtol
        # DOP853 reports accepted/rejected/rhs_calls; Taylor steps (= accepted, 0 rejected), order, no RHS calls.
        stats = {k: run.meta[k] for k in ("accepted", "rejected", "rhs_calls", "steps", "order") if k in run.meta}
        stats.update(integrator=plan.integrator, rtol=rtol, samples=int(samples.days.size),
                     passes=int(getattr(samples, "passes", 0)))
        return run, {"dropped": plan.dropped_bound_rad, "integration": integration, "sampling": sampling}, stats

    def _coupled(self, plan, report):
        """The fully coupled REBOUND run (BS), checked against a second run at 10× eps."""
        from spinorbit.coupling.long_run import coupled_run

        y0 = self.state.core_state()
        eps = plan.rtol
        share = max(plan.integration_share_rad, 0.0)
        for attempt in range(MAX_RTOL_RETRIES + 1):
            rows, stats = coupled_run(self.orbit.simulation, self.orbit.name, self.moments_per_mass, y0,
                                      self.epoch_day, self.output_days, plan.kept, eps)
            check, _ = coupled_run(self.orbit.simulation, self.orbit.name, self.moments_per_mass, y0,
                                   self.epoch_day, self.output_days, plan.kept, min(eps * CHECK_RTOL_FACTOR, 1e-6))
            integration = float(np.max(_angles(rows[:, :4], check[:, :4])))
            report((attempt + 1) / (MAX_RTOL_RETRIES + 1))
            if integration <= 0.5 * share or eps <= COUPLED_EPS_RANGE[0]:
                break
            eps = max(eps / 100.0, COUPLED_EPS_RANGE[0])
        rows[:, :4] /= np.linalg.norm(rows[:, :4], axis=1, keepdims=True)
        table = self._table(*from_principal(self.state.body, rows))
        table.meta["rtol"] = eps
        stats.update(rtol=eps)
        return table, {"dropped": 0.0, "integration": integration, "sampling": 0.0}, stats


def _worst_attitude(estimate):
    """The worst-attitude bound of a PerturberEstimate (``bound_rad`` for one made without it)."""
    return estimate.bound_rad if estimate.worst_attitude_rad is None else estimate.worst_attitude_rad


def _first_tolerance(integrator, share):
    """First local tolerance for an integration error share (rad): DOP853's rtol from
    :func:`spinorbit.scene.planner.initial_rtol`, the Taylor tol from :data:`TAYLOR_TOL_PER_ERROR`, both
    clipped to the planner's range (the retry loop of ``Scene._one_way`` goes down to 1e-13)."""
    if integrator == "taylor":
        return float(np.clip(share * TAYLOR_TOL_PER_ERROR, *RTOL_RANGE))
    return initial_rtol(share)


def _subset(samples, names):
    """The columns of ``names`` of a SampledPerturbers (same grid, same error estimates per perturber)."""
    from spinorbit.coupling.sampling import SampledPerturbers

    index = [samples.names.index(n) for n in names]
    return SampledPerturbers(tuple(names), samples.gm[index], samples.days, samples.states[:, index],
                             samples.tolerance, samples.midpoint_error[index], samples.passes,
                             {n: samples.closest[n] for n in names if n in samples.closest})


class _NoSamples:
    """Stand-in for SampledPerturbers when only fixed perturbers are kept."""

    names = ()
    tolerance = 0.0
    passes = 0
    midpoint_error = np.zeros(0)

    def __init__(self, start, end):
        self.days = np.array([start, end])
        self.span = (start, end)

    def sources(self):
        return []


def _angles(q1, q2):
    """Rotation angle (rad) between two attitude quaternion series (q and −q are one attitude)."""
    from spinorbit.core.math.rotations import rotation_angle_between_many

    return rotation_angle_between_many(np.ascontiguousarray(np.atleast_2d(q1), dtype=float),
                                       np.ascontiguousarray(np.atleast_2d(q2), dtype=float))
