"""
The Moon's physical libration against DE421
===========================================

The lunar physical libration from DE421 at J2000 (or --start), integrated with the orbits, against DE421.

Usage::

    python examples/moon_libration.py                 # 1 year, all three models
    python examples/moon_libration.py --years 20 --plot moon20.png
    python examples/moon_libration.py --years 5 --models de421 --ablation
    python examples/moon_libration.py --start 1920-01-01 --years 100 --step 10

Prints, for each model (de421: DE421's mantle + fluid core + tides on DE421's orbits; rigid: DE421's
total moments; core-corrected: the fluid core's share of the polar moment removed), the maximum and
final attitude difference against DE421's librations in arcsec and the wall time per simulated year;
optionally writes a PNG per model (needs matplotlib) with the difference and the libration itself.
``--ablation`` reruns the de421 model with one term switched off at a time (which terms matter).
See docs/coupling.md for the measured numbers.
"""
# gallery-arguments: --models de421 --plot moon.png
# sphinx_gallery_thumbnail_path = "gallery/moon_libration.png"


import argparse
import time

import numpy as np
from astropy.time import Time

from spinorbit.commands.moon import plot_comparison
from spinorbit.core.integrators.quaternion import integrate_quaternion
from spinorbit.core.model.lunar_interior import (
    IN_CORE_A,
    IN_CORE_C,
    IN_EARTH_J2R2,
    IN_K2,
    IN_KV,
    IN_TAU,
    INTERIOR_SIZE,
)
from spinorbit.coupling.moon import (
    INTERIOR_RTOL,
    MOON_MODELS,
    _comparison,
    _output_times,
    compare_interior_with_de421,
    compare_with_de421,
    core_angular_velocity,
    interior_model,
    moon_at_de421,
)
from spinorbit.ephemeris import moon_orientation_raw
from spinorbit.time import tdb_day_and_fraction


def run_rigid(model, span, step, years, epoch):
    start = time.perf_counter()
    single = moon_at_de421(epoch=epoch, model=model)
    single.integrate(single.sim.t + span)  # one call: the integrator's own cost, no output stops
    single_wall = time.perf_counter() - start
    comparison = compare_with_de421(moon_at_de421(epoch=epoch, model=model), span, step)
    return comparison, f"wall {single_wall / years:.3f} s/yr in one call, {comparison.wall_seconds / years:.3f} s/yr with output"


def run_de421(span, step, years, start_day):
    comparison = compare_interior_with_de421(span, step, start_day=start_day)
    return comparison, (f"wall {comparison.wall_seconds / years:.3f} s/yr integration, "
                        f"{comparison.sampling_seconds / years:.3f} s/yr sampling DE421's orbits")


#: One term off at a time: (label, what to change in the interior block, perturbers).
ABLATIONS = (
    ("full model", {}, None),
    ("no tides or spin distortion (k2 = 0)", {IN_K2: 0.0}, None),
    ("no tidal delay (tau = 0)", {IN_TAU: 0.0}, None),
    ("no core-mantle friction (k_v = 0)", {IN_KV: 0.0}, None),
    ("spherical core boundary (C_c = A_c)", {IN_CORE_A: None}, None),
    ("no Earth J2 on the lunar figure", {IN_EARTH_J2R2: 0.0}, None),
    ("Earth and Sun only (no planets)", {}, ("earth", "sun")),
)


def ablation(span, step):
    times = _output_times(0.0, span, step)
    quaternion, omega = moon_orientation_raw(0.0, 0.0)
    core = np.array(core_angular_velocity(0.0))
    for label, changes, perturbers in ABLATIONS + (("core started with the mantle's spin", {}, "core"),):
        model = interior_model(times[0], times[-1], *(() if perturbers in (None, "core") else (perturbers,)))
        for index, value in changes.items():
            where = model.size - INTERIOR_SIZE + index
            model[where] = model[model.size - INTERIOR_SIZE + IN_CORE_C] if value is None else value
        state = np.concatenate([quaternion, omega, omega if perturbers == "core" else core])
        states = integrate_quaternion(state, 0.0, times[1:], model, rtol=INTERIOR_RTOL)
        result = _comparison(times, np.vstack([quaternion, states[:, :4]]), 0.0)
        print(f"  {label:40s} max {result.max_difference_arcsec:9.5f} arcsec")


def main():
    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument("--start", default="2000-01-01T12:00:00", help="start, ISO date TDB (default J2000.0)")
    parser.add_argument("--years", type=float, default=1.0, help="span from --start in Julian years (default 1)")
    parser.add_argument("--step", type=float, default=None, help="comparison spacing in days (default: 1 d per year of span)")
    parser.add_argument("--models", nargs="+", choices=MOON_MODELS, default=list(MOON_MODELS))
    parser.add_argument("--plot", metavar="FILE.png", help="write the plots (one PNG per model, model name appended)")
    parser.add_argument("--ablation", action="store_true", help="de421 model with one term off at a time")
    args = parser.parse_args()
    span = 365.25 * args.years
    step = args.step if args.step is not None else max(1.0, round(args.years))
    epoch = Time(args.start, scale="tdb")
    start_day = float(sum(tdb_day_and_fraction(epoch)))
    for model in args.models:
        comparison, timing = run_de421(span, step, args.years, start_day) if model == "de421" else run_rigid(
            model, span, step, args.years, epoch)
        print(f"{model:15s} max {comparison.max_difference_arcsec:8.5f} arcsec, "
              f"final {comparison.attitude_difference_arcsec[-1]:8.5f} arcsec over {args.years:g} yr; {timing}")
        if args.plot:
            path = args.plot.removesuffix(".png") + f"_{model}.png"
            plot_comparison(comparison, path, f"Moon vs DE421, {model}, {args.years:g} yr")
            print(f"wrote {path}")
    if args.ablation:
        print(f"de421 model, one term off at a time, {args.years:g} yr from J2000:")
        ablation(span, step)


if __name__ == "__main__":
    main()
