"""The mantle-and-core pieces of spinorbit.core.model.lunar_interior against independent formulas."""

import numpy as np
import pytest

from spinorbit.core.model import lunar_interior as li
from spinorbit.core.dynamics.equations import MODEL_PERTURBERS, make_model, rhs
from spinorbit.core.integrators.quaternion import integrate_quaternion
from spinorbit.core.model.perturbers import sampled_source
from spinorbit.core.math.rotations import quat_to_attitude

PAIRS = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))


def full(six):
    m = np.empty((3, 3))
    for value, (i, j) in zip(six, PAIRS):
        m[i, j] = m[j, i] = value
    return m


def block(**overrides):
    parameters = {"earth_row": MODEL_PERTURBERS + 1, "gravitational_constant": 1.0, "love_number": 0.02,
                  "time_delay": 0.1, "radius": 0.5, "mean_motion": 0.23, "core_polar_moment": 0.03,
                  "core_flattening": 0.2, "friction": 0.01, "earth_j2": 1e-3, "earth_radius": 0.7,
                  "earth_pole": (0.0, 0.6, 0.8)}
    parameters.update(overrides)
    return li.make_interior_block(**parameters)


def test_j2_hessian_is_the_second_derivative_of_the_j2_force_function():
    parameters = block()
    mu, pole, s0 = 2.0, np.array([0.0, 0.6, 0.8]), np.array([3.0, -1.0, 2.0])

    def force_function(s):
        r = np.linalg.norm(s)
        return -mu * 1e-3 * 0.49 * (3 * (s @ pole) ** 2 - r * r) / (2 * r**5)

    hessian = np.empty(6)
    li.j2_hessian(parameters, mu, *s0, *pole, hessian)
    # Second-order central differences: truncation ~ (step/|s|)² ≈ 1e-9 relative, rounding
    # ε·|U|/step² ≈ 1e-7 relative to the Hessian; 1e-6 of its largest entry covers both.
    step = 1e-4
    numeric = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            def u(a, b, i=i, j=j):
                e = s0.copy()
                e[i] += a * step
                e[j] += b * step
                return force_function(e)
            numeric[i, j] = (u(1, 1) - u(1, -1) - u(-1, 1) + u(-1, -1)) / (4 * step * step)
    assert np.trace(full(hessian)) == pytest.approx(0.0, abs=1e-12 * np.abs(hessian).max())
    np.testing.assert_allclose(full(hessian), numeric, rtol=0, atol=1e-6 * np.abs(hessian).max())


def test_figure_figure_torque_of_a_point_mass_is_maccullagh():
    rng = np.random.default_rng(3)
    inertia = rng.normal(size=(3, 3))
    inertia = inertia @ inertia.T + 3 * np.eye(3)
    six = np.array([inertia[i, j] for i, j in PAIRS])
    r, mu = np.array([1.5, -0.4, 0.9]), 2.5
    d = np.linalg.norm(r)
    hessian = mu * (3 * np.outer(r, r) - d * d * np.eye(3)) / d**5
    torque = li.figure_figure_torque(six, np.array([hessian[i, j] for i, j in PAIRS]))
    expected = 3 * mu / d**5 * np.cross(r, inertia @ r)
    np.testing.assert_allclose(torque, expected, rtol=1e-13)
    np.testing.assert_allclose(li.point_mass_torque(six, mu, *r), expected, rtol=1e-13)
    np.testing.assert_allclose(li.symmetric_solve(six, *r), np.linalg.solve(inertia, r), rtol=1e-13)


def test_distortion_rate_is_the_time_derivative_of_the_distortion():
    parameters = block()
    r0, v = np.array([10.0, 2.0, -1.0]), np.array([0.3, -0.5, 0.2])
    w0, a = np.array([0.01, -0.02, 0.23]), np.array([1e-3, 2e-3, -5e-4])

    def at(t):
        out, rate = np.empty(6), np.empty(6)
        li.distortion(parameters, *(r0 + v * t), *v, 3.0, *(w0 + a * t), *a, out, rate)
        return out, rate

    step = 1e-3
    numeric = (at(step)[0] - at(-step)[0]) / (2 * step)
    # Central difference of a smooth function: error ~ step²·(third derivative) ≈ 1e-7 relative.
    np.testing.assert_allclose(at(0.0)[1], numeric, rtol=1e-6, atol=1e-9 * np.abs(at(0.0)[0]).max())


def test_mantle_and_core_conserve_total_angular_momentum_without_external_torque():
    # A perturber with μ → tiny and the tide off: only the core–mantle torque acts, an internal torque,
    # so M(q)(I_m ω + I_c ω_c) must stay constant. Conservation holds for any form of N_cmb that acts
    # with opposite signs on mantle and core, so this checks the assembly, not DE421's physics.
    times = np.linspace(-1.0, 60.0, 400)
    far = sampled_source(1e-30, times, np.tile([1e3, 0.0, 0.0], (times.size, 1)), np.zeros((times.size, 3)))
    base = make_model([0.9, 0.95, 1.0], [far])
    parameters = block(love_number=0.0, earth_j2=0.0, core_polar_moment=0.2, friction=0.05)
    model = np.concatenate([base, parameters])
    assert li.has_interior(model) and not li.has_interior(base)
    y0 = np.array([1.0, 0, 0, 0, 0.02, -0.01, 0.3, 0.05, 0.03, 0.25])
    ys = integrate_quaternion(y0, 0.0, np.linspace(1.0, 50.0, 50), model, rtol=1e-12)
    mantle = np.diag([0.9 - 0.2 * 0.8, 0.95 - 0.2 * 0.8, 1.0 - 0.2])
    core = np.diag([0.2 * 0.8, 0.2 * 0.8, 0.2])
    momentum = [quat_to_attitude(np.ascontiguousarray(y[:4])).T @ (mantle @ y[4:7] + core @ y[7:]) for y in ys]
    # Local DOP853 errors at rtol 1e-12 over ~100 steps: drift ≲ 1e-11 of |L|.
    np.testing.assert_allclose(momentum, np.tile(momentum[0], (len(momentum), 1)), atol=1e-10)
    # The friction acts: the core's spin relative to the mantle decays (k_v > 0).
    assert np.linalg.norm(ys[-1, 7:] - ys[-1, 4:7]) < np.linalg.norm(y0[7:] - y0[4:7])
    assert rhs(0.0, y0, model).shape == (10,)


def test_interior_block_refuses_bad_parameters():
    with pytest.raises(ValueError, match="core_flattening"):
        block(core_flattening=1.5)
    with pytest.raises(ValueError, match="earth_pole"):
        block(earth_pole=(0.0, 0.0, 2.0))
    with pytest.raises(ValueError, match="non-negative"):
        block(time_delay=-1.0)
