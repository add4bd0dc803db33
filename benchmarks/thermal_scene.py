"""The Scene's thermal routes measured: their cost per right-hand side, their agreement, the planner's choices.

Writes the section ``thermal_scene`` of docs/thermal.md (every number there comes from this script):

1. CPU time per right-hand side of the full route (quaternion DOP853 under the Sun and the recoil, on
   the degree-8 harmonics and on the facets) and of the mean route (eq. 11 and the exact orbit
   average at one torus point), at two mesh sizes: interleaved repeats, median and range; the planner
   prices both routes with them (``FULL_RHS_SECONDS``, ``FULL_FACET_SECONDS``, ``MEAN_RHS_SECONDS``,
   ``MEAN_FACET_SECONDS`` in spinorbit/scene/thermal_planning.py, which this script compares with
   what it measured);
2. the Scene's mean route against its full route over a span both afford (two sizes), at whole and
   half orbits, against the mean route's own error estimate;
3. the planner's choice, reason and estimated costs for spans from 1 yr to 10⁶ yr.

Usage::

    PYTHONPATH=$PWD python benchmarks/thermal_scene.py            # ≈ 1 min
    PYTHONPATH=$PWD python benchmarks/thermal_scene.py --no-write # print only
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from pathlib import Path

import numpy as np
from astropy import units as u
from astropy.time import Time

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from _report import interleaved_timings, machine_line, write_section  # noqa: E402

from spinorbit import RotationState  # noqa: E402
from spinorbit.core.averaging.thermal_mean import propagate_mean_thermal  # noqa: E402
from spinorbit.core.integrators.quaternion import integrate_quaternion  # noqa: E402
from spinorbit.scene import Orbit, Scene, ThermalModel  # noqa: E402
from spinorbit.scene import thermal_planning  # noqa: E402
from spinorbit.scene.thermal_planning import mean_difference, thermal_setup  # noqa: E402
from spinorbit.shape import gaussian_random_sphere, rigid_body_from_shape  # noqa: E402

DENSITY = 2000 * u.kg / u.m**3
EPOCH = Time("2020-01-01", scale="tdb")
ELEMENTS = (1 * u.au, 0.1, 5 * u.deg, 20 * u.deg, 30 * u.deg, 0 * u.deg)
SPIN = 2 * math.pi / 0.25


class _Tumbler:
    def __init__(self, state, shape):
        self.state, self.body_shape = state, shape


def tumbler(radius_km, mu_q=None, subdivisions=None):
    """(state, thermal model) of the tumbler; with ``subdivisions``, (a holder of state and shape, None)."""
    shape = gaussian_random_sphere(radius_km * u.km, 0.15, seed=5, subdivisions=subdivisions or 3)
    body = rigid_body_from_shape(shape, density=DENSITY)
    q = np.array([0.9, 0.2, -0.3, 0.25])
    state = RotationState(body, q / np.linalg.norm(q), np.array([0.3, 0.1, 1.0]) * SPIN * u.rad / u.day)
    if subdivisions is not None:
        return _Tumbler(state, shape), None
    return state, ThermalModel.from_shape(shape, DENSITY, mu_q=mu_q)


def elements(table):
    s, z, h = (table[c].value for c in ("S", "Z", "H"))
    return np.stack([s, z, h, 0 * s, 0 * s, np.radians(table["h"].to_value(u.deg))], axis=1)


def rhs_costs(repeats):
    """CPU seconds per right-hand side: the full route on the harmonics and on the facets, and the mean route
    per torus point, on the tumbler at two mesh sizes (so a facet's share and the fixed part separate)."""
    from spinorbit.core.averaging.thermal_mean import EXACT_POINTS_S, EXACT_POINTS_Z

    out = {}
    for subdivisions in (2, 3):
        state, _ = tumbler(0.2, subdivisions=subdivisions)
        orbit = Orbit.kepler(*ELEMENTS, EPOCH)
        counts, jobs = {}, []
        for torque in ("harmonics", "facets"):
            thermal = ThermalModel.from_shape(state.body_shape, DENSITY, torque=torque)
            setup = thermal_setup(Scene(state.state, EPOCH, EPOCH + 1 * u.yr, orbit=orbit, thermal=thermal))

            def full(setup=setup, torque=torque):
                _, stats = integrate_quaternion(setup.y0, setup.t0, [setup.t0 + 100.0], setup.model, rtol=1e-10,
                                                return_stats=True)
                counts[torque] = stats["rhs_calls"]

            jobs.append(full)

        def mean(setup=setup):
            _, steps = propagate_mean_thermal(setup.el0, setup.t0, [setup.t0 + 4 * 365.25], setup.model, setup.frame,
                                              365.25)
            counts["mean"] = steps * thermal_planning.STAGES * EXACT_POINTS_S * EXACT_POINTS_Z

        timings, _ = interleaved_timings(jobs + [mean], repeats, clock=time.process_time, warm_up=True)
        out[len(state.body_shape)] = {name: (t, counts[name]) for name, t in zip(("harmonics", "facets", "mean"), timings)}
    return out


def agreement():
    rows = []
    for radius in (0.06, 0.2):
        holder, _ = tumbler(radius, subdivisions=3)
        # The full route on the facet sum: the mean route averages it exactly (the harmonics' differ by ~15 %).
        state, thermal = holder.state, ThermalModel.from_shape(holder.body_shape, DENSITY, torque="facets")
        orbit = Orbit.kepler(*ELEMENTS, EPOCH)
        setup = thermal_setup(Scene(state, EPOCH, EPOCH + 1 * u.yr, orbit=orbit, thermal=thermal))
        days = setup.period_orbit * np.array([1.0, 1.5, 2.0, 2.5, 4.0, 8.0])
        results, cpu = {}, {}
        for route in ("full", "mean"):
            start = time.process_time()
            results[route] = Scene(state, EPOCH, EPOCH + days * u.day, orbit=orbit, thermal=thermal,
                                   tolerance=0.01 * u.rad, thermal_route=route).run()
            cpu[route] = time.process_time() - start
        full, mean = elements(results["full"].table), elements(results["mean"].table)
        whole, half = [0, 2, 4, 5], [1, 3]
        change = abs(full[-1, 1] - setup.el0[1]) / setup.el0[1]
        rows.append((radius, change, mean_difference(full[whole], mean[whole]), mean_difference(full[half], mean[half]),
                     results["mean"].error_estimate.to_value(u.rad), cpu["full"], cpu["mean"],
                     results["full"].stats["rtol"]))
    return rows


def choices():
    state, thermal = tumbler(0.2, mu_q=1e9 * u.Pa)
    orbit = Orbit.kepler(*ELEMENTS, EPOCH)
    rows = []
    for years, tolerance in ((1, 1 * u.deg), (100, 1 * u.deg), (1e4, 1 * u.deg), (1e6, 0.1 * u.rad),
                             (1e4, 1 * u.arcsec)):
        scene = Scene(state, EPOCH, EPOCH + np.linspace(years / 20, years, 20) * u.yr, orbit=orbit,
                      thermal=thermal, tolerance=tolerance)
        try:
            plan = scene.plan()
            route = plan.route
            reason = next(d.reason for d in plan.decisions if d.topic == "route")
        except thermal_planning.PlanError as error:
            route, reason = f"refused ({type(error).__name__})", str(error)
        cost_text = reason[reason.find("cost:") + 6:].split(")")[0] + ")" if "cost:" in reason else "—"
        estimate = reason[reason.find("mean estimate"):].split(" (")[0] if "mean estimate" in reason else "—"
        rows.append((years, tolerance, route, estimate, cost_text))
    return rows


def markdown(costs, agree, picks, seconds):
    load = os.getloadavg()[0]
    lines = [f"Written by `PYTHONPATH=$PWD python benchmarks/thermal_scene.py` in {seconds:.0f} s. {machine_line()} "
             f"1-minute load average at the end: {load:.2f}.", ""]
    per = {n: {k: (t.median / c, t.min / c, t.max / c, len(t.samples)) for k, (t, c) in row.items()}
           for n, row in costs.items()}
    small, large = sorted(per)
    facet_full = (per[large]["facets"][0] - per[large]["harmonics"][0]) / large
    facet_mean = (per[large]["mean"][0] - per[small]["mean"][0]) / (large - small)
    fixed_mean = per[large]["mean"][0] - large * facet_mean
    lines += ["**Cost per right-hand side** (CPU time of this process, interleaved repeats, median and range), "
              f"200 m Gaussian random sphere at two mesh sizes ({small} and {large} facets): the full route (quaternion "
              "equations, the Sun and the recoil) on the degree-8 harmonics and on the facet sum, and the mean route "
              "per torus point (eq. 11 and the exact orbit average of the facet sum).", "",
              "| facets | full, harmonics (ns) | full, facets (ns) | mean, per torus point (ns) |", "|---|---|---|---|"]
    for n in (small, large):
        lines.append(f"| {n} | " + " | ".join(f"{per[n][k][0] * 1e9:.0f} ({per[n][k][1] * 1e9:.0f}–{per[n][k][2] * 1e9:.0f}, "
                                              f"{per[n][k][3]} runs)" for k in ("harmonics", "facets", "mean")) + " |")
    lines += ["", f"From these: a facet adds {facet_full * 1e9:.2f} ns to a full right-hand side on the facets and "
              f"{facet_mean * 1e9:.2f} ns to a mean torus point, whose fixed part is {fixed_mean * 1e9:.0f} ns. The planner's "
              f"constants (spinorbit/scene/thermal_planning.py): FULL_RHS_SECONDS {thermal_planning.FULL_RHS_SECONDS * 1e9:.0f} ns, "
              f"FULL_FACET_SECONDS {thermal_planning.FULL_FACET_SECONDS * 1e9:.2f} ns, MEAN_RHS_SECONDS "
              f"{thermal_planning.MEAN_RHS_SECONDS * 1e9:.0f} ns, MEAN_FACET_SECONDS "
              f"{thermal_planning.MEAN_FACET_SECONDS * 1e9:.2f} ns; only the routes' ratio decides."]
    lines += ["", "**Mean route against full route** through the Scene (the full route on the facet sum, `torque=\"facets\"`; the tumbler at 1 au, e = 0.1, 6 h, "
              "tolerance 0.01 rad), outputs at 1, 2, 4 and 8 orbits (whole) and at 1.5 and 2.5 orbits (half): the largest difference of the L direction, Z and S (rad, as `mean_difference`) against the "
              "mean route's error estimate.", "",
              "| radius | ΔZ/Z over 8 orbits (full) | whole orbits | half orbits | mean estimate | full (CPU s) | "
              "mean (CPU s) | full rtol |", "|---|---|---|---|---|---|---|---|"]
    for radius, change, whole, half, estimate, cpu_full, cpu_mean, rtol in agree:
        lines.append(f"| {radius * 1000:.0f} m | {change:.2e} | {whole:.2e} | {half:.2e} | {estimate:.2e} | "
                     f"{cpu_full:.2f} | {cpu_mean:.2f} | {rtol:.0e} |")
    lines += ["", "**The planner's choice** for the 200 m tumbler with nutation damping (μQ = 10⁹ Pa), 20 outputs:",
              "", "| span | tolerance | route | mean estimate | estimated cost |", "|---|---|---|---|---|"]
    for years, tolerance, route, estimate, cost in picks:
        lines.append(f"| {years:g} yr | {tolerance:g} | {route} | {estimate.replace('mean estimate ', '')} | {cost} |")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-write", action="store_true", help="print only, do not write docs/thermal.md")
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args(argv)
    start = time.perf_counter()
    costs = rhs_costs(args.repeat)
    agree = agreement()
    picks = choices()
    text = markdown(costs, agree, picks, time.perf_counter() - start)
    print(text)
    if not args.no_write:
        print(write_section("thermal_scene", text, page="thermal.md"))


if __name__ == "__main__":
    main()
