"""State transition matrices and parameter sensitivities (issue 21).

The exact free-flow STM (:mod:`spinorbit.core.free_motion.stm`) against 40-digit finite differences of
an independent Taylor integrator (``tests/_mp_rigid_body.py``); the DOP853 variational equations
(:mod:`spinorbit.core.integrators.variational`) against central finite differences of the integrator
itself and against the exact STM.
"""

import numpy as np
import pytest

from _mp_rigid_body import stm_by_finite_differences
from spinorbit.core.errors import SingularElementsError
from spinorbit.core.free_motion.stm import free_flow_stm
from spinorbit.core.math.rotations import quat_conjugate, quat_multiply

MOMENTS = np.array([1.0, 2.0, 3.0])
Q0 = np.array([0.9, 0.1, -0.3, 0.2]) / np.linalg.norm([0.9, 0.1, -0.3, 0.2])
#: One short-axis-mode state (spin near C, E/E0 < C/B) and one long-axis-mode state (spin near A).
STATES = {"SAM": np.array([0.3, 0.2, 1.0]), "LAM": np.array([1.0, 0.2, 0.1])}


def rotation_vector(q):
    """log of a unit quaternion as a rotation vector (q and −q alike)."""
    q = q if q[0] >= 0 else -q
    s = np.linalg.norm(q[1:])
    return np.zeros(3) if s == 0 else 2.0 * np.arctan2(s, q[0]) * q[1:] / s


def exp_rotation(v):
    angle = np.linalg.norm(v)
    if angle == 0:
        return np.array([1.0, 0.0, 0.0, 0.0])
    return np.concatenate([[np.cos(angle / 2)], np.sin(angle / 2) * v / angle])


def local_difference(q_ref, q, omega):
    """(δθ, ω) of a state relative to the reference attitude: q = q_ref ⊗ exp(δθ/2)."""
    return np.concatenate([rotation_vector(quat_multiply(quat_conjugate(q_ref), q)), omega])


@pytest.mark.parametrize("mode", STATES)
def test_free_flow_stm_matches_40_digit_finite_differences(mode):
    # Tolerance 1e-13 absolute on entries of size 1–5: the flow and the section-4 Jacobian are each good
    # to a few ulps, and K(0)⁻¹ (condition number ~1e2 here) amplifies that; measured 9e-16 (SAM) and
    # 4e-15 (LAM) for Φ, 6e-15 and 1.4e-14 for Ψ at t = 4.
    t = 2.5
    phi_ref, psi_ref = stm_by_finite_differences(Q0, STATES[mode], MOMENTS, t)
    _, _, phi, psi = free_flow_stm(Q0, STATES[mode], MOMENTS, [t])
    assert np.abs(phi[0]).max() > 1.5  # not the identity: the test can fail
    np.testing.assert_allclose(phi[0], np.array(phi_ref), rtol=0, atol=1e-13)
    np.testing.assert_allclose(psi[0], np.array(psi_ref), rtol=0, atol=5e-13)


@pytest.mark.parametrize("mode", STATES)
def test_free_flow_stm_over_many_periods_matches_finite_differences_of_the_flow(mode):
    # 60 time units, ~10 rotations: Φ and Ψ grow secularly (the period depends on the energy and the
    # moments), and so do the third derivatives that limit a finite difference (measured: the central
    # difference of Ψ errs by 1.2e5·h²). Reference: Richardson-extrapolated central differences of the
    # exact flow, (4 D(h/2) − D(h))/3 with h = 2e-5, error O(h⁴) + ε|x|/h ≈ 1e-10·|Ψ|; tolerance
    # 1e-8 relative to the largest entry.
    t = np.array([-9.0, 0.0, 7.0, 60.0])  # both directions of time (the quadrature runs each way)
    omega = STATES[mode]
    q_ref, _, phi, psi = free_flow_stm(Q0, omega, MOMENTS, t)
    np.testing.assert_allclose(phi[1], np.eye(6), atol=1e-14)

    def run(delta, dp=(0.0, 0.0)):
        moments = MOMENTS + np.array([dp[0], dp[1], 0.0]) * MOMENTS[2]
        q, w, _, _ = free_flow_stm(quat_multiply(Q0, exp_rotation(delta[:3])), omega + delta[3:], moments, t,
                                   parameters=False)
        return np.array([local_difference(q_ref[k], q[k], w[k]) for k in range(t.size)])

    def richardson(f, n, h=2e-5):
        def central(step):
            return np.stack([(f(step * e) - f(-step * e)) / (2 * step) for e in np.eye(n)], axis=-1)
        return (4.0 * central(h / 2) - central(h)) / 3.0

    fd = richardson(run, 6)
    fd_p = richardson(lambda dp: run(np.zeros(6), dp), 2)
    scale, scale_p = np.abs(phi[-1]).max(), np.abs(psi[-1]).max()
    assert scale > 10.0 and scale_p > 10.0
    np.testing.assert_allclose(phi, fd, rtol=0, atol=1e-8 * scale)
    np.testing.assert_allclose(psi, fd_p, rtol=0, atol=1e-8 * scale_p)


def test_free_flow_stm_is_symplectic_in_momentum_variables():
    # Φ in (δθ, M) of a Hamiltonian flow on the Lie group preserves the Lie–Poisson structure; a cheap
    # necessary check: det Φ = 1 (the free flow preserves phase-space volume in (δθ, ω) too, since
    # T = diag(1, I) is constant). Tolerance 1e-10 on a determinant of entries up to ~50.
    _, _, phi, _ = free_flow_stm(Q0, STATES["LAM"], MOMENTS, [3.0, 40.0], parameters=False)
    np.testing.assert_allclose(np.linalg.det(phi), 1.0, atol=1e-10)


@pytest.mark.parametrize(
    ("omega", "moments", "match"),
    [
        (np.array([0.0, 0.0, 1.0]), MOMENTS, "off the C axis"),
        (np.array([0.0, 1.0, 0.0]), MOMENTS, "no finite canonical elements"),
        (np.array([0.3, 0.2, 1.0]), np.array([1.0, 1.0, 3.0]), "triaxial"),
    ],
)
def test_free_flow_stm_refuses_singular_states(omega, moments, match):
    with pytest.raises(SingularElementsError, match=match):
        free_flow_stm(Q0, omega, moments, [1.0])


# --------------------------------------------------------------------------------------------------
# DOP853 variational equations
# --------------------------------------------------------------------------------------------------

from spinorbit.core.dynamics.equations import make_model  # noqa: E402
from spinorbit.core.integrators.quaternion import integrate_quaternion  # noqa: E402
from spinorbit.core.integrators.variational import integrate_variational  # noqa: E402
from spinorbit.core.model.perturbers import kepler_source  # noqa: E402

#: A perturber close enough that its degree-2 torque changes Φ by O(1) over the span (measured 5.2
#: in max|Φ_torqued − Φ_free| at t = 20).
PERTURBER = kepler_source(2.0, 3.0, 0.2, 0.4, 0.3, 0.1, 0.0)


@pytest.mark.parametrize("mode", STATES)
def test_variational_equations_without_torque_reproduce_the_exact_stm(mode):
    # Two independent routes: numerical integration of the linearised equations at rtol 1e-13 against
    # the closed form through the elements. Measured 8e-13 (SAM) and 1.5e-12 (LAM) on entries up to 19
    # at t = 20: the integrator's global error; tolerance 1e-11.
    t = np.array([3.0, 20.0])
    _, phi, psi = integrate_variational(np.concatenate([Q0, STATES[mode]]), 0.0, t, make_model(MOMENTS), rtol=1e-13)
    _, _, phi_exact, psi_exact = free_flow_stm(Q0, STATES[mode], MOMENTS, t)
    assert np.abs(phi_exact).max() > 10.0
    np.testing.assert_allclose(phi, phi_exact, rtol=0, atol=1e-11)
    np.testing.assert_allclose(psi, psi_exact, rtol=0, atol=1e-11)


def test_variational_equations_with_a_gravity_torque_match_differences_of_the_integrator():
    # Reference: Richardson-extrapolated central differences (h = 2e-4, 1e-4) of integrate_quaternion
    # at rtol 1e-14. Their error: O(h⁴) truncation plus the integrator's ~1e-14 noise over 2h; measured
    # agreement 7e-12 (Φ) and 1.9e-11 (Ψ) relative to the largest entry; tolerance 1e-10 relative.
    t = np.array([3.0, 20.0])
    omega = STATES["SAM"]

    def model(dp=(0.0, 0.0)):
        return make_model(MOMENTS + np.array([dp[0], dp[1], 0.0]) * MOMENTS[2], [PERTURBER])

    ys, phi, psi = integrate_variational(np.concatenate([Q0, omega]), 0.0, t, model(), rtol=1e-13)
    _, _, phi_free, _ = free_flow_stm(Q0, omega, MOMENTS, t, parameters=False)
    assert np.abs(phi - phi_free).max() > 1.0  # the torque matters: the test can tell

    def run(delta, dp=(0.0, 0.0)):
        y0 = np.concatenate([quat_multiply(Q0, exp_rotation(delta[:3])), omega + delta[3:]])
        y = integrate_quaternion(y0, 0.0, t, model(dp), rtol=1e-14)
        return np.array([local_difference(ys[k, :4], y[k, :4], y[k, 4:]) for k in range(t.size)])

    def richardson(f, n, h=2e-4):
        def central(step):
            return np.stack([(f(step * e) - f(-step * e)) / (2 * step) for e in np.eye(n)], axis=-1)
        return (4.0 * central(h / 2) - central(h)) / 3.0

    fd = richardson(run, 6)
    fd_p = richardson(lambda dp: run(np.zeros(6), dp), 2)
    np.testing.assert_allclose(phi, fd, rtol=0, atol=1e-10 * np.abs(phi).max())
    np.testing.assert_allclose(psi, fd_p, rtol=0, atol=1e-10 * np.abs(psi).max())


def test_variational_equations_refuse_what_they_do_not_linearise():
    stokes_c = np.zeros((5, 5))
    stokes_c[3, 0] = 1e-3
    model = make_model(MOMENTS, [PERTURBER], mass=1.0, stokes_c=stokes_c, stokes_s=np.zeros((5, 5)))
    with pytest.raises(ValueError, match="degree-2 torque only"):
        integrate_variational(np.concatenate([Q0, STATES["SAM"]]), 0.0, [1.0], model)
    with pytest.raises(ValueError, match="rtol"):
        integrate_variational(np.concatenate([Q0, STATES["SAM"]]), 0.0, [1.0], make_model(MOMENTS), rtol=0.0)


# --------------------------------------------------------------------------------------------------
# Taylor variational equations
# --------------------------------------------------------------------------------------------------

from spinorbit.core.integrators.taylor import integrate_taylor  # noqa: E402
from spinorbit.core.integrators.taylor_variational import integrate_taylor_variational  # noqa: E402


@pytest.mark.parametrize("mode", STATES)
def test_taylor_variational_equations_without_torque_reproduce_the_exact_stm(mode):
    # The recurrences of (Φ, Ψ) at tol 1e-14 (order 18) against the closed form through the elements.
    # Measured 1.6e-14 (SAM) and 1.6e-14 (LAM) for Φ, 2.5e-14 and 1.4e-14 for Ψ, on entries up to 19 at
    # t = 20: the series' truncation and rounding over ~60 steps; tolerance 1e-12 (the DOP853 route's
    # own agreement is 1e-12, so this also shows the Taylor STM is the more accurate one).
    t = np.array([3.0, 20.0])
    _, phi, psi = integrate_taylor_variational(np.concatenate([Q0, STATES[mode]]), 0.0, t, make_model(MOMENTS),
                                               tol=1e-14)
    _, _, phi_exact, psi_exact = free_flow_stm(Q0, STATES[mode], MOMENTS, t)
    assert np.abs(phi_exact).max() > 10.0
    np.testing.assert_allclose(phi, phi_exact, rtol=0, atol=1e-12)
    np.testing.assert_allclose(psi, psi_exact, rtol=0, atol=1e-12)


def test_taylor_variational_equations_backwards_in_time_reproduce_the_exact_stm():
    # Backwards from t0 the same recurrences hold with h < 0. Measured 1.0e-14 (Φ) and 4.7e-14 (Ψ) on
    # entries up to 14 at t = −15; tolerance 1e-12 as above.
    t = np.array([-2.0, -15.0])
    _, phi, psi = integrate_taylor_variational(np.concatenate([Q0, STATES["SAM"]]), 0.0, t, make_model(MOMENTS),
                                               tol=1e-14)
    _, _, phi_exact, psi_exact = free_flow_stm(Q0, STATES["SAM"], MOMENTS, t)
    assert np.abs(phi_exact).max() > 10.0
    np.testing.assert_allclose(phi, phi_exact, rtol=0, atol=1e-12)
    np.testing.assert_allclose(psi, psi_exact, rtol=0, atol=1e-12)


def test_taylor_variational_equations_with_a_gravity_torque_match_differences_of_integrate_taylor():
    # Reference: Richardson-extrapolated central differences (h = 2e-4, 1e-4) of integrate_taylor at tol
    # 1e-14. Their error: O(h⁴) truncation plus the integrator's ~1e-14 noise (its step sequence
    # changes with the perturbation) over 2h. Measured agreement 2.7e-12 (Φ) and 1.9e-11 (Ψ) relative
    # to the largest entry, as for the DOP853 route; tolerance 1e-10 relative.
    t = np.array([3.0, 20.0])
    omega = STATES["SAM"]

    def model(dp=(0.0, 0.0)):
        return make_model(MOMENTS + np.array([dp[0], dp[1], 0.0]) * MOMENTS[2], [PERTURBER])

    ys, phi, psi = integrate_taylor_variational(np.concatenate([Q0, omega]), 0.0, t, model(), tol=1e-14)
    _, _, phi_free, _ = free_flow_stm(Q0, omega, MOMENTS, t, parameters=False)
    assert np.abs(phi - phi_free).max() > 1.0  # the torque matters: the test can tell

    def run(delta, dp=(0.0, 0.0)):
        y0 = np.concatenate([quat_multiply(Q0, exp_rotation(delta[:3])), omega + delta[3:]])
        y = integrate_taylor(y0, 0.0, t, model(dp), tol=1e-14)
        return np.array([local_difference(ys[k, :4], y[k, :4], y[k, 4:]) for k in range(t.size)])

    def richardson(f, n, h=2e-4):
        def central(step):
            return np.stack([(f(step * e) - f(-step * e)) / (2 * step) for e in np.eye(n)], axis=-1)
        return (4.0 * central(h / 2) - central(h)) / 3.0

    fd = richardson(run, 6)
    fd_p = richardson(lambda dp: run(np.zeros(6), dp), 2)
    np.testing.assert_allclose(phi, fd, rtol=0, atol=1e-10 * np.abs(phi).max())
    np.testing.assert_allclose(psi, fd_p, rtol=0, atol=1e-10 * np.abs(psi).max())


def test_taylor_variational_equations_refuse_what_they_do_not_linearise():
    stokes_c = np.zeros((5, 5))
    stokes_c[3, 0] = 1e-3
    model = make_model(MOMENTS, [PERTURBER], mass=1.0, stokes_c=stokes_c, stokes_s=np.zeros((5, 5)))
    with pytest.raises(ValueError, match="degree-2 torque only"):
        integrate_taylor_variational(np.concatenate([Q0, STATES["SAM"]]), 0.0, [1.0], model)
    with pytest.raises(ValueError, match="tol"):
        integrate_taylor_variational(np.concatenate([Q0, STATES["SAM"]]), 0.0, [1.0], make_model(MOMENTS), tol=0.0)


# --------------------------------------------------------------------------------------------------
# The averaged propagator: STM of the mean elements
# --------------------------------------------------------------------------------------------------

import dataclasses  # noqa: E402

from benchmarks.scenes import scene_apophis  # noqa: E402
from spinorbit.core.averaging.mean_equations import moments_of  # noqa: E402
from spinorbit.core.averaging.mean_variational import mean_elements_stm, osculating_elements_stm  # noqa: E402
from spinorbit.core.averaging.propagate import averaging_frame, propagate_averaged, state_of_elements  # noqa: E402
from spinorbit.core.averaging.short_period import osculating_to_mean  # noqa: E402
from spinorbit.core.elements.canonical import inertia_constants  # noqa: E402
from spinorbit.core.integrators.elements import elements_of_state  # noqa: E402


def apophis_mean_problem():
    """The Apophis-like scene of tests/test_averaged.py with the solar torque × 10 (ε ≈ 0.025)."""
    scene = scene_apophis()
    sun = dataclasses.replace(scene.perturbers[0], mu=scene.perturbers[0].mu * 10.0, mu_orbit=scene.perturbers[0].mu)
    model = make_model(scene.moments, [sun.source()])
    ic = inertia_constants(*moments_of(model))
    frame = averaging_frame(scene.y0, model)
    mean0 = osculating_to_mean(0.0, elements_of_state(scene.y0, model, frame), model, frame, ic)
    return scene.y0, model, frame, mean0


@pytest.mark.parametrize(("orbit_averaged", "t_out"), [(False, [10.0, 30.0]), (True, [100.0, 400.0])])
def test_mean_elements_stm_matches_differences_of_propagate_averaged(orbit_averaged, t_out):
    # Reference: central differences (step 1e-7 × Z in the actions, 1e-7 rad in the angles) of
    # propagate_averaged's mean elements with its default stepping (singly averaged: in the Sun's true
    # anomaly, while the STM steps in time). The reference scatters by ~2e-9 of the largest entry when
    # its step changes (3e-8 … 3e-7); measured agreement 2.2e-9 (singly averaged, 30 d, entries up to
    # 2e3) and 1.4e-9 (doubly averaged, 400 d, up to 2.4e4) relative to the largest entry; tolerance 1e-7.
    y0, model, frame, mean0 = apophis_mean_problem()
    t_out = np.array(t_out)
    mean, phi = mean_elements_stm(mean0, 0.0, t_out, model, frame, orbit_averaged=orbit_averaged)

    def run(m0):
        return propagate_averaged(y0, 0.0, t_out, model, frame=frame, mean0=m0, hand_over=False,
                                  orbit_averaged=orbit_averaged).mean_elements

    # The mean elements themselves: the steppings agree to 8.5e-12 (H) and 7e-12 rad (s) singly averaged,
    # 1.1e-12 rad doubly; tolerance 1e-10.
    np.testing.assert_allclose(mean, run(mean0), rtol=0, atol=1e-10)
    fd = np.zeros_like(phi)
    for j in range(6):
        step = 1e-7 * (abs(mean0[1]) if j < 3 else 1.0)
        delta = np.zeros(6)
        delta[j] = step
        diff = run(mean0 + delta) - run(mean0 - delta)
        diff[:, 4:] -= 2 * np.pi * np.rint(diff[:, 4:] / (2 * np.pi))  # z and h are angles mod 2π
        fd[:, :, j] = diff / (2 * step)
    scale = np.abs(phi).max()
    assert scale > 100.0  # Φ(s, S) grows like the period's sensitivity × the turns: not the identity
    assert np.abs(phi[:, 2, 5]).max() > 1e-3  # the torque couples H to h: the test sees it
    np.testing.assert_allclose(phi, fd, rtol=0, atol=1e-7 * scale)


def test_mean_elements_stm_refuses_what_it_does_not_cover():
    _, model, frame, mean0 = apophis_mean_problem()
    with pytest.raises(ValueError, match="mean0"):
        mean_elements_stm(mean0[:5], 0.0, [1.0], model, frame)
    with pytest.raises(ValueError, match="frame"):
        mean_elements_stm(mean0, 0.0, [1.0], model, 2.0 * frame)
    with pytest.raises(ValueError, match="averaging is invalid"):
        mean_elements_stm(mean0, 0.0, [1.0], model, frame, max_perturbation=1e-6)


def test_osculating_elements_stm_matches_differences_of_propagate_averaged():
    # Through the short-period maps: osc(t) = mean_to_osculating(x(t)), x(t0) = osculating_to_mean(osc0).
    # Reference: central differences (step 1e-6 × Z, 1e-6 rad) of the osculating output of
    # propagate_averaged started from the state of osc0 ± step, turned back into elements. The maps drop
    # harmonics below 1e-11, so both sides are differences good to ~1e-5 absolute on entries ~1 and
    # more on the large ones; measured agreement 4.6e-8 relative to the largest entry (2e3);
    # tolerance 1e-6 relative.
    y0, model, frame, _ = apophis_mean_problem()
    moments = moments_of(model)
    osc0 = elements_of_state(y0, model, frame)
    t_out = np.array([10.0, 30.0])
    osc, phi = osculating_elements_stm(osc0, 0.0, t_out, model, frame)
    _, phi_mean = mean_elements_stm(osculating_to_mean(0.0, osc0, model, frame, inertia_constants(*moments)), 0.0,
                                    t_out, model, frame)

    def run(x0):
        res = propagate_averaged(state_of_elements(x0, frame, moments), 0.0, t_out, model, frame=frame,
                                 hand_over=False, osculating=True)
        return np.array([elements_of_state(state, model, frame) for state in res.states])

    # the osculating elements themselves: measured 5e-11 (round trip through (q, ω)); tolerance 1e-9
    np.testing.assert_allclose(osc, run(osc0), rtol=0, atol=1e-9)
    fd = np.zeros_like(phi)
    for j in range(6):
        step = 1e-6 * (abs(osc0[1]) if j < 3 else 1.0)
        delta = np.zeros(6)
        delta[j] = step
        diff = run(osc0 + delta) - run(osc0 - delta)
        diff[:, 4:] -= 2 * np.pi * np.rint(diff[:, 4:] / (2 * np.pi))  # z and h are angles mod 2π
        fd[:, :, j] = diff / (2 * step)
    scale = np.abs(phi).max()
    # the short-period maps change the STM by 2e-5 of its largest entry (measured), 20× the tolerance below
    assert np.abs(phi - phi_mean).max() > 5e-6 * scale
    np.testing.assert_allclose(phi, fd, rtol=0, atol=1e-6 * scale)
