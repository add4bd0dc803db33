"""Numerical stability at the edges and over long runs; writes a section of docs/stability.md + plots.

Run: ``python benchmarks/stability.py`` (≈ 2 min on 2 shared cores; ``--quick`` for a 10× shorter
smoke run that does not touch docs/). Every error is printed next to the machine-precision floor it
is compared to:

1. energy error vs steps under a torque with a conserved energy, 10⁶ steps of each integrator
   (floor: Brouwer's law ε√n, the random walk of one rounding per step);
2. the exact torque-free flow over 10⁷ rotations: |M| and E, and the attitude error against a
   40-digit mpmath evaluation (floor: the change of the state at t when each input moves by 2 ulps,
   plus ulp(t)·|ω|);
3. the Hyperion-like chaotic tumbler (``benchmarks/chaotic.py``): Lyapunov time and forward–backward
   return error vs span, fitted to ε·exp(T/τ) (floor: ε_machine·exp(T/T_L));
4. round trip state → elements → state and the group property of the flow across the phase-space
   sweep of ``tests/stress/test_phase_space_floor.py`` (floor: 2-ulp sensitivity of each map);
5. the element ↔ quaternion hand-over on a scene with separatrix passages.

Timings are not reported (shared machine); only errors, which are deterministic.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "benchmarks"))

import chaotic
from _mp_reference import exact_states
from _report import DOCS, machine_line, write_section

from spinorbit.core.dynamics.equations import make_model, total_energy
from spinorbit.core.integrators.elements import integrate_elements
from spinorbit.core.integrators.quaternion import integrate_quaternion
from spinorbit.core.integrators.splitting import integrate_splitting
from spinorbit.core.model.perturbers import fixed_source
from spinorbit.core.math.rotations import rotation_angle_between_many
from spinorbit.core.free_motion.flow import torque_free_states

EPS = np.finfo(float).eps
IMG = DOCS / "img"

# ----------------------------------------------------------------------------- 1. energy, 10⁶ steps
# The energy scene of tests/test_integrate_splitting.py: HLW body, a point mass μ = 1e-3 at rest
# (time-independent U, so E = T − U is conserved).
HLW_MOMENTS = (2.0 / 3.0, 1.0, 2.0)
HLW_Y0 = np.r_[1.0, 0.0, 0.0, 0.0, np.array([math.sin(1.1), 0.0, math.cos(1.1)]) / np.array(HLW_MOMENTS)]


def energy_model():
    return make_model(HLW_MOMENTS, [fixed_source(1e-3, np.array([1.0, 0.3, 0.5]))])


def growth_exponent(steps, errors):
    """p of |ΔE| ∝ nᵖ, least squares in log–log over the last two decades of steps."""
    late = steps >= steps[-1] / 100
    return float(np.polyfit(np.log(steps[late]), np.log(np.maximum(errors[late], EPS / 10)), 1)[0])


def energy_runs(n_steps):
    """{label: (step numbers, |ΔE/E|)} for each integrator after ``n_steps`` steps.

    The adaptive integrators take nearly constant steps on this scene; their span is set from a
    calibration run so they take ≈ n_steps steps, and step numbers are t × (steps / span).
    """
    model = energy_model()
    e0 = total_energy(0.0, HLW_Y0, model)
    runs = {}

    def record(label, span, steps, times, ys):
        energy = np.array([total_energy(t, y, model) for t, y in zip(times, ys)])
        runs[label] = (times * steps / span, np.abs(energy / e0 - 1.0))

    tau = 0.1
    span = n_steps * tau
    times = np.geomspace(tau, span, 400)
    times[-1] = span
    record("SABA2 splitting, τ = 0.1", span, n_steps, times,
           integrate_splitting(HLW_Y0, 0.0, times, model, tau, "saba2"))
    for rtol in (1e-10, 1e-13):
        _, stats = integrate_quaternion(HLW_Y0, 0.0, [1000.0], model, rtol=rtol, return_stats=True)
        span = 1000.0 * n_steps / stats["accepted"]
        times = np.geomspace(1.0, span, 400)
        ys, stats = integrate_quaternion(HLW_Y0, 0.0, times, model, rtol=rtol, return_stats=True,
                                         max_steps=4 * n_steps)
        record(f"DOP853 quaternion, rtol {rtol:.0e}", span, stats["accepted"], times, ys)
    rtol = 1e-10
    _, stats = integrate_elements(HLW_Y0, 0.0, [1000.0], model, rtol=rtol, return_stats=True)
    span = 1000.0 * n_steps / stats["accepted"]
    times = np.geomspace(1.0, span, 400)
    ys, stats = integrate_elements(HLW_Y0, 0.0, times, model, rtol=rtol, return_stats=True, max_steps=4 * n_steps)
    record(f"elements, rtol {rtol:.0e}", span, stats["accepted"], times, ys)
    return runs


# -------------------------------------------------------------------- 2. torque-free, 10⁷ rotations
FREE_MOMENTS = (0.61, 0.965, 1.0)  # Apophis-like SAM (tests/test_torque_free.py)
FREE_MOMENTUM = np.array([0.15, 0.25, 0.95])
FREE_Q0 = np.array([0.9, 0.1, -0.3, 0.2]) / math.sqrt(0.95)


def flow_floor(t, period):
    """2-ulp sensitivity of the flow at time t to its 7 inputs (quadrature) + ulp(t)·|ω|."""
    q_ref, m_ref = torque_free_states(FREE_Q0, FREE_MOMENTUM, *FREE_MOMENTS, np.array([t]))
    total = 0.0
    for i in range(7):
        worst = 0.0
        for towards in (np.inf, -np.inf):
            q0, m0 = FREE_Q0.copy(), FREE_MOMENTUM.copy()
            for _ in range(2):
                if i < 4:
                    q0[i] = np.nextafter(q0[i], towards)
                else:
                    m0[i - 4] = np.nextafter(m0[i - 4], towards)
            q, m = torque_free_states(q0, m0, *FREE_MOMENTS, np.array([t]))
            worst = max(worst, float(rotation_angle_between_many(q, q_ref)[0])
                        + float(np.linalg.norm(m - m_ref)) / np.linalg.norm(FREE_MOMENTUM))
        total += worst**2
    omega = np.linalg.norm(FREE_MOMENTUM / np.array(FREE_MOMENTS))
    return math.sqrt(total) + float(np.spacing(t)) * omega


def torque_free_long(max_rotations):
    from test_torque_free import rotation_period

    period = rotation_period(FREE_Q0, FREE_MOMENTUM, FREE_MOMENTS)
    dense = period * (np.geomspace(1.0, max_rotations, 3000) + 0.3)
    _q, m = torque_free_states(FREE_Q0, FREE_MOMENTUM, *FREE_MOMENTS, dense)
    g0 = np.linalg.norm(FREE_MOMENTUM)
    e0 = np.sum(FREE_MOMENTUM**2 / np.array(FREE_MOMENTS))
    momentum_error = np.abs(np.linalg.norm(m, axis=1) / g0 - 1.0)
    energy_error = np.abs(np.sum(m**2 / np.array(FREE_MOMENTS), axis=1) / e0 - 1.0)
    rotations = np.array([10.0**k for k in range(round(math.log10(max_rotations)) + 1)])
    times = period * (rotations + 0.3)
    q_mp, _ = exact_states(FREE_Q0, FREE_MOMENTUM, FREE_MOMENTS, times)
    q_pkg, _ = torque_free_states(FREE_Q0, FREE_MOMENTUM, *FREE_MOMENTS, times)
    phase_error = rotation_angle_between_many(np.ascontiguousarray(q_mp), q_pkg)
    floors = np.array([flow_floor(t, period) for t in times])
    return {"dense_rotations": dense / period, "momentum": momentum_error, "energy": energy_error,
            "rotations": rotations, "phase": phase_error, "floor": floors}


# ------------------------------------------------------------------------------------ 3. chaotic
SATURATION = 1e-3
def chaotic_runs(n_lyapunov, max_orbits):
    offsets = {"spin rate": np.array([0, 0, 0, 0, 0, 0, 1e-9]), "attitude": np.array([0, 0, 1e-9, 0, 0, 0, 0])}
    t_l = {name: chaotic.lyapunov_time(n_lyapunov, off) for name, off in offsets.items()}
    orbits = np.arange(1, max_orbits + 1)
    spans = orbits * chaotic.ORBIT
    m = chaotic.model()
    curves = {}
    for name, rtol in [("DOP853 (quaternion)", 1e-9), ("DOP853 (quaternion)", 1e-12),
                       ("elements (hand-over)", 1e-12), ("SABA3 splitting", None)]:
        label = name + (f", rtol {rtol:.0e}" if rtol else ", τ = P_orb/100")
        errors = np.array([chaotic.return_error(name, t, rtol or 1e-12, m) for t in spans])
        # fit only before saturation: once the return error is O(1e-3) the trajectories have parted
        fit = errors < SATURATION
        eps, tau = chaotic.exponential_fit(spans[fit], errors[fit])
        curves[label] = (errors, eps, tau)
    return t_l, orbits, curves


# ------------------------------------------------------------------------------- 4. the sweep
def sweep():
    from stress import test_phase_space_floor as sweep_tests

    rows = []
    for label, body, momentum in sweep_tests.SWEEP:
        for kind in ("generic", "momentum 1e-12 rad from z"):
            ic = sweep_tests.inertia_constants(*body)
            q0 = sweep_tests.quaternion_for(kind, momentum)
            elements, flip, _ = sweep_tests.elements_from_state(sweep_tests.quat_to_attitude(q0), momentum, ic)
            scale = float(np.linalg.norm(momentum))

            def backward(el, flip=flip, ic=ic):
                attitude, mm = sweep_tests.state_from_elements(el, flip, ic)
                return sweep_tests.attitude_to_quat(attitude), mm

            back = backward(elements)
            floor = sweep_tests.one_ulp_floor(elements, backward, back, scale)
            error = sweep_tests.state_distance(q0, momentum, *back, scale)
            rows.append((f"{label}, {kind}", error, floor))
    return rows


# ------------------------------------------------------------------------------ 5. hand-over
def handover_table():
    from stress import test_handover as scene

    from spinorbit.core.integrators.handover import integrate_with_handover

    lines = ["| initial state | rtol | switches | hand-over error (rad) | DOP853 alone (rad) |", "|---|---:|---:|---:|---:|"]
    for gap, label in [(0.02, "1 − m = 0.23, passages"), (0.06, "1 − m = 0.64, none")]:
        y0 = scene.state_with_gap(gap)
        ref = scene.reference(y0)
        for rtol in (1e-10, 1e-12):
            ys, switches = integrate_with_handover(y0, 0.0, scene.T_OUT, scene.model(), rtol=rtol)
            plain = integrate_quaternion(y0, 0.0, scene.T_OUT, scene.model(), rtol=rtol)
            lines.append(f"| {label} | {rtol:.0e} | {len(switches)} | {scene.angle(ys, ref):.1e} | "
                         f"{scene.angle(plain, ref):.1e} |")
    return lines


# ------------------------------------------------------------------------------------ report
def plots(energy, free, chaos, rows):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    IMG.mkdir(parents=True, exist_ok=True)
    kw = {"figsize": (6.0, 3.6), "dpi": 80}

    fig, ax = plt.subplots(**kw)
    for label, (steps, err) in energy.items():
        ax.loglog(steps, np.maximum(err, EPS / 10), label=label, lw=1)
    n = np.geomspace(1, max(s[-1] for s, _ in energy.values()), 50)
    ax.loglog(n, EPS * np.sqrt(n), "k--", lw=1, label="floor ε√n (Brouwer)")
    ax.set(xlabel="steps (adaptive: t × steps/span)", ylabel="|ΔE / E|", title="Energy error under a torque (E = T − U conserved)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(IMG / "stability_energy.png")
    plt.close(fig)

    fig, ax = plt.subplots(**kw)
    ax.loglog(free["rotations"], np.maximum(free["phase"], EPS / 10), "o-", label="attitude error vs mpmath (40 digits)")
    ax.loglog(free["rotations"], free["floor"], "k--", label="floor: 2-ulp input sensitivity + ulp(t)|ω|")
    ax.loglog(free["dense_rotations"], np.maximum(free["momentum"], EPS / 10), ".", ms=1, label="| |M|/|M₀| − 1 |")
    ax.loglog(free["dense_rotations"], np.maximum(free["energy"], EPS / 10), ".", ms=1, label="| E/E₀ − 1 |")
    ax.axhline(EPS, color="gray", lw=0.8)
    ax.set(xlabel="rotations", ylabel="error (exact 0 drawn at ε/10)", title="Exact torque-free flow over 10⁷ rotations")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(IMG / "stability_torque_free.png")
    plt.close(fig)

    t_l, orbits, curves = chaos
    tl = t_l["spin rate"]
    fig, ax = plt.subplots(**kw)
    for label, (errors, eps, tau) in curves.items():
        (line,) = ax.semilogy(orbits, errors, "o", ms=3, label=f"{label}: ε = {eps:.0e}, τ = {tau / tl:.2f} T_L")
        ax.semilogy(orbits, eps * np.exp(orbits * chaotic.ORBIT / tau), "-", lw=0.8, color=line.get_color())
    ax.semilogy(orbits, EPS * np.exp(orbits * chaotic.ORBIT / tl), "k--", lw=1, label="floor ε_mach · exp(T/T_L)")
    ax.set(xlabel="T (orbits of Saturn)", ylabel="return error", title=f"Forward–backward, Hyperion-like (T_L = {tl / chaotic.ORBIT:.2f} orbits)")
    ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(IMG / "stability_chaotic.png")
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(6.0, 4.2), dpi=80)
    x = np.arange(len(rows))
    ax.semilogy(x, [max(r[1], EPS / 100) for r in rows], "o", ms=3, label="round-trip error")
    ax.semilogy(x, [r[2] for r in rows], "k_", ms=8, label="floor (2-ulp sensitivity of the backward map)")
    ax.set(xlabel="sweep case (table below)", ylabel="rad + |ΔM|/G", title="State → elements → state across the sweep")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(IMG / "stability_round_trip.png")
    plt.close(fig)


def report(energy, free, chaos, rows, handover, n_steps):
    t_l, orbits, curves = chaos
    lines = ["## Measured (`benchmarks/stability.py`)", "", machine_line(), ""]
    lines += ["### Energy error under a torque, 10⁶ steps", "",
              "![energy](img/stability_energy.png)", "",
              ("| integrator | steps | max \\|ΔE/E\\| | at the end | growth p (\\|ΔE\\| ∝ nᵖ, last 2 decades) "
              "| floor ε√n at the end |"), "|---|---:|---:|---:|---:|---:|"]
    for label, (steps, err) in energy.items():
        lines.append(f"| {label} | {steps[-1]:.2e} | {err.max():.1e} | {err[-1]:.1e} | "
                     f"{growth_exponent(steps, err):.2f} | {EPS * math.sqrt(steps[-1]):.1e} |")
    lines += ["", "### Exact torque-free flow, 10⁷ rotations (Apophis-like SAM body)", "",
              "![torque-free](img/stability_torque_free.png)", "",
              (f"Largest \\|\\|M\\|/\\|M₀\\| − 1\\| = {free['momentum'].max() / EPS:.1f} ε and \\|E/E₀ − 1\\| = "
              f"{free['energy'].max() / EPS:.1f} ε over 3000 times to 10⁷ rotations."), "",
              "| rotations | attitude error vs mpmath (rad) | floor (rad) |", "|---:|---:|---:|"]
    for r, e, f in zip(free["rotations"], free["phase"], free["floor"]):
        lines.append(f"| {r:.0e} | {e:.1e} | {f:.1e} |")
    lines += ["", "### Chaotic rotation: Hyperion-like body (`benchmarks/chaotic.py`)", "",
              "![chaotic](img/stability_chaotic.png)", "",
              "Lyapunov time from renormalised nearby states: " + ", ".join(
                  f"{v / chaotic.ORBIT:.3f} orbits (offset in {k})" for k, v in t_l.items()) + ".", "",
              f"Fit of log(return error) = log ε + T/τ over the spans where the error is below {SATURATION:g}.", "",
              f"| integrator | ε (fit) | τ / T_L (fit) | return error at {orbits[-1]} orbits | floor ε_mach·exp(T/T_L) |",
              "|---|---:|---:|---:|---:|"]
    tl = t_l["spin rate"]
    for label, (errors, eps, tau) in curves.items():
        floor = EPS * math.exp(orbits[-1] * chaotic.ORBIT / tl)
        lines.append(f"| {label} | {eps:.1e} | {tau / tl:.2f} | {errors[-1]:.1e} | {floor:.1e} |")
    lines += ["", "### Round trip through the elements across the sweep", "",
              "![round trip](img/stability_round_trip.png)", "",
              "| # | case | round-trip error | floor | error / floor |", "|---:|---|---:|---:|---:|"]
    for i, (label, err, floor) in enumerate(rows):
        lines.append(f"| {i} | {label} | {err:.1e} | {floor:.1e} | {err / floor:.2f} |")
    lines += ["", "### Element ↔ quaternion hand-over (scene of `tests/stress/test_handover.py`)", "",
              "Errors against DOP853 at rtol 1e-15 over 60 time units (~30 turns).", "", *handover]
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="10x shorter runs, print only")
    args = parser.parse_args()
    scale = 10 if args.quick else 1
    n_steps = 1_000_000 // scale
    energy = energy_runs(n_steps)
    free = torque_free_long(10**7 // scale)
    chaos = chaotic_runs(300 // scale, 20)
    rows = sweep()
    handover = handover_table()
    markdown = report(energy, free, chaos, rows, handover, n_steps)
    print(markdown)
    if not args.quick:
        plots(energy, free, chaos, rows)
        write_section("stability", markdown, page="stability.md")


if __name__ == "__main__":
    main()
