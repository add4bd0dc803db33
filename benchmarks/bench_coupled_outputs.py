"""What daily comparison outputs cost the Moon's runs: per simulated year, with and without output stops.

For each Moon model (``spinorbit.coupling.moon.MOON_MODELS``) one year from J2000 against DE421,
daily (365 outputs) and with one output at the end, timed interleaved (wall time per call, the
integration alone as the comparison reports it, and the whole call). The REBOUND-coupled models
("rigid", "core-corrected") run to each output with ``exact_finish_time``, once as the package does
(:func:`spinorbit.coupling.long_run.reach_in_one_step` lets a step reach the next output) and once
with that growth off (the former behaviour: REBOUND keeps the step below the output spacing, a full
and a cut step per day); the BS steps of each are counted. The "de421" model integrates with DOP853
and its dense output, so its outputs cut no step.

Writes the ``coupled_outputs`` section of ``docs/performance.md`` unless ``--no-write``; ``--quick``:
30 days, one round, print only.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import spinorbit.coupling.long_run as long_run  # noqa: E402
from benchmarks._report import Timing, machine_line, write_section  # noqa: E402
from spinorbit.coupling.moon import MOON_MODELS, compare_model_with_de421  # noqa: E402

YEAR_DAYS = 365.25
#: Goal of issue 18 for the daily-output coupled Moon (s of wall time per simulated year).
GOAL_SECONDS_PER_YEAR = 0.05
ROUNDS = 5


def _counting_steps(model, span, step):
    """(comparison, whole-call wall s, BS steps) of compare_model_with_de421 (0 steps for "de421").

    The steps are counted on the simulation ``reach_in_one_step`` is handed before each output.
    """
    if model == "de421":
        begin = time.perf_counter()
        comparison = compare_model_with_de421(model, span, step)
        return comparison, time.perf_counter() - begin, 0
    original = long_run.reach_in_one_step
    seen = {}

    def watching(sim, target):
        seen.setdefault("sim", sim)
        seen.setdefault("start", sim.steps_done)
        original(sim, target)

    long_run.reach_in_one_step = watching
    try:
        begin = time.perf_counter()
        comparison = compare_model_with_de421(model, span, step)
        whole = time.perf_counter() - begin
    finally:
        long_run.reach_in_one_step = original
    return comparison, whole, int(seen["sim"].steps_done - seen["start"])


def measure(span, rounds):
    """{(model, outputs, growth): [(integration s, whole s, steps, max difference ″)]}, interleaved."""
    cases = []
    for model in MOON_MODELS:
        cases.append((model, "daily", True))
        if model != "de421":
            cases.append((model, "daily", False))
        cases.append((model, "end only", True))
    for model in MOON_MODELS:
        compare_model_with_de421(model, 10.0, 1.0)  # compile / load numba's cache, untimed
    samples = {case: [] for case in cases}
    for _ in range(rounds):
        for case in cases:
            model, outputs, growth = case
            long_run.OUTPUT_STEP_GROWTH = 2.0 if growth else 1.0
            try:
                comparison, whole, steps = _counting_steps(model, span, 1.0 if outputs == "daily" else span)
            finally:
                long_run.OUTPUT_STEP_GROWTH = 2.0
            samples[case].append((comparison.wall_seconds, whole, steps, comparison.max_difference_arcsec))
    return samples


def markdown(samples, span, rounds, load):
    years = span / YEAR_DAYS
    lines = ["## Coupled Moon with daily outputs (`benchmarks/bench_coupled_outputs.py`)", "", machine_line(),
             f"One run of {span:g} d from J2000 against DE421 per row, {rounds} rounds interleaved; wall "
             "seconds per simulated year, median (min–max). *Integration* is the comparison's own "
             "`wall_seconds` (for the de421 model the DOP853 run alone, its DE421 sampling outside); "
             f"*whole call* is everything `compare_model_with_de421` does. 1-minute load average "
             f"{load[0]:.1f} before, {load[1]:.1f} after.", "",
             "| model | outputs | step reaches the output | BS steps | integration (s/yr) | whole call (s/yr) "
             f"| max difference from DE421 | goal ≤ {GOAL_SECONDS_PER_YEAR} s/yr (whole, daily) |",
             "|---|---|---|---:|---:|---:|---:|---|"]
    for (model, outputs, growth), rows in samples.items():
        rows = np.array(rows)
        integration = Timing(tuple(rows[:, 0] / years))
        whole = Timing(tuple(rows[:, 1] / years))
        reaches = "—" if model == "de421" else ("yes" if growth else "no (former)")
        steps = "—" if model == "de421" else f"{int(rows[0, 2])}"
        verdict = ""
        if outputs == "daily" and growth:
            verdict = "met" if whole.median <= GOAL_SECONDS_PER_YEAR else f"missed ({whole.median / GOAL_SECONDS_PER_YEAR:.1f}×)"
        lines.append(f"| {model} | {outputs} | {reaches} | {steps} | {integration.text(1.0, '.3f')} | "
                     f"{whole.text(1.0, '.3f')} | {rows[0, 3]:.5f}″ | {verdict} |")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-write", action="store_true", help="print only, do not touch docs/performance.md")
    parser.add_argument("--quick", action="store_true", help="30 days, one round, print only (smoke run)")
    args = parser.parse_args(argv)
    span, rounds = (30.0, 1) if args.quick else (YEAR_DAYS, ROUNDS)
    load_before = os.getloadavg()[0]
    samples = measure(span, rounds)
    text = markdown(samples, span, rounds, (load_before, os.getloadavg()[0]))
    print(text)
    if not (args.no_write or args.quick):
        print(f"wrote {write_section('coupled_outputs', text)}")


if __name__ == "__main__":
    main()
