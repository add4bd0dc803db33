"""What each of the scene planner's skips saves: the planned run against the full run of the same scene.

For every scene: the wall time of ``Scene.run(scene.plan(skip=False))`` (the full run: every
perturber, the orbits as given, the output asked for densely; the plan is built beforehand and not
timed) against ``scene.plan()`` + ``scene.run(plan)`` (the planner's survey and sensitivity probe
included), median (min–max) of ``--repeat`` in the same process, and the attitude difference between the two
(the error the skip made) next to the tolerance and the planned run's error estimate. Timings on a
shared machine are noisy: the ratio of the two runs in the same process is what to read.

Two rows compare integrators rather than skips: 'Taylor instead of DOP853' and 'DOP853 instead of
Taylor' time ``scene.plan()`` + ``scene.run(plan)`` against the same for the same scene forced to the
other integrator, so only the integrator (and the planner's Taylor probe) differs. A second table, 'Taylor against DOP853 by knots', times
the two integrators alone (``time.process_time``, alternated, medians of ``--repeat``) on every one-way
scene's model at tol = rtol = 1e-10 with the counts the planner's rule uses (``Scene._integrator_choice``:
rotation steps of the free motion, knots inside the span).

Usage::

    python benchmarks/bench_scene_skips.py            # writes the 'scene_skips' section of docs/performance.md
    python benchmarks/bench_scene_skips.py --no-write # print only
"""

from __future__ import annotations

import copy as _copy
import math
import sys
import time
from pathlib import Path

import numpy as np
import rebound
from astropy import constants as const
from astropy import units as u
from astropy.time import Time

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from _report import interleaved_timings, machine_line, repeat_main

from spinorbit.data import asteroids
from spinorbit import RigidBody, RotationState
from spinorbit.coupling.rebound import body_index, simulation_from_de421
from spinorbit.state_table import quaternion_array
from spinorbit.ephemeris import de421_constants, moon_orientation
from spinorbit.scene import EphemerisPerturber, Orbit, Scene
from spinorbit.scene.routes import attitude_angles as _angles
from spinorbit.time import tdb_days

EPOCH = Time("2020-01-01", scale="tdb")


def sam_state():
    """The Apophis-like short-axis state of tests/test_scene.py (moment ratios 0.61 : 0.965 : 1, 9 h spin)."""
    return RotationState.from_euler313(RigidBody([0.61, 0.965, 1.0]), 10 * u.deg, 40 * u.deg, 70 * u.deg,
                                       [5, 3, 40] * u.deg / u.hour)


def luna_scene(span_days, outputs, tolerance, figure=True):
    """The Moon with its DE421 figure, renamed 'Luna' in the 11-body DE421 simulation so that the planner
    cannot take DE421's orbit. ``figure``: moments in kg m² and the mass (the back-reaction can be
    estimated and the coupled route run); otherwise the moment ratios alone (one-way only)."""
    constants = de421_constants()
    sim = simulation_from_de421(EPOCH)
    sim.particles[body_index(sim, "moon")].name = "Luna"
    q, omega = moon_orientation(EPOCH)
    mass = (constants.gm["moon"] * u.au**3 / u.day**2 / const.G).to(u.kg)
    ratios = np.array(constants.moon_moments_over_mr2)
    body = RigidBody((ratios * mass * (1738 * u.km) ** 2).to(u.kg * u.m**2), mass=mass) if figure else RigidBody(ratios)
    return Scene(RotationState(body, q, omega), EPOCH, EPOCH + np.linspace(span_days / outputs, span_days, outputs) * u.day,
                 perturbers=("earth", "sun"), orbit=Orbit.rebound(sim, "Luna"), tolerance=tolerance)


def flattened_earth_scene(span_days, outputs, tolerance, orbit):
    """The Earth with a 50x flattened figure, Moon + Sun (the scene of tests/test_scene.py): one-way on
    DE421's orbits within the back-reaction bound, coupled when given as a REBOUND particle."""
    mass = (de421_constants().gm["earth"] * u.au**3 / u.day**2 / const.G).to(u.kg)
    body = RigidBody(([0.33, 0.331, 0.38] * mass * (6378 * u.km) ** 2).to(u.kg * u.m**2), mass=mass)
    state = RotationState.from_euler313(body, 10 * u.deg, 23 * u.deg, 30 * u.deg, [0, 0, 2 * np.pi] * u.rad / u.day)
    return Scene(state, EPOCH, EPOCH + np.linspace(span_days / outputs, span_days, outputs) * u.day,
                 perturbers=("moon", "sun"), orbit=orbit, tolerance=tolerance)


def moonlike_scene(span_days, outputs, tolerance, figure=True):
    """A Moon-mass body with a 200x lunar figure ((C-A)/(M R²) = 0.05) 0.00257 au from a 3e-6 Msun planet
    1 au from a Sun (the three-body system of tests/test_scene.py)."""
    sim = rebound.Simulation()
    sim.units = ("AU", "day", "Msun")
    sim.t = float(sum(tdb_days(EPOCH)))
    sim.add(m=1.0, name="Sun")
    sim.add(m=3e-6, a=1.0, name="Planet")
    sim.add(m=3.7e-8, a=0.00257, e=0.05, inc=0.1, primary=sim.particles[1], name="Body")
    sim.move_to_com()
    sim.exact_finish_time = 1
    mass, radius = 3.7e-8 * const.M_sun, 1.16e-5 * u.au
    body = (RigidBody(([0.35, 0.38, 0.40] * mass * radius**2).to(u.kg * u.m**2), mass=mass) if figure
            else RigidBody([0.35, 0.38, 0.40]))
    n = float(np.sqrt(sim.G * 3.037e-6 / 0.00257**3))
    state = RotationState.from_euler313(body, 10 * u.deg, 20 * u.deg, 30 * u.deg, [0.01 * n, 0.02 * n, n] * u.rad / u.day)
    return Scene(state, EPOCH, EPOCH + np.linspace(span_days / outputs, span_days, outputs) * u.day,
                 perturbers=("sun", "planet"), orbit=Orbit.rebound(sim, "Body"), tolerance=tolerance)


def scenes():
    """(skip, description, planned scene, full scene)."""
    planets = ("sun", "mercury", "venus", "mars", "jupiter", "saturn")
    dense = EPOCH + np.linspace(0.1, 20.0, 200) * u.day
    out = []
    free = Scene(sam_state(), EPOCH, EPOCH + np.linspace(0.01, 2.0, 500) * u.day, perturbers=("sun", "jupiter"),
                 orbit=Orbit.circular(2.5 * u.au), tolerance=60 * u.arcsec)
    out.append(("torque-free", "SAM body at 2.5 au, Sun + Jupiter, 2 d, 500 outputs, tolerance 60 arcsec",
                free, free))
    drop = Scene(sam_state(), EPOCH, dense, perturbers=planets, orbit=Orbit.circular(2.5 * u.au),
                 tolerance=1 * u.arcsec)
    out.append(("drop perturbers", "same body, Sun + 5 planets, 20 d, 200 outputs", drop, drop))
    out.append(("Taylor instead of DOP853", "the same scene, planned (Taylor) against planned with "
                "integrator='quaternion'", drop, Scene(sam_state(), EPOCH, dense, perturbers=planets,
                                                       orbit=Orbit.circular(2.5 * u.au), tolerance=1 * u.arcsec,
                                                       integrator="quaternion")))
    end = Scene(sam_state(), EPOCH, dense[-1], perturbers=("sun",), orbit=Orbit.circular(2.5 * u.au),
                tolerance=1 * u.arcsec)
    end_full = Scene(sam_state(), EPOCH, dense, perturbers=("sun",), orbit=Orbit.circular(2.5 * u.au),
                     tolerance=1 * u.arcsec)
    out.append(("end only", "same body, Sun, 20 d: 1 output vs 200", end, end_full))
    q, omega = moon_orientation(EPOCH)
    moon = RotationState(RigidBody(list(de421_constants().moon_moments_over_mr2)), q, omega)
    known = Scene(moon, EPOCH, EPOCH + np.linspace(0.5, 10.0, 20) * u.day, perturbers=("earth", "sun"),
                  orbit=Orbit.rebound(simulation_from_de421(EPOCH), "Moon"), tolerance=1 * u.arcsec)
    out.append(("DE421 instead of N-body", "the Moon (degree 2), Earth + Sun, 10 d, given as a REBOUND particle",
                known, known))
    out.append(("DOP853 instead of Taylor", "the same Moon scene (224 samples in 10 d), planned (DOP853) against "
                "planned with integrator='taylor'", known,
                Scene(moon, EPOCH, EPOCH + np.linspace(0.5, 10.0, 20) * u.day, perturbers=("earth", "sun"),
                      orbit=Orbit.rebound(simulation_from_de421(EPOCH), "Moon"), tolerance=1 * u.arcsec,
                      integrator="taylor")))
    start = asteroids.APOPHIS_2029.time_tdb - 1 * u.day
    flyby = Scene(asteroids.apophis_rotation_state().with_epoch(start), start, start + np.linspace(0.02, 2.0, 100) * u.day,
                  perturbers=("sun", "earth", "moon", "venus", "mars", "jupiter"),
                  orbit=Orbit.rebound(asteroids.apophis_encounter_simulation("published"), "Apophis"), tolerance=1 * u.arcsec)
    out.append(("drop perturbers (N-body)", "Apophis 2029 flyby +-1 d, Sun, Earth, Moon + 3 planets (REBOUND)",
                flyby, flyby))
    symmetric = RotationState.from_euler313(RigidBody([1.0, 1.0, 2.0]), 10 * u.deg, 40 * u.deg, 70 * u.deg,
                                            [5, 3, 40] * u.deg / u.hour)
    closed = Scene(symmetric, EPOCH, EPOCH + np.linspace(0.01, 100.0, 2000) * u.day, tolerance=1e-12 * u.rad)
    out.append(("closed form", "axisymmetric body (1, 1, 2), no perturbers, 100 d, 2000 outputs: regular precession "
                "vs the elliptic flow", closed, closed))
    # The coupling: on DE421's orbits one-way is the skip (the full run is coupled, in REBOUND); on a
    # REBOUND orbit the planner takes the coupled route, and its "full" peer here is the one-way run of
    # the same state given by moment ratios (the only way to ask a Scene for one-way there).
    out.append(("one-way (DE421) instead of coupled", "Earth with a 50x flattened figure, Moon + Sun, 10 d, "
                "100 outputs, tolerance 10 arcsec (full: the same given as a REBOUND particle)",
                flattened_earth_scene(10.0, 100, 10 * u.arcsec, Orbit.de421("earth")),
                flattened_earth_scene(10.0, 100, 10 * u.arcsec, Orbit.rebound(simulation_from_de421(EPOCH), "Earth"))))
    for outputs in (5, 200):
        out.append(("coupled instead of one-way (N-body)", f"the Moon's figure as 'Luna' in the 11-body DE421 "
                    f"REBOUND simulation, Earth + Sun, 30 d, {outputs} outputs",
                    luna_scene(30.0, outputs, 1 * u.arcsec), luna_scene(30.0, outputs, 1 * u.arcsec, figure=False)))
    out.append(("coupled instead of one-way (N-body)", "Moon-mass body with a 200x lunar figure, planet + Sun "
                "(3 bodies), 10 d, 100 outputs, tolerance 200 arcsec", moonlike_scene(10.0, 100, 200 * u.arcsec),
                moonlike_scene(10.0, 100, 200 * u.arcsec, figure=False)))
    return out


def interleaved_pair(repeat, first, second, clock=time.perf_counter):
    """(Timing, last value) of each of two functions, called alternately (same machine load)."""
    timings, values = interleaved_timings((first, second), repeat, clock)
    return (timings[0], values[0]), (timings[1], values[1])


def _ms(timing, fmt=".1f"):
    """'median (min–max)' in ms."""
    return f"{timing.median * 1e3:{fmt}} ({timing.min * 1e3:{fmt}}–{timing.max * 1e3:{fmt}})"


#: Periods (d) of the moonlet sweep of the 'by knots' table: its relative circle sets the sample
#: spacing (∝ period), so the knots per rotation step run from ≈ 0.1 to ≈ 3.
MOONLET_PERIODS = (300.0, 100.0, 40.0, 15.0, 5.0)


def moonlet_scene(period_days):
    """The SAM body on the 2.5 au circle with the Sun and a 'moonlet' on a 0.01 au circle about it (a
    relative EphemerisPerturber, G·M 1e-12 au³/day²: its torque ≈ 1/20 of the Sun's, so it is kept) of
    the given period, 20 d, 200 outputs, 1 arcsec."""
    radius, rate = 0.01, 2 * math.pi / period_days

    def circle(days):
        days = np.atleast_1d(np.asarray(days, dtype=float))
        c, s, zero = np.cos(rate * days), np.sin(rate * days), np.zeros(days.shape)
        return radius * np.stack([c, zero, s], axis=1), radius * rate * np.stack([-s, zero, c], axis=1)

    moonlet = EphemerisPerturber("moonlet", 1e-12 * u.au**3 / u.day**2, circle, relative=True)
    return Scene(sam_state(), EPOCH, EPOCH + np.linspace(0.1, 20.0, 200) * u.day, perturbers=("sun", moonlet),
                 orbit=Orbit.circular(2.5 * u.au), tolerance=1 * u.arcsec)


#: Rows whose peer is the same scene planned too (skip=True) with the other integrator forced.
INTEGRATOR_ROWS = ("Taylor instead of DOP853", "DOP853 instead of Taylor")


def knot_rows(scene_rows, repeat):
    """Taylor against DOP853 on each one-way scene's model, each at the first tolerance the planner would
    give it, with the rule's counts (``spinorbit.scene.integrator_choice.taylor_steps``) and the true ones."""
    from spinorbit.core.dynamics.equations import make_model
    from spinorbit.core.integrators.quaternion import integrate_quaternion
    from spinorbit.core.integrators.taylor import integrate_taylor
    from spinorbit.scene.integrator_choice import taylor_steps
    from spinorbit.scene.tolerances import first_tolerance as _first_tolerance

    rows, seen = [], set()
    sweep = [(f"moonlet, period {period:g} d", None, moonlet_scene(period), None) for period in MOONLET_PERIODS]
    for skip, _, scene, _ in [*scene_rows, *sweep]:
        if skip in INTEGRATOR_ROWS or skip == "end only":  # the same models as other rows
            continue
        plan = scene.plan()
        if plan.route != "one-way" or id(scene) in seen:
            continue
        seen.add(id(scene))
        named = [n for n in plan.kept if n in scene.named]
        moving = [p.name for p in scene.moving if p.name in plan.kept]
        groups = ([scene.sample_perturbers(plan.orbit_source, named, scene.sample_tolerance)] if named else []) + (
            [scene.sample_perturbers("user", moving, scene.sample_tolerance)] if moving else [])
        model = make_model(scene.state.body.principal_moments, [s for g in groups for s in g.sources()])
        y0, t0, t_out = scene.state.core_state(), scene.epoch_day, scene.output_days
        share = plan.integration_share_rad
        tol, rtol = _first_tolerance("taylor", share), _first_tolerance("quaternion", share)
        steps, estimate, _ = taylor_steps(scene, plan.orbit_source, plan.kept, True, tol)
        days = np.unique(np.concatenate([g.days for g in groups]))
        knots = int(np.count_nonzero((days > t0) & (days < t_out[-1])))
        reference = integrate_quaternion(y0, t0, t_out, model, rtol=1e-14)
        yt, taylor_stats = integrate_taylor(y0, t0, t_out, model, tol=tol, return_stats=True)
        yd, dop_stats = integrate_quaternion(y0, t0, t_out, model, rtol=rtol, return_stats=True)
        # The whole scene forced to each integrator (planned, skip=True): the run pair, the a posteriori
        # check and its retries included, which is what the planner's choice decides.
        forced = []
        for name in ("taylor", "quaternion"):
            copy = _copy.copy(scene)
            copy.integrator = name
            forced.append((copy, copy.plan()))
        (scene_taylor, taylor_result), (scene_dop, dop_result) = interleaved_pair(
            repeat, *(lambda s=s, p=p: s.run(p) for s, p in forced))
        (taylor_time, _), (dop_time, _) = interleaved_pair(
            max(repeat, 5), lambda: integrate_taylor(y0, t0, t_out, model, tol=tol),
            lambda: integrate_quaternion(y0, t0, t_out, model, rtol=rtol), clock=time.process_time)
        rows.append({"skip": skip, "kept": ", ".join(plan.kept), "knots": knots, "estimate": estimate,
                     "rotation": steps, "tol": tol, "rtol": rtol, "taylor_steps": taylor_stats["steps"],
                     "dop_steps": dop_stats["accepted"] + dop_stats["rejected"], "taylor": taylor_time, "dop": dop_time,
                     "taylor_error": float(np.max(_angles(reference[:, :4], yt[:, :4]))),
                     "dop_error": float(np.max(_angles(reference[:, :4], yd[:, :4]))), "choice": plan.integrator,
                     "scene_taylor": scene_taylor, "scene_dop": scene_dop, "final_tol": taylor_result.stats["rtol"],
                     "final_rtol": dop_result.stats["rtol"]})
        r = rows[-1]
        print(f"{skip[:26]:26s} knots {knots:5d} (est. {estimate:6.0f}) rotation {steps:6.0f} est. ratio "
              f"{estimate / steps:6.3g}  Taylor tol {tol:.1e} {r['taylor_steps']:5d} steps {_ms(taylor_time, '.3f')} ms "
              f"err {r['taylor_error']:.1e}  DOP853 rtol {rtol:.1e} {r['dop_steps']:5d} steps {_ms(dop_time, '.3f')} ms "
              f"err {r['dop_error']:.1e}  Taylor/DOP853 {taylor_time.median / dop_time.median:5.2f}  scene "
              f"{_ms(scene_taylor, '.2f')} / {_ms(scene_dop, '.2f')} ms = {scene_taylor.median / scene_dop.median:5.2f} (final tol {r['final_tol']:.1e}, rtol "
              f"{r['final_rtol']:.1e})  (plan: {plan.integrator})", flush=True)
    return rows


def measure(repeat):
    rows = []
    all_scenes = scenes()
    for skip, description, planned_scene, full_scene in all_scenes:
        same_plan = skip in INTEGRATOR_ROWS  # the peer is planned too: time its plan() as well
        full_plan = full_scene.plan(skip=same_plan)
        full_scene.run(full_plan)  # warm-up: numba compilation, DE421 pages
        planned_scene.run(planned_scene.plan())
        (full_time, full), (planned_time, planned) = interleaved_pair(
            repeat, (lambda s=full_scene: s.run(s.plan())) if same_plan else (lambda s=full_scene, p=full_plan: s.run(p)),
            lambda s=planned_scene: s.run(s.plan()))
        n = len(planned.table)
        error = float(np.max(_angles(quaternion_array(planned.table), quaternion_array(full.table)[-n:])))
        rows.append({"skip": skip, "description": description, "full": full_time, "planned": planned_time,
                         "error": error * 206264.80624709636, "estimate": planned.error_estimate.to_value(u.arcsec),
                         "tolerance": planned.plan.tolerance_rad * 206264.80624709636, "route": planned.plan.route,
                         "dropped": ", ".join(planned.plan.dropped) or "none", "source": planned.plan.orbit_source,
                         "full_route": full_plan.route})
        print(f"{skip:26s} full {_ms(full_time)} ms  planned {_ms(planned_time)} ms  "
              f"x{full_time.median / planned_time.median:6.2f}  error {rows[-1]['error']:.2e} arcsec  "
              f"estimate {rows[-1]['estimate']:.2e}  ({planned.plan.route}, dropped {rows[-1]['dropped']})")
        rows[-1].update(integrator=planned.plan.integrator, full_integrator=full_plan.integrator)
    return {"skips": rows, "knots": knot_rows(all_scenes, repeat)}


def markdown(results, repeat):
    rows = results["skips"]
    lines = ["## What the scene planner's skips save (`benchmarks/bench_scene_skips.py`)", "",
             machine_line(), "",
             (f"Wall time of the full run (`Scene.run(scene.plan(skip=False))`, plan built beforehand) against the "
             f"planned run (`scene.plan()` + `scene.run(plan)`, the planner's survey and sensitivity probe included), "
             f"median (min–max) of {repeat} in one process, the two runs alternated; error = largest attitude angle between the two runs' outputs "
             "(the planned run's times), next to the tolerance and the planned run's own error estimate. Both runs "
             "include the a posteriori integration check (a second run at 10× rtol). In the rows 'Taylor instead of "
             "DOP853' and 'DOP853 instead of Taylor' the 'full' run is the same scene with the other integrator "
             "forced (`integrator=...`), planned (skip=True) and timed with its `plan()` like the planned one."), "",
             ("| skip | scene | full (ms) | planned (ms) | full / planned | error (arcsec) | estimate (arcsec) "
             "| tolerance (arcsec) | plan |"),
             "|---|---|---:|---:|---:|---:|---:|---:|---|"]
    for r in rows:
        plan = (f"{r['route']}, orbits {r['source']}, dropped {r['dropped']}, {r['integrator']} (full: "
                f"{r['full_route']}, {r['full_integrator']})")
        lines.append(f"| {r['skip']} | {r['description']} | {_ms(r['full'])} | {_ms(r['planned'])} | "
                     f"{r['full'].median / r['planned'].median:.2f} | {r['error']:.2e} | {r['estimate']:.2e} | {r['tolerance']:g} "
                     f"| {plan} |")
    lines += ["", "### Taylor against DOP853 by knots", "",
              (f"The two integrators alone on each one-way scene's model (the kept perturbers' samples at the run's "
               "sample tolerance), each at the first tolerance the planner gives it for the scene's integration "
               "share (Taylor tol = share × 0.3/60, DOP853 rtol = share / 1000), CPU (`time.process_time`) median "
               f"(min–max) of {max(repeat, 5)}, the two alternated, ratios of the medians; error = largest attitude angle against DOP853 at rtol 1e-14. "
               "Rotation steps and estimated knots: the planner's counts (`spinorbit.scene.integrator_choice.taylor_steps`: the Taylor method "
               "on the free motion over ≤ 20 rotations, scaled; knots from the survey's a priori grid); knots: the "
               "true sample times strictly inside the span (each ends a Taylor step). The planner takes Taylor while "
               "estimated knots ≤ `spinorbit.scene.integrator_choice.TAYLOR_KNOT_SHARE` × rotation steps. The moonlet rows: the SAM "
               "body at 2.5 au with the Sun and a relative circle of 0.01 au (G·M 1e-12 au³/day²) of the given "
               "period, 20 d, 200 outputs, 1 arcsec. Scene run: the whole `Scene.run` of the scene planned (skip=True) "
               "with `integrator` forced to 'taylor' and to 'quaternion', alternated, medians of --repeat: the run, its "
               "a posteriori check at 10× the tolerance and any retry at 1/100 of it (final tol / rtol)."), "",
              "| scene | kept | knots (estimated) | rotation steps | est. knots / rotation steps | Taylor tol | "
              "Taylor steps | Taylor (ms) | Taylor error (rad) | DOP853 rtol | DOP853 steps | DOP853 (ms) "
              "| DOP853 error (rad) | Taylor / DOP853 | scene run: Taylor / DOP853 (ms) | final tol / rtol | plan |",
              "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---|"]
    for r in results["knots"]:
        lines.append(f"| {r['skip']} | {r['kept']} | {r['knots']} ({r['estimate']:.0f}) | {r['rotation']:.0f} | "
                     f"{r['estimate'] / r['rotation']:.3g} | {r['tol']:.1e} | {r['taylor_steps']} | "
                     f"{_ms(r['taylor'], '.3f')} | {r['taylor_error']:.1e} | {r['rtol']:.1e} | {r['dop_steps']} | "
                     f"{_ms(r['dop'], '.3f')} | {r['dop_error']:.1e} | {r['taylor'].median / r['dop'].median:.2f} | "
                     f"{r['scene_taylor'].median / r['scene_dop'].median:.2f} ({_ms(r['scene_taylor'])} / "
                     f"{_ms(r['scene_dop'])}) | "
                     f"{r['final_tol']:.0e} / {r['final_rtol']:.0e} | {r['choice']} |")
    return "\n".join(lines)


def main(argv=None):
    repeat_main("scene_skips", __doc__.splitlines()[0], measure, markdown, repeat=3, argv=argv)


if __name__ == "__main__":
    main()
