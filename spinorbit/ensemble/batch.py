"""The ensemble's batch route: members that share a plan are planned once and integrated together at the core.

A chunk's members whose Scenes agree on everything the plan depends on except the rotation state and
the body's moments (:func:`group_key`: the same orbit object, perturbers, epoch, output time,
tolerances, quantities and integrator option) form a **group**. The group's plan is the Scene plan of
its *leader* (:meth:`~spinorbit.scene.Scene.plan`, taken with what follows from it as a
:class:`GroupPlan`): its route, its perturbers kept and dropped, its integrator. The ensemble names
the leader (:func:`spinorbit.ensemble.ensemble.run_chunk`: its member 0 where it fits the group, else
the group's first member). Every member of the group then gets, from its own state and moments,

- its **bounds**: the worst-attitude bound of every perturber
  (:func:`~spinorbit.scene.bounds.dropped_torque_bound` on the group's shared survey, with the member's
  |L|/A, moments and attitude sensitivity κ, :func:`~spinorbit.scene.bounds.attitude_sensitivities`:
  the planner's κ, from the exact free flow of every member and of its three kicked states in one
  vectorised call). The worst-attitude bound is never below the free-motion bound a Scene may take,
  so a drop it allows is a drop the member may take;
- the group's **drops, if they hold for it**: the bounds of the leader's dropped perturbers must fit
  in :data:`~spinorbit.scene.tolerances.DROP_SHARE` × tolerance for this member, else the member runs
  through its own Scene (the per-member route). So does a member whose perturbers together stay below
  the tolerance (its own Scene would take the torque-free route) or whose free flow would leave its
  domain;
- its **tolerances**: the integration share (tolerance − its dropped bound) and from it the first
  rtol (:func:`~spinorbit.scene.tolerances.first_tolerance`), the a posteriori check at
  :data:`~spinorbit.scene.tolerances.CHECK_RTOL_FACTOR` × rtol and the retries of
  :func:`~spinorbit.scene.tolerances.refine`, member by member;
- its **error estimate**: dropped bound + integration (the run against the check) + sampling
  (:func:`~spinorbit.scene.tolerances.sampling_error_bound` of its kept bounds), as
  :func:`spinorbit.scene.routes.run_one_way` sums them.

What the group shares is what the plan shares: the samples (the chunk's
:class:`~spinorbit.scene.sampling.SharedSamples`), the kept sources and the integrator. The members
are integrated together by a **batch integrator** (:data:`BATCH_INTEGRATORS`, by the plan's integrator
name; any function with :func:`~spinorbit.core.integrators.batch_quaternion.integrate_quaternion_batch`'s
signature can be plugged in), each on its own model array (its moments in front of the group's
perturber block), and the outcome row is computed from the core end state directly: no result table.

Where the member's own plan would take the group's decisions (the same kept perturbers and
integrator; always when the group drops nothing, as in the Apophis encounter), its integration is
the Scene's to the last bit (the batch DOP853 is the scalar one per lane) and so are its outcome
columns, and so is its error estimate (the same κ, bounds, run and check). Where the leader's
plan differs from the member's own (a member that would drop a perturber the leader keeps, or take
the Taylor method), the row is the group plan's, whose error estimate holds for the member all the
same: it is made of the member's own bounds and its own a posteriori check. Which members ran where
is in the table's ``meta["member_routes"]``.

A group's leader is fixed by the ensemble, not by where its chunk runs, so its rows do not depend on
the executor or the number of workers. A member that fails (its bounds, or its integration stopping)
is recorded alone; a batch call that refuses its input as a whole sends its members to the
per-member route, where each fails or runs on its own.
"""

from __future__ import annotations

import numpy as np
from astropy import units as u

from spinorbit.core.integrators.batch_quaternion import integrate_quaternion_batch

__all__ = ["BATCH_INTEGRATORS", "GroupPlan", "group_key", "plan_group", "run_group"]

#: The batch integrator of each plan integrator: a function with integrate_quaternion_batch's signature
#: ``(y0s, t0, t_end, models, rtol, ...) -> (end states (N, 7), stats dict of (N,) arrays)``. A plan
#: whose integrator has none here runs through the per-member route.
BATCH_INTEGRATORS = {"quaternion": integrate_quaternion_batch}

#: The scale factors of astropy's conversions of the error estimate (rad → arcsec, and back for the
#: tolerance check): ``(x * u.rad).to(u.arcsec)`` multiplies x by the first, so the plain products are the
#: Scene's Quantity values bit for bit (tests/test_ensemble_batch.py), without two Quantities per member.
ARCSEC_PER_RAD = u.rad.to(u.arcsec)
RAD_PER_ARCSEC = u.arcsec.to(u.rad)


def group_key(scene, at_days):
    """What the members of one group share (a hashable key), or None when the scene cannot be batched.

    Batched: a single-body scene, all output times after the epoch, one output time (the batch
    integrators return end states) at which the outcome is asked, and no back-reaction to bound
    (massless in the orbit model, or moments known only as ratios). The key holds every input the plan
    reads besides the state and the moments; objects (orbit, perturbers) by identity, as the chunk's
    sharing key.
    """
    if scene.members is not None or scene.in_legs or not scene.end_only:
        return None
    if at_days is not None and not (at_days.size == 1 and abs(float(at_days[0]) - float(scene.output_days[-1])) <= 1e-9):
        return None
    if scene.moments_per_mass is not None and scene.gm_in_orbit_model != 0.0:
        return None
    return (id(scene.orbit), tuple(scene.named), tuple(id(p) for p in scene.fixed), tuple(id(p) for p in scene.moving),
            float(scene.epoch_day), float(scene.output_days[-1]), scene.tolerance_rad, scene.sample_tolerance,
            tuple(scene.quantities), scene.integrator)


def _survey(leader, plan):
    """[(name, survey days, 1.5 μ / r³ per unit (C − A)/A, source kind)] of the leader's survey (the chunk's
    shared samples: the requests :func:`spinorbit.scene.planning.survey_perturbers` made)."""
    from spinorbit.scene.tolerances import SURVEY_TOLERANCE, survey_tolerance

    rows = []
    surveys = []
    if leader.named:
        keep = leader.keeps_survey(plan.orbit_source, True)
        surveys.append(leader.sample_perturbers(plan.orbit_source, leader.named,
                                                survey_tolerance(keep, leader.sample_tolerance)))
    if leader.moving:
        surveys.append(leader.sample_perturbers("user", [p.name for p in leader.moving], SURVEY_TOLERANCE))
    for samples in surveys:
        distances = np.linalg.norm(samples.states[:, :, :3], axis=2)
        for i, name in enumerate(samples.names):
            rows.append((name, samples.days, samples.gm[i], distances[:, i]))
    ends = np.array([leader.epoch_day, leader.output_days[-1]])
    for fixed in leader.fixed:
        r = float(np.linalg.norm(fixed.position_au))
        rows.append((fixed.name, ends, fixed.gm_au3_day2, np.array([r, r])))
    return rows


def _member_bounds(survey, t_end, moments, momenta, kappas):
    """{name: worst-attitude bound (rad)} of every member: the planner's dropped_torque_bound on the survey,
    each perturber's for all members at once (:func:`~spinorbit.scene.bounds.dropped_torque_bounds`: every
    member's value the bits of its own call). ``moments`` (N, 3) principal, ``momenta`` (N, 3) I ω in user
    axes (rad/day), ``kappas`` (N,)."""
    from spinorbit.scene.bounds import dropped_torque_bounds, max_torque_over_a

    over_a = _row_norms(momenta) / moments[:, 0]  # |L|/A as the planner takes it
    columns = {}
    for name, days, gm, r in survey:
        torque = max_torque_over_a(moments.T[:, :, None], gm, r)  # (N, samples): each member's moments
        columns[name] = dropped_torque_bounds(days, torque, t_end, kappas, over_a)
    return [{name: float(column[m]) for name, column in columns.items()} for m in range(len(moments))]


def _row_norms(vectors):
    """np.linalg.norm of each row (N, 3) as of the row alone: √(x·x) with the one-row dot of each."""
    return np.sqrt(np.matmul(vectors[:, None, :], vectors[:, :, None]))[:, 0, 0]


def _kept_sources(leader, plan):
    """The sources of the leader's run (:func:`spinorbit.scene.routes.one_way_sources`, in its order), the
    samples, and whether a sampled perturber is kept (then the error estimate has a sampling part)."""
    from spinorbit.scene.routes import one_way_sources

    samples, extra, named, moving = one_way_sources(leader, plan)
    return [*samples.sources(), *extra], samples, bool(named or moving)


def _models(moments, sources):
    """Each member's model array, twice (run and check lanes: rows m and N + m): make_model's array of the
    first member with each member's principal moments written into the figure's A, B, C slots (make_body
    stores them as given, and every other figure entry is the group's: the bits of make_model for that
    member; tests/test_ensemble_batch.py). ValueError, as make_body's, for moments it would refuse."""
    from spinorbit.core.dynamics.equations import make_model
    from spinorbit.core.model.gravity_field import BODY_A, BODY_C

    moments = np.array(moments, dtype=float)
    good = np.all(np.isfinite(moments) & (moments > 0.0), axis=1) & np.all(np.diff(moments, axis=1) >= 0.0, axis=1)
    if not np.all(good):
        raise ValueError(f"moments: expected finite positive principal moments A ≤ B ≤ C for every member; got "
                         f"{moments[~good][0].tolist()}. Give each member's moments as RigidBody.principal_moments.")
    first = make_model(moments[0], sources)
    models = np.empty((2 * len(moments), first.size))
    models[:] = first
    models[:, BODY_A:BODY_C + 1] = np.concatenate([moments, moments])
    return models


def _same_axes(bodies):
    """Whether every body has the first one's principal axes (then their rows take one vectorised call)."""
    p = bodies[0].to_principal.tobytes()
    return all(body.to_principal.tobytes() == p for body in bodies)


def _integrate(integrator, function, bodies, y0s, t0, t_end, models, rtols, shares):
    """refine() of every member: run, check at 10×, retry 100× tighter while the difference misses its share.

    The run and the check of the pending members go through one batch call (a member's lane-mates do
    not change its bits); ``models`` (2N, M) holds each member's model twice (run, check). Returns (end
    states, integration errors, statuses) per member; a member whose run or check stopped has a
    non-zero status.
    """
    from spinorbit.coupling.one_way import one_way_quaternions
    from spinorbit.scene.routes import attitude_angles
    from spinorbit.scene.tolerances import ACCEPTED_SHARE, MAX_RTOL_RETRIES, RETRY_FACTOR, RULES, check_tolerance

    n = len(bodies)
    lowest = RULES[integrator].lowest
    same_axes = _same_axes(bodies)
    ends, errors, status = np.full((n, 7), np.nan), np.full(n, np.nan), np.zeros(n, dtype=np.int64)
    tolerances = np.array(rtols, dtype=float)
    pending = np.arange(n)
    for _ in range(MAX_RTOL_RETRIES + 1):
        k = pending.size
        checks = np.array([check_tolerance(integrator, t) for t in tolerances[pending]])
        lanes = models if k == n else models[np.concatenate([pending, n + pending])]
        both, stats = function(np.concatenate([y0s[pending]] * 2), t0, t_end, lanes,
                               np.concatenate([tolerances[pending], checks]))
        codes = np.where(stats["status"][:k] != 0, stats["status"][:k], stats["status"][k:])
        status[pending] = codes
        done = np.flatnonzero(codes == 0)  # lanes j of the pending members whose run and check both finished
        ends[pending[done]] = both[done]
        if same_axes and done.size:  # every row's attitude and angle as in its own call (row-wise kernels)
            quaternions = one_way_quaternions(bodies[0], np.concatenate([both[done], both[k + done]]))
            errors[pending[done]] = attitude_angles(quaternions[:done.size], quaternions[done.size:])
        else:
            for j in done:
                body = bodies[pending[j]]
                errors[pending[j]] = float(np.max(attitude_angles(one_way_quaternions(body, both[j:j + 1]),
                                                                  one_way_quaternions(body, both[k + j:k + j + 1]))))
        retry = [int(m) for m in pending[done]
                 if not (errors[m] <= ACCEPTED_SHARE * shares[m] or tolerances[m] <= lowest)]
        if not retry:
            break
        pending = np.array(retry)
        tolerances[pending] = np.maximum(tolerances[pending] / RETRY_FACTOR, lowest)
    return ends, errors, status


def _motion_summaries(momenta, moments):
    """(mode names, E/E0, P_ψ, P_φ, P_sid in h) of principal body momenta (N, 3), each with its moments:
    the kernel of RotationState's properties and of the table's motion columns (motion_summary), per row."""
    from spinorbit.core.free_motion.members import motion_summary_each
    from spinorbit.state import MODE_NAMES

    n = momenta.shape[0]
    modes, ratios, p_psi, p_phi, p_sidereal = np.empty(n, dtype=np.int64), *(np.empty(n) for _ in range(4))
    motion_summary_each(np.ascontiguousarray(momenta), np.ascontiguousarray(moments), modes, ratios, p_psi, p_phi,
                        p_sidereal)
    hours = u.day.to(u.h)  # (p * u.day).to(u.h) of the table and of the properties: p × 24, the same bits
    return [MODE_NAMES[int(c)] for c in modes], ratios, p_psi * hours, p_phi * hours, p_sidereal * hours


class _Stacked:
    """The members' bodies as one body for state_table's row functions: their shared principal axes and each
    row's own moments (rows (N, 3); those functions take the moments elementwise, row by row)."""

    def __init__(self, to_principal, moment_values):
        self.to_principal, self.moment_values = to_principal, moment_values


def _start_poles(states, momenta):
    """RotationState.angular_momentum_direction of every state, its user momenta ``momenta`` (N, 3) given:
    Rᵀ (I ω) / |…| with each row's product and norm the same one-row BLAS calls as the property's."""
    attitudes = np.array([state.attitude_matrix for state in states])
    inertial = np.matmul(np.swapaxes(attitudes, 1, 2), momenta[:, :, None])[:, :, 0]  # (3, 3)ᵀ @ (3,) per row
    return inertial / _row_norms(inertial)[:, None]


def _rows(scenes, ends, normals, moments, momenta):
    """The outcome values of every member's end state (principal axes) and its initial state, plain values
    in the outcome units, as the Scene's one-row table and outcome_row would hold them. ``moments`` (N, 3)
    principal, ``momenta`` (N, 3) the initial I ω in user axes (rad/day).

    Members with the same principal axes (the same P, as in every ensemble of one body's moment ratios)
    take state_table's functions once for all their rows: each row's numbers are its one-row call's (row-wise
    kernels and one BLAS call per row). Others are taken member by member.
    """
    from spinorbit import pole as _pole
    from spinorbit.state import InvalidStateError
    from spinorbit.state_table import from_principal, pole_directions, unit_quaternions

    states = [scene.state for scene in scenes]
    p = states[0].body.to_principal
    if _same_axes([state.body for state in states]):
        values = np.array([state.body.moment_values for state in states])
        quaternions, omegas = from_principal(states[0].body, ends)
        directions = pole_directions(_Stacked(p, values), unit_quaternions(quaternions), omegas)
        end_momenta = np.matmul((values * omegas)[:, None, :], p.T)[:, 0]  # the table's P (I ω), row by row
        start_momenta = np.matmul(p, momenta[:, :, None])[:, :, 0]  # the properties' momentum P (I ω)
        start_poles = _start_poles(states, momenta)
    else:
        directions, end_momenta, start_momenta, start_poles = [], [], [], []
        for state, end in zip(states, ends):  # each member's own body (its axes, its moments)
            body = state.body
            quaternions, omegas = from_principal(body, end[None, :])
            directions.append(pole_directions(body, unit_quaternions(np.atleast_2d(quaternions)), omegas)[0])
            end_momenta.append(((body.moment_values * omegas) @ body.to_principal.T)[0])  # the table's P (I ω)
            start_momenta.append(state.principal_attitude_and_momentum()[1])  # the properties' momentum
            start_poles.append(state.angular_momentum_direction)
        directions = np.array(directions)
    ra, dec, lon, lat = _pole.pole_angles_deg(directions)  # row by row (no BLAS): a member's bits are its own
    values = {"pole_ra": ra, "pole_dec": dec, "pole_lon": lon, "pole_lat": lat}
    if normals is not None:
        values["obliquity"] = _pole.obliquity_deg(directions, np.broadcast_to(normals, directions.shape))
    if "periods" in scenes[0].quantities:
        values.update(zip(("mode", "energy_ratio", "P_psi", "P_phi", "sidereal_period"),
                          _motion_summaries(np.array(end_momenta), moments)))
    values["pole_shift"] = _pole.angle_between_deg(_pole.directions_from_ra_dec_deg(ra, dec), np.array(start_poles),
                                                   "the pole", "the start pole")
    initial = _motion_summaries(np.array(start_momenta), moments)
    if not np.all(np.isfinite(np.abs(initial[2]) + np.abs(initial[3]))
                  | np.isinf(initial[2]) | np.isinf(initial[3])):
        raise InvalidStateError("the periods of a member's initial state are not computable in float64; express the "
                                "moments and spin nearer 1.")
    rows = []
    for m in range(len(scenes)):
        row = {name: (v[m] if isinstance(v[m], str) else float(v[m])) for name, v in values.items()}
        row.update(P_psi_initial=float(initial[2][m]), P_phi_initial=float(initial[3][m]),
                   sidereal_period_initial=float(initial[4][m]), energy_ratio_initial=float(initial[1][m]))
        rows.append(row)
    return rows


class GroupPlan:
    """What a group takes from its leader (:func:`plan_group`): the leader Scene, its plan, its perturber
    survey, the kept sources (and whether a sampled one is among them), the orbit normals and the run's days."""

    def __init__(self, leader, plan, survey, sources, sampled, normals, t0, t_out):
        self.leader, self.plan, self.survey, self.sources, self.sampled = leader, plan, survey, sources, sampled
        self.normals, self.t0, self.t_out = normals, t0, t_out


def plan_group(leader, shared, integrators=None):
    """The :class:`GroupPlan` of the Scene ``leader`` planned within the samples ``shared``, or None when its
    plan cannot be shared by the batch route (the plan fails, is not a one-way run on a batch integrator,
    bounds a back-reaction, or its samples do not cover the run): its group then runs member by member."""
    from spinorbit.coupling.one_way import one_way_days
    from spinorbit.scene.routes import scene_orbit_normals
    from spinorbit.time import time_from_tdb_days

    integrators = BATCH_INTEGRATORS if integrators is None else integrators
    with leader.sharing_samples(shared):
        try:
            plan = leader.plan()
        except Exception:  # noqa: BLE001 — the leader's own Scene run records it
            return None
        if (plan.route != "one-way" or plan.integrator not in integrators or plan.back_reaction_rad != 0.0
                or plan.back_reaction_bound_rad is not None):
            return None
        survey = _survey(leader, plan)
        sources, samples, sampled = _kept_sources(leader, plan)
        normals, _ = scene_orbit_normals(leader, plan) if leader.orbit is not None else (None, None)
        t0, t_out = one_way_days(time_from_tdb_days(leader.epoch_day), time_from_tdb_days(leader.output_days))
    lo, hi = samples.span
    if min(t0, t_out.min()) < lo or max(t0, t_out.max()) > hi:
        return None
    return GroupPlan(leader, plan, survey, sources, sampled, normals, t0, t_out)


def run_group(group, group_plan, at_days, integrators=None):
    """Run one group [(index, Scene, parameters)] of a chunk by the batch route, on its leader's ``group_plan``.

    Returns (rows, failures, fallback): outcome rows and the exceptions of failed members by index, and
    the members [(index, Scene, parameters)] that go to the per-member route (the plan cannot be shared
    with them). The members sample within the leader's samples (the plan's sources).
    """
    from spinorbit.core.integrators.dop853 import STATUS_MESSAGES, IntegrationError
    from spinorbit.scene.bounds import attitude_sensitivities
    from spinorbit.scene.tolerances import DROP_SHARE, first_tolerance, sampling_error_bound
    from spinorbit.state import MAX_FLOW_PHASE

    integrators = BATCH_INTEGRATORS if integrators is None else integrators
    rows, failures = {}, {}
    leader, plan, survey, normals = group_plan.leader, group_plan.plan, group_plan.survey, group_plan.normals
    sources, sampled, t0, t_out = group_plan.sources, group_plan.sampled, group_plan.t0, group_plan.t_out
    tolerance, span = plan.tolerance_rad, leader.span_days
    # members whose free flow over the span stays in its domain (attitude_sensitivity would refuse the others)
    fits = []
    for member in group:
        state = member[1].state
        momentum = np.linalg.norm(state.principal_attitude_and_momentum()[1])
        fits.append(bool(momentum > 0.0 and momentum / state.body.principal_moments[0] * span <= MAX_FLOW_PHASE))
    fallback = [m for m, ok in zip(group, fits) if not ok]
    group = [m for m, ok in zip(group, fits) if ok]
    if not group:
        return rows, failures, fallback
    states = [s.state for _, s, _ in group]
    # each member's plain values, read from its state once: principal moments, I ω (user axes, rad/day)
    moments = np.array([state.body.principal_moments for state in states])
    momenta = np.array([state.body.moment_values for state in states]) * np.array(
        [state.angular_velocity_rad_per_day for state in states])
    bounds = _member_bounds(survey, leader.output_days[-1], moments, momenta, attitude_sensitivities(states, span))
    batch, picked, used, kept_bounds = [], [], [], []
    for position, (member, bound) in enumerate(zip(group, bounds)):
        dropped = 0.0
        for name in plan.dropped:  # in the plan's order, as it summed them
            dropped += bound[name]
        # the group's drops must fit this member; a member below the tolerance altogether is its Scene's
        # (the torque-free route)
        if dropped > DROP_SHARE * tolerance or sum(bound.values()) <= tolerance:
            fallback.append(member)
            continue
        kept = 0.0
        for name in plan.kept:
            kept += bound[name]
        batch.append(member)
        picked.append(position)
        used.append(dropped)
        kept_bounds.append(kept)
    if not batch:
        return rows, failures, fallback
    scenes = [s for _, s, _ in batch]
    moments, momenta = moments[picked], momenta[picked]
    shares = np.array([tolerance - d - 0.0 for d in used])  # run_one_way: tolerance − dropped − back-reaction
    rtols = np.array([first_tolerance(plan.integrator, s) for s in shares])
    y0s = np.array([s.state.core_state() for s in scenes])
    try:
        ends, errors, status = _integrate(plan.integrator, integrators[plan.integrator],
                                          [s.state.body for s in scenes], y0s, t0, float(t_out[-1]),
                                          _models(moments, sources), rtols, np.maximum(shares, 0.0))
    except (ValueError, RuntimeError):  # the batch refused its input as a whole: each member on its own
        return rows, failures, fallback + batch
    ok = [m for m in range(len(batch)) if not status[m]]
    for m in range(len(batch)):
        if status[m]:
            failures[batch[m][0]] = IntegrationError(
                f"the batch {plan.integrator} integration stopped: {STATUS_MESSAGES[int(status[m])]}")
    if not ok:
        return rows, failures, fallback
    try:
        values = _rows([scenes[m] for m in ok], ends[ok], normals, moments[ok], momenta[ok])
    except Exception:  # noqa: BLE001 — a member the vectorised outcome refuses: each on its own Scene
        return rows, failures, fallback + [batch[m] for m in ok]
    suffix = "" if at_days is None else "_t0"  # the one named time is the end
    timed = ("pole_ra", "pole_dec", "pole_lon", "pole_lat", "obliquity", "mode", "energy_ratio", "P_psi", "P_phi",
             "sidereal_period", "pole_shift")
    for m, row in zip(ok, values):
        index, scene, _ = batch[m]
        sampling = sampling_error_bound(scene.sample_tolerance, kept_bounds[m]) if sampled else 0.0
        # Scene.run's sum and units: parts in run_one_way's order, the estimate in arcsec, met in rad
        total = ARCSEC_PER_RAD * sum({"dropped": used[m], "integration": float(errors[m]), "sampling": sampling,
                                      "back_reaction": plan.back_reaction_rad}.values())
        rows[index] = {**{(f"{k}{suffix}" if k in timed else k): v for k, v in row.items()},
                       "error_estimate": float(total), "tolerance_met": bool(RAD_PER_ARCSEC * total <= tolerance),
                       "route": plan.route}
    return rows, failures, fallback
