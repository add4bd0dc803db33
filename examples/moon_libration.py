"""The lunar physical libration from DE421 at J2000, integrated with the orbits, against DE421.

Usage::

    python examples/moon_libration.py                 # 1 year, both models
    python examples/moon_libration.py --years 20 --plot moon20.png

Prints, for each model (rigid: DE421's total moments; core-corrected: the fluid core's share of the
polar moment removed), the maximum and final attitude difference against DE421's librations in
arcsec and the wall time per simulated year; optionally writes a PNG (needs matplotlib) with the
difference and the libration itself. See docs/coupling.md for the measured numbers and what is missing.
"""

import argparse
import time

from spinorbit.commands.moon import plot_comparison
from spinorbit.coupling.moon import MOON_MODELS, compare_with_de421, moon_at_de421


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--years", type=float, default=1.0, help="span from J2000 in Julian years (default 1)")
    parser.add_argument("--step", type=float, default=None, help="comparison spacing in days (default: 1 d per year of span)")
    parser.add_argument("--plot", metavar="FILE.png", help="write the plots (one PNG per model, model name appended)")
    args = parser.parse_args()
    span = 365.25 * args.years
    step = args.step if args.step is not None else max(1.0, round(args.years))
    for model in MOON_MODELS:
        moon = moon_at_de421(model=model)
        start = time.perf_counter()
        single = moon_at_de421(model=model)
        single.integrate(single.sim.t + span)  # one call: the integrator's own cost, no output stops
        single_wall = time.perf_counter() - start
        comparison = compare_with_de421(moon, span, step)
        print(f"{model:15s} max {comparison.max_difference_arcsec:7.3f} arcsec, "
              f"final {comparison.attitude_difference_arcsec[-1]:7.3f} arcsec over {args.years:g} yr; "
              f"wall {single_wall / args.years:.3f} s/yr in one call, "
              f"{comparison.wall_seconds / args.years:.3f} s/yr with output every {step:g} d")
        if args.plot:
            path = args.plot.removesuffix(".png") + f"_{model}.png"
            plot_comparison(comparison, path, f"Moon vs DE421, {model}, {args.years:g} yr")
            print(f"wrote {path}")


if __name__ == "__main__":
    main()
