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
from _report import interleaved_timings, machine_line, write_section  # noqa: E402
from peers import fastest_heyoka_integrator, heyoka_equations  # noqa: E402

from spinorbit.core import make_model  # noqa: E402
from spinorbit.core.dynamics import python_reference  # noqa: E402

from spinorbit.core.free_motion.flow import torque_free_states, torque_free_states_many  # noqa: E402
from spinorbit.core.free_motion.flow_constants import FL_PERIOD_HI, FL_RATE_HI, flow_constants  # noqa: E402

GOAL_STATES_PER_SECOND = 5.0e6  # issue 18: many times per state, one core
GOAL_ONE_TIME_STATES_PER_SECOND = 2.0e6  # issue 18: one time per state
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
    """Kernels timing the set-up's pieces one at a time over many states (compiled here, not cached:
    they measure, they are not part of the package). Each returns a sum so that nothing is optimised away."""
    from spinorbit.core.elements.canonical import (
        MO_MODE, MO_SIZE, amplitude_from_momentum, flip_signs, motion_from_momentum_into)
    from spinorbit.core.free_motion.flow_constants import (
        FLOW_SIZE, complete_k_pi_dd, flow_constants_buffers, moment_constants, phase_constants_dd)
    from spinorbit.core.free_motion.flow import flow_state
    from spinorbit.core.jit import jit
    from spinorbit.core.math.carlson import rf, rf_pair
    from spinorbit.core.math.pn_fourier import pn_fourier_coefficients_at, pole_integral, sine_series

    @jit(cache=False)
    def inputs(momenta, a, b, c):
        """Per state: mode, flipped momentum, phase constants, amplitude's sin/cos, the pole's R_F arguments."""
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
        return out

    @jit(cache=False)
    def whole(quaternions, momenta, a, b, c, t):
        flow, mo = np.empty(FLOW_SIZE), np.empty(MO_SIZE)
        ic, inertia_dd = moment_constants(a, b, c)
        acc = 0.0
        for i in range(quaternions.shape[0]):
            mk, pk = flow_constants_buffers(flow, mo, quaternions[i], momenta[i], a, b, c, ic, inertia_dd)
            state = flow_state(t, flow, mo, mk, pk)
            acc += state[0] + state[4]
        return acc

    @jit(cache=False)
    def set_up(quaternions, momenta, a, b, c):
        flow, mo = np.empty(FLOW_SIZE), np.empty(MO_SIZE)
        ic, inertia_dd = moment_constants(a, b, c)
        acc = 0.0
        for i in range(quaternions.shape[0]):
            flow_constants_buffers(flow, mo, quaternions[i], momenta[i], a, b, c, ic, inertia_dd)
            acc += flow[0] + flow[5] + flow[10]
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
        for i in range(x.shape[0]):
            r = phase_constants_dd(int(x[i, 0]), x[i, 1], x[i, 2], x[i, 3], inertia_dd)
            acc += r[0] + r[4] + r[6] + r[10]
        return acc

    @jit(cache=False)
    def integrals(x):
        acc = 0.0
        for i in range(x.shape[0]):
            s, c = x[i, 9], x[i, 10]
            f1, f2 = rf_pair(c * c, c * c + x[i, 6] * (s * s), 1.0, x[i, 12], x[i, 13], x[i, 14])
            acc += f1 + f2
        return acc

    @jit(cache=False)
    def agm(x):
        acc = 0.0
        for i in range(x.shape[0]):
            kh, _, pih, _ = complete_k_pi_dd(x[i, 4], x[i, 5], x[i, 6], x[i, 7])
            acc += kh + pih
        return acc

    @jit(cache=False)
    def series(x, out):
        acc = 0.0
        for i in range(x.shape[0]):
            terms = pn_fourier_coefficients_at(x[i, 4], x[i, 8], x[i, 17], x[i, 16], x[i, 18], x[i, 15] > 0.0, out)
            acc += sine_series(0.3 + 1e-6 * i, out, 0, terms) + terms
        return acc

    return inputs, whole, set_up, motion, phase, integrals, agm, series


def one_time_floor(quaternions, momenta, t, repeats=7):
    """CPU ns per state of the one-time-per-state kernel and of its set-up's pieces (interleaved medians)."""
    inputs, whole, set_up, motion, phase, integrals, agm, series = _floor_kernels()
    x = inputs(momenta, *MOMENTS)
    out = np.empty(128)
    jobs = {
        "one time per state (set-up + one evaluation)": lambda: whole(quaternions, momenta, *MOMENTS, t),
        "the set-up alone (`flow_constants_buffers`)": lambda: set_up(quaternions, momenta, *MOMENTS),
        "motion constants from the momentum (mode, flip, energy differences)": lambda: motion(momenta, *MOMENTS),
        "phase constants in double-double (rates, κ, n, p, p_c)": lambda: phase(x, *MOMENTS),
        "the two R_F (the amplitude's F, pn's pole), paired": lambda: integrals(x),
        "the compensated AGM (K and Π in double-double)": lambda: agm(x),
        "pn's nome series: its coefficients and one sum": lambda: series(x, out),
    }
    timings, _ = interleaved_timings(list(jobs.values()), repeats, clock=time.process_time, warm_up=True)
    return {name: timing.median / len(momenta) * 1e9 for name, timing in zip(jobs, timings)}


def floor_text(floor, one_time_rate):
    names = list(floor)
    whole, set_up = floor[names[0]], floor[names[1]]
    pieces = sum(floor[name] for name in names[2:])
    budget = 1e9 / GOAL_ONE_TIME_STATES_PER_SECOND
    lines = ["", "Where one time per state goes (CPU ns per state, the workload's states, each piece timed "
             "alone in a loop of its own; medians of interleaved repeats):", "",
             "| part | ns per state |", "|---|---:|"]
    lines += [f"| {name} | {floor[name]:.0f} |" for name in names]
    lines += [f"| one evaluation (the first row less the second) | {whole - set_up:.0f} |",
              f"| the rest of the set-up (node frame, elliptic kernels' constants, remainders; the second row "
              f"less the pieces) | {set_up - pieces:.0f} |", "",
              f"The goal's budget is {budget:.0f} ns per state; the whole call measures "
              f"{1e9 / one_time_rate:.0f} ns (the kernel above plus the Python wrapper's checks and the "
              f"outputs' stores). With the evaluation and the wrapper as they are, the set-up would have to "
              f"fall from {set_up:.0f} to {set_up - (1e9 / one_time_rate - budget):.0f} ns "
              f"({100 * (1e9 / one_time_rate - budget) / set_up:.0f} % less), with no piece above "
              f"{max(floor[name] for name in names[2:]):.0f} ns and each already in the form the earlier "
              f"rounds found fastest (the two R_F paired, K and Π from one compensated AGM, the nome series' "
              f"terms counted by the loop that forms them)."]
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
    verdict = "met" if exact_rate >= GOAL_STATES_PER_SECOND else "missed"
    one_time_rate = rates[2]
    one_time_verdict = "met" if one_time_rate >= GOAL_ONE_TIME_STATES_PER_SECOND else "missed"
    lines += [
        "",
        f"Goal: ≥ {GOAL_STATES_PER_SECOND:.0e} states/s on one core for the exact solution (many times "
        f"per state): **{verdict}** ({exact_rate:.3g} states/s). With one time per state the per-state "
        f"setup dominates (one compensated AGM for K and Π, forward map to the elements, node frame, "
        f"coefficients of pn's nome series; "
        f"≈ {1e6 / one_time_rate:.1f} µs per state; goal ≥ {GOAL_ONE_TIME_STATES_PER_SECOND:.0e}): "
        f"**{one_time_verdict}** for that workload ({one_time_rate:.3g} states/s). The integrators cannot reach the exact "
        "solution's error in double precision at any tolerance they accept; they are shown at their "
        "tightest tolerance, so their speed is an upper bound for equal accuracy. Their cost scales with "
        "the span, not with the number of output times; the exact solution's cost is per output time "
        "and does not depend on the span.",
    ]
    lines += floor_text(one_time_floor(quaternions_many, momenta_many, float(one_time[0]),
                                       repeats=min(EXACT_REPEATS, 7)), one_time_rate)
    markdown = "\n".join(lines)
    print(markdown)
    if write:
        write_section("bench_torque_free", markdown)
    closed_form_section(write)


if __name__ == "__main__":
    main()
