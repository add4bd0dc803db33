"""A run described declaratively, planned cheapest-first within a tolerance, then carried out.

A :class:`Scene` says *what* is wanted — one rotating body's state at an epoch, the perturbers that
may torque it, where the orbits come from, the output times, the quantities and the attitude
tolerance — and :meth:`Scene.plan` decides *how*, each decision with its reason in words and numbers
(``print(scene.plan())``, like a query planner's EXPLAIN). :meth:`Scene.run` carries the plan out and
returns the results with an error estimate. The class is the front of the scene package: the inputs
are checked in :mod:`~spinorbit.scene.inputs`, the decisions taken in :mod:`~spinorbit.scene.planning`
(bounds in :mod:`~spinorbit.scene.bounds`, tolerances in :mod:`~spinorbit.scene.tolerances`, the
integrator in :mod:`~spinorbit.scene.integrator_choice`), recorded in a :class:`~spinorbit.scene.plan.Plan`
and carried out by :mod:`~spinorbit.scene.routes`; ``docs/scenes.md`` explains them.

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
   force on the orbits is bounded through to the attitude (:func:`spinorbit.scene.bounds.back_reaction_bound`);
   within the drop share of the tolerance → one-way, that number in the reason and in the error
   estimate; above it → the **coupled** route: REBOUND's BS with the rotation as a user ODE and the
   figure's back-reaction (:class:`spinorbit.coupling.rigid_body.CoupledRigidBody`, ``coupled=True``).
   The Moon on DE421's orbits needs neither: DE421 integrated its orbit with the lunar figure.
5. **Outputs only at the end → one output time**: the dense interpolant is formed for the last step alone, quantities computed once.
6. **Integrator**: the Taylor method (:mod:`spinorbit.core.integrators.taylor`, the fastest in the
   work-precision scenes of ``docs/performance.md``) while the sampled perturbers' knots, each of
   which ends a Taylor step, are at most as many as the steps the rotation needs; otherwise the
   quaternion DOP853, which steps across them (:func:`spinorbit.scene.integrator_choice.choose_integrator`). The
   canonical-element integrator is used only when asked for and the state is away from its singular
   sets; otherwise the plan says why not.

Frames and units as in :mod:`spinorbit.coupling.one_way`: the state's attitude is relative to ICRF,
times are astropy Times (TDB inside), distances au, GM au³/day².
"""

from __future__ import annotations

import contextlib
import functools
import time as _time
from dataclasses import dataclass, field

from astropy import units as u
from astropy.table import QTable

from spinorbit.scene import inputs
from spinorbit.scene.inputs import QUANTITIES, SceneError
from spinorbit.scene.plan import Plan
from spinorbit.scene.planning import plan_scene
from spinorbit.scene.routes import run_coupled, run_one_way, run_torque_free, scene_orbit_normals
from spinorbit.scene.sampling import SharedSamples, grid_of_samples, sample_perturbers
from spinorbit.spin_forms import PA_MAX_WOBBLE, SpinFormError, wobble_threshold_deg

__all__ = ["Scene", "SceneResult"]


def _sharing_samples(method):
    """Share perturber samples between the steps of one plan() or run() call, and forget them after
    (a later call samples afresh: a benchmark timing a run must not find the samples of the last)."""

    @functools.wraps(method)
    def wrapper(self, *args, **kwargs):
        owned = self._cache is None
        if owned:
            self._cache = SharedSamples()
        try:
            return method(self, *args, **kwargs)
        finally:
            if owned:
                self._cache = None

    return wrapper


@dataclass
class SceneResult:
    """What :meth:`Scene.run` returns.

    Attributes
    ----------
    table : astropy.table.QTable
        The one output schema (``docs/conventions.md``, "Output tables"): ``time`` (Time, TDB),
        ``q_w, q_x, q_y, q_z`` (scalar first, user body axes → ICRF), ``omega_x, omega_y, omega_z``
        (rad/day, user body axes), ``pole_ra, pole_dec`` (deg, ICRF), ``pole_lon, pole_lat`` (deg,
        ecliptic J2000), ``obliquity`` (deg, to the osculating heliocentric orbit plane; with an
        orbit); with "periods" asked: ``mode``, ``energy_ratio``, ``P_psi``, ``P_phi``,
        ``sidereal_period`` (h), ``wobble_amplitude`` (deg) and ``rotation_class`` ("PA" rows have P_psi,
        P_phi masked; ``pa_threshold``). ``table.meta`` names ``epoch``, ``frame``, ``model``,
        ``spinorbit_version`` and ``columns``. Only the quantities asked for are filled in beyond
        time, attitude and pole. Each row holds what its RotationState would give
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
    epoch : astropy.time.Time, optional
        Time of ``state`` (scalar). Leave it out when the state carries its own
        (:attr:`~spinorbit.RotationState.epoch`: ``Scene(state, times=...)``); given as well, it must be
        that same instant.
    times : astropy.time.Time
        Output times, strictly increasing; a scalar Time means "the end only". They may lie before
        ``epoch`` or on both sides of it: the state belongs to its epoch, and the run goes from there
        forwards and backwards (:mod:`spinorbit.scene.epochs`), so the state at a given time does not
        depend on the span asked for.
    perturbers : sequence of str, FixedPerturber or EphemerisPerturber
        DE421 body names (``"sun"``, ``"earth"``, ``"jupiter"``…; particle names for a REBOUND orbit)
        and/or :class:`FixedPerturber` s and :class:`EphemerisPerturber` s. Empty: torque-free.
    orbit : Orbit or dict, optional
        Needed when any perturber is named; for several bodies, one Orbit for all or
        ``{name: Orbit}``.
    tolerance : Quantity
        Attitude tolerance (angle) of the whole run.
    quantities : sequence of str
        Among :data:`QUANTITIES`.
    integrator : {"auto", "quaternion", "elements", "taylor"}
        "auto" lets the planner choose between the Taylor method and the quaternion DOP853
        (:func:`~spinorbit.scene.integrator_choice.choose_integrator`: Taylor while the sampled
        perturbers' knots are few against the rotation's own steps).
    sample_tolerance : float
        Relative interpolation error of the sampled perturbers in the run.
    thermal : spinorbit.scene.ThermalModel, optional
        The body feels sunlight: Rubincam's recoil of its shape (and nutation damping if the model
        has μQ). Needs ``orbit=Orbit.kepler(...)`` and output times after the epoch; the body's
        moments must be its shape's (``rigid_body_from_shape``). Planned by
        :mod:`spinorbit.scene.thermal_planning` (docs/thermal.md).
    thermal_route : {"auto", "full", "mean"}
        "auto" lets the planner choose between the full integration and the mean YORP run; the
        others force one.
    pa_threshold : Quantity
        Wobble amplitude (an angle in [0°, 90°)) up to which a row of the table is a principal-axis
        rotator: ``rotation_class`` "PA", P_ψ and P_φ masked (:func:`spinorbit.state_table.classify_rows`).
        Default 1° (:data:`spinorbit.spin_forms.PA_MAX_WOBBLE`; why: ``docs/design.md``, "PA or NPA").

    Raises
    ------
    SceneError
        Inputs of the wrong kind, times before the epoch, perturbers without an orbit, …
    """

    def __init__(self, state, epoch=None, times=None, perturbers=(), orbit=None, tolerance=1 * u.arcsec,
                 quantities=QUANTITIES, integrator="auto", sample_tolerance=1e-10, thermal=None,
                 thermal_route="auto", pa_threshold=PA_MAX_WOBBLE):
        self.members, self._cache = None, None  # _cache: the SharedSamples of the plan() / run() under way
        self._report_planning = None  # plan()'s progress callback while it plans
        self.thermal, self.thermal_route = thermal, thermal_route
        try:  # refused here, not after the run
            wobble_threshold_deg(pa_threshold, "pa_threshold")
        except SpinFormError as error:
            raise SceneError(str(error)) from None
        self.pa_threshold = pa_threshold
        if isinstance(state, (list, tuple, dict)):
            from spinorbit.scene import many

            def make(member_state, member_orbit):
                return Scene(member_state, epoch, times, perturbers, member_orbit, tolerance, quantities, integrator,
                             sample_tolerance, thermal, thermal_route, pa_threshold)

            self.members = many.members(state, orbit, make)
            self.epoch, self.times, self.tolerance_rad, self.output_days, self.epoch_day = (
                many.common_times(self.members))
            return
        self.state = inputs.validate_state(state)
        epoch = inputs.resolve_epoch(state, epoch, times)
        if thermal is not None or (orbit is not None and getattr(orbit, "kind", None) == "kepler"):
            from spinorbit.scene.thermal import validate_thermal

            validate_thermal(self.state, thermal, thermal_route, orbit, perturbers, epoch, times)
        self.epoch_day, self.output_days, self.end_only = inputs.validate_times(epoch, times, either_side=True)
        self.epoch, self.times = epoch, times
        self.tolerance_rad, self.quantities = inputs.validate_options(tolerance, quantities, integrator,
                                                                      sample_tolerance)
        self.integrator, self.sample_tolerance = integrator, sample_tolerance
        self.named, self.fixed, self.moving = inputs.validate_perturbers(perturbers, orbit)
        self.orbit = orbit
        if orbit is not None:
            orbit.check_span(self.epoch_day, self.output_days[0], self.output_days[-1])
        self.moments_per_mass = inputs.moments_per_mass(state.body, orbit)
        self.backward = self.forward = None  # the two legs when times are not all after the epoch
        self.in_legs = bool(self.output_days[0] <= self.epoch_day)
        if self.in_legs:
            from spinorbit.scene import epochs

            def make(leg_state, leg_epoch, leg_times, leg_perturbers, leg_orbit):
                return Scene(leg_state, leg_epoch, leg_times, leg_perturbers, leg_orbit, tolerance,
                             tuple(dict.fromkeys(("omega", *self.quantities))), integrator, sample_tolerance,
                             pa_threshold=pa_threshold)

            epochs.split_legs(self, make, perturbers, orbit)

    @property
    def span_days(self):
        """Days from the epoch to the last output time."""
        return float(self.output_days[-1] - self.epoch_day)

    @property
    def gm_in_orbit_model(self):
        """The body's G·M (au³/day²) in the orbit model: 0 for a test particle or a given ephemeris."""
        return inputs.gm_in_orbit_model(self.orbit)

    def coupled_runnable(self):
        """The coupled route can run: a REBOUND orbit, a body with mass in it and a figure of known
        size, and every perturber a particle of the simulation."""
        return (self.orbit is not None and self.orbit.kind == "rebound" and not self.fixed and not self.moving
                and self.moments_per_mass is not None and self.gm_in_orbit_model > 0.0)

    def keeps_survey(self, source, skip):
        """Whether the survey is taken at the run's tolerance and kept for it: a planned one-way run on
        a REBOUND orbit (the coupled route samples nothing; the reference run samples for itself)."""
        return skip and source == "rebound" and not self.coupled_runnable()

    # ------------------------------------------------------------------------------------------
    # Samples of the perturbers

    def sample_perturbers(self, source, names, tolerance):
        """Sample ``names`` relative to the body from ``source`` over the epoch…last-output span.

        Within one :meth:`plan` or :meth:`run` (and across the bodies of a scene that share an orbit,
        :meth:`sharing_samples`), samples already taken at the same tolerance from the same source are
        reused (:class:`~spinorbit.scene.sampling.SharedSamples`).
        """
        if self._cache is not None:
            found = self._cache.find(source, names, tolerance)
            if found is not None:
                return found
        samples = self._sample(source, names, tolerance)
        if self._cache is not None:
            self._cache.add(source, tolerance, samples)
        if self._report_planning is not None:  # the survey's sampling is most of a plan's time
            self._report_planning(0.8)
        return samples

    def grid_of(self, samples, tolerance):
        """The a priori grid (:func:`~spinorbit.scene.sampling.grid_of_samples`) of ``samples`` at ``tolerance``;
        within :meth:`sharing_samples`, computed once per samples object for every scene sharing them."""
        if self._cache is not None:
            return self._cache.grid_of(samples, tolerance)
        return grid_of_samples(samples, tolerance)

    def _sample(self, source, names, tolerance):
        return sample_perturbers(self.orbit, self.moving, self.epoch_day, self.output_days[-1], source, names,
                                 tolerance)

    @contextlib.contextmanager
    def sharing_samples(self, shared):
        """Within the block, :meth:`plan` and :meth:`run` take and keep their samples in ``shared``
        (a :class:`~spinorbit.scene.sampling.SharedSamples`: the bodies of one orbit sample once)."""
        self._cache = shared
        try:
            yield self
        finally:
            self._cache = None

    # ------------------------------------------------------------------------------------------
    # Planning and running

    @_sharing_samples
    def plan(self, skip=True, progress=None):
        """Decide how to run the scene; ``skip=False`` gives the reference plan (nothing skipped).

        ``progress``, if given, is called with a fraction in [0, 1] as planning advances (0 at the
        start, after the survey of the perturbers — the sampling of their orbits, the long part —
        and 1 at the end), like :meth:`run`'s.

        Returns
        -------
        Plan or spinorbit.scene.many.ScenePlans
            ``print(plan)`` lists every decision with its reason (:mod:`spinorbit.scene.planning`); one
            Plan per body for a scene of several bodies.
        """
        if self.members is not None:
            from spinorbit.scene.many import plan_many

            return plan_many(self.members, skip)
        report = progress or (lambda fraction: None)
        report(0.0)
        self._report_planning = report
        try:
            if self.thermal is not None:
                from spinorbit.scene.thermal_planning import plan_thermal

                plan = plan_thermal(self, skip)
            elif self.in_legs:
                from spinorbit.scene.epochs import plan_legs

                plan = plan_legs(self, skip)
            else:
                plan = plan_scene(self, skip)
        finally:
            self._report_planning = None
        report(1.0)
        return plan

    def _complete_table(self, table, plan):
        """The output schema's obliquity (when the run has an orbit) and metadata, whatever the route."""
        from spinorbit.state_table import add_obliquity, classify_rows, schema_meta

        if self.orbit is not None and "obliquity" not in table.colnames:
            normals, why_not = scene_orbit_normals(self, plan)
            if normals is not None:
                add_obliquity(table, normals)
            else:
                table.meta["obliquity"] = f"not computed: {why_not}"
        kept = ", ".join(plan.kept) or "none"
        meta = schema_meta(self.epoch, f"Scene, route {plan.route}, orbits from {plan.orbit_source}, "
                                       f"integrator {plan.integrator}, torques of {kept}")
        table.meta.update({k: v for k, v in meta.items() if k not in table.meta or k in ("model", "epoch")})
        classify_rows(table, self.pa_threshold)
        if "obliquity" in table.colnames and "mode" in table.colnames:  # the schema's order: before the motion
            column = table["obliquity"]
            table.remove_column("obliquity")
            table.add_column(column, index=table.colnames.index("mode"), name="obliquity")

    @_sharing_samples
    def run(self, plan=None, progress=None):
        """Carry out ``plan`` (default: :meth:`plan`) and return a :class:`SceneResult`.

        ``progress``, if given, is called with a fraction in [0, 1] as the run advances. A scene of
        several bodies returns :class:`~spinorbit.scene.many.SceneResults` (one result per body).
        """
        if self.members is not None:
            from spinorbit.scene.many import run_many

            return run_many(self.members, self.plan() if plan is None else plan, progress)
        if self.in_legs:
            from spinorbit.scene.epochs import run_legs
            from spinorbit.scene.routes import result_table

            return run_legs(self, plan, progress, SceneResult, result_table)
        clock = _time.perf_counter()
        plan = self.plan() if plan is None else plan
        if not isinstance(plan, Plan):
            raise SceneError(f"plan expects a spinorbit.scene.Plan from Scene.plan(); got {type(plan).__name__}.")
        report = progress or (lambda fraction: None)
        report(0.0)
        if plan.route in ("thermal-full", "thermal-mean"):
            from spinorbit.scene.thermal_routes import run_thermal_full, run_thermal_mean

            runner = run_thermal_full if plan.route == "thermal-full" else run_thermal_mean
            table, parts, stats = runner(self, plan, report)
        elif plan.route == "torque-free":
            table, parts, stats = run_torque_free(self, plan)
        elif plan.route == "coupled":
            table, parts, stats = run_coupled(self, plan, report)
        else:
            table, parts, stats = run_one_way(self, plan, report)
        parts.setdefault("back_reaction", plan.back_reaction_rad)
        self._complete_table(table, plan)
        report(1.0)
        parts_q = {k: (v * u.rad).to(u.arcsec) for k, v in parts.items()}
        total = sum(parts.values()) * u.rad
        table.meta["error_estimate_arcsec"] = float(total.to_value(u.arcsec))
        table.meta["route"] = plan.route
        table.meta["tolerance_met"] = bool(total.to_value(u.rad) <= plan.tolerance_rad)
        return SceneResult(table=table, error_estimate=total.to(u.arcsec), error_parts=parts_q, plan=plan,
                           wall_seconds=_time.perf_counter() - clock, stats=stats)
