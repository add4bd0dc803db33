"""Work-precision benchmark: attitude error against CPU time, spinorbit and its peers in one run.

For each scene of ``benchmarks/scenes.py`` and each method of ``benchmarks/peers.py`` (adding a method
is adding an entry to ``peers.METHODS``) and each tolerance:

- error: the largest rotation angle (rad) between the method's attitude and the reference attitude
  over the scene's output times (10 times spread over the span, the last one at the end);
- CPU: ``time.process_time`` of one integration, the median of several repeats, with their minimum
  and maximum beside it; compilation (heyoka's LLVM, numba's first call / cache load) is done
  beforehand and reported separately.

Reference: heyoka's Taylor integrator in x86 extended precision (long double, tol = ε ≈ 1.1e-19),
checked against spinorbit's own integrator at rtol = 1e-14 landing on the output times: two
independent methods and implementations; their disagreement is printed in the report.

Also: convergence orders of every integrator's fixed-step mode (quaternion DOP853, canonical
elements, Taylor at orders 4/6/8, the splitting schemes) in scenes (a) and (c) over a short span,
attitude error against the extended-precision reference as the step is halved; and the cost per step
of spinorbit's Taylor method against heyoka's (steps, order, ns per step).

spinorbit's Taylor method and heyoka are also timed head to head, interleaved run by run
(:func:`head_to_head`), so that the ratio the issue's goal is about sees the same machine load on
both sides. heyoka runs in its faster mode on each scene (compact or not, ``peers.fastest_heyoka_integrator``),
which the report names.

A method's sweep over tolerances stops once one point costs more than SLOW_POINT_S of CPU (the more
accurate points would cost more still), so that the whole run takes a few minutes.

Writes ``docs/img/work_precision_<scene>.png`` and the ``work_precision`` section of
``docs/performance.md``. ``--averaged`` then runs the long-span comparison of the averaged
propagator against heyoka (``benchmarks/bench_averaged.py``, its own section). ``--quick`` runs
shortened scenes and fewer tolerances and only prints (a
smoke test, not the published numbers).
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import itertools

from benchmarks._report import DOCS, interleaved_timings, machine_line, write_section
from benchmarks.peers import METHODS, MODE_TRIAL_STEPS, prepare_spinorbit, reference_solution
from benchmarks.scenes import all_scenes
from spinorbit.runs.atomic import atomic_path
from spinorbit.core.integrators.elements import integrate_elements_fixed_step
from spinorbit.core.integrators.quaternion import integrate_fixed_step
from spinorbit.core import integrate_quaternion, integrate_splitting, integrate_taylor, make_model
from spinorbit.core.integrators.taylor import integrate_taylor_fixed_step
from spinorbit.core.math.rotations import rotation_angle_between_many

#: Accuracy at which methods are compared (rad).
TARGET_ERROR = 1e-10
#: Scene (c) (10⁴ rotations) cannot reach 1e-10 rad in double precision with any method here (the
#: phase error of ~2e5 steps accumulates), so it is also compared at this looser accuracy (rad).
TARGET_ERROR_LONG = 1e-6
#: Repeat a timing until this much CPU time is spent (s) or MAX_REPEATS runs are done; up to 25 so
#: that the millisecond runs (heyoka, Taylor) get enough repeats for a median through bursts of load.
TIMING_BUDGET_S = 1.0
MAX_REPEATS = 25
#: Tolerances of the interleaved Taylor-vs-heyoka timing (head_to_head): brackets 1e-8, 1e-10 and 1e-6 rad.
HEAD_TO_HEAD_TOLERANCES = (1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13)
#: Accuracies of the head-to-head ratio (issue 18's goal: ≥ 1.5× faster than heyoka at both), rad;
#: scene (c) at TARGET_ERROR_LONG.
HEAD_TO_HEAD_TARGETS = (1e-8, TARGET_ERROR)
#: A method's sweep stops after a point that costs more than this (s of CPU): keeps the run short.
SLOW_POINT_S = 1.5


def attitude_error(ys, ref):
    a = np.ascontiguousarray(ys[:, :4], dtype=float)
    b = np.ascontiguousarray(ref[:, :4], dtype=float)
    return float(rotation_angle_between_many(a, b).max())


def time_run(run):
    """Process times of run() (≥ 1 repeats, until TIMING_BUDGET_S or MAX_REPEATS) as a Timing, and its result."""
    (timing,), (result,) = interleaved_timings([run], MAX_REPEATS, time.process_time, TIMING_BUDGET_S)
    return timing, result


def cpu_at_error(points, target=TARGET_ERROR):
    """CPU time at the target error by log-log interpolation between the two bracketing points.

    points: list of (error, cpu). Returns (cpu, how) with how = 'interpolated', or (None, reason).
    """
    pts = sorted((e, c) for e, c in points if e > 0 and math.isfinite(e))
    if not pts:
        return None, "no points"
    # Walk from the least accurate point to the most accurate one; use the first bracketing pair.
    pts.sort(key=lambda p: -p[0])
    for (e1, c1), (e2, c2) in itertools.pairwise(pts):
        if e1 >= target >= e2:
            if e1 == e2:
                return min(c1, c2), "interpolated"
            w = (math.log(target) - math.log(e1)) / (math.log(e2) - math.log(e1))
            return math.exp(math.log(c1) + w * (math.log(c2) - math.log(c1))), "interpolated"
    if pts[-1][0] > target:
        return None, f"not reached (best {pts[-1][0]:.1e} rad)"
    return pts[0][1], "all points more accurate; cheapest shown"


def rhs_cost_ns(model, y, t0, calls=200_000):
    """CPU per call (ns) of the compiled RHS alone, in a numba loop (no integrator around it)."""
    import numba

    from spinorbit.core.dynamics.equations import rhs_into

    @numba.njit
    def loop(y, model, t0, n):
        dy = np.empty(7)
        s = 0.0
        for i in range(n):
            rhs_into(t0 + i * 1e-4, y, model, dy)
            s += dy[4]
        return s

    loop(y, model, t0, 10)
    t = time.process_time()
    loop(y, model, t0, calls)
    return (time.process_time() - t) / calls * 1e9


def cost_breakdown(scene, tol=1e-12):
    """Where spinorbit's time goes at one tolerance: steps, RHS calls, RHS cost with/without torque."""
    from spinorbit.core.integrators.quaternion import default_atol

    y0 = np.asarray(scene.y0, float)
    atol = default_atol(y0, tol)

    def run():
        return integrate_quaternion(y0, scene.t0, scene.t_out, scene.model, rtol=tol, atol=atol, return_stats=True)

    run()
    timing, (_, stats) = time_run(run)
    cpu = timing.median
    with_torque = rhs_cost_ns(scene.model, y0, scene.t0)
    free = rhs_cost_ns(make_model(scene.moments), y0, scene.t0)
    per_call = cpu / stats["rhs_calls"] * 1e9
    return (f"Cost breakdown, spinorbit at rtol = {tol:.0e}: {stats['accepted']} accepted + {stats['rejected']} "
            f"rejected steps, {stats['rhs_calls']} RHS calls, {per_call:.0f} ns of CPU per RHS call in the "
            f"integrator; the RHS alone costs {with_torque:.0f} ns with the torque model and {free:.0f} ns "
            f"torque-free, so the torque (perturber positions, Kepler solves) is "
            f"{(with_torque - free) / per_call:.0%} of the integrator's time, the torque-free RHS "
            f"{free / per_call:.0%} and the DOP853 stage arithmetic, error norm and dense output the rest "
            f"({(per_call - with_torque) / per_call:.0%}).")


def _splitting_fixed(scheme):
    def run(y0, t0, t1, n, model):
        return integrate_splitting(y0, t0, np.array([t1]), model, (t1 - t0) / n, scheme)[0]
    return run


#: Fixed-step integrators whose order is measured: (label, theoretical order, y(t1) from n steps).
ORDER_METHODS = [
    ("quaternion DOP853", 8, integrate_fixed_step),
    ("canonical elements DOP853", 8, integrate_elements_fixed_step),
    ("Taylor, order 4", 4, lambda y0, t0, t1, n, model: integrate_taylor_fixed_step(y0, t0, t1, n, model, 4)),
    ("Taylor, order 6", 6, lambda y0, t0, t1, n, model: integrate_taylor_fixed_step(y0, t0, t1, n, model, 6)),
    ("Taylor, order 8", 8, lambda y0, t0, t1, n, model: integrate_taylor_fixed_step(y0, t0, t1, n, model, 8)),
    ("splitting Strang", "2", _splitting_fixed("strang")),
    ("splitting SABA2", "2 (4 as ε → 0)", _splitting_fixed("saba2")),
    ("splitting SABA4", "2 (8 as ε → 0)", _splitting_fixed("saba4")),
    ("splitting Yoshida4", "4", _splitting_fixed("yoshida4")),
    ("splitting Yoshida6", "6", _splitting_fixed("yoshida6")),
]


#: Step counts relative to the DOP853 rows, per method: low-order splittings need more steps to reach
#: the asymptotic regime, SABA4/Yoshida6 fewer (at 8× they are already at the rounding floor).
STEP_FACTOR = {"splitting Strang": 8, "splitting SABA2": 8, "splitting Yoshida4": 8, "splitting SABA4": 2,
               "splitting Yoshida6": 2, "Taylor, order 4": 2, "Taylor, order 6": 2, "Taylor, order 8": 2}


def measure_orders(scene, spans_steps, integrate):
    """Fixed-step convergence: attitude error at t_end for n, 2n, 4n… steps; orders log2(e_n/e_2n)."""
    span, steps = spans_steps
    ref = _short_reference(scene, span)
    rows = []
    for n in steps:
        y = integrate(scene.y0, scene.t0, scene.t0 + span, n, scene.model)
        rows.append((n, attitude_error(np.asarray(y)[None, :], ref)))
    orders = [math.log2(e1 / e2) if e2 > 0 else math.nan for (_, e1), (_, e2) in itertools.pairwise(rows)]
    return rows, orders


_REFERENCES = {}


def _short_reference(scene, span):
    key = (scene.name, span)
    if key not in _REFERENCES:
        short = dataclasses.replace(scene, t_out=np.array([scene.t0 + span]))
        _REFERENCES[key] = reference_solution(short)[0]
    return _REFERENCES[key]


#: Tolerances of the Taylor cost-per-step table (taylor_cost_rows): heyoka's order is 11 … 14 there.
TAYLOR_COST_TOLERANCES = (1e-8, 1e-9, 1e-10, 1e-11)


def taylor_cost_rows(scene, tolerances=TAYLOR_COST_TOLERANCES):
    """Where the Taylor floor is: steps and CPU per step of spinorbit (torqued and torque-free) and heyoka.

    The three are timed interleaved (propagate_until / one output, no grid) at each tol, so they see
    the same load. The torque-free row integrates the same initial state with the perturbers removed:
    it is what a step of spinorbit's recurrences costs without the torque, the lower bound of any
    torque formulation. Returns markdown table rows.
    """
    from benchmarks.peers import make_heyoka_integrator

    end = np.asarray(scene.t_out[-1:], float)
    free = make_model(scene.moments)
    rows = []
    for tol in tolerances:
        ta, state = make_heyoka_integrator(scene, tol)

        def ours(model):
            def run():
                return integrate_taylor(scene.y0, scene.t0, end, model, tol=tol, return_stats=True)
            run()
            return run

        def theirs():
            ta.state[:] = state
            ta.time = scene.t0
            return ta.propagate_until(float(end[0]))

        load = os.getloadavg()[0]
        (t_ours, t_free, t_hy), (res_ours, res_free, res_hy) = interleaved_timings(
            [ours(scene.model), ours(free), theirs], MAX_REPEATS, time.process_time, 3 * TIMING_BUDGET_S)
        steps, steps_free, steps_hy = res_ours[1]["steps"], res_free[1]["steps"], int(res_hy[3])
        rows.append(f"| ({scene.name}) | {tol:.0e} | {res_ours[1]['order']} / {ta.order} | "
                    f"{res_ours[1]['mean_orbit_order']:.1f} | "
                    f"{steps} ({steps / scene.rotations:.2f}) | {steps_hy} ({steps_hy / scene.rotations:.2f}) | "
                    f"{t_ours.median / steps * 1e9:.0f} | {t_hy.median / steps_hy * 1e9:.0f} | "
                    f"{t_free.median / steps_free * 1e9:.0f} | {t_ours.text()} | {t_hy.text()} | "
                    f"{t_hy.median / t_ours.median:.2f} | {load:.1f}–{os.getloadavg()[0]:.1f} |")
        print("   " + rows[-1], flush=True)
    return rows


TAYLOR_COST_HEAD = (
    "| scene | tol | order (spinorbit / heyoka) | spinorbit orbit-series order (mean, summed over perturbers) "
    "| spinorbit steps (per rotation) | heyoka steps (per rotation) "
    "| spinorbit ns/step | heyoka ns/step | spinorbit torque-free ns/step | spinorbit ms | heyoka ms "
    "| heyoka / spinorbit (medians) | load (1 min) |\n"
    "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|")


def head_to_head(scene, ref, tolerances):
    """spinorbit Taylor and heyoka timed *interleaved* (ours, theirs, ours, …) at each tolerance.

    The sweep times one method after the other, seconds apart; on a shared machine the load changes
    in between. Alternating the two makes both see the same load. Each is called once untimed first (the
    first call of a process pays one-off costs). Repeats: up to MAX_REPEATS pairs or 2 × TIMING_BUDGET_S of CPU. Returns two lists of (error, Timing) and the (lowest, highest) 1-minute
    load average seen before and after each tolerance.
    """
    from benchmarks.peers import prepare_heyoka, prepare_spinorbit_taylor

    ours_pts, theirs_pts = [], []
    loads = [os.getloadavg()[0]]
    for tol in tolerances:
        runs = [prepare_spinorbit_taylor(scene, tol)[0], prepare_heyoka(scene, tol)[0]]
        (ours, theirs), outputs = interleaved_timings(runs, MAX_REPEATS, time.process_time, 2 * TIMING_BUDGET_S,
                                                      warm_up=True)
        ours_pts.append((attitude_error(outputs[0], ref), ours))
        theirs_pts.append((attitude_error(outputs[1], ref), theirs))
        loads.append(os.getloadavg()[0])
    return ours_pts, theirs_pts, (min(loads), max(loads))


def _at_error(points, statistic, target):
    """cpu_at_error of (error, Timing) points by one statistic of the timings ('median', 'min', 'max')."""
    return cpu_at_error([(e, getattr(t, statistic)) for e, t in points], target)


def heyoka_mode_line(infos):
    """One sentence naming heyoka's mode at each tolerance and the trial that chose it."""
    parts = []
    for tol, info in sorted(infos.items(), reverse=True):
        trial = info["mode_trial_cpu"]
        parts.append(f"{tol:.0e}: {'compact' if info['compact_mode'] else 'non-compact'} "
                     f"({trial[False] * 1e3:.2f} ms non-compact, {trial[True] * 1e3:.2f} ms compact)")
    return (f"heyoka mode, the faster of the two by the median of interleaved {MODE_TRIAL_STEPS}-step trials, "
            "per tolerance: "
            + "; ".join(parts) + ".")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="short scenes, few tolerances (smoke test)")
    parser.add_argument("--scenes", default="abc", help="which scenes to run, e.g. 'a' or 'ac'")
    parser.add_argument("--no-write", action="store_true", help="print only; do not touch docs/")
    parser.add_argument("--averaged", action="store_true",
                        help="then the averaged propagator against heyoka over 1000 orbits (benchmarks/bench_averaged.py, "
                             "its own section of docs/performance.md; with --quick: 30 orbits, print only)")
    args = parser.parse_args(argv)
    if args.quick:
        # A smoke run must never overwrite the published plots and tables.
        args.no_write = True

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scenes = [s for s in all_scenes(quick=args.quick) if s.name in args.scenes]
    md = [machine_line(), ""]
    md.append(
        "Attitude error = largest rotation angle between the computed and the reference attitude over "
        "10 output times spanning the run (rad). CPU = `time.process_time` of one integration, median of "
        f"up to {MAX_REPEATS} repeats (their min–max in the tables), one core, compilation excluded "
        "(reported separately); ratios and interpolations use the medians. Reference: "
        "heyoka Taylor in 80-bit extended precision at tol = 1.1e-19. spinorbit's tolerance is its rtol "
        "(atol = rtol × component scale); heyoka's is its tol; scipy gets the same rtol/atol as spinorbit."
    )
    md.append("")
    summary = []
    taylor_cost = []
    for scene in scenes:
        print(f"== scene ({scene.name}) {scene.title}", flush=True)
        ref, ref_s = reference_solution(scene)
        run_check, _ = prepare_spinorbit(scene, 1e-14, hit_output_times=True)
        agreement = attitude_error(run_check(), ref)
        print(f"   reference {ref_s:.1f} s; spinorbit rtol=1e-14 vs reference: {agreement:.2e} rad", flush=True)
        results = {}
        compile_times = {}
        heyoka_modes = {}
        methods = [m for m in METHODS if scene.name in m.scenes]
        for method in methods:
            tols = method.tolerances
            if method.name.startswith("scipy"):
                # scipy's Python-level loop is slow: fewer tolerances on the long scenes.
                if args.quick:
                    tols = tols[:1]
                elif scene.name == "c":
                    tols = tols[:2]
            pts = []
            for tol in tols:
                run, info = method.prepare(scene, tol)
                compile_times.setdefault(method.name, []).append(info["prepare_s"])
                if "compact_mode" in info:
                    heyoka_modes[tol] = info
                timing, ys = time_run(run)
                err = attitude_error(ys, ref)
                pts.append((tol, err, timing))
                print(f"   {method.name:28s} tol={tol:.0e}  err={err:.2e} rad  cpu={timing.text()} ms", flush=True)
                if timing.median > SLOW_POINT_S:
                    break
            results[method.name] = pts

        # Plot.
        fig, ax = plt.subplots(figsize=(6.4, 4.6))
        for method in methods:
            pts = results[method.name]
            ax.loglog([p[2].median for p in pts], [p[1] for p in pts], marker=method.marker, color=method.color,
                      label=method.name)
            for tol, err, timing in pts:
                ax.annotate(f"{tol:.0e}", (timing.median, err), fontsize=6, textcoords="offset points",
                            xytext=(3, 3))
        ax.axhline(TARGET_ERROR_LONG if scene.name == "c" else TARGET_ERROR, color="0.7", lw=0.8, ls="--")
        ax.set_xlabel("CPU time per integration (s, median)")
        ax.set_ylabel("max attitude error (rad)")
        ax.set_title(f"({scene.name}) {scene.title}", fontsize=9)
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=7)
        fig.tight_layout()
        img = DOCS / "img" / f"work_precision_{scene.name}.png"
        if not args.no_write:
            img.parent.mkdir(parents=True, exist_ok=True)
            with atomic_path(img) as temporary:
                fig.savefig(temporary, format="png", dpi=120)
        plt.close(fig)

        # Table.
        md.append(f"### Scene ({scene.name}): {scene.title}")
        md.append("")
        md.append(scene.notes)
        md.append("")
        md.append(f"Reference check: spinorbit at rtol = 1e-14 (steps landing on the output times) differs "
                  f"from the extended-precision heyoka reference by {agreement:.1e} rad.")
        md.append("")
        md.append(f"![work-precision ({scene.name})](img/work_precision_{scene.name}.png)")
        md.append("")
        md.append("| method | tolerance | max attitude error (rad) | CPU median (ms) | min–max (ms) | runs |")
        md.append("|---|---|---|---|---|---|")
        for method in methods:
            for tol, err, t in results[method.name]:
                md.append(f"| {method.name} | {tol:.0e} | {err:.2e} | {t.median * 1e3:.2f} | "
                          f"{t.min * 1e3:.2f}–{t.max * 1e3:.2f} | {len(t.samples)} |")
        md.append("")
        comp = ", ".join(f"{k}: {np.median(v):.2f} s" for k, v in compile_times.items())
        md.append(f"One-off preparation per tolerance (median; excluded from CPU): {comp}.")
        md.append("")
        if heyoka_modes:
            md.append(heyoka_mode_line(heyoka_modes))
            md.append("")
        target = TARGET_ERROR_LONG if scene.name == "c" else TARGET_ERROR
        at = {}
        for method in methods:
            at[method.name] = cpu_at_error([(e, t.median) for _, e, t in results[method.name]], target)
        by_name = dict(at)
        taylor = by_name["spinorbit Taylor (numba)"]
        pure = by_name.get("scipy DOP853, pure-Python RHS", (None, "not run"))
        so = by_name["spinorbit DOP853 (numba)"]
        so_tab = by_name["spinorbit DOP853, tabulated perturbers"]
        hy_ = by_name["heyoka Taylor"]
        sp = by_name["scipy DOP853 (Python RHS)"]
        line = f"CPU at {target:.0e} rad (log-log interpolation): " + "; ".join(
            f"{name}: {'%.2f ms' % (v[0] * 1e3) if v[0] else v[1]}" for name, v in at.items())
        md.append(line + ".")
        # (numerator label, numerator, denominator label, denominator, format): slower / faster.
        pairs = [("spinorbit Taylor", taylor, "heyoka", hy_, ".2f"),
                 ("scipy DOP853 pure-Python RHS", pure, "spinorbit Taylor", taylor, ".0f"),
                 ("scipy DOP853 (compiled RHS)", sp, "spinorbit Taylor", taylor, ".0f"),
                 ("spinorbit", so, "heyoka", hy_, ".2f"),
                 ("spinorbit tabulated", so_tab, "heyoka", hy_, ".2f"),
                 ("scipy DOP853", sp, "spinorbit", so, ".0f"),
                 ("scipy DOP853", sp, "spinorbit tabulated", so_tab, ".0f")]
        ratios = [f"{a} / {b} = {x[0] / y[0]:{fmt}}" for a, x, b, y, fmt in pairs if x[0] and y[0]]
        md.append("")
        md.append(f"**Ratios at {target:.0e} rad:** " + ("; ".join(ratios) if ratios else "not measurable (see above)") + ".")
        same_tol = [(tol, c_sp.median / c_so.median) for (tol, _, c_sp) in results["scipy DOP853 (Python RHS)"]
                    for (tol2, _, c_so) in results["spinorbit DOP853 (numba)"] if tol == tol2]
        if same_tol:
            md.append("")
            md.append("scipy DOP853 / spinorbit DOP853 at the same rtol (same method, same steps, same error): "
                      + ", ".join(f"{r:.0f}× at {t:.0e}" for t, r in same_tol) + ".")
        md.append("")
        breakdown = cost_breakdown(scene)
        print("   " + breakdown, flush=True)
        md.append(breakdown)
        md.append("")
        h2h_ours, h2h_theirs, h2h_load = head_to_head(scene, ref, HEAD_TO_HEAD_TOLERANCES)
        h2h_text = (f"**Head to head** (spinorbit Taylor and heyoka timed interleaved at tol "
                    f"{', '.join(f'{t:.0e}' for t in HEAD_TO_HEAD_TOLERANCES)}; (error rad, median CPU ms "
                    "[min–max]) ours: "
                    + ", ".join(f"({e:.1e}, {t.median * 1e3:.2f} [{t.min * 1e3:.2f}–{t.max * 1e3:.2f}])"
                                for e, t in h2h_ours) + "; heyoka: "
                    + ", ".join(f"({e:.1e}, {t.median * 1e3:.2f} [{t.min * 1e3:.2f}–{t.max * 1e3:.2f}])"
                                for e, t in h2h_theirs) + "): ")
        verdicts = []
        for h2h_target in (TARGET_ERROR_LONG,) if scene.name == "c" else HEAD_TO_HEAD_TARGETS:
            h2h = {stat: (_at_error(h2h_ours, stat, h2h_target), _at_error(h2h_theirs, stat, h2h_target))
                   for stat in ("median", "min", "max")}
            (ours_med, _), (theirs_med, _) = h2h["median"]
            if ours_med and theirs_med:
                spread = [h2h[stat][0][0] / h2h[stat][1][0] for stat in ("min", "max")
                          if h2h[stat][0][0] and h2h[stat][1][0]]
                text = (f"at {h2h_target:.0e} rad spinorbit Taylor {ours_med * 1e3:.2f} ms, heyoka "
                        f"{theirs_med * 1e3:.2f} ms (medians), ratio **{ours_med / theirs_med:.2f}**, heyoka "
                        f"{theirs_med / ours_med:.2f}× spinorbit's CPU")
                text += (f" (ratio by the minima {spread[0]:.2f}, by the maxima {spread[1]:.2f})"
                         if len(spread) == 2 else "")
            else:
                text = f"at {h2h_target:.0e} rad not measurable ({h2h['median'][0][1]}; {h2h['median'][1][1]})"
            verdicts.append(text)
        h2h_text += "; ".join(verdicts)
        h2h_text += f"; 1-minute load average {h2h_load[0]:.1f}–{h2h_load[1]:.1f} during the timing."
        print("   " + h2h_text, flush=True)
        md.append(h2h_text)
        md.append("")
        taylor_cost.extend(taylor_cost_rows(scene, TAYLOR_COST_TOLERANCES[::2] if args.quick else TAYLOR_COST_TOLERANCES))
        summary.append((scene.name, so, so_tab, hy_, sp))

    md.append("### Where the Taylor floor is: steps and cost per step against heyoka")
    md.append("")
    md.append("One integration to the end of each scene (`propagate_until`, no output grid), spinorbit's "
              "Taylor method with the torque, the same without the perturbers (torque-free: the cost of "
              "the attitude recurrences alone), and heyoka in its faster mode, timed interleaved; CPU "
              "medians (min–max) in ms. Both use heyoka's order and step rule, so the steps agree to a few %; "
              "a lead over heyoka must come from the cost per step, whose lower bound is the torque-free "
              "column.")
    md.append("")
    md.append(TAYLOR_COST_HEAD)
    md.extend(taylor_cost)
    md.append("")
    # Orders.
    md.append("### Convergence order of the fixed-step modes")
    md.append("")
    md.append("Attitude error at the end of a short span against the extended-precision reference, with the "
              "step halved each column; order = log2(e(n)/e(2n)) for each halving. Theoretical orders: "
              "the theory column (SABAn: O(ε h^2n + ε² h²), ε the torque's relative size, so the "
              "weak-perturbation order shows until the ε² h² term takes over). Step counts differ per method "
              "(STEP_FACTOR in the script) so that each is measured between its pre-asymptotic range and "
              "its rounding floor (~1e-12 rad).")
    md.append("")
    md.append("| scene | method | theory | steps | errors (rad) | measured orders |")
    md.append("|---|---|---|---|---|---|")
    order_spec = {"a": (20.0, [20, 40, 80, 160]), "c": (50.0, [25, 50, 100, 200])}
    for scene in scenes:
        if scene.name not in order_spec:
            continue
        span, steps = order_spec[scene.name]
        for label, theory, integrate in ORDER_METHODS:
            factor = STEP_FACTOR.get(label, 1)
            spec = (span, [factor * n for n in steps])
            rows, orders = measure_orders(scene, spec, integrate)
            errs = ", ".join(f"{e:.1e}" for _, e in rows)
            o = ", ".join(f"{x:.2f}" for x in orders)
            md.append(f"| ({scene.name}) | {label} | {theory} | {rows[0][0]}…{rows[-1][0]} | {errs} | {o} |")
            print(f"   order ({scene.name}) {label}: {errs} -> {o}", flush=True)
    md.append("")
    text = "\n".join(md)
    print(text)
    if not args.no_write:
        write_section("work_precision", text)
    if args.averaged:
        # Long spans are a regime of their own (span × accuracy map): one script measures it, reached
        # from here so that the work-precision run can cover the full and the averaged methods at once.
        from benchmarks.bench_averaged import main as averaged_main

        averaged_main(["--quick"] if args.quick else [])


if __name__ == "__main__":
    main()
