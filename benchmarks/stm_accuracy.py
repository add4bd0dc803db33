"""How exact the STMs are: the measured agreement behind the tolerances of tests/test_stm.py.

Writes the section ``stm_accuracy`` of docs/fitting.md. The same states and references as the tests:
the body (A, B, C) = (1, 2, 3) in a short-axis mode (ω = (0.3, 0.2, 1)) and a long-axis mode
(ω = (1, 0.2, 0.1)), and

1. the exact STM (Φ, Ψ) at t = 2.5 against 40-digit central differences of an independent Taylor
   integrator (``tests/_mp_rigid_body.py``);
2. the DOP853 variational equations at rtol 1e-13 without torque against the exact STM at t = 3, 20;
3. the DOP853 variational equations with a perturber's degree-2 torque against Richardson-extrapolated
   central differences of ``integrate_quaternion`` at rtol 1e-14;
4. the Taylor variational recurrences at tol 1e-14, without torque against the exact STM and with the
   torque against Richardson differences of ``integrate_taylor`` at tol 1e-14;
5. the averaged propagator's mean-element STM (Apophis-like scene, solar torque × 10, t = 10, 30 d;
   doubly averaged t = 100, 400 d) against central differences of ``propagate_averaged`` (step 1e-7),
   and its osculating-element STM against differences of its osculating output (step 1e-6).

Usage::

    PYTHONPATH=$PWD python benchmarks/stm_accuracy.py [--no-write]     # ≈ 20 s
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))

from _mp_rigid_body import stm_by_finite_differences  # noqa: E402
from _report import machine_line, write_section  # noqa: E402

from test_stm import apophis_mean_problem  # noqa: E402

from spinorbit.core.averaging.mean_equations import moments_of  # noqa: E402
from spinorbit.core.averaging.mean_variational import mean_elements_stm, osculating_elements_stm  # noqa: E402
from spinorbit.core.averaging.propagate import propagate_averaged, state_of_elements  # noqa: E402
from spinorbit.core.dynamics.equations import make_model  # noqa: E402
from spinorbit.core.free_motion.stm import free_flow_stm  # noqa: E402
from spinorbit.core.integrators.elements import elements_of_state  # noqa: E402
from spinorbit.core.integrators.quaternion import integrate_quaternion  # noqa: E402
from spinorbit.core.integrators.taylor import integrate_taylor  # noqa: E402
from spinorbit.core.integrators.taylor_variational import integrate_taylor_variational  # noqa: E402
from spinorbit.core.integrators.variational import integrate_variational  # noqa: E402
from spinorbit.core.math.rotations import quat_conjugate, quat_multiply  # noqa: E402
from spinorbit.core.model.perturbers import kepler_source  # noqa: E402
from spinorbit.fit.observations import rotation_quaternion, rotation_vector  # noqa: E402

MOMENTS = np.array([1.0, 2.0, 3.0])
Q0 = np.array([0.9, 0.1, -0.3, 0.2]) / np.linalg.norm([0.9, 0.1, -0.3, 0.2])
STATES = {"SAM": np.array([0.3, 0.2, 1.0]), "LAM": np.array([1.0, 0.2, 0.1])}
PERTURBER = kepler_source(2.0, 3.0, 0.2, 0.4, 0.3, 0.1, 0.0)


def quaternion_reference(y0, times, model):
    return integrate_quaternion(y0, 0.0, times, model, rtol=1e-14)


def taylor_reference(y0, times, model):
    return integrate_taylor(y0, 0.0, times, model, tol=1e-14)


def richardson_of_integrator(omega, times, ys, integrate=quaternion_reference, h=2e-4):
    def model(dp):
        return make_model(MOMENTS + np.array([dp[0], dp[1], 0.0]) * MOMENTS[2], [PERTURBER])

    def run(delta, dp=(0.0, 0.0)):
        y0 = np.concatenate([quat_multiply(Q0, rotation_quaternion(delta[:3])), omega + delta[3:]])
        y = integrate(y0, times, model(dp))
        return np.array([np.concatenate([rotation_vector(quat_multiply(quat_conjugate(ys[k, :4]), y[k, :4])),
                                         y[k, 4:]]) for k in range(times.size)])

    def derivative(f, n):
        def central(step):
            return np.stack([(f(step * e) - f(-step * e)) / (2 * step) for e in np.eye(n)], axis=-1)
        return (4.0 * central(h / 2) - central(h)) / 3.0

    return derivative(run, 6), derivative(lambda dp: run(np.zeros(6), dp), 2)


def measure():
    rows = []
    for mode, omega in STATES.items():
        phi_ref, psi_ref = stm_by_finite_differences(Q0, omega, MOMENTS, 2.5)
        _, _, phi, psi = free_flow_stm(Q0, omega, MOMENTS, [2.5])
        rows.append((f"exact STM, {mode}, t = 2.5", "40-digit differences of a Taylor integrator",
                     np.abs(phi[0] - phi_ref).max(), np.abs(psi[0] - psi_ref).max(),
                     max(np.abs(phi[0]).max(), np.abs(psi[0]).max())))
    times = np.array([3.0, 20.0])
    for mode, omega in STATES.items():
        _, phi, psi = integrate_variational(np.concatenate([Q0, omega]), 0.0, times, make_model(MOMENTS), rtol=1e-13)
        _, _, phi_e, psi_e = free_flow_stm(Q0, omega, MOMENTS, times)
        rows.append((f"DOP853 variational, {mode}, no torque, t ≤ 20", "the exact STM",
                     np.abs(phi - phi_e).max(), np.abs(psi - psi_e).max(), max(np.abs(phi_e).max(), np.abs(psi_e).max())))
    omega = STATES["SAM"]
    ys, phi, psi = integrate_variational(np.concatenate([Q0, omega]), 0.0, times, make_model(MOMENTS, [PERTURBER]),
                                         rtol=1e-13)
    fd, fd_p = richardson_of_integrator(omega, times, ys)
    rows.append(("DOP853 variational, SAM, degree-2 torque, t ≤ 20",
                 "Richardson differences of integrate_quaternion (rtol 1e-14)",
                 np.abs(phi - fd).max(), np.abs(psi - fd_p).max(), max(np.abs(phi).max(), np.abs(psi).max())))
    for mode, omega in STATES.items():
        _, phi, psi = integrate_taylor_variational(np.concatenate([Q0, omega]), 0.0, times, make_model(MOMENTS),
                                                   tol=1e-14)
        _, _, phi_e, psi_e = free_flow_stm(Q0, omega, MOMENTS, times)
        rows.append((f"Taylor variational, {mode}, no torque, t ≤ 20", "the exact STM",
                     np.abs(phi - phi_e).max(), np.abs(psi - psi_e).max(), max(np.abs(phi_e).max(), np.abs(psi_e).max())))
    omega = STATES["SAM"]
    ys, phi, psi = integrate_taylor_variational(np.concatenate([Q0, omega]), 0.0, times,
                                                make_model(MOMENTS, [PERTURBER]), tol=1e-14)
    fd, fd_p = richardson_of_integrator(omega, times, ys, integrate=taylor_reference)
    rows.append(("Taylor variational, SAM, degree-2 torque, t ≤ 20",
                 "Richardson differences of integrate_taylor (tol 1e-14)",
                 np.abs(phi - fd).max(), np.abs(psi - fd_p).max(), max(np.abs(phi).max(), np.abs(psi).max())))
    rows.extend(averaged_rows())
    return rows


def differences(run, x0, step):
    """Central differences of run (6 elements in, (n, 6) out) in each element, z and h mod 2π."""
    columns = []
    for j in range(6):
        h = step * (abs(x0[1]) if j < 3 else 1.0)
        delta = np.zeros(6)
        delta[j] = h
        diff = run(x0 + delta) - run(x0 - delta)
        diff[:, 4:] -= 2 * np.pi * np.rint(diff[:, 4:] / (2 * np.pi))  # z, h are angles
        columns.append(diff / (2 * h))
    return np.stack(columns, axis=-1)


def averaged_rows():
    y0, model, frame, mean0 = apophis_mean_problem()
    rows = []
    for orbit_averaged, times, label in ((False, np.array([10.0, 30.0]), "t ≤ 30 d"),
                                         (True, np.array([100.0, 400.0]), "doubly averaged, t ≤ 400 d")):
        _, phi = mean_elements_stm(mean0, 0.0, times, model, frame, orbit_averaged=orbit_averaged)

        def run(m0, times=times, orbit_averaged=orbit_averaged):
            return propagate_averaged(y0, 0.0, times, model, frame=frame, mean0=m0, hand_over=False,
                                      orbit_averaged=orbit_averaged).mean_elements

        fd = differences(run, mean0, 1e-7)
        rows.append((f"averaged mean elements, Apophis-like (Sun × 10), {label}",
                     "central differences of propagate_averaged", np.abs(phi - fd).max(), None, np.abs(phi).max()))
    moments = moments_of(model)
    osc0 = elements_of_state(y0, model, frame)
    times = np.array([10.0, 30.0])
    _, phi = osculating_elements_stm(osc0, 0.0, times, model, frame)

    def run_osculating(x0):
        res = propagate_averaged(state_of_elements(x0, frame, moments), 0.0, times, model, frame=frame,
                                 hand_over=False, osculating=True)
        return np.array([elements_of_state(state, model, frame) for state in res.states])

    fd = differences(run_osculating, osc0, 1e-6)
    rows.append(("averaged osculating elements, Apophis-like (Sun × 10), t ≤ 30 d",
                 "central differences of propagate_averaged's osculating output", np.abs(phi - fd).max(), None,
                 np.abs(phi).max()))
    return rows


def markdown(rows):
    lines = ["| STM | reference | max \\|ΔΦ\\| | max \\|ΔΨ\\| | largest entry |", "|---|---|---:|---:|---:|"]
    for label, reference, d_phi, d_psi, scale in rows:
        psi_text = "–" if d_psi is None else f"{d_psi:.1e}"
        lines.append(f"| {label} | {reference} | {d_phi:.1e} | {psi_text} | {scale:.1f} |")
    lines += ["", machine_line()]
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-write", action="store_true")
    args = parser.parse_args(argv)
    text = markdown(measure())
    print(text)
    if not args.no_write:
        print(f"wrote {write_section('stm_accuracy', text, page='fitting.md')}")


if __name__ == "__main__":
    main()
