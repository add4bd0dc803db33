"""The route runners: what :meth:`spinorbit.scene.Scene.run` does for each route of a plan.

- **torque-free** (:func:`run_torque_free`): the exact free motion at the output times, no integration;
- **one-way** (:func:`run_one_way`): :func:`spinorbit.coupling.one_way.propagate_one_way` under the
  kept perturbers with the plan's integrator (Taylor, quaternion or element DOP853);
- **coupled** (:func:`run_coupled`): REBOUND's BS with the rotation as a user ODE and the figure's
  force on the orbits (:func:`spinorbit.coupling.rigid_body.coupled_run`).

The integrating routes check themselves a posteriori against a second run at a looser tolerance and
tighten theirs while the difference misses its share (:func:`spinorbit.scene.tolerances.refine`).
Each runner returns ``(table, error_parts, stats)``: the result table, the error estimate's parts (rad)
and the integrator's and sampler's statistics.
"""

from __future__ import annotations

import numpy as np
from astropy import units as u
from astropy.table import QTable

from spinorbit.scene.sampling import NoSamples, subset_samples
from spinorbit.scene.tolerances import MAX_RTOL_RETRIES, refine, sampling_error_bound
from spinorbit.state_table import OMEGA_COLUMNS, from_principal, table_columns, time_column
from spinorbit.time import time_from_tdb_days

__all__ = ["attitude_angles", "one_way_sources", "result_table", "run_coupled", "run_one_way", "run_torque_free",
           "scene_orbit_normals"]


def attitude_angles(q1, q2):
    """Rotation angle (rad) between two attitude quaternion series (q and −q are one attitude)."""
    from spinorbit.core.math.rotations import rotation_angle_between_many

    return rotation_angle_between_many(np.ascontiguousarray(np.atleast_2d(q1), dtype=float),
                                       np.ascontiguousarray(np.atleast_2d(q2), dtype=float))


def result_table(scene, quaternions, omegas, motion="rows"):
    """The result table of user-axes rows (quaternions, ω in rad/day), all rows at once.

    ``motion``: "rows" computes mode, E/E0 and the periods per row; a RotationState takes them once
    from it (constants of the torque-free motion). Only the quantities the scene asks for are filled in.
    """
    table = QTable()
    table["time"] = time_column(scene.output_days)
    for name, column in table_columns(scene.state.body, quaternions, omegas, omega="omega" in scene.quantities,
                                      motion=motion if "periods" in scene.quantities else None).items():
        table[name] = column
    return table


def scene_orbit_normals(scene, plan):
    """Unit normals of the body's heliocentric orbit plane at the output times, or (None, why not).

    From the Sun sampled relative to the body on the scene's orbit (the samples a run already took at
    the scene's sample tolerance are reused; :func:`spinorbit.coupling.one_way.heliocentric_normals`).
    """
    from spinorbit.coupling.one_way import heliocentric_normals

    from spinorbit.scene.sampling import sample_perturbers

    if scene.orbit is None:
        return None, "the scene has no orbit"
    # the plan's orbit source when it names one ("de421" for a DE421 body given as a REBOUND particle),
    # else the orbit's own kind
    source = plan.orbit_source if plan.orbit_source in ("de421", "ephemeris", "rebound") else scene.orbit.kind
    start = min(scene.epoch_day, float(scene.output_days[0]))
    try:
        if start == scene.epoch_day:  # the span the run sampled: reuse its samples
            samples = scene.sample_perturbers(source, ("sun",), scene.sample_tolerance)
        else:  # output times before the epoch: the Sun over all of them
            samples = sample_perturbers(scene.orbit, scene.moving, start, float(scene.output_days[-1]), source,
                                        ("sun",), scene.sample_tolerance)
        return heliocentric_normals(samples, scene.output_days), None
    except (LookupError, ValueError) as error:  # no "sun" particle (MissingBodyError), outside DE421, …
        return None, f"the Sun could not be sampled on the scene's orbit ({type(error).__name__}: {error})"


def run_torque_free(scene, plan):
    """The exact free motion at the scene's output times: its table, error parts and (no) statistics."""
    offsets = scene.output_days - scene.epoch_day
    quaternions, omegas = scene.state.propagate_torque_free(offsets * u.day, closed_forms=not plan.full)
    # Mode, E/E0 and the periods are constants of the torque-free motion: the initial state's, once.
    table = result_table(scene, quaternions, omegas.to_value(u.rad / u.day), motion=scene.state)
    return table, {"dropped": plan.dropped_bound_rad, "integration": 0.0, "sampling": 0.0}, {}


def one_way_sources(scene, plan):
    """What the one-way run integrates under: (samples of the kept named perturbers, or NoSamples; the extra
    sources of the kept fixed perturbers and user ephemerides; the kept named and user names).

    The model's sources are ``[*samples.sources(), *extra]``, in that order (:func:`run_one_way`, and the
    ensemble's batch route, which builds one such model per member).
    """
    from spinorbit.core.model.perturbers import fixed_source

    named = tuple(n for n in plan.kept if n in scene.named)
    fixed = [fixed_source(p.gm_au3_day2, p.position_au) for p in scene.fixed if p.name in plan.kept]
    moving = [p.name for p in scene.moving if p.name in plan.kept]
    if moving:
        fixed += scene.sample_perturbers("user", moving, scene.sample_tolerance).sources()
    if named and plan.samples is not None:
        samples = subset_samples(plan.samples, named)
    else:
        samples = scene.sample_perturbers(plan.orbit_source, named, scene.sample_tolerance) if named else None
    if samples is None:
        samples = NoSamples(scene.epoch_day, scene.output_days[-1])
    return samples, fixed, named, moving


def run_one_way(scene, plan, report):
    """The one-way integration under the plan's kept perturbers, checked a posteriori; ``report(fraction)``."""
    from spinorbit.coupling.one_way import integrate_one_way, one_way_days, one_way_quaternions, one_way_table

    samples, fixed, named, moving = one_way_sources(scene, plan)
    report(0.3)
    epoch = time_from_tdb_days(scene.epoch_day)
    t0, t_out = one_way_days(epoch, time_from_tdb_days(scene.output_days))  # propagate_one_way's days, once
    body = scene.state.body

    def run_and_check(rtol, check_rtol):
        # Both integrations of propagate_one_way, compared on the attitudes its table would hold; only the
        # accepted run becomes a table (the check needs none).
        run = integrate_one_way(scene.state, t0, t_out, samples, rtol, plan.integrator, fixed)
        check, _ = integrate_one_way(scene.state, t0, t_out, samples, check_rtol, plan.integrator, fixed)
        return run, float(np.max(attitude_angles(one_way_quaternions(body, run[0]), one_way_quaternions(body, check))))

    def attempted(attempt):
        report(0.3 + 0.7 * (attempt + 1) / (MAX_RTOL_RETRIES + 1))

    (ys, run_stats), integration, rtol = refine(plan.integrator, plan.rtol, max(plan.integration_share_rad, 0.0),
                                                run_and_check, attempted)
    run = one_way_table(body, epoch, t_out, ys, run_stats, samples, rtol, plan.integrator,
                        periods="periods" in scene.quantities)
    kept_bound = sum(plan.estimates[n].worst_or_bound_rad for n in plan.kept)
    sampling = sampling_error_bound(scene.sample_tolerance, kept_bound) if named or moving else 0.0
    if "omega" not in scene.quantities:
        run.remove_columns(list(OMEGA_COLUMNS))
    run.meta["rtol"] = rtol
    # DOP853 reports accepted/rejected/rhs_calls; Taylor steps (= accepted, 0 rejected), order, no RHS calls.
    stats = {k: run.meta[k] for k in ("accepted", "rejected", "rhs_calls", "steps", "order") if k in run.meta}
    stats.update(integrator=plan.integrator, rtol=rtol, samples=int(samples.days.size),
                 passes=int(getattr(samples, "passes", 0)))
    if samples.names:
        from spinorbit.coupling.one_way import closest_approaches

        run.meta["closest_approaches"] = {name: {"time": time_from_tdb_days(day).tdb.isot, "distance_au": distance}
                                          for name, (day, distance) in closest_approaches(samples).items()}
    return run, {"dropped": plan.dropped_bound_rad, "integration": integration, "sampling": sampling}, stats


def run_coupled(scene, plan, report):
    """The fully coupled REBOUND run (BS), checked a posteriori against a second run; ``report(fraction)``."""
    from spinorbit.coupling.long_run import coupled_run

    y0 = scene.state.core_state()

    def run_and_check(eps, check_eps):
        rows, stats = coupled_run(scene.orbit.simulation, scene.orbit.name, scene.moments_per_mass, y0,
                                  scene.epoch_day, scene.output_days, plan.kept, eps)
        check, _ = coupled_run(scene.orbit.simulation, scene.orbit.name, scene.moments_per_mass, y0,
                               scene.epoch_day, scene.output_days, plan.kept, check_eps)
        return (rows, stats), float(np.max(attitude_angles(rows[:, :4], check[:, :4])))

    def attempted(attempt):
        report((attempt + 1) / (MAX_RTOL_RETRIES + 1))

    (rows, stats), integration, eps = refine("rebound-bs", plan.rtol, max(plan.integration_share_rad, 0.0),
                                             run_and_check, attempted)
    rows[:, :4] /= np.linalg.norm(rows[:, :4], axis=1, keepdims=True)
    table = result_table(scene, *from_principal(scene.state.body, rows))
    table.meta["rtol"] = eps
    stats.update(rtol=eps)
    return table, {"dropped": 0.0, "integration": integration, "sampling": 0.0}, stats
