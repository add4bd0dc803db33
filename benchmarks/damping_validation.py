"""Nutation damping: the model's time scale against Burns & Safronov's formula, and the mean run's decay.

::

    PYTHONPATH=$PWD python benchmarks/damping_validation.py             # writes docs/thermal.md's section
    PYTHONPATH=$PWD python benchmarks/damping_validation.py --no-write  # print only

Reference: τ_D = μQ/(ρ K₃² R² ω³) (Burns & Safronov 1973), evaluated here in SI by hand, apart from
:mod:`spinorbit.core.averaging.dissipation`; and the decay of the energy above the principal-axis
state, exp(−2t/τ_D), that the drift is defined to follow. The mean run
(:func:`~spinorbit.core.averaging.thermal_mean.propagate_mean_thermal`, damping only) is compared
with that closed form for a short-axis and a long-axis tumbler; the long-axis one crosses the
separatrix on the way.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from _report import machine_line, write_section  # noqa: E402

from spinorbit.core.averaging.dissipation import damping_constant, damping_time  # noqa: E402
from spinorbit.core.averaging.thermal_mean import propagate_mean_thermal  # noqa: E402
from spinorbit.core.dynamics.equations import make_model  # noqa: E402
from spinorbit.core.elements.canonical import inertia_constants  # noqa: E402
from spinorbit.core.integrators.elements import elements_of_state  # noqa: E402
from spinorbit.core.model.perturbers import kepler_source  # noqa: E402

GM_SUN = 0.01720209895**2  # au³/day²
SECONDS_PER_YEAR = 365.25 * 86400.0
#: (μQ Pa, ρ kg/m³, R m, K₃², spin period h): μQ = 5e12 Pa and K₃² = 0.01–0.1 as Harris (1994) took them,
#: and softer interiors (1e11, 1e9 Pa) for range; sizes and spins of tumbling near-Earth asteroids.
CASES = ((5e12, 2000.0, 500.0, 0.01, 6.0), (5e12, 2000.0, 100.0, 0.05, 30.0), (1e11, 1500.0, 2000.0, 0.1, 12.0),
         (1e9, 2000.0, 200.0, 0.01, 6.0))
MOMENTS = np.array([0.6, 0.92, 1.0]) * 1e16  # kg m², a 200 m-class body


def time_scale_rows():
    ic = inertia_constants(*MOMENTS)
    rows = []
    for mu_q, rho, radius, k3, period_h in CASES:
        omega_si = 2 * math.pi / (period_h * 3600.0)
        big_z = MOMENTS[2] * omega_si * 86400.0  # rotation about C at ω, kg m² rad/day
        model_days = damping_time(big_z, ic, damping_constant(mu_q, rho, radius, k3))
        formula_s = mu_q / (rho * k3 * radius**2 * omega_si**3)
        rows.append((mu_q, rho, radius, k3, period_h, model_days * 86400.0 / SECONDS_PER_YEAR,
                     formula_s / SECONDS_PER_YEAR, abs(model_days * 86400.0 / formula_s - 1.0)))
    return rows


def decay_rows():
    """The mean run's energy excess against exp(−2t/τ_D) at 0.25–6 τ_D, for a short- and a long-axis start."""
    sun = kepler_source(GM_SUN, 1.0, 0.1, 0.0, 0.0, 0.0, 0.0, sign=-1.0)
    model = make_model(MOMENTS, [sun])
    frame = np.diag([-1.0, -1.0, 1.0])
    a, b, c, _, _, _ = ic = inertia_constants(*MOMENTS)
    omega = 2 * math.pi / 0.25
    q = np.array([0.9, 0.2, -0.3, 0.25])
    starts = (("short-axis (SAM) near C", np.array([*(q / np.linalg.norm(q)), 0.1 * omega, 0.1 * omega, omega])),
              ("long-axis (LAM), through the separatrix", np.array([1.0, 0.0, 0.0, 0.0, omega, 0.2 * omega,
                                                                     0.2 * omega])))
    k = 1e9  # day⁻²: τ_D ≈ 6e4 days at this 6 h spin (the time scale only sets the clock)
    rows = []
    for name, y0 in starts:
        el0 = elements_of_state(y0, model, frame)
        tau = damping_time(el0[1], ic, k)
        ratios = np.array([0.25, 0.5, 1.0, 2.0, 4.0, 6.0])
        out, _ = propagate_mean_thermal(el0, 0.0, tau * ratios, model, frame, step=tau / 50, with_gravity=False,
                                        damping_constant=k)
        d0, d = a * el0[0] ** 2 / el0[1] ** 2, a * out[:, 0] ** 2 / out[:, 1] ** 2
        excess = (d - c) / (d0 - c)
        error = np.max(np.abs(excess / np.exp(-2 * ratios) - 1.0))
        crossed = bool(d0 > b > d[-1])
        rows.append((name, tau, d0 / c, d[-1] / c, crossed, error, float(np.max(np.abs(out[:, 1] / el0[1] - 1.0)))))
    return rows


def markdown(scales, decays, seconds):
    lines = [f"Written by `PYTHONPATH=$PWD python benchmarks/damping_validation.py` in {seconds:.0f} s. "
             f"{machine_line()}", "",
             "**Time scale.** τ_D from the package (`damping_time` of `damping_constant(μQ, ρ, R, K₃²)`, rotation "
             "about C at ω) against Burns & Safronov's τ_D = μQ/(ρ K₃² R² ω³) evaluated here in SI:", "",
             "| μQ (Pa) | ρ (kg/m³) | R (m) | K₃² | P (h) | τ_D, package (yr) | τ_D, formula (yr) | relative difference |",
             "|---|---|---|---|---|---|---|---|"]
    for mu_q, rho, radius, k3, period, model_yr, formula_yr, diff in scales:
        lines.append(f"| {mu_q:.0e} | {rho:.0f} | {radius:.0f} | {k3:g} | {period:g} | {model_yr:.6g} | "
                     f"{formula_yr:.6g} | {diff:.1e} |")
    lines += ["", "**Decay in the mean run** (`propagate_mean_thermal`, damping only, steps of τ_D/50): the energy "
              "above the principal-axis state, as (d − c)/(d₀ − c) with d = a S²/Z², against exp(−2t/τ_D) at "
              "t/τ_D = 0.25, 0.5, 1, 2, 4, 6; Z (the angular momentum) must not change; d/c = 1 is rotation about C, d = b the separatrix:", "",
              "| start | τ_D (days) | d₀/c | d/c at 6 τ_D | crossed the separatrix (d = b) | largest relative error | "
              "largest change of Z |", "|---|---|---|---|---|---|---|"]
    for name, tau, d0, d_end, crossed, error, z_change in decays:
        lines.append(f"| {name} | {tau:.3g} | {d0:.6f} | {d_end:.6f} | {'yes' if crossed else 'no'} | {error:.1e} | "
                     f"{z_change:.1e} |")
    lines += ["", "The relative differences of the time scale are rounding (the SI and day units are converted in "
              "different orders). The decay's error is the integrator's on a smooth exponential; the separatrix "
              "does not show in it, because damping alone needs no torus average."]
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-write", action="store_true", help="print only, do not write docs/thermal.md")
    args = parser.parse_args(argv)
    start = time.perf_counter()
    text = markdown(time_scale_rows(), decay_rows(), time.perf_counter() - start)
    print(text)
    if not args.no_write:
        print(write_section("damping_validation", text, page="thermal.md"))


if __name__ == "__main__":
    main()
