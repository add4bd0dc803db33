"""What each of the scene planner's skips saves: the planned run against the full run of the same scene.

For every scene: the wall time of ``Scene.run(scene.plan(skip=False))`` (the full run: every
perturber, the orbits as given, the output asked for densely; the plan is built beforehand and not
timed) against ``scene.plan()`` + ``scene.run(plan)`` (the planner's survey and sensitivity probe
included), best of ``--repeat`` in the same process, and the attitude difference between the two
(the error the skip made) next to the tolerance and the planned run's error estimate. Timings on a
shared machine are noisy: the ratio of the two runs in the same process is what to read.

Usage::

    python benchmarks/bench_scene_skips.py            # writes the 'scene_skips' section of docs/performance.md
    python benchmarks/bench_scene_skips.py --no-write # print only
"""

from __future__ import annotations

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

from _report import machine_line, repeat_main

from spinorbit import RigidBody, RotationState, asteroids
from spinorbit.coupling.rebound_adapter import body_index, simulation_from_de421
from spinorbit.ephemeris import de421_constants, moon_orientation
from spinorbit.scene import Orbit, Scene, _angles
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
    start = asteroids.APOPHIS_2029.time_tdb - 1 * u.day
    flyby = Scene(asteroids.apophis_rotation_state(), start, start + np.linspace(0.02, 2.0, 100) * u.day,
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


def interleaved_best_of(repeat, first, second):
    """Best wall time and last value of each of two functions, called alternately (same machine load)."""
    best, values = [math.inf, math.inf], [None, None]
    for _ in range(repeat):
        for i, function in enumerate((first, second)):
            clock = time.perf_counter()
            values[i] = function()
            best[i] = min(best[i], time.perf_counter() - clock)
    return (best[0], values[0]), (best[1], values[1])


def measure(repeat):
    rows = []
    for skip, description, planned_scene, full_scene in scenes():
        full_plan = full_scene.plan(skip=False)
        full_scene.run(full_plan)  # warm-up: numba compilation, DE421 pages
        planned_scene.run(planned_scene.plan())
        (full_time, full), (planned_time, planned) = interleaved_best_of(
            repeat, lambda s=full_scene, p=full_plan: s.run(p), lambda s=planned_scene: s.run(s.plan()))
        n = len(planned.table)
        error = float(np.max(_angles(planned.table["quaternion"], full.table["quaternion"][-n:])))
        rows.append({"skip": skip, "description": description, "full": full_time, "planned": planned_time,
                         "error": error * 206264.80624709636, "estimate": planned.error_estimate.to_value(u.arcsec),
                         "tolerance": planned.plan.tolerance_rad * 206264.80624709636, "route": planned.plan.route,
                         "dropped": ", ".join(planned.plan.dropped) or "none", "source": planned.plan.orbit_source,
                         "full_route": full_plan.route})
        print(f"{skip:26s} full {full_time * 1e3:8.1f} ms  planned {planned_time * 1e3:8.1f} ms  "
              f"x{full_time / planned_time:6.2f}  error {rows[-1]['error']:.2e} arcsec  "
              f"estimate {rows[-1]['estimate']:.2e}  ({planned.plan.route}, dropped {rows[-1]['dropped']})")
    return rows


def markdown(rows, repeat):
    lines = ["## What the scene planner's skips save (`benchmarks/bench_scene_skips.py`)", "",
             machine_line(), "",
             (f"Wall time of the full run (`Scene.run(scene.plan(skip=False))`, plan built beforehand) against the "
             f"planned run (`scene.plan()` + `scene.run(plan)`, the planner's survey and sensitivity probe included), "
             f"best of {repeat} in one process, the two runs alternated; error = largest attitude angle between the two runs' outputs "
             "(the planned run's times), next to the tolerance and the planned run's own error estimate. Both runs "
             "include the a posteriori integration check (a second run at 10× rtol)."), "",
             ("| skip | scene | full (ms) | planned (ms) | full / planned | error (arcsec) | estimate (arcsec) "
             "| tolerance (arcsec) | plan |"),
             "|---|---|---:|---:|---:|---:|---:|---:|---|"]
    for r in rows:
        plan = f"{r['route']}, orbits {r['source']}, dropped {r['dropped']} (full: {r['full_route']})"
        lines.append(f"| {r['skip']} | {r['description']} | {r['full'] * 1e3:.1f} | {r['planned'] * 1e3:.1f} | "
                     f"{r['full'] / r['planned']:.2f} | {r['error']:.2e} | {r['estimate']:.2e} | {r['tolerance']:g} "
                     f"| {plan} |")
    return "\n".join(lines)


def main(argv=None):
    repeat_main("scene_skips", __doc__.splitlines()[0], measure, markdown, repeat=3, argv=argv)


if __name__ == "__main__":
    main()
