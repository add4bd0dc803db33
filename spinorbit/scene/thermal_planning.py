"""How the scene planner runs a body that feels sunlight: the full torques, or the mean YORP run, and why.

A :class:`~spinorbit.scene.Scene` with ``thermal=`` (a :class:`~spinorbit.scene.thermal.ThermalModel`)
on a heliocentric Kepler orbit (:meth:`~spinorbit.scene.Orbit.kepler`) is planned here. Both routes
integrate one model array, ``make_model(moments, [Sun], thermal=block)``: the Sun's gravity torque
and its recoil torque in the one torque sum.

- **full** (route "thermal-full"): the quaternion DOP853 (:func:`spinorbit.core.integrators.quaternion.integrate_quaternion`)
  under both torques, checked a posteriori like the one-way route (:func:`spinorbit.scene.tolerances.refine`).
  The Taylor method has no recurrence for the recoil, so it is not offered.
- **mean** (route "thermal-mean"): :func:`spinorbit.core.averaging.thermal_mean.propagate_mean_thermal`,
  the recoil averaged over the (s, z) torus and the orbit, gravity's mean precession and the
  nutation damping, for the slow state (S, Z, H, h). It does not follow the rotation phase: it
  answers the pole, the obliquity, the spin state and the periods, not the attitude.

The mean route's error against the osculating quantities of the full run is estimated in three
parts (rad; the direction of L as an angle, Z and S relative to Z):

- ``short_period``: the terms averaging leaves out. Over the orbit, measured: the torus-averaged
  rates of (S, Z, H, h) under the whole torque at :data:`ORBIT_POINTS` orbital phases, their
  oscillation about the orbit mean integrated through the orbit (:func:`orbit_short_period`). Over
  the torus, bounded: (|T|max + |N|max)/(Z ν), ν the slowest free-motion frequency.
- ``averaging``: the first-order theory's error of the secular change, :data:`MEAN_CHANGE_ERROR` ×
  the change over the span estimated from the initial rates (docs/thermal.md's table).
- ``integration``: a posteriori, the run against one at half its step.

``auto`` takes the mean route when it is cheaper (right-hand sides counted for both and priced at
their measured CPU times, :data:`FULL_RHS_SECONDS`, :data:`MEAN_RHS_SECONDS`) and
its estimate is within the tolerance, the span covers :data:`MIN_MEAN_ORBITS` orbits, and the
separatrix is not reached within the span at the initial mean rate; otherwise the full route when
it is affordable (:data:`MAX_FULL_RHS`), else :class:`~spinorbit.scene.plan.PlanError` saying why.
"""

from __future__ import annotations

import math

import numpy as np
from astropy import units as u

from spinorbit.core.errors import SpinorbitError
from spinorbit.scene.plan import ARCSEC_PER_RAD, Decision, Plan, PlanError
from spinorbit.scene.tolerances import CHECK_RTOL_FACTOR, first_tolerance

__all__ = ["THERMAL_ROUTES", "MIN_MEAN_ORBITS", "MEAN_STEP_SHARE", "MAX_FULL_RHS", "MEAN_CHANGE_ERROR",
           "ORBIT_POINTS", "FULL_RHS_SECONDS", "MEAN_RHS_SECONDS", "FULL_FACET_SECONDS", "MEAN_FACET_SECONDS", "SeparatrixCrossingError", "ThermalSetup", "plan_thermal", "thermal_setup",
           "orbit_short_period", "mean_difference"]

THERMAL_ROUTES = ("auto", "full", "mean")
#: The mean route answers orbit averages: it is taken only over spans of at least this many orbits.
MIN_MEAN_ORBITS = 2.0
#: Mean step = this share of the shortest evolution time of (S, Z, H) at the start (at least one orbit):
#: docs/thermal.md measured the 10⁶-yr run's changes to 8.4e-3 of their size at 200 steps (1/200 of
#: the span) against 400.
MEAN_STEP_SHARE = 0.01
#: CPU time of one right-hand side of the full route (quaternion equations, the Sun and the degree-8
#: recoil) and of the mean route at one torus point (eq. 11 and the exact orbit average, its fixed part),
#: and what each facet adds: to a full right-hand side with ``torque="facets"`` (the direct sum), and to
#: a mean torus point (the orbit average's pass over the facets). benchmarks/thermal_scene.py measures
#: all four (docs/thermal.md, "The Scene's thermal routes": medians 498 ns, 1190 ns, 0.46 ns and 0.96 ns
#: per facet on 2 shared cores, from meshes of 320 and 1280 facets); the planner compares the routes in
#: these seconds, so only their ratios decide.
FULL_RHS_SECONDS = 5.0e-7
MEAN_RHS_SECONDS = 1.2e-6
FULL_FACET_SECONDS = 4.6e-10
MEAN_FACET_SECONDS = 9.6e-10
#: Right-hand sides beyond which the full route is refused: 2e9 is ~17 min at FULL_RHS_SECONDS.
MAX_FULL_RHS = 2e9
#: Relative error of the mean theory's secular changes of (S, Z, H) against the full integration:
#: the worst entry of docs/thermal.md's "Mean YORP against the full integration" table (60 m, ΔH).
MEAN_CHANGE_ERROR = 0.06
#: Orbital phases at which the torus-averaged rates are evaluated for the orbit's short-period terms.
ORBIT_POINTS = 32
#: Free-motion rotations the full route's step count is probed over (then scaled to the span).
PROBE_ROTATIONS = 20.0
#: DOP853 stages per step (right-hand sides per accepted step, the cost unit of both routes).
STAGES = 12


class SeparatrixCrossingError(PlanError):
    """The mean YORP run reaches the separatrix inside the span, where the torus average is undefined.

    ``time`` (astropy Time) is where, and ``table`` (or None) the mean outputs before it.
    """

    def __init__(self, message, time, table=None):
        super().__init__(message)
        self.time, self.table = time, table


class ThermalSetup:
    """The core pieces both routes integrate, in au, day and the body's moment unit (built once per plan)."""

    def __init__(self, scene):
        from spinorbit.core.dynamics.equations import make_model

        thermal, orbit, body = scene.thermal, scene.orbit, scene.state.body
        self.moments = np.array(body.principal_moments)
        self.block = thermal.block_for(body)
        self.moment_scale = float((1.0 * u.kg * u.m**2).to_value(body.moment_unit))
        self.sun = orbit.kepler_sun()
        self.model = make_model(self.moments, [self.sun], thermal=self.block, thermal_sun=0)
        self.frame = orbit.kepler_frame()  # inertial → (P, Q, W): H/Z is the cosine of the obliquity
        self.y0 = scene.state.core_state()
        self.t0 = scene.epoch_day
        a, e = orbit.kepler_elements[0], orbit.kepler_elements[1]
        from spinorbit.ephemeris import de421_constants

        self.gm_sun = de421_constants().gm["sun"]
        self.mean_motion = math.sqrt(self.gm_sun / a**3)
        self.period_orbit = 2.0 * math.pi / self.mean_motion
        self.perihelion = a * (1.0 - e)
        self.damping = thermal.damping_constant
        self.spin = float(np.linalg.norm(self.y0[4:]))
        try:
            from spinorbit.core.integrators.elements import elements_of_state

            self.el0, self.why_no_elements = elements_of_state(self.y0, self.model, self.frame), None
        except SpinorbitError as error:  # a permanent rotation or a state on the separatrix
            self.el0, self.why_no_elements = None, str(error)


def thermal_setup(scene):
    """:class:`ThermalSetup` of a thermal scene."""
    return ThermalSetup(scene)


def _exact_rates(setup):
    """The recoil's mean d(S, Z, H, h)/dt at the start: the exact orbit average on the mean route's torus grid."""
    from spinorbit.core.averaging.thermal_mean import EXACT_POINTS_S, EXACT_POINTS_Z, exact_mean_thermal_rates
    from spinorbit.core.elements.canonical import inertia_constants

    out = np.empty(4)
    exact_mean_thermal_rates(setup.el0, setup.model, setup.frame, inertia_constants(*setup.moments), EXACT_POINTS_S,
                             EXACT_POINTS_Z, out)
    return out


def _torus_rates(setup, t, model, n_orbit=1, period=1.0):
    """Torus-averaged d(S, Z, H, h)/dt at ``t`` under ``model`` (n_orbit = 1: no orbit average)."""
    from spinorbit.core.averaging.thermal_mean import THERMAL_POINTS_S, THERMAL_POINTS_Z, mean_thermal_rates
    from spinorbit.core.elements.canonical import inertia_constants

    out = np.empty(4)
    mean_thermal_rates(float(t), setup.el0, model, setup.frame, inertia_constants(*setup.moments), THERMAL_POINTS_S,
                       THERMAL_POINTS_Z, int(n_orbit), float(period), out)
    return out


def direction_of(big_z, big_h, small_h):
    """Unit direction of L in the reference frame from (Z, H, h): (sin J sin h, −sin J cos h, cos J)."""
    cos_j = np.clip(np.asarray(big_h) / np.asarray(big_z), -1.0, 1.0)
    sin_j = np.sqrt(1.0 - cos_j * cos_j)
    return np.stack([sin_j * np.sin(small_h), -sin_j * np.cos(small_h), cos_j], axis=-1)


def mean_difference(a, b):
    """Largest difference (rad) between two series of (S, Z, H, h) rows: the angle between the L
    directions, |ΔZ|/Z and |ΔS|/Z, whichever is largest over the rows."""
    a, b = np.atleast_2d(a), np.atleast_2d(b)
    da, db = direction_of(a[:, 1], a[:, 2], a[:, 5]), direction_of(b[:, 1], b[:, 2], b[:, 5])
    angle = 2.0 * np.arcsin(np.clip(0.5 * np.linalg.norm(da - db, axis=1), 0.0, 1.0))
    scale = np.abs(a[:, 1])
    return float(np.max(np.maximum(angle, np.maximum(np.abs(a[:, 1] - b[:, 1]), np.abs(a[:, 0] - b[:, 0])) / scale)))


def orbit_short_period(setup):
    """The orbit's short-period amplitude (rad) of the mean elements under the whole torque (measured).

    The torus-averaged rates at :data:`ORBIT_POINTS` phases over one orbit, minus their orbit mean,
    integrated through the orbit (trapezoids): the osculating-minus-mean excursion of (S, Z, H, h),
    measured as :func:`mean_difference` from the start.
    """
    times = setup.t0 + setup.period_orbit * np.arange(ORBIT_POINTS + 1) / ORBIT_POINTS
    rates = np.array([_torus_rates(setup, t, setup.model) for t in times])
    rates -= rates[:-1].mean(axis=0)
    dt = setup.period_orbit / ORBIT_POINTS
    excursion = np.vstack([np.zeros(4), np.cumsum(0.5 * (rates[1:] + rates[:-1]) * dt, axis=0)])
    rows = np.tile(setup.el0, (times.size, 1))
    moved = rows.copy()
    moved[:, [0, 1, 2, 5]] += excursion
    excursion_rad = mean_difference(rows, moved)
    return excursion_rad


def _torus_bound(setup, thermal):
    """(bound (rad), ν (rad/day)) of the torus's short-period terms: (|T|max + |N|max)/(Z ν)."""
    from spinorbit.core.averaging.mean_equations import torus_frequencies
    from spinorbit.core.elements.canonical import inertia_constants

    big_a, _, big_c = setup.moments
    gravity = 1.5 * setup.gm_sun * (big_c - big_a) / setup.perihelion**3  # |3GM r̂ × I r̂ / r³| ≤ 3GM(C−A)/(2r³)
    recoil_si = thermal.torque_bound(setup.perihelion * u.au).to_value(u.N * u.m)
    recoil = recoil_si * 86400.0**2 * setup.moment_scale  # N m → kg m² day⁻² → the body's moment unit / day²
    period, _, s_rate = torus_frequencies(setup.el0[0], setup.el0[1], inertia_constants(*setup.moments))
    nu = min(setup.spin, 2.0 * math.pi * s_rate / period if math.isfinite(period) else setup.spin)
    return (gravity + recoil) / (setup.el0[1] * nu), nu


def _full_rhs(setup, rtol, span):
    """Estimated right-hand sides of the full run (and its check): a probe over PROBE_ROTATIONS, scaled."""
    from spinorbit.core.integrators.quaternion import integrate_quaternion

    probed = min(span, PROBE_ROTATIONS * 2.0 * math.pi / setup.spin)
    _, stats = integrate_quaternion(setup.y0, setup.t0, [setup.t0 + probed], setup.model, rtol=rtol,
                                    return_stats=True)
    return 2.0 * stats["rhs_calls"] * span / probed, probed


def _separatrix_time(setup, rates):
    """(1 − m at the start, days to MIN_SEPARATRIX_DISTANCE at the initial mean rate or inf)."""
    from spinorbit.core.averaging.thermal_mean import MIN_SEPARATRIX_DISTANCE
    from spinorbit.core.elements.canonical import MO_PARAM_C, inertia_constants, motion_from_elements

    ic = inertia_constants(*setup.moments)
    big_s, big_z = abs(setup.el0[0]), setup.el0[1]
    now = motion_from_elements(big_s, big_z, ic)[MO_PARAM_C]
    scale = max(abs(rates[0]), abs(rates[1])) / big_z
    if scale == 0.0:
        return now, math.inf
    dt = 1e-6 / scale
    later = motion_from_elements(abs(big_s + math.copysign(1.0, setup.el0[0]) * rates[0] * dt),
                                 big_z + rates[1] * dt, ic)[MO_PARAM_C]
    rate = (later - now) / dt
    return now, (now - MIN_SEPARATRIX_DISTANCE) / -rate if rate < 0.0 else math.inf


def _years(days):
    return f"{days / 365.25:.4g} yr"


def plan_thermal(scene, skip=True):
    """The :class:`~spinorbit.scene.plan.Plan` of a scene with ``thermal=``: full or mean, each with its reason.

    Raises
    ------
    PlanError
        Neither route reaches the tolerance affordably (the message names the numbers and what to do).
    SeparatrixCrossingError
        The mean route is needed but reaches the separatrix inside the span at the initial rate.
    """
    from spinorbit.core.averaging.thermal_mean import EXACT_POINTS_S, EXACT_POINTS_Z, MIN_SEPARATRIX_DISTANCE
    from spinorbit.time import time_from_tdb_days

    tolerance = scene.tolerance_rad
    setup = thermal_setup(scene)
    span = scene.span_days
    forced = scene.thermal_route
    thermal = scene.thermal
    decisions = [Decision("outputs", f"{scene.output_days.size} output time(s)", "as asked")]
    recoil_at_q = thermal.torque_bound(setup.perihelion * u.au)
    decisions.append(Decision(
        "sunlight", f"Rubincam recoil of {len(thermal.shape)} facets (full route: {thermal.torque_text}), "
        f"η = {thermal.efficiency:g}"
        + (f"; nutation damping μQ = {thermal.mu_q:.3g}, K₃² = {thermal.k3_squared:g}" if thermal.mu_q is not None else ""),
        f"thermal= was given; |T| ≤ {recoil_at_q.to_value(u.N * u.m):.3g} N m at perihelion "
        f"({setup.perihelion:.4g} au); the Sun's gravity torque comes with its position (one torque sum)"))
    orbits = span / setup.period_orbit
    rotations = span * setup.spin / (2.0 * math.pi)
    rtol = first_tolerance("quaternion", tolerance)
    full_rhs, probed = _full_rhs(setup, rtol, span)
    facts = f"span {_years(span)} = {orbits:.3g} orbits = {rotations:.3g} rotations"
    mean_info = None
    refusal = []
    if setup.el0 is None:
        refusal.append(f"the state has no canonical elements ({setup.why_no_elements})")
    else:
        rates = _exact_rates(setup)
        from spinorbit.core.averaging.dissipation import damping_rate_of_s
        from spinorbit.core.elements.canonical import inertia_constants

        rates[0] += damping_rate_of_s(setup.el0[0], setup.el0[1], inertia_constants(*setup.moments), setup.damping)
        big_z = setup.el0[1]
        evolution = big_z / max(float(np.max(np.abs(rates[:3]))), 1e-300)
        step = min(max(MEAN_STEP_SHARE * evolution, setup.period_orbit), span)
        intervals = np.diff(np.concatenate([[setup.t0], scene.output_days]))
        mean_steps = int(np.sum(np.ceil(intervals / step - 1e-9)))  # each output is landed on
        check_steps = int(np.sum(np.ceil(intervals / (0.5 * step) - 1e-9)))  # the check at half the step
        grid = EXACT_POINTS_S * EXACT_POINTS_Z
        mean_rhs = float(mean_steps + check_steps) * STAGES * grid
        short_orbit = orbit_short_period(setup)
        short_torus, nu = _torus_bound(setup, thermal)
        change = min(span / evolution, 2.0)  # the relative change of the fastest of S, Z, H over the span
        averaging = MEAN_CHANGE_ERROR * change
        estimate = short_orbit + short_torus + averaging
        separatrix, to_separatrix = _separatrix_time(setup, rates)
        mean_info = dict(step=step, steps=mean_steps, rhs=mean_rhs, short_period=short_orbit + short_torus,
                         averaging=averaging, estimate=estimate, separatrix=separatrix, to_separatrix=to_separatrix,
                         evolution=evolution, n_grid=(EXACT_POINTS_S, EXACT_POINTS_Z))
        facts += (f"; YORP{' + damping' if setup.damping else ''} evolution time Z/|rate| ≈ {_years(evolution)}; "
                  f"mean estimate {estimate * ARCSEC_PER_RAD:.3g} arcsec (orbit short-period {short_orbit * ARCSEC_PER_RAD:.3g}, "
                  f"torus bound {short_torus * ARCSEC_PER_RAD:.3g} at ν = {nu:.3g} rad/d, averaging "
                  f"{MEAN_CHANGE_ERROR:g} × change {change:.2g} = {averaging * ARCSEC_PER_RAD:.3g}); "
                  f"1 − m = {separatrix:.3g}"
                  + (f", separatrix in ≈ {_years(to_separatrix)} at the initial rate" if math.isfinite(to_separatrix)
                     else ", not approaching the separatrix"))
        facets = len(thermal.shape)
        full_s = full_rhs * (FULL_RHS_SECONDS + (facets * FULL_FACET_SECONDS if thermal.torque == "facets" else 0.0))
        mean_s = mean_rhs * (MEAN_RHS_SECONDS + facets * MEAN_FACET_SECONDS)
        costs = (f"cost: full ≈ {full_rhs:.3g} right-hand sides ≈ {full_s:.3g} CPU s, mean ≈ {mean_rhs:.3g} ≈ "
                 f"{mean_s:.3g} CPU s ({mean_steps} steps of {_years(step)})")
        facts += "; " + costs
        if separatrix < MIN_SEPARATRIX_DISTANCE:
            refusal.append(f"1 − m = {separatrix:.3g} < {MIN_SEPARATRIX_DISTANCE:g}: at the separatrix the torus average is undefined")
        if to_separatrix <= span:
            refusal.append(f"the mean run reaches the separatrix after ≈ {_years(to_separatrix)}, inside the span")
        if orbits < MIN_MEAN_ORBITS:
            refusal.append(f"the span is {orbits:.3g} orbits < {MIN_MEAN_ORBITS:g}: the mean route answers orbit averages")
        if estimate > tolerance:
            refusal.append(f"its estimate {estimate * ARCSEC_PER_RAD:.3g} arcsec > tolerance {tolerance * ARCSEC_PER_RAD:.3g} arcsec")
        if mean_s >= full_s:
            refusal.append("it is not cheaper than the full integration")
    full_ok = full_rhs <= MAX_FULL_RHS
    if forced == "full":
        route, why = "full", f"thermal_route='full' (forced); {facts}"
    elif forced == "mean":
        if setup.el0 is None or mean_info["separatrix"] < MIN_SEPARATRIX_DISTANCE:
            raise PlanError(f"thermal_route='mean' cannot run: {refusal[0]}. Use thermal_route='full'.")
        route, why = "mean", f"thermal_route='mean' (forced); {facts}"
        if mean_info["estimate"] > tolerance:
            why += f"; NOTE its estimate exceeds the tolerance {tolerance * ARCSEC_PER_RAD:.3g} arcsec"
    elif not refusal:
        route, why = "mean", f"{facts}: the mean route is within the tolerance and cheaper"
    elif full_ok:
        route = "full"
        why = f"{facts}; the mean route is not taken: {'; '.join(refusal)}"
    else:
        crossing = mean_info is not None and mean_info["to_separatrix"] <= span
        message = (f"no route reaches the tolerance affordably: the full integration needs ≈ {full_rhs:.3g} right-hand "
                   f"sides (> {MAX_FULL_RHS:g}) and the mean route is not taken ({'; '.join(refusal)}). {facts}.")
        if crossing and len(refusal) == 1:
            when = time_from_tdb_days(setup.t0 + mean_info["to_separatrix"])
            raise SeparatrixCrossingError(
                f"{message} The mean run would reach the separatrix near {when.tdb.iso} TDB (estimated at the initial "
                "rate); a hand-over to the full integrator there is not implemented. Run the mean route to before "
                "that time (times ending earlier), or force thermal_route='full' over a span it affords.", when)
        raise PlanError(message + " Loosen the tolerance to at least the mean estimate, shorten the span, or force "
                        "thermal_route='full' or 'mean'.")
    decisions.append(Decision("route", "full: the quaternion DOP853 under the Sun's gravity and sunlight's recoil"
                              if route == "full" else
                              "mean: propagate_mean_thermal over the (s, z) torus and the orbit (no rotation phase)", why))
    if route == "full":
        decisions.append(Decision(
            "integrator", f"quaternion DOP853, rtol {rtol:.1e} (checked a posteriori against a run at "
            f"{CHECK_RTOL_FACTOR:g}× rtol)",
            "the Taylor method has no recurrence for the recoil (it would fall back to DOP853) and the canonical "
            "elements are singular where YORP can take the spin"))
        return Plan(route="thermal-full", orbit_source="kepler", kept=("sun",), dropped=(), estimates={},
                    integrator="quaternion", rtol=rtol, end_only=scene.end_only, tolerance_rad=tolerance, kappa=1.0,
                    dropped_bound_rad=0.0, full=not skip, decisions=decisions,
                    thermal=dict(setup=setup, mean=mean_info))
    n_s, n_z = mean_info["n_grid"]
    decisions.append(Decision(
        "integrator", f"mean DOP853, fixed step {_years(mean_info['step'])} ({mean_info['steps']} steps; checked "
        f"against half the step), the facet sum's orbit average in closed form on a {n_s} × {n_z} torus grid, "
        "gravity's mean precession" + (", nutation damping" if setup.damping else ""),
        f"step = {MEAN_STEP_SHARE:g} × the evolution time (at least one orbit); the torus grid leaves a few 1e-4 "
        "of the mean rates (docs/thermal.md, tests/test_yorp_mean.py)"))
    return Plan(route="thermal-mean", orbit_source="kepler", kept=("sun",), dropped=(), estimates={},
                integrator="mean-dop853", rtol=None, end_only=scene.end_only, tolerance_rad=tolerance, kappa=1.0,
                dropped_bound_rad=0.0, full=not skip, decisions=decisions, thermal=dict(setup=setup, mean=mean_info))
