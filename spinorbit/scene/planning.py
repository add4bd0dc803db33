"""How the scene planner decides: route, orbits, drops and coupling, each decision with its reason.

:func:`plan_scene` takes the decisions of ``docs/scenes.md`` cheapest first for one body (a scene of
several bodies plans each through it, :mod:`spinorbit.scene.many`): the outputs, the form of the free
flow (:func:`shape_decision`), where the orbits come from (:func:`choose_orbit_source`), the survey
and the per-perturber bounds (:func:`survey_perturbers`, the bounds of :mod:`spinorbit.scene.bounds`),
the torque-free route when everything together is below the tolerance, one-way or coupled
(:func:`choose_coupling`), the drops within :data:`~spinorbit.scene.tolerances.DROP_SHARE` of the
tolerance, and the integrator (:mod:`spinorbit.scene.integrator_choice`) with its first tolerance
(:mod:`spinorbit.scene.tolerances`). The functions read a :class:`~spinorbit.scene.Scene`'s public
attributes and sample through :meth:`~spinorbit.scene.Scene.sample_perturbers`.
"""

from __future__ import annotations

import math

import numpy as np
from astropy import units as u

from spinorbit.scene.bounds import (
    attitude_sensitivity,
    back_reaction_bound,
    dropped_torque_bound,
    free_motion_bounds,
    max_torque_over_a,
)
from spinorbit.scene.integrator_choice import choose_integrator
from spinorbit.scene.plan import (
    ARCSEC_PER_RAD,
    Decision,
    PerturberEstimate,
    Plan,
    PlanError,
)
from spinorbit.scene.tolerances import (
    CHECK_RTOL_FACTOR,
    COUPLED_EPS_RANGE,
    DROP_SHARE,
    SURVEY_TOLERANCE,
    first_tolerance,
    survey_tolerance,
)

__all__ = ["choose_coupling", "choose_orbit_source", "plan_scene", "shape_decision", "survey_perturbers"]


def plan_scene(scene, skip=True):
    """The :class:`~spinorbit.scene.plan.Plan` of a single-body ``scene`` (:meth:`spinorbit.scene.Scene.plan`).

    ``skip=False`` gives the reference plan: nothing skipped, nothing dropped.
    """
    decisions = []
    tolerance = scene.tolerance_rad
    moments = scene.state.body.principal_moments
    span = scene.span_days
    if scene.end_only:
        decisions.append(Decision("outputs", "end only: one output time (the dense interpolant is formed for "
                                  "the last step alone), quantities once", "a single output time was asked"))
    else:
        decisions.append(Decision("outputs", f"{scene.output_days.size} output times (dense output)",
                                  "several output times were asked"))
    shape = shape_decision(scene, skip)
    if not scene.named and not scene.fixed and not scene.moving:
        decisions.append(Decision("route", "exact torque-free solution, no integration",
                                  "the scene has no perturbers: the torque is zero"))
        decisions.append(shape)
        return Plan(route="torque-free", orbit_source="none", kept=(), dropped=(), estimates={}, integrator="exact",
                    rtol=None, end_only=scene.end_only, tolerance_rad=tolerance, kappa=1.0, dropped_bound_rad=0.0,
                    full=not skip, decisions=decisions)
    source = choose_orbit_source(scene, skip, decisions)
    kappa = attitude_sensitivity(scene.state, span)
    momentum = np.linalg.norm(scene.state.angular_momentum.value) / moments[0]
    estimates, survey, survey_note = survey_perturbers(scene, source, kappa, momentum, moments, keep=skip)
    samples = survey if scene.keeps_survey(source, skip) else None
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
        return Plan(route="torque-free", orbit_source=source, kept=(), dropped=tuple(names), estimates=estimates,
                    integrator="exact", rtol=None, end_only=scene.end_only, tolerance_rad=tolerance, kappa=kappa,
                    dropped_bound_rad=total, full=False, decisions=decisions)
    route, back_reaction, bound, coupling = choose_coupling(scene, skip, source, kappa, momentum, moments, survey)
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
        eps = first_tolerance("rebound-bs", tolerance)
        decisions.append(Decision("integrator", f"REBOUND BS, eps {eps:.1e}, rotation as a user ODE (checked a "
                                  f"posteriori against a run at {CHECK_RTOL_FACTOR:g}× eps)",
                                  "BS is the one REBOUND integrator that integrates a user ODE together with the "
                                  "orbits (docs/coupling.md); eps within "
                                  f"{COUPLED_EPS_RANGE[0]:g}…{COUPLED_EPS_RANGE[1]:g} since it controls the orbits too"))
        return Plan(route="coupled", orbit_source="rebound", kept=tuple(names), dropped=(), estimates=estimates,
                    integrator="rebound-bs", rtol=eps, end_only=scene.end_only, tolerance_rad=tolerance, kappa=kappa,
                    dropped_bound_rad=0.0, full=not skip, decisions=decisions, back_reaction_bound_rad=bound)
    share = tolerance - used - back_reaction
    kept = tuple(n for n in names if n not in dropped)
    integrator, reason = choose_integrator(scene, skip, source, kept, share)
    rtol = first_tolerance(integrator, share)
    what, knob = ("Taylor (core.integrate_taylor)", "tol") if integrator == "taylor" else (
        f"{integrator} DOP853", "rtol")
    decisions.append(Decision("integrator", f"{what}, {knob} {rtol:.1e} (checked a posteriori "
                              f"against a run at {CHECK_RTOL_FACTOR:g}× {knob})", reason))
    return Plan(route="one-way", orbit_source=source, kept=kept, dropped=tuple(dropped), estimates=estimates,
                integrator=integrator, rtol=rtol, end_only=scene.end_only, tolerance_rad=tolerance, kappa=kappa,
                dropped_bound_rad=used, full=not skip, decisions=decisions, samples=samples,
                back_reaction_rad=back_reaction, back_reaction_bound_rad=bound)


def shape_decision(scene, skip=True):
    """Which form of the exact free flow the torque-free route runs (the dispatch of ``core.free_motion.flow``).

    ``skip=False`` (the reference plan) runs the elliptic flow for every body, so that the closed
    form's saving and agreement can be measured against it.
    """
    from spinorbit.core.free_motion.regular_precession import (
        NO_SYMMETRY_AXIS,
        symmetry_axis,
    )

    big_a, big_b, big_c = scene.state.body.principal_moments
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
    mode = scene.state.mode
    _, momentum = scene.state.principal_attitude_and_momentum()
    if mode == "permanent rotation" and momentum[1] == 0.0:  # exactly about A or C
        return Decision("closed form", "elliptic free flow at parameter 0 (exact)",
                        "the spin is exactly along the A or C axis (a permanent rotation): the flow's SAM or LAM "
                        "formulas of zero amplitude give the uniform rotation")
    if mode == "permanent rotation":
        return Decision("closed form", "uniform rotation (no elliptic functions)",
                        "the spin is exactly along the intermediate axis B (a permanent rotation; spin along A or "
                        "C takes the elliptic flow at parameter 0)")
    asymmetry = min(big_b - big_a, big_c - big_b) / big_c
    wobble = float(min(np.hypot(momentum[0], momentum[1]), np.hypot(momentum[1], momentum[2]))
                   / np.linalg.norm(momentum))
    return Decision("closed form", f"elliptic free flow, {mode} (exact; no approximate form taken)",
                    f"triaxial body (smallest moment gap / C = {asymmetry:.3g}, wobble sin(angle of M from the A or C axis) = {wobble:.3g}): "
                    "Jacobi functions and the secular pn of eq. (12). A regular precession or small-wobble "
                    "approximation would make a phase error that grows with the span and has no tested bound "
                    "here, so it is not used")


def choose_orbit_source(scene, skip, decisions):
    if not scene.named:
        return "none"
    kind = scene.orbit.kind
    if kind != "rebound":
        decisions.append(Decision("orbits", f"{kind} positions, no N-body integration",
                                  f"the body's orbit is given ({kind}) and the perturbers are DE421 bodies"))
        return kind
    from spinorbit.ephemeris import DE421_SPAN_JD_TDB, KNOWN_BODIES
    from spinorbit.time import J2000_JD_TDB

    lo, hi = (jd - J2000_JD_TDB for jd in DE421_SPAN_JD_TDB)
    inside = lo <= scene.epoch_day and scene.output_days[-1] <= hi
    known = scene.orbit.name.lower() in KNOWN_BODIES and all(n in KNOWN_BODIES for n in scene.named)
    if skip and known and inside:
        decisions.append(Decision("orbits", "DE421 positions instead of the REBOUND (N-body) run",
                                  f"'{scene.orbit.name}' and every perturber are DE421 bodies and the span lies "
                                  "inside DE421 (1900-2200): the ephemeris is the orbit the N-body run would "
                                  "reproduce (to metres, docs/ephemeris.md)"))
        return "de421"
    why = ("skip=False (reference run)" if not skip else
           f"'{scene.orbit.name}' is not a DE421 body: its orbit is known only through the simulation"
           if scene.orbit.name.lower() not in KNOWN_BODIES else "a perturber or the span is outside DE421")
    decisions.append(Decision("orbits", "REBOUND (N-body) run, perturbers from the same run", why))
    return "rebound"


def survey_perturbers(scene, source, kappa, momentum, moments, keep=True):
    """Per-perturber bounds (:mod:`spinorbit.scene.bounds`) from a survey of the distances.

    ``keep``: for a REBOUND orbit, survey at the run's tolerance so that the run can reuse it
    (:meth:`~spinorbit.scene.Scene.keeps_survey`; the reference plan, ``keep=False``, keeps nothing, so a full run pays its
    own sampling). Returns the estimates, the survey of the named perturbers (None without any; the
    back-reaction bound reads the same survey) and what the bound was (the free-motion bound, or why
    the worst-attitude one).
    """
    from spinorbit.core.model.perturbers import fixed_source

    t_end = scene.output_days[-1]
    survey = None
    surveys = []
    if scene.named:
        # With a REBOUND orbit every sampling pass is an N-body run, whose cost hardly depends on the
        # tolerance (the pilot and the run dominate): survey at the run's tolerance and keep it.
        # With an ephemeris, sampling costs per perturber: survey loosely, sample only the kept.
        keep = scene.keeps_survey(source, keep)
        survey = scene.sample_perturbers(source, scene.named, survey_tolerance(keep, scene.sample_tolerance))
        surveys.append(survey)
    if scene.moving:  # user ephemerides: like an ephemeris, surveyed loosely, the kept sampled for the run
        surveys.append(scene.sample_perturbers("user", [p.name for p in scene.moving], SURVEY_TOLERANCE))
    # Per perturber: (name, closest, its source, its survey days, |N|_max/A on them).
    rows = []
    for samples in surveys:
        distances = np.linalg.norm(samples.states[:, :, :3], axis=2)
        for i, (name, torque_source) in enumerate(zip(samples.names, samples.sources())):
            rows.append((name, float(distances[:, i].min()), torque_source, samples.days,
                         max_torque_over_a(moments, samples.gm[i], distances[:, i])))
    ends = np.array([scene.epoch_day, t_end])
    for fixed in scene.fixed:
        r = float(np.linalg.norm(fixed.position_au))
        rows.append((fixed.name, r, fixed_source(fixed.gm_au3_day2, fixed.position_au), ends,
                     max_torque_over_a(moments, fixed.gm_au3_day2, np.array([r, r]))))
    worst = [dropped_torque_bound(days, n, t_end, kappa, momentum) for _, _, _, days, n in rows]
    bounds, note = free_motion_bounds(scene.state, scene.epoch_day, t_end, [row[2:] for row in rows], worst,
                                      max((s.tolerance for s in surveys), default=0.0), kappa)
    estimates = {name: PerturberEstimate(name=name, closest_au=closest, bound_rad=bound, kept=True,
                                         worst_attitude_rad=w)
                 for (name, closest, *_), bound, w in zip(rows, bounds, worst)}
    return estimates, survey, note


def choose_coupling(scene, skip, source, kappa, momentum, moments, survey):
    """One-way or fully coupled: (route, back-reaction left out (rad), its bound (rad or None), decisions).

    ``survey`` is the planning survey of the named perturbers (:func:`survey_perturbers`), read here
    rather than sampled again. The bound (:func:`spinorbit.scene.bounds.back_reaction_bound`) needs the
    figure's absolute size and the body's mass; a massless body in the orbit model has none to estimate.
    """
    choice = "one-way (the rotation does not act on the orbits)"
    gm_body = scene.gm_in_orbit_model
    if gm_body == 0.0:
        return "one-way", 0.0, None, [Decision(
            "coupling", choice,
            "the body is massless in the orbit model (a test particle or a given ephemeris), so its figure cannot "
            "act on the orbits; for a real small body that force is of relative size (C-A)/(M r²) ~ J2 (R/r)², "
            "≈ 1e-13 for a 300 m asteroid at 1 au (coupling/one_way.py)")]
    if scene.moments_per_mass is None:
        return "one-way", 0.0, None, [Decision(
            "coupling", choice + "; back-reaction NOT estimated",
            f"'{scene.orbit.name}' has mass in the orbit model but a Scene knows only its moment ratios (give "
            "RigidBody the moments in kg m² and the mass for the estimate); for the Moon the back-reaction was "
            "measured at ≈ 0.1 arcsec over a year (docs/coupling.md: 0.305 one-way vs 0.207 arcsec coupled)")]
    big_a, _, big_c = scene.moments_per_mass
    if survey is None:  # only user perturbers were surveyed: the (empty) named set gives the survey grid
        kept_for_the_run = scene.keeps_survey(source, skip)
        survey = scene.sample_perturbers(source, scene.named, survey_tolerance(kept_for_the_run, scene.sample_tolerance))
    distances = np.linalg.norm(survey.states[:, :, :3], axis=2)
    bound, displacement = back_reaction_bound(survey.days, distances, survey.gm, gm_body, big_c - big_a, moments,
                                              scene.output_days[-1], kappa, momentum)
    au_km = float((1 * u.au).to_value(u.km))
    numbers = (f"figure (C-A)/M = ({math.sqrt(big_c - big_a) * au_km:.3g} km)², G·M = {gm_body:.3g} au³/day²: "
               f"the figure's force moves the perturber vectors by at most {float(np.max(displacement)) * au_km:.3g} "
               f"km and so the attitude by at most {bound * ARCSEC_PER_RAD:.3g} arcsec over the span "
               "(planner: back-reaction bound)")
    if source == "de421" and scene.orbit.name == "moon":
        return "one-way", 0.0, bound, [Decision(
            "coupling", choice + "; the back-reaction is in the ephemeris",
            "DE421 integrated the lunar orbit together with the lunar figure (Williams et al. 2008), so its orbits "
            "already hold what a coupled run adds; " + numbers)]
    share = DROP_SHARE * scene.tolerance_rad
    runnable = scene.coupled_runnable()
    coupled = "fully coupled: REBOUND with the figure's force on the orbits (CoupledRigidBody, coupled=True)"
    if runnable:
        # Given a REBOUND orbit, the coupled BS run needs no sampling, so it is the cheap route.
        why = "skip=False (reference run): nothing left out; " if not skip else (
            "with a REBOUND orbit the coupled run is also the cheaper one (it needs no sampling: faster than "
            "one-way in every REBOUND scene of bench_scene_skips, docs/performance.md) and leaves nothing out; ")
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
    user = [p.name for p in (*scene.fixed, *scene.moving)]
    what = (f"the perturbers {user} are not particles of a REBOUND simulation" if user else
            f"the orbit is {scene.orbit.kind!r}, not a REBOUND simulation")
    raise PlanError(
        f"the back-reaction bound {bound * ARCSEC_PER_RAD:.3g} arcsec exceeds {DROP_SHARE:g} × tolerance "
        f"({share * ARCSEC_PER_RAD:.3g} arcsec), so one-way coupling is not within the tolerance; a coupled run "
        f"needs every orbit in one REBOUND simulation, but {what}. Give orbit=Orbit.rebound(sim, "
        f"'{scene.orbit.name}') with the body and its perturbers as particles (e.g. from simulation_from_de421), "
        "or loosen the tolerance.")
