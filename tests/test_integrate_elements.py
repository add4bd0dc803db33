"""The canonical-element integrator (paper eq. 11): gradients, exact flow, agreement, invariants."""

import math

import numpy as np
import pytest

from benchmarks.scenes import scene_apophis, scene_hlw, scene_toutatis
from spinorbit.core.elements.andoyer import attitude_from_andoyer
from spinorbit.core.elements.canonical import inertia_constants
from spinorbit.core.dynamics.equations import force_function_and_torque_xyz, make_model
from spinorbit.core.elements.equations import (
    andoyer_gradient_from_torque,
    elements_rhs_into,
    force_function_of_elements,
    reduce_phase,
)
from spinorbit.core.errors import SingularElementsError
from spinorbit.core.integrators.elements import (
    ElementsSingularityError,
    elements_of_state,
    integrate_elements,
    reference_frame_for,
)
from spinorbit.core.integrators.quaternion import integrate_quaternion
from spinorbit.core.model.perturbers import fixed_source
from spinorbit.core.math.rotations import attitude_to_quat, rotation_angle_between_many

#: Central differences with step 1e-5 on O(1) quantities: truncation ~1e-10 · U''', rounding
#: ~1e-16/1e-5 = 1e-11; 1e-8 relative to the largest component leaves a wide margin for both.
FD_STEP = 1e-5
FD_RTOL = 1e-8
#: The two integrators run at rtol 1e-13 over the (shortened) scenes agree to this many radians; the
#: quaternion DOP853 alone has a global error of ~1e-11 … 1e-10 there (docs/performance.md).
AGREEMENT_RAD = 1e-9

MOMENTS = (0.6, 0.9, 1.0)


def fixed_model():
    """Two perturbers at rest: a time-independent U, so T − U is conserved."""
    return make_model(MOMENTS, [fixed_source(0.3, np.array([1.2, -0.7, 0.9])),
                                fixed_source(0.1, np.array([-0.4, 2.0, 0.3]))])


def attitude_error(ys, ref):
    return float(rotation_angle_between_many(np.ascontiguousarray(ys[:, :4]), np.ascontiguousarray(ref[:, :4])).max())


@pytest.mark.parametrize("andoyer", [
    (0.5, 1.3, -0.4, 0.7, 2.1, -1.2),
    (-1.1, 1.3, 0.9, -2.5, -0.3, 2.8),
    (1.25, 1.3, -1.2, 3.0, 1.0, 0.1),  # near J = 0 and I = π: larger 1/sin terms, still checked
])
def test_force_function_gradient_in_andoyer_variables_matches_finite_differences(andoyer):
    model = fixed_model()
    v = np.array(andoyer)

    def force(x):
        attitude, _ = attitude_from_andoyer(*x)
        q = attitude_to_quat(attitude)
        return force_function_and_torque_xyz(0.0, q[0], q[1], q[2], q[3], model)[0]

    attitude, momentum = attitude_from_andoyer(*v)
    q = attitude_to_quat(attitude)
    _, nx, ny, nz = force_function_and_torque_xyz(0.0, q[0], q[1], q[2], q[3], model)
    analytic = andoyer_gradient_from_torque(attitude, momentum, nx, ny, nz)
    numeric = np.empty(6)
    for i in range(6):
        step = np.zeros(6)
        step[i] = FD_STEP
        numeric[i] = (force(v + step) - force(v - step)) / (2 * FD_STEP)
    np.testing.assert_allclose(analytic, numeric, rtol=0, atol=FD_RTOL * np.abs(numeric).max())


@pytest.mark.parametrize("sense", [1.0, -1.0])
@pytest.mark.parametrize("omega", [(0.3, 0.2, 1.1), (1.4, 0.3, 0.2)])  # SAM, LAM
def test_element_rhs_is_eq_11_with_finite_difference_gradient(sense, omega):
    """dS/dt = ∂U/∂s, …, ds/dt = aS − ∂U/∂S, with ∂U/∂(elements) by differences of U(elements)."""
    model = fixed_model()
    y0 = np.concatenate([[0.9, 0.1, -0.3, 0.2], sense * np.array(omega)])
    y0[:4] /= np.linalg.norm(y0[:4])
    frame = reference_frame_for(y0, np.array(MOMENTS))
    ic = inertia_constants(*MOMENTS)
    el = elements_of_state(y0, model, frame)
    assert np.sign(el[0]) == sense
    dy = np.empty(6)
    elements_rhs_into(0.0, el, model, frame, ic, dy)
    grad = np.empty(6)
    for i in range(6):
        step = np.zeros(6)
        step[i] = FD_STEP
        grad[i] = (force_function_of_elements(0.0, el + step, model, frame, ic)
                   - force_function_of_elements(0.0, el - step, model, frame, ic)) / (2 * FD_STEP)
    expected = np.array([grad[3], grad[4], grad[5], ic[0] * el[0] - grad[0], -grad[1], -grad[2]])
    np.testing.assert_allclose(dy, expected, rtol=0, atol=FD_RTOL * np.abs(expected).max())


def test_phase_reduction_keeps_the_state():
    model = fixed_model()
    y0 = np.array([1.0, 0.0, 0.0, 0.0, 0.3, 0.2, 1.1])
    frame = np.eye(3)
    ic = inertia_constants(*MOMENTS)
    el = elements_of_state(y0, model, frame)
    el[3] += 57.3  # many periods further along s
    reduced = el.copy()
    assert reduce_phase(reduced, ic) != 0
    assert abs(reduced[3]) < abs(el[3])
    from spinorbit.core.elements.equations import attitude_and_momentum

    r1, m1 = attitude_and_momentum(el, ic)
    r2, m2 = attitude_and_momentum(reduced, ic)
    np.testing.assert_allclose(r2, r1, atol=1e-12)
    np.testing.assert_allclose(m2, m1, atol=1e-12)


@pytest.mark.parametrize("omega", [(0.3, 0.2, 1.1), (-1.4, 0.3, 0.2)])
def test_torque_free_run_is_the_exact_flow(omega):
    """No torque: S, Z, H, h never move, z only by whole-period shifts, and s = s0 + a S t."""
    model = make_model(MOMENTS)
    y0 = np.concatenate([[0.9, 0.1, -0.3, 0.2], omega])
    t_out = np.linspace(0, 200.0, 9)[1:]
    ys, els, stats = integrate_elements(y0, 0.0, t_out, model, rtol=1e-12, return_elements=True, return_stats=True,
                                        reduce_phases=False)
    frame = stats["frame"]
    el0 = elements_of_state(y0 / np.r_[np.linalg.norm(y0[:4]) * np.ones(4), np.ones(3)], model, frame)
    a = 1 / MOMENTS[0]
    for k, t in enumerate(t_out):
        np.testing.assert_array_equal(els[k, [0, 1, 2, 4, 5]], el0[[0, 1, 2, 4, 5]])
        assert els[k, 3] == pytest.approx(el0[3] + a * el0[0] * t, rel=1e-14, abs=1e-12)
    # A linear s is integrated exactly: error estimates at rounding level, so the step grows by up to
    # MAX_FACTOR = 10 per step from Hairer's starting guess and only the first few steps are short.
    assert stats["accepted"] <= 20
    ref = integrate_quaternion(y0, 0.0, t_out, model, rtol=1e-13)
    assert attitude_error(ys, ref) < AGREEMENT_RAD


@pytest.mark.parametrize("scene, reverse", [
    (scene_apophis(n_out=6), False),
    (scene_apophis(n_out=6), True),  # S < 0: the same tumbler spinning the other way
    (scene_hlw(n_out=6, rotations=300), False),
    (scene_toutatis(n_out=6, half_span=10.0), False),  # LAM through an Earth flyby
], ids=["a-SAM", "a-SAM-reversed", "c-HLW-LAM", "b-LAM-flyby"])
def test_agrees_with_quaternion_integrator(scene, reverse):
    y0 = np.array(scene.y0, float)
    if reverse:
        y0[4:] = -y0[4:]
    ref = integrate_quaternion(y0, scene.t0, scene.t_out, scene.model, rtol=1e-13)
    ys = integrate_elements(y0, scene.t0, scene.t_out, scene.model, rtol=1e-13)
    assert attitude_error(ys, ref) < AGREEMENT_RAD
    np.testing.assert_allclose(ys[:, 4:], ref[:, 4:], rtol=0, atol=AGREEMENT_RAD * np.abs(ref[:, 4:]).max())


def test_error_decreases_with_rtol():
    scene = scene_hlw(n_out=4, rotations=100)
    ref = integrate_quaternion(scene.y0, scene.t0, scene.t_out, scene.model, rtol=1e-14)
    # The global error is not a smooth function of rtol (at 100 turns it is 3e-8 at rtol 1e-8 but
    # 1e-7 at 1e-9: cancellations between steps), so compare factors of 1000 in rtol and ask for 30.
    errors = [attitude_error(integrate_elements(scene.y0, scene.t0, scene.t_out, scene.model, rtol=tol), ref)
              for tol in (1e-6, 1e-9, 1e-12)]
    assert errors[0] > 30 * errors[1] > 900 * errors[2]
    assert errors[2] < 1e-10


def test_energy_t_minus_u_is_conserved_with_perturbers_at_rest():
    model = fixed_model()
    y0 = np.array([0.9, 0.1, -0.3, 0.2, 0.3, 0.2, 1.1])
    t_out = np.linspace(0, 100.0, 11)[1:]
    ys, els, stats = integrate_elements(y0, 0.0, t_out, model, rtol=1e-12, return_elements=True, return_stats=True)
    ic = inertia_constants(*MOMENTS)
    frame = stats["frame"]
    el0 = elements_of_state(y0 / np.r_[np.linalg.norm(y0[:4]) * np.ones(4), np.ones(3)], model, frame)

    def energy(el):
        return 0.5 * ic[0] * el[0] ** 2 - force_function_of_elements(0.0, el, model, frame, ic)

    e0 = energy(el0)
    drift = max(abs(energy(el) - e0) for el in els)
    assert drift < 1e-10 * abs(e0)
    assert abs(els[:, 0] - el0[0]).max() > 1e-6 * abs(el0[0])  # the torque is not negligible


def test_spin_about_c_is_detected_not_crossed():
    model = fixed_model()
    y0 = np.array([1.0, 0.0, 0.0, 0.0, 1e-5, 0.0, 1.0])  # sin J ≈ 6e-6 < MIN_SIN_J
    with pytest.raises(ElementsSingularityError) as info:
        integrate_elements(y0, 0.0, [1.0], model, rtol=1e-10)
    assert info.value.kind == "spin about C"
    assert info.value.t_stop == 0.0


def test_separatrix_approach_is_detected():
    big_a, big_b, big_c = MOMENTS
    # d = (Mx²/A + Mz²/C)/(Mx² + Mz²) = (1 − 1e-6)/B, just inside SAM, so 1 − m ≈ 1e-6 is below
    # MIN_SEPARATRIX_DISTANCE: Mx²/Mz² = (d − 1/C)/(1/A − d).
    d = (1 - 1e-6) / big_b
    momentum = np.array([math.sqrt((d - 1 / big_c) / (1 / big_a - d)), 0.0, 1.0])
    y0 = np.concatenate([[1.0, 0, 0, 0], momentum / np.array(MOMENTS)])
    with pytest.raises(ElementsSingularityError) as info:
        integrate_elements(y0, 0.0, [1.0], fixed_model(), rtol=1e-10)
    assert info.value.kind == "separatrix"


def test_reference_frame_is_turned_when_momentum_is_along_inertial_z():
    model = fixed_model()
    y0 = np.array([1.0, 0.0, 0.0, 0.0, 0.0, 0.05, 1.0])  # M nearly along inertial z: sin I ≈ 0.05
    frame = reference_frame_for(y0, np.array(MOMENTS))
    assert not np.allclose(frame, np.eye(3))
    t_out = np.array([5.0, 10.0])
    ys = integrate_elements(y0, 0.0, t_out, model, rtol=1e-12)
    ref = integrate_quaternion(y0, 0.0, t_out, model, rtol=1e-13)
    assert attitude_error(ys, ref) < AGREEMENT_RAD


def test_permanent_rotation_is_refused():
    with pytest.raises(SingularElementsError, match="y0"):
        integrate_elements([1, 0, 0, 0, 0, 1.0, 0], 0.0, [1.0], fixed_model())


@pytest.mark.parametrize("kwargs, name", [
    ({"rtol": 0.0}, "rtol"),
    ({"rtol": 1e-17}, "rtol"),
    ({"atol": [1e-10] * 5}, "atol"),
    ({"atol": -1.0}, "atol"),
])
def test_validation_errors_name_the_parameter(kwargs, name):
    with pytest.raises(ValueError, match=name):
        integrate_elements([1, 0, 0, 0, 0.3, 0.2, 1.1], 0.0, [1.0], fixed_model(), **kwargs)


def test_bad_times_and_state_name_the_parameter():
    with pytest.raises(ValueError, match="t_out"):
        integrate_elements([1, 0, 0, 0, 0.3, 0.2, 1.1], 0.0, [1.0, 0.5], fixed_model())
    with pytest.raises(ValueError, match="y0"):
        integrate_elements([1, 0, 0, 0, 0.3, 0.2], 0.0, [1.0], fixed_model())
