"""Re-fit the Toutatis 1992 state from synthetic radar attitudes: how the moment ratios' uncertainty shrinks.

Writes the section ``toutatis_fit`` of docs/fitting.md and the figure docs/img/fitting_toutatis.png (the
numbers there come from this script only).

The truth is the published state of Takahashi, Busch & Scheeres (2013, Table 2; ``spinorbit.data``),
moments A/C = 0.3091, B/C = 0.9532. Synthetic "radar" attitudes are that state propagated by the exact
free flow to N epochs spread evenly over the 30 days after the published epoch, each turned by a
Gaussian rotation vector of σ = 2° per axis (torques are left out of the data and of the fit alike).
Each set is fitted with :func:`spinorbit.fit.fit_rotation` (exact STM back end) from one first guess
5.8° and 3 % off in spin and with moments (1.0, 3.0, 3.3), i.e. A/C = 0.303, B/C = 0.909. For each N,
``DRAWS`` noise draws: how many converged, the median formal σ of A/C and B/C (from the covariance),
the scatter (standard deviation) of the fitted values over the converged draws, and the median
reduced χ².

Usage::

    PYTHONPATH=$PWD python benchmarks/fit_toutatis.py            # ≈ 1 min
    PYTHONPATH=$PWD python benchmarks/fit_toutatis.py --no-write # print only
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np
from astropy import units as u
from astropy.time import TimeDelta

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from _report import machine_line, write_section  # noqa: E402

from spinorbit.body import RigidBody  # noqa: E402
from spinorbit.core.free_motion.flow import torque_free_states  # noqa: E402
from spinorbit.core.math.rotations import attitude_to_quat, quat_multiply, quat_to_attitude  # noqa: E402
from spinorbit.data.asteroids import TOUTATIS_EPOCH, toutatis_rotation_state  # noqa: E402
from spinorbit.fit import AttitudeObservation, FitError, UnseparatedParametersWarning, fit_rotation  # noqa: E402
from spinorbit.fit.observations import rotation_quaternion  # noqa: E402
from spinorbit.state import RotationState  # noqa: E402

COUNTS = (10, 15, 30, 60, 120)
DRAWS = 20
SPAN_DAYS = 30.0
SIGMA_DEG = 2.0
SEED = 1992
FIGURE = Path(__file__).resolve().parent.parent / "docs" / "img" / "fitting_toutatis.png"


def synthetic_set(truth, days, rng):
    body = truth.body
    p = body.to_principal
    core = truth.core_state()
    moments = np.array(body.principal_moments)
    q = torque_free_states(core[:4], moments * core[4:], *moments, days)[0]
    sigma = np.deg2rad(SIGMA_DEG)
    out = []
    for k, d in enumerate(days):
        noisy = quat_multiply(q[k], rotation_quaternion(rng.normal(0.0, sigma, 3)))
        user = attitude_to_quat(np.ascontiguousarray(p.T @ quat_to_attitude(noisy)))
        out.append(AttitudeObservation(TOUTATIS_EPOCH + TimeDelta(d * u.day), user, SIGMA_DEG * u.deg))
    return out


def first_guess(truth):
    p = truth.body.to_principal
    core = truth.core_state()
    q = quat_multiply(core[:4], rotation_quaternion(np.deg2rad([4.0, -2.5, 3.0])))
    return RotationState.from_matrix(RigidBody([3.0, 3.3, 1.0]), p.T @ quat_to_attitude(q),
                                     truth.angular_velocity * 1.03)


def measure():
    truth = toutatis_rotation_state("ecliptic")
    big_a, big_b, big_c = truth.body.principal_moments
    rng = np.random.default_rng(SEED)
    rows = []
    for n in COUNTS:
        days = np.linspace(0.0, SPAN_DAYS, n)
        fitted, sigmas, chi2, failures = [], [], [], 0
        start = time.perf_counter()
        for _ in range(DRAWS):
            observations = synthetic_set(truth, days, rng)
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", UnseparatedParametersWarning)
                    result = fit_rotation(observations, first_guess(truth), TOUTATIS_EPOCH)
            except FitError:
                failures += 1
                continue
            fitted.append(result.moment_ratios)
            sigmas.append(result.standard_errors[6:])
            chi2.append(result.reduced_chi2)
        rows.append(dict(n=n, converged=DRAWS - failures, fitted=np.array(fitted), sigmas=np.array(sigmas),
                         chi2=np.array(chi2), seconds=time.perf_counter() - start))
    return (big_a / big_c, big_b / big_c), rows


def markdown(truth_ratios, rows):
    lines = [f"Truth A/C = {truth_ratios[0]:.4f}, B/C = {truth_ratios[1]:.4f}; σ = {SIGMA_DEG:g}° per axis, "
             f"N attitudes evenly over {SPAN_DAYS:g} d, {DRAWS} noise draws per N (seed {SEED}).", "",
             "| N | converged | median formal σ(A/C) | scatter of A/C | median formal σ(B/C) | scatter of B/C | "
             "mean A/C − truth | mean B/C − truth | median χ²/dof | s per fit |",
             "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for row in rows:
        if row["converged"] < 2:
            lines.append(f"| {row['n']} | {row['converged']}/{DRAWS} | – | – | – | – | – | – | – | – |")
            continue
        sig = np.median(row["sigmas"], axis=0)
        scatter = np.std(row["fitted"], axis=0, ddof=1)
        bias = np.mean(row["fitted"], axis=0) - np.array(truth_ratios)
        lines.append(f"| {row['n']} | {row['converged']}/{DRAWS} | {sig[0]:.2e} | {scatter[0]:.2e} | {sig[1]:.2e} | "
                     f"{scatter[1]:.2e} | {bias[0]:+.1e} | {bias[1]:+.1e} | {np.median(row['chi2']):.2f} | "
                     f"{row['seconds'] / DRAWS:.2f} |")
    lines += ["", "![Formal σ of the moment ratios (lines) and the scatter of the fitted values (markers) against "
              "the number of attitudes, with N^(−1/2)](img/fitting_toutatis.png)", "", machine_line()]
    return "\n".join(lines)


def plot(rows):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    usable = [row for row in rows if row["converged"] >= 2]
    n = np.array([row["n"] for row in usable])
    for k, (name, colour) in enumerate((("A/C", "C0"), ("B/C", "C1"))):
        ax.loglog(n, [np.median(row["sigmas"][:, k]) for row in usable], "-", color=colour, label=f"formal σ({name})")
        ax.loglog(n, [np.std(row["fitted"][:, k], ddof=1) for row in usable], "o", color=colour,
                  label=f"scatter of {name}")
    reference = np.median(usable[0]["sigmas"][:, 1]) * np.sqrt(n[0] / n)
    ax.loglog(n, reference, ":", color="0.5", label="∝ N^(−1/2)")
    ax.set_xlabel("number of attitudes N (over 30 d)")
    ax.set_ylabel("uncertainty of the ratio")
    ax.set_title(f"Toutatis re-fit from synthetic attitudes (σ = {SIGMA_DEG:g}°)")
    ax.legend(fontsize="small")
    fig.tight_layout()
    FIGURE.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(FIGURE, dpi=110)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-write", action="store_true", help="print only, do not touch docs/")
    args = parser.parse_args(argv)
    truth_ratios, rows = measure()
    text = markdown(truth_ratios, rows)
    print(text)
    if not args.no_write:
        plot(rows)
        print(f"wrote {write_section('toutatis_fit', text, page='fitting.md')} and {FIGURE}")


if __name__ == "__main__":
    main()
