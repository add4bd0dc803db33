"""Throughput of the exact torque-free solution beside heyoka and scipy, on the same body, one core.

Run: ``python benchmarks/bench_torque_free.py`` (from the worktree root). Writes the sections
``bench_torque_free`` and ``bench_closed_form`` of ``docs/performance.md``;
``--closed-form-only`` runs and writes only the second (the regular precession of axisymmetric
bodies against the elliptic flow at parameter 0, timed interleaved in the same process);
``--no-write`` prints only.

Workload: the Hairer–Lubich–Wanner body (I = (2, 1, 2/3) → A, B, C = 2/3, 1, 2; body momentum
(cos 1.1, 0, sin 1.1) in the original axes; identity attitude at t = 0). A "state" is one attitude
quaternion + body momentum at one time. Every method outputs the same grid: T times uniformly over
SPAN_PERIODS polhode periods (4K/ν ≈ 10.73 time units). Errors are the largest attitude error over
the grid against heyoka in long double at tolerance 1e-19 (the package matches a 40-digit reference
to ~1e-15 rad there). Integrators are run at the tightest tolerance they accept, i.e. as close to
"the same error" as they can get in double precision; their error is reported next to their speed.
"""

from __future__ import annotations

import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")  # one core; the kernels are serial loops anyway
# CPU time (process_time) counts every thread of the process: OpenBLAS's idle workers, woken by any
# numpy linear algebra in the script, spin for a while and were ≈ 4 % of a timing (perf, 2026-12-04)
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import math  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "benchmarks"))

from _heyoka_reference import propagate as reference_propagate, rotation_angle  # noqa: E402
from _report import interleaved_timings, machine_line, ratio_goal, write_section  # noqa: E402
from peers import fastest_heyoka_integrator, heyoka_equations  # noqa: E402

from spinorbit.core import make_model  # noqa: E402
from spinorbit.core.dynamics import python_reference  # noqa: E402

from spinorbit.core.free_motion.flow import torque_free_states, torque_free_states_many  # noqa: E402
from spinorbit.core.free_motion.flow_constants import FL_PERIOD_HI, FL_RATE_HI, flow_constants  # noqa: E402

# The goals as ratios to heyoka's states/s measured in the same run (issue 39: absolute rates on the shared
# machines move by 1.5× from run to run). Issue 18's absolute goals, 5e6 states/s (many times per state) and
# 2e6 (one time per state), over heyoka's 4.48e5 in the run that first met them: 11× and 4.5×, rounded down.
GOAL_RATIO_TO_HEYOKA = 10.0
GOAL_ONE_TIME_RATIO_TO_HEYOKA = 4.0
MOMENTS = (2.0 / 3.0, 1.0, 2.0)
MOMENTUM = np.array([math.sin(1.1), 0.0, math.cos(1.1)])
IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])
# A body whose pn takes Carlson's form, not the nome series (f = −n ≈ 17, ρ ≈ 0.66 > FOURIER_RHO_MAX):
# the Apophis-like moments and momentum of tests/test_torque_free.py.
CARLSON_MOMENTS = (0.61, 0.965, 1.0)
CARLSON_MOMENTUM = np.array([0.15, 0.25, 0.95])
SPAN_PERIODS = 100.0
N_TIMES = 1000  # output times per state
N_STATES = 2000  # states in the many-states run of the exact solution
N_STATES_HEYOKA = 20  # integrators: per-state cost is independent of N, so a few states suffice
HEYOKA_TOLERANCE = 2.0**-52  # heyoka's default (machine epsilon): the tightest meaningful in double
SCIPY_TOLERANCE = 2.3e-14  # DOP853 refuses rtol < 100 ε (it raises it with a warning)


EXACT_REPEATS = 9  # interleaved rounds of the four exact-solution workloads


def timed(function, repeats=5):
    """CPU times (``time.process_time``) of ``repeats`` calls after one warm-up call (a Timing:
    median, min, max)."""
    return interleaved_timings([function], repeats, clock=time.process_time, warm_up=True)[0][0]


def rate_text(count, timing):
    """'median rate (range min–max)' in states/s."""
    return f"{count / timing.median:.3g} ({count / timing.max:.3g}–{count / timing.min:.3g})"


CLOSED_FORM_BODIES = {"oblate A = B (1, 1, 2)": (1.0, 1.0, 2.0), "prolate B = C (0.5, 1, 1)": (0.5, 1.0, 1.0)}
CLOSED_FORM_REPEATS = 7


def closed_form_section(write=True):
    """Regular precession (closed form) against the elliptic flow, same axisymmetric states, interleaved."""
    rng = np.random.default_rng(2)
    quaternions = rng.normal(size=(N_STATES, 4))
    quaternions /= np.linalg.norm(quaternions, axis=1, keepdims=True)
    momenta = rng.normal(size=(N_STATES, 3))
    many = 50 * N_STATES
    quaternions_many, momenta_many = np.repeat(quaternions, 50, axis=0), np.repeat(momenta, 50, axis=0)
    rows = []
    for label, moments in CLOSED_FORM_BODIES.items():
        rate = np.linalg.norm(MOMENTUM / np.array(moments))
        times = np.linspace(0.0, 100.0 * 2.0 * math.pi / rate, N_TIMES + 1)[1:]
        one_time = np.array([times[N_TIMES // 2]])
        workloads = [
            (f"1 state × {N_TIMES} times", N_TIMES, (IDENTITY[None], MOMENTUM[None], times)),
            (f"{N_STATES} states × {N_TIMES} times", N_STATES * N_TIMES, (quaternions, momenta, times)),
            (f"{many} states × 1 time", many, (quaternions_many, momenta_many, one_time)),
        ]
        for name, count, (q, m, t) in workloads:
            def run(closed, q=q, m=m, t=t):
                return torque_free_states_many(q, m, moments, t, closed_forms=closed)

            (q_closed, _), (q_elliptic, _) = run(True), run(False)
            error = rotation_angle(q_closed.reshape(-1, 4), q_elliptic.reshape(-1, 4)).max()
            (closed, elliptic), _ = interleaved_timings([lambda: run(True), lambda: run(False)], CLOSED_FORM_REPEATS,
                                                        clock=time.process_time, warm_up=True)
            rows.append((label, name, count, closed, elliptic, error))
    lines = [
        "## Closed form for axisymmetric bodies (`benchmarks/bench_torque_free.py --closed-form-only`)",
        "",
        machine_line() + " One core (`NUMBA_NUM_THREADS=1`).",
        "",
        "Regular precession in closed form (`spinorbit.core.free_motion.regular_precession`: two sin/cos and two quaternion "
        "products per output, double-double phases) against the elliptic flow at parameter 0 "
        "(`closed_forms=False`) for the same states: random attitudes and body momenta (seeded), times over "
        "100 turns. The two are timed alternately in one process (CPU, `time.process_time`), "
        f"{CLOSED_FORM_REPEATS} times each: median rate (min–max range), ratio of the medians (of the minima "
        "in brackets); the ratio is what to read. Difference: largest attitude angle between the two "
        "kernels' outputs (both are exact; `tests/test_regular_precession.py` holds each to a 40-digit reference).",
        "",
        "| body | workload | closed form (states/s) | elliptic (states/s) | elliptic / closed time | difference (rad) |",
        "|---|---|---:|---:|---:|---:|",
    ]
    for label, name, count, closed, elliptic, error in rows:
        lines.append(f"| {label} | {name} | {rate_text(count, closed)} | {rate_text(count, elliptic)} | "
                     f"{elliptic.median / closed.median:.2f} ({elliptic.min / closed.min:.2f}) | {error:.1e} |")
    markdown = "\n".join(lines)
    print(markdown)
    if write:
        write_section("bench_closed_form", markdown)
    return rows


# ------------------------------------------------------------------ where one time per state goes

def _floor_kernels():
    """Kernels timing the one-time-per-state work piece by piece over many states, each piece in its
    scalar form (one state at a time) and, where the package runs it so, in lanes (eight states in one
    register, :mod:`spinorbit.core.free_motion.flow_blocks`). Compiled here, not cached: they measure,
    they are not part of the package. Each returns a sum so that nothing is optimised away."""
    from spinorbit.core.elements.canonical import (
        MO_MODE, MO_SIZE, MODE_SAM, amplitude_from_momentum, flip_signs, motion_from_momentum_into)
    from spinorbit.core.free_motion.flow import flow_state, propagate_many_into
    from spinorbit.core.free_motion.flow_blocks import (
        BLOCK, INTEGRALS_SIZE, MOTION_SIZE, NODE_SIZE, STAGE_SIZE, finish_lane, integrals_of_block, nodes_of_block,
        set_up_block_start)
    from spinorbit.core.free_motion.flow_constants import FLOW_SIZE, flow_constants_buffers
    from spinorbit.core.free_motion.phase_constants import moment_constants, phase_constants_dd, phase_constants_lanes
    from spinorbit.core.jit import jit
    from spinorbit.core.math.carlson import rf, rf_pair, rf_pair_lanes
    from spinorbit.core.math.complete_agm import complete_k_pi_dd, complete_k_pi_lanes
    from spinorbit.core.math.lanes import broadcast, load_lanes, store_lanes
    from spinorbit.core.math.pn_fourier import pn_fourier_coefficients_at, pole_integral, sine_series

    @jit(cache=False)
    def inputs(momenta, a, b, c):
        """Per state (rows of the transpose): mode, flipped momentum, phase constants, amplitude's sin/cos,
        the pole's R_F arguments, κ, K, the pole's distance."""
        n = momenta.shape[0]
        out = np.empty((n, 19))
        mo = np.empty(MO_SIZE)
        ic, inertia_dd = moment_constants(a, b, c)
        for i in range(n):
            fx, fy, fz = flip_signs(motion_from_momentum_into(mo, momenta[i, 0], momenta[i, 1], momenta[i, 2], ic))
            mode = mo[MO_MODE]
            mx, my, mz = fx * momenta[i, 0], fy * momenta[i, 1], fz * momenta[i, 2]
            _, _, _, _, kah, _, fh, fl, pch, pcl, param = phase_constants_dd(int(mode), mx, my, mz, inertia_dd)
            am = amplitude_from_momentum(mx, my, mz, mo, ic)
            pre, x, y, z, near = pole_integral(fh, param)
            kh = complete_k_pi_dd(fh, fl, pch, pcl)[0]
            out[i] = (mode, mx, my, mz, fh, fl, pch, pcl, param, math.sin(am), math.cos(am), pre, x, y, z,
                      1.0 if near else 0.0, kah, kh, pre * rf(x, y, z))
        return np.ascontiguousarray(out.T)

    @jit(cache=False)
    def whole_scalar(quaternions, momenta, a, b, c, t):
        flow, mo = np.empty(FLOW_SIZE), np.empty(MO_SIZE)
        ic, inertia_dd = moment_constants(a, b, c)
        acc = 0.0
        for i in range(quaternions.shape[0]):
            mk, pk = flow_constants_buffers(flow, mo, quaternions[i], momenta[i], a, b, c, ic, inertia_dd)
            state = flow_state(t, flow, mo, mk, pk)
            acc += state[0] + state[4]
        return acc

    @jit(cache=False)
    def set_up_scalar(quaternions, momenta, a, b, c):
        flow, mo = np.empty(FLOW_SIZE), np.empty(MO_SIZE)
        ic, inertia_dd = moment_constants(a, b, c)
        acc = 0.0
        for i in range(quaternions.shape[0]):
            flow_constants_buffers(flow, mo, quaternions[i], momenta[i], a, b, c, ic, inertia_dd)
            acc += flow[0] + flow[5] + flow[10]
        return acc

    @jit(cache=False)
    def set_up_blocks(quaternions, momenta, a, b, c):
        flows, mos = np.empty((BLOCK, FLOW_SIZE)), np.empty((BLOCK, MO_SIZE))
        stages, integrals = np.empty((STAGE_SIZE, BLOCK)), np.empty((INTEGRALS_SIZE, BLOCK))
        motions, nodes = np.empty((MOTION_SIZE, BLOCK)), np.empty((NODE_SIZE, BLOCK))
        ic, inertia_dd = moment_constants(a, b, c)
        acc = 0.0
        for first in range(0, quaternions.shape[0] - BLOCK + 1, BLOCK):
            periodic = set_up_block_start(flows, mos, stages, motions, quaternions, momenta, first, a, b, c, ic,
                                          inertia_dd)
            integrals_of_block(stages, integrals, periodic)
            nodes_of_block(flows, stages, nodes, quaternions, momenta, first)
            for lane in range(BLOCK):
                finish_lane(flows, mos, stages, integrals, nodes, lane, quaternions[first + lane],
                            momenta[first + lane], ic)
                acc += flows[lane, 0] + flows[lane, 5] + flows[lane, 10]
        return acc

    @jit(cache=False)
    def motion(momenta, a, b, c):
        mo = np.empty(MO_SIZE)
        ic, _ = moment_constants(a, b, c)
        acc = 0.0
        for i in range(momenta.shape[0]):
            acc += motion_from_momentum_into(mo, momenta[i, 0], momenta[i, 1], momenta[i, 2], ic) + mo[3]
        return acc

    @jit(cache=False)
    def phase(x, a, b, c):
        _, inertia_dd = moment_constants(a, b, c)
        acc = 0.0
        for i in range(x.shape[1]):
            r = phase_constants_dd(int(x[0, i]), x[1, i], x[2, i], x[3, i], inertia_dd)
            acc += r[0] + r[4] + r[6] + r[10]
        return acc

    @jit(cache=False)
    def lane_sum(values):
        sink = np.empty(BLOCK)
        store_lanes(sink, 0, values)
        return sink.sum()

    @jit(cache=False)
    def phase_lanes(x, a, b, c):
        _, inertia_dd = moment_constants(a, b, c)
        acc = broadcast(0.0)
        for i in range(0, x.shape[1] - BLOCK + 1, BLOCK):
            r = phase_constants_lanes(load_lanes(x[0], i) == MODE_SAM, load_lanes(x[1], i), load_lanes(x[2], i),
                                      load_lanes(x[3], i), inertia_dd)
            acc = acc + r[0] + r[4] + r[6] + r[10]
        return lane_sum(acc)

    @jit(cache=False)
    def integrals(x):
        acc = 0.0
        for i in range(x.shape[1]):
            s, c = x[9, i], x[10, i]
            f1, f2 = rf_pair(c * c, c * c + x[6, i] * (s * s), 1.0, x[12, i], x[13, i], x[14, i])
            acc += f1 + f2
        return acc

    @jit(cache=False)
    def integrals_lanes(x):
        acc = broadcast(0.0)
        for i in range(0, x.shape[1] - BLOCK + 1, BLOCK):
            s, c = load_lanes(x[9], i), load_lanes(x[10], i)
            f1, f2 = rf_pair_lanes(c * c, c * c + load_lanes(x[6], i) * (s * s), broadcast(1.0), load_lanes(x[12], i),
                                   load_lanes(x[13], i), load_lanes(x[14], i))
            acc = acc + f1 + f2
        return lane_sum(acc)

    @jit(cache=False)
    def agm(x):
        acc = 0.0
        for i in range(x.shape[1]):
            kh, _, pih, _ = complete_k_pi_dd(x[4, i], x[5, i], x[6, i], x[7, i])
            acc += kh + pih
        return acc

    @jit(cache=False)
    def agm_lanes(x):
        acc = broadcast(0.0)
        for i in range(0, x.shape[1] - BLOCK + 1, BLOCK):
            kh, _, pih, _ = complete_k_pi_lanes(load_lanes(x[4], i), load_lanes(x[5], i), load_lanes(x[6], i),
                                                load_lanes(x[7], i))
            acc = acc + kh + pih
        return lane_sum(acc)

    @jit(cache=False)
    def series(x, out):
        acc = 0.0
        for i in range(x.shape[1]):
            terms = pn_fourier_coefficients_at(x[4, i], x[8, i], x[17, i], x[16, i], x[18, i], x[15, i] > 0.0, out)
            acc += sine_series(0.3 + 1e-6 * i, out, 0, terms) + terms
        return acc

    def kernel(quaternions, momenta, moments, t, q_out, m_out):
        propagate_many_into(quaternions, momenta, moments, t, q_out, m_out, True)

    return dict(inputs=inputs, whole_scalar=whole_scalar, set_up_scalar=set_up_scalar, set_up_blocks=set_up_blocks,
                motion=motion, phase=phase, phase_lanes=phase_lanes, integrals=integrals,
                integrals_lanes=integrals_lanes, agm=agm, agm_lanes=agm_lanes, series=series, kernel=kernel)


def one_time_floor(quaternions, momenta, t, repeats=7):
    """CPU ns per state of the one-time-per-state kernel and of its pieces, scalar and in lanes
    (interleaved medians): {name: (scalar, lanes or None)}."""
    k = _floor_kernels()
    x = k["inputs"](momenta, *MOMENTS)
    out = np.empty(128)
    n = len(momenta)
    moments = np.ascontiguousarray(np.broadcast_to(np.array(MOMENTS), (n, 3)))
    times = np.array([t])
    q_out, m_out = np.empty((n, 1, 4)), np.empty((n, 1, 3))
    jobs = {
        "the kernel (`propagate_many_into`: set-up + one evaluation + stores)": (
            None, lambda: k["kernel"](quaternions, momenta, moments, times, q_out, m_out)),
        "set-up + one evaluation, state by state": (lambda: k["whole_scalar"](quaternions, momenta, *MOMENTS, t), None),
        "the set-up": (lambda: k["set_up_scalar"](quaternions, momenta, *MOMENTS),
                       lambda: k["set_up_blocks"](quaternions, momenta, *MOMENTS)),
        "motion constants from the momentum (mode, flip, energy differences)": (
            lambda: k["motion"](momenta, *MOMENTS), None),
        "phase constants in double-double (rates, κ, n, p, p_c)": (
            lambda: k["phase"](x, *MOMENTS), lambda: k["phase_lanes"](x, *MOMENTS)),
        "the two R_F (the amplitude's F, pn's pole), paired": (
            lambda: k["integrals"](x), lambda: k["integrals_lanes"](x)),
        "the compensated AGM (K and Π in double-double)": (lambda: k["agm"](x), lambda: k["agm_lanes"](x)),
        "pn's nome series: its coefficients and one sum": (lambda: k["series"](x, out), None),
    }
    functions = [f for pair in jobs.values() for f in pair if f is not None]
    timings, _ = interleaved_timings(functions, repeats, clock=time.process_time, warm_up=True)
    per_state = iter(timing.median / n * 1e9 for timing in timings)
    return {name: tuple(None if f is None else next(per_state) for f in pair) for name, pair in jobs.items()}


def floor_text(floor, one_time_rate, heyoka_rate):
    names = list(floor)
    kernel = floor[names[0]][1]
    whole_scalar = floor[names[1]][0]
    set_up_scalar, set_up_lanes = floor[names[2]]
    evaluation = whole_scalar - set_up_scalar
    budget = 1e9 / (GOAL_ONE_TIME_RATIO_TO_HEYOKA * heyoka_rate)  # ns per state at the bar, in this run
    call = 1e9 / one_time_rate

    def cell(value):
        return "–" if value is None else f"{value:.0f}"

    lines = ["", "Where one time per state goes (CPU ns per state over the workload's states; each piece timed "
             "alone in a loop of its own, one state at a time and, where the package runs it so, eight states in "
             "the lanes of one register (`spinorbit.core.free_motion.flow_blocks`); medians of interleaved "
             "repeats):", "",
             "| part | one state at a time | eight in lanes |", "|---|---:|---:|"]
    lines += [f"| {name} | {cell(scalar)} | {cell(lanes)} |" for name, (scalar, lanes) in floor.items()]
    lines += [f"| one evaluation (the second row less the third's first column) | {evaluation:.0f} | – |", "",
              f"The goal's budget in this run is {budget:.0f} ns per state; the whole call measures {call:.0f} ns, {kernel:.0f} ns "
              f"of it in the kernel (the first row), the rest the Python wrapper's checks and the allocation of "
              f"the outputs. In lanes the set-up costs "
              f"{set_up_lanes:.0f} ns against {set_up_scalar:.0f} ns state by state: the motion constants, the "
              f"phase constants, the two R_F, the AGM and the node frame's arithmetic, whose divisions and square "
              f"roots bound the scalar set-up, issue eight at a time (the same results bit for bit, "
              f"`tests/test_lanes.py`); the motion constants and the node frame run in lanes only inside the "
              f"block set-up (each lane's mode, flip and atan2 chosen alone), so their lane cells are in the "
              f"set-up row. What stays scalar has branches by the state (the mode and flip, the nome series' "
              f"length) or a library call per state (sin, cos, exp, atan2)."]
    return lines


#: ``--quick`` (benchmarks/run_all.py's smoke run): (N_STATES, N_TIMES, SPAN_PERIODS, EXACT_REPEATS,
#: N_STATES_HEYOKA), print only.
QUICK_SIZES = (50, 100, 10.0, 2, 2)


def main():
    global N_STATES, N_TIMES, SPAN_PERIODS, EXACT_REPEATS, N_STATES_HEYOKA
    write = "--no-write" not in sys.argv[1:] and "--quick" not in sys.argv[1:]
    if "--quick" in sys.argv[1:]:
        N_STATES, N_TIMES, SPAN_PERIODS, EXACT_REPEATS, N_STATES_HEYOKA = QUICK_SIZES
    if "--closed-form-only" in sys.argv[1:]:
        closed_form_section(write)
        return
    from scipy.integrate import solve_ivp

    flow, _, _, _ = flow_constants(IDENTITY, MOMENTUM, *MOMENTS)
    period = 2.0 * flow[FL_PERIOD_HI] / flow[FL_RATE_HI]
    span = SPAN_PERIODS * period
    times = np.linspace(0.0, span, N_TIMES + 1)[1:]
    q_ref, _ = reference_propagate(IDENTITY, MOMENTUM, MOMENTS, times)
    rows = []

    # exact solution: one state → many times, many states → many times (small random rotations of
    # the HLW state), many states at one time each (setup-dominated: the compensated AGM per
    # state); the four timed in turn, EXACT_REPEATS rounds, so the machine's load moves all alike
    q, m = torque_free_states(IDENTITY, MOMENTUM, *MOMENTS, times)
    error = rotation_angle(q_ref, q).max()
    rng = np.random.default_rng(1)
    quaternions = rng.normal(size=(N_STATES, 4))
    quaternions /= np.linalg.norm(quaternions, axis=1, keepdims=True)
    momenta = MOMENTUM + 1e-3 * rng.normal(size=(N_STATES, 3))
    one_time = np.array([0.5 * span])
    many = 50 * N_STATES
    quaternions_many = np.repeat(quaternions, 50, axis=0)
    momenta_many = np.repeat(momenta, 50, axis=0)
    momenta_carlson = CARLSON_MOMENTUM + 1e-3 * rng.normal(size=(N_STATES, 3))
    (one_state, many_states, one_time_each, carlson_states), _ = interleaved_timings(
        [lambda: torque_free_states(IDENTITY, MOMENTUM, *MOMENTS, times),
         lambda: torque_free_states_many(quaternions, momenta, MOMENTS, times),
         lambda: torque_free_states_many(quaternions_many, momenta_many, MOMENTS, one_time),
         lambda: torque_free_states_many(quaternions, momenta_carlson, CARLSON_MOMENTS, times)],
        EXACT_REPEATS, clock=time.process_time, warm_up=True)
    rows.append((f"spinorbit exact, 1 state × {N_TIMES} times", N_TIMES, one_state, error))
    rows.append((f"spinorbit exact, {N_STATES} states × {N_TIMES} times", N_STATES * N_TIMES, many_states, error))
    rows.append((f"spinorbit exact, {many} states × 1 time", many, one_time_each, math.nan))
    rows.append((f"spinorbit exact, Apophis-like body (pn in Carlson's form), {N_STATES} states × {N_TIMES} times",
                 N_STATES * N_TIMES, carlson_states, math.nan))

    # heyoka, double precision, Taylor, the package's equations in peers' formulation, its faster mode;
    # compiled once, reused for every state
    y0 = np.concatenate((IDENTITY, MOMENTUM / np.array(MOMENTS)))
    equations, _ = heyoka_equations(MOMENTS, [], 0.0)
    ta, compact_mode, _ = fastest_heyoka_integrator(equations, y0, 0.0, span, HEYOKA_TOLERANCE)
    grid = np.concatenate(([0.0], times))

    def run_heyoka():
        out = None
        for _ in range(N_STATES_HEYOKA):
            ta.time = 0.0
            ta.state[:] = y0
            out = ta.propagate_grid(grid)[-1]
        return out

    out = run_heyoka()
    error = rotation_angle(q_ref, out[1:, :4]).max()
    mode = "compact" if compact_mode else "non-compact"
    rows.append((f"heyoka double ({mode}), tol {HEYOKA_TOLERANCE:.1e}, 1 state × {N_TIMES} times",
                 N_TIMES * N_STATES_HEYOKA, timed(run_heyoka, repeats=3), error))

    # scipy DOP853 on the package's right-hand side in plain Python, dense output on the same grid
    python_rhs = python_reference.make_rhs(make_model(MOMENTS))

    def run_scipy():
        return solve_ivp(python_rhs, (0.0, span), y0, method="DOP853", t_eval=times, rtol=SCIPY_TOLERANCE,
                         atol=SCIPY_TOLERANCE)

    sol = run_scipy()
    error = rotation_angle(q_ref, sol.y[:4].T).max()
    rows.append((f"scipy DOP853 (pure-Python RHS), rtol=atol={SCIPY_TOLERANCE:.1e}, 1 state × {N_TIMES} times",
                 N_TIMES, timed(run_scipy, repeats=3), error))

    rates = [count / timing.median for _, count, timing, _ in rows]
    exact_rate = rates[1]
    lines = [
        "## Torque-free propagation (`benchmarks/bench_torque_free.py`)",
        "",
        machine_line() + " One core (`NUMBA_NUM_THREADS=1`, serial loops).",
        "",
        f"Hairer–Lubich–Wanner body, {N_TIMES} output times over {SPAN_PERIODS:.0f} polhode periods "
        f"({span:.0f} time units) per state; a *state* is one attitude quaternion + body momentum at "
        "one time. The Apophis-like row (moments (0.61, 0.965, 1), f = −n ≈ 17, same grid) is a body "
        "whose pn keeps Carlson's form: the nome series of `spinorbit.core.math.pn_fourier` is taken "
        "only where its ratio ρ ≤ 0.196 (HLW: ρ ≈ 0.09, 16 terms). "
        "Error: largest attitude error on the grid against heyoka long double (tol 1e-19). "
        f"Rates: CPU (`time.process_time`), median of the repeats, their min–max range beside it; the four "
        f"exact-solution rows are timed in turn ({EXACT_REPEATS} rounds), so the machine's load moves them alike.",
        "",
        "| method | states/s (range) | vs exact (many states) | max attitude error (rad) |",
        "|---|---:|---:|---:|",
    ]
    for (name, count, timing, err), rate in zip(rows, rates):
        err_text = "—" if math.isnan(err) else f"{err:.1e}"
        lines.append(f"| {name} | {rate_text(count, timing)} | {rate / exact_rate:.3g}× | {err_text} |")
    one_time_rate = rates[2]
    heyoka_rate = rates[4]  # heyoka double, many times per state: the peer of both goals
    verdict = ratio_goal("torque-free exact (many times per state) / heyoka", exact_rate / heyoka_rate,
                         GOAL_RATIO_TO_HEYOKA)
    one_time_verdict = ratio_goal("torque-free exact (one time per state) / heyoka", one_time_rate / heyoka_rate,
                                  GOAL_ONE_TIME_RATIO_TO_HEYOKA)
    lines += [
        "",
        f"Goals, as ratios to heyoka's states/s in this run (absolute rates on the shared machine move by "
        f"1.5× from run to run): the exact solution, many times per state, {exact_rate:.3g} states/s against "
        f"heyoka's {heyoka_rate:.3g}: **{verdict}**. With one time per state the per-state "
        f"setup dominates (one compensated AGM for K and Π, forward map to the elements, node frame, "
        f"coefficients of pn's nome series; ≈ {1e6 / one_time_rate:.1f} µs per state), {one_time_rate:.3g} "
        f"states/s: **{one_time_verdict}**. The integrators cannot reach the exact "
        "solution's error in double precision at any tolerance they accept; they are shown at their "
        "tightest tolerance, so their speed is an upper bound for equal accuracy. Their cost scales with "
        "the span, not with the number of output times; the exact solution's cost is per output time "
        "and does not depend on the span.",
    ]
    lines += floor_text(one_time_floor(quaternions_many, momenta_many, float(one_time[0]),
                                       repeats=min(EXACT_REPEATS, 7)), one_time_rate, heyoka_rate)
    markdown = "\n".join(lines)
    print(markdown)
    if write:
        write_section("bench_torque_free", markdown)
    closed_form_section(write)


if __name__ == "__main__":
    main()
