"""Batch mode: members per second of spinorbit's batch integrators against heyoka's ``taylor_adaptive_batch``.

The members are the Kepler Apophis encounter of ``bench_ensemble.py`` (``encounter_kepler.py``: the
Earth on its geocentric hyperbola, the Sun on Apophis's heliocentric ellipse, moment ratios and rotation
phase drawn as in :mod:`spinorbit.ensemble.apophis`), each member on its own model (its moments).
Engines, timed interleaved (CPU time of this process, ``--repeat`` rounds):

- spinorbit's scalar ``integrate_quaternion``, member after member (the floor of bench_ensemble.py),
  with the perturbers sampled once as a Scene samples them, at the Scene's rtol;
- spinorbit's ``integrate_quaternion_batch`` (:mod:`spinorbit.core.integrators.batch_quaternion`) at
  ``LANES`` lanes on the same models (its end states are checked equal to the scalar's, bit for bit);
- spinorbit's ``integrate_taylor_batch`` (:mod:`spinorbit.core.integrators.batch_taylor`) at
  ``TAYLOR_LANES`` lanes on the Kepler orbits themselves (the Taylor method carries a Kepler perturber's
  orbit as a series; on the Scene's Hermite samples it would clip every step at a sample time), at
  the loosest tol of ``TAYLOR_TOLS`` whose worst member is as accurate as the DOP853 batch's worst
  (end states checked equal to ``integrate_taylor``'s, bit for bit);
- heyoka's ``taylor_adaptive_batch`` at 4 lanes and at its recommended SIMD width (the member's moments
  as per-lane parameters, compact mode off), at the loosest tolerance of ``HEYOKA_TOLS`` whose worst
  member is as accurate as the DOP853 batch's worst, against heyoka at tol 1e-15.

Usage::

    python benchmarks/bench_batch.py               # writes the 'batch' section of docs/performance.md
    python benchmarks/bench_batch.py --quick       # 8 members, 1 round, print only
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import numpy as np
from _report import interleaved_timings, machine_line, ratio_goal, write_section

from spinorbit.core.jit import jit
from spinorbit.core.math.ddouble import fma
from spinorbit.core.math.lanes import lane_of, load_lanes, load_quad, quad_lane

MEMBERS = 64
REPEATS = 5
LANES = (1, 4, 8)
TAYLOR_LANES = (1, 8)
REFERENCE_TOL = 1e-15
HEYOKA_TOLS = (1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12)
TAYLOR_TOLS = (1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12)
PEAK_ROUNDS = 2_000_000
#: Issue 39's goal: the Taylor batch's members/s over heyoka's batch mode's at equal accuracy (stretch 1.5×).
GOAL_RATIO = 1.0
STRETCH_RATIO = 1.5


def attitude_error(q, reference):
    """Rotation angle (rad) between unit quaternions (rows), sign-blind: 4 asin(|q ∓ q_ref| / 2)."""
    q = q / np.linalg.norm(q, axis=1)[:, None]
    d = np.minimum(np.linalg.norm(q - reference, axis=1), np.linalg.norm(q + reference, axis=1))
    return 4.0 * np.arcsin(np.minimum(d / 2.0, 1.0))


def heyoka_batch_run(ek, earth, sun, tol, states, pars, t0, t_end, lanes=None, counts=None):
    """A function running every member through one ``taylor_adaptive_batch`` of ``lanes`` lanes (default
    heyoka's recommended SIMD width; lanes filled in member order, the last batch padded with its last
    member), returning the end states (N, 7); ``counts`` (a dict) receives the mean steps per member and
    the order."""
    import heyoka as hy

    lanes = hy.recommended_simd_size() if lanes is None else lanes
    n = states.shape[0]
    ta = hy.taylor_adaptive_batch(ek.heyoka_system(earth, sun), np.zeros((13, lanes)), tol=tol,
                                  pars=np.zeros((9, lanes)))
    steps = []

    def run():
        out = np.empty((n, 7))
        for start in range(0, n, lanes):
            index = [min(start + k, n - 1) for k in range(lanes)]
            ta.set_time(np.full(lanes, t0))
            ta.state[:] = states[index].T
            ta.pars[:] = pars[index].T
            ta.propagate_until(t_end)
            out[start:start + lanes] = ta.state[:7].T[:min(lanes, n - start)]
            steps.extend(res[3] for res in ta.propagate_res[:min(lanes, n - start)])
        if counts is not None:
            counts.update(steps=float(np.mean(steps)), order=ta.order)
        steps.clear()
        return out

    return run, lanes


@jit(cache=False)
def _multiply_add_chains(x, m, c, times):
    """``times`` rounds of 12 independent chains of multiply-adds a ← a·m + c on values held in registers
    (m and c doubles, Quads or Lanes; x gives the chains' start values in their type)."""
    a0, a1, a2, a3, a4, a5 = x * 1.0, x * 0.9, x * 0.8, x * 0.7, x * 0.6, x * 0.5
    a6, a7, a8, a9, a10, a11 = x * 0.4, x * 0.3, x * 0.2, x * 0.1, x * 0.05, x * 0.01
    for _ in range(times):
        a0, a1, a2, a3, a4, a5 = fma(a0, m, c), fma(a1, m, c), fma(a2, m, c), fma(a3, m, c), fma(a4, m, c), fma(a5, m, c)
        a6, a7, a8, a9, a10, a11 = (fma(a6, m, c), fma(a7, m, c), fma(a8, m, c), fma(a9, m, c), fma(a10, m, c),
                                    fma(a11, m, c))
    return ((a0 + a1) + (a2 + a3)) + ((a4 + a5) + (a6 + a7)) + ((a8 + a9) + (a10 + a11))


@jit(cache=False)
def _chains_quad(values, times):
    out = _multiply_add_chains(load_quad(values, 0), load_quad(values, 8), load_quad(values, 16), times)
    return quad_lane(out, 0)


@jit(cache=False)
def _chains_lanes(values, times):
    out = _multiply_add_chains(load_lanes(values, 0), load_lanes(values, 8), load_lanes(values, 16), times)
    return lane_of((out,), 0)[0]


def peak_rates(repeats=REPEATS, times=PEAK_ROUNDS):
    """This machine's multiply-adds per ns (doubles, medians of interleaved repeats) when nothing but
    multiply-adds in registers limits them: 12 independent chains (more than the units' latency × throughput
    needs) of four-wide (Quad) and of eight-wide (Lanes) instructions. {"quad": …, "lanes": …}."""
    values = np.array([1.0] * 8 + [0.999999] * 8 + [1e-7] * 8)
    runs = {"quad": (_chains_quad, 4), "lanes": (_chains_lanes, 8)}
    for kernel, _ in runs.values():
        kernel(values, 10)
    timings, _ = interleaved_timings([lambda kernel=kernel: kernel(values, times) for kernel, _ in runs.values()],
                                     repeats, clock=time.process_time)
    return {name: 12 * times * width / (timing.median * 1e9) for (name, (_, width)), timing in zip(runs.items(), timings)}


def cauchy_quad_multiply_adds(order, orbit_orders):
    """The four-wide multiply-adds of one step's Cauchy sums in the recurrences (what any implementation of
    them must issue, without the orbit series and the driver): per order k ≤ order − 1, k + 1 terms of the
    attitude's four products and of each perturber's four, and min(k, m) + 1 terms of its cross product u × ρ
    (two, on the orbit series' length m)."""
    total = 0
    for k in range(order):
        total += 4 * (k + 1)
        for m in orbit_orders:
            total += 4 * (k + 1) + 2 * (min(k, m) + 1)
    return total


def loosest(tols, error_of, target):
    """(tol, errors) at the loosest of ``tols`` (loosest first) whose worst member error is ≤ target; the
    tightest tried if none is (the errors say so)."""
    errors = None
    for tol in tols:
        errors = error_of(tol)
        if errors.max() <= target:
            return tol, errors
    return tols[-1], errors


def kepler_models(ek, rows, earth, sun):
    """Each member's model with the Earth and the Sun as Kepler perturbers (the orbits of heyoka's system)."""
    from spinorbit.core import kepler_source, make_model

    sources = []
    for text in (earth, sun):
        mu, a, e, inc, node, argp, mean, epoch = (float(x) for x in text.split())
        sources.append(kepler_source(mu, a, e, inc, node, argp, mean, epoch=epoch))
    return [make_model((row["i1_i3"], row["i2_i3"], 1.0), sources) for row in rows]


def measure(members, repeats, lanes_list, taylor_lanes=TAYLOR_LANES):
    import encounter_kepler as ek
    from spinorbit.core import integrate_quaternion, integrate_taylor, integrate_taylor_batch, make_model
    from spinorbit.core.integrators.batch_quaternion import integrate_quaternion_batch, raise_for_batch_status
    from spinorbit.ensemble.apophis import apophis_parameters

    load = [os.getloadavg()]
    earth, sun = ek.encounter_orbits()
    rows = [dict(row, earth=earth, sun=sun) for row in ek.state_rows(apophis_parameters(members, seed=2029))]
    t0, t_end = ek.span_days()
    states, pars, _ = ek.heyoka_members(rows, earth, sun)
    reference_run, _ = heyoka_batch_run(ek, earth, sun, REFERENCE_TOL, states, pars, t0, t_end)
    reference = reference_run()[:, :4]
    reference /= np.linalg.norm(reference, axis=1)[:, None]

    first = ek.kepler_member(**rows[0])
    result = first.run()
    samples = first.sample_perturbers("user", list(result.plan.kept), first.sample_tolerance)
    rtol = result.stats["rtol"]
    models = [make_model((row["i1_i3"], row["i2_i3"], 1.0), samples.sources()) for row in rows]
    y0s = states[:, :7]

    def scalar():
        return np.array([integrate_quaternion(y0s[i], t0, np.array([t_end]), models[i], rtol=rtol)[-1]
                         for i in range(members)])

    calls = {}

    def batch(lanes):
        ys, stats = integrate_quaternion_batch(y0s, t0, t_end, models, rtol, lanes=lanes)
        raise_for_batch_status(stats)
        calls["rhs"], calls["steps"] = stats["rhs_calls"].mean(), (stats["accepted"] + stats["rejected"]).mean()
        return ys

    # the engine's own cost: the same members torque-free (its right-hand side ~60 ns), at the widest lanes
    free_models = [make_model((row["i1_i3"], row["i2_i3"], 1.0)) for row in rows]
    free_calls = {}

    def free_batch():
        ys, stats = integrate_quaternion_batch(y0s, t0, t_end, free_models, rtol, lanes=max(lanes_list))
        raise_for_batch_status(stats)
        free_calls["rhs"] = stats["rhs_calls"].mean()
        return ys

    scalar_states = scalar()
    batch_states = {w: batch(w) for w in lanes_list}  # compile / cache load, untimed
    identical = all(np.array_equal(batch_states[w], scalar_states) for w in lanes_list)
    spin_error = attitude_error(scalar_states[:, :4], reference)
    target = spin_error.max()

    # the Taylor batch on the Kepler orbits, at the loosest tol as accurate as the DOP853 batch
    k_models = kepler_models(ek, rows, earth, sun)
    taylor_counts = {}

    def taylor_batch(lanes, tol, chosen_models=k_models, counts=taylor_counts):
        ys, stats = integrate_taylor_batch(y0s, t0, t_end, chosen_models, tol, lanes=lanes)
        raise_for_batch_status(stats)
        counts.update(steps=float(stats["steps"].mean()), order=int(stats["order"][0]),
                      orbit_order=float(stats["mean_orbit_order"].mean()))
        return ys

    taylor_tol, taylor_error = loosest(
        TAYLOR_TOLS, lambda tol: attitude_error(taylor_batch(max(taylor_lanes), tol)[:, :4], reference), target)
    taylor_scalar = np.array([integrate_taylor(y0s[i], t0, [t_end], k_models[i], tol=taylor_tol)[-1]
                              for i in range(members)])
    taylor_identical = all(np.array_equal(taylor_batch(w, taylor_tol), taylor_scalar) for w in taylor_lanes)
    free_taylor_counts = {}

    def free_taylor():  # the attitude recurrences alone: the floor of any torque formulation on them
        return taylor_batch(max(taylor_lanes), taylor_tol, free_models, free_taylor_counts)

    import heyoka as hy

    hy_lanes_list = sorted({4, hy.recommended_simd_size()})
    tol, heyoka_error = loosest(HEYOKA_TOLS, lambda tol: attitude_error(
        heyoka_batch_run(ek, earth, sun, tol, states, pars, t0, t_end)[0]()[:, :4], reference), target)
    heyoka_counts = {}
    heyoka_runs = [heyoka_batch_run(ek, earth, sun, tol, states, pars, t0, t_end, lanes=w, counts=heyoka_counts)[0]
                   for w in hy_lanes_list]

    engines = (["scalar"] + [f"batch {w}" for w in lanes_list] + [f"taylor {w}" for w in taylor_lanes]
               + [f"heyoka {w}" for w in hy_lanes_list])
    functions = ([scalar] + [lambda w=w: batch(w) for w in lanes_list]
                 + [lambda w=w: taylor_batch(w, taylor_tol) for w in taylor_lanes] + heyoka_runs
                 + [free_batch, free_taylor])
    timings, _ = interleaved_timings(functions, repeats, clock=time.process_time, warm_up=True)
    free_taylor_timing = timings.pop()
    free_timing = timings.pop()
    peak = peak_rates(repeats)
    load.append(os.getloadavg())
    return dict(members=members, repeats=repeats, rtol=rtol, tol=tol, hy_lanes=hy_lanes_list, identical=identical,
                spin_error=spin_error, heyoka_error=heyoka_error, timings=dict(zip(engines, timings)), load=load,
                lanes_list=lanes_list, rhs_calls=calls["rhs"], steps=calls["steps"],
                free_per_rhs=free_timing.median / members / free_calls["rhs"], free_lanes=max(lanes_list),
                taylor_tol=taylor_tol, taylor_error=taylor_error, taylor_identical=taylor_identical,
                taylor=taylor_counts, heyoka=heyoka_counts, free_taylor=free_taylor_counts,
                free_taylor_timing=free_taylor_timing, taylor_lanes=taylor_lanes, peak=peak)


def markdown(m):
    n = m["members"]
    t = m["timings"]
    hy_best = max((k for k in t if k.startswith("heyoka")), key=lambda k: n / t[k].median)
    heyoka_rate = n / t[hy_best].median
    lines = [machine_line(), "",
             f"The Kepler Apophis encounter (`benchmarks/encounter_kepler.py`), {n} members, each on its own model "
             f"(its moments); CPU time of this process, {m['repeats']} interleaved rounds (median, min–max). "
             f"The DOP853 rows run on the Scene's Hermite samples of the two orbits at the Scene's rtol "
             f"{m['rtol']:.2g}; the Taylor rows on the Kepler orbits themselves (as heyoka), at tol "
             f"{m['taylor_tol']:.0e}, and heyoka at tol {m['tol']:.0e}: for each, the loosest tolerance whose worst "
             "member is as accurate as the DOP853 rows' worst.", "",
             f"| engine | members/s (median) | min–max | against heyoka batch ({hy_best.split()[1]} lanes) |",
             "|---|---|---|---|"]
    for key, timing in t.items():
        kind, _, lanes = key.partition(" ")
        label = {"scalar": "spinorbit `integrate_quaternion`, member after member",
                 "batch": f"spinorbit `integrate_quaternion_batch`, {lanes} lanes",
                 "taylor": f"spinorbit `integrate_taylor_batch`, {lanes} lanes, tol {m['taylor_tol']:.0e}",
                 "heyoka": f"heyoka `taylor_adaptive_batch`, {lanes} lanes, tol {m['tol']:.0e}"}[kind]
        lines.append(f"| {label} | {n / timing.median:.0f} | {n / timing.max:.0f}–{n / timing.min:.0f} | "
                     f"{n / timing.median / heyoka_rate:.2f} |")
    best = max((k for k in t if k.startswith("taylor")), key=lambda k: n / t[k].median)
    ratio = n / t[best].median / heyoka_rate
    ty, hy, free = m["taylor"], m["heyoka"], m["free_taylor"]
    hy_lanes = int(hy_best.split()[1])
    ns_taylor = t[best].median / n / ty["steps"] * 1e9
    ns_heyoka = t[hy_best].median / n / hy["steps"] * 1e9
    ns_free = m["free_taylor_timing"].median / n / free["steps"] * 1e9
    budget = ns_heyoka / GOAL_RATIO * hy["steps"] / ty["steps"]
    orbit = ty["orbit_order"] / 2.0  # mean orbit-series order of each of the two perturbers
    quads = cauchy_quad_multiply_adds(ty["order"], (round(orbit), round(orbit)))
    peak = m["peak"]
    lines += ["", f"Accuracy against heyoka at tol 1e-15 (end attitude): DOP853 worst {m['spin_error'].max():.2e} rad "
              f"(median {np.median(m['spin_error']):.2e}), Taylor batch worst {m['taylor_error'].max():.2e} rad "
              f"(median {np.median(m['taylor_error']):.2e}), heyoka batch worst {m['heyoka_error'].max():.2e} rad "
              f"(median {np.median(m['heyoka_error']):.2e}). The DOP853 batch end states are "
              f"{'the scalar integrator’s, bit for bit' if m['identical'] else 'NOT the scalar integrator’s bits'}, "
              f"the Taylor batch's {'integrate_taylor’s, bit for bit' if m['taylor_identical'] else 'NOT integrate_taylor’s bits'}. "
              f"The 1-minute load average was {m['load'][0][0]:.2f} before and {m['load'][1][0]:.2f} after "
              "(the 2 cores are shared). "
              + f"The goal (issue 39: the best Taylor batch row against heyoka's best batch row, members/s at "
              f"equal accuracy): {ratio_goal(f'Taylor batch / heyoka batch ({n} members)', ratio, GOAL_RATIO, stretch=STRETCH_RATIO)}.",
              "",
              "| per member | steps | order | orbit-series order (mean, summed over both perturbers) | "
              "CPU per lane-step (ns) |", "|---|---:|---:|---:|---:|",
              f"| spinorbit Taylor batch, {best.split()[1]} lanes | {ty['steps']:.1f} | {ty['order']} | "
              f"{ty['orbit_order']:.1f} | {ns_taylor:.0f} |",
              f"| the same members torque-free (attitude recurrences alone) | {free['steps']:.1f} | {free['order']} | – | "
              f"{ns_free:.0f} |",
              f"| heyoka batch, {hy_lanes} lanes | {hy['steps']:.1f} | {hy['order']} | – | {ns_heyoka:.0f} |",
              "",
              f"Where the floor is: both Taylor methods take about the same steps (heyoka's order and step rule), so "
              f"the throughput is the cost per lane-step. heyoka's batch mode runs its straight-line Taylor code on "
              f"{hy_lanes} lanes in SIMD registers, {ns_heyoka:.0f} ns per lane-step; {GOAL_RATIO:g}× its "
              f"throughput would need {budget:.0f} ns per lane-step at our step count. spinorbit's lanes are interleaved, each lane the "
              f"recurrences that multiply four doubles per instruction (`Quad`, `docs/design.md`): {ns_taylor:.0f} ns "
              f"per lane-step, and the attitude recurrences alone (no torque) {ns_free:.0f} ns. This machine's "
              f"multiply-add rate when nothing else limits it (`peak_rates`: 12 independent chains in registers) is "
              f"{peak['quad']:.1f} doubles per ns in four-wide instructions and {peak['lanes']:.1f} in eight-wide ones, "
              "so members in the lanes of eight-wide vectors " + ("would add little arithmetic to what the four-wide "
              "recurrences can issue" if peak["lanes"] < 1.25 * peak["quad"] else "could issue more arithmetic") +
              f". The Cauchy sums of one step at order {ty['order']} with the mean orbit-series orders are "
              f"{quads} four-wide multiply-adds (`cauchy_quad_multiply_adds`: the products alone, without the orbit "
              f"series, the newest terms' bookkeeping, the stores and the driver): {4 * quads / peak['quad']:.0f} ns "
              f"at the peak rate, {4 * quads / peak['quad'] / budget:.0%} of the goal's budget, leaving "
              f"{budget - 4 * quads / peak['quad']:.0f} ns for everything else of the step. The present step issues "
              f"them at {4 * quads / ns_taylor / peak['quad']:.0%} of the peak rate on average.",
              ]
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--members", type=int, default=MEMBERS)
    parser.add_argument("--repeat", type=int, default=REPEATS)
    parser.add_argument("--quick", action="store_true", help="8 members, 1 round, print only")
    parser.add_argument("--no-write", action="store_true", help="print only, do not touch docs/performance.md")
    args = parser.parse_args(argv)
    members, repeats = (8, 1) if args.quick else (args.members, args.repeat)
    text = markdown(measure(members, repeats, LANES))
    print(text)
    if not (args.no_write or args.quick):
        print(f"wrote {write_section('batch', text)}")


if __name__ == "__main__":
    main()
