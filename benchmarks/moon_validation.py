"""The Moon models against DE421 over 1, 20 and 100 years, their cost, and their free-mode periods.

Writes two sections of ``docs/validation.md``: ``moon-spans`` (maximum and final attitude difference
and the largest τ, ρ, Iσ differences per model and span, wall time per simulated year) and
``moon-free-modes`` (each model's measured free periods against Rambaux & Williams 2011 and Yang et
al. 2017). Every number on those parts of the page comes from this script::

    PYTHONPATH=$PWD python benchmarks/moon_validation.py            # ≈ 5 min on 2 cores
    PYTHONPATH=$PWD python benchmarks/moon_validation.py --no-write # print only
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine_line, write_section  # noqa: E402

from spinorbit.coupling.lunar_free_modes import (  # noqa: E402
    DEFAULT_SPAN_DAYS,
    DEFAULT_START_DAY,
    DEFAULT_STEP_DAYS,
    FREE_MODES,
    LITERATURE_PERIODS_DAYS,
    free_modes,
)
from spinorbit.time import time_from_tdb_days  # noqa: E402
from spinorbit.coupling.moon import MOON_MODELS, compare_model_with_de421  # noqa: E402

#: (years, output step in days): daily for a year, then coarser so the comparison stays cheap.
SPANS = ((1, 1.0), (20, 5.0), (100, 10.0))
YEAR_DAYS = 365.25
#: ``--quick`` (benchmarks/run_all.py's smoke run): one month, daily.
QUICK_SPANS = ((30 / YEAR_DAYS, 1.0),)
#: Yang et al. 2017 (RAA 17, 127, abstract): the wobble's fitted amplitudes in DE430, arcsec. The
#: kick here sets the size of the model's ellipse; its axis ratio is the model's own.
YANG_WOBBLE_ARCSEC = (8.19, 3.31)


def spans_section():
    rows = []
    for model in MOON_MODELS:
        compare_model_with_de421(model, 10.0, 1.0)  # compile (or load from numba's cache) before timing
        for years, step in SPANS:
            begin = time.perf_counter()
            comparison = compare_model_with_de421(model, years * YEAR_DAYS, step)
            total = time.perf_counter() - begin
            libration = np.max(np.abs(comparison.librations_model - comparison.librations_de421), axis=0)
            rows.append(f"| {model} | {years} | {step:g} d | {comparison.max_difference_arcsec:.4f}″ "
                        f"({comparison.attitude_difference_arcsec[-1]:.4f}″) | {libration[0]:.4f}″ | "
                        f"{libration[1]:.4f}″ | {libration[2]:.4f}″ | "
                        f"{(comparison.wall_seconds + comparison.sampling_seconds) / years:.3f} s | "
                        f"{total / years:.3f} s |")
            print(rows[-1], flush=True)
    head = ("| model | years from J2000 | step | max (final) attitude difference | max Δτ | max Δρ | max ΔIσ "
            "| wall per simulated year: integration (+ DE421 sampling) | the whole call per year |\n"
            "|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    return (f"`python benchmarks/moon_validation.py` ({machine_line()}):\n\n{head}\n" + "\n".join(rows) + "\n\n"
            "Each model runs a 10-day comparison first, so no row times numba's compilation. "
            "The whole call includes building the model (REBOUND set-up, DE421 sampling, and for the de421 "
            "model the core state at the start: shipped for J2000, otherwise carried from DE421's 1969 epoch "
            "once and cached, coupling/lunar_core.py) and the comparison with DE421 at every step.")


def free_modes_section():
    yang = LITERATURE_PERIODS_DAYS["Yang et al. 2017 (DE430)"]
    rambaux = LITERATURE_PERIODS_DAYS["Rambaux & Williams 2011 (DE421)"]
    # Rambaux & Williams give 1056 d, 24.2 yr and 74.6 yr: shown as published, with the days.
    published_text = {"longitude": f"{rambaux['longitude']:.0f} d",
                      "latitude": f"{rambaux['latitude'] / YEAR_DAYS:.1f} yr ({rambaux['latitude']:.0f} d)",
                      "wobble": f"{rambaux['wobble'] / YEAR_DAYS:.1f} yr ({rambaux['wobble']:.0f} d)"}
    rows = ["| published: Rambaux & Williams 2011 (DE421) | " + " | ".join(published_text[m] for m in FREE_MODES)
            + " | | |",
            "| published: Yang et al. 2017 (DE430) | " + " | ".join(f"{yang[m]:.2f} d" for m in FREE_MODES)
            + f" | {YANG_WOBBLE_ARCSEC[0]}″ × {YANG_WOBBLE_ARCSEC[1]}″ "
              f"({YANG_WOBBLE_ARCSEC[0] / YANG_WOBBLE_ARCSEC[1]:.3f}) | |"]
    for model in MOON_MODELS:
        result = free_modes(model)
        relative = result.relative_to()
        rows.append(f"| {model} | " + " | ".join(
            f"{result.modes[m].period_days:.2f} d ({100 * relative[m]:+.3f} %)" for m in FREE_MODES)
            + f" | {result.modes['wobble'].amplitude_arcsec:.2f}″ × {result.modes['wobble'].minor_amplitude_arcsec:.2f}″ "
            f"({result.modes['wobble'].amplitude_arcsec / result.modes['wobble'].minor_amplitude_arcsec:.3f})"
            + f" | {result.wall_seconds:.0f} s |")
        print(rows[-1], flush=True)
    head = ("| | longitude | latitude | wobble | wobble ellipse (axis ratio) | wall (two runs) |\n"
            "|---|---:|---:|---:|---:|---:|")
    return (f"`python benchmarks/moon_validation.py` ({machine_line()}), each model run twice over "
            f"{DEFAULT_SPAN_DAYS / YEAR_DAYS:g} yr from {time_from_tdb_days(DEFAULT_START_DAY).tdb.iso[:16]} TDB "
            f"with a {DEFAULT_STEP_DAYS:g}-d step (percentages against Yang et al. 2017):\n\n{head}\n"
            + "\n".join(rows))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-write", action="store_true", help="print only, do not touch docs/validation.md")
    parser.add_argument("--only", choices=("spans", "free-modes"), help="one section only")
    parser.add_argument("--quick", action="store_true", help="the spans table at 30 d only, print only (smoke run)")
    args = parser.parse_args(argv)
    if args.quick:
        global SPANS
        SPANS = QUICK_SPANS
        args.only, args.no_write = "spans", True
    sections = {"moon-spans": spans_section, "moon-free-modes": free_modes_section}
    for name, build in sections.items():
        if args.only is not None and not name.endswith(args.only):
            continue
        text = build()
        print(text)
        if not args.no_write:
            print(f"wrote {write_section(name, text, page='validation.md')}")


if __name__ == "__main__":
    main()
